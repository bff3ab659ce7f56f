//! Runs of the controller against the adversary model (docs/semantics.md §7).
//!
//! A run starts in h0. Until it commits, the robot follows the controller's [`Steps::step`]; the
//! adversary draws its action from the [`AdversaryModel`]. After committing to a set of
//! sub-tasks it plays that set's reactive strategy until every sub-task of the set is satisfied
//! (a target state of their DFAs), or a stuck state ends the play. A run also ends when
//! `max_steps` moves (of either player) have been made. Before committing, a run that enters a
//! state of value 0 ends at once as `none`: nothing can be gained from there.
//!
//! Payoffs follow the MDP's convention exactly, so that the mean payoff estimates the value of
//! h0: a run that commits to set `T` after `k` robot moves (`stop` is not a move) and then
//! satisfies it pays `r(T) · g^k`; a run that gives up, or hits the step bound, pays 0. A run
//! that meets a stuck adversary ends with its own outcome and pays what the attractor credits it
//! with: the committed set's payoff, or that of all sub-tasks before committing. Because of the
//! step bound, the estimate is biased downwards by the probability of runs longer than the bound.
//!
//! Randomness: ChaCha8 seeded with the seed; one `u64` per adversary move, turned into a uniform
//! number in [0, 1) with 53 bits. The same inputs and seed give the same runs on every platform.
//! Runs and traces record states, sets and actions, never display names: reports name them.

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

use super::adversary::AdversaryModel;
use super::evaluate::{Plan, Step, Steps};
use super::presentation::Presentation;
use super::view::GameView;
use crate::arena::ActionId;
use crate::game::{HState, TaskSet};
use crate::stage::{Meter, Stage};

/// How many runs to simulate, from which seed, and how long a run may be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SimulationOptions {
    /// The number of runs.
    pub runs: u32,
    /// The seed of the random stream (ChaCha8).
    pub seed: u64,
    /// The most moves (of either player) a run may make before it ends as `step bound hit`.
    pub max_steps: u32,
}

pub use super::ending::Ending;

/// Outcome counts and the mean payoff with a 95% confidence interval (normal approximation:
/// mean ± 1.96 · s / √n, s the sample standard deviation).
#[derive(Clone, Debug, PartialEq)]
pub struct Simulation {
    /// The options the runs were made with.
    pub options: SimulationOptions,
    /// Per set of sub-tasks (indexed by its mask), the runs that committed to it and satisfied
    /// it.
    pub satisfied: Vec<u32>,
    /// The runs that met a stuck adversary.
    pub adversary_stuck: u32,
    /// The runs that gained nothing: they reached a state of value 0, or the strategy had no
    /// move.
    pub none: u32,
    /// The runs that hit the step bound.
    pub step_bound: u32,
    /// The mean payoff over the runs, an estimate of the value of h0.
    pub mean_payoff: f64,
    /// The lower end of the 95% confidence interval of the mean payoff.
    pub ci_low: f64,
    /// The upper end of the 95% confidence interval of the mean payoff.
    pub ci_high: f64,
}

impl Simulation {
    /// The runs per ending, in the order reports list them: the sets `presentation` lists
    /// ([`Presentation::outcome_sets`]), then `adversary stuck`, `none`, `step bound hit`.
    pub fn endings(&self, presentation: &Presentation) -> Vec<(Ending, u32)> {
        presentation
            .outcome_sets(&self.satisfied)
            .into_iter()
            .map(|set| (Ending::Satisfied(set), self.satisfied[set.0 as usize]))
            .chain([
                (Ending::AdversaryStuck, self.adversary_stuck),
                (Ending::None, self.none),
                (Ending::StepBound, self.step_bound),
            ])
            .collect()
    }
}

/// What a run did in one state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraceAction {
    /// An arena action (of either player).
    Move(ActionId),
    /// The robot's `stop`.
    Stop,
}

/// One step of a traced run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraceStep {
    /// The product state.
    pub state: HState,
    /// What was played here; `None` where the run ends or commits without moving.
    pub action: Option<TraceAction>,
    /// The set committed to so far.
    pub committed: Option<TaskSet>,
}

/// A traced run: its ending, payoff and steps from h0.
#[derive(Clone, Debug, PartialEq)]
pub struct Trace {
    /// How the run ended.
    pub ending: Ending,
    /// What it paid (see the module documentation).
    pub payoff: f64,
    /// Its steps, one per state visited (a state where the robot plays `stop` appears twice).
    pub steps: Vec<TraceStep>,
}

/// What a run reads of the game besides the controller's [`Steps`], whichever engine holds
/// it: the product's moves and the adversary's distribution.
pub trait Board {
    /// The initial product state.
    fn initial(&self) -> HState;
    /// Whether the robot moves in `h`.
    fn is_robot(&self, h: HState) -> bool;
    /// Fills `out` with the edges of `h` (action, successor), in edge order.
    fn edges(&self, h: HState, out: &mut Vec<(ActionId, HState)>);
    /// Fills `out` with the adversary's probability of each edge of adversary state `h`.
    fn distribution(&self, h: HState, out: &mut Vec<f64>);
}

/// A game with the adversary model its runs draw from: the explicit engine's [`Board`].
pub struct Against<'a, G> {
    /// The game.
    pub game: &'a G,
    /// The adversary.
    pub adversary: &'a AdversaryModel,
}

impl<G: GameView> Board for Against<'_, G> {
    fn initial(&self) -> HState {
        self.game.initial()
    }
    fn is_robot(&self, h: HState) -> bool {
        self.game.is_robot(h)
    }
    fn edges(&self, h: HState, out: &mut Vec<(ActionId, HState)>) {
        out.clear();
        out.extend(self.game.edges(h));
    }
    fn distribution(&self, h: HState, out: &mut Vec<f64>) {
        self.adversary.distribution(self.game, h, out);
    }
}

/// Simulates `options.runs` runs of `plan` with one RNG stream.
pub fn simulate<P: Plan>(
    plan: &P,
    adversary: &AdversaryModel,
    options: SimulationOptions,
) -> Simulation {
    simulate_metered(
        plan,
        adversary,
        options,
        &mut Meter::unobserved(Stage::Simulation),
    )
}

/// [`simulate`], reporting the runs made to `meter` (one after another: the runs share one
/// random stream, so they are not spread over threads).
pub fn simulate_metered<P: Plan>(
    plan: &P,
    adversary: &AdversaryModel,
    options: SimulationOptions,
    meter: &mut Meter<'_>,
) -> Simulation {
    let board = Against {
        game: plan.game(),
        adversary,
    };
    simulate_on(plan, &board, options, meter)
}

/// [`simulate_metered`] for any controller's [`Steps`] on any [`Board`].
pub fn simulate_on(
    plan: &impl Steps,
    board: &impl Board,
    options: SimulationOptions,
    meter: &mut Meter<'_>,
) -> Simulation {
    let mut simulation = Simulation {
        options,
        satisfied: vec![0; plan.num_goals()],
        adversary_stuck: 0,
        none: 0,
        step_bound: 0,
        mean_payoff: 0.0,
        ci_low: 0.0,
        ci_high: 0.0,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let (mut sum, mut sum_squares) = (0.0, 0.0);
    meter.set_total(u64::from(options.runs));
    for _ in 0..options.runs {
        meter.advance(1);
        let (ending, payoff) = run(plan, board, options.max_steps, &mut rng, None);
        *match ending {
            Ending::Satisfied(set) => &mut simulation.satisfied[set.0 as usize],
            Ending::AdversaryStuck => &mut simulation.adversary_stuck,
            Ending::None => &mut simulation.none,
            Ending::StepBound => &mut simulation.step_bound,
        } += 1;
        sum += payoff;
        sum_squares += payoff * payoff;
    }
    let n = f64::from(options.runs.max(1));
    let mean = sum / n;
    let variance = if options.runs > 1 {
        ((sum_squares - n * mean * mean) / (n - 1.0)).max(0.0)
    } else {
        0.0
    };
    let half_width = 1.96 * (variance / n).sqrt();
    simulation.mean_payoff = mean;
    simulation.ci_low = mean - half_width;
    simulation.ci_high = mean + half_width;
    simulation
}

/// One run of `plan` from the seed (the first run of [`simulate`] with that seed), recorded
/// state by state.
pub fn trace<P: Plan>(plan: &P, adversary: &AdversaryModel, seed: u64, max_steps: u32) -> Trace {
    let board = Against {
        game: plan.game(),
        adversary,
    };
    trace_on(plan, &board, seed, max_steps)
}

/// [`trace`] for any controller's [`Steps`] on any [`Board`].
pub fn trace_on(plan: &impl Steps, board: &impl Board, seed: u64, max_steps: u32) -> Trace {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut steps = Vec::new();
    let (ending, payoff) = run(plan, board, max_steps, &mut rng, Some(&mut steps));
    Trace {
        ending,
        payoff,
        steps,
    }
}

/// One random move, as every simulation, trace and play draws it: one `u64` of `rng` read as
/// a fraction `u` in [0, 1) (its top 53 bits), and the index of the first entry of positive
/// probability, in order, whose cumulative probability exceeds `u` (the last positive one
/// when rounding leaves the sum at or below `u`); None when no entry is positive. The draw
/// is made (the stream advances) either way.
pub fn draw(rng: &mut impl RngCore, probabilities: &[f64]) -> Option<usize> {
    let u = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    let mut cumulative = 0.0;
    let mut chosen = None;
    for (i, &p) in probabilities.iter().enumerate() {
        if p > 0.0 {
            chosen = Some(i);
            cumulative += p;
            if u < cumulative {
                break;
            }
        }
    }
    chosen
}

fn run(
    plan: &impl Steps,
    board: &impl Board,
    max_steps: u32,
    rng: &mut ChaCha8Rng,
    mut trace: Option<&mut Vec<TraceStep>>,
) -> (Ending, f64) {
    let g = plan.discount();
    let mut h = board.initial();
    // The goal committed to, with its payoff.
    let mut committed: Option<(usize, f64)> = None;
    let mut robot_moves = 0i32;
    let mut steps = 0u32;
    let (mut distribution, mut edges) = (Vec::new(), Vec::new());
    let mut record = |h: HState, action: Option<TraceAction>, committed: Option<(usize, f64)>| {
        if let Some(trace) = trace.as_deref_mut() {
            trace.push(TraceStep {
                state: h,
                action,
                committed: committed.map(|(goal, _)| TaskSet(goal as u8)),
            });
        }
    };
    let finish = |ending: Ending, committed: Option<(usize, f64)>, robot_moves: i32| {
        let payoff = match ending {
            Ending::None | Ending::StepBound => 0.0,
            _ => committed.map_or(plan.stuck_payoff(), |(_, payoff)| payoff) * g.powi(robot_moves),
        };
        (ending, payoff)
    };
    loop {
        if let Some((goal, _)) = committed
            && plan.is_goal_target(goal, h)
        {
            record(h, None, committed);
            return finish(
                Ending::Satisfied(TaskSet(goal as u8)),
                committed,
                robot_moves,
            );
        }
        if steps >= max_steps {
            record(h, None, committed);
            return finish(Ending::StepBound, committed, robot_moves);
        }
        let next = if board.is_robot(h) {
            match committed {
                Some((goal, _)) => plan.goal_move(goal, h),
                None => match plan.step(h) {
                    Step::Move { action, successor } => {
                        robot_moves += 1;
                        Some((action, successor))
                    }
                    Step::Commit { goal, payoff, stop } => {
                        if stop {
                            record(h, Some(TraceAction::Stop), committed);
                        }
                        committed = Some((goal, payoff));
                        continue;
                    }
                    Step::GiveUp => None,
                },
            }
        } else {
            board.edges(h, &mut edges);
            if edges.is_empty() {
                record(h, None, committed);
                return finish(Ending::AdversaryStuck, committed, robot_moves);
            } else if committed.is_none() && plan.is_worthless(h) {
                None
            } else {
                board.distribution(h, &mut distribution);
                draw(rng, &distribution).map(|i| edges[i])
            }
        };
        let Some((action, successor)) = next else {
            record(h, None, committed);
            return finish(Ending::None, committed, robot_moves);
        };
        record(h, Some(TraceAction::Move(action)), committed);
        h = successor;
        steps += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::solve::{Discount, Solution, SolveOptions, solve};
    use crate::opportunistic::adversary::SigmaL;
    use crate::opportunistic::build::{HypergameMdp, Risk};
    use crate::opportunistic::controller::Controller;
    use crate::opportunistic::view::testing::{ToyGame, hs};

    /// r0 `(W,L,L)` plays `a` to adversary a1 (in Win(phi1), uniform), which moves `x` to r2
    /// (`(W,W,W)`, a target of phi) or `y` to r3 (`(W,L,L)`, a target of phi1, only `stop`).
    /// With g = 0.9: `a` is worth 0.9 · (0.5 · 300 + 0.5 · 200) = 225 > stop (200, at once).
    fn coin_game() -> ToyGame {
        let mut g = ToyGame::new(&["a", "x", "y"]);
        let r0 = g.state(true, "WLL", 1);
        let a1 = g.state(false, "WLL", 1);
        let r2 = g.state(true, "WWW", 0);
        let r3 = g.state(true, "WLL", 0);
        g.edge(r0, "a", a1);
        g.edge(a1, "x", r2);
        g.edge(a1, "y", r3);
        g
    }

    /// The controller of a solved toy game, with the default payoffs.
    fn controller<'a>(
        g: &'a ToyGame,
        built: &'a HypergameMdp,
        solution: &'a Solution,
    ) -> Controller<'a, ToyGame> {
        Controller {
            game: g,
            mdp: built,
            solution,
        }
    }

    fn solved(g: &ToyGame, discount: f64) -> (HypergameMdp, Solution, AdversaryModel) {
        let adversary = AdversaryModel::new(g, &SigmaL::Uniform).unwrap();
        let built = HypergameMdp::build(g, &adversary, Risk::Paper).unwrap();
        let options = SolveOptions {
            discount: Discount::new(discount).unwrap(),
            ..SolveOptions::default()
        };
        let solution = solve(built.mdp(), &options).unwrap();
        (built, solution, adversary)
    }

    #[test]
    fn each_run_follows_one_draw_and_pays_the_discounted_payoff() {
        let g = coin_game();
        let (built, solution, adversary) = solved(&g, 0.9);
        assert!((solution.value(built.node(g.initial)).lower - 225.0).abs() < 1e-5);
        let controller = controller(&g, &built, &solution);
        let options = SimulationOptions {
            runs: 2000,
            seed: 11,
            max_steps: 100,
        };
        let report = simulate(&controller, &adversary, options);
        // Each run draws once, at a1: `x` (phi, 300 · 0.9) when the draw's top bit is 0,
        // else `y` then stop (phi1, 200 · 0.9: stop is not a move).
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let phi = (0..2000).filter(|_| rng.next_u64() >> 63 == 0).count() as u32;
        let mut satisfied = vec![0; 4];
        satisfied[TaskSet(0b11).0 as usize] = phi;
        satisfied[TaskSet(0b01).0 as usize] = 2000 - phi;
        assert_eq!(report.satisfied, satisfied);
        assert_eq!(
            (report.adversary_stuck, report.none, report.step_bound),
            (0, 0, 0)
        );
        let mean = (270.0 * f64::from(phi) + 180.0 * f64::from(2000 - phi)) / 2000.0;
        assert!((report.mean_payoff - mean).abs() < 1e-9);
        assert!(
            report.ci_low <= 225.0 && 225.0 <= report.ci_high,
            "{report:?}"
        );
        assert_eq!(report, simulate(&controller, &adversary, options));
    }

    #[test]
    fn a_draw_picks_the_entry_whose_cumulative_probability_passes_the_fraction() {
        // The fractions of the first draws of seed 3, read as the draw reads them.
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let fractions: Vec<f64> = (0..200)
            .map(|_| (rng.next_u64() >> 11) as f64 / 9_007_199_254_740_992.0)
            .collect();
        // Entries 0 and 2 are impossible; 1 has 0.25, 3 has 0.75.
        let probabilities = [0.0, 0.25, 0.0, 0.75];
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut seen = [0u32; 4];
        for &u in &fractions {
            let expected = if u < 0.25 { 1 } else { 3 };
            let chosen = draw(&mut rng, &probabilities);
            assert_eq!(chosen, Some(expected), "u = {u}");
            seen[expected] += 1;
        }
        assert!(seen[1] > 0 && seen[3] > 0, "{seen:?}");
        // A sum that rounding leaves below the fraction takes the last positive entry; no
        // positive entry, no move, and the stream advances all the same.
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        assert_eq!(draw(&mut rng, &[0.0, 1e-300, 0.0]), Some(1));
        assert_eq!(draw(&mut rng, &[0.0, 0.0]), None);
        assert_eq!(
            (rng.next_u64() >> 11) as f64 / 9_007_199_254_740_992.0,
            fractions[2]
        );
    }

    #[test]
    fn trace_records_moves_and_commitment() {
        let g = coin_game();
        let (built, solution, adversary) = solved(&g, 0.9);
        let controller = controller(&g, &built, &solution);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let heads = rng.next_u64() >> 63 == 0;
        let traced = trace(&controller, &adversary, 5, 100);
        let action = |name: &str| {
            let a = g.actions.iter().position(|x| x == name).unwrap() as ActionId;
            Some(TraceAction::Move(a))
        };
        let step = |h: u32, action: Option<TraceAction>, committed: Option<u8>| TraceStep {
            state: hs(h),
            action,
            committed: committed.map(TaskSet),
        };
        let mut expected = vec![step(0, action("a"), None)];
        if heads {
            expected.push(step(1, action("x"), None));
            expected.push(step(2, None, Some(0b11)));
            assert_eq!(
                (traced.ending, traced.payoff),
                (Ending::Satisfied(TaskSet(0b11)), 270.0)
            );
        } else {
            expected.push(step(1, action("y"), None));
            expected.push(step(3, Some(TraceAction::Stop), None));
            expected.push(step(3, None, Some(0b01)));
            assert_eq!(traced.ending, Ending::Satisfied(TaskSet(0b01)));
        }
        assert_eq!(traced.steps, expected);
    }

    #[test]
    fn a_stuck_adversary_ends_the_run_with_its_own_outcome() {
        // r0 `(W,W,W)` commits to phi at once and moves `a` to a1, which has no move: the run
        // ends as `adversary stuck` (not as phi satisfied) and pays r, the attractor's credit.
        let mut g = ToyGame::new(&["a"]);
        // As the attractor ranks them: the stuck adversary at rank 1, r0 at rank 2.
        let r0 = g.state(true, "WWW", 2);
        let a1 = g.state(false, "WWW", 1);
        g.edge(r0, "a", a1);
        let (built, solution, adversary) = solved(&g, 0.9);
        let controller = controller(&g, &built, &solution);
        let traced = trace(&controller, &adversary, 1, 10);
        assert_eq!(
            (traced.ending, traced.payoff),
            (Ending::AdversaryStuck, 300.0)
        );
        assert_eq!(traced.steps.len(), 2);
        assert_eq!(traced.steps[1].committed, Some(TaskSet(0b11)));
    }

    #[test]
    fn a_run_in_a_worthless_state_ends_at_once_and_pays_nothing() {
        let mut g = ToyGame::new(&["a"]);
        let r0 = g.state(true, "LLL", 0);
        g.edge(r0, "a", r0);
        let (built, solution, adversary) = solved(&g, 1.0);
        let controller = controller(&g, &built, &solution);
        let report = simulate(
            &controller,
            &adversary,
            SimulationOptions {
                runs: 3,
                seed: 0,
                max_steps: 7,
            },
        );
        // r0 is worth 0: the controller gives up there instead of walking to the step bound.
        assert_eq!(report.none, 3);
        assert_eq!(report.step_bound, 0);
        assert_eq!(
            (report.mean_payoff, report.ci_low, report.ci_high),
            (0.0, 0.0, 0.0)
        );
    }
}
