use super::*;
use crate::opportunistic::adversary::SigmaL;
use crate::opportunistic::view::testing::ToyGame;

/// r0 `go` → a1 (outside Win(phi1): sigma_W; `x` → r2 and `y` → r3 are unsafe, `z` → r0
/// safe); r2 in Win(phi1), stuck; r3 in Win(phi1) `go` → a4 (in Win(phi1): sigma_L; `x` → r2,
/// `y` → r3). Arena state `sN` is product state N.
fn game() -> ToyGame {
    let mut g = ToyGame::new(&["go", "x", "y", "z"]);
    let r0 = g.state(true, "LLL", 1);
    let a1 = g.state(false, "LLL", 1);
    let r2 = g.state(true, "WLL", 0);
    let r3 = g.state(true, "WLL", 1);
    let a4 = g.state(false, "WLL", 1);
    g.edge(r0, "go", a1);
    g.edge(a1, "x", r2);
    g.edge(a1, "y", r3);
    g.edge(a1, "z", r0);
    g.edge(r3, "go", a4);
    g.edge(a4, "x", r2);
    g.edge(a4, "y", r3);
    g
}

fn count(text: &str) -> Result<Counts, ObservationsErrors> {
    let g = game();
    let adversary = AdversaryModel::new(&g, &SigmaL::Uniform).unwrap();
    Observations::parse(text)?.count(&g, &adversary)
}

#[test]
fn adversary_steps_are_attributed_to_sigma_l_or_sigma_w() {
    let text = "# two runs\n\
                s0 go s1 y s3 go s4 y s3 go s4 x s2\n\
                \n\
                \"s0\" go s1 z s0 go s1 x s2 # a misfit at the end\n";
    let counts = count(text).unwrap();
    assert_eq!(counts.runs, 2);
    // a4 (sigma_L) answered y then x; a1 (sigma_W) moved three times: y and x are unsafe.
    assert_eq!(counts.of(crate::arena::StateId::new(4)), Some(&[1, 1][..]));
    assert_eq!(counts.of(crate::arena::StateId::new(1)), None);
    assert_eq!(counts.of(crate::arena::StateId::new(0)), None);
    assert_eq!(counts.counted, 2);
    assert_eq!(counts.sigma_w_steps, 3);
    assert_eq!(counts.misfits, 2);
    // A run of one state has no step.
    assert_eq!(count("s0\n").unwrap().counted, 0);
}

#[test]
fn hoeffding_intervals_with_a_union_bound() {
    // 100 runs with one y and one x of a4 each: n = 200, p_hat = 1/2 for both actions; the
    // union bound is over K = 2 pairs (a4's; a1 is unobserved), so at delta = 0.05
    // e = sqrt(ln(80) / 400) = sqrt(4.382027 / 400) = 0.104666.
    let text = "s0 go s1 y s3 go s4 y s3 go s4 x s2\n".repeat(100);
    let counts = count(&text).unwrap();
    let region = Region::new(&counts, 0.05).unwrap();
    assert_eq!(region.pairs, 2);
    let a4 = crate::arena::StateId::new(4);
    for edge in 0..2 {
        assert_eq!(region.estimate(a4, edge, 2), 0.5);
        let [lower, upper] = region.interval(a4, edge, 2);
        assert!((lower - (0.5 - 0.104666)).abs() < 1e-6, "{lower}");
        assert!((upper - (0.5 + 0.104666)).abs() < 1e-6, "{upper}");
    }
    assert!(region.is_observed(a4));
    // Unobserved a1: uniform estimate, [0, 1].
    let a1 = crate::arena::StateId::new(1);
    assert!(!region.is_observed(a1));
    assert_eq!(region.estimate(a1, 2, 3), 1.0 / 3.0);
    assert_eq!(region.interval(a1, 0, 3), [0.0, 1.0]);
    // Four times the observations halve the width: e = sqrt(ln(80) / 1600) = 0.052333.
    let counts = count(&text.repeat(4)).unwrap();
    let region = Region::new(&counts, 0.05).unwrap();
    let [lower, _] = region.interval(a4, 0, 2);
    assert!((lower - (0.5 - 0.052333)).abs() < 1e-6, "{lower}");
    for delta in [0.0, 1.0, f64::NAN, -0.5] {
        assert!(Region::new(&counts, delta).is_err());
    }
}

#[test]
fn bad_observations_get_located_errors() {
    type Case = (&'static str, (usize, usize), fn(&ObservationsError) -> bool);
    let cases: [Case; 7] = [
        ("s0 go s1 \"y", (1, 10), |e| {
            matches!(e, ObservationsError::Lexical(_))
        }),
        ("s0 go s1\ns0 go", (2, 4), |e| {
            matches!(e, ObservationsError::EndsWithAction { .. })
        }),
        ("s0 go s9", (1, 7), |e| {
            matches!(e, ObservationsError::UnknownState { .. })
        }),
        ("\ns1 y s3", (2, 1), |e| {
            matches!(e, ObservationsError::NotInitial { .. })
        }),
        ("s0 go s1 w s3", (1, 10), |e| {
            matches!(e, ObservationsError::UnknownAction { .. })
        }),
        ("s0 go s1 y s2", (1, 12), |e| {
            matches!(e, ObservationsError::NotATransition { .. })
        }),
        ("s0 go s1 y s3 go s4 y s3 go s5", (1, 29), |e| {
            matches!(e, ObservationsError::UnknownState { .. })
        }),
    ];
    for (text, at, is_expected) in cases {
        let errors = count(text).unwrap_err();
        let first = errors.first();
        assert_eq!((first.position.line, first.position.column), at, "{text:?}");
        assert!(is_expected(&first.message), "{text:?}: {:?}", first.message);
    }
    // Every run is checked; the errors come in file order.
    let errors = count("s0 go s9\ns0 go s1 y s3\ns1\ns0 go s1 q s3\n").unwrap_err();
    let lines: Vec<usize> = errors.iter().map(|e| e.position.line).collect();
    assert_eq!(lines, [1, 3, 4]);
    assert_eq!(
        count("s0 go s1 y s2").unwrap_err().first().to_string(),
        "1:12: `s1` `y` leads to `s3`, not to `s2`"
    );
}

#[test]
fn a_run_line_quotes_names_as_the_arena_format_and_reads_back() {
    let mut builder = crate::arena::ArenaBuilder::new();
    let r = builder
        .add_state("r 0", crate::arena::Owner::Robot, [], None)
        .unwrap();
    let a = builder
        .add_state("a", crate::arena::Owner::Adversary, [], None)
        .unwrap();
    builder.add_transition(r, "go", a).unwrap();
    builder.add_transition(a, "back \"x\"", r).unwrap();
    builder.set_initial(r);
    let arena = builder.build().unwrap();
    let (go, back) = (
        arena.find_action("go").unwrap(),
        arena.find_action("back \"x\"").unwrap(),
    );
    let line = run_line(&arena, &[(r, go), (a, back)], r);
    assert_eq!(line, r#""r 0" go a "back \"x\"" "r 0""#);
    // Read back, it is one run of three states.
    let read = Observations::parse(&line).unwrap();
    assert_eq!(read.num_runs(), 1);
    assert_eq!(run_line(&arena, &[], a), "a");
}
