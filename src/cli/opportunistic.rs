//! The MDP stage's options of the main form (flattened into `synth::Args`), turned into the
//! library's options and requests, and its errors into messages that name the options.

use std::path::PathBuf;

use anyhow::Context;

use hypersynth::diagnostic::Source;
use hypersynth::game::StateNameError;
use hypersynth::mdp::DrnForm;
use hypersynth::mdp::solve::{SolveError, SolveOptions};
use hypersynth::opportunistic::adversary::SigmaL;
use hypersynth::opportunistic::observations::DEFAULT_DELTA;
use hypersynth::pipeline::spec::{
    Field, LearntSpec, MdpSpec, Precision, SigmaLSpec, SpecErrorKind,
};
use hypersynth::pipeline::{CurveRequest, Requests};
use hypersynth::render::TitleChoice;
use hypersynth::report::StageError;

use super::choices::ScopeArg;
use super::io::read_input;

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SigmaLKind {
    Uniform,
    Random,
}

/// `--drn-form`: the library's [`DrnForm`], as a value of the option.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrnFormArg {
    /// Payoffs as rewards: `R{"r"}max=? [C]` is the value.
    Reward,
    /// Payoffs as the probability of reaching `goal`: `r_max * Pmax=? [F "goal"]` is the value.
    Reachability,
}

impl From<DrnFormArg> for DrnForm {
    fn from(form: DrnFormArg) -> DrnForm {
        match form {
            DrnFormArg::Reward => DrnForm::Reward,
            DrnFormArg::Reachability => DrnForm::Reachability,
        }
    }
}

/// Options of the opportunistic (MDP) stage.
#[derive(clap::Args, Debug)]
#[group(id = "opportunistic")]
pub struct Args {
    /// The adversary's distribution where it believes it has lost: uniform, or random weights
    /// drawn from `--seed`.
    #[arg(
        help_heading = "Adversary model",
        long,
        value_enum,
        default_value = "random"
    )]
    pub sigma_l: SigmaLKind,
    /// Seed of the random weights and of the simulation.
    #[arg(help_heading = "Adversary model", long, default_value_t = 2019)]
    pub seed: u64,
    /// Read sigma_L's weights from FILE (`STATE ACTION WEIGHT` lines), instead of --sigma-l.
    #[arg(
        help_heading = "Adversary model",
        long,
        value_name = "FILE",
        conflicts_with = "sigma_l"
    )]
    pub adversary: Option<String>,
    /// Learn sigma_L from the observed runs in FILE (`s0 a0 s1 a1 ... sn` per line) and add
    /// the robust value and controller to the report; --sigma-l/--adversary then give the
    /// model --simulate runs the robust controller against.
    #[arg(help_heading = "Adversary model", long, value_name = "FILE")]
    pub observations: Option<String>,
    /// With --observations: the learnt region holds with probability at least 1 - D.
    #[arg(
        help_heading = "Adversary model",
        long,
        value_name = "D",
        default_value_t = DEFAULT_DELTA,
        requires = "observations"
    )]
    pub delta: f64,
    /// Payoff of phi1.
    #[arg(help_heading = "Payoffs and solver", long, default_value_t = 200.0)]
    pub r1: f64,
    /// Payoff of phi2.
    #[arg(help_heading = "Payoffs and solver", long, default_value_t = 100.0)]
    pub r2: f64,
    /// Payoff of phi (at least r1 + r2).
    #[arg(help_heading = "Payoffs and solver", long, default_value_t = 300.0)]
    pub r: f64,
    /// Discount g per robot move, 0 < g <= 1.
    #[arg(help_heading = "Payoffs and solver", long, default_value_t = 1.0)]
    pub discount: f64,
    /// Certified bound on the error of the values.
    #[arg(help_heading = "Payoffs and solver", long, default_value_t = 1e-6)]
    pub epsilon: f64,
    /// Certified bound on the error of the values relative to each value (Storm's and PRISM's
    /// default precision), instead of --epsilon: every state's bounds at most E times its lower
    /// bound apart.
    #[arg(
        help_heading = "Payoffs and solver",
        long,
        value_name = "E",
        conflicts_with = "epsilon"
    )]
    pub relative_epsilon: Option<f64>,
    /// Sweeps of value iteration after which the solver gives up.
    #[arg(help_heading = "Payoffs and solver", long, value_name = "N", default_value_t = SolveOptions::default().max_iterations)]
    pub max_iterations: u32,
    /// Print the decision table of STATE (`--explain=ARENA_STATE|Q1|Q2`; default h0). The `=`
    /// is required, so that `--explain ARENA` leaves ARENA to the main form.
    #[arg(help_heading = "Explanation and simulation", 
        long,
        value_name = "STATE",
        num_args = 0..=1,
        require_equals = true,
        default_missing_value = "h0"
    )]
    pub explain: Option<String>,
    /// Simulate N runs (N >= 1) of the controller against the adversary model.
    #[arg(
        help_heading = "Explanation and simulation",
        long,
        value_name = "N",
        value_parser = clap::value_parser!(u32).range(1..)
    )]
    pub simulate: Option<u32>,
    /// With --simulate: write the simulated runs to FILE in the observations format (for
    /// --observations), the controller against sigma_L of --sigma-l/--adversary.
    #[arg(
        help_heading = "Output",
        long,
        value_name = "FILE",
        requires = "simulate"
    )]
    pub record: Option<PathBuf>,
    /// With --observations: also write the learning curve as SVG into FILE (atomically), the
    /// robust and nominal value of h0 learnt from the first 1, 2, 5, 10, ... runs and from all
    /// of them (--learning-curve-runs), with its table in the report.
    #[arg(
        help_heading = "Output",
        long,
        value_name = "FILE",
        requires = "observations"
    )]
    pub learning_curve: Option<PathBuf>,
    /// With --observations: also write the learning curve as PNG into FILE (atomically), at
    /// --dpi, with the bundled font.
    #[arg(
        help_heading = "Output",
        long,
        value_name = "FILE",
        requires = "observations"
    )]
    pub learning_curve_png: Option<PathBuf>,
    /// With --observations: the numbers of runs the learning curve learns from, increasing,
    /// each at most the number of runs observed (the first N runs of the file) [default: 1, 2,
    /// 5, 10, ... and all]; without a picture, the curve's table alone joins the report.
    #[arg(
        help_heading = "Adversary model",
        long,
        value_name = "N,N,...",
        requires = "observations",
        value_parser = parse_runs
    )]
    pub learning_curve_runs: Option<CurveRuns>,
    /// Print one simulated run state by state.
    #[arg(help_heading = "Explanation and simulation", long)]
    pub trace: bool,
    /// Step bound of simulated runs.
    #[arg(
        help_heading = "Explanation and simulation",
        long,
        default_value_t = 1000
    )]
    pub max_steps: u32,
    /// Write the hypergame MDP in Storm's DRN format to FILE (with --observations: the interval
    /// MDP of the learnt region), in the form --drn-form gives.
    #[arg(help_heading = "Output", long, value_name = "FILE")]
    pub export_mdp: Option<PathBuf>,
    /// How --export-mdp encodes the payoffs: `reward` (rewards; Storm's `R{"r"}max=? [C]` is
    /// the value) or `reachability` (a state `goal` reached with probability payoff / r_max;
    /// r_max times `Pmax=? [F "goal"]` is the value). Storm 2.0 reads the interval model of
    /// --observations in both forms, but its interval checker refuses total-reward formulas:
    /// check it in reachability form (`uncertainty_resolution_mode` ROBUST).
    #[arg(
        help_heading = "Output",
        long,
        value_enum,
        value_name = "FORM",
        default_value = "reward",
        requires = "export_mdp"
    )]
    pub drn_form: DrnFormArg,
    /// With --export-mdp, keep only the controller's choices: the Markov chain it induces,
    /// whose value in Storm is the controller's own (`policy_value`).
    #[arg(
        help_heading = "Output",
        long,
        requires = "export_mdp",
        conflicts_with = "observations"
    )]
    pub induced: bool,
    /// Write the opportunistic controller to FILE (JSON, format hypersynth-controller/2), for
    /// `hypersynth execute` or a robot's own executor.
    #[arg(help_heading = "Output", long, value_name = "FILE")]
    pub export_controller: Option<PathBuf>,
    /// With --export-controller: the robot states it decides at, `reachable` from h0 when the
    /// robot follows it, or `all`, so that `hypersynth execute` goes on after a robot move
    /// other than the one answered (a slip).
    #[arg(
        help_heading = "Output",
        long,
        value_name = "SCOPE",
        value_enum,
        default_value_t = ScopeArg::Reachable,
        requires = "export_controller"
    )]
    pub controller_scope: ScopeArg,
    /// Add to the exported controller a certificate of its value's bounds, which `hypersynth
    /// check FILE` checks from the file alone.
    #[arg(help_heading = "Output", long, requires = "export_controller")]
    pub certificate: bool,
}

/// The runs of `--learning-curve-runs`, a list (a newtype, so that clap takes it as one value).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CurveRuns(Vec<usize>);

fn parse_runs(text: &str) -> Result<CurveRuns, String> {
    let runs = text
        .split(',')
        .map(|s| s.trim().parse::<usize>().ok().filter(|&n| n > 0))
        .collect::<Option<Vec<usize>>>()
        .ok_or_else(|| format!("`{text}` is not a list of numbers of runs such as `1,10,100`"))?;
    if runs.windows(2).any(|w| w[0] >= w[1]) {
        return Err(format!("`{text}`: the numbers of runs must increase"));
    }
    Ok(CurveRuns(runs))
}

/// The MDP stage's options as the library's specification: `--adversary`'s weights file and
/// `--observations`' runs are read here (and checked by the library against the arena).
pub fn spec(args: &Args) -> anyhow::Result<MdpSpec> {
    let sigma_l = match (&args.adversary, args.sigma_l) {
        (Some(path), _) => SigmaLSpec::WeightsFile {
            name: path.clone(),
            text: read_input(path).with_context(|| format!("{path}: cannot read"))?,
        },
        (None, SigmaLKind::Uniform) => SigmaLSpec::Value(SigmaL::Uniform),
        (None, SigmaLKind::Random) => SigmaLSpec::Value(SigmaL::Random { seed: args.seed }),
    };
    let learnt = match &args.observations {
        Some(path) => Some(LearntSpec {
            name: path.clone(),
            text: read_input(path).with_context(|| format!("{path}: cannot read"))?,
            delta: args.delta,
        }),
        None => None,
    };
    Ok(MdpSpec {
        sigma_l,
        seed: args.seed,
        discount: args.discount,
        precision: match args.relative_epsilon {
            Some(epsilon) => Precision::Relative(epsilon),
            None => Precision::Absolute(args.epsilon),
        },
        max_iterations: args.max_iterations,
        learnt,
    })
}

/// An error of the MDP stage's options of `spec` (the one [`spec`] made): the files' located
/// in them, the others after the option that gave them.
pub fn error(spec: &MdpSpec, field: &Field, kind: SpecErrorKind) -> anyhow::Error {
    match (field, kind, &spec.sigma_l, &spec.learnt) {
        (
            Field::Weights,
            SpecErrorKind::WeightsFile(errors),
            SigmaLSpec::WeightsFile { name, text },
            _,
        ) => super::output::located(&Source::new(name, text), &errors),
        (Field::Observations, SpecErrorKind::Observations(errors), _, Some(learnt)) => {
            super::output::located(&Source::new(&learnt.name, &learnt.text), &errors)
        }
        (Field::Discount, SpecErrorKind::Solve(error), ..) => {
            anyhow::Error::new(error).context("--discount")
        }
        (_, SpecErrorKind::Solve(error), ..) => error.into(),
        (_, kind, ..) => kind.into(),
    }
}

/// A failed MDP stage as the CLI reports it: the options to change when the solver or the
/// evaluation ran out of sweeps; runs that do not fit the game located in the observations of
/// `spec`. (The adversary file's errors are found when the specification is built.)
pub fn stage_error(args: &Args, spec: Option<&MdpSpec>, error: StageError) -> anyhow::Error {
    match &error {
        StageError::Solve(SolveError::IterationLimit { .. }) | StageError::Evaluation(_) => {
            anyhow::anyhow!(
                "{error}; raise --max-iterations (now {}) or {}",
                args.max_iterations,
                if args.relative_epsilon.is_some() {
                    "--relative-epsilon"
                } else {
                    "--epsilon"
                }
            )
        }
        StageError::Observations(errors) => match spec.and_then(|spec| spec.learnt.as_ref()) {
            Some(learnt) => {
                super::output::located(&Source::new(&learnt.name, &learnt.text), errors)
            }
            None => anyhow::anyhow!(
                "{}: {error}",
                args.observations.as_deref().unwrap_or_default()
            ),
        },
        StageError::Region(_) => anyhow::anyhow!("--delta: {error}"),
        StageError::CurveWithoutRuns => anyhow::anyhow!(
            "{}: {error}",
            args.observations.as_deref().unwrap_or_default()
        ),
        StageError::CurveRuns { .. } => anyhow::anyhow!(
            "--learning-curve-runs: {error} in {}",
            args.observations.as_deref().unwrap_or_default()
        ),
        _ => error.into(),
    }
}

/// A `--explain=STATE` that names no product state, located in the option's value with a caret.
pub fn explain_error(args: &Args, error: StateNameError) -> anyhow::Error {
    let text = args.explain.as_deref().unwrap_or_default();
    let position = match &error {
        StateNameError::Malformed(position, _)
        | StateNameError::UnknownArenaState(position, _)
        | StateNameError::Unreachable(position, _)
        | StateNameError::NoSuchDfaState { position, .. }
        | StateNameError::NotEnumerated { position, .. } => *position,
    };
    // The error's text is `LINE:COL: message`.
    let shown = error.to_string();
    let message = shown
        .strip_prefix(&format!("{position}: "))
        .unwrap_or(&shown);
    super::output::located_at(&Source::new("--explain", text), position, message)
}

/// The learning curve the options ask for, drawn when a file is given, with `title`.
fn curve(args: &Args, title: TitleChoice) -> Option<CurveRequest> {
    let drawn = args.learning_curve.is_some() || args.learning_curve_png.is_some();
    if !drawn && args.learning_curve_runs.is_none() {
        return None;
    }
    Some(CurveRequest {
        runs: args
            .learning_curve_runs
            .as_ref()
            .map_or_else(Vec::new, |runs| runs.0.clone()),
        picture: drawn.then_some(title),
    })
}

/// What the report adds (decision table, simulations, trace, learning curve) and whether to
/// export the MDP; `title` is the learning curve's.
pub fn requests(args: &Args, title: TitleChoice) -> Requests {
    Requests {
        explain: args.explain.clone(),
        simulate: args.simulate,
        trace: args.trace,
        max_steps: args.max_steps,
        export_mdp: args.export_mdp.is_some(),
        induced: args.induced,
        drn_form: args.drn_form.into(),
        export_controller: args.export_controller.is_some(),
        controller_scope: args.controller_scope.into(),
        certificate: args.certificate,
        record: args.record.is_some(),
        learning_curve: curve(args, title),
        ..Requests::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hypersynth::arena::{Arena, ArenaBuilder, Owner};
    use hypersynth::automata::testing::eventually;
    use hypersynth::game::{Payoffs, States};
    use hypersynth::pipeline::{self, PipelineError, Problem, Task, Tasks};
    use hypersynth::report::Synthesis;

    /// Robot `r` moves `go` to adversary `a`, which moves `x` back to `r` or `y` to robot `g`
    /// (labelled A and B, with a self-loop `stay`).
    fn arena() -> Arena {
        let mut b = ArenaBuilder::new();
        let r = b.add_state("r", Owner::Robot, [], None).unwrap();
        let a = b.add_state("a", Owner::Adversary, [], None).unwrap();
        let g = b.add_state("g", Owner::Robot, ["A", "B"], None).unwrap();
        for (from, action, to) in [(r, "go", a), (a, "x", r), (a, "y", g), (g, "stay", g)] {
            b.add_transition(from, action, to).unwrap();
        }
        b.set_initial(r);
        b.build().unwrap()
    }

    fn args(adversary: Option<String>, export: Option<PathBuf>) -> Args {
        Args {
            sigma_l: SigmaLKind::Uniform,
            seed: 1,
            adversary,
            observations: None,
            delta: DEFAULT_DELTA,
            r1: 200.0,
            r2: 100.0,
            r: 300.0,
            discount: 1.0,
            epsilon: 1e-6,
            relative_epsilon: None,
            max_iterations: 100_000,
            explain: None,
            simulate: None,
            record: None,
            trace: false,
            max_steps: 10,
            export_mdp: export,
            drn_form: DrnFormArg::Reward,
            induced: false,
            export_controller: None,
            controller_scope: ScopeArg::Reachable,
            certificate: false,
            learning_curve: None,
            learning_curve_png: None,
            learning_curve_runs: None,
        }
    }

    fn run_on(args: &Args) -> anyhow::Result<(Synthesis, Option<String>)> {
        let tasks = Tasks::from_parts(
            Task::from_automaton("F A", &eventually("A")),
            Task::from_automaton("F B", &eventually("B")),
            Payoffs::default(),
        );
        let arena = arena();
        let spec = spec(args)?;
        let options = spec
            .build(&arena)
            .map_err(|e| error(&spec, &e.field, *e.kind))?;
        let problem = Problem {
            arena_name: "arena".to_string(),
            arena,
            map: None,
            tasks,
            states: States::Full,
            mdp: Some(options),
        };
        let requests = requests(args, TitleChoice::Default);
        let outcome = pipeline::run(&problem, &requests, &mut ()).map_err(|e| match e {
            PipelineError::Stage(e) => stage_error(args, Some(&spec), e),
            other => other.into(),
        })?;
        let synthesis = outcome
            .report
            .synthesis
            .expect("the MDP stage was asked for");
        Ok((synthesis, outcome.drn))
    }

    #[test]
    fn weights_file_errors_name_the_file_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("weights.txt");
        std::fs::write(&path, "# weights\na  z 1\n").unwrap();
        let path = path.to_str().unwrap().to_string();
        let error = run_on(&args(Some(path.clone()), None)).unwrap_err();
        assert_eq!(
            error.to_string(),
            format!(
                "{path}:2:4: action `z` is not enabled in adversary state `a`\n    a  z 1\n       ^"
            )
        );
    }

    #[test]
    fn export_gives_the_drn_of_the_solved_mdp() {
        let (report, drn) = run_on(&args(None, Some(PathBuf::from("mdp.drn")))).unwrap();
        // The adversary can answer x forever, so h0 is (L, L, L), and in `a` (outside
        // Win(phi1)) sigma_W plays its only safe action x: the robot never reaches g, value 0.
        assert_eq!(report.decision.value, 0.0);
        assert_eq!(report.mdp.robot_states, 8);
        let text = drn.expect("asked for");
        assert!(text.starts_with("// hypersynth MDP"));
        assert!(text.contains("@type: MDP"));
    }
}
