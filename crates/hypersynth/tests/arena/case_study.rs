//! The bundled case-study arena (`specs/case-study/arena.txt`) against docs/semantics.md §11: its
//! size, and transitions worked out by hand from the grid below (obstacles marked X).
//!
//! ```text
//!   y=4   .  .  .  X  B
//!   y=3   A  .  .  .  X
//!   y=2   R  .  .  .  I      R = robot start (0,2), I = adversary start (4,2)
//!   y=1   X  X  .  .  .
//!   y=0   .  X  .  .  .
//!        x=0 1  2  3  4
//! ```
//!
//! The obstacle list below restates docs/semantics.md §11, independently of the generator's parameters
//! (`specs/case-study/gridworld.args`), so that a wrong parameter there is caught here.

use hypersynth::arena::{self, Arena, Owner};

const ARENA: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../specs/case-study/arena.txt"
));
const OBSTACLES: [(i32, i32); 5] = [(0, 1), (1, 0), (1, 1), (3, 4), (4, 3)];

fn case_study() -> Arena {
    arena::parse(ARENA).expect("the case study parses").arena
}

/// The moves of a state as `(action, successor)` pairs, in the arena's order.
fn moves(arena: &Arena, state: &str) -> Vec<(String, String)> {
    let id = arena.find_state(state).expect("state exists");
    arena
        .edges(id)
        .map(|(a, t)| (arena.action_name(a).to_string(), arena.name(t).to_string()))
        .collect()
}

fn expected(list: &[(&str, &str)]) -> Vec<(String, String)> {
    list.iter()
        .map(|&(a, t)| (a.to_string(), t.to_string()))
        .collect()
}

#[test]
fn the_case_study_has_800_states_over_20_free_cells_and_the_design_labels() {
    let arena = case_study();
    assert_eq!(arena.num_states(), 20 * 20 * 2);
    let robot = arena
        .states()
        .filter(|&s| arena.owner(s) == Owner::Robot)
        .count();
    assert_eq!(robot, 400);
    assert_eq!(arena.name(arena.initial()), "((0,2),(4,2),0)");
    assert_eq!(arena.owner(arena.initial()), Owner::Robot);
    assert_eq!(arena.propositions(), ["A", "B", "O"]);
    assert_eq!(
        arena.actions(),
        ["N", "S", "E", "W", "NE", "NW", "SE", "SW", "STAY"]
    );
    let carrying = |p: &str| {
        let p = arena.find_proposition(p).unwrap() as usize;
        arena
            .states()
            .filter(|&s| arena.label(s).contains(p))
            .count()
    };
    // The robot on A's cell (or B's), the adversary on any of 20 cells, both turns.
    assert_eq!(carrying("A"), 40);
    assert_eq!(carrying("B"), 40);
    assert_eq!(carrying("O"), 0);
    let label = |s: &str| arena.label(arena.find_state(s).unwrap()).iter().count();
    assert_eq!(label("((0,3),(4,2),1)"), 1);
    assert_eq!(label("((0,2),(0,3),0)"), 0);
}

#[test]
fn moves_from_the_initial_state_and_the_adversarys_replies() {
    let arena = case_study();
    // (0,2): S and SE are obstacles, W, NW and SW off the grid.
    assert_eq!(
        moves(&arena, "((0,2),(4,2),0)"),
        expected(&[
            ("N", "((0,3),(4,2),1)"),
            ("E", "((1,2),(4,2),1)"),
            ("NE", "((1,3),(4,2),1)"),
        ])
    );
    // IDroid at (4,2): N is an obstacle, E off the grid.
    assert_eq!(
        moves(&arena, "((0,3),(4,2),1)"),
        expected(&[
            ("S", "((0,3),(4,1),0)"),
            ("W", "((0,3),(3,2),0)"),
            ("STAY", "((0,3),(4,2),0)"),
        ])
    );
}

#[test]
fn moves_in_corners_next_to_obstacles_and_next_to_the_other_player() {
    let arena = case_study();
    // (0,0) is walled in by obstacles: the robot is stuck, the adversary can only stay.
    assert_eq!(moves(&arena, "((0,0),(4,2),0)"), expected(&[]));
    assert_eq!(
        moves(&arena, "((2,2),(0,0),1)"),
        expected(&[("STAY", "((2,2),(0,0),0)")])
    );
    // (4,4): only SW to (3,3), unless the adversary stands there.
    assert_eq!(
        moves(&arena, "((4,4),(0,2),0)"),
        expected(&[("SW", "((3,3),(0,2),1)")])
    );
    assert_eq!(moves(&arena, "((4,4),(3,3),0)"), expected(&[]));
    // (2,3): NE is the obstacle (3,4).
    assert_eq!(
        moves(&arena, "((2,3),(0,0),0)"),
        expected(&[
            ("N", "((2,4),(0,0),1)"),
            ("S", "((2,2),(0,0),1)"),
            ("E", "((3,3),(0,0),1)"),
            ("W", "((1,3),(0,0),1)"),
            ("NW", "((1,4),(0,0),1)"),
            ("SE", "((3,2),(0,0),1)"),
            ("SW", "((1,2),(0,0),1)"),
        ])
    );
    // The adversary at (3,3): N and E are obstacles.
    assert_eq!(
        moves(&arena, "((0,2),(3,3),1)"),
        expected(&[
            ("S", "((0,2),(3,2),0)"),
            ("W", "((0,2),(2,3),0)"),
            ("STAY", "((0,2),(3,3),0)"),
        ])
    );
    // Side by side: E would enter the adversary's cell, SW is an obstacle.
    assert_eq!(
        moves(&arena, "((2,2),(3,2),0)"),
        expected(&[
            ("N", "((2,3),(3,2),1)"),
            ("S", "((2,1),(3,2),1)"),
            ("W", "((1,2),(3,2),1)"),
            ("NE", "((3,3),(3,2),1)"),
            ("NW", "((1,3),(3,2),1)"),
            ("SE", "((3,1),(3,2),1)"),
        ])
    );
    // And the adversary's side: W would enter the robot's cell.
    assert_eq!(
        moves(&arena, "((2,2),(3,2),1)"),
        expected(&[
            ("N", "((2,2),(3,3),0)"),
            ("S", "((2,2),(3,1),0)"),
            ("E", "((2,2),(4,2),0)"),
            ("STAY", "((2,2),(3,2),0)"),
        ])
    );
}

/// Counts the transitions naively from the description of docs/semantics.md §11: a move exists when its target
/// is on the grid, free, and not the other player's cell.
#[test]
fn the_number_of_transitions_matches_a_naive_count() {
    let free: Vec<(i32, i32)> = (0..5)
        .flat_map(|x| (0..5).map(move |y| (x, y)))
        .filter(|c| !OBSTACLES.contains(c))
        .collect();
    assert_eq!(free.len(), 20);
    let robot: [(i32, i32); 8] = [
        (0, 1),
        (0, -1),
        (1, 0),
        (-1, 0),
        (1, 1),
        (-1, 1),
        (1, -1),
        (-1, -1),
    ];
    let adversary: [(i32, i32); 5] = [(0, 1), (0, -1), (1, 0), (-1, 0), (0, 0)];
    let count = |me: (i32, i32), other: (i32, i32), moves: &[(i32, i32)]| {
        moves
            .iter()
            .map(|(dx, dy)| (me.0 + dx, me.1 + dy))
            .filter(|target| free.contains(target) && *target != other)
            .count()
    };
    let mut total = 0;
    for &r in &free {
        for &a in &free {
            total += count(r, a, &robot) + count(a, r, &adversary);
        }
    }
    assert_eq!(case_study().num_transitions(), total);
}

#[test]
fn the_case_study_round_trips_through_the_writer() {
    let arena = case_study();
    let written = arena::write(&arena);
    assert_eq!(arena::parse(&written).unwrap().arena, arena);
    // The committed file is the canonical form plus the generator's comment lines.
    let without_comments: Vec<&str> = ARENA
        .lines()
        .filter(|line| !line.starts_with("# ") || *line == arena::HEADER)
        .collect();
    assert_eq!(written.lines().collect::<Vec<_>>(), without_comments);
}
