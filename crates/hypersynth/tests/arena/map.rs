//! Random maps: a map drawn from random generator parameters reads back as exactly those
//! parameters, and the reader never panics, whatever the text.

use hypersynth::arena::Owner;
use hypersynth::arena::gridworld::{Cell, Collision, Gridworld, Move};
use hypersynth::arena::map;
use proptest::prelude::*;

/// Random parameters on grids of up to 6x6: each cell free, an obstacle, or carrying some of
/// the propositions `p0`..`p2`; two distinct free starts; random moves, collision rule and first
/// player.
fn world() -> impl Strategy<Value = Gridworld> {
    (1u32..=6, 1u32..=6)
        .prop_flat_map(|(width, height)| {
            let cells = (width * height) as usize;
            (
                Just((width, height)),
                prop::collection::vec(0u8..8, cells),
                any::<prop::sample::Index>(),
                any::<prop::sample::Index>(),
                prop::sample::subsequence(Move::ALL.to_vec(), 1..=9),
                prop::sample::subsequence(Move::ALL.to_vec(), 1..=9),
                0u8..3,
                any::<bool>(),
            )
        })
        .prop_filter_map(
            "two free cells for the starts",
            |((width, height), kinds, r, a, robot_moves, adversary_moves, rule, first)| {
                // Kind 0 is an obstacle; otherwise bits 0..2 of kind - 1 say which of p0..p2.
                let cell = |i: usize| Cell {
                    x: (i / height as usize) as u32,
                    y: (i % height as usize) as u32,
                };
                let free: Vec<usize> = (0..kinds.len()).filter(|&i| kinds[i] != 0).collect();
                if free.len() < 2 {
                    return None;
                }
                let robot = free[r.index(free.len())];
                let others: Vec<usize> = free.iter().copied().filter(|&i| i != robot).collect();
                let adversary = others[a.index(others.len())];
                let mut world = Gridworld::new(width, height, cell(robot), cell(adversary));
                // Cells are numbered x * height + y: the generator's (and the reader's) order.
                for (i, &kind) in kinds.iter().enumerate() {
                    if kind == 0 {
                        world.obstacles.push(cell(i));
                    }
                    for p in 0..3 {
                        if kind != 0 && (kind - 1) & (1 << p) != 0 {
                            world.labels.push((format!("p{p}"), cell(i)));
                        }
                    }
                }
                world.robot_moves = robot_moves;
                world.adversary_moves = adversary_moves;
                world.collision = match rule {
                    0 => Collision::Forbidden,
                    1 => Collision::Allowed,
                    _ => Collision::Label("crash".into()),
                };
                world.first = if first {
                    Owner::Robot
                } else {
                    Owner::Adversary
                };
                Some(world)
            },
        )
}

/// The map of `world`, written independently of the reader: rows from north to south.
fn draw(world: &Gridworld) -> String {
    let moves = |moves: &[Move]| {
        let names: Vec<&str> = moves.iter().map(|m| m.name()).collect();
        names.join(" ")
    };
    let mut text = format!(
        "hypersynth map v1\nrobot-moves {}\nadversary-moves {}\ncollision {}\nfirst {}\ngrid\n",
        moves(&world.robot_moves),
        moves(&world.adversary_moves),
        world.collision,
        if world.first == Owner::Robot {
            "robot"
        } else {
            "adversary"
        },
    );
    for y in (0..world.height).rev() {
        let row: Vec<String> = (0..world.width)
            .map(|x| {
                let cell = Cell { x, y };
                if world.obstacles.contains(&cell) {
                    return "O".to_string();
                }
                let mut parts: Vec<String> = Vec::new();
                if world.robot == cell {
                    parts.push("@r".into());
                }
                if world.adversary == cell {
                    parts.push("@a".into());
                }
                parts.extend(
                    world
                        .labels
                        .iter()
                        .filter(|(_, c)| *c == cell)
                        .map(|(p, _)| p.clone()),
                );
                if parts.is_empty() {
                    ".".to_string()
                } else {
                    parts.join("+")
                }
            })
            .collect();
        text += &row.join("  ");
        text += "   # a row\n";
    }
    text
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn a_drawn_map_reads_back_as_its_parameters(world in world()) {
        let text = draw(&world);
        prop_assert_eq!(map::parse(&text).unwrap(), world.clone());
        // And its arena is the generator's.
        prop_assert_eq!(map::parse(&text).unwrap().build().unwrap(), world.build().unwrap());
    }

    #[test]
    fn the_reader_never_panics(text in "hypersynth map v1\n(grid\n)?[@ra.O+A_1 \t#\n\r]{0,80}") {
        if let Err(errors) = map::parse(&text) {
            let lines = text.split('\n').count();
            for e in &errors {
                prop_assert!(e.position.line >= 1 && e.position.line <= lines + 1);
                prop_assert!(e.position.column >= 1);
            }
            prop_assert!(errors.as_slice().is_sorted_by_key(|e| e.position));
        }
    }
}
