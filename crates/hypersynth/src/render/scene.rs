//! Which product states a picture shows, and what the games stage says of them: the paper's
//! win-labels, or the general form's labels and guarantees.

use super::colour::{NOTHING_COLOUR, rank_colour, set_colour};
use super::controller::ControllerView;
use super::picture::{CellView, Key, Tag, TracePoint, win_label_key, win_label_tag};
use crate::arena::Owner;
use crate::arena::StateId;
use crate::arena::gridworld::{Cell, Collision, Gridworld, Layout};
use crate::automata::DfaState;
use crate::game::Wins;
use crate::game::{HState, Hypergame, SubsetLabel, SubsetPayoffs, TaskSet};

/// What a picture reads of a product, either engine's: its automata's enumerated states, the
/// state of an arena state and an automata tuple, and a state's arena state (the implicit
/// engine's indices are the explicit product's full enumeration, so both answer alike).
pub trait ProductView {
    /// The number of automata of the product.
    fn num_automata(&self) -> usize;
    /// The states of automaton `i` the product enumerates, in order.
    fn automaton_states(&self, i: usize) -> Vec<DfaState>;
    /// The product state of arena state `arena` with the automata in `automata` (one per
    /// automaton, each enumerated), if the product holds it.
    fn find_tuple(&self, arena: StateId, automata: &[DfaState]) -> Option<HState>;
    /// The arena state of `h`.
    fn arena_state(&self, h: HState) -> StateId;
}

impl ProductView for Hypergame<'_> {
    fn num_automata(&self) -> usize {
        Hypergame::num_automata(self)
    }
    fn automaton_states(&self, i: usize) -> Vec<DfaState> {
        Hypergame::automaton_states(self, i).to_vec()
    }
    fn find_tuple(&self, arena: StateId, automata: &[DfaState]) -> Option<HState> {
        Hypergame::find_tuple(self, arena, automata)
    }
    fn arena_state(&self, h: HState) -> StateId {
        Hypergame::arena_state(self, h)
    }
}

/// Why a picture cannot be drawn.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RenderError {
    /// The adversary's cell (`--adversary-at`) is an obstacle or outside the map.
    #[error("the adversary's cell {0} is not a free cell of the map")]
    AdversaryCell(Cell),
    #[error(
        "{state} is not an enumerated state of the automaton of {automaton} (those are: {})",
        .enumerated.iter().map(u32::to_string).collect::<Vec<_>>().join(" ")
    )]
    /// A requested automaton state is not one the product enumerates for that automaton.
    AutomatonState {
        /// The automaton's name.
        automaton: String,
        /// The requested state.
        state: DfaState,
        /// The automaton's states the product enumerates.
        enumerated: Vec<DfaState>,
    },
    #[error(
        "the product has {} automata ({}), so a picture needs {} automaton states, not {given}",
        .automata.len(), .automata.join(", "), .automata.len()
    )]
    /// The number of automaton states given differs from the number of automata in the product.
    AutomataCount {
        /// The product's automata by name, in product order.
        automata: Vec<String>,
        /// How many automaton states were given.
        given: usize,
    },
}

/// The robot states of a partition picture: for each free cell of `layout` (by `x`, then `y`)
/// the robot's product state with the adversary on `adversary`, the robot to move and the
/// product's automata (named `names`, in product order) in the states `automata`; `None` where
/// the product does not enumerate it. The adversary's own cell is left out when collisions are
/// forbidden (the robot cannot be there).
pub fn partition_states(
    world: &Gridworld,
    layout: &Layout,
    game: &dyn ProductView,
    adversary: Cell,
    automata: &[DfaState],
    names: &[String],
) -> Result<Vec<(Cell, Option<HState>)>, RenderError> {
    if !layout.free_cells().contains(&adversary) {
        return Err(RenderError::AdversaryCell(adversary));
    }
    if automata.len() != game.num_automata() {
        return Err(RenderError::AutomataCount {
            automata: names.to_vec(),
            given: automata.len(),
        });
    }
    for (i, (&state, name)) in automata.iter().zip(names).enumerate() {
        let enumerated = game.automaton_states(i);
        if !enumerated.contains(&state) {
            return Err(RenderError::AutomatonState {
                automaton: name.clone(),
                state,
                enumerated,
            });
        }
    }
    let forbidden = world.collision == Collision::Forbidden;
    Ok(layout
        .free_cells()
        .iter()
        .filter(|&&cell| !(forbidden && cell == adversary))
        .map(|&cell| {
            let h = layout
                .state(cell, adversary, Owner::Robot)
                .and_then(|arena| game.find_tuple(arena, automata));
            (cell, h)
        })
        .collect())
}

/// The cells of a partition picture: each state's tag, and the controller's mark and value
/// when `controller` (computed for the states of `states`, in order) is given; the state
/// `initial` (h0) is marked.
pub fn partition_cells(
    states: &[(Cell, Option<HState>)],
    tag: impl Fn(HState) -> Tag,
    controller: Option<&ControllerView>,
    initial: HState,
) -> Vec<CellView> {
    let mut decisions = controller.map(|view| view.decisions.iter());
    states
        .iter()
        .map(|&(cell, h)| {
            let (mark, value) = match (h, decisions.as_mut()) {
                (Some(_), Some(decisions)) => decisions.next().copied().unwrap_or((None, None)),
                _ => (None, None),
            };
            CellView {
                cell,
                tag: h.map(&tag),
                mark,
                value,
                initial: h == Some(initial),
            }
        })
        .collect()
}

/// The points of a run given as product states (with the action played in each).
pub fn trace_points(
    layout: &Layout,
    game: &dyn ProductView,
    tag: impl Fn(HState) -> Tag,
    run: &[(HState, Option<String>)],
) -> Vec<TracePoint> {
    run.iter()
        .map(|(h, action)| {
            let (robot, adversary, turn) = layout.cells(game.arena_state(*h));
            TracePoint {
                robot,
                adversary,
                turn,
                tag: tag(*h),
                action: action.clone(),
            }
        })
        .collect()
}

/// How the robot's states show in pictures. In the paper's terms (`by_win_label`) a state is
/// filled and coded by its win-label (`(W, L, L)`, code `WLL`), and the legend lists the five
/// possible labels. Otherwise (docs/semantics.md §8) a state's fill is the set it would
/// settle for (the best it can force, whose payoff is its *guarantee* `gr(h)`), in that set's
/// colour ([`super::colour`]: the same set has the same colour in every picture), vermillion
/// for none. Its code, written in the cell, is its whole label: the inclusion-maximal winnable
/// sets, then `|W` or `|L` for whether psi is winnable (`AB C|W`: A and B together, or C; names
/// joined by `,` when some name is longer than one character; `-` for none).
pub struct Tags<'a> {
    by_win_label: bool,
    regions: &'a dyn Wins,
    payoffs: &'a SubsetPayoffs,
    names: &'a [String],
    /// The distinct positive payoffs, largest first (for the colours of four tasks and more).
    classes: Vec<f64>,
}

impl<'a> Tags<'a> {
    /// The tags of the states of `regions`, whose sub-tasks are named `names` (in product order)
    /// and whose sets pay `payoffs`; by win-label when `by_win_label`.
    pub fn new(
        regions: &'a dyn Wins,
        payoffs: &'a SubsetPayoffs,
        names: &'a [String],
        by_win_label: bool,
    ) -> Tags<'a> {
        let mut classes: Vec<f64> = TaskSet::non_empty(payoffs.num_tasks())
            .map(|set| payoffs.get(set))
            .filter(|&payoff| payoff > 0.0)
            .collect();
        classes.sort_by(|a, b| b.total_cmp(a));
        classes.dedup();
        Tags {
            by_win_label,
            regions,
            payoffs,
            names,
            classes,
        }
    }

    /// The fill of states that settle for `set` (`None`: nothing).
    fn colour(&self, set: Option<TaskSet>) -> String {
        let Some(set) = set else {
            return NOTHING_COLOUR.to_string();
        };
        if self.payoffs.num_tasks() <= 3
            && let Some(colour) = set_colour(set)
        {
            return colour.to_string();
        }
        let payoff = self.payoffs.get(set);
        match self.classes.iter().position(|&c| c == payoff) {
            Some(index) if payoff > 0.0 => rank_colour(index, self.classes.len()),
            _ => NOTHING_COLOUR.to_string(),
        }
    }

    /// The short form of a label, written in cells and in a run's table.
    pub fn code(&self, label: &SubsetLabel) -> String {
        let separator = if self.names.iter().all(|n| n.chars().count() == 1) {
            ""
        } else {
            ","
        };
        let sets: Vec<String> = label
            .maximal
            .iter()
            .map(|set| set.names(self.names).join(separator))
            .collect();
        let sets = if sets.is_empty() {
            "-".to_string()
        } else {
            sets.join(" ")
        };
        format!("{sets}|{}", if label.psi { 'W' } else { 'L' })
    }

    /// How product state `h` shows.
    pub fn tag(&self, h: HState) -> Tag {
        if self.by_win_label {
            return win_label_tag(self.regions.win_label(h));
        }
        let label = self.regions.label(h);
        let guarantee = self.regions.guarantee(self.payoffs, h);
        Tag {
            colour: self.colour(self.regions.best(self.payoffs, h)),
            code: self.code(&label),
            text: format!("{}, guarantee {guarantee}", label.display(self.names)),
        }
    }

    /// The legend of the fills of `shown` (the states a picture shows): one line per set some
    /// of them would settle for, largest payoff first, then the code's meaning.
    pub fn key(&self, shown: impl IntoIterator<Item = HState>) -> Key {
        if self.by_win_label {
            return win_label_key();
        }
        let mut settles: Vec<Option<TaskSet>> = shown
            .into_iter()
            .map(|h| self.regions.best(self.payoffs, h))
            .collect();
        let preference = self.payoffs.preference();
        let position = |set: &Option<TaskSet>| match set {
            Some(set) => preference
                .iter()
                .position(|s| s == set)
                .unwrap_or(usize::MAX),
            None => usize::MAX,
        };
        settles.sort_by_key(position);
        settles.dedup();
        let mut entries: Vec<(Option<String>, String)> = settles
            .into_iter()
            .map(|set| match set {
                Some(set) => {
                    let payoff = self.payoffs.get(set);
                    (
                        Some(self.colour(Some(set))),
                        format!("{{{}}}: {payoff}", set.display(self.names)),
                    )
                }
                None => (Some(NOTHING_COLOUR.to_string()), "nothing: 0".to_string()),
            })
            .collect();
        entries.push((None, "code: maximal winnable sets | psi W or L".to_string()));
        Key {
            heading: "Best set the robot can force: its payoff".to_string(),
            entries,
        }
    }
}
