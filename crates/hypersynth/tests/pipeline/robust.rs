//! The robust stage of the pipeline (sigma_L learnt from observations) asks the observer for
//! its memory before each allocation, and a refusal is a clean error (the command's
//! `--observations` is the root package's `tests/robust.rs`).

use hypersynth::testing::RETRY_ARENA;

/// An observer that refuses every memory reservation from the `refuse_from`-th on (counting
/// from 0), as a ceiling of 0 bytes would, and records what each was for.
struct Refusing {
    refuse_from: usize,
    asked: Vec<String>,
}

impl hypersynth::stage::Observer for Refusing {
    fn reserve(
        &mut self,
        _stage: hypersynth::stage::Stage,
        bytes: u64,
        what: &dyn Fn() -> String,
    ) -> Result<(), hypersynth::limits::MemoryLimit> {
        let ceiling = if self.asked.len() >= self.refuse_from {
            0
        } else {
            u64::MAX
        };
        self.asked.push(what());
        hypersynth::limits::MemoryBudget::new(ceiling).check(0, bytes, what)
    }
}

/// The retry arena's problem in the paper's form (phi1 = F A, phi2 = F B, psi = phi1) with
/// sigma_L learnt from one run.
fn retry_problem() -> hypersynth::pipeline::Problem {
    use hypersynth::game::{Payoffs, States};
    use hypersynth::mdp::SolveOptions;
    use hypersynth::opportunistic::adversary::SigmaL;
    use hypersynth::opportunistic::observations::Observations;
    use hypersynth::pipeline::{Learnt, MdpOptions, Problem, Task, Tasks};
    let eventually = crate::common::eventually;
    Problem {
        arena_name: "retry".to_string(),
        arena: hypersynth::arena::parse(RETRY_ARENA).unwrap().arena,
        map: None,
        tasks: Tasks::from_parts(
            Task::from_automaton("F A", &eventually("A")),
            Task::from_automaton("F B", &eventually("B")),
            Payoffs::default(),
        ),
        states: States::Full,
        mdp: Some(MdpOptions {
            sigma_l: SigmaL::Uniform,
            seed: 1,
            solve: SolveOptions::default(),
            learnt: Some(Learnt {
                observations: Observations::parse("r go a x g\n").unwrap(),
                file: "runs.txt".to_string(),
                delta: 0.05,
            }),
        }),
    }
}

#[test]
fn the_robust_stage_asks_for_its_memory_and_a_refusal_is_a_clean_error() {
    use hypersynth::mdp::SolveError;
    use hypersynth::pipeline::{self, PipelineError, Requests};
    use hypersynth::report::StageError;
    let problem = retry_problem();
    let mut all = Refusing {
        refuse_from: usize::MAX,
        asked: Vec::new(),
    };
    pipeline::run(&problem, &Requests::default(), &mut all).unwrap();
    let position = |prefix: &str| {
        all.asked
            .iter()
            .position(|what| what.starts_with(prefix))
            .unwrap_or_else(|| panic!("no reservation for {prefix}: {:?}", all.asked))
    };
    let nominal = position("solving the MDP");
    let intervals = position("the learnt region's intervals");
    let robust = position("solving the interval MDP robustly");
    let estimate = position("the MDP with the estimate's probabilities");
    let chain = position("the robust controller's chain");
    assert!(
        nominal < intervals && intervals < robust && robust < estimate && estimate < chain,
        "{:?}",
        all.asked
    );
    for (refused, prefix) in [
        (intervals, "the learnt region's intervals"),
        (robust, "solving the interval MDP robustly"),
        (estimate, "the MDP with the estimate's probabilities"),
        (chain, "the robust controller's chain"),
    ] {
        let mut observer = Refusing {
            refuse_from: refused,
            asked: Vec::new(),
        };
        let error = pipeline::run(&problem, &Requests::default(), &mut observer).unwrap_err();
        let PipelineError::Stage(StageError::Solve(SolveError::Memory(limit))) = &error else {
            panic!("{error:?}");
        };
        assert!(limit.what.starts_with(prefix), "{error}");
        assert!(
            error
                .to_string()
                .contains("more than the memory limit of 0 B"),
            "{error}"
        );
        // Nothing was asked after the refusal: the stage stopped before allocating.
        assert_eq!(observer.asked.len(), refused + 1);
    }
}
