//! The hypergame MDP (DESIGN.md 3.6).
//!
//! MDP states: one per product state, with the product's numbers, then the two stop sinks
//! `stop(phi1)` (payoff r1) and `stop(best)` (payoff max(r1, r2)). Robot states are decision
//! nodes, adversary states *chance nodes*: one instant choice (named [`CHANCE`]) whose
//! distribution is the adversary model's, without its probability-0 edges. Chains, diamonds and
//! cycles of adversary states therefore cost one state each: nothing is enumerated along paths.
//! A set of adversary states that the model can never leave is an ordinary closed set of chance
//! nodes; the run stays out of the robot's control forever and collects 0, which is what the
//! solver computes for it (it cannot reach a payoff).
//!
//! By the win-label of a robot state:
//! - `(L,L,L)`: every action, no stop; with no enabled action, absorbing with payoff 0;
//! - `(W,L,L)`: the actions with probability 0 of reaching an `(L,L,L)` robot state next
//!   (directly, or through adversary states with positive probability: one backward search,
//!   [`least_next_level`] with level 0 for `(L,L,L)`), plus `stop` → `stop(phi1)`;
//! - `(W,W,L)`: likewise, plus `stop` → `stop(best)`;
//! - `(L,W,L)`: absorbing, payoff r2; `(W,W,W)`: absorbing, payoff r.
//!
//! Arena actions are moves (one robot move: discounted, counted as time); `stop` is instant: it
//! collects its payoff at once, like arriving in an absorbing state, so no robot state is worth
//! less than what it can settle for. A stuck adversary state ends the play; the attractor counts
//! it as won for every task, so it is absorbing with payoff r. An impossible label
//! (`Win(phi)` outside `Win(phi1) ∩ Win(phi2)`) is an error. The initial state may belong to
//! either player: if it is the adversary's, its value is the expectation over the adversary's
//! first move. Arena actions keep their names; `stop` is reserved.
//!
//! Cost: O(|H| + |edges|) time; the MDP has |H| + 2 states and at most one choice per product
//! edge plus one per robot state. The build goes through the product twice, by chunks of
//! consecutive states on the rayon pool: it counts each state's choices and transitions, then
//! writes them in arrays allocated once at their exact size (`MdpLayout`), so that its peak is
//! the MDP itself (about 53 bytes per product state on the gridworlds) plus a bit per state (the
//! risky successors); before that, the level search takes its own temporaries and frees them.
//! The MDP does not depend on the chunks or the threads.

use std::ops::Range;

use bit_set::BitSet;
use thiserror::Error;

use super::adversary::AdversaryModel;
use super::levels::least_next_level;
use super::model::{ActionNames, AddStates, ChoiceId, Counts, Mdp, MdpError, MdpLayout, MdpState};
use super::solve::Solution;
use super::view::{GameView, SolvedGame, win_label};
use crate::arena::ActionId;
use crate::game::{HState, Task, WinLabel};
use crate::index::Id;
use crate::stage::{Meter, Stage, Tally};

/// The reserved action name of the robot's decision to settle for a sub-task.
pub const STOP: &str = "stop";

/// The name of the single (instant) choice of a chance node: the adversary's move.
pub const CHANCE: &str = "adversary";

/// The payoffs of `phi1`, `phi2` and `phi`: positive, with r ≥ r1 + r2.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Payoffs {
    r1: f64,
    r2: f64,
    r: f64,
}

impl Payoffs {
    /// The payoffs of phi1, phi2 and phi; all positive and finite, with `r >= r1 + r2`
    /// (DESIGN.md 3.6), else [`BuildError::Payoffs`].
    pub fn new(r1: f64, r2: f64, r: f64) -> Result<Payoffs, BuildError> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !(positive(r1) && positive(r2) && positive(r) && r >= r1 + r2) {
            return Err(BuildError::Payoffs { r1, r2, r });
        }
        Ok(Payoffs { r1, r2, r })
    }

    /// The payoff of satisfying `goal`.
    pub fn get(self, goal: Task) -> f64 {
        match goal {
            Task::Phi1 => self.r1,
            Task::Phi2 => self.r2,
            Task::Phi => self.r,
        }
    }

    /// The sub-task a `stop` in `(W,W,L)` settles for: phi1 unless r2 pays strictly more.
    pub fn better_subtask(self) -> Task {
        if self.r2 > self.r1 {
            Task::Phi2
        } else {
            Task::Phi1
        }
    }
}

impl Default for Payoffs {
    /// The case study's payoffs.
    fn default() -> Self {
        Payoffs {
            r1: 200.0,
            r2: 100.0,
            r: 300.0,
        }
    }
}

/// Why the hypergame MDP cannot be built.
#[derive(Debug, Error, PartialEq)]
pub enum BuildError {
    /// Payoffs that are not positive and finite with `r >= r1 + r2`.
    #[error("payoffs must be positive with r >= r1 + r2 (got r1 = {r1}, r2 = {r2}, r = {r})")]
    Payoffs {
        /// The payoff of phi1 given.
        r1: f64,
        /// The payoff of phi2 given.
        r2: f64,
        /// The payoff of phi given.
        r: f64,
    },
    /// A robot state whose win-label the design rules out (`(W,L,W)`, `(L,W,W)`, `(L,L,W)`):
    /// the regions are inconsistent, a bug rather than an input error.
    #[error("state {state} has the impossible win-label {label}")]
    ImpossibleLabel {
        /// The state's name.
        state: String,
        /// Its win-label as printed.
        label: String,
    },
    /// The arena has an action named `stop`, the name of the MDP's own stop action.
    #[error("the arena action `stop` clashes with the reserved stop action")]
    ReservedAction,
    /// The MDP builder refused the model.
    #[error(transparent)]
    Mdp(#[from] MdpError),
}

/// How the MDP treats a robot state, by its win-label.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeKind {
    /// `(L,L,L)`.
    Losing,
    /// `(W,L,L)`.
    Phi1Only,
    /// `(W,W,L)`.
    BothSubtasks,
    /// `(L,W,L)`.
    Phi2Only,
    /// `(W,W,W)`.
    Phi,
}

/// The kind of robot state `h`; `None` for an impossible label.
pub fn node_kind(game: &impl SolvedGame, h: HState) -> Option<NodeKind> {
    match win_label(game, h) {
        WinLabel {
            phi: true,
            phi1: true,
            phi2: true,
        } => Some(NodeKind::Phi),
        WinLabel { phi: true, .. } => None,
        WinLabel {
            phi1: false,
            phi2: false,
            ..
        } => Some(NodeKind::Losing),
        WinLabel {
            phi1: true,
            phi2: false,
            ..
        } => Some(NodeKind::Phi1Only),
        WinLabel {
            phi1: true,
            phi2: true,
            ..
        } => Some(NodeKind::BothSubtasks),
        WinLabel {
            phi1: false,
            phi2: true,
            ..
        } => Some(NodeKind::Phi2Only),
    }
}

/// The hypergame MDP. MDP state `h` is product state `h`; the two stop sinks follow.
#[derive(Clone, Debug, PartialEq)]
pub struct HypergameMdp {
    mdp: Mdp,
    /// MDP action id → arena action (`u32::NONE` for `stop` and the chance move). A choice's
    /// arena action is found through its MDP action, so that nothing is kept per choice: moves
    /// are exactly the choices of arena actions (`stop` and chance choices are instant), which
    /// tells them apart even from an arena action named like the chance move.
    arena_actions: Vec<ActionId>,
}

/// The sizes reported for a solved hypergame MDP, in the paper's terms (DESIGN.md 3.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct MdpSizes {
    /// Decision nodes in the sense of the paper: every robot product state.
    pub robot_states: u32,
    /// Robot states labelled `(W,W,W)` or `(L,W,L)`.
    pub absorbing: u32,
    /// The other robot states of positive value.
    pub with_opportunity: u32,
    /// The remaining robot states (value 0). The three add up to `robot_states`.
    pub without_opportunity: u32,
    /// Robot states without an enabled action (also counted in the three above).
    pub stuck: u32,
    /// Adversary states that move (chance nodes); stuck ones are absorbing.
    pub chance_nodes: u32,
    /// The MDP's own number of states (the product states and two sinks).
    pub states: u32,
    /// The MDP's choices (the enabled actions of all its states, `stop` included).
    pub choices: u32,
    /// The MDP's transitions (the targets of all its choices).
    pub transitions: u32,
}

impl HypergameMdp {
    /// The hypergame MDP of `game` (DESIGN.md 3.6) with the adversary playing `adversary` and
    /// the payoffs `payoffs`: MDP state `h` is product state `h`, followed by the sinks
    /// `stop(phi1)` and `stop(best)`.
    pub fn build(
        game: &(impl SolvedGame + Sync),
        adversary: &AdversaryModel,
        payoffs: Payoffs,
    ) -> Result<HypergameMdp, BuildError> {
        let meter = &mut Meter::unobserved(Stage::MdpBuild);
        HypergameMdp::build_metered(game, adversary, payoffs, meter)
    }

    /// [`HypergameMdp::build`], reporting to `meter` the product states dealt with: each is
    /// counted, then written (the total is twice the product's states).
    pub fn build_metered(
        game: &(impl SolvedGame + Sync),
        adversary: &AdversaryModel,
        payoffs: Payoffs,
        meter: &mut Meter<'_>,
    ) -> Result<HypergameMdp, BuildError> {
        HypergameMdp::build_chunked(game, adversary, payoffs, meter, CHUNK)
    }

    /// [`HypergameMdp::build_metered`] with `chunk` product states per parallel job.
    fn build_chunked(
        game: &(impl SolvedGame + Sync),
        adversary: &AdversaryModel,
        payoffs: Payoffs,
        meter: &mut Meter<'_>,
        chunk: usize,
    ) -> Result<HypergameMdp, BuildError> {
        let n = game.num_states();
        let mut names = ActionNames::default();
        let stop = names.intern(STOP)?;
        let chance = names.intern(CHANCE)?;
        let arena = game.arena();
        let mut actions = Vec::with_capacity(arena.actions().len());
        let mut arena_actions = vec![u32::NONE; 2];
        for (a, name) in arena.actions().iter().enumerate() {
            if name == STOP {
                return Err(BuildError::ReservedAction);
            }
            let id = names.intern(name)?;
            if id as usize >= arena_actions.len() {
                arena_actions.resize(id as usize + 1, u32::NONE);
            }
            arena_actions[id as usize] = a as ActionId;
            actions.push(id);
        }
        // The next robot state is `(L,L,L)` with positive probability (level 0): a bit per
        // state is all the rules need of the levels.
        let risky: BitSet = least_next_level(game, adversary, |h| {
            u32::from(!matches!(kind(game, h), Ok(Some(NodeKind::Losing))))
        })
        .iter()
        .enumerate()
        .filter_map(|(h, &level)| (level == 0).then_some(h))
        .collect();
        let rules = Rules {
            game,
            adversary,
            payoffs,
            actions,
            stop,
            chance,
            risky,
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
        product_state(s, self.mdp.num_states() - 2)
    }

    /// The display name of MDP state `s`: its product state's, or `stop(phi1)`, `stop(best)`.
    pub fn state_name(&self, game: &impl SolvedGame, s: MdpState) -> String {
        match self.product_state(s) {
            Some(h) => game.state_name(h),
            None if s.index() + 2 == self.mdp.num_states() => "stop(phi1)".to_string(),
            None => "stop(best)".to_string(),
        }
    }

    /// The arena action of MDP choice `choice`; `None` for `stop` and chance choices.
    pub fn arena_action(&self, choice: ChoiceId) -> Option<ActionId> {
        if self.mdp.is_instant(choice) {
            return None;
        }
        self.arena_actions[self.mdp.action(choice) as usize].to_option()
    }

    /// The report's sizes of this MDP, with the robot states classified by `solution`'s values.
    pub fn sizes(&self, game: &impl SolvedGame, solution: &Solution) -> MdpSizes {
        count_sizes(&self.mdp, game, |h| match node_kind(game, h) {
            Some(NodeKind::Phi | NodeKind::Phi2Only) => RobotCategory::Absorbing,
            // Values fixed qualitatively to 0 have upper bound 0; every other value is positive.
            _ if solution.value(node(h)).upper > 0.0 => RobotCategory::WithOpportunity,
            _ => RobotCategory::WithoutOpportunity,
        })
    }
}

/// Product states per job of the build's parallel passes: enough that a job's overhead (a spawn,
/// a few buffers) is negligible, few enough that two cores share the work evenly.
const CHUNK: usize = 1 << 15;

/// The kind of product state `h`: `None` for an adversary state, an error for an impossible
/// label.
fn kind(game: &impl SolvedGame, h: HState) -> Result<Option<NodeKind>, BuildError> {
    if !game.is_robot(h) {
        return Ok(None);
    }
    node_kind(game, h)
        .map(Some)
        .ok_or_else(|| BuildError::ImpossibleLabel {
            state: game.state_name(h),
            label: win_label(game, h).to_string(),
        })
}

/// What decides the MDP's states: the rules of the module documentation, applied one product
/// state at a time.
struct Rules<'a, G> {
    game: &'a G,
    adversary: &'a AdversaryModel,
    payoffs: Payoffs,
    /// MDP action id per arena action.
    actions: Vec<u32>,
    stop: u32,
    chance: u32,
    /// The states whose next robot state may be `(L,L,L)`.
    risky: BitSet,
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
        let (game, payoffs) = (self.game, self.payoffs);
        let stuck = game.edges(h).next().is_none();
        match kind(game, h)? {
            None if stuck => out.add_absorbing_state(payoffs.r)?,
            None => {
                out.add_decision_state()?;
                let moves = chance_moves.of(game, self.adversary, h);
                out.add_choice(self.chance, moves, true)?;
            }
            Some(NodeKind::Phi) => out.add_absorbing_state(payoffs.r)?,
            Some(NodeKind::Phi2Only) => out.add_absorbing_state(payoffs.r2)?,
            Some(NodeKind::Losing) if stuck => out.add_absorbing_state(0.0)?,
            Some(kind) => {
                out.add_decision_state()?;
                let n = game.num_states();
                for (a, t) in game.edges(h) {
                    if kind != NodeKind::Losing && self.risky.contains(t.index()) {
                        continue;
                    }
                    out.add_choice(self.actions[a as usize], &[(node(t), 1.0)], false)?;
                }
                let sink = match kind {
                    NodeKind::Phi1Only => Some(MdpState::new(n)),
                    NodeKind::BothSubtasks => Some(MdpState::new(n + 1)),
                    _ => None,
                };
                if let Some(sink) = sink {
                    out.add_choice(self.stop, &[(sink, 1.0)], true)?;
                }
            }
        }
        Ok(())
    }

    /// Adds the two stop sinks, `stop(phi1)` and `stop(best)`.
    fn add_sinks(&self, out: &mut impl AddStates) -> Result<(), BuildError> {
        out.add_absorbing_state(self.payoffs.r1)?;
        out.add_absorbing_state(self.payoffs.r1.max(self.payoffs.r2))?;
        Ok(())
    }
}

/// How a report counts a robot state.
pub(crate) enum RobotCategory {
    Absorbing,
    WithOpportunity,
    WithoutOpportunity,
}

/// The sizes of an MDP built over `game` (MDP state h = product state h), each robot state
/// counted in the category `classify` gives it; stuck robot states are also counted on their
/// own, moving adversary states as chance nodes.
pub(crate) fn count_sizes(
    mdp: &Mdp,
    game: &impl GameView,
    mut classify: impl FnMut(HState) -> RobotCategory,
) -> MdpSizes {
    let mut sizes = MdpSizes {
        robot_states: 0,
        absorbing: 0,
        with_opportunity: 0,
        without_opportunity: 0,
        stuck: 0,
        chance_nodes: 0,
        states: mdp.num_states() as u32,
        choices: mdp.num_choices() as u32,
        transitions: mdp.num_transitions() as u32,
    };
    for h in game.states() {
        let stuck = game.edges(h).next().is_none();
        if !game.is_robot(h) {
            sizes.chance_nodes += u32::from(!stuck);
            continue;
        }
        sizes.robot_states += 1;
        sizes.stuck += u32::from(stuck);
        *match classify(h) {
            RobotCategory::Absorbing => &mut sizes.absorbing,
            RobotCategory::WithOpportunity => &mut sizes.with_opportunity,
            RobotCategory::WithoutOpportunity => &mut sizes.without_opportunity,
        } += 1;
    }
    sizes
}

/// The MDP state of product state `h` in both hypergame MDPs, which number the product states
/// first, in product order.
pub(crate) fn node(h: HState) -> MdpState {
    MdpState::from_u32(h.as_u32())
}

/// The product state of MDP state `s` of an MDP built over `num_product_states` product states
/// (see [`node`]); `None` for the states after them.
pub(crate) fn product_state(s: MdpState, num_product_states: usize) -> Option<HState> {
    (s.index() < num_product_states).then(|| HState::from_u32(s.as_u32()))
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
        game: &impl GameView,
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
    use crate::mdp::adversary::SigmaL;
    use crate::mdp::model::MdpBuilder;
    use crate::mdp::solve::{SolveOptions, solve};
    use crate::mdp::testing::ms;
    use crate::mdp::view::testing::{ToyGame, hs};

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
        HypergameMdp::build(g, &adversary, Payoffs::default()).unwrap()
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

    /// The MDP built the straightforward way, state by state with an [`MdpBuilder`] (the build
    /// before it was laid out from exact counts): what the chunked build must equal.
    fn build_with_builder(
        game: &ToyGame,
        adversary: &AdversaryModel,
        payoffs: Payoffs,
    ) -> Result<HypergameMdp, BuildError> {
        let n = game.num_states();
        let mut builder = MdpBuilder::new();
        let stop = builder.action(STOP)?;
        let chance = builder.action(CHANCE)?;
        let mut actions = Vec::new();
        let mut arena_actions = vec![u32::NONE; 2];
        for (a, name) in game.arena().actions().iter().enumerate() {
            if name == STOP {
                return Err(BuildError::ReservedAction);
            }
            let id = builder.action(name)?;
            if id as usize >= arena_actions.len() {
                arena_actions.resize(id as usize + 1, u32::NONE);
            }
            arena_actions[id as usize] = a as ActionId;
            actions.push(id);
        }
        let kinds = game
            .states()
            .map(|h| kind(game, h))
            .collect::<Result<Vec<_>, _>>()?;
        let next_level = least_next_level(game, adversary, |h| {
            u32::from(kinds[h.index()] != Some(NodeKind::Losing))
        });
        let mut chance_moves = ChanceMoves::default();
        for h in game.states() {
            let stuck = game.edges(h).next().is_none();
            match kinds[h.index()] {
                None if stuck => builder.add_absorbing_state(payoffs.r)?,
                None => {
                    let state = builder.add_decision_state()?;
                    builder.add_instant_choice(chance, chance_moves.of(game, adversary, h))?;
                    state
                }
                Some(NodeKind::Phi) => builder.add_absorbing_state(payoffs.r)?,
                Some(NodeKind::Phi2Only) => builder.add_absorbing_state(payoffs.r2)?,
                Some(NodeKind::Losing) if stuck => builder.add_absorbing_state(0.0)?,
                Some(kind) => {
                    let state = builder.add_decision_state()?;
                    for (a, t) in game.edges(h) {
                        if kind != NodeKind::Losing && next_level[t.index()] == 0 {
                            continue;
                        }
                        builder.add_choice(actions[a as usize], &[(node(t), 1.0)])?;
                    }
                    match kind {
                        NodeKind::Phi1Only => {
                            builder.add_instant_choice(stop, &[(MdpState::new(n), 1.0)])?;
                        }
                        NodeKind::BothSubtasks => {
                            builder.add_instant_choice(stop, &[(MdpState::new(n + 1), 1.0)])?;
                        }
                        _ => {}
                    }
                    state
                }
            };
        }
        builder.add_absorbing_state(payoffs.r1)?;
        builder.add_absorbing_state(payoffs.r1.max(payoffs.r2))?;
        builder.set_initial(node(game.initial()));
        Ok(HypergameMdp {
            mdp: builder.build()?,
            arena_actions,
        })
    }

    /// A random game of `states` states: random owners and labels (an impossible one with
    /// `impossible`), up to four edges per state over actions that include the chance move's
    /// name, duplicate targets among them.
    fn random_game(rng: &mut ChaCha8Rng, states: u32, impossible: bool) -> ToyGame {
        let mut g = ToyGame::new(&["a", "b", CHANCE, "c"]);
        let mut labels = vec!["LLL", "WLL", "WWL", "LWL", "WWW"];
        if impossible {
            labels.push("LLW");
        }
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
        /// (field by field) or the error of the straightforward build.
        #[test]
        fn chunked_build_equals_the_builders(
            seed: u64,
            states in 1u32..60,
            impossible: bool,
            random_sigma: bool,
            equal_payoffs: bool,
        ) {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let g = random_game(&mut rng, states, impossible);
            let sigma = if random_sigma { SigmaL::Random { seed } } else { SigmaL::Uniform };
            let adversary = AdversaryModel::new(&g, &sigma).unwrap();
            let payoffs = if equal_payoffs {
                Payoffs::new(5.0, 5.0, 10.0).unwrap()
            } else {
                Payoffs::default()
            };
            let expected = build_with_builder(&g, &adversary, payoffs);
            let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
            for chunk in [1, 2, 3, 7, states as usize, CHUNK] {
                let build = || {
                    let meter = &mut Meter::unobserved(Stage::MdpBuild);
                    HypergameMdp::build_chunked(&g, &adversary, payoffs, meter, chunk)
                };
                proptest::prop_assert_eq!(&build(), &expected, "chunk {}", chunk);
                proptest::prop_assert_eq!(&one.install(build), &expected, "chunk {}", chunk);
            }
        }
    }

    #[test]
    fn payoffs_are_checked() {
        assert!(Payoffs::new(1.0, 2.0, 3.0).is_ok());
        assert!(matches!(
            Payoffs::new(1.0, 2.0, 2.9),
            Err(BuildError::Payoffs { .. })
        ));
        assert!(Payoffs::new(0.0, 2.0, 3.0).is_err());
        assert!(Payoffs::new(f64::NAN, 2.0, 3.0).is_err());
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
        let mut g = game();
        g.ranks[9] = [None, None, Some(0)];
        let adversary = AdversaryModel::new(&g, &SigmaL::Uniform).unwrap();
        assert!(matches!(
            HypergameMdp::build(&g, &adversary, Payoffs::default()),
            Err(BuildError::ImpossibleLabel { .. })
        ));
    }
}
