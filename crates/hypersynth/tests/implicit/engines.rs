//! The implicit engine against the explicit one, state by state: a map's rules against the arena
//! the map builds, and the index space's regions and labels against the stored product's, on
//! random text arenas and random maps (adversary chains, diamonds and cycles, adversary-first
//! maps, every collision rule, k = 1, 2 and 3 sub-tasks, psi a set of sub-tasks or an automaton).

use hypersynth::game::Wins;
use std::collections::BTreeMap;

use crate::common::{random_arena, random_dfa, random_world};
use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::arena::{Arena, Owner, StateId};
use hypersynth::automata::Dfa;
use hypersynth::game::{Belief, HState, Hypergame, States, TaskRegions, TaskSet};
use hypersynth::implicit::{ArenaMoves, MapMoves, Moves, Regions, Space};
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

fn below(rng: &mut ChaCha8Rng, n: u32) -> u32 {
    rng.next_u32() % n
}

/// What the explicit arena says of state `s`, in names: owner, label, edges, predecessors.
type Described = (
    Owner,
    Vec<String>,
    Vec<(String, String)>,
    BTreeMap<String, usize>,
);

fn explicit_state(arena: &Arena, s: StateId) -> Described {
    let label = arena
        .label(s)
        .iter()
        .map(|p| arena.propositions()[p].clone())
        .collect();
    let edges = arena
        .edges(s)
        .map(|(a, t)| (arena.action_name(a).to_string(), arena.name(t).to_string()))
        .collect();
    let mut predecessors = BTreeMap::new();
    for p in arena.states() {
        for (_, t) in arena.edges(p) {
            if t == s {
                *predecessors.entry(arena.name(p).to_string()).or_insert(0) += 1;
            }
        }
    }
    (arena.owner(s), label, edges, predecessors)
}

fn implicit_state(moves: &MapMoves, arena: &Arena, s: u32) -> Described {
    let label = moves.labels()[moves.label(s) as usize]
        .iter()
        .map(|p| moves.propositions()[p].clone())
        .collect();
    let mut edges = Vec::new();
    moves.edges(s, |a, t, label| {
        assert_eq!(
            label,
            moves.label(t),
            "the label given with an edge is its target's"
        );
        edges.push((arena.actions()[a as usize].clone(), moves.name(t)))
    });
    let mut predecessors = BTreeMap::new();
    moves.predecessors(s, |p| *predecessors.entry(moves.name(p)).or_insert(0) += 1);
    (moves.owner(s), label, edges, predecessors)
}

#[test]
fn a_maps_rules_describe_the_arena_the_map_builds() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for case in 0..300 {
        let world = random_world(&mut rng);
        let arena = world.build().unwrap();
        let moves = MapMoves::new(&world).unwrap();
        assert_eq!(moves.num_states(), arena.num_states(), "case {case}");
        assert_eq!(moves.initial(), arena.initial().as_u32(), "case {case}");
        assert_eq!(moves.propositions(), arena.propositions(), "case {case}");
        // Same labels in the same order: the automata's states are then enumerated alike.
        assert_eq!(moves.labels(), arena.labels(), "case {case}");
        let degree = arena.states().map(|s| arena.edges(s).len()).max().unwrap();
        assert!(moves.max_degree() as usize >= degree, "case {case}");
        for s in arena.states() {
            let h = s.as_u32();
            assert_eq!(moves.name(h), arena.name(s), "case {case}");
            assert_eq!(moves.label(h), arena.label_id(s), "case {case}");
            assert_eq!(
                implicit_state(&moves, &arena, h),
                explicit_state(&arena, s),
                "case {case}, state {}",
                arena.name(s)
            );
            assert_eq!(moves.degree(h) as usize, arena.edges(s).len());
            assert_eq!(moves.state_of(arena.name(s)), Some(h), "case {case}");
        }
    }
}

#[test]
fn a_maps_rules_find_a_state_by_name_as_the_arena_does() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let mut found = 0;
    for case in 0..40 {
        let world = random_world(&mut rng);
        let arena = world.build().unwrap();
        let moves = MapMoves::new(&world).unwrap();
        let mut names = Vec::new();
        // Every pair of cells on and off the grid (obstacles too), every turn and a bad one.
        for (xr, yr, xa, ya) in
            (0..25).flat_map(|r| (0..25).map(move |a| (r / 5, r % 5, a / 5, a % 5)))
        {
            for t in 0..3 {
                names.push(format!("(({xr},{yr}),({xa},{ya}),{t})"));
            }
        }
        // Other spellings of a state's numbers and punctuation.
        names.extend(
            [
                "( (0,0),(0,0),0)",
                "((00,0),(0,0),0)",
                "((0,0),(0,0),0) ",
                "((0,0),(0,0),0)0",
                "(0,0),(0,0),0",
                "((0,0),(0,0),0,0)",
                "((0;0),(0,0),0)",
                "((+0,0),(0,0),0)",
                "((4294967296,0),(0,0),0)",
                "",
                "s0",
            ]
            .map(String::from),
        );
        for name in &names {
            let expected = arena.find_state(name).map(StateId::as_u32);
            assert_eq!(moves.state_of(name), expected, "case {case}: {name:?}");
            found += usize::from(expected.is_some());
        }
    }
    assert!(found > 0);
}

#[test]
fn a_map_with_a_bad_parameter_is_refused_as_its_arena_is() {
    let world = Gridworld {
        obstacles: vec![Cell { x: 0, y: 0 }],
        ..Gridworld::new(2, 2, Cell { x: 0, y: 0 }, Cell { x: 1, y: 1 })
    };
    let expected = world.build().unwrap_err().to_string();
    assert_eq!(MapMoves::new(&world).unwrap_err().to_string(), expected);
}

/// Compares the implicit engine's product and regions with the explicit engine's on `moves`,
/// which describe `arena`, for sub-task automata `tasks` and, when `psi` is given, psi's own.
fn compare(moves: &impl Moves, arena: &Arena, tasks: &[Dfa], psi: Option<&Dfa>, case: &str) {
    let k = tasks.len();
    let mut automata: Vec<(&str, &Dfa)> = tasks.iter().map(|d| ("task", d)).collect();
    automata.extend(psi.map(|d| ("psi", d)));
    let game = Hypergame::with_automata(arena, &automata, States::Full).unwrap();
    let dfas: Vec<&Dfa> = automata.iter().map(|(_, d)| *d).collect();
    let space = Space::new(moves, &dfas).unwrap();
    assert_eq!(space.num_states(), game.num_states(), "{case}");
    assert_eq!(space.initial(), game.initial().as_u32(), "{case}");
    for h in game.states() {
        let i = h.as_u32();
        assert_eq!(space.name(i), game.name(h), "{case}");
        assert_eq!(space.owner(i), game.owner(h), "{case}");
        let mut edges = Vec::new();
        space.edges(i, |a, t| edges.push((a, HState::from_u32(t))));
        assert_eq!(
            edges,
            game.edges(h).collect::<Vec<_>>(),
            "{case} {}",
            game.name(h)
        );
        let mut predecessors = Vec::new();
        space.predecessors(i, |p| predecessors.push(HState::from_u32(p)));
        predecessors.sort();
        assert_eq!(
            predecessors,
            game.predecessors(h),
            "{case} {}",
            game.name(h)
        );
    }
    let belief = if psi.is_some() {
        Belief::Automaton
    } else {
        Belief::Tasks(TaskSet(1 + (case.len() % ((1 << k) - 1)) as u8))
    };
    let explicit = TaskRegions::compute(&game, k, belief);
    let implicit = Regions::compute(&space, k, belief);
    for set in TaskSet::non_empty(k) {
        assert_eq!(
            implicit.win(set),
            explicit.win(set).region(),
            "{case}: Win({set:?})"
        );
    }
    assert_eq!(
        implicit.believed(),
        explicit.believed().region(),
        "{case}: Win(psi)"
    );
    for h in game.states() {
        assert_eq!(implicit.label(h.as_u32()), explicit.label(h), "{case}");
    }
}

#[test]
fn regions_equal_the_explicit_engines_on_random_text_arenas() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for case in 0..300 {
        let arena = random_arena(&mut rng, case);
        let k = 1 + below(&mut rng, 3) as usize;
        let tasks: Vec<Dfa> = (0..k).map(|_| random_dfa(&mut rng)).collect();
        let psi = (below(&mut rng, 2) == 0).then(|| random_dfa(&mut rng));
        let moves = ArenaMoves::new(&arena);
        compare(
            &moves,
            &arena,
            &tasks,
            psi.as_ref(),
            &format!("arena case {case}"),
        );
    }
}

#[test]
fn regions_equal_the_explicit_engines_on_random_maps() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for case in 0..150 {
        let world = random_world(&mut rng);
        let arena = world.build().unwrap();
        let k = 1 + below(&mut rng, 3) as usize;
        let tasks: Vec<Dfa> = (0..k).map(|_| random_dfa(&mut rng)).collect();
        let psi = (below(&mut rng, 2) == 0).then(|| random_dfa(&mut rng));
        let moves = MapMoves::new(&world).unwrap();
        compare(
            &moves,
            &arena,
            &tasks,
            psi.as_ref(),
            &format!("map case {case}"),
        );
    }
}
