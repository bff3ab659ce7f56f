//! The paper's 5×5 case study (docs/semantics.md §11), built in-process with the gridworld generator and
//! hand-made DFAs for `!O U A` and `!O U B`: the facts docs/semantics.md §11 states, the invariants, and the
//! strategies checked against every adversary behaviour.

use crate::common::{PAPER_TASKS, PHI1, PHI2, avoid_until, strategy_failures};
use hypersynth::arena::Arena;
use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::game::Wins;
use hypersynth::game::{Hypergame, Partition, States, WinLabel};

fn case_study() -> Arena {
    let cell = |x, y| Cell { x, y };
    let mut grid = Gridworld::new(5, 5, cell(0, 2), cell(4, 2));
    grid.obstacles = vec![cell(0, 1), cell(1, 0), cell(1, 1), cell(3, 4), cell(4, 3)];
    grid.labels = vec![("A".into(), cell(0, 3)), ("B".into(), cell(4, 4))];
    grid.build().unwrap()
}

#[test]
fn case_study_hypergame_has_the_stated_size_initial_label_and_invariants() {
    let arena = case_study();
    assert_eq!(arena.num_states(), 800);
    let (d1, d2) = (avoid_until("O", "A"), avoid_until("O", "B"));
    let game = Hypergame::new(&arena, &d1, &d2, States::Full).unwrap();
    // No state is labelled O, so the sinks are never entered: 800 × 2 × 2.
    assert_eq!(game.num_states(), 3200);
    assert_eq!(game.q1_states(), [0, 1]);
    assert_eq!(game.q2_states(), [0, 1]);
    let h0 = game.initial();
    assert_eq!(game.name(h0), "((0,2),(4,2),0)|0|0");
    let mut first_moves: Vec<&str> = game.edges(h0).map(|(a, _)| arena.action_name(a)).collect();
    first_moves.sort_unstable();
    assert_eq!(first_moves, ["E", "N", "NE"]);

    let regions = crate::common::paper_regions(&game);
    assert_eq!(regions.win_label(h0), WinLabel::new(true, false, false));
    let partition = Partition::compute(&game, &regions);
    let robot: usize = partition.iter().map(|(_, c)| c.robot).sum();
    assert_eq!(robot, 1600, "the MDP's decision nodes");
    for (label, counts) in partition.iter() {
        if !label.is_possible() {
            assert_eq!(counts.total, 0, "{label}");
        }
    }
    assert_eq!(regions.win(PHI1).len() % 2, 0);
    assert_eq!(regions.win(PHI2).len() % 2, 0);
    for (_, set) in PAPER_TASKS {
        assert_eq!(
            strategy_failures(&game, set, regions.win(set)),
            Vec::<String>::new()
        );
    }
}

#[test]
fn reachable_and_full_products_agree_on_the_reachable_states() {
    let arena = case_study();
    let (d1, d2) = (avoid_until("O", "A"), avoid_until("O", "B"));
    let full = Hypergame::new(&arena, &d1, &d2, States::Full).unwrap();
    let reachable = Hypergame::new(&arena, &d1, &d2, States::Reachable).unwrap();
    let (full_regions, reachable_regions) = (
        crate::common::paper_regions(&full),
        crate::common::paper_regions(&reachable),
    );
    // Win restricted to a set closed under successors does not depend on the rest.
    for h in reachable.states() {
        let g = full.find(reachable.state(h)).unwrap();
        for (_, set) in PAPER_TASKS {
            assert_eq!(
                reachable_regions.win(set).rank(h),
                full_regions.win(set).rank(g)
            );
        }
    }
}
