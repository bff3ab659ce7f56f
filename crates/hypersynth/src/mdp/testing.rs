//! Test support: small MDPs written as literals, seeded random MDPs and random intervals, an
//! evaluation of policies that shares no code with the solver (exact linear algebra instead of
//! iteration), and the adversary's inner minimum by enumeration of vertices.

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

use super::model::{ChoiceId, Mdp, MdpBuilder, MdpState};
use super::robust::Intervals;

/// MDP state `i`, for tests written with numbers.
pub(crate) fn ms(i: u32) -> MdpState {
    MdpState::from_u32(i)
}

/// MDP choice `i`.
pub(crate) fn mc(i: u32) -> ChoiceId {
    ChoiceId::from_u32(i)
}

/// A distribution with numbered targets, as MDP states.
fn distribution(successors: &[(u32, f64)]) -> Vec<(MdpState, f64)> {
    successors.iter().map(|&(t, p)| (ms(t), p)).collect()
}

/// One state of a literal MDP: its choices `(action, [(target, probability)])`, or a payoff.
pub(crate) enum Spec<'a> {
    Decide(&'a [(&'a str, &'a [(u32, f64)])]),
    Absorb(f64),
}

/// The MDP with the given states, initial state 0.
pub(crate) fn mdp_from(states: &[Spec]) -> Mdp {
    let mut builder = MdpBuilder::new();
    for spec in states {
        match spec {
            Spec::Decide(choices) => {
                builder.add_decision_state().unwrap();
                for (action, successors) in *choices {
                    let action = builder.action(action).unwrap();
                    builder
                        .add_choice(action, &distribution(successors))
                        .unwrap();
                }
            }
            Spec::Absorb(payoff) => {
                builder.add_absorbing_state(*payoff).unwrap();
            }
        }
    }
    builder.set_initial(ms(0));
    builder.build().unwrap()
}

/// Decision states with one choice `go` each (the given distributions), then absorbing states
/// with the given payoffs; initial state 0.
pub(crate) fn chain_mdp(distributions: &[Vec<(u32, f64)>], payoffs: &[f64]) -> Mdp {
    let mut builder = MdpBuilder::new();
    let go = builder.action("go").unwrap();
    for successors in distributions {
        builder.add_decision_state().unwrap();
        builder.add_choice(go, &distribution(successors)).unwrap();
    }
    for &payoff in payoffs {
        builder.add_absorbing_state(payoff).unwrap();
    }
    builder.set_initial(ms(0));
    builder.build().unwrap()
}

pub(crate) fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

fn below(rng: &mut ChaCha8Rng, bound: u32) -> u32 {
    rng.next_u32() % bound
}

/// A random MDP of 2..=`max_states` states: about a third absorbing with payoffs in
/// {0, 1, 2, 5} (so that values tie and zero regions occur), the others with 1..=3 choices over
/// 1..=3 targets drawn with replacement (self-loops and cycles, hence end components, are
/// common) and integer weights 1..=4.
pub(crate) fn random_mdp(rng: &mut ChaCha8Rng, max_states: u32) -> Mdp {
    random_mdp_with_weights(rng, max_states, &[1.0, 2.0, 3.0, 4.0])
}

/// Like [`random_mdp`], with the transition weights drawn from `weights` (e.g. `[1, 1e6]`
/// makes exits of probability about 1e-6 common).
pub(crate) fn random_mdp_with_weights(
    rng: &mut ChaCha8Rng,
    max_states: u32,
    weights: &[f64],
) -> Mdp {
    random_mdp_of(rng, max_states, weights, false)
}

/// Like [`random_mdp`], with about a third of the choices instant (not discounted, no move).
pub(crate) fn random_mdp_with_instant_choices(rng: &mut ChaCha8Rng, max_states: u32) -> Mdp {
    random_mdp_of(rng, max_states, &[1.0, 2.0, 3.0, 4.0], true)
}

fn random_mdp_of(rng: &mut ChaCha8Rng, max_states: u32, weights: &[f64], instants: bool) -> Mdp {
    let n = 2 + below(rng, max_states - 1);
    let mut builder = MdpBuilder::new();
    let actions = ["a", "b", "c"].map(|name| builder.action(name).unwrap());
    for _ in 0..n {
        if below(rng, 3) == 0 {
            builder
                .add_absorbing_state([0.0, 1.0, 2.0, 5.0][below(rng, 4) as usize])
                .unwrap();
            continue;
        }
        builder.add_decision_state().unwrap();
        for &action in &actions[..1 + below(rng, 3) as usize] {
            let successors: Vec<(u32, f64)> = (0..1 + below(rng, 3))
                .map(|_| {
                    (
                        below(rng, n),
                        weights[below(rng, weights.len() as u32) as usize],
                    )
                })
                .collect();
            let total: f64 = successors.iter().map(|(_, weight)| weight).sum();
            let distribution: Vec<(MdpState, f64)> = successors
                .iter()
                .map(|&(t, weight)| (ms(t), weight / total))
                .collect();
            if instants && below(rng, 3) == 0 {
                builder.add_instant_choice(action, &distribution).unwrap();
            } else {
                builder.add_choice(action, &distribution).unwrap();
            }
        }
    }
    builder.set_initial(ms(0));
    builder.build().unwrap()
}

/// The exact value of a memoryless policy (`policy[s]` = the choice played in decision state
/// `s`): states that cannot reach a positive payoff in the policy's Markov chain are worth 0;
/// the others solve `x = g · P x + g · P payoff`, which has a unique solution because each of
/// them leaves the set with positive probability. Solved by Gaussian elimination.
pub(crate) fn policy_value(mdp: &Mdp, policy: &[Option<ChoiceId>], g: f64) -> Vec<f64> {
    let n = mdp.num_states();
    let payoff = |t: MdpState| mdp.payoff(t).unwrap_or(0.0);
    let mut reaches = vec![false; n];
    let mut changed = true;
    while changed {
        changed = false;
        for s in 0..n {
            if let Some(choice) = policy[s]
                && !reaches[s]
                && mdp
                    .targets(choice)
                    .iter()
                    .any(|&t| payoff(t) > 0.0 || reaches[t.index()])
            {
                reaches[s] = true;
                changed = true;
            }
        }
    }
    let unknowns: Vec<usize> = (0..n).filter(|&s| reaches[s]).collect();
    let mut column = vec![usize::MAX; n];
    for (i, &s) in unknowns.iter().enumerate() {
        column[s] = i;
    }
    let m = unknowns.len();
    // Row i: x_i = Σ_j w_ij x_j + stay_i x_i + rhs_i, with the probability of leaving the
    // unknowns (`leak`, including the discount's 1 − g) kept apart, so that 1 − stay_i is
    // always leak_i + Σ_j w_ij: a sum, never a difference (exits of 1e-6 stay exact).
    let mut w = vec![vec![0.0f64; m]; m];
    let mut leak = vec![0.0f64; m];
    let mut rhs = vec![0.0f64; m];
    for (i, &s) in unknowns.iter().enumerate() {
        for (t, p) in mdp.successors(policy[s].unwrap()) {
            if reaches[t.index()] {
                if column[t.index()] != i {
                    w[i][column[t.index()]] += g * p;
                }
            } else {
                leak[i] += g * p;
                rhs[i] += g * p * payoff(t);
            }
        }
        leak[i] += 1.0 - g;
    }
    // Eliminate every unknown from every other row (Gauss–Jordan by state elimination).
    for k in 0..m {
        let exit: f64 = leak[k] + w[k].iter().sum::<f64>();
        assert!(exit > 0.0, "singular policy system");
        let row_k = w[k].clone();
        let rows: Vec<usize> = (0..m).filter(|&i| i != k && w[i][k] > 0.0).collect();
        for i in rows {
            let factor = w[i][k] / exit;
            w[i][k] = 0.0;
            for j in (0..m).filter(|&j| j != k && j != i) {
                w[i][j] += factor * row_k[j];
            }
            leak[i] += factor * leak[k];
            rhs[i] += factor * rhs[k];
        }
    }
    (0..n)
        .map(|s| {
            if mdp.is_absorbing(MdpState::new(s)) {
                payoff(MdpState::new(s))
            } else if reaches[s] {
                // Every other unknown has been eliminated from this row.
                rhs[column[s]] / leak[column[s]]
            } else {
                0.0
            }
        })
        .collect()
}

/// The optimal values, as the pointwise maximum over every deterministic memoryless policy
/// (such policies suffice for expected payoff at absorption).
pub(crate) fn optimal_values_by_enumeration(mdp: &Mdp, g: f64) -> Vec<f64> {
    let states: Vec<MdpState> = mdp.states().filter(|&s| !mdp.is_absorbing(s)).collect();
    let mut policy: Vec<Option<ChoiceId>> = mdp
        .states()
        .map(|s| (!mdp.is_absorbing(s)).then(|| mdp.choices(s).start()))
        .collect();
    let mut best = policy_value(mdp, &policy, g);
    // Odometer over the choices of the decision states.
    'policies: loop {
        for &s in &states {
            let current = policy[s.index()].unwrap();
            let next = ChoiceId::new(current.index() + 1);
            if next < mdp.choices(s).end() {
                policy[s.index()] = Some(next);
                let value = policy_value(mdp, &policy, g);
                for (b, v) in best.iter_mut().zip(value) {
                    *b = b.max(v);
                }
                continue 'policies;
            }
            policy[s.index()] = Some(mdp.choices(s).start());
        }
        return best;
    }
}

/// Random intervals around the model's probabilities on about half of the choices with two
/// targets or more: widths 0 (a point), 0.1, 0.3 or 1 on either side.
pub(crate) fn random_intervals(rng: &mut ChaCha8Rng, mdp: &Mdp) -> Intervals {
    let mut intervals = Intervals::exact(mdp);
    let widths = [0.0, 0.1, 0.3, 1.0];
    for choice in mdp.all_choices() {
        if mdp.targets(choice).len() < 2 || rng.next_u32().is_multiple_of(2) {
            continue;
        }
        let bounds: Vec<[f64; 2]> = mdp
            .successors(choice)
            .map(|(_, p)| {
                let below = widths[rng.next_u32() as usize % 4];
                let above = widths[rng.next_u32() as usize % 4];
                [(p - below).max(0.0), (p + above).min(1.0)]
            })
            .collect();
        intervals.set(mdp, choice, &bounds).unwrap();
    }
    intervals
}

/// The least value of `Σ p · v` over the vertices of `{l ≤ p ≤ u, Σ p = 1}`: every coordinate
/// but one at a bound, the free one taking the rest (when that fits its interval).
pub(crate) fn vertex_minimum(values: &[f64], bounds: &[[f64; 2]]) -> f64 {
    let k = values.len();
    let mut best = f64::INFINITY;
    for free in 0..k {
        for mask in 0..1u32 << k {
            let mut p = vec![0.0; k];
            let mut used = 0.0;
            for i in (0..k).filter(|&i| i != free) {
                p[i] = bounds[i][((mask >> i) & 1) as usize];
                used += p[i];
            }
            p[free] = 1.0 - used;
            if p[free] >= bounds[free][0] - 1e-12 && p[free] <= bounds[free][1] + 1e-12 {
                best = best.min(p.iter().zip(values).map(|(p, v)| p * v).sum());
            }
        }
    }
    best
}
