//! The hypergame of a seven-state arena whose regions, ranks, labels and strategies were worked
//! out by hand (the derivation is in the comments).

use crate::common::{PHI, PHI1, PHI2, avoid_until, eventually, seven_state_arena as arena};
use hypersynth::arena::{ArenaBuilder, Owner};
use hypersynth::automata::Dfa;
use hypersynth::game::Wins;
use hypersynth::game::{
    HState, Hypergame, Partition, ProductState, ReactiveStrategy, StateNameError, States,
    TaskRegions, TaskSet, WinLabel,
};
use hypersynth::position::Position;

fn dfas() -> (Dfa, Dfa) {
    (eventually("a"), eventually("b"))
}

fn find(game: &Hypergame, name: &str) -> HState {
    game.parse_state(name).unwrap()
}

/// The ranks of the named states in `Win(task)`.
fn ranks(
    game: &Hypergame,
    regions: &TaskRegions,
    set: TaskSet,
    names: &[&str],
) -> Vec<Option<u32>> {
    names
        .iter()
        .map(|name| regions.win(set).rank(find(game, name)))
        .collect()
}

#[test]
fn full_product_regions_and_ranks_match_the_hand_computation() {
    let arena = arena();
    let (d1, d2) = dfas();
    let game = Hypergame::new(&arena, &d1, &d2, States::Full).unwrap();
    // Both DFA states of F a and F b are reached by arena labels: 7 × 2 × 2.
    assert_eq!(game.num_states(), 28);
    assert_eq!(game.num_edges(), 7 * 4);
    assert_eq!(game.q1_states(), [0, 1]);
    assert_eq!(game.q2_states(), [0, 1]);
    assert_eq!(game.name(game.initial()), "s0|0|0");
    assert!(game.missing_propositions().is_empty());

    let regions = crate::common::paper_regions(&game);
    // Win(phi1): the 14 states with q1 = 1, plus s6|0|* (stuck adversary, rank 1),
    // s1|0|* (all of l, r, t attracted, the last at rank 1: rank 2), s0|0|* (go: rank 3).
    // s2|0|* and s3|0|* lead only to stuck robot states s4|0|*, s5|0|*: not attracted.
    assert_eq!(regions.win(PHI1).len(), 20);
    assert_eq!(
        ranks(
            &game,
            &regions,
            PHI1,
            &[
                "s0|0|0", "s1|0|1", "s6|0|0", "s2|1|0", "s2|0|0", "s4|0|1", "s5|0|0"
            ]
        ),
        [Some(3), Some(2), Some(1), Some(0), None, None, None]
    );
    // Win(phi2): the 14 states with q2 = 1, plus s6|*|0 (rank 1) and s2|*|0 (go into b: rank 1).
    // s1|*|0 is not attracted because of r (s3 leads to the stuck s5), so neither is s0|*|0.
    assert_eq!(regions.win(PHI2).len(), 18);
    assert_eq!(
        ranks(
            &game,
            &regions,
            PHI2,
            &["s2|0|0", "s6|1|0", "s4|0|1", "s1|0|0", "s0|1|0", "s4|1|0"]
        ),
        [Some(1), Some(1), Some(0), None, None, None]
    );
    // Win(phi): the 7 states with q1 = q2 = 1, s6 with the three other pairs (rank 1), s2|1|0
    // (rank 1), s1|0|1 (l, r into targets, t into s6|0|1 at rank 1: rank 2), s0|0|1 (rank 3).
    assert_eq!(regions.win(PHI).len(), 13);
    assert_eq!(
        ranks(
            &game,
            &regions,
            PHI,
            &[
                "s0|0|1", "s1|0|1", "s2|1|0", "s6|1|0", "s3|1|1", "s0|0|0", "s1|1|0", "s2|0|1"
            ]
        ),
        [
            Some(3),
            Some(2),
            Some(1),
            Some(1),
            Some(0),
            None,
            None,
            None
        ]
    );
    assert_eq!(regions.win(PHI).max_rank(), Some(3));

    // h0 = s0|0|0 is winning for phi1 only.
    assert_eq!(
        regions.win_label(game.initial()),
        WinLabel::new(true, false, false)
    );
    assert_eq!(regions.win_label(find(&game, "s2|0|0")).code(), "LWL");
    assert_eq!(regions.win_label(find(&game, "s3|0|0")).code(), "LLL");

    // Per arena state (q1q2 = 00, 01, 10, 11):
    //   s0 R: WLL WWW WLL WWW    s1 A: WLL WWW WLL WWW    s2 R: LWL LWL WWW WWW
    //   s3 R: LLL LWL WLL WWW    s4, s5 R: LLL LWL WLL WWW  s6 A: WWW WWW WWW WWW
    let partition = Partition::compute(&game, &regions);
    let count = |code: &str| {
        let label = WinLabel::ALL
            .into_iter()
            .find(|l| l.code() == code)
            .unwrap();
        let c = partition.get(label);
        (c.robot, c.adversary, c.total)
    };
    assert_eq!(count("WWW"), (7, 6, 13));
    assert_eq!(count("WWL"), (0, 0, 0));
    assert_eq!(count("WLL"), (5, 2, 7));
    assert_eq!(count("LWL"), (5, 0, 5));
    assert_eq!(count("LLL"), (3, 0, 3));
    for impossible in ["WLW", "LWW", "LLW"] {
        assert_eq!(count(impossible), (0, 0, 0));
    }
}

#[test]
fn reachable_product_keeps_the_seven_states_reachable_from_h0() {
    let arena = arena();
    let (d1, d2) = dfas();
    let game = Hypergame::new(&arena, &d1, &d2, States::Reachable).unwrap();
    // Breadth-first from h0: s0|0|0, then s1|0|0 (go; wait loops), then l, r, t, then s2's and
    // s3's successors.
    let names: Vec<String> = game.states().map(|h| game.name(h)).collect();
    assert_eq!(
        names,
        [
            "s0|0|0", "s1|0|0", "s2|1|0", "s3|1|0", "s6|0|0", "s4|1|1", "s5|1|0"
        ]
    );
    assert_eq!(game.num_edges(), 7);
    let h = HState::new;
    assert_eq!(game.initial(), h(0));
    assert_eq!(game.predecessors(h(0)), [h(0)]);
    assert_eq!(game.predecessors(h(1)), [h(0)]);
    let regions = crate::common::paper_regions(&game);
    assert_eq!(regions.win(PHI1).len(), 7);
    assert_eq!(regions.win(PHI1).rank(h(0)), Some(3));
    let codes: Vec<&str> = game.states().map(|h| regions.win_label(h).code()).collect();
    assert_eq!(codes, ["WLL", "WLL", "WWW", "WLL", "WWW", "WWW", "WLL"]);
    // A state of the full product that is not reachable cannot be named here.
    assert_eq!(
        game.parse_state("s0|0|1"),
        Err(StateNameError::Unreachable(
            Position { line: 1, column: 1 },
            "s0|0|1".into()
        ))
    );
}

#[test]
fn strategies_decrease_the_rank_and_the_adversary_avoids_the_robots_region() {
    let arena = arena();
    let (d1, d2) = dfas();
    let game = Hypergame::new(&arena, &d1, &d2, States::Full).unwrap();
    let regions = crate::common::paper_regions(&game);
    let robot = ReactiveStrategy::robot(&game, regions.win(PHI));
    let adversary = ReactiveStrategy::adversary(&game, regions.win(PHI));
    let moves = |strategy: &ReactiveStrategy, name: &str| -> Vec<(String, String)> {
        strategy
            .moves(&game, find(&game, name))
            .map(|(a, h)| (arena.action_name(a).to_string(), game.name(h)))
            .collect()
    };
    let pair = |a: &str, h: &str| (a.to_string(), h.to_string());
    // Rank 3: go lowers the rank to 2, wait keeps it at 3.
    assert_eq!(moves(&robot, "s0|0|1"), [pair("go", "s1|0|1")]);
    // Rank 0 (target): every action staying in Win(phi).
    assert_eq!(moves(&robot, "s3|1|1"), [pair("go", "s5|1|1")]);
    assert!(robot.is_defined(find(&game, "s4|1|1")));
    assert!(!robot.is_defined(find(&game, "s0|0|0")));
    assert!(
        !robot.is_defined(find(&game, "s1|0|1")),
        "an adversary state"
    );
    // Outside Win(phi), s1|0|0: l and t lead into Win(phi), r does not.
    assert_eq!(moves(&adversary, "s1|0|0"), [pair("r", "s3|1|0")]);
    assert!(
        !adversary.is_defined(find(&game, "s1|0|1")),
        "robot's region"
    );
    assert_eq!(adversary.player(), Owner::Adversary);
    // For phi1 from h0: go (rank 2), not wait.
    let robot1 = ReactiveStrategy::robot(&game, regions.win(PHI1));
    assert_eq!(moves(&robot1, "s0|0|0"), [pair("go", "s1|0|0")]);
}

#[test]
fn unreachable_dfa_states_are_not_enumerated_and_missing_propositions_are_reported() {
    let arena = arena();
    // No arena state carries o: the sink of !o U a is never entered.
    let d1 = avoid_until("o", "a");
    let d2 = eventually("b");
    let game = Hypergame::new(&arena, &d1, &d2, States::Full).unwrap();
    assert_eq!(game.q1_states(), [0, 1]);
    assert_eq!(game.num_states(), 28);
    assert_eq!(game.missing_propositions(), ["o"]);
    assert_eq!(
        game.parse_state("s0|2|0"),
        Err(StateNameError::NotEnumerated {
            position: Position { line: 1, column: 4 },
            automaton: "phi1".into(),
            state: 2
        })
    );
    // Same regions as F a, since o never holds.
    let regions = crate::common::paper_regions(&game);
    assert_eq!(regions.win(PHI1).len(), 20);
}

#[test]
fn product_state_names_round_trip_and_bad_names_are_located() {
    let mut b = ArenaBuilder::new();
    let x = b.add_state("x|y", Owner::Robot, ["a"], None).unwrap();
    let z = b.add_state("z", Owner::Adversary, [], None).unwrap();
    b.add_transition(x, "go", z).unwrap();
    b.add_transition(z, "back", x).unwrap();
    b.set_initial(z);
    let arena = b.build().unwrap();
    let (d1, d2) = dfas();
    for enumeration in [States::Full, States::Reachable] {
        let game = Hypergame::new(&arena, &d1, &d2, enumeration).unwrap();
        for h in game.states() {
            assert_eq!(game.parse_state(&game.name(h)), Ok(h));
            assert_eq!(game.find(game.state(h)), Some(h));
        }
    }
    let game = Hypergame::new(&arena, &d1, &d2, States::Full).unwrap();
    // b never holds, so q2 stays 0; a holds in x|y.
    assert_eq!(game.q2_states(), [0]);
    assert_eq!(game.name(game.initial()), "z|0|0");
    assert_eq!(
        game.state(game.parse_state("x|y|1|0").unwrap()),
        ProductState {
            arena: x,
            q1: 1,
            q2: 0
        }
    );
    let at = |column| Position { line: 1, column };
    assert_eq!(
        game.parse_state("z|0"),
        Err(StateNameError::Malformed(at(4), "ARENA_STATE|Q1|Q2".into()))
    );
    assert_eq!(
        game.parse_state("w|0|0"),
        Err(StateNameError::UnknownArenaState(at(1), "w".into()))
    );
    assert_eq!(
        game.parse_state("z|0|x"),
        Err(StateNameError::NoSuchDfaState {
            position: at(5),
            automaton: "phi2".into(),
            text: "x".into()
        })
    );
    assert_eq!(
        game.parse_state("z|7|0"),
        Err(StateNameError::NoSuchDfaState {
            position: at(3),
            automaton: "phi1".into(),
            text: "7".into()
        })
    );
    assert_eq!(
        game.parse_state("z|0|1"),
        Err(StateNameError::NotEnumerated {
            position: at(5),
            automaton: "phi2".into(),
            state: 1
        })
    );
}
