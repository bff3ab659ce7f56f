//! The games report and the strategy export on the hand-solved seven-state arena (the regions
//! are derived in `game/hypergame_hand.rs`).

use crate::common::{eventually, seven_state_arena};
use hypersynth::game::{Hypergame, Payoffs, States};
use hypersynth::opportunistic::presentation::Presentation;
use hypersynth::report::{Games, Report, StrategyExport, TaskAutomaton};
use serde_json::json;

fn report(states: States) -> Report {
    let arena = seven_state_arena();
    let (d1, d2) = (eventually("a"), eventually("b"));
    let game = Hypergame::new(&arena, &d1, &d2, states).unwrap();
    let regions = crate::common::paper_regions(&game);
    let automata = [
        TaskAutomaton {
            formula: "F a",
            dfa: &d1,
            translator: "table",
        },
        TaskAutomaton {
            formula: "F b",
            dfa: &d2,
            translator: "table",
        },
    ];
    let presentation = Presentation::paper("F a & F b");
    let payoffs = Payoffs::default().subsets(presentation.names());
    let games = Games::new(
        &presentation,
        &automata,
        ("F a", None),
        &payoffs,
        &game,
        &regions,
    );
    Report {
        presentation,
        games,
        synthesis: None,
    }
}

/// The report's JSON, parsed.
fn json_of(report: &Report) -> serde_json::Value {
    serde_json::from_str(&report.to_json(None).unwrap()).unwrap()
}

#[test]
fn json_report_has_the_hand_computed_figures() {
    let value = json_of(&report(States::Full));
    let counts =
        |robot, adversary, total| json!({"robot": robot, "adversary": adversary, "total": total});
    assert_eq!(
        value,
        json!({
            "arena": {"states": 7, "robot_states": 5, "adversary_states": 2, "transitions": 7},
            "phi": "F a & F b",
            "automata": {
                "phi1": {"formula": "F a", "states": 2, "edges": 3, "translator": "table", "enumerated_states": 2},
                "phi2": {"formula": "F b", "states": 2, "edges": 3, "translator": "table", "enumerated_states": 2}
            },
            "states": "full",
            "engine": "explicit",
            "product_states": 28,
            "product_edges": 28,
            "winning_region_sizes": {"phi1": 20, "phi2": 18, "phi": 13},
            "max_ranks": {"phi1": 3, "phi2": 1, "phi": 3},
            "partition": {
                "WWW": counts(7, 6, 13), "WWL": counts(0, 0, 0), "WLL": counts(5, 2, 7),
                "LWL": counts(5, 0, 5), "LLL": counts(3, 0, 3), "WLW": counts(0, 0, 0),
                "LWW": counts(0, 0, 0), "LLW": counts(0, 0, 0)
            },
            "initial": {"state": "s0|0|0", "label": "WLL", "ranks": {"phi1": 3, "phi2": null, "phi": null}},
            "realizable": {"phi1": true, "phi2": false, "phi": false},
            "missing_propositions": []
        })
    );
    // The partition keeps the order of the eight labels.
    let text = report(States::Full).to_json(None).unwrap();
    let positions: Vec<usize> = [
        "\"WWW\"", "\"WWL\"", "\"WLL\"", "\"LWL\"", "\"LLL\"", "\"WLW\"", "\"LWW\"", "\"LLW\"",
    ]
    .iter()
    .map(|key| text.find(key).unwrap())
    .collect();
    assert!(positions.windows(2).all(|w| w[0] < w[1]));
}

#[test]
fn text_report_prints_the_table_and_the_verdicts() {
    let expected = "\
arena          7 states (5 robot, 2 adversary), 7 transitions
phi            F a & F b
phi1 = psi     F a
               DFA: 2 states, 3 edges (table); 2 reachable by arena labels
phi2           F b
               DFA: 2 states, 3 edges (table); 2 reachable by arena labels
product        7 states, 7 edges (reachable from h0; explicit engine)
winning        |Win(phi1)| = 7, |Win(phi2)| = 3, |Win(phi)| = 3

win-label      robot adversary     total
(W, W, W)          2         1         3
(W, W, L)          0         0         0
(W, L, L)          3         1         4
(L, W, L)          0         0         0
(L, L, L)          0         0         0
(W, L, W)          0         0         0  (impossible)
(L, W, W)          0         0         0  (impossible)
(L, L, W)          0         0         0  (impossible)

initial state  s0|0|0  (W, L, L)
realizable     phi: no, phi1: yes (rank 3), phi2: no
";
    assert_eq!(report(States::Reachable).to_string(), expected);
}

#[test]
fn strategy_export_is_keyed_by_product_state_names() {
    let arena = seven_state_arena();
    let (d1, d2) = (eventually("a"), eventually("b"));
    let game = Hypergame::new(&arena, &d1, &d2, States::Reachable).unwrap();
    let regions = crate::common::paper_regions(&game);
    let presentation = Presentation::paper("F a & F b");
    let payoffs = Payoffs::default().subsets(presentation.names());
    let export = StrategyExport::new(&game, &regions, &payoffs, &presentation, "F a");
    let value = serde_json::to_value(export).unwrap();
    // Reachable states: s0|0|0 s1|0|0 s2|1|0 s3|1|0 s6|0|0 s4|1|1 s5|1|0 (robot: s0, s2, s3,
    // s4, s5). Win(phi) = {s4|1|1 (0), s2|1|0 (1), s6|0|0 (1)}.
    assert_eq!(
        value["tasks"]["phi"],
        json!({
            "realizable": false,
            "robot": {
                "s2|1|0": {"rank": 1, "actions": ["go"]},
                "s4|1|1": {"rank": 0, "actions": []}
            },
            "adversary": {"s1|0|0": ["r"]}
        })
    );
    // Win(phi1) is everything: go lowers h0's rank from 3 to 2, wait does not; no adversary
    // state is outside.
    assert_eq!(
        value["tasks"]["phi1"]["robot"]["s0|0|0"],
        json!({"rank": 3, "actions": ["go"]})
    );
    assert_eq!(value["tasks"]["phi1"]["adversary"], json!({}));
    assert_eq!(value["initial"], json!("s0|0|0"));
    assert_eq!(value["states"], json!("reachable"));
}
