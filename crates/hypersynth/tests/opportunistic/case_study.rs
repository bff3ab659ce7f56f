//! The case study's hypergame MDP (docs/semantics.md §11), on an arena built here independently of the
//! gridworld generator: 5×5 grid, obstacles (0,1) (1,0) (1,1) (3,4) (4,3), A at (0,3), B at
//! (4,4), robot from (0,2) with king moves, adversary from (4,2) with N S E W STAY, players
//! block each other; phi1 = `!O U A`, phi2 = `!O U B`.

use crate::common::PaperGame;
use hypersynth::game::Wins;

use hypersynth::arena::{Arena, ArenaBuilder, Owner};
use hypersynth::automata::Dfa;
use hypersynth::game::{HState, Hypergame, States, TaskRegions};
use hypersynth::mdp::solve::{Discount, SolveOptions, solve};
use hypersynth::mdp::{DrnForm, MdpState, write_drn};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::build::{HypergameMdp, Risk};
use hypersynth::opportunistic::controller::{Controller, Decision};
use hypersynth::opportunistic::evaluate::ControllerEvaluation;
use hypersynth::opportunistic::presentation::Presentation;
use hypersynth::opportunistic::simulate::trace;
use hypersynth::opportunistic::simulate::{SimulationOptions, simulate};
use hypersynth::opportunistic::view::GameView;
use hypersynth::pipeline::{MdpOptions, OpportunisticSolution, ReportRequests};
use hypersynth::report::{Games, Report, TaskAutomaton};

const OBSTACLES: [(i32, i32); 5] = [(0, 1), (1, 0), (1, 1), (3, 4), (4, 3)];
const ROBOT_MOVES: [(&str, i32, i32); 8] = [
    ("N", 0, 1),
    ("S", 0, -1),
    ("E", 1, 0),
    ("W", -1, 0),
    ("NE", 1, 1),
    ("NW", -1, 1),
    ("SE", 1, -1),
    ("SW", -1, -1),
];
const ADVERSARY_MOVES: [(&str, i32, i32); 5] = [
    ("N", 0, 1),
    ("S", 0, -1),
    ("E", 1, 0),
    ("W", -1, 0),
    ("STAY", 0, 0),
];

fn free(x: i32, y: i32) -> bool {
    (0..5).contains(&x) && (0..5).contains(&y) && !OBSTACLES.contains(&(x, y))
}

fn case_study_arena() -> Arena {
    let cells: Vec<(i32, i32)> = (0..5)
        .flat_map(|x| (0..5).map(move |y| (x, y)))
        .filter(|&(x, y)| free(x, y))
        .collect();
    // Named as the gridworld generator names them (random sigma_L keys its draws by names).
    let name =
        |r: (i32, i32), a: (i32, i32), t: u8| format!("(({},{}),({},{}),{t})", r.0, r.1, a.0, a.1);
    let mut builder = ArenaBuilder::new();
    for &r in &cells {
        for &a in &cells {
            let label: Vec<&str> = match r {
                (0, 3) => vec!["A"],
                (4, 4) => vec!["B"],
                _ => vec![],
            };
            for t in 0..2 {
                let owner = if t == 0 {
                    Owner::Robot
                } else {
                    Owner::Adversary
                };
                builder
                    .add_state(&name(r, a, t), owner, label.iter().copied(), None)
                    .unwrap();
            }
        }
    }
    for &r in &cells {
        for &a in &cells {
            let robot = builder.find_state(&name(r, a, 0)).unwrap();
            for (action, dx, dy) in ROBOT_MOVES {
                let next = (r.0 + dx, r.1 + dy);
                if free(next.0, next.1) && next != a {
                    let to = builder.find_state(&name(next, a, 1)).unwrap();
                    builder.add_transition(robot, action, to).unwrap();
                }
            }
            let adversary = builder.find_state(&name(r, a, 1)).unwrap();
            for (action, dx, dy) in ADVERSARY_MOVES {
                let next = (a.0 + dx, a.1 + dy);
                if free(next.0, next.1) && next != r {
                    let to = builder.find_state(&name(r, next, 0)).unwrap();
                    builder.add_transition(adversary, action, to).unwrap();
                }
            }
        }
    }
    builder.set_initial(builder.find_state(&name((0, 2), (4, 2), 0)).unwrap());
    builder.build().unwrap()
}

#[test]
fn case_study_mdp_matches_the_paper() {
    check_case_study(&case_study_arena());
}

#[test]
fn bundled_case_study_arena_gives_the_same_mdp() {
    let text = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs/case-study/arena.txt"
    ));
    check_case_study(&hypersynth::arena::parse(text).unwrap().arena);
}

fn check_case_study(arena: &Arena) {
    assert_eq!(arena.num_states(), 800);
    let (dfa1, dfa2) = (
        crate::common::avoid_until("O", "A"),
        crate::common::avoid_until("O", "B"),
    );
    let product = Hypergame::new(arena, &dfa1, &dfa2, States::Full).unwrap();
    assert_eq!(product.num_states(), 3200);
    let paper = PaperGame::new(&product);
    let game = paper.view(&product);
    let h0 = game.initial();
    assert_eq!(paper.regions.win_label(h0).to_string(), "(W, L, L)");

    let adversary = AdversaryModel::new(&game, &SigmaL::Uniform).unwrap();
    let built = HypergameMdp::build(&game, &adversary, Risk::Paper).unwrap();
    let mdp = built.mdp();
    let s0 = built.node(h0);
    let mut actions: Vec<&str> = mdp.choices(s0).map(|c| mdp.action_name(c)).collect();
    actions.sort_unstable();
    assert_eq!(actions, ["E", "N", "NE", "stop"]);

    let options = SolveOptions {
        discount: Discount::new(0.99).unwrap(),
        ..SolveOptions::default()
    };
    let solution = solve(mdp, &options).unwrap();
    let sizes = built.sizes(&game, &solution);
    assert_eq!(sizes.robot_states, 1600);
    // The paper's breakdown, counted here from the win-labels alone: absorbing = robot states
    // labelled (W,W,W) or (L,W,L).
    let robot: Vec<HState> = product.states().filter(|&h| game.is_robot(h)).collect();
    let absorbing = robot
        .iter()
        .filter(|&&h| matches!(paper.regions.win_label(h).code(), "WWW" | "LWL"))
        .count() as u32;
    assert_eq!(sizes.absorbing, absorbing);
    assert_eq!(
        sizes.absorbing + sizes.with_opportunity + sizes.without_opportunity,
        1600
    );
    let controller = Controller {
        game: &game,
        mdp: &built,
        solution: &solution,
    };
    // N is strictly best under discount 0.99 (docs/semantics.md §11).
    let Decision::Move { action, .. } = controller.decide(h0) else {
        panic!("h0 is a decision node")
    };
    assert_eq!(arena.action_name(action), "N");
    let evaluation = ControllerEvaluation::new(&controller, &adversary, 1e-9, 100_000).unwrap();
    let table = controller.explain(h0, &evaluation);
    let value_of = |name: &str| {
        table
            .actions
            .iter()
            .find(|r| r.action == name)
            .unwrap()
            .value
    };
    assert!(value_of("N") > value_of("E") + 1e-3 && value_of("N") > value_of("NE") + 1e-3);

    // The simulated mean payoff estimates the value of h0 (g = 0.99, uniform adversary).
    let report = simulate(
        &controller,
        &adversary,
        SimulationOptions {
            runs: 4000,
            seed: 2019,
            max_steps: 1000,
        },
    );
    let value = solution.value(s0);
    assert!(
        report.ci_low <= value.upper && value.lower <= report.ci_high,
        "{report:?} vs {value:?}"
    );
}

fn case_study_report(
    product: &Hypergame,
    regions: &TaskRegions,
    dfas: [&Dfa; 2],
    simulate: Option<u32>,
) -> (String, String, HypergameMdp) {
    let automata = [("!O U A", dfas[0]), ("!O U B", dfas[1])].map(|(formula, dfa)| TaskAutomaton {
        formula,
        dfa,
        translator: "table",
    });
    let presentation = Presentation::paper("(!O U A) & (!O U B)");
    let options = MdpOptions {
        sigma_l: SigmaL::Uniform,
        seed: 7,
        solve: SolveOptions {
            discount: Discount::new(0.99).unwrap(),
            ..SolveOptions::default()
        },
        learnt: None,
    };
    let requests = ReportRequests {
        explain: Some(product.initial()),
        simulate,
        max_steps: 1000,
    };
    let paper = PaperGame::new(product);
    assert_eq!(&paper.regions, regions);
    let games = Games::new(
        &presentation,
        &automata,
        ("!O U A", None),
        &paper.payoffs,
        product,
        regions,
    );
    let game = paper.view(product);
    let solved = OpportunisticSolution::solve(&game, Risk::Paper, &options, &mut ()).unwrap();
    let run = trace(
        &solved.controller(&game),
        &solved.adversary,
        options.seed,
        1000,
    );
    let report = Report {
        presentation,
        games,
        synthesis: Some(solved.synthesis(&game, &requests, Some(&run), &mut ())),
    };
    let json = report.to_json(None).unwrap();
    (report.to_string(), json, solved.mdp)
}

#[test]
fn case_study_report_is_deterministic_and_names_the_first_action() {
    let arena = case_study_arena();
    let (dfa1, dfa2) = (
        crate::common::avoid_until("O", "A"),
        crate::common::avoid_until("O", "B"),
    );
    let product = Hypergame::new(&arena, &dfa1, &dfa2, States::Full).unwrap();
    let regions = crate::common::paper_regions(&product);
    let (text, json, _) = case_study_report(&product, &regions, [&dfa1, &dfa2], Some(300));
    let (text2, json2, _) = case_study_report(&product, &regions, [&dfa1, &dfa2], Some(300));
    assert_eq!((&text, &json), (&text2, &json2));
    let value: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(value["initial"]["action"], "N");
    assert_eq!(value["initial"]["label"], "WLL");
    assert_eq!(value["mdp"]["robot_states"], 1600);
    assert_eq!(value["explain"]["chosen"], "N");
    assert_eq!(value["simulation"]["runs"], 300);
    let outcomes = &value["simulation"]["outcomes"];
    let total: u64 = [
        "phi",
        "phi1_only",
        "phi2_only",
        "adversary_stuck",
        "none",
        "step_bound",
    ]
    .iter()
    .map(|k| outcomes[k].as_u64().unwrap())
    .sum();
    assert_eq!(total, 300);
    assert!(
        text.contains("decision table of ((0,2),(4,2),0)|"),
        "{text}"
    );
}

/// Reads the DRN export by the rules documented in `mdp::drn`: header counts, one `state` block
/// per state in order, `init` once, each action's probabilities summing to 1 with targets
/// ascending and in range, and `collect` rewards equal to the absorbing payoffs.
#[test]
fn case_study_drn_export_follows_the_documented_rules() {
    let arena = case_study_arena();
    let (dfa1, dfa2) = (
        crate::common::avoid_until("O", "A"),
        crate::common::avoid_until("O", "B"),
    );
    let product = Hypergame::new(&arena, &dfa1, &dfa2, States::Full).unwrap();
    let regions = crate::common::paper_regions(&product);
    let (_, _, built) = case_study_report(&product, &regions, [&dfa1, &dfa2], None);
    let mdp = built.mdp();
    let paper = PaperGame::new(&product);
    let game = paper.view(&product);
    let text = write_drn(mdp, Discount::new(0.99).unwrap(), DrnForm::Reward, |s| {
        Some(built.state_name(&game, s))
    });
    let lines: Vec<&str> = text.lines().filter(|l| !l.starts_with("//")).collect();
    let header = |key: &str| lines[lines.iter().position(|l| *l == key).unwrap() + 1];
    let states: u32 = header("@nr_states").parse().unwrap();
    assert_eq!(states as usize, mdp.num_states() + 1);
    let model = lines.iter().position(|l| *l == "@model").unwrap();
    let (mut next_state, mut actions, mut inits) = (0u32, 0u32, Vec::new());
    let mut distribution: Vec<(u32, f64)> = Vec::new();
    let check = |distribution: &[(u32, f64)]| {
        if !distribution.is_empty() {
            let sum: f64 = distribution.iter().map(|d| d.1).sum();
            assert!((sum - 1.0).abs() < 1e-9, "{distribution:?}");
            assert!(distribution.windows(2).all(|w| w[0].0 < w[1].0));
            assert!(distribution.iter().all(|d| d.0 < states));
        }
    };
    for line in &lines[model + 1..] {
        if let Some(rest) = line.strip_prefix("state ") {
            check(&distribution);
            distribution.clear();
            let mut words = rest.split(' ');
            assert_eq!(words.next().unwrap().parse::<u32>().unwrap(), next_state);
            if words.any(|w| w == "init") {
                inits.push(next_state);
            }
            next_state += 1;
        } else if let Some(rest) = line.strip_prefix("\taction ") {
            check(&distribution);
            distribution.clear();
            actions += 1;
            if let Some(reward) = rest.strip_prefix("collect [") {
                let payoff: f64 = reward.trim_end_matches(']').parse().unwrap();
                assert_eq!(Some(payoff), mdp.payoff(MdpState::from_u32(next_state - 1)));
            }
        } else {
            let (target, probability) = line.trim().split_once(" : ").unwrap();
            distribution.push((target.parse().unwrap(), probability.parse().unwrap()));
        }
    }
    check(&distribution);
    assert_eq!(next_state, states);
    assert_eq!(header("@nr_choices").parse::<u32>().unwrap(), actions);
    assert_eq!(inits, [mdp.initial().as_u32()]);
    let comment = text
        .lines()
        .take_while(|l| !l.starts_with("state 0"))
        .last()
        .unwrap();
    assert_eq!(
        comment,
        format!(
            "// {}",
            product.name(built.product_state(MdpState::new(0)).unwrap())
        )
    );
}

/// The figures the guide (`docs/guide.md`, "The case study") and `specs/case-study/README.md`
/// print are the ones computed here.
#[test]
fn documented_case_study_figures_are_current() {
    let text = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs/case-study/arena.txt"
    ));
    let arena = hypersynth::arena::parse(text).unwrap().arena;
    let (dfa1, dfa2) = (
        crate::common::avoid_until("O", "A"),
        crate::common::avoid_until("O", "B"),
    );
    let product = Hypergame::new(&arena, &dfa1, &dfa2, States::Full).unwrap();
    let paper = PaperGame::new(&product);
    let game = paper.view(&product);
    // Prose is compared with line breaks and indentation folded into single spaces.
    let fold = |text: &str| text.split_whitespace().collect::<Vec<_>>().join(" ");
    let guide = fold(include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/guide.md"
    )));
    let case_readme = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs/case-study/README.md"
    ));
    let solved = |sigma_l: SigmaL, g: f64| {
        let adversary = AdversaryModel::new(&game, &sigma_l).unwrap();
        let built = HypergameMdp::build(&game, &adversary, Risk::Paper).unwrap();
        let options = SolveOptions {
            discount: Discount::new(g).unwrap(),
            ..SolveOptions::default()
        };
        let solution = solve(built.mdp(), &options).unwrap();
        (adversary, built, solution)
    };
    let (adversary, built, solution) = solved(SigmaL::Random { seed: 2019 }, 1.0);
    let sizes = built.sizes(&game, &solution);
    let breakdown = format!(
        "{} absorbing robot states (1025 `(W,W,W)`, 220 `(L,W,L)`), {} with an opportunity and {} without",
        sizes.absorbing, sizes.with_opportunity, sizes.without_opportunity
    );
    assert!(
        guide.contains(&breakdown),
        "docs/guide.md lacks: {breakdown}"
    );
    for row in [
        format!(
            "| absorbing: labelled `(W,W,W)` or `(L,W,L)` | {} (1025 + 220) | 1245 |",
            sizes.absorbing
        ),
        format!(
            "| with an opportunity: other robot states of positive value | {} | 312 |",
            sizes.with_opportunity
        ),
        format!(
            "| without an opportunity: value 0 | {} | 43 |",
            sizes.without_opportunity
        ),
    ] {
        assert!(
            case_readme.contains(&row),
            "specs/case-study/README.md lacks: {row}"
        );
    }
    // Undiscounted: N, NE and E tie at 300; their expected robot moves pick N.
    let controller = Controller {
        game: &game,
        mdp: &built,
        solution: &solution,
    };
    let evaluation = ControllerEvaluation::new(&controller, &adversary, 1e-9, 100_000).unwrap();
    let table = controller.explain(game.initial(), &evaluation);
    let moves = |action: &str| {
        let row = table.actions.iter().find(|r| r.action == action).unwrap();
        assert!((row.value - 300.0).abs() < 1e-6);
        format!("{:.1}", row.expected_moves)
    };
    let sentence = format!(
        "1.7 robot moves before it commits with N, {} with NE and {} with E",
        moves("NE"),
        moves("E")
    );
    assert_eq!(moves("N"), "1.7");
    assert!(guide.contains(&sentence), "docs/guide.md lacks: {sentence}");
    assert_eq!(table.chosen.as_deref(), Some("N"));
    // Discount 0.99: uniform and random sigma_L, values to two decimals.
    let values = |sigma_l: SigmaL| {
        let (_, built, solution) = solved(sigma_l, 0.99);
        let mdp = built.mdp();
        let h0 = game.initial();
        let value_of = |action: &str| {
            let choice = mdp
                .choices(built.node(h0))
                .find(|&c| mdp.action_name(c) == action)
                .unwrap();
            format!("{:.2}", solution.choice_value(mdp, choice).lower)
        };
        (
            format!("{:.2}", solution.value(built.node(h0)).lower),
            value_of("N"),
            value_of("E"),
            value_of("NE"),
        )
    };
    let (h0, n, e, ne) = values(SigmaL::Uniform);
    assert_eq!(h0, n);
    assert!(
        guide.contains(&format!("the value of h0 is {h0} with N (E and NE {e}")),
        "{h0} {e}"
    );
    assert_eq!(e, ne);
    let (_, n, e, ne) = values(SigmaL::Random { seed: 2019 });
    assert!(
        guide.contains(&format!("N {n}, NE {ne}, E {e}")),
        "N {n}, NE {ne}, E {e}"
    );
}
