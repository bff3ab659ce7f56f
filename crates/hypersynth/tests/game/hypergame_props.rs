//! Random arenas and random DFAs: the product against a naive construction, the linear attractor
//! against a naive fixpoint iteration, the invariants of the win-labels, and the strategies
//! against every adversary behaviour.

use hypersynth::game::Wins;
use std::collections::{HashMap, HashSet, VecDeque};

use crate::common::{PAPER_TASKS, PHI, PHI1, PHI2, dfa_from_table, strategy_failures};
use bit_set::BitSet;
use hypersynth::arena::{Arena, ArenaBuilder, Owner, StateId};
use hypersynth::automata::Dfa;
use hypersynth::game::{
    HState, Hypergame, Partition, ProductState, ReactiveStrategy, States, WinLabel,
};
use proptest::prelude::*;

const PROPOSITIONS: [&str; 3] = ["a", "b", "c"];
const ACTIONS: [&str; 3] = ["x", "y", "z"];

/// States with an owner (robot if true), a label (bits over `PROPOSITIONS`) and edges
/// (action index, target); repeated actions of a state are dropped when building.
type ArenaSpec = (Vec<(bool, u8, Vec<(usize, usize)>)>, usize);

fn arena_spec() -> impl Strategy<Value = ArenaSpec> {
    (1usize..9).prop_flat_map(|n| {
        let state = (
            any::<bool>(),
            0u8..8,
            prop::collection::vec((0..ACTIONS.len(), 0..n), 0..4),
        );
        (prop::collection::vec(state, n), 0..n)
    })
}

fn build_arena((states, initial): &ArenaSpec) -> Arena {
    let mut b = ArenaBuilder::new();
    for (i, (robot, label, _)) in states.iter().enumerate() {
        let owner = if *robot {
            Owner::Robot
        } else {
            Owner::Adversary
        };
        let props = PROPOSITIONS
            .iter()
            .enumerate()
            .filter(|(bit, _)| label & (1 << bit) != 0)
            .map(|(_, p)| *p);
        b.add_state(&format!("s{i}"), owner, props, None).unwrap();
    }
    for (i, (_, _, edges)) in states.iter().enumerate() {
        let mut used = HashSet::new();
        for &(action, target) in edges {
            if used.insert(action) {
                b.add_transition(StateId::new(i), ACTIONS[action], StateId::new(target))
                    .unwrap();
            }
        }
    }
    b.set_initial(StateId::new(*initial));
    b.build().unwrap()
}

/// A random complete DFA over up to three propositions, possibly one (`d`) no arena carries.
fn dfa() -> impl Strategy<Value = Dfa> {
    (
        prop::sample::subsequence(vec!["a", "b", "c", "d"], 0..=3),
        1usize..5,
    )
        .prop_flat_map(|(aps, k)| {
            let letters = 1usize << aps.len();
            (
                Just(aps),
                prop::collection::vec(prop::collection::vec(0..k as u32, letters), k),
                prop::collection::vec(any::<bool>(), k),
                0..k as u32,
            )
        })
        .prop_map(|(aps, table, finals, initial)| {
            let finals: Vec<u32> = (0..finals.len() as u32)
                .filter(|&q| finals[q as usize])
                .collect();
            dfa_from_table(&aps, initial, &finals, &table)
        })
}

/// The DFA's letter for the label of arena state `s`, by proposition names.
fn letter(dfa: &Dfa, arena: &Arena, s: StateId) -> u64 {
    dfa.letter(
        arena
            .label(s)
            .iter()
            .map(|p| arena.propositions()[p].as_str()),
    )
}

/// The DFA states reachable from the initial one by sequences of letters of arena states.
fn naive_reachable_dfa_states(dfa: &Dfa, arena: &Arena) -> Vec<u32> {
    let mut seen = vec![dfa.initial()];
    let mut i = 0;
    while i < seen.len() {
        for s in arena.states() {
            let q = dfa.step(seen[i], letter(dfa, arena, s));
            if !seen.contains(&q) {
                seen.push(q);
            }
        }
        i += 1;
    }
    seen
}

/// The successors of a product triple, stepping the DFAs on every edge.
fn naive_edges(
    arena: &Arena,
    d1: &Dfa,
    d2: &Dfa,
    (s, q1, q2): (StateId, u32, u32),
) -> Vec<(String, (StateId, u32, u32))> {
    arena
        .edges(s)
        .map(|(a, t)| {
            let target = (
                t,
                d1.step(q1, letter(d1, arena, t)),
                d2.step(q2, letter(d2, arena, t)),
            );
            (arena.action_name(a).to_string(), target)
        })
        .collect()
}

/// The triples of the product, per enumeration, computed directly from docs/semantics.md §4.
fn naive_product_states(
    arena: &Arena,
    d1: &Dfa,
    d2: &Dfa,
    states: States,
) -> HashSet<(StateId, u32, u32)> {
    match states {
        States::Full => {
            let r1 = naive_reachable_dfa_states(d1, arena);
            let r2 = naive_reachable_dfa_states(d2, arena);
            let mut all = HashSet::new();
            for s in arena.states() {
                for &q1 in &r1 {
                    for &q2 in &r2 {
                        all.insert((s, q1, q2));
                    }
                }
            }
            all
        }
        States::Reachable => {
            let s0 = arena.initial();
            let h0 = (
                s0,
                d1.step(d1.initial(), letter(d1, arena, s0)),
                d2.step(d2.initial(), letter(d2, arena, s0)),
            );
            let mut seen = HashSet::from([h0]);
            let mut queue = VecDeque::from([h0]);
            while let Some(h) = queue.pop_front() {
                for (_, t) in naive_edges(arena, d1, d2, h) {
                    if seen.insert(t) {
                        queue.push_back(t);
                    }
                }
            }
            seen
        }
    }
}

fn triple(game: &Hypergame, h: HState) -> (StateId, u32, u32) {
    let ProductState { arena, q1, q2 } = game.state(h);
    (arena, q1, q2)
}

/// Attractor by the definition: iterate `A_{k+1} = A_k ∪ CPre(A_k)` until stable, ranking each
/// state by the iteration in which it first appears.
fn naive_attractor(game: &Hypergame, targets: &BitSet) -> Vec<Option<u32>> {
    let n = game.num_states();
    let mut ranks: Vec<Option<u32>> = (0..n).map(|h| targets.contains(h).then_some(0)).collect();
    for level in 1.. {
        let inside = ranks.clone();
        let joins = |h: usize| {
            let mut succs = game
                .successors(HState::new(h))
                .map(|t| inside[t.index()].is_some());
            match game.owner(HState::new(h)) {
                Owner::Robot => succs.any(|x| x),
                Owner::Adversary => succs.all(|x| x),
            }
        };
        let new: Vec<usize> = (0..n)
            .filter(|&h| inside[h].is_none() && joins(h))
            .collect();
        if new.is_empty() {
            break;
        }
        for h in new {
            ranks[h] = Some(level);
        }
    }
    ranks
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn product_matches_the_naive_construction(spec in arena_spec(), d1 in dfa(), d2 in dfa()) {
        let arena = build_arena(&spec);
        for states in [States::Full, States::Reachable] {
            let game = Hypergame::new(&arena, &d1, &d2, states).unwrap();
            let expected = naive_product_states(&arena, &d1, &d2, states);
            let actual: HashSet<_> = game.states().map(|h| triple(&game, h)).collect();
            prop_assert_eq!(actual.len(), game.num_states(), "states are distinct");
            prop_assert_eq!(&actual, &expected);
            let s0 = arena.initial();
            let h0 = (s0, d1.step(d1.initial(), letter(&d1, &arena, s0)), d2.step(d2.initial(), letter(&d2, &arena, s0)));
            prop_assert_eq!(triple(&game, game.initial()), h0);
            let mut predecessors: HashMap<HState, Vec<HState>> = HashMap::new();
            for h in game.states() {
                let edges: Vec<_> = game.edges(h).map(|(a, t)| (arena.action_name(a).to_string(), triple(&game, t))).collect();
                prop_assert_eq!(edges, naive_edges(&arena, &d1, &d2, triple(&game, h)));
                prop_assert_eq!(game.owner(h), arena.owner(game.state(h).arena));
                prop_assert_eq!(game.parse_state(&game.name(h)), Ok(h));
                for t in game.successors(h) {
                    predecessors.entry(t).or_default().push(h);
                }
            }
            for h in game.states() {
                let mut expected = predecessors.remove(&h).unwrap_or_default();
                let mut actual = game.predecessors(h).to_vec();
                expected.sort_unstable();
                actual.sort_unstable();
                prop_assert_eq!(actual, expected);
            }
            let missing: Vec<&str> = d1.aps().iter().chain(d2.aps()).filter(|ap| arena.find_proposition(ap).is_none_or(|p| !arena.labels().iter().any(|l| l.contains(p as usize)))).map(String::as_str).collect::<Vec<_>>();
            let mut missing_unique: Vec<&str> = Vec::new();
            for ap in missing {
                if !missing_unique.contains(&ap) {
                    missing_unique.push(ap);
                }
            }
            prop_assert_eq!(game.missing_propositions(), missing_unique);
        }
    }

    #[test]
    fn attractors_match_the_naive_fixpoint_and_labels_are_consistent(spec in arena_spec(), d1 in dfa(), d2 in dfa()) {
        let arena = build_arena(&spec);
        for states in [States::Full, States::Reachable] {
            let game = Hypergame::new(&arena, &d1, &d2, states).unwrap();
            let regions = crate::common::paper_regions(&game);
            for (_, set) in PAPER_TASKS {
                let naive = naive_attractor(&game, &game.targets(set));
                let win = regions.win(set);
                let ranks: Vec<Option<u32>> = game.states().map(|h| win.rank(h)).collect();
                prop_assert_eq!(&ranks, &naive);
                let region: Vec<usize> = win.region().iter().collect();
                let naive_region: Vec<usize> = (0..naive.len()).filter(|&h| naive[h].is_some()).collect();
                prop_assert_eq!(win.len(), naive_region.len());
                prop_assert_eq!(region, naive_region);
                prop_assert_eq!(win.max_rank(), naive.iter().flatten().max().copied());
            }
            let partition = Partition::compute(&game, &regions);
            let total: usize = partition.iter().map(|(_, c)| c.total).sum();
            prop_assert_eq!(total, game.num_states());
            for (label, counts) in partition.iter() {
                prop_assert_eq!(counts.robot + counts.adversary, counts.total);
                if !label.is_possible() {
                    prop_assert_eq!(counts.total, 0, "impossible label {}", label);
                }
            }
            let winning = |label: WinLabel| partition.get(label).total;
            prop_assert_eq!(
                regions.win(PHI1).len(),
                WinLabel::ALL.into_iter().filter(|l| l.phi1).map(winning).sum::<usize>()
            );
        }
    }

    #[test]
    fn full_regions_of_one_task_ignore_the_other_automaton(spec in arena_spec(), d1 in dfa(), d2 in dfa()) {
        let arena = build_arena(&spec);
        let game = Hypergame::new(&arena, &d1, &d2, States::Full).unwrap();
        let regions = crate::common::paper_regions(&game);
        let (n1, n2) = (game.q1_states().len(), game.q2_states().len());
        prop_assert_eq!(regions.win(PHI1).len() % n2, 0);
        prop_assert_eq!(regions.win(PHI2).len() % n1, 0);
        // Stronger: membership and rank are constant on every block {(s, q1)} × Q2.
        for h in game.states() {
            let ProductState { arena: s, q1, q2 } = game.state(h);
            for &other in game.q2_states() {
                let g = game.find(ProductState { arena: s, q1, q2: other }).unwrap();
                prop_assert_eq!(regions.win(PHI1).rank(g), regions.win(PHI1).rank(h));
            }
            for &other in game.q1_states() {
                let g = game.find(ProductState { arena: s, q1: other, q2 }).unwrap();
                prop_assert_eq!(regions.win(PHI2).rank(g), regions.win(PHI2).rank(h));
            }
        }
    }

    #[test]
    fn strategies_win_within_the_rank_and_the_adversary_stays_out(spec in arena_spec(), d1 in dfa(), d2 in dfa()) {
        let arena = build_arena(&spec);
        for states in [States::Full, States::Reachable] {
            let game = Hypergame::new(&arena, &d1, &d2, states).unwrap();
            let regions = crate::common::paper_regions(&game);
            for (_, set) in PAPER_TASKS {
                let win = regions.win(set);
                let robot = ReactiveStrategy::robot(&game, win);
                let adversary = ReactiveStrategy::adversary(&game, win);
                prop_assert_eq!(strategy_failures(&game, set, win), Vec::<String>::new());
                for h in game.states() {
                    let robot_turn = game.owner(h) == Owner::Robot;
                    prop_assert_eq!(robot.is_defined(h), robot_turn && win.contains(h));
                    prop_assert_eq!(adversary.is_defined(h), !robot_turn && !win.contains(h));
                    if robot_turn && win.rank(h).is_some_and(|rank| rank > 0) {
                        prop_assert!(robot.moves(&game, h).next().is_some());
                    }
                    // Outside Win the adversary always has a move, and no play it allows, nor
                    // any robot move, enters Win.
                    if !win.contains(h) {
                        let next: Vec<HState> = if robot_turn {
                            game.successors(h).collect()
                        } else {
                            adversary.moves(&game, h).map(|(_, t)| t).collect()
                        };
                        prop_assert!(robot_turn || !next.is_empty());
                        // Maximally permissive: every move that stays out is allowed.
                        let staying_out = game.successors(h).filter(|&t| !win.contains(t)).count();
                        prop_assert_eq!(next.len(), staying_out);
                        prop_assert!(next.iter().all(|&t| !win.contains(t)));
                    }
                }
            }
            prop_assert_eq!(regions.win(PHI).contains(game.initial()), regions.win_label(game.initial()).phi);
        }
    }
}
