//! The robust stage on the implicit engine (docs/semantics.md §10, docs/engines.md): the
//! explicit stage's steps (`robust.rs`) over the model's rules, nothing stored per transition.
//!
//! The model is built with sigma_L's full support (uniform), as the explicit stage builds its
//! MDP, so that levels, commitments and choices are the nominal problem's whatever was
//! observed. The observations are counted over its product ([`RunProduct`]), the region keeps
//! the observed arena states only; its intervals ([`implicit::Intervals`]) and estimate
//! ([`Model::with_estimate`]) are rules per arena state. The robust values and policy are
//! [`implicit::solve_robust`]'s and [`implicit::robust_policy`]'s, the nominal value under the
//! estimate the nominal implicit solve's; the robust policy is checked on its Markov chain
//! against the adversary's reply to the certified lower bounds ([`Model::with_replies`]), by
//! the nominal evaluation (no code of the robust solve), and simulated against the problem's
//! own sigma_L ([`Model::with_sigma_l`]).

use std::sync::Arc;

use super::engine::{IMPLICIT_COMPILED, IMPLICIT_PER_LIVE, ImplicitError, RunError, model};
use super::opportunistic::{Learnt, MdpOptions};
use super::robust::sigma_l_states;
use super::{PipelineError, Tasks};
use crate::arena::Owner;
use crate::implicit::{self, Choice, Model, Moves, Regions, Space};
use crate::opportunistic::adversary::SigmaL;
use crate::opportunistic::controller::clamped;
use crate::opportunistic::observations::{Counts, Region};
use crate::opportunistic::simulate::{SimulationOptions, simulate_on};
use crate::report::{RobustChoice, RobustSimulation, RobustSummary, StageError};
use crate::stage::{Meter, Observer, Stage, metered};

/// The implicit engine's robust stage: the model with sigma_L's full support, what was
/// learnt, and the robust solution and policy.
pub(super) struct ImplicitRobust<'a, 'm, M> {
    /// The model with sigma_L's full support (uniform).
    pub(super) model: Model<'a, 'm, M>,
    /// The adversary's steps along the runs.
    pub(super) counts: Counts,
    /// The confidence region.
    pub(super) region: Region,
    /// The region's intervals.
    pub(super) intervals: Arc<implicit::Intervals>,
    /// The robust solution and policy.
    pub(super) solution: Arc<implicit::Solution>,
    pub(super) policy: implicit::Policy,
    /// The nominal solution under the estimate.
    nominal: implicit::Solution,
    nominal_policy: implicit::Policy,
    /// The robust policy's value against the worst-case reply, at h0.
    worst_case: f64,
}

/// The precision `options` ask of the implicit solves.
fn precision(options: &MdpOptions) -> implicit::Precision {
    let solve = &options.solve;
    match solve.relative {
        true => implicit::Precision::relative(solve.epsilon),
        false => implicit::Precision::absolute(solve.epsilon),
    }
}

impl<'a, 'm, M: Moves> ImplicitRobust<'a, 'm, M> {
    /// Learns the region from `learnt` over `space` with its `regions`, solves the robust and
    /// nominal problems and checks the robust policy against the worst case (module
    /// documentation).
    pub(super) fn solve(
        tasks: &'a Tasks,
        (space, regions): (&'a Space<'m, M>, &'a Regions),
        options: &MdpOptions,
        learnt: &Learnt,
        observer: &mut dyn Observer,
    ) -> Result<ImplicitRobust<'a, 'm, M>, RunError> {
        // The model's levels and commitments (three bytes per state), then per live state
        // the robust bounds and the uncertain nodes, the nominal bounds under the estimate and
        // the policy's chain, each asked before it is made.
        let states = space.num_states() as u64;
        metered(observer, Stage::MdpBuild, |meter| {
            meter.reserve(3 * states, || {
                format!("the model with sigma_L's full support over {states} product states")
            })
        })?;
        let model = model(tasks, space, regions, &SigmaL::Uniform, observer)?;
        let counts = learnt
            .observations
            .count_on(&model)
            .map_err(|e| PipelineError::Stage(StageError::Observations(e)))?;
        let region = Region::new(&counts, learnt.delta)
            .map_err(|e| PipelineError::Stage(StageError::from(e)))?;
        let row = |edges: &[[f64; 3]], f: fn(&[f64; 3]) -> [f64; 2]| edges.iter().map(f).collect();
        let intervals = Arc::new(implicit::Intervals::new(
            region
                .observed()
                .map(|r| (r.state.as_u32(), row(r.edges, |e| [e[1], e[2]]))),
        ));
        let estimate: Vec<(u32, Box<[f64]>)> = region
            .observed()
            .map(|r| (r.state.as_u32(), r.edges.iter().map(|e| e[0]).collect()))
            .collect();
        let solve = &options.solve;
        let (g, max_iterations) = (solve.discount.get(), solve.max_iterations);
        let live = model.num_live();
        metered(observer, Stage::RobustSolve, |meter| {
            meter.reserve(
                live.saturating_mul(3 * IMPLICIT_PER_LIVE + IMPLICIT_COMPILED) + states / 8,
                || {
                    format!(
                        "the implicit engine's robust and nominal bounds and the robust policy's \
                     chain over {live} live states"
                    )
                },
            )
        })?;
        let solution = metered(observer, Stage::RobustSolve, |_| {
            implicit::solve_robust(&model, &intervals, g, precision(options), max_iterations)
        })
        .map_err(ImplicitError::Solve)?;
        let policy = metered(observer, Stage::Policy, |_| {
            implicit::robust_policy(&model, &intervals, &solution, g)
        })
        .map_err(ImplicitError::Policy)?;
        let estimated = model.with_estimate(estimate);
        let (nominal, nominal_policy) = metered(observer, Stage::Solve, |_| {
            let nominal = implicit::solve(&estimated, g, precision(options), max_iterations)
                .map_err(ImplicitError::Solve)?;
            let policy = implicit::policy(&estimated, &nominal, g, max_iterations)
                .map_err(ImplicitError::Policy)?;
            Ok::<_, ImplicitError>((nominal, policy))
        })?;
        drop(estimated);
        // The robust policy's chain against the adversary's reply to the lower bounds: it
        // must collect at least the certified lower bound at h0.
        let solution = Arc::new(solution);
        let h0 = space.initial();
        let value = solution.value(&model, h0);
        let worst = model.with_replies(Arc::clone(&intervals), Arc::clone(&solution));
        let chain = metered(observer, Stage::Evaluation, |_| {
            implicit::chain(&worst, &policy, solve.epsilon, max_iterations)
        })
        .map_err(ImplicitError::Policy)?;
        let worst_case = chain.value(h0).unwrap_or(value);
        let tolerance = solve.epsilon + 1e-9 * value.upper.max(1.0);
        if worst_case.upper < value.lower - tolerance {
            return Err(PipelineError::Stage(StageError::ControllerMismatch {
                policy_lower: worst_case.lower,
                policy_upper: worst_case.upper,
                lower: value.lower,
                upper: value.upper,
            })
            .into());
        }
        Ok(ImplicitRobust {
            model,
            counts,
            region,
            intervals,
            solution,
            policy,
            nominal,
            nominal_policy,
            worst_case: worst_case.lower,
        })
    }

    /// The report's summary, as the explicit stage makes it; with `simulate`, the robust
    /// controller simulated against the problem's own sigma_L.
    pub(super) fn summary(
        &self,
        tasks: &Tasks,
        (learnt, options): (&Learnt, &MdpOptions),
        simulate: Option<(u32, u32)>,
        observer: &mut dyn Observer,
    ) -> Result<RobustSummary, RunError> {
        let model = &self.model;
        let space = model.space();
        let h0 = space.initial();
        let g = options.solve.discount.get();
        let robot = space.owner(h0) == Owner::Robot;
        let action = |solution: &implicit::Solution, policy: &implicit::Policy| {
            policy
                .mdp_choice(h0)
                .filter(|_| robot && solution.value(model, h0).upper > 0.0)
                .and_then(|c| model.choice(h0, c))
                .map(|c| model.choice_name(c))
        };
        let mut choices = Vec::new();
        if robot && !matches!(model.kind(h0), implicit::Kind::Absorbing(_)) {
            let q = |solution: &implicit::Solution, c: Choice| match c {
                Choice::Move { target, .. } => g * solution.value(model, target).lower,
                Choice::Stop { payoff } => payoff,
            };
            model.choices(h0, |c| {
                choices.push(RobustChoice {
                    action: model.choice_name(c),
                    robust: q(&self.solution, c),
                    nominal: q(&self.nominal, c),
                })
            });
        }
        let (sigma_l_states, never_observed) = sigma_l_states(model, &self.region);
        let top = tasks.payoffs().all();
        let clamp = |x: f64| x.clamp(0.0, top);
        let value = clamped(self.solution.value(model, h0), top);
        let nominal = clamped(self.nominal.value(model, h0), top);
        let simulation = match simulate {
            Some((runs, max_steps)) => {
                let truth = model
                    .with_sigma_l(&options.sigma_l)
                    .map_err(ImplicitError::Model)?;
                let controller = implicit::Controller::new(&truth, &self.solution, &self.policy);
                let options = SimulationOptions {
                    runs,
                    seed: options.seed,
                    max_steps,
                };
                let sim = metered(observer, Stage::Simulation, |_| {
                    let unobserved = &mut Meter::unobserved(Stage::Simulation);
                    simulate_on(&controller, &controller, options, unobserved)
                });
                Some(RobustSimulation {
                    runs,
                    mean_payoff: sim.mean_payoff,
                    ci_low: sim.ci_low,
                    ci_high: sim.ci_high,
                })
            }
            None => None,
        };
        Ok(RobustSummary {
            observations: learnt.file.clone(),
            delta: learnt.delta,
            runs: self.counts.runs,
            counted: self.counts.counted,
            sigma_w_steps: self.counts.sigma_w_steps,
            misfits: self.counts.misfits,
            pairs: self.region.pairs,
            sigma_l_states,
            never_observed,
            value: value.lower,
            value_upper: value.upper,
            nominal_value: nominal.lower,
            nominal_value_upper: nominal.upper,
            action: action(&self.solution, &self.policy),
            nominal_action: action(&self.nominal, &self.nominal_policy),
            worst_case_value: clamp(self.worst_case),
            iterations: self.solution.iterations(),
            gap: self.solution.gap(),
            choices,
            simulation,
            learning_curve: Vec::new(),
        })
    }
}
