//! The robust MDP stage (docs/semantics.md §10): sigma_L learnt from observed runs as a
//! confidence region, the hypergame MDP with the region's intervals at the chance nodes where
//! sigma_L rules, its robust and nominal solutions, and the robust controller checked against
//! the worst-case adversary.
//!
//! The MDP is built with the full support of the adversary (every enabled action where sigma_L
//! rules, as a uniform sigma_L gives it), so win-labels, enabled robot actions, commitments and
//! absorbing states are those of the nominal problem whatever was observed. At a chance node
//! where sigma_L rules, two actions leading to the same product state share one MDP target:
//! its interval is the sum of theirs (the exact projection of the region), cut at 1.
//!
//! The nominal value (under the estimate: p_hat, uniform where unobserved) is the nominal
//! solver's on a copy of the MDP with the estimate's probabilities at those chance nodes
//! (zero ones dropped), with the same states and choices; the nominal solver's preprocessing
//! makes it about twice as fast as the robust solver with point intervals on the 24x24
//! gridworld at g = 0.99.
//!
//! The robust controller is the ordinary [`Controller`] over this MDP and the robust
//! solution. Its check: the Markov chain of the controller's choices and of the adversary's
//! worst-case reply to the certified lower bounds is solved by the nominal solver (no code of
//! the robust solver); it must collect at least the robust lower bound at h0.

use bit_set::BitSet;

use crate::arena::{Owner, StateId};
use crate::index::{Id, IdRange};
use crate::mdp::model::{ChoiceId, Mdp, MdpBuilder, MdpState};
use crate::mdp::robust::{self, IntervalError, Intervals, choice_value, worst_case};
use crate::mdp::solve::{Solution, SolveError, solve, solve_observed};
use crate::mdp::{DrnForm, write_interval_drn};
use crate::opportunistic::adversary::{AdversaryModel, ArenaLookup, SigmaL};
use crate::opportunistic::build::{HypergameMdp, Risk};
use crate::opportunistic::controller::Controller;
use crate::opportunistic::observations::CurvePoint;
use crate::opportunistic::observations::{Counts, Region, RunProduct};
use crate::opportunistic::simulate::{Against, SimulationOptions, simulate};
use crate::opportunistic::view::{GameView, SolvedGame, SolvedHypergame};
use crate::report::{RobustChoice, RobustSimulation, RobustSummary, StageError};
use crate::stage::{Observer, Stage, metered, timed};

use super::PipelineError;
use super::opportunistic::{Learnt, MdpOptions, controller_file};
use crate::game::HState;
use crate::opportunistic::export::{ExportInputs, ModelRules, SigmaLRule};

/// The robust stage's results.
pub struct RobustSolution {
    /// The adversary with sigma_L's full support (and sigma_W as usual).
    pub adversary: AdversaryModel,
    /// The hypergame MDP built with that support.
    pub mdp: HypergameMdp,
    /// The adversary's steps along the runs.
    pub counts: Counts,
    /// The confidence region.
    pub region: Region,
    /// The region's intervals on the MDP's chance choices.
    pub intervals: Intervals,
    /// The estimate as point intervals (uniform where unobserved).
    pub estimate: Intervals,
    /// The robust solution (value and policy).
    pub solution: Solution,
    /// The nominal solution under the estimate.
    pub nominal: Solution,
    /// The value of the robust controller's chain against the worst-case reply, at h0.
    pub worst_case: crate::mdp::Interval,
}

impl RobustSolution {
    /// Learns the region from `learnt`, builds and solves the robust and nominal MDPs of
    /// `game`, and checks the robust controller against the worst case.
    pub fn solve(
        game: &SolvedHypergame,
        risk: Risk,
        options: &MdpOptions,
        learnt: &Learnt,
        observer: &mut dyn Observer,
    ) -> Result<RobustSolution, StageError> {
        let adversary = timed(observer, Stage::Adversary, || {
            AdversaryModel::new(game, &SigmaL::Uniform)
        })?;
        let counts = learnt
            .observations
            .count(game, &adversary)
            .map_err(StageError::Observations)?;
        let region = Region::new(&counts, learnt.delta).map_err(StageError::from)?;
        let mdp = metered(observer, Stage::MdpBuild, |meter| {
            HypergameMdp::build_metered(game, &adversary, risk, meter)
        })?;
        // The region's intervals and the estimate's points, each at most `Intervals::bytes`.
        let m = mdp.mdp();
        observer
            .reserve(Stage::MdpBuild, 2 * Intervals::bytes(m), &|| {
                format!(
                    "the learnt region's intervals on the MDP ({} choices, {} transitions)",
                    m.num_choices(),
                    m.num_transitions()
                )
            })
            .map_err(SolveError::from)?;
        let intervals = chance_intervals(&mdp, game, &adversary, |s, e, degree| {
            region.interval(s, e, degree)
        })
        .map_err(StageError::from)?;
        let estimate = chance_intervals(&mdp, game, &adversary, |s, e, degree| {
            let p = region.estimate(s, e, degree);
            [p, p]
        })
        .map_err(StageError::from)?;
        let solution = robust::solve_observed(mdp.mdp(), &intervals, &options.solve, observer)?;
        // The nominal value under the estimate: the nominal solver on the model with the
        // estimate's probabilities (the same states and choices; the model's own probabilities
        // elsewhere).
        let copy = |what: &'static str| {
            move || {
                format!(
                    "{what} ({} states, {} transitions)",
                    m.num_states(),
                    m.num_transitions()
                )
            }
        };
        observer
            .reserve(
                Stage::MdpBuild,
                copy_bytes(m),
                &copy("the MDP with the estimate's probabilities"),
            )
            .map_err(SolveError::from)?;
        let estimated = timed(observer, Stage::MdpBuild, || {
            resolved(mdp.mdp(), &estimate, &[], None)
        });
        let nominal = solve_observed(&estimated, &options.solve, observer)?;
        drop(estimated);
        let s0 = mdp.node(game.initial());
        // The controller's check against the worst case, an evaluation.
        observer
            .reserve(
                Stage::Evaluation,
                copy_bytes(m),
                &copy("the robust controller's chain against the worst case"),
            )
            .map_err(SolveError::from)?;
        let worst_case = timed(observer, Stage::Evaluation, || {
            let lower: Vec<f64> = mdp
                .mdp()
                .states()
                .map(|s| solution.value(s).lower)
                .collect();
            let chain = resolved(mdp.mdp(), &intervals, &lower, Some(&solution));
            solve(&chain, &options.solve).map(|chain| chain.value(s0))
        })?;
        let value = solution.value(s0);
        let tolerance = options.solve.epsilon + 1e-9 * value.upper.max(1.0);
        if worst_case.upper < value.lower - tolerance {
            return Err(StageError::ControllerMismatch {
                policy_lower: worst_case.lower,
                policy_upper: worst_case.upper,
                lower: value.lower,
                upper: value.upper,
            });
        }
        Ok(RobustSolution {
            adversary,
            mdp,
            counts,
            region,
            intervals,
            estimate,
            solution,
            nominal,
            worst_case,
        })
    }

    /// The MDP with the region's intervals in Storm's interval DRN in `form`
    /// ([`write_interval_drn`]: Storm checks only the reachability form of an interval model),
    /// its states named after the product states.
    pub fn drn(&self, game: &impl SolvedGame, options: &MdpOptions, form: DrnForm) -> String {
        write_interval_drn(
            self.mdp.mdp(),
            &self.intervals,
            options.solve.discount,
            form,
            |s| Some(self.mdp.state_name(game, s)),
        )
    }

    /// The robust controller as an exported file (docs/semantics.md §9), its sigma_L the
    /// learnt region (the counts and `delta`) and its MDP built with `risk`; with
    /// `certificate`, with its certificate against every adversary within the region (§9.4)
    /// made from the robust solution's lower bounds, which the controller collects, and upper
    /// ones.
    pub fn export_controller(
        &self,
        game: &SolvedHypergame,
        risk: Risk,
        inputs: &ExportInputs,
        certificate: bool,
    ) -> Result<String, PipelineError> {
        let rules = ModelRules {
            risk,
            sigma_l: SigmaLRule::Learnt {
                delta: self.region.delta,
                counts: self.counts.entries(game.arena()),
            },
        };
        let bounds = |h: HState| {
            let value = self.solution.value(self.mdp.node(h));
            [value.lower, value.upper]
        };
        let controller = self.controller(game);
        controller_file(
            &controller,
            &self.adversary,
            rules,
            inputs,
            certificate,
            bounds,
        )
    }

    /// The robust controller on `game`.
    pub fn controller<'s, G: SolvedGame>(&'s self, game: &'s G) -> Controller<'s, G> {
        Controller {
            game,
            mdp: &self.mdp,
            solution: &self.solution,
        }
    }

    /// The report's summary; with `simulate`, the robust controller simulated against `truth`.
    pub fn summary(
        &self,
        game: &impl SolvedGame,
        learnt: &Learnt,
        options: &MdpOptions,
        truth: &AdversaryModel,
        simulate_runs: Option<(u32, u32)>,
    ) -> RobustSummary {
        let m = self.mdp.mdp();
        let h0 = game.initial();
        let s0 = self.mdp.node(h0);
        let g = options.solve.discount.get();
        let action_name = |solution: &Solution| {
            solution
                .policy(s0)
                .filter(|_| game.is_robot(h0) && solution.value(s0).upper > 0.0)
                .map(|c| m.action_name(c).to_string())
        };
        let choices = if game.is_robot(h0) && !m.is_absorbing(s0) {
            let lower = |solution: &Solution| -> Vec<f64> {
                m.states().map(|s| solution.value(s).lower).collect()
            };
            let (robust_lower, nominal_lower) = (lower(&self.solution), lower(&self.nominal));
            m.choices(s0)
                .map(|c: ChoiceId| RobustChoice {
                    action: m.action_name(c).to_string(),
                    robust: choice_value(m, &self.intervals, g, &robust_lower, c),
                    nominal: choice_value(m, &self.estimate, g, &nominal_lower, c),
                })
                .collect()
        } else {
            Vec::new()
        };
        let product = Against {
            game,
            adversary: &self.adversary,
        };
        let (sigma_l_states, never_observed) = sigma_l_states(&product, &self.region);
        let top = game.payoffs().all();
        let clamp = |x: f64| x.clamp(0.0, top);
        RobustSummary {
            observations: learnt.file.clone(),
            delta: learnt.delta,
            runs: self.counts.runs,
            counted: self.counts.counted,
            sigma_w_steps: self.counts.sigma_w_steps,
            misfits: self.counts.misfits,
            pairs: self.region.pairs,
            sigma_l_states,
            never_observed,
            value: clamp(self.solution.value(s0).lower),
            value_upper: clamp(self.solution.value(s0).upper),
            nominal_value: clamp(self.nominal.value(s0).lower),
            nominal_value_upper: clamp(self.nominal.value(s0).upper),
            action: action_name(&self.solution),
            nominal_action: action_name(&self.nominal),
            worst_case_value: clamp(self.worst_case.lower),
            iterations: self.solution.iterations(),
            gap: self.solution.gap(),
            choices,
            simulation: simulate_runs.map(|(runs, max_steps)| {
                let sim = simulate(
                    &self.controller(game),
                    truth,
                    SimulationOptions {
                        runs,
                        seed: options.seed,
                        max_steps,
                    },
                );
                RobustSimulation {
                    runs,
                    mean_payoff: sim.mean_payoff,
                    ci_low: sim.ci_low,
                    ci_high: sim.ci_high,
                }
            }),
            learning_curve: Vec::new(),
        }
    }
}

/// The learning curve of `learnt` (docs/semantics.md §10): for each number of runs in `runs`,
/// in the order given, the robust stage learnt from the first that many runs of the
/// observations alone, as the main form would report it from a file holding only those runs
/// ([`RobustSolution::solve`], then [`RobustSolution::summary`]). Every point uses 1 to all of
/// the runs (`CurveRuns` otherwise, and `CurveWithoutRuns` when there is none, before anything
/// is solved). `all`, the summary of the robust stage learnt from all the runs when the caller
/// has it already, gives the point of all the runs instead of a second solve. Cost: one robust
/// and one nominal solve per other point.
pub fn learning_curve(
    game: &SolvedHypergame,
    risk: Risk,
    options: &MdpOptions,
    learnt: &Learnt,
    runs: &[usize],
    all: Option<&RobustSummary>,
    observer: &mut dyn Observer,
) -> Result<Vec<CurvePoint>, StageError> {
    curve_points(learnt, runs, all, |prefix| {
        let robust = RobustSolution::solve(game, risk, options, prefix, observer)?;
        // No simulation: the summary's adversary model is not used.
        let summary = robust.summary(game, prefix, options, &robust.adversary, None);
        Ok(summary.curve_point())
    })
}

/// The points of `learnt`'s learning curve at `runs` ([`learning_curve`]), each of the
/// others made by `point` from the observations' first runs, on either engine.
pub(super) fn curve_points<E: From<StageError>>(
    learnt: &Learnt,
    runs: &[usize],
    all: Option<&RobustSummary>,
    mut point: impl FnMut(&Learnt) -> Result<CurvePoint, E>,
) -> Result<Vec<CurvePoint>, E> {
    let available = learnt.observations.num_runs();
    if available == 0 {
        return Err(StageError::CurveWithoutRuns.into());
    }
    if let Some(&bad) = runs.iter().find(|&&n| n == 0 || n > available) {
        return Err(StageError::CurveRuns {
            runs: bad,
            available,
        }
        .into());
    }
    runs.iter()
        .map(|&n| {
            if let Some(summary) = all.filter(|_| n == available) {
                return Ok(summary.curve_point());
            }
            let prefix = Learnt {
                observations: learnt.observations.prefix(n),
                ..learnt.clone()
            };
            point(&prefix)
        })
        .collect()
}

/// The runs a learning curve uses by default when `total` were observed: 1, 2, 5, 10, 20, 50,
/// ... below `total`, then `total` (nothing when no run was observed).
pub fn curve_runs(total: usize) -> Vec<usize> {
    let mut runs: Vec<usize> = (0..usize::BITS)
        .flat_map(|e| [1, 2, 5].map(|m: usize| m.saturating_mul(10usize.saturating_pow(e))))
        .take_while(|&n| n < total)
        .collect();
    if total > 0 {
        runs.push(total);
    }
    runs
}

/// Intervals on the chance choices of `mdp` where sigma_L rules, from `bounds` per arena
/// state, edge and the state's number of edges (see the module documentation).
fn chance_intervals(
    mdp: &HypergameMdp,
    game: &impl GameView,
    adversary: &AdversaryModel,
    bounds: impl Fn(StateId, usize, usize) -> [f64; 2],
) -> Result<Intervals, IntervalError> {
    let m = mdp.mdp();
    let mut intervals = Intervals::exact(m);
    let mut row: Vec<[f64; 2]> = Vec::new();
    for h in game.states() {
        let node = mdp.node(h);
        if game.is_robot(h) || adversary.plays_sigma_w(h) || m.is_absorbing(node) {
            continue;
        }
        let choice = m.choices(node).start();
        let targets = m.targets(choice);
        row.clear();
        row.resize(targets.len(), [0.0, 0.0]);
        let s = game.arena_state(h);
        let degree = game.arena().edges(s).len();
        for (edge, (_, t)) in game.edges(h).enumerate() {
            let i = targets
                .iter()
                .position(|&x| x == mdp.node(t))
                .expect("every enabled edge is a target under full support");
            let [lower, upper] = bounds(s, edge, degree);
            row[i][0] += lower;
            row[i][1] += upper;
        }
        for b in &mut row {
            b[1] = b[1].min(1.0);
            b[0] = b[0].min(b[1]);
        }
        intervals.set(m, choice, &row)?;
    }
    Ok(intervals)
}

/// About the bytes of a copy of `m` ([`resolved`]): per state its choices' offset and payoff,
/// per choice its action, offset and distribution, per transition its target and probability.
fn copy_bytes(m: &Mdp) -> u64 {
    8 * m.num_states() as u64 + 12 * m.num_choices() as u64 + 12 * m.num_transitions() as u64
}

/// `m` with every interval choice resolved by the adversary's reply to `values` (one per state;
/// for point intervals any values, even none, give the points), every other choice as it is,
/// zero probabilities dropped; with `policy`, only its choice in each decision state (the
/// Markov chain it induces, its choices named `play`). Without `policy`, states and choices
/// keep their ids and names.
fn resolved(m: &Mdp, intervals: &Intervals, values: &[f64], policy: Option<&Solution>) -> Mdp {
    let mut builder = MdpBuilder::new();
    let play = builder.action("play").expect("a valid action name");
    let mut reply = Vec::new();
    let mut successors: Vec<(MdpState, f64)> = Vec::new();
    for s in m.states() {
        if let Some(payoff) = m.payoff(s) {
            builder
                .add_absorbing_state(payoff)
                .expect("a payoff of the model");
            continue;
        }
        builder.add_decision_state().expect("a state");
        let choices = match policy {
            Some(policy) => {
                let choice = policy.policy(s).expect("a choice in every decision state");
                IdRange::new(choice, ChoiceId::new(choice.index() + 1))
            }
            None => m.choices(s),
        };
        for choice in choices {
            successors.clear();
            match intervals.get(m, choice) {
                None => successors.extend(m.successors(choice)),
                Some(bounds) if values.is_empty() => successors.extend(
                    m.targets(choice)
                        .iter()
                        .zip(bounds)
                        .map(|(&t, b)| (t, b[0])),
                ),
                Some(_) => {
                    worst_case(m, intervals, values, choice, &mut reply);
                    successors.extend(m.targets(choice).iter().copied().zip(reply.iter().copied()));
                }
            }
            successors.retain(|&(_, p)| p > 0.0);
            let total: f64 = successors.iter().map(|s| s.1).sum();
            for s in &mut successors {
                s.1 /= total;
            }
            let action = match policy {
                Some(_) => play,
                None => builder
                    .action(m.action_name(choice))
                    .expect("an action of the model"),
            };
            if m.is_instant(choice) {
                builder.add_instant_choice(action, &successors)
            } else {
                builder.add_choice(action, &successors)
            }
            .expect("a distribution");
        }
    }
    builder.set_initial(m.initial());
    builder.build().expect("a copy of a valid model")
}

/// The adversary arena states (with two actions or more) over which some state of `product`
/// plays sigma_L, and how many of them `region` never observed. One bit per arena state.
pub fn sigma_l_states(product: &impl RunProduct, region: &Region) -> (u32, u32) {
    let arena = product.arena();
    let mut seen = BitSet::new();
    product.for_each_state(|h| {
        let s = product.arena_state(h);
        if !seen.contains(s.index())
            && arena.owner(s) == Owner::Adversary
            && arena.degree(s) >= 2
            && !product.plays_sigma_w(h)
        {
            seen.insert(s.index());
        }
    });
    let observed = region
        .observed()
        .filter(|row| seen.contains(row.state.index()))
        .count();
    let states = seen.count();
    (states as u32, (states - observed) as u32)
}

#[cfg(test)]
mod tests {
    use super::curve_runs;

    #[test]
    fn default_curve_runs_go_one_two_five_and_end_with_all() {
        assert_eq!(curve_runs(0), Vec::<usize>::new());
        assert_eq!(curve_runs(1), [1]);
        assert_eq!(curve_runs(2), [1, 2]);
        assert_eq!(curve_runs(7), [1, 2, 5, 7]);
        assert_eq!(curve_runs(100), [1, 2, 5, 10, 20, 50, 100]);
        assert_eq!(curve_runs(101), [1, 2, 5, 10, 20, 50, 100, 101]);
    }
}
