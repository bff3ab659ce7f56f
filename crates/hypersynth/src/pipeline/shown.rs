//! What the pictures and the explorer page read of a solved problem, from either engine
//! ([`Shown`] for the product and its regions, [`Controlled`] for the MDP stage's controller),
//! so that one implementation draws both engines' pictures and makes both engines' pages.
//!
//! The implicit engine's indices are the explicit product's full enumeration
//! (docs/semantics.md §13), so a state has the same index, name, tag and slice in both; where
//! the two controllers decide alike, the pictures and the page are the same bytes.

use bit_set::BitSet;

use super::opportunistic::MdpOptions;
use crate::arena::{ActionId, LabelId, StateId};
use crate::automata::DfaState;
use crate::game::{HState, SubsetPayoffs, TaskSet, Wins};
use crate::implicit::{Moves, PolicyError, Regions, Space};
use crate::opportunistic::controller::Explanation;
use crate::opportunistic::export::Exportable;
use crate::opportunistic::presentation::Presentation;
use crate::opportunistic::simulate::Trace;
use crate::opportunistic::view::{GameView, SolvedGame, SolvedHypergame};
use crate::render::ProductView;

/// A product with its winning regions, the sets' payoffs and the problem's presentation, as
/// the pictures and the explorer read them.
pub(crate) trait Shown: ProductView + Wins {
    /// How reports name the tasks and label the states.
    fn presentation(&self) -> &Presentation;
    /// The payoff of every set of sub-tasks.
    fn payoffs(&self) -> &SubsetPayoffs;
    /// h0.
    fn initial(&self) -> HState;
    /// Whether the robot moves in `h`.
    fn is_robot(&self, h: HState) -> bool;
    /// The automata tuple of `h` (its automata slot).
    fn tuple_of(&self, h: HState) -> u32;
    /// The number of automata tuples.
    fn num_tuples(&self) -> u32;
    /// The automata's states in tuple `tuple`.
    fn tuple(&self, tuple: u32) -> Vec<DfaState>;
    /// The name of `h` (`ARENA_STATE|q1|…`).
    fn state_name(&self, h: HState) -> String;
    /// Fills `out` with the edges of `h`, in edge order.
    fn edges(&self, h: HState, out: &mut Vec<(ActionId, HState)>);
    /// The name of arena action `action`.
    fn action_name(&self, action: ActionId) -> &str;
    /// The arena's distinct labels, each a set of indices into [`Shown::propositions`].
    fn labels(&self) -> &[BitSet];
    /// The arena's propositions.
    fn propositions(&self) -> &[String];
    /// The label of arena state `s`, an index into [`Shown::labels`].
    fn arena_label(&self, s: StateId) -> LabelId;

    /// How reports label `h` ([`Presentation::state_label`]).
    fn state_label(&self, h: HState) -> String {
        self.presentation().state_label(self, self.payoffs(), h)
    }

    /// How reports name `set`.
    fn set_name(&self, set: TaskSet) -> String {
        self.presentation().set_name(set)
    }
}

/// The decision tables of product states, in order: what the page embeds (one call, so that
/// the implicit engine solves its policy's chain once for all of them).
pub(crate) type Tables<'a> = dyn Fn(&[HState]) -> Result<Vec<Explanation>, PolicyError> + 'a;

/// The MDP stage's controller as the pictures and the page read it: its decisions, values and
/// reactive moves, its decision tables, the traced run and the options it was solved with.
pub(crate) struct Controlled<'a> {
    /// The controller.
    pub(crate) controller: &'a dyn Exportable,
    /// The decision tables of product states, in order.
    pub(crate) explain: &'a Tables<'a>,
    /// The options of the MDP stage.
    pub(crate) options: &'a MdpOptions,
    /// The traced run, when one was asked for.
    pub(crate) trace: Option<&'a Trace>,
}

/// The explicit engine's solved product as [`Shown`] (a type of its own, so that its own
/// methods of the same names stay unambiguous).
pub(crate) struct ExplicitShown<'g, 'a>(pub(crate) &'g SolvedHypergame<'g, 'a>);

impl Wins for ExplicitShown<'_, '_> {
    fn num_tasks(&self) -> usize {
        self.0.regions().num_tasks()
    }
    fn wins(&self, set: TaskSet, h: HState) -> bool {
        self.0.regions().wins(set, h)
    }
    fn believed_wins(&self, h: HState) -> bool {
        self.0.regions().believed_wins(h)
    }
}

impl ProductView for ExplicitShown<'_, '_> {
    fn num_automata(&self) -> usize {
        self.0.game().num_automata()
    }
    fn automaton_states(&self, i: usize) -> Vec<DfaState> {
        self.0.game().automaton_states(i).to_vec()
    }
    fn find_tuple(&self, arena: StateId, automata: &[DfaState]) -> Option<HState> {
        self.0.game().find_tuple(arena, automata)
    }
    fn arena_state(&self, h: HState) -> StateId {
        self.0.game().arena_state(h)
    }
}

impl Shown for ExplicitShown<'_, '_> {
    fn presentation(&self) -> &Presentation {
        SolvedGame::presentation(self.0)
    }
    fn payoffs(&self) -> &SubsetPayoffs {
        SolvedGame::payoffs(self.0)
    }
    fn initial(&self) -> HState {
        GameView::initial(self.0)
    }
    fn is_robot(&self, h: HState) -> bool {
        GameView::is_robot(self.0, h)
    }
    fn tuple_of(&self, h: HState) -> u32 {
        self.0.game().automata_slot(h)
    }
    fn num_tuples(&self) -> u32 {
        self.0.game().num_automata_slots()
    }
    fn tuple(&self, tuple: u32) -> Vec<DfaState> {
        self.0.game().automata_of_slot(tuple)
    }
    fn state_name(&self, h: HState) -> String {
        GameView::state_name(self.0, h)
    }
    fn edges(&self, h: HState, out: &mut Vec<(ActionId, HState)>) {
        out.clear();
        out.extend(GameView::edges(self.0, h));
    }
    fn action_name(&self, action: ActionId) -> &str {
        GameView::action_name(self.0, action)
    }
    fn labels(&self) -> &[BitSet] {
        self.0.arena().labels()
    }
    fn propositions(&self) -> &[String] {
        self.0.arena().propositions()
    }
    fn arena_label(&self, s: StateId) -> LabelId {
        self.0.arena().label_id(s)
    }
}

/// The implicit engine's product ([`Space`]) with its regions, as [`Shown`].
pub(crate) struct ImplicitShown<'a, 'm, M> {
    pub(crate) space: &'a Space<'m, M>,
    pub(crate) regions: &'a Regions,
    pub(crate) payoffs: &'a SubsetPayoffs,
    pub(crate) presentation: &'a Presentation,
}

impl<M: Moves> Wins for ImplicitShown<'_, '_, M> {
    fn num_tasks(&self) -> usize {
        self.regions.num_tasks()
    }
    fn wins(&self, set: TaskSet, h: HState) -> bool {
        self.regions.wins(set, h.as_u32())
    }
    fn believed_wins(&self, h: HState) -> bool {
        self.regions.believed_wins(h)
    }
}

impl<M: Moves> ProductView for ImplicitShown<'_, '_, M> {
    fn num_automata(&self) -> usize {
        self.space.num_automata()
    }
    fn automaton_states(&self, i: usize) -> Vec<DfaState> {
        self.space.tuple_states_of(i).to_vec()
    }
    fn find_tuple(&self, arena: StateId, automata: &[DfaState]) -> Option<HState> {
        self.space
            .find_tuple(arena.as_u32(), automata)
            .map(HState::from_u32)
    }
    fn arena_state(&self, h: HState) -> StateId {
        StateId::from_u32(self.space.arena_state(h.as_u32()))
    }
}

impl<M: Moves> Shown for ImplicitShown<'_, '_, M> {
    fn presentation(&self) -> &Presentation {
        self.presentation
    }
    fn payoffs(&self) -> &SubsetPayoffs {
        self.payoffs
    }
    fn initial(&self) -> HState {
        HState::from_u32(self.space.initial())
    }
    fn is_robot(&self, h: HState) -> bool {
        self.space.owner(h.as_u32()) == crate::arena::Owner::Robot
    }
    fn tuple_of(&self, h: HState) -> u32 {
        self.space.tuple(h.as_u32())
    }
    fn num_tuples(&self) -> u32 {
        self.space.num_tuples()
    }
    fn tuple(&self, tuple: u32) -> Vec<DfaState> {
        self.space.tuple_states(tuple)
    }
    fn state_name(&self, h: HState) -> String {
        self.space.name(h.as_u32())
    }
    fn edges(&self, h: HState, out: &mut Vec<(ActionId, HState)>) {
        out.clear();
        self.space
            .edges(h.as_u32(), |a, t| out.push((a, HState::from_u32(t))));
    }
    fn action_name(&self, action: ActionId) -> &str {
        &self.space.moves().actions()[action as usize]
    }
    fn labels(&self) -> &[BitSet] {
        self.space.moves().labels()
    }
    fn propositions(&self) -> &[String] {
        self.space.moves().propositions()
    }
    fn arena_label(&self, s: StateId) -> LabelId {
        self.space.moves().label(s.as_u32())
    }
}
