//! The implicit engine's robust solve against the explicit one's (`mdp::robust`), state by
//! state, on random text arenas and maps with random probability intervals where sigma_L
//! rules; and its policy's worst case, found by the explicit robust solver on the interval
//! Markov chain the policy induces, against the certified lower bounds.

use super::solve::{EPSILON, random_tasks, with_model};
use crate::common::{random_arena, random_world};
use hypersynth::arena::{Arena, Owner};
use hypersynth::game::States;
use hypersynth::implicit::{
    ArenaMoves, Intervals, Kind, MapMoves, Model, Moves, Policy, Precision, Solution,
    robust_policy, solve_robust,
};
use hypersynth::mdp::robust::{self, Intervals as ChoiceIntervals};
use hypersynth::mdp::solve::{Discount, SolveOptions};
use hypersynth::mdp::{Mdp, MdpBuilder, MdpState};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::build::HypergameMdp;
use hypersynth::opportunistic::view::{GameView, SolvedHypergame};
use hypersynth::pipeline::Tasks;
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

fn below(rng: &mut ChaCha8Rng, n: u32) -> u32 {
    rng.next_u32() % n
}

/// Random intervals for about half of the adversary arena states with two edges or more, as
/// a learnt region makes them: an estimate from random counts and a random radius, cut to
/// [0, 1] (the others keep [0, 1] on every edge).
fn random_rows(rng: &mut ChaCha8Rng, arena: &Arena) -> Vec<(u32, Vec<[f64; 2]>)> {
    let mut rows = Vec::new();
    for s in arena.states() {
        let degree = arena.edges(s).len();
        if arena.owner(s) != Owner::Adversary || degree < 2 || below(rng, 2) == 0 {
            continue;
        }
        let counts: Vec<u32> = (0..degree).map(|_| below(rng, 5)).collect();
        let total: u32 = counts.iter().sum();
        if total == 0 {
            continue;
        }
        let radius = [0.0, 0.05, 0.2, 0.6][below(rng, 4) as usize];
        let row = counts
            .iter()
            .map(|&c| {
                let p = f64::from(c) / f64::from(total);
                [(p - radius).max(0.0), (p + radius).min(1.0)]
            })
            .collect();
        rows.push((s.as_u32(), row));
    }
    rows
}

/// The explicit MDP's intervals: at each chance node where sigma_L rules, the rows' interval
/// of each edge (merged where two edges reach the same state: their sum, cut at 1).
fn choice_intervals(
    solved: &SolvedHypergame<'_, '_>,
    adversary: &AdversaryModel,
    mdp: &HypergameMdp,
    intervals: &Intervals,
) -> ChoiceIntervals {
    let m = mdp.mdp();
    let mut result = ChoiceIntervals::exact(m);
    let mut row = Vec::new();
    for h in solved.states() {
        let node = mdp.node(h);
        if solved.is_robot(h) || adversary.plays_sigma_w(h) || m.is_absorbing(node) {
            continue;
        }
        let choice = m.choices(node).start();
        let targets = m.targets(choice);
        let edges: Vec<_> = solved.edges(h).collect();
        let s = solved.arena_state(h);
        intervals.row(s.as_u32(), edges.len(), &mut row);
        let mut merged = vec![[0.0f64, 0.0f64]; targets.len()];
        for (k, (_, t)) in edges.iter().enumerate() {
            let i = targets.iter().position(|&x| x == mdp.node(*t)).unwrap();
            merged[i][0] += row[k][0];
            merged[i][1] += row[k][1];
        }
        for b in &mut merged {
            b[1] = b[1].min(1.0);
            b[0] = b[0].min(b[1]);
        }
        result.set(m, choice, &merged).unwrap();
    }
    result
}

/// The interval Markov chain `policy` induces on `m`: each decision state keeps the choice at
/// the policy's position alone.
fn induced<M: Moves>(
    m: &Mdp,
    intervals: &ChoiceIntervals,
    model: &Model<'_, '_, M>,
    policy: &Policy,
) -> (Mdp, ChoiceIntervals) {
    let mut builder = MdpBuilder::new();
    let play = builder.action("play").unwrap();
    let mut kept = Vec::new();
    for s in m.states() {
        if let Some(payoff) = m.payoff(s) {
            builder.add_absorbing_state(payoff).unwrap();
            continue;
        }
        builder.add_decision_state().unwrap();
        let mut choices = m.choices(s);
        let choice = match (s.index() < model.space().num_states())
            .then(|| policy.mdp_choice(s.index() as u32))
            .flatten()
        {
            Some(position) => choices.nth(usize::from(position)).unwrap(),
            None => choices.next().unwrap(),
        };
        let successors: Vec<(MdpState, f64)> = m.successors(choice).collect();
        if m.is_instant(choice) {
            builder.add_instant_choice(play, &successors).unwrap();
        } else {
            builder.add_choice(play, &successors).unwrap();
        }
        kept.push(choice);
    }
    builder.set_initial(m.initial());
    let chain = builder.build().unwrap();
    let mut chain_intervals = ChoiceIntervals::exact(&chain);
    for (new, &old) in chain.all_choices().zip(&kept) {
        if let Some(bounds) = intervals.get(m, old) {
            chain_intervals.set(&chain, new, bounds).unwrap();
        }
    }
    (chain, chain_intervals)
}

/// Solves `tasks` on `arena` (described by `moves`) robustly with both engines at discount `g`
/// against random intervals, and compares every product state's bounds; then checks that the
/// implicit robust policy collects its certified lower bound from every state against the
/// worst adversary within the intervals. Returns the states where the robust value is below
/// the nominal (uniform) one by more than the precision.
fn compare<M: Moves>(
    moves: &M,
    arena: &Arena,
    tasks: &Tasks,
    (g, rng): (f64, &mut ChaCha8Rng),
    case: &str,
) -> usize {
    let rows = random_rows(rng, arena);
    let intervals = Intervals::new(rows);
    let game = tasks.hypergame(arena, States::Full).unwrap();
    let regions = tasks.regions(&game);
    let solved = SolvedHypergame::new(&game, &regions, tasks.payoffs(), tasks.presentation());
    let adversary = AdversaryModel::new(&solved, &SigmaL::Uniform).unwrap();
    let mdp = HypergameMdp::build(&solved, &adversary, tasks.risk()).unwrap();
    let explicit_intervals = choice_intervals(&solved, &adversary, &mdp, &intervals);
    let options = SolveOptions {
        discount: Discount::new(g).unwrap(),
        epsilon: EPSILON,
        ..SolveOptions::default()
    };
    let explicit = robust::solve(mdp.mdp(), &explicit_intervals, &options).unwrap();
    let nominal = hypersynth::mdp::solve::solve(mdp.mdp(), &options).unwrap();
    with_model(moves, tasks, &SigmaL::Uniform, |model| {
        let model = model.unwrap();
        let precision = Precision::absolute(EPSILON);
        let implicit: Solution = solve_robust(&model, &intervals, g, precision, 100_000).unwrap();
        let mut lowered = 0;
        for h in game.states() {
            let node = MdpState::new(h.index());
            let e = explicit.value(node);
            let i = implicit.value(&model, h.as_u32());
            let name = game.name(h);
            assert!(
                i.upper - i.lower <= EPSILON,
                "{case} {name}: implicit {i:?}"
            );
            assert!(
                i.lower <= e.upper + 1e-9 && e.lower <= i.upper + 1e-9,
                "{case} {name}, g = {g}: explicit {e:?}, implicit {i:?}"
            );
            lowered += usize::from(i.upper < nominal.value(node).lower - EPSILON);
        }
        let policy = robust_policy(&model, &intervals, &implicit, g).unwrap();
        let (chain, chain_intervals) = induced(mdp.mdp(), &explicit_intervals, &model, &policy);
        let worst = robust::solve(&chain, &chain_intervals, &options).unwrap();
        for h in game.states() {
            if matches!(model.kind(h.as_u32()), Kind::Absorbing(_)) {
                continue;
            }
            let w = worst.value(MdpState::new(h.index()));
            let i = implicit.value(&model, h.as_u32());
            assert!(
                w.upper >= i.lower - 2.0 * EPSILON - 1e-9 * i.lower,
                "{case} {}, g = {g}: the policy collects {w:?} against the worst case, \
                 below the certified {i:?}",
                game.name(h)
            );
        }
        lowered
    })
}

#[test]
fn robust_values_equal_the_explicit_engines_on_random_text_arenas() {
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let mut lowered = 0;
    for case in 0..80 {
        let arena = random_arena(&mut rng, case);
        let tasks = random_tasks(&mut rng);
        let moves = ArenaMoves::new(&arena);
        let g = [0.9, 0.99, 1.0][below(&mut rng, 3) as usize];
        let case = format!("arena case {case}");
        lowered += compare(&moves, &arena, &tasks, (g, &mut rng), &case);
    }
    assert!(
        lowered > 20,
        "only {lowered} states lost value to the intervals"
    );
}

#[test]
fn robust_values_equal_the_explicit_engines_on_random_maps() {
    let mut rng = ChaCha8Rng::seed_from_u64(43);
    let mut lowered = 0;
    for case in 0..40 {
        let world = random_world(&mut rng);
        let arena = world.build().unwrap();
        let tasks = random_tasks(&mut rng);
        let moves = MapMoves::new(&world).unwrap();
        let g = [0.9, 0.99, 1.0][below(&mut rng, 3) as usize];
        let case = format!("map case {case}");
        lowered += compare(&moves, &arena, &tasks, (g, &mut rng), &case);
    }
    // The random maps are small and mostly won: few states lose value there.
    assert!(lowered > 0, "no state lost value to the intervals");
}
