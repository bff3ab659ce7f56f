//! The progress protocol of `hypersynth::stage` on the case study: what an observer hears
//! (coarse, `done` non-decreasing and at most a fixed `total`, only for the running stage), that
//! the stages run in parallel give the results of a one-thread pool (that the command shows
//! nothing on standard error off a terminal is the command's `tests/main_form.rs`).

use crate::common;

use hypersynth::arena;
use hypersynth::game::{Hypergame, Payoffs, States, SubsetPayoffs};
use hypersynth::ltl;
use hypersynth::mdp::solve::{Discount, SolveOptions, solve, solve_observed};
use hypersynth::mdp::{Mdp, MdpBuilder, MdpState};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::build::{HypergameMdp, Risk};
use hypersynth::opportunistic::controller::Controller;
use hypersynth::opportunistic::evaluate::ControllerEvaluation;
use hypersynth::pipeline::{self, MdpOptions, Problem, Requests, Tasks};
use hypersynth::stage::{Meter, Observer, Stage};
use hypersynth::translate::{Builtin, TranslationLimits};

const ARENA: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../specs/case-study/arena.txt"
));

/// Every report, checked against the stage running.
#[derive(Default)]
struct Recorder {
    running: Option<Stage>,
    reports: Vec<(Stage, u64, u64)>,
}

impl Observer for Recorder {
    fn started(&mut self, stage: Stage) {
        assert_eq!(self.running, None, "{stage:?} starts inside another stage");
        self.running = Some(stage);
    }

    fn progress(&mut self, stage: Stage, done: u64, total: u64) {
        assert_eq!(self.running, Some(stage), "progress outside its stage");
        self.reports.push((stage, done, total));
    }

    fn finished(&mut self, stage: Stage, _seconds: f64) {
        assert_eq!(self.running, Some(stage));
        self.running = None;
    }
}

impl Recorder {
    /// Checks the protocol for `stage` and returns its (done, total) reports.
    fn check(&self, stage: Stage) -> Vec<(u64, u64)> {
        let reports: Vec<(u64, u64)> = self
            .reports
            .iter()
            .filter(|r| r.0 == stage)
            .map(|&(_, done, total)| (done, total))
            .collect();
        assert!(reports.len() >= 2, "{stage:?}: {reports:?}");
        assert!(reports.len() <= 260, "{stage:?}: {} reports", reports.len());
        let total = reports[0].1;
        assert!(total > 0);
        assert_eq!(reports[0].0, 0, "{stage:?} starts at 0");
        for pair in reports.windows(2) {
            assert!(pair[0].0 <= pair[1].0, "{stage:?} goes back: {pair:?}");
        }
        for &(done, t) in &reports {
            assert_eq!(t, total, "{stage:?} changes its total");
            assert!(done <= total, "{stage:?}: {done} > {total}");
        }
        reports
    }
}

fn case_study(observer: &mut Recorder) -> Problem {
    let parsed = observer.started_parse();
    let translator = Builtin::new(TranslationLimits::default());
    let phi = ltl::parse("(!O U A) & (!O U B)").unwrap();
    let psi = ltl::parse("!O U A").unwrap();
    Problem {
        arena_name: "arena.txt".into(),
        arena: parsed,
        map: None,
        tasks: Tasks::from_formulas(&phi, &psi, None, &translator, Payoffs::default()).unwrap(),
        states: States::Full,
        mdp: Some(MdpOptions {
            sigma_l: SigmaL::Random { seed: 1 },
            seed: 1,
            solve: SolveOptions::default(),
            learnt: None,
        }),
    }
}

impl Recorder {
    /// Reads the case study's arena as the `parse` stage.
    fn started_parse(&mut self) -> arena::Arena {
        hypersynth::stage::metered(self, Stage::Parse, |meter| {
            arena::parse_metered(ARENA, meter).unwrap().arena
        })
    }
}

#[test]
fn the_observer_hears_coarse_non_decreasing_progress_below_a_fixed_total() {
    let mut recorder = Recorder::default();
    let problem = case_study(&mut recorder);
    let requests = Requests {
        simulate: Some(1000),
        max_steps: 100,
        ..Requests::default()
    };
    pipeline::run(&problem, &requests, &mut recorder).unwrap();
    assert_eq!(recorder.running, None);
    // The arena is read twice: its bytes count twice, and the last line is reached.
    let parse = recorder.check(Stage::Parse);
    assert_eq!(parse[0].1, 2 * ARENA.len() as u64);
    assert!(parse.last().unwrap().0 > ARENA.len() as u64);
    // Every state of the product is dealt with by each of the three attractors.
    let attractors = recorder.check(Stage::Attractors);
    assert_eq!(attractors.last().unwrap().0, attractors[0].1);
    // The MDP build counts the product states it has dealt with, each twice (counted, then
    // written), all of them in the end.
    let build = recorder.check(Stage::MdpBuild);
    assert_eq!(build[0].1, 2 * attractors[0].1 / 3);
    assert_eq!(build.last().unwrap().0, build[0].1);
    // The product counts its states once per pass over them that builds the predecessor lists.
    let product = recorder.check(Stage::Product);
    assert_eq!(product[0].1, 2 * attractors[0].1 / 3);
    assert_eq!(product.last().unwrap().0, product[0].1);
    // The solver counts the MDP's states twice: once through its preprocessing, once (scaled)
    // as the components are solved; all of them in the end. The MDP has the product's states
    // and two sinks.
    let solve = recorder.check(Stage::Solve);
    assert_eq!(solve[0].1, 2 * (build[0].1 / 2 + 2));
    assert_eq!(solve.last().unwrap().0, solve[0].1);
    // The policy (g = 1) counts the MDP's states once per phase: ties, ranking, expected moves
    // and the choice itself.
    let policy = recorder.check(Stage::Policy);
    assert_eq!(policy[0].1, 4 * (build[0].1 / 2 + 2));
    assert_eq!(policy.last().unwrap().0, policy[0].1);
    let evaluation = recorder.check(Stage::Evaluation);
    assert_eq!(evaluation.last().unwrap().0, evaluation[0].1);
    let simulation = recorder.check(Stage::Simulation);
    assert_eq!(simulation[0].1, 1000);
}

#[test]
fn the_general_form_reports_its_product_attractors_mdp_build_evaluation_and_simulation() {
    let mut recorder = Recorder::default();
    let arena = recorder.started_parse();
    let (tasks, believed) =
        common::translated_subtasks(&[("A", "!O U A"), ("B", "!O U B")], "(!O U A) & (!O U B)");
    let names = ["A".to_string(), "B".to_string()];
    // A correctly informed adversary: not the paper's preset.
    let payoffs = SubsetPayoffs::new(&[200.0, 100.0], &[], &names).unwrap();
    let tasks = Tasks::new(tasks, payoffs, believed, Risk::Paper);
    assert!(tasks.presentation().whole_task().is_none());
    let problem = Problem {
        arena_name: "arena.txt".into(),
        arena,
        map: None,
        tasks,
        states: States::Full,
        mdp: Some(MdpOptions {
            sigma_l: SigmaL::Random { seed: 1 },
            seed: 1,
            solve: SolveOptions::default(),
            learnt: None,
        }),
    };
    let requests = Requests {
        simulate: Some(500),
        max_steps: 100,
        ..Requests::default()
    };
    pipeline::run(&problem, &requests, &mut recorder).unwrap();
    for stage in [
        Stage::Product,
        Stage::Attractors,
        Stage::MdpBuild,
        Stage::Evaluation,
        Stage::Simulation,
    ] {
        recorder.check(stage);
    }
}

/// A ring of `n` decision states, each moving on with probability 0.95 and otherwise to an
/// absorbing state of payoff 1 (probability 0.04) or 0 (0.01): all of them one strongly
/// connected component worth 0.8 (less than the largest payoff they can reach, so that the
/// solver must iterate).
fn ring(n: usize) -> Mdp {
    let mut builder = MdpBuilder::new();
    let go = builder.action("go").unwrap();
    let (payoff, loss) = (MdpState::new(n), MdpState::new(n + 1));
    for i in 0..n {
        builder.add_decision_state().unwrap();
        let next = MdpState::new((i + 1) % n);
        builder
            .add_choice(go, &[(next, 0.95), (payoff, 0.04), (loss, 0.01)])
            .unwrap();
    }
    builder.add_absorbing_state(1.0).unwrap();
    builder.add_absorbing_state(0.0).unwrap();
    builder.set_initial(MdpState::new(0));
    builder.build().unwrap()
}

#[test]
fn the_solver_reports_progress_inside_a_component_and_through_the_policy() {
    let n = 20_000;
    let mdp = ring(n);
    for g in [1.0, 0.99] {
        let mut recorder = Recorder::default();
        let options = SolveOptions {
            discount: Discount::new(g).unwrap(),
            ..SolveOptions::default()
        };
        let solution = solve_observed(&mdp, &options, &mut recorder).unwrap();
        assert!(solution.iterations() > 10, "{}", solution.iterations());
        // The n + 2 states twice, the second time as the one component of all n decision
        // states is solved: per solved component, the bar would jump from halfway to the end;
        // it moves with the gap instead.
        let states = n as u64 + 2;
        let solve = recorder.check(Stage::Solve);
        assert_eq!(solve[0].1, 2 * states);
        assert_eq!(solve.last().unwrap().0, 2 * states);
        let inside = solve.iter().filter(|r| r.0 > states && r.0 < r.1).count();
        assert!(inside >= 5, "g = {g}: {solve:?}");
        // The policy counts the states, once per phase at g = 1 (four of them).
        let phases = if g == 1.0 { 4 } else { 1 };
        let policy = recorder.check(Stage::Policy);
        assert_eq!(policy[0].1, phases * states);
        assert_eq!(policy.last().unwrap().0, policy[0].1);
        let inside = policy.iter().filter(|r| r.0 > 0 && r.0 < r.1).count();
        assert!(inside >= 5, "g = {g}: {policy:?}");
    }
}

#[test]
fn a_meter_reports_at_most_about_256_times_and_never_goes_back() {
    let mut recorder = Recorder::default();
    hypersynth::stage::metered(&mut recorder, Stage::Solve, |meter: &mut Meter<'_>| {
        meter.set_total(1_000_000);
        meter.set_total(5); // ignored: the total is fixed
        for _ in 0..1_000_000 {
            meter.advance(1);
        }
        meter.set(10); // ignored: below the count
        meter.advance(1_000_000); // clamped to the total
    });
    let reports = recorder.check(Stage::Solve);
    assert_eq!(reports.last(), Some(&(1_000_000, 1_000_000)));
    assert!(reports.len() <= 258, "{}", reports.len());
    // Parallel jobs report through their tally, from the calling thread.
    let mut recorder = Recorder::default();
    let sums = hypersynth::stage::metered(&mut recorder, Stage::Attractors, |meter| {
        meter.set_total(4 * 100_000);
        let jobs: Vec<_> = (0..4u64)
            .map(|job| {
                move |tally: &hypersynth::stage::Tally| {
                    let mut sum = 0;
                    for i in 0..100_000u64 {
                        sum += i * job;
                        if i % 1000 == 999 {
                            tally.add(1000);
                        }
                    }
                    sum
                }
            })
            .collect();
        meter.parallel(jobs)
    });
    assert_eq!(
        sums,
        (0..4).map(|j| j * 4_999_950_000).collect::<Vec<u64>>()
    );
    assert_eq!(
        recorder.check(Stage::Attractors).last(),
        Some(&(400_000, 400_000))
    );
}

#[test]
fn parallel_stages_give_the_results_of_one_thread() {
    let mut recorder = Recorder::default();
    let problem = case_study(&mut recorder);
    let game = problem
        .tasks
        .hypergame(&problem.arena, States::Full)
        .unwrap();
    let evaluate = |game: &Hypergame| {
        let paper = common::PaperGame::new(game);
        let solved = paper.view(game);
        let adversary = AdversaryModel::new(&solved, &SigmaL::Random { seed: 7 }).unwrap();
        let mdp = HypergameMdp::build(&solved, &adversary, Risk::Paper).unwrap();
        let solution = solve(mdp.mdp(), &SolveOptions::default()).unwrap();
        let controller = Controller {
            game: &solved,
            mdp: &mdp,
            solution: &solution,
        };
        let evaluation = ControllerEvaluation::new(&controller, &adversary, 1e-9, 100_000).unwrap();
        let values: Vec<_> = game
            .states()
            .map(|h| (evaluation.value(h), evaluation.expected_moves(h)))
            .collect();
        (paper.regions, format!("{values:?}"))
    };
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let sequential = one.install(|| evaluate(&game));
    let parallel = evaluate(&game);
    assert!(sequential.0 == parallel.0, "the attractors differ");
    assert_eq!(sequential.1, parallel.1, "the evaluations differ");
}
