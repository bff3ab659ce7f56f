//! The hypergame MDP of both forms (docs/semantics.md §6 and §8), built in one way.
//!
//! MDP states: one per product state, with the product's numbers, then the stop sinks. Robot
//! states are decision nodes, adversary states *chance nodes*: one instant choice (named
//! [`CHANCE`]) whose distribution is the adversary model's, without its probability-0 edges
//! (sigma_W outside `Win(psi)`, sigma_L inside). Chains, diamonds and cycles of adversary states
//! therefore cost one state each: nothing is enumerated along paths. A set of adversary states
//! that the model can never leave is an ordinary closed set of chance nodes; the run stays out of
//! the robot's control forever and collects 0, which is what the solver computes for it. A stuck
//! adversary state ends the play; the attractors count it as won for every set, so it is
//! absorbing with the payoff of all sub-tasks.
//!
//! A robot state *commits* (is absorbing with its guarantee `gr(h)`, see [`SolvedGame::best`])
//! by the problem's [`Commitment`] rule (its presentation's):
//! - the paper's (§6.3): in `Win(phi)` (label `(W,W,W)`, payoff r), and outside `Win(psi)` with a
//!   positive guarantee (`(L,W,L)`, payoff r2);
//! - the general one (§8.5): where no robot state of a larger guarantee can be reached (through
//!   any robot move and the adversary's moves of positive probability, a stuck adversary state
//!   counting as all sub-tasks): [`greatest_reachable_level`].
//!
//! Any other robot state is a decision node with `stop` (instant, to the sink of the set it
//! settles for) when `gr(h) > 0`, and the arena actions the [`Risk`] rule allows, judged on the
//! least guarantee of the next robot state ([`least_next_level`]); a stuck robot state of
//! guarantee 0 (only the paper's rule leaves one uncommitted) is absorbing with payoff 0. Levels
//! are the ranks of the distinct payoffs, 0 for payoff 0. The paper's `(L,L,L)` states keep every
//! action and have no stop; its `(W,·,L)` states keep the actions with probability 0 of an
//! `(L,L,L)` robot state next. Its two stop sinks are `stop(phi1)` (r1, from `(W,L,L)`) and
//! `stop(best)` (max(r1, r2), from `(W,W,L)`); the general form has one sink per non-empty set,
//! in mask order (`stop(A,B)`, payoff r(T)).
//!
//! Arena actions are moves (one robot move: discounted, counted as time); `stop` is instant: it
//! collects its payoff at once, like arriving in an absorbing state, so no robot state is worth
//! less than what it can settle for. The initial state may belong to either player. Arena
//! actions keep their names; `stop` is reserved.
//!
//! Cost: O(|H| + |edges|) time plus the level searches; the MDP has |H| states plus the sinks
//! and at most one choice per product edge plus one per robot state. The build goes through the
//! product twice, by chunks of consecutive states on the rayon pool: it counts each state's
//! choices and transitions, then writes them in arrays allocated once at their exact size
//! (`MdpLayout`), so that its peak is the MDP itself (about 53 bytes per product state on the
//! gridworlds) plus two bytes per state (the least next level) and a bit (the committing states);
//! before that, the level searches take their own temporaries and free them. The MDP does not
//! depend on the chunks or the threads.

use std::ops::Range;

use bit_set::BitSet;
use serde::Serialize;
use thiserror::Error;

use super::adversary::AdversaryModel;
use super::levels::{Levels, greatest_reachable_level, least_next_level};
use super::presentation::Commitment;
pub use super::risk::Risk;
use super::view::SolvedGame;
use crate::arena::ActionId;
use crate::game::{HState, TaskSet};
use crate::index::Id;
use crate::mdp::model::{
    ActionNames, AddStates, ChoiceId, Counts, Mdp, MdpError, MdpLayout, MdpState,
};
use crate::mdp::solve::Solution;
use crate::stage::{Meter, Stage, Tally};

/// The reserved action name of the robot's decision to settle for a set of sub-tasks.
pub const STOP: &str = "stop";

/// The name of the single (instant) choice of a chance node: the adversary's move.
pub const CHANCE: &str = "adversary";

/// Why the hypergame MDP cannot be built.
#[derive(Debug, Error, PartialEq)]
pub enum BuildError {
    /// The arena has an action named `stop`, the name of the MDP's own stop action.
    #[error("the arena action `stop` clashes with the reserved stop action")]
    ReservedAction,
    /// The MDP builder refused the model.
    #[error(transparent)]
    Mdp(#[from] MdpError),
}

/// The hypergame MDP. MDP state `h` is product state `h`; the stop sinks follow.
#[derive(Clone, Debug, PartialEq)]
pub struct HypergameMdp {
    mdp: Mdp,
    /// MDP action id → arena action (`u32::NONE` for `stop` and the chance move). A choice's
    /// arena action is found through its MDP action, so that nothing is kept per choice: moves
    /// are exactly the choices of arena actions (`stop` and chance choices are instant), which
    /// tells them apart even from an arena action named like the chance move.
    arena_actions: Vec<ActionId>,
    /// The robot states that commit without moving (absorbing by the commitment rule).
    commits: BitSet,
    /// The names of the stop sinks that follow the product states.
    sinks: Vec<String>,
    num_product_states: usize,
}

/// The sizes reported for a solved hypergame MDP (docs/semantics.md §6.10).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct MdpSizes {
    /// Decision nodes in the sense of the paper: every robot product state.
    pub robot_states: u32,
    /// Robot states where the robot commits without moving (`(W,W,W)` and `(L,W,L)` in the
    /// paper's form; where nothing better can ever come in general).
    pub absorbing: u32,
    /// The other robot states of positive value.
    pub with_opportunity: u32,
    /// The remaining robot states (value 0). The three add up to `robot_states`.
    pub without_opportunity: u32,
    /// Robot states whose value exceeds their guarantee (by more than the certified error);
    /// reported in the general form only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub above_guarantee: Option<u32>,
    /// Robot states without an enabled action (also counted in the three above).
    pub stuck: u32,
    /// Adversary states that move (chance nodes); stuck ones are absorbing.
    pub chance_nodes: u32,
    /// The MDP's own number of states (the product states and the sinks).
    pub states: u32,
    /// The MDP's choices (the enabled actions of all its states, `stop` included).
    pub choices: u32,
    /// The MDP's transitions (the targets of all its choices).
    pub transitions: u32,
}

impl HypergameMdp {
    /// The hypergame MDP of `game` with the adversary playing `adversary` and the robot keeping
    /// the actions `risk` allows: MDP state `h` is product state `h`, followed by the sinks.
    pub fn build(
        game: &(impl SolvedGame + Sync),
        adversary: &AdversaryModel,
        risk: Risk,
    ) -> Result<HypergameMdp, BuildError> {
        let meter = &mut Meter::unobserved(Stage::MdpBuild);
        HypergameMdp::build_metered(game, adversary, risk, meter)
    }

    /// [`HypergameMdp::build`], reporting to `meter` the product states dealt with: each is
    /// counted, then written (the total is twice the product's states).
    pub fn build_metered(
        game: &(impl SolvedGame + Sync),
        adversary: &AdversaryModel,
        risk: Risk,
        meter: &mut Meter<'_>,
    ) -> Result<HypergameMdp, BuildError> {
        HypergameMdp::build_chunked(game, adversary, risk, meter, CHUNK)
    }

    /// [`HypergameMdp::build_metered`] with `chunk` product states per parallel job.
    fn build_chunked(
        game: &(impl SolvedGame + Sync),
        adversary: &AdversaryModel,
        risk: Risk,
        meter: &mut Meter<'_>,
        chunk: usize,
    ) -> Result<HypergameMdp, BuildError> {
        let n = game.num_states();
        let mut names = ActionNames::default();
        let (stop, chance) = (names.intern(STOP)?, names.intern(CHANCE)?);
        let (actions, arena_actions) = action_ids(game.arena(), |name| names.intern(name))?;
        let levels = Levels::new(game.payoffs());
        let commits = committing_states(game, adversary, &levels);
        // Only the least level of the next robot state is kept of the risk rules' search.
        let next: Vec<u16> = least_next_level(game, adversary, |h| level_of(&levels, game, h))
            .into_iter()
            .map(|level| u16::try_from(level).unwrap_or(u16::MAX))
            .collect();
        let rules = Rules {
            game,
            adversary,
            risk,
            levels,
            next,
            commits: &commits,
            actions,
            stop,
            chance,
        };
        // Two passes over the same chunks, in parallel: count each chunk's choices and
        // transitions exactly, then write each at its place in arrays allocated once at their
        // final length. Either pass gives the first error in state order.
        let chunks: Vec<Range<usize>> = (0..n)
            .step_by(chunk.max(1))
            .map(|start| start..n.min(start + chunk.max(1)))
            .collect();
        meter.set_total(2 * n as u64);
        let rules = &rules;
        let jobs = chunks
            .iter()
            .map(|states| {
                move |tally: &Tally| {
                    let mut counts = Counts::default();
                    rules.add_states(states.clone(), &mut counts, tally)?;
                    Ok(counts)
                }
            })
            .collect();
        let mut counts = meter
            .parallel(jobs)
            .into_iter()
            .collect::<Result<Vec<_>, BuildError>>()?;
        let mut sinks = Counts::default();
        rules.add_sinks(&mut sinks)?;
        counts.push(sinks);
        let mut layout = MdpLayout::new(names, &counts, meter)?;
        drop(counts);
        let mut writers = layout.writers();
        let mut sinks = writers.pop().expect("the sinks' chunk");
        let jobs = writers
            .into_iter()
            .zip(&chunks)
            .map(|(mut writer, states)| {
                move |tally: &Tally| {
                    rules.add_states(states.clone(), &mut writer, tally)?;
                    Ok(writer.finish()?)
                }
            })
            .collect();
        let mut instant = meter
            .parallel(jobs)
            .into_iter()
            .collect::<Result<Vec<_>, BuildError>>()?;
        rules.add_sinks(&mut sinks)?;
        instant.push(sinks.finish()?);
        Ok(HypergameMdp {
            mdp: layout.finish(instant, node(game.initial()))?,
            arena_actions,
            commits,
            sinks: sink_names(game),
            num_product_states: n,
        })
    }

    /// The MDP itself.
    pub fn mdp(&self) -> &Mdp {
        &self.mdp
    }

    /// The MDP state of product state `h` (the same number).
    pub fn node(&self, h: HState) -> MdpState {
        node(h)
    }

    /// The product state of MDP state `s`; `None` for the stop sinks.
    pub fn product_state(&self, s: MdpState) -> Option<HState> {
        (s.index() < self.num_product_states).then(|| HState::from_u32(s.as_u32()))
    }

    /// Whether the robot commits in robot state `h` without moving (the MDP absorbs it with its
    /// guarantee).
    pub fn commits(&self, h: HState) -> bool {
        self.commits.contains(h.index())
    }

    /// The display name of MDP state `s`: its product state's, or its stop sink's:
    /// `stop(phi1)`, `stop(best)` in the paper's form, `stop(A,B)` in general.
    pub fn state_name(&self, game: &impl SolvedGame, s: MdpState) -> String {
        match self.product_state(s) {
            Some(h) => game.state_name(h),
            None => self.sinks[s.index() - self.num_product_states].clone(),
        }
    }

    /// The arena action of MDP choice `choice`; `None` for `stop` and chance choices.
    pub fn arena_action(&self, choice: ChoiceId) -> Option<ActionId> {
        if self.mdp.is_instant(choice) {
            return None;
        }
        self.arena_actions[self.mdp.action(choice) as usize].to_option()
    }

    /// The report's sizes of this MDP, with the robot states classified by `solution`'s values
    /// (those fixed qualitatively to 0 have upper bound 0; every other value is positive).
    pub fn sizes(&self, game: &impl SolvedGame, solution: &Solution) -> MdpSizes {
        let mdp = &self.mdp;
        let mut sizes = SizeCount::new(
            mdp.num_states() as u32,
            mdp.num_choices() as u32,
            mdp.num_transitions() as u32,
        );
        for h in game.states() {
            let stuck = game.edges(h).next().is_none();
            if !game.is_robot(h) {
                sizes.chance_nodes(u32::from(!stuck));
                continue;
            }
            let value = solution.value(node(h));
            let above = value.lower > game.guarantee(h) + solution.gap();
            sizes.robot_state(stuck, self.commits(h), value.upper, above);
        }
        sizes.finish(game.presentation().layout().states_guarantees)
    }
}

/// [`MdpSizes`] counted state by state, the robot states classified as the report classifies
/// them (either engine's).
pub(crate) struct SizeCount {
    sizes: MdpSizes,
    above_guarantee: u32,
}

impl SizeCount {
    /// No state counted yet, in an MDP of these sizes.
    pub(crate) fn new(states: u32, choices: u32, transitions: u32) -> SizeCount {
        SizeCount {
            sizes: MdpSizes {
                robot_states: 0,
                absorbing: 0,
                with_opportunity: 0,
                without_opportunity: 0,
                above_guarantee: None,
                stuck: 0,
                chance_nodes: 0,
                states,
                choices,
                transitions,
            },
            above_guarantee: 0,
        }
    }

    /// Counts `n` chance nodes.
    pub(crate) fn chance_nodes(&mut self, n: u32) {
        self.sizes.chance_nodes += n;
    }

    /// Counts a robot state: `stuck` without an action, committing without moving, of upper
    /// bound `upper`, with a lower bound `above` its guarantee by more than the solver's gap.
    pub(crate) fn robot_state(&mut self, stuck: bool, commits: bool, upper: f64, above: bool) {
        let sizes = &mut self.sizes;
        sizes.robot_states += 1;
        sizes.stuck += u32::from(stuck);
        self.above_guarantee += u32::from(above);
        *if commits {
            &mut sizes.absorbing
        } else if upper > 0.0 {
            &mut sizes.with_opportunity
        } else {
            &mut sizes.without_opportunity
        } += 1;
    }

    /// Adds the states `other` counted (its states, choices and transitions included).
    pub(crate) fn add(&mut self, other: &SizeCount) {
        let (sizes, more) = (&mut self.sizes, &other.sizes);
        sizes.robot_states += more.robot_states;
        sizes.absorbing += more.absorbing;
        sizes.with_opportunity += more.with_opportunity;
        sizes.without_opportunity += more.without_opportunity;
        sizes.stuck += more.stuck;
        sizes.chance_nodes += more.chance_nodes;
        sizes.states += more.states;
        sizes.choices += more.choices;
        sizes.transitions += more.transitions;
        self.above_guarantee += other.above_guarantee;
    }

    /// Counts `choices` choices with `transitions` transitions between them.
    pub(crate) fn choices(&mut self, choices: u32, transitions: u32) {
        self.sizes.choices += choices;
        self.sizes.transitions += transitions;
    }

    /// The sizes, with the count above the guarantee where the report states guarantees.
    pub(crate) fn finish(mut self, states_guarantees: bool) -> MdpSizes {
        if states_guarantees {
            self.sizes.above_guarantee = Some(self.above_guarantee);
        }
        self.sizes
    }
}

/// The MDP action id of each arena action, interned by `intern` after `stop` and the chance
/// move, and the arena action of each MDP action id (`u32::NONE` for `stop` and the chance
/// move); an arena action named `stop` is refused.
fn action_ids(
    arena: &crate::arena::Arena,
    mut intern: impl FnMut(&str) -> Result<u32, MdpError>,
) -> Result<(Vec<u32>, Vec<ActionId>), BuildError> {
    let mut actions = Vec::with_capacity(arena.actions().len());
    let mut arena_actions = vec![u32::NONE; 2];
    for (a, name) in arena.actions().iter().enumerate() {
        if name == STOP {
            return Err(BuildError::ReservedAction);
        }
        let id = intern(name)?;
        if id as usize >= arena_actions.len() {
            arena_actions.resize(id as usize + 1, u32::NONE);
        }
        arena_actions[id as usize] = a as ActionId;
        actions.push(id);
    }
    Ok((actions, arena_actions))
}

/// Product states per job of the build's parallel passes: enough that a job's overhead (a spawn,
/// a few buffers) is negligible, few enough that two cores share the work evenly.
const CHUNK: usize = 1 << 15;

/// The level of a game's robot state or stuck adversary state `h` ([`Levels`]).
fn level_of(levels: &Levels, game: &impl SolvedGame, h: HState) -> u32 {
    if game.is_robot(h) {
        levels.of_set(game.best(h))
    } else {
        levels.top()
    }
}

/// The robot states that commit without moving, by the game's commitment rule.
fn committing_states(
    game: &impl SolvedGame,
    adversary: &AdversaryModel,
    levels: &Levels,
) -> BitSet {
    let robot = game.states().filter(|&h| game.is_robot(h));
    match game.presentation().commitment() {
        Commitment::Labels => {
            let all = TaskSet::all(game.payoffs().num_tasks());
            robot
                .filter(|&h| {
                    game.wins(all, h) || (!game.believed_win(h) && game.guarantee(h) > 0.0)
                })
                .map(HState::index)
                .collect()
        }
        Commitment::NothingBetter => {
            let reachable =
                greatest_reachable_level(game, adversary, |h| level_of(levels, game, h));
            robot
                .filter(|&h| reachable[h.index()] <= level_of(levels, game, h))
                .map(HState::index)
                .collect()
        }
    }
}

/// What decides the MDP's states: the rules of the module documentation, applied one product
/// state at a time.
struct Rules<'a, G> {
    game: &'a G,
    adversary: &'a AdversaryModel,
    risk: Risk,
    levels: Levels,
    /// Per state, the least level of the next robot state (`u16::MAX`: none is reachable).
    next: Vec<u16>,
    commits: &'a BitSet,
    /// MDP action id per arena action.
    actions: Vec<u32>,
    stop: u32,
    chance: u32,
}

impl<G: SolvedGame> Rules<'_, G> {
    /// Adds MDP states `states` (product states of the same numbers) to `out`, in order, and
    /// their number to `tally` at the end.
    fn add_states(
        &self,
        states: Range<usize>,
        out: &mut impl AddStates,
        tally: &Tally,
    ) -> Result<(), BuildError> {
        let mut chance_moves = ChanceMoves::default();
        let count = states.len() as u64;
        for h in states.map(HState::new) {
            self.add_state(h, out, &mut chance_moves)?;
        }
        tally.add(count);
        Ok(())
    }

    fn add_state(
        &self,
        h: HState,
        out: &mut impl AddStates,
        chance_moves: &mut ChanceMoves,
    ) -> Result<(), BuildError> {
        let game = self.game;
        let stuck = game.edges(h).next().is_none();
        if !game.is_robot(h) {
            if stuck {
                out.add_absorbing_state(game.payoffs().all())?;
            } else {
                out.add_decision_state()?;
                let moves = chance_moves.of(game, self.adversary, h);
                out.add_choice(self.chance, moves, true)?;
            }
            return Ok(());
        }
        if self.commits.contains(h.index()) {
            out.add_absorbing_state(game.guarantee(h))?;
            return Ok(());
        }
        let own = level_of(&self.levels, game, h);
        if stuck && own == 0 {
            out.add_absorbing_state(0.0)?;
            return Ok(());
        }
        out.add_decision_state()?;
        for (a, t) in game.edges(h) {
            if self.allows(own, t) {
                out.add_choice(self.actions[a as usize], &[(node(t), 1.0)], false)?;
            }
        }
        if own > 0 {
            let sink = MdpState::new(game.num_states() + self.sink(h));
            out.add_choice(self.stop, &[(sink, 1.0)], true)?;
        }
        Ok(())
    }

    /// Whether the risk rule lets a robot state of level `own` move to `t`. A successor from
    /// which no robot state can come next (a closed set of chance nodes) is worth 0 and never
    /// lowers a guarantee: always allowed.
    fn allows(&self, own: u32, t: HState) -> bool {
        self.risk.allows(own, self.next[t.index()])
    }

    /// The stop sink (counted from the first) robot state `h` stops to.
    fn sink(&self, h: HState) -> usize {
        let game = self.game;
        game.presentation()
            .stop_sink(|set| game.wins(set, h), game.best(h))
    }

    /// Adds the stop sinks of the game's presentation ([`Presentation::sinks`]).
    ///
    /// [`Presentation::sinks`]: super::presentation::Presentation::sinks
    fn add_sinks(&self, out: &mut impl AddStates) -> Result<(), BuildError> {
        for sink in self.game.presentation().sinks(self.game.payoffs()) {
            out.add_absorbing_state(sink.payoff)?;
        }
        Ok(())
    }
}

/// The MDP state of product state `h`: MDP states number the product states first, in
/// product order.
/// The names of the stop sinks, in the order the build adds them.
fn sink_names(game: &impl SolvedGame) -> Vec<String> {
    game.presentation()
        .sinks(game.payoffs())
        .into_iter()
        .map(|sink| sink.name)
        .collect()
}

pub(crate) fn node(h: HState) -> MdpState {
    MdpState::from_u32(h.as_u32())
}

/// The chance move of an adversary state as an MDP distribution: the adversary model's moves of
/// positive probability, with the buffers they are computed in.
#[derive(Default)]
pub(crate) struct ChanceMoves {
    scratch: Vec<f64>,
    moves: Vec<(HState, f64)>,
    outcomes: Vec<(MdpState, f64)>,
}

impl ChanceMoves {
    pub(crate) fn of(
        &mut self,
        game: &impl super::view::GameView,
        adversary: &AdversaryModel,
        h: HState,
    ) -> &[(MdpState, f64)] {
        adversary.positive_moves(game, h, &mut self.scratch, &mut self.moves);
        self.outcomes.clear();
        self.outcomes
            .extend(self.moves.iter().map(|&(t, p)| (node(t), p)));
        &self.outcomes
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use rand_chacha::ChaCha8Rng;
    use rand_core::{RngCore, SeedableRng};

    use super::*;
    use crate::game::{Payoffs, Wins};
    use crate::mdp::model::MdpBuilder;
    use crate::mdp::solve::{SolveOptions, solve};
    use crate::mdp::testing::ms;
    use crate::opportunistic::adversary::SigmaL;
    use crate::opportunistic::presentation::Presentation;
    use crate::opportunistic::view::testing::{ToyGame, hs};
    use crate::opportunistic::view::{GameView, SolvedGame};

    /// A game exercising every rule (MDP state = product state; sinks 11 and 12):
    /// - r0 `(W,L,L)`: `a` → a1 (outside Win(phi1): sigma_W keeps only its safe `y` → r3
    ///   `(L,L,L)`, so `a` is filtered), `b` → a4 (in Win(phi1), uniform: r2 or r5), `c` → r5;
    /// - r2 `(W,W,W)`; r3 `(L,L,L)`: `a` → r3, `b` → r9, `c` → a10 (stuck adversary);
    /// - r5 `(W,W,L)`: `a` → a6, which goes to a7 or r8 (a7 then to r2 or r5): a chain;
    ///   `b` → r3 is filtered;
    /// - r8 `(L,W,L)`; r9 `(L,L,L)` stuck; a10 stuck; stop(phi1) 11; stop(best) 12.
    pub(crate) fn game() -> ToyGame {
        let mut g = ToyGame::new(&["a", "b", "c", "x", "y"]);
        let r0 = g.state(true, "WLL", 2);
        let a1 = g.state(false, "LLL", 0);
        let r2 = g.state(true, "WWW", 0);
        let r3 = g.state(true, "LLL", 0);
        let a4 = g.state(false, "WLL", 1);
        // A target of phi1 and phi2 (not of phi), so that stopping there satisfies phi1 at once.
        let r5 = g.state(true, "WWL", 0);
        let a6 = g.state(false, "WWL", 1);
        let a7 = g.state(false, "WLL", 1);
        let r8 = g.state(true, "LWL", 0);
        let r9 = g.state(true, "LLL", 0);
        let a10 = g.state(false, "WWW", 0);
        for (from, action, to) in [
            (r0, "a", a1),
            (r0, "b", a4),
            (r0, "c", r5),
            (a1, "x", r2),
            (a1, "y", r3),
            (r3, "a", r3),
            (r3, "b", r9),
            (r3, "c", a10),
            (a4, "x", r2),
            (a4, "y", r5),
            (r5, "a", a6),
            (r5, "b", r3),
            (a6, "x", a7),
            (a6, "y", r8),
            (a7, "x", r2),
            (a7, "y", r5),
        ] {
            g.edge(from, action, to);
        }
        g
    }

    pub(crate) fn build(g: &ToyGame) -> HypergameMdp {
        let adversary = AdversaryModel::new(g, &SigmaL::Uniform).unwrap();
        HypergameMdp::build(g, &adversary, Risk::Paper).unwrap()
    }

    type Choices = Vec<(String, Vec<(u32, f64)>)>;

    /// The choices of MDP state `s`, with the targets as numbers.
    fn choices(mdp: &Mdp, s: u32) -> Choices {
        mdp.choices(ms(s))
            .map(|c| {
                let successors = mdp.successors(c).map(|(t, p)| (t.as_u32(), p));
                (mdp.action_name(c).to_string(), successors.collect())
            })
            .collect()
    }

    fn expect(list: &[(&str, &[(u32, f64)])]) -> Choices {
        list.iter()
            .map(|(a, d)| (a.to_string(), d.to_vec()))
            .collect()
    }

    #[test]
    fn choices_stop_and_absorbing_states_follow_the_win_labels() {
        let g = game();
        let built = build(&g);
        let mdp = built.mdp();
        assert_eq!(mdp.num_states(), 13);
        assert_eq!(mdp.initial(), ms(0));
        assert_eq!(
            choices(mdp, 0),
            expect(&[
                ("b", &[(4, 1.0)]),
                ("c", &[(5, 1.0)]),
                ("stop", &[(11, 1.0)])
            ])
        );
        // Chance nodes: sigma_W in a1 (only the safe y), sigma_L uniform in a4, a6, a7.
        assert_eq!(choices(mdp, 1), expect(&[(CHANCE, &[(3, 1.0)])]));
        assert_eq!(
            choices(mdp, 2 + 2),
            expect(&[(CHANCE, &[(2, 0.5), (5, 0.5)])])
        );
        assert_eq!(
            choices(mdp, 3),
            expect(&[("a", &[(3, 1.0)]), ("b", &[(9, 1.0)]), ("c", &[(10, 1.0)])])
        );
        assert_eq!(
            choices(mdp, 5),
            expect(&[("a", &[(6, 1.0)]), ("stop", &[(12, 1.0)])])
        );
        assert_eq!(choices(mdp, 6), expect(&[(CHANCE, &[(7, 0.5), (8, 0.5)])]));
        // Arena actions are moves; stop and the adversary's chance moves are instant.
        let instant: Vec<&str> = mdp
            .all_choices()
            .filter(|&c| mdp.is_instant(c))
            .map(|c| mdp.action_name(c))
            .collect();
        assert_eq!(instant, ["stop", CHANCE, CHANCE, "stop", CHANCE, CHANCE]);
        let payoffs: Vec<Option<f64>> = mdp.states().map(|s| mdp.payoff(s)).collect();
        let (r, r2, r1) = (Some(300.0), Some(100.0), Some(200.0));
        assert_eq!(
            payoffs,
            [
                None,
                None,
                r,
                None,
                None,
                None,
                None,
                None,
                r2,
                Some(0.0),
                r,
                r1,
                r1
            ]
        );
        assert_eq!(built.state_name(&g, ms(0)), "h0");
        assert_eq!(built.state_name(&g, ms(11)), "stop(phi1)");
        assert_eq!(built.state_name(&g, ms(12)), "stop(best)");
        assert_eq!(
            (
                built.node(hs(5)),
                built.product_state(ms(5)),
                built.product_state(ms(11))
            ),
            (ms(5), Some(hs(5)), None)
        );
    }

    #[test]
    fn sizes_and_values_match_the_hand_computation() {
        let g = game();
        let built = build(&g);
        let solution = solve(built.mdp(), &SolveOptions::default()).unwrap();
        // r5: stop pays 200 at once; `a` pays V(a6) = 0.5 V(a7) + 0.5 · 100 with
        // V(a7) = 0.5 · 300 + 0.5 V(r5): 175 if V(r5) = 200, so stop. r0: `b` pays
        // 0.5 · 300 + 0.5 · 200 = 250. r3: `c` reaches the stuck adversary: 300.
        for (s, v) in [
            (0, 250.0),
            (3, 300.0),
            (5, 200.0),
            (7, 250.0),
            (6, 175.0),
            (9, 0.0),
        ] {
            let value = solution.value(ms(s));
            assert!(
                value.lower <= v + 1e-9 && v - 1e-9 <= value.upper,
                "state {s}: {value:?}"
            );
        }
        assert_eq!(
            built.mdp().action_name(solution.policy(ms(0)).unwrap()),
            "b"
        );
        assert_eq!(
            built.sizes(&g, &solution),
            MdpSizes {
                robot_states: 6,
                absorbing: 2,
                with_opportunity: 3,
                without_opportunity: 1,
                above_guarantee: None,
                stuck: 3,
                chance_nodes: 4,
                states: 13,
                choices: 12,
                transitions: 15,
            }
        );
    }

    #[test]
    fn arena_actions_are_found_through_the_mdp_action_even_when_named_like_the_chance_move() {
        let g = game();
        let built = build(&g);
        let mdp = built.mdp();
        let actions: Vec<Option<&str>> = mdp
            .all_choices()
            .map(|c| built.arena_action(c).map(|a| g.action_name(a)))
            .collect();
        let names: Vec<Option<&str>> = mdp
            .all_choices()
            .map(|c| (!mdp.is_instant(c)).then(|| mdp.action_name(c)))
            .collect();
        assert_eq!(actions, names);
        // r0 --adversary--> a1 --x--> r2 (W,W,W): the arena action shares the chance move's
        // MDP action id, and only the move is an arena action.
        let mut g = ToyGame::new(&["x", CHANCE]);
        let r0 = g.state(true, "LLL", 0);
        let a1 = g.state(false, "LLL", 0);
        let r2 = g.state(true, "WWW", 0);
        g.edge(r0, CHANCE, a1);
        g.edge(a1, "x", r2);
        let built = build(&g);
        let mdp = built.mdp();
        let (go, chance) = (mdp.choices(ms(0)).start(), mdp.choices(ms(1)).start());
        assert_eq!(mdp.action(go), mdp.action(chance));
        assert_eq!(built.arena_action(go), Some(1));
        assert_eq!(built.arena_action(chance), None);
    }

    /// The successors of adversary state `h` that the adversary model gives a positive
    /// probability, with it, in edge order.
    fn adversary_moves(
        game: &ToyGame,
        adversary: &AdversaryModel,
        h: HState,
    ) -> Vec<(HState, f64)> {
        let mut probabilities = Vec::new();
        adversary.distribution(game, h, &mut probabilities);
        game.edges(h)
            .zip(probabilities)
            .filter(|&(_, p)| p > 0.0)
            .map(|((_, t), p)| (t, p))
            .collect()
    }

    /// The moves that can happen from `h` (docs/semantics.md §8.5): every robot action, and the
    /// adversary's actions of positive probability.
    fn possible_moves(game: &ToyGame, adversary: &AdversaryModel, h: HState) -> Vec<HState> {
        if game.is_robot(h) {
            return game.edges(h).map(|(_, t)| t).collect();
        }
        let moves = adversary_moves(game, adversary, h);
        moves.into_iter().map(|(t, _)| t).collect()
    }

    /// The chance move of adversary state `h` as an MDP distribution (MDP state `h` is product
    /// state `h`).
    fn chance_distribution(
        game: &ToyGame,
        adversary: &AdversaryModel,
        h: HState,
    ) -> Vec<(MdpState, f64)> {
        let moves = adversary_moves(game, adversary, h);
        moves
            .into_iter()
            .map(|(t, p)| (ms(t.as_u32()), p))
            .collect()
    }

    /// Where the play may next be decided or ended, having entered `t`: `t` itself if it is a
    /// robot state or a stuck adversary state, else the first such states reached through the
    /// adversary's moves of positive probability (none for a closed set of chance nodes).
    /// Depth-first, each state once.
    fn next_stops(game: &ToyGame, adversary: &AdversaryModel, t: HState) -> Vec<HState> {
        let stops = |u: HState| game.is_robot(u) || game.edges(u).next().is_none();
        let (mut seen, mut stack, mut found) = (vec![t], vec![t], Vec::new());
        while let Some(u) = stack.pop() {
            if stops(u) {
                found.push(u);
                continue;
            }
            for v in possible_moves(game, adversary, u) {
                if !seen.contains(&v) {
                    seen.push(v);
                    stack.push(v);
                }
            }
        }
        found
    }

    /// Every state reachable from `h` (`h` included) through the moves that can happen.
    fn reachable(game: &ToyGame, adversary: &AdversaryModel, h: HState) -> Vec<HState> {
        let (mut seen, mut next) = (vec![h], 0);
        while next < seen.len() {
            for v in possible_moves(game, adversary, seen[next]) {
                if !seen.contains(&v) {
                    seen.push(v);
                }
            }
            next += 1;
        }
        seen
    }

    /// The sets of the game's sub-tasks, by mask (`1..2^k`).
    fn sets(game: &ToyGame) -> Vec<TaskSet> {
        let k = game.payoffs().num_tasks();
        (1..1u8 << k).map(TaskSet).collect()
    }

    /// `gr(h)` by its definition (§8.4): the largest payoff of a set whose region holds `h`, 0
    /// when none does.
    fn guarantee_by_definition(game: &ToyGame, h: HState) -> f64 {
        sets(game)
            .into_iter()
            .filter(|&set| game.wins(set, h))
            .map(|set| game.payoffs().get(set))
            .fold(0.0, f64::max)
    }

    /// The preferred set of robot state `h` (§8.4): among the sets whose region holds `h`, the
    /// one of largest payoff, then of fewer sub-tasks, then whose members come first.
    fn preferred_set(game: &ToyGame, h: HState) -> TaskSet {
        let members =
            |set: TaskSet| -> Vec<u8> { (0..8).filter(|i| set.0 & (1 << i) != 0).collect() };
        let mut best: Option<TaskSet> = None;
        for set in sets(game).into_iter().filter(|&set| game.wins(set, h)) {
            let better = match best {
                None => true,
                Some(b) => {
                    let (r, rb) = (game.payoffs().get(set), game.payoffs().get(b));
                    r > rb
                        || (r == rb && members(set).len() < members(b).len())
                        || (r == rb
                            && members(set).len() == members(b).len()
                            && members(set) < members(b))
                }
            };
            if better {
                best = Some(set);
            }
        }
        best.expect("a robot state of positive guarantee wins a set")
    }

    /// The level of a payoff (§8.5): how many distinct values of `{0} ∪ {r(T)}` lie below it.
    fn level_of(game: &ToyGame, value: f64) -> usize {
        let mut below: Vec<f64> = Vec::new();
        let values =
            std::iter::once(0.0).chain(sets(game).into_iter().map(|set| game.payoffs().get(set)));
        for v in values {
            if v < value && !below.contains(&v) {
                below.push(v);
            }
        }
        below.len()
    }

    /// The paper's MDP built from docs/semantics.md §6.3 alone, state by state with an
    /// [`MdpBuilder`] (the adversary's moves and the next robot states searched here, naively):
    /// what the chunked build must equal in the paper's form.
    fn paper_by_definition(
        game: &ToyGame,
        adversary: &AdversaryModel,
        payoffs: Payoffs,
    ) -> Result<HypergameMdp, BuildError> {
        let n = game.num_states();
        let (mut builder, actions, arena_actions) = builder_with_actions(game)?;
        let (stop, chance) = (0, 1);
        let label = |h: HState| [0b01, 0b10, 0b11].map(|mask| game.wins(TaskSet(mask), h));
        let losing = |h: HState| game.is_robot(h) && label(h) == [false, false, false];
        // Risky: the next robot state after entering `t` may be (L,L,L).
        let risky = |t: HState| next_stops(game, adversary, t).into_iter().any(losing);
        let mut commits = BitSet::new();
        for h in game.states() {
            let stuck = game.edges(h).next().is_none();
            if !game.is_robot(h) {
                if stuck {
                    builder.add_absorbing_state(payoffs.r())?;
                } else {
                    builder.add_decision_state()?;
                    builder.add_instant_choice(chance, &chance_distribution(game, adversary, h))?;
                }
                continue;
            }
            match label(h) {
                [_, _, true] => {
                    commits.insert(h.index());
                    builder.add_absorbing_state(payoffs.r())?;
                }
                [false, true, false] => {
                    commits.insert(h.index());
                    builder.add_absorbing_state(payoffs.r2())?;
                }
                [false, false, false] if stuck => {
                    builder.add_absorbing_state(0.0)?;
                }
                [phi1, phi2, _] => {
                    builder.add_decision_state()?;
                    for (a, t) in game.edges(h) {
                        if (phi1 || phi2) && risky(t) {
                            continue;
                        }
                        builder.add_choice(actions[a as usize], &[(ms(t.as_u32()), 1.0)])?;
                    }
                    if phi1 {
                        let sink = MdpState::new(n + usize::from(phi2));
                        builder.add_instant_choice(stop, &[(sink, 1.0)])?;
                    }
                }
            }
        }
        let (r1, r2) = (payoffs.r1(), payoffs.r2());
        let sinks = [r1, r1.max(r2)].into_iter();
        finish(builder, sinks, game, arena_actions, commits)
    }

    /// The general MDP built from docs/semantics.md §8.5 alone, state by state with an
    /// [`MdpBuilder`]: the guarantees, preferred sets and levels from their definitions, the
    /// greatest reachable level and the next robot states by naive searches, sharing nothing
    /// with the build but the builder: what the chunked build must equal in the general form.
    fn general_by_definition(
        game: &ToyGame,
        adversary: &AdversaryModel,
        risk: Risk,
    ) -> Result<HypergameMdp, BuildError> {
        let n = game.num_states();
        let all = game
            .payoffs()
            .get(TaskSet((1 << game.payoffs().num_tasks()) - 1));
        let (mut builder, actions, arena_actions) = builder_with_actions(game)?;
        let (stop, chance) = (0, 1);
        let stops = |h: HState| game.is_robot(h) || game.edges(h).next().is_none();
        // A robot state's level is its guarantee's, a stuck adversary state's that of r(all).
        let level = |h: HState| {
            if game.is_robot(h) {
                level_of(game, guarantee_by_definition(game, h))
            } else {
                level_of(game, all)
            }
        };
        let mut commits = BitSet::new();
        for h in game.states() {
            let stuck = game.edges(h).next().is_none();
            if !game.is_robot(h) {
                if stuck {
                    builder.add_absorbing_state(all)?;
                } else {
                    builder.add_decision_state()?;
                    builder.add_instant_choice(chance, &chance_distribution(game, adversary, h))?;
                }
                continue;
            }
            let own = level(h);
            let greatest = reachable(game, adversary, h)
                .into_iter()
                .filter(|&u| stops(u))
                .map(level)
                .max();
            // Absorbing when nothing better than settling can ever come.
            if greatest == Some(own) {
                commits.insert(h.index());
                builder.add_absorbing_state(guarantee_by_definition(game, h))?;
                continue;
            }
            builder.add_decision_state()?;
            for (a, t) in game.edges(h) {
                let next: Vec<usize> = next_stops(game, adversary, t)
                    .into_iter()
                    .map(level)
                    .collect();
                let allowed = match risk {
                    Risk::Paper => own == 0 || next.iter().all(|&l| l > 0),
                    Risk::Strict => next.iter().all(|&l| l >= own),
                    Risk::Neutral => true,
                };
                if allowed {
                    builder.add_choice(actions[a as usize], &[(ms(t.as_u32()), 1.0)])?;
                }
            }
            if own > 0 {
                let sink = MdpState::new(n + preferred_set(game, h).0 as usize - 1);
                builder.add_instant_choice(stop, &[(sink, 1.0)])?;
            }
        }
        let sinks: Vec<f64> = sets(game)
            .into_iter()
            .map(|set| game.payoffs().get(set))
            .collect();
        finish(builder, sinks.into_iter(), game, arena_actions, commits)
    }

    /// The builds from the definitions' last steps: the stop sinks paying `sinks`, h0 initial.
    fn finish(
        mut builder: MdpBuilder,
        sinks: impl Iterator<Item = f64>,
        game: &ToyGame,
        arena_actions: Vec<u32>,
        commits: BitSet,
    ) -> Result<HypergameMdp, BuildError> {
        for payoff in sinks {
            builder.add_absorbing_state(payoff)?;
        }
        builder.set_initial(ms(game.initial().as_u32()));
        Ok(HypergameMdp {
            mdp: builder.build()?,
            arena_actions,
            commits,
            sinks: sink_names(game),
            num_product_states: game.num_states(),
        })
    }

    /// An [`MdpBuilder`] with `stop` (0), the chance move (1) and the game's arena actions;
    /// the MDP action id of each arena action, and the arena action of each MDP action.
    fn builder_with_actions(
        game: &ToyGame,
    ) -> Result<(MdpBuilder, Vec<u32>, Vec<ActionId>), BuildError> {
        let mut builder = MdpBuilder::new();
        builder.action(STOP)?;
        builder.action(CHANCE)?;
        let (actions, arena_actions) = action_ids(game.arena(), |name| builder.action(name))?;
        Ok((builder, actions, arena_actions))
    }

    /// A random game of `states` states: random owners and (possible) labels, up to four
    /// edges per state over actions that include the chance move's name, duplicate targets
    /// among them.
    fn random_game(rng: &mut ChaCha8Rng, states: u32) -> ToyGame {
        let mut g = ToyGame::new(&["a", "b", CHANCE, "c"]);
        let labels = ["LLL", "WLL", "WWL", "LWL", "WWW"];
        for _ in 0..states {
            let robot = rng.next_u32() & 1 == 0;
            let label = labels[rng.next_u32() as usize % labels.len()];
            g.state(robot, label, 1);
        }
        for h in 0..states {
            for _ in 0..rng.next_u32() % 5 {
                let action = ["a", "b", CHANCE, "c"][rng.next_u32() as usize % 4];
                let edges = &g.edges[h as usize];
                // At most one edge per action, as in an arena.
                if edges.iter().any(|&(a, _)| g.actions[a as usize] == action) {
                    continue;
                }
                let to = rng.next_u32() % states;
                g.edge(hs(h), action, hs(to));
            }
        }
        g.initial = hs(rng.next_u32() % states);
        g
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]

        /// The chunked build, with any chunk size and on one thread or the pool, gives the MDP
        /// (field by field) built from the definitions of the game's form.
        #[test]
        fn chunked_build_equals_the_builders(
            seed: u64,
            states in 1u32..60,
            random_sigma: bool,
            equal_payoffs: bool,
            general: bool,
            risk in 0usize..3,
        ) {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let payoffs = if equal_payoffs {
                Payoffs::new(5.0, 5.0, 10.0).unwrap()
            } else {
                Payoffs::default()
            };
            let mut g = random_game(&mut rng, states).with_payoffs(payoffs);
            let sigma = if random_sigma { SigmaL::Random { seed } } else { SigmaL::Uniform };
            let adversary = AdversaryModel::new(&g, &sigma).unwrap();
            let (risk, expected) = if general {
                g.presentation = Presentation::general(g.names().to_vec());
                let risk = [Risk::Paper, Risk::Strict, Risk::Neutral][risk];
                (risk, general_by_definition(&g, &adversary, risk))
            } else {
                (Risk::Paper, paper_by_definition(&g, &adversary, payoffs))
            };
            let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
            for chunk in [1, 2, 3, 7, states as usize, CHUNK] {
                let build = || {
                    let meter = &mut Meter::unobserved(Stage::MdpBuild);
                    HypergameMdp::build_chunked(&g, &adversary, risk, meter, chunk)
                };
                proptest::prop_assert_eq!(&build(), &expected, "chunk {}", chunk);
                proptest::prop_assert_eq!(&one.install(build), &expected, "chunk {}", chunk);
            }
        }
    }

    #[test]
    fn adversary_cycles_are_chance_structures_and_closed_ones_are_worth_zero() {
        // a7 may now also go back to a6 (`a`): a cycle a6 → a7 → a6 the adversary leaves.
        let mut g = game();
        g.edge(hs(7), "a", hs(6));
        let built = build(&g);
        assert_eq!(
            choices(built.mdp(), 7),
            expect(&[(CHANCE, &[(2, 1.0 / 3.0), (5, 1.0 / 3.0), (6, 1.0 / 3.0)])])
        );
        let solution = solve(built.mdp(), &SolveOptions::default()).unwrap();
        // V(a7) = (300 + V(r5) + V(a6)) / 3, V(a6) = (V(a7) + 100) / 2, V(r5) = 200 (stop):
        // V(a7) = (500 + V(a7)/2 + 50) / 3, so V(a7) = 220 and V(a6) = 160.
        for (s, v) in [(7, 220.0), (6, 160.0), (5, 200.0)] {
            let value = solution.value(ms(s));
            assert!(
                value.lower <= v + 1e-6 && v - 1e-6 <= value.upper,
                "{s}: {value:?}"
            );
        }
        // r0 → adversary p ⇄ q, never left: the run stays there and collects 0.
        let mut g = ToyGame::new(&["go", "x"]);
        let r0 = g.state(true, "LLL", 0);
        let p = g.state(false, "LLL", 0);
        let q = g.state(false, "LLL", 0);
        g.edge(r0, "go", p);
        g.edge(p, "x", q);
        g.edge(q, "x", p);
        let solution = solve(build(&g).mdp(), &SolveOptions::default()).unwrap();
        assert_eq!(solution.value(ms(0)).upper, 0.0);
    }

    #[test]
    fn adversary_first_arenas_and_impossible_labels() {
        let mut g = game();
        g.initial = hs(4);
        let built = build(&g);
        assert_eq!(built.mdp().initial(), ms(4));
        let solution = solve(built.mdp(), &SolveOptions::default()).unwrap();
        // a4: half r2 (300), half r5 (200).
        let value = solution.value(ms(4));
        assert!((value.lower - 250.0).abs() < 1e-6, "{value:?}");
    }

    mod general {
        //! Hand-solved games, one per rule: the three risk rules on one arena, a belief disjoint
        //! from every sub-task, and three sub-tasks with a bonus for all three.

        use super::*;
        use crate::arena::{Arena, ArenaBuilder, Owner, StateId};
        use crate::automata::testing::eventually;
        use crate::automata::{Dfa, Guard};
        use crate::game::{Belief, Hypergame, States, SubsetPayoffs, TaskRegions};
        use crate::mdp::solve::Discount;
        use crate::opportunistic::controller::{Controller, Decision};
        use crate::opportunistic::evaluate::ControllerEvaluation;
        use crate::opportunistic::view::{SolvedGame, SolvedHypergame};

        /// An arena from `(name, robot, labels)` states (the first is initial) and edges.
        fn arena(states: &[(&str, bool, &[&str])], edges: &[(&str, &str, &str)]) -> Arena {
            let mut b = ArenaBuilder::new();
            for &(name, robot, labels) in states {
                let owner = if robot {
                    Owner::Robot
                } else {
                    Owner::Adversary
                };
                b.add_state(name, owner, labels.iter().copied(), None)
                    .unwrap();
            }
            let id = |name: &str| StateId::new(states.iter().position(|s| s.0 == name).unwrap());
            for &(from, action, to) in edges {
                b.add_transition(id(from), action, id(to)).unwrap();
            }
            b.set_initial(StateId::new(0));
            b.build().unwrap()
        }

        struct Solved {
            value: f64,
            choices: Vec<String>,
            decision: Decision,
            guarantee: f64,
            label: String,
        }

        /// Solves the general MDP and returns what h0 looks like; the controller's evaluation is
        /// checked against the value on the way.
        #[allow(clippy::too_many_arguments)]
        fn solve_h0(
            arena: &Arena,
            tasks: &[&Dfa],
            psi: Option<&Dfa>,
            belief: Belief,
            payoffs: &SubsetPayoffs,
            risk: Risk,
            g: f64,
        ) -> Solved {
            let names: Vec<String> = ["A", "B", "C"][..tasks.len()]
                .iter()
                .map(|s| s.to_string())
                .collect();
            let mut automata: Vec<(&str, &Dfa)> = names
                .iter()
                .map(String::as_str)
                .zip(tasks.iter().copied())
                .collect();
            automata.extend(psi.map(|psi| ("psi", psi)));
            let product = Hypergame::with_automata(arena, &automata, States::Reachable).unwrap();
            let regions = TaskRegions::compute(&product, tasks.len(), belief);
            let presentation = Presentation::general(names.clone());
            let game = SolvedHypergame::new(&product, &regions, payoffs, &presentation);
            let adversary = AdversaryModel::new(&game, &SigmaL::Uniform).unwrap();
            let built = HypergameMdp::build(&game, &adversary, risk).unwrap();
            let options = SolveOptions {
                discount: Discount::new(g).unwrap(),
                ..SolveOptions::default()
            };
            let solution = solve(built.mdp(), &options).unwrap();
            let controller = Controller {
                game: &game,
                mdp: &built,
                solution: &solution,
            };
            let h0 = game.initial();
            let evaluation =
                ControllerEvaluation::new(&controller, &adversary, 1e-9, 10_000).unwrap();
            let (value, collected) = (solution.value(built.node(h0)), evaluation.value(h0));
            assert!(
                (value.lower - collected.lower).abs() < 1e-6,
                "{value:?} {collected:?}"
            );
            let mdp = built.mdp();
            Solved {
                value: value.lower,
                choices: mdp
                    .choices(built.node(h0))
                    .map(|c| mdp.action_name(c).to_string())
                    .collect(),
                decision: controller.decide(h0),
                guarantee: game.guarantee(h0),
                label: regions.label(h0).display(&names),
            }
        }

        /// ```text
        /// r0 (robot)  settle → ra {a}            (A for sure: guarantee r(A) = 100)
        ///             gamble → c: x, x2 → rab {a,b} (200), y → rz {} (0)
        ///             half   → d: x → rab (200), y → rb {b} (r(B) = 60)
        /// ```
        /// psi = true: the adversary believes it has lost everywhere and plays uniformly. At g = 1:
        /// settle and stop 100, gamble 2/3 · 200 = 133.3 (risks a state of guarantee 0), half
        /// 0.5 · 200 + 0.5 · 60 = 130 (risks a state of lower guarantee than 100).
        fn risky_arena() -> Arena {
            arena(
                &[
                    ("r0", true, &[]),
                    ("ra", true, &["a"]),
                    ("c", false, &[]),
                    ("d", false, &[]),
                    ("rab", true, &["a", "b"]),
                    ("rz", true, &[]),
                    ("rb", true, &["b"]),
                ],
                &[
                    ("r0", "settle", "ra"),
                    ("r0", "gamble", "c"),
                    ("r0", "half", "d"),
                    ("c", "x", "rab"),
                    ("c", "x2", "rab"),
                    ("c", "y", "rz"),
                    ("d", "x", "rab"),
                    ("d", "y", "rb"),
                ],
            )
        }

        #[test]
        fn each_risk_rule_keeps_the_actions_it_states() {
            let arena = risky_arena();
            let (a, b) = (eventually("a"), eventually("b"));
            let truth = Dfa::new(
                vec![],
                0,
                [0].into_iter().collect(),
                vec![vec![(Guard::always(), 0)]],
            )
            .unwrap();
            let names = ["A".to_string(), "B".to_string()];
            let payoffs =
                SubsetPayoffs::new(&[100.0, 60.0], &[(TaskSet(0b11), 200.0)], &names).unwrap();
            let solved = |risk, g| {
                solve_h0(
                    &arena,
                    &[&a, &b],
                    Some(&truth),
                    Belief::Automaton,
                    &payoffs,
                    risk,
                    g,
                )
            };
            let paper = solved(Risk::Paper, 1.0);
            assert_eq!(paper.guarantee, 100.0);
            assert_eq!(paper.label, "{A} {B} | psi W");
            assert_eq!(paper.choices, ["settle", "half", "stop"]);
            assert!((paper.value - 130.0).abs() < 1e-6);
            let half = arena.find_action("half").unwrap();
            assert!(
                matches!(paper.decision, Decision::Move { action, .. } if action == half),
                "{:?}",
                paper.decision
            );
            let strict = solved(Risk::Strict, 1.0);
            assert_eq!(strict.choices, ["settle", "stop"]);
            assert!((strict.value - 100.0).abs() < 1e-6);
            // settle and stop tie at g = 1; stop takes no move.
            assert_eq!(strict.decision, Decision::Stop(TaskSet(0b01)));
            let neutral = solved(Risk::Neutral, 1.0);
            assert_eq!(neutral.choices, ["settle", "gamble", "half", "stop"]);
            assert!((neutral.value - 400.0 / 3.0).abs() < 1e-6);
            // At g = 0.9 each move costs 10%: gamble 0.9 · 133.3 = 120, half 0.9 · 130 = 117,
            // settle 90, stop 100.
            let neutral = solved(Risk::Neutral, 0.9);
            assert!((neutral.value - 120.0).abs() < 1e-6);
            let strict = solved(Risk::Strict, 0.9);
            assert!((strict.value - 100.0).abs() < 1e-6);
        }

        /// ```text
        /// r0 (robot) go → c (adversary): toA → ra {a}, toZ → rz {z}, block → rx {}
        /// ```
        /// One sub-task A = F a (payoff 100). c is outside Win(A) and outside Win(psi) for either
        /// belief, so it plays sigma_W: uniform over the actions that keep the play outside Win(psi).
        /// Believing psi = F z (a decoy, disjoint from A): toA and block, so A comes with
        /// probability 1/2 (value 50). Believing psi = F a (correctly informed): toZ and block,
        /// value 0.
        #[test]
        fn a_belief_disjoint_from_the_task_is_an_opportunity() {
            let arena = arena(
                &[
                    ("r0", true, &[]),
                    ("c", false, &[]),
                    ("ra", true, &["a"]),
                    ("rz", true, &["z"]),
                    ("rx", true, &[]),
                ],
                &[
                    ("r0", "go", "c"),
                    ("c", "toA", "ra"),
                    ("c", "toZ", "rz"),
                    ("c", "block", "rx"),
                ],
            );
            let (a, z) = (eventually("a"), eventually("z"));
            let payoffs = SubsetPayoffs::new(&[100.0], &[], &["A".to_string()]).unwrap();
            let decoy = solve_h0(
                &arena,
                &[&a],
                Some(&z),
                Belief::Automaton,
                &payoffs,
                Risk::Paper,
                1.0,
            );
            assert_eq!(decoy.guarantee, 0.0);
            assert_eq!(decoy.label, "{} | psi L");
            assert!((decoy.value - 50.0).abs() < 1e-6);
            let informed = solve_h0(
                &arena,
                &[&a],
                None,
                Belief::Tasks(TaskSet(0b1)),
                &payoffs,
                Risk::Paper,
                1.0,
            );
            assert_eq!(informed.value, 0.0);
            assert_eq!(informed.decision, Decision::GiveUp);
        }

        /// ```text
        /// r0 (robot, {a}) go → d (adversary): x → rbc {b,c}, y → rb {b}
        /// ```
        /// Three sub-tasks F a, F b, F c, 100 each, 500 for all three; psi = F a. A holds from the
        /// start, so d is in Win(psi) and plays uniformly. r0 can force {A,B} (guarantee 200);
        /// `go` pays 0.5 · 500 + 0.5 · 200 = 350 under every risk rule (rb's guarantee is r0's).
        #[test]
        fn three_sub_tasks_with_a_bonus_for_all() {
            let arena = arena(
                &[
                    ("r0", true, &["a"]),
                    ("d", false, &[]),
                    ("rbc", true, &["b", "c"]),
                    ("rb", true, &["b"]),
                ],
                &[("r0", "go", "d"), ("d", "x", "rbc"), ("d", "y", "rb")],
            );
            let (a, b, c) = (eventually("a"), eventually("b"), eventually("c"));
            let names: Vec<String> = ["A", "B", "C"].iter().map(|s| s.to_string()).collect();
            let payoffs =
                SubsetPayoffs::new(&[100.0, 100.0, 100.0], &[(TaskSet(0b111), 500.0)], &names)
                    .unwrap();
            for risk in [Risk::Paper, Risk::Strict, Risk::Neutral] {
                let solved = solve_h0(
                    &arena,
                    &[&a, &b, &c],
                    None,
                    Belief::Tasks(TaskSet(0b001)),
                    &payoffs,
                    risk,
                    1.0,
                );
                assert_eq!(solved.label, "{A,B} | psi W");
                assert_eq!(solved.guarantee, 200.0);
                assert_eq!(solved.choices, ["go", "stop"]);
                assert!((solved.value - 350.0).abs() < 1e-6, "{risk:?}");
                assert!(matches!(solved.decision, Decision::Move { .. }));
            }
        }
    }
}
