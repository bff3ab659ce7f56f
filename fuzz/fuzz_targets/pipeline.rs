//! The main form on small random problems: an arena of at most 6 states over the propositions
//! `a` and `b`, two co-safe formulas of depth at most 3 over them, either enumeration, either
//! adversary model and a random discount, through `pipeline::run` with simulations, a trace,
//! the DRN (in either form) and strategy exports. Every such problem must be solved: no panic, no limit reached
//! (the translation's limits are small but far above what these formulas need, and the
//! solver's sweeps are plenty for these MDPs), reports that format, and an exported controller
//! that reads back.
#![no_main]

use hypersynth::arena::{ArenaBuilder, Owner};
use hypersynth::game::{Payoffs, States};
use hypersynth::ltl;
use hypersynth::mdp::DrnForm;
use hypersynth::mdp::solve::{Discount, SolveOptions};
use hypersynth::opportunistic::adversary::SigmaL;
use hypersynth::opportunistic::executor::Executor;
use hypersynth::pipeline::{self, MdpOptions, Problem, Requests, Tasks};
use hypersynth::translate::{Builtin, Translator};
use libfuzzer_sys::arbitrary::{Result, Unstructured};
use libfuzzer_sys::fuzz_target;

/// A co-safe formula over `a` and `b` (and constants) of depth at most `depth`.
fn formula(u: &mut Unstructured, depth: u32) -> Result<String> {
    let literal = |u: &mut Unstructured| -> Result<String> {
        Ok(match u.int_in_range(0..=5)? {
            0 => "a".into(),
            1 => "b".into(),
            2 => "!a".into(),
            3 => "!b".into(),
            4 => "true".into(),
            _ => "false".into(),
        })
    };
    if depth == 0 || u.ratio(1, 3)? {
        return literal(u);
    }
    let left = formula(u, depth - 1)?;
    Ok(match u.int_in_range(0..=7)? {
        0 => format!("X({left})"),
        1 => format!("F({left})"),
        2 => format!("({left}) U ({})", formula(u, depth - 1)?),
        3 => format!("({left}) M ({})", formula(u, depth - 1)?),
        4 => format!("({left}) & ({})", formula(u, depth - 1)?),
        5 => format!("({left}) | ({})", formula(u, depth - 1)?),
        6 => format!("!G!({left})"),
        // Both polarities under `<->`: co-safe only over literals.
        _ => format!("({}) <-> X({})", literal(u)?, literal(u)?),
    })
}

/// The problem the bytes describe (an error when they run out first).
fn problem(u: &mut Unstructured) -> Result<(Problem, Requests)> {
    let mut builder = ArenaBuilder::new();
    let states = u.int_in_range(1..=6)?;
    let mut ids = Vec::new();
    for i in 0..states {
        let owner = if u.arbitrary()? {
            Owner::Robot
        } else {
            Owner::Adversary
        };
        let label: Vec<&str> = [("a", u.arbitrary::<bool>()?), ("b", u.arbitrary()?)]
            .into_iter()
            .filter_map(|(p, holds)| holds.then_some(p))
            .collect();
        ids.push(
            builder
                .add_state(&format!("s{i}"), owner, label, None)
                .expect("distinct names"),
        );
    }
    for &from in &ids {
        // Each state moves somewhere (a stuck state is allowed too, one time in eight).
        let moves = if u.ratio(1, 8)? {
            0
        } else {
            u.int_in_range(1..=3)?
        };
        for m in 0..moves {
            let to = ids[u.choose_index(states)?];
            builder
                .add_transition(from, &format!("m{m}"), to)
                .expect("one successor per action");
        }
    }
    builder.set_initial(ids[u.choose_index(states)?]);
    let arena = builder.build().expect("a well-formed arena");
    let (phi1, phi2) = (formula(u, 3)?, formula(u, 3)?);
    let phi = ltl::parse(&format!("({phi1}) & ({phi2})")).expect("a formula");
    let psi = ltl::parse(&phi1).expect("a formula");
    let translator = Builtin::new(hypersynth_fuzz::limits());
    let tasks = match Tasks::from_formulas(
        &phi,
        &psi,
        None,
        &translator as &dyn Translator,
        Payoffs::default(),
    ) {
        Ok(tasks) => tasks,
        // `(x) & (x)` is one conjunct, and psi may then be all of phi: phi2 is true. Any other
        // failure is a finding.
        Err(error) => panic!("{phi} / {psi}: {error}"),
    };
    let sigma_l = if u.arbitrary()? {
        SigmaL::Uniform
    } else {
        SigmaL::Random {
            seed: u.arbitrary()?,
        }
    };
    let discount = [1.0, 0.99, 0.9, 0.5][u.choose_index(4)?];
    let mdp = MdpOptions {
        sigma_l,
        seed: u.arbitrary()?,
        solve: SolveOptions {
            discount: Discount::new(discount).expect("a discount in (0, 1]"),
            ..SolveOptions::default()
        },
        learnt: None,
    };
    let problem = Problem {
        arena_name: "fuzz".into(),
        arena,
        map: None,
        tasks,
        states: if u.arbitrary()? {
            States::Full
        } else {
            States::Reachable
        },
        mdp: u.ratio(7, 8)?.then_some(mdp),
    };
    let requests = Requests {
        simulate: Some(3),
        trace: true,
        max_steps: 20,
        export_mdp: true,
        drn_form: if u.arbitrary()? {
            DrnForm::Reachability
        } else {
            DrnForm::Reward
        },
        export_strategy: true,
        export_controller: true,
        explain: Some("h0".into()),
        ..Requests::default()
    };
    Ok((problem, requests))
}

fuzz_target!(|data: &[u8]| {
    let Ok((problem, requests)) = problem(&mut Unstructured::new(data)) else {
        return;
    };
    let outcome =
        pipeline::run(&problem, &requests, &mut ()).unwrap_or_else(|error| panic!("{error}"));
    let _ = outcome.report.to_string();
    let _ = outcome.report.to_json(None).expect("a JSON report");
    if let Some(controller) = &outcome.controller {
        Executor::from_json(controller).unwrap_or_else(|error| panic!("{error}\n{controller}"));
    }
});
