//! Runs of the controller against the adversary model (DESIGN.md 3.7).
//!
//! A run starts in h0. Until it commits, the robot follows [`Controller::decide`]; the adversary
//! draws its action from the [`AdversaryModel`]. After committing to a task it plays that task's
//! reactive strategy until the task is satisfied (a target state of its DFA(s)), or a stuck state
//! ends the play. A run also ends when `max_steps` moves (of either player) have been made.
//! Before committing, a run that enters a state of value 0 ends at once as `none`: nothing can
//! be gained from there.
//!
//! Payoffs follow the MDP's convention exactly, so that the mean payoff estimates the value of
//! h0: a run that commits to task `t` after `k` robot moves (`stop` is not a move) and then
//! satisfies it pays `payoff(t) · g^k`; a run that gives up, or hits the step bound, pays 0. A
//! run that meets a stuck adversary ends with its own outcome and pays what the attractor
//! credits it with: the committed task's payoff, or r before committing. Because of the step
//! bound, the estimate is biased downwards by the probability of runs longer than the bound.
//!
//! Randomness: ChaCha8 seeded with the seed; one `u64` per adversary move, turned into a uniform
//! number in [0, 1) with 53 bits. The same inputs and seed give the same runs on every platform.

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};
use serde::Serialize;

use crate::game::{HState, Task};
use crate::opportunistic::adversary::AdversaryModel;
use crate::opportunistic::controller::Controller;
use crate::opportunistic::evaluate::{Plan, Step};
use crate::opportunistic::view::{GameView, SolvedGame};
use crate::stage::{Meter, Stage};

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RunOutcome {
    /// The robot committed to phi and satisfied it.
    Phi,
    /// It committed to phi1 (stop) and satisfied it.
    Phi1Only,
    /// It committed to phi2 and satisfied it.
    Phi2Only,
    /// The adversary was stuck (no enabled action), which counts as a win for the robot.
    AdversaryStuck,
    /// It reached a state of value 0 before committing (a stuck `(L,L,L)` state among them),
    /// or its reactive strategy had no move.
    None,
    /// The step bound was hit first.
    StepBound,
}

impl RunOutcome {
    /// Every outcome, in the order reports list them.
    pub const ALL: [RunOutcome; 6] = [
        RunOutcome::Phi,
        RunOutcome::Phi1Only,
        RunOutcome::Phi2Only,
        RunOutcome::AdversaryStuck,
        RunOutcome::None,
        RunOutcome::StepBound,
    ];

    fn satisfied(task: Task) -> RunOutcome {
        match task {
            Task::Phi => RunOutcome::Phi,
            Task::Phi1 => RunOutcome::Phi1Only,
            Task::Phi2 => RunOutcome::Phi2Only,
        }
    }

    /// The outcome's name in reports (`phi satisfied`, `step bound hit`...).
    pub fn name(self) -> &'static str {
        match self {
            RunOutcome::Phi => "phi satisfied",
            RunOutcome::Phi1Only => "phi1 only",
            RunOutcome::Phi2Only => "phi2 only",
            RunOutcome::AdversaryStuck => "adversary stuck",
            RunOutcome::None => "none",
            RunOutcome::StepBound => "step bound hit",
        }
    }
}

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

/// Outcome frequencies and the mean payoff with a 95% confidence interval (normal
/// approximation: mean ± 1.96 · s / √n, s the sample standard deviation).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SimulationReport {
    /// The number of runs.
    pub runs: u32,
    /// The seed of the random stream.
    pub seed: u64,
    /// The most moves a run could make.
    pub max_steps: u32,
    /// How many runs ended each way.
    pub outcomes: OutcomeCounts,
    /// The mean payoff over the runs, an estimate of the value of h0.
    pub mean_payoff: f64,
    /// The lower end of the 95% confidence interval of the mean payoff.
    pub ci_low: f64,
    /// The upper end of the 95% confidence interval of the mean payoff.
    pub ci_high: f64,
}

/// How many runs ended each way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct OutcomeCounts {
    /// Runs that committed to phi and satisfied it.
    pub phi: u32,
    /// Runs that committed to phi1 and satisfied it.
    pub phi1_only: u32,
    /// Runs that committed to phi2 and satisfied it.
    pub phi2_only: u32,
    /// Runs that met a stuck adversary.
    pub adversary_stuck: u32,
    /// Runs that gained nothing: they reached a state of value 0, or the strategy had no move.
    pub none: u32,
    /// Runs that hit the step bound.
    pub step_bound: u32,
}

impl OutcomeCounts {
    fn add(&mut self, outcome: RunOutcome) {
        *match outcome {
            RunOutcome::Phi => &mut self.phi,
            RunOutcome::Phi1Only => &mut self.phi1_only,
            RunOutcome::Phi2Only => &mut self.phi2_only,
            RunOutcome::AdversaryStuck => &mut self.adversary_stuck,
            RunOutcome::None => &mut self.none,
            RunOutcome::StepBound => &mut self.step_bound,
        } += 1;
    }

    /// The counts in the order of [`RunOutcome::ALL`].
    pub fn iter(&self) -> impl Iterator<Item = (RunOutcome, u32)> {
        RunOutcome::ALL.into_iter().zip([
            self.phi,
            self.phi1_only,
            self.phi2_only,
            self.adversary_stuck,
            self.none,
            self.step_bound,
        ])
    }
}

/// One move of a traced run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TraceStep {
    /// The hypergame state's display name.
    pub state: String,
    /// The state's win-label.
    pub label: String,
    /// The action played here (`stop`, an arena action), or `None` where the run ends or commits.
    pub action: Option<String>,
    /// The task committed to so far (`phi1`, or a set of sub-tasks such as `A,B`).
    pub committed: Option<String>,
}

/// A finished run: its outcome and payoff.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Run {
    /// How the run ended.
    pub outcome: RunOutcome,
    /// What the run paid (see the module documentation).
    pub payoff: f64,
}

/// Simulates `options.runs` runs with one RNG stream.
pub fn simulate<G: SolvedGame>(
    controller: &Controller<'_, G>,
    adversary: &AdversaryModel,
    options: SimulationOptions,
) -> SimulationReport {
    let meter = &mut Meter::unobserved(Stage::Simulation);
    simulate_metered(controller, adversary, options, meter)
}

/// [`simulate`], reporting the runs made to `meter` (one after another: the runs share one
/// random stream, so they are not spread over threads).
pub fn simulate_metered<G: SolvedGame>(
    controller: &Controller<'_, G>,
    adversary: &AdversaryModel,
    options: SimulationOptions,
    meter: &mut Meter<'_>,
) -> SimulationReport {
    let mut counts = OutcomeCounts::default();
    let stats = run_many(controller, adversary, options, meter, |ending| {
        counts.add(paper_outcome(ending))
    });
    SimulationReport {
        runs: options.runs,
        seed: options.seed,
        max_steps: options.max_steps,
        outcomes: counts,
        mean_payoff: stats.mean,
        ci_low: stats.ci_low,
        ci_high: stats.ci_high,
    }
}

/// One run from the seed, recorded state by state.
pub fn trace<G: SolvedGame>(
    controller: &Controller<'_, G>,
    adversary: &AdversaryModel,
    seed: u64,
    max_steps: u32,
) -> (Run, Vec<TraceStep>) {
    let (ending, payoff, steps) = trace_plan(controller, adversary, seed, max_steps);
    let run = Run {
        outcome: paper_outcome(ending),
        payoff,
    };
    (run, steps)
}

/// How a run of any controller ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ending {
    /// It committed to this goal and satisfied it.
    Satisfied(usize),
    /// The adversary had no enabled action.
    AdversaryStuck,
    /// It reached a state of value 0 before committing, or its reactive strategy had no move.
    None,
    /// The step bound was hit first.
    StepBound,
}

fn paper_outcome(ending: Ending) -> RunOutcome {
    match ending {
        Ending::Satisfied(goal) => RunOutcome::satisfied(Task::ALL[goal]),
        Ending::AdversaryStuck => RunOutcome::AdversaryStuck,
        Ending::None => RunOutcome::None,
        Ending::StepBound => RunOutcome::StepBound,
    }
}

/// The mean payoff of many runs and its 95% interval.
struct PayoffStats {
    mean: f64,
    ci_low: f64,
    ci_high: f64,
}

/// `options.runs` runs of `plan` with one RNG stream, told to `meter`; `count` sees each
/// ending.
fn run_many<P: Plan>(
    plan: &P,
    adversary: &AdversaryModel,
    options: SimulationOptions,
    meter: &mut Meter<'_>,
    mut count: impl FnMut(Ending),
) -> PayoffStats {
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let (mut sum, mut sum_squares) = (0.0, 0.0);
    meter.set_total(u64::from(options.runs));
    for _ in 0..options.runs {
        meter.advance(1);
        let (ending, payoff) = run(plan, adversary, options.max_steps, &mut rng, None);
        count(ending);
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
    PayoffStats {
        mean,
        ci_low: mean - half_width,
        ci_high: mean + half_width,
    }
}

/// Simulation of any controller (the general form's): outcome counts by name, in the order
/// the goals are numbered, then `adversary stuck`, `none`, `step bound hit`; goals no run
/// satisfied are left out.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GoalSimulationReport {
    /// The number of runs.
    pub runs: u32,
    /// The seed of the random stream.
    pub seed: u64,
    /// The most moves a run could make.
    pub max_steps: u32,
    /// How many runs ended each way, in the order given above.
    pub outcomes: Vec<OutcomeCount>,
    /// The mean payoff over the runs, an estimate of the value of h0.
    pub mean_payoff: f64,
    /// The lower end of the 95% confidence interval of the mean payoff.
    pub ci_low: f64,
    /// The upper end of the 95% confidence interval of the mean payoff.
    pub ci_high: f64,
}

/// How many runs ended one way.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutcomeCount {
    /// The outcome's name: `GOAL satisfied`, or [`RunOutcome::name`] of the others.
    pub outcome: String,
    /// The number of runs that ended so.
    pub count: u32,
}

/// Simulates `options.runs` runs of `plan` with one RNG stream.
pub fn simulate_plan<P: Plan>(
    plan: &P,
    adversary: &AdversaryModel,
    options: SimulationOptions,
) -> GoalSimulationReport {
    let meter = &mut Meter::unobserved(Stage::Simulation);
    simulate_plan_metered(plan, adversary, options, meter)
}

/// [`simulate_plan`], reporting the runs made to `meter`.
pub fn simulate_plan_metered<P: Plan>(
    plan: &P,
    adversary: &AdversaryModel,
    options: SimulationOptions,
    meter: &mut Meter<'_>,
) -> GoalSimulationReport {
    let goals = plan.num_goals();
    // Per goal, then stuck, none, step bound.
    let mut counts = vec![0u32; goals + 3];
    let stats = run_many(plan, adversary, options, meter, |ending| {
        counts[match ending {
            Ending::Satisfied(goal) => goal,
            Ending::AdversaryStuck => goals,
            Ending::None => goals + 1,
            Ending::StepBound => goals + 2,
        }] += 1
    });
    let outcomes = counts
        .iter()
        .enumerate()
        .filter(|&(i, &count)| i >= goals || count > 0)
        .map(|(i, &count)| OutcomeCount {
            outcome: match i.checked_sub(goals) {
                None => format!("{} satisfied", plan.goal_name(i)),
                Some(0) => RunOutcome::AdversaryStuck.name().to_string(),
                Some(1) => RunOutcome::None.name().to_string(),
                Some(_) => RunOutcome::StepBound.name().to_string(),
            },
            count,
        })
        .collect();
    GoalSimulationReport {
        runs: options.runs,
        seed: options.seed,
        max_steps: options.max_steps,
        outcomes,
        mean_payoff: stats.mean,
        ci_low: stats.ci_low,
        ci_high: stats.ci_high,
    }
}

/// One run of `plan` from the seed, recorded state by state: its ending, payoff and steps.
pub fn trace_plan<P: Plan>(
    plan: &P,
    adversary: &AdversaryModel,
    seed: u64,
    max_steps: u32,
) -> (Ending, f64, Vec<TraceStep>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut steps = Vec::new();
    let (ending, payoff) = run(plan, adversary, max_steps, &mut rng, Some(&mut steps));
    (ending, payoff, steps)
}

fn run<P: Plan>(
    plan: &P,
    adversary: &AdversaryModel,
    max_steps: u32,
    rng: &mut ChaCha8Rng,
    mut trace: Option<&mut Vec<TraceStep>>,
) -> (Ending, f64) {
    let game = plan.game();
    let g = plan.discount();
    let mut h = game.initial();
    // The goal committed to, with its payoff.
    let mut committed: Option<(usize, f64)> = None;
    let mut robot_moves = 0i32;
    let mut steps = 0u32;
    let mut distribution = Vec::new();
    let mut record = |h: HState, action: Option<&str>, committed: Option<(usize, f64)>| {
        if let Some(trace) = trace.as_deref_mut() {
            trace.push(TraceStep {
                state: game.state_name(h),
                label: plan.label(h),
                action: action.map(str::to_string),
                committed: committed.map(|(goal, _)| plan.goal_name(goal)),
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
            return finish(Ending::Satisfied(goal), committed, robot_moves);
        }
        if steps >= max_steps {
            record(h, None, committed);
            return finish(Ending::StepBound, committed, robot_moves);
        }
        let next = if game.is_robot(h) {
            match committed {
                Some((goal, _)) => plan.goal_move(goal, h),
                None => match plan.step(h) {
                    Step::Move { action, successor } => {
                        robot_moves += 1;
                        Some((action, successor))
                    }
                    Step::Commit { goal, payoff, stop } => {
                        if stop {
                            record(h, Some(crate::opportunistic::build::STOP), committed);
                        }
                        committed = Some((goal, payoff));
                        continue;
                    }
                    Step::GiveUp => None,
                },
            }
        } else if game.edges(h).next().is_none() {
            record(h, None, committed);
            return finish(Ending::AdversaryStuck, committed, robot_moves);
        } else if committed.is_none() && plan.is_worthless(h) {
            None
        } else {
            adversary.distribution(game, h, &mut distribution);
            let u = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
            let mut cumulative = 0.0;
            let mut chosen = None;
            for (edge, &p) in game.edges(h).zip(&distribution) {
                if p > 0.0 {
                    chosen = Some(edge);
                    cumulative += p;
                    if u < cumulative {
                        break;
                    }
                }
            }
            chosen
        };
        let Some((action, successor)) = next else {
            record(h, None, committed);
            return finish(Ending::None, committed, robot_moves);
        };
        record(h, Some(game.action_name(action)), committed);
        h = successor;
        steps += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::solve::{Discount, Solution, SolveOptions, solve};
    use crate::opportunistic::adversary::SigmaL;
    use crate::opportunistic::build::{HypergameMdp, Payoffs};
    use crate::opportunistic::view::testing::ToyGame;

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
            payoffs: Payoffs::default(),
        }
    }

    fn solved(g: &ToyGame, discount: f64) -> (HypergameMdp, Solution, AdversaryModel) {
        let adversary = AdversaryModel::new(g, &SigmaL::Uniform).unwrap();
        let built = HypergameMdp::build(g, &adversary, Payoffs::default()).unwrap();
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
        assert_eq!(
            report.outcomes,
            OutcomeCounts {
                phi,
                phi1_only: 2000 - phi,
                ..OutcomeCounts::default()
            }
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
    fn trace_records_moves_labels_and_commitment() {
        let g = coin_game();
        let (built, solution, adversary) = solved(&g, 0.9);
        let controller = controller(&g, &built, &solution);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let heads = rng.next_u64() >> 63 == 0;
        let (run, steps) = trace(&controller, &adversary, 5, 100);
        let rows: Vec<(String, String, Option<String>, Option<String>)> = steps
            .into_iter()
            .map(|s| (s.state, s.label, s.action, s.committed))
            .collect();
        let row = |h: &str, l: &str, a: Option<&str>, c: Option<Task>| {
            (
                h.to_string(),
                l.to_string(),
                a.map(str::to_string),
                c.map(|t: Task| t.name().to_string()),
            )
        };
        let mut expected = vec![row("h0", "(W, L, L)", Some("a"), None)];
        if heads {
            expected.push(row("h1", "(W, L, L)", Some("x"), None));
            expected.push(row("h2", "(W, W, W)", None, Some(Task::Phi)));
            assert_eq!(
                run,
                Run {
                    outcome: RunOutcome::Phi,
                    payoff: 270.0
                }
            );
        } else {
            expected.push(row("h1", "(W, L, L)", Some("y"), None));
            expected.push(row("h3", "(W, L, L)", Some("stop"), None));
            expected.push(row("h3", "(W, L, L)", None, Some(Task::Phi1)));
            assert_eq!(run.outcome, RunOutcome::Phi1Only);
        }
        assert_eq!(rows, expected);
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
        let (run, steps) = trace(&controller, &adversary, 1, 10);
        assert_eq!(
            run,
            Run {
                outcome: RunOutcome::AdversaryStuck,
                payoff: 300.0
            }
        );
        assert_eq!(steps.len(), 2);
        assert_eq!(steps[1].committed.as_deref(), Some("phi"));
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
        assert_eq!(report.outcomes.none, 3);
        assert_eq!(report.outcomes.step_bound, 0);
        assert_eq!(
            (report.mean_payoff, report.ci_low, report.ci_high),
            (0.0, 0.0, 0.0)
        );
    }
}
