//! Where a Markov chain first leaves a set of *transient* states: the distribution over the
//! first non-transient state reached (docs/semantics.md §6.9, the next robot states of a
//! decision table, where the transient states are the adversary's chance nodes, in the
//! explicit MDP or the implicit engine's model alike: the chain is given by a successor
//! function).
//!
//! Started with some mass on states, the chain moves through transient states by their
//! successors (an MDP state by its first choice). The mass that reaches each exit is `start(e) + Σ_c y(c) · P(c, e)`, where `y(c)` is
//! the expected number of visits of transient state `c`: `y = b + Qᵀ y`, `b` the start mass on
//! transient states and `Q` the transient part of the chain. Transient states from which no
//! exit can be reached form closed sets that keep their mass forever: it is reported as never
//! leaving. On the others, `I − Qᵀ` is invertible; it is solved one strongly connected
//! component at a time in topological order, exactly (Gaussian elimination with partial
//! pivoting) for components of up to `EXACT_LIMIT` (256) states, by Gauss–Seidel sweeps until the
//! visits change by less than 1e-15 of themselves otherwise.
//!
//! Cost: linear in the transient states reached and their transitions, plus the cube of the
//! largest component solved exactly. Only the states reachable from the start are looked at.

use std::collections::{BTreeMap, HashMap};
use std::hash::Hash;

use super::graph::strongly_connected_components;
use super::model::{Mdp, MdpState};
use crate::csr::Csr;

/// The largest strongly connected component solved by elimination; larger ones are iterated.
const EXACT_LIMIT: usize = 256;

/// The most sweeps spent on a large component.
const MAX_SWEEPS: u32 = 1_000_000;

/// The probability of each state being the first non-transient state reached from `start`
/// (pairs of state and mass, summing to 1), by exit state in ascending order; `None` carries
/// the mass that stays among transient states forever (absent when there is none). A transient
/// state moves as `successors` (called once per transient state reached) lists its moves, with
/// their probabilities: in an MDP, its first choice ([`choice_successors`]); in the implicit
/// engine's model, the adversary's distribution.
pub fn first_exits<S: Copy + Ord + Hash>(
    start: impl IntoIterator<Item = (S, f64)>,
    is_transient: impl Fn(S) -> bool,
    mut successors: impl FnMut(S, &mut Vec<(S, f64)>),
) -> Vec<(Option<S>, f64)> {
    let mut exits: BTreeMap<S, f64> = BTreeMap::new();
    // The transient states reached, numbered in the order found, with their start mass.
    let mut local: HashMap<S, u32> = HashMap::new();
    let mut states: Vec<S> = Vec::new();
    let mut mass: Vec<f64> = Vec::new();
    let enter = |s: S, local: &mut HashMap<S, u32>, states: &mut Vec<_>| {
        *local.entry(s).or_insert_with(|| {
            states.push(s);
            (states.len() - 1) as u32
        })
    };
    for (s, p) in start {
        if is_transient(s) {
            let i = enter(s, &mut local, &mut states) as usize;
            mass.resize(states.len(), 0.0);
            mass[i] += p;
        } else {
            *exits.entry(s).or_default() += p;
        }
    }
    let mut next = 0;
    // Successor lists over the local numbering: transient successors (local ids) and exits.
    let mut inner: Csr<u32, (u32, f64)> = Csr::new();
    let mut outer: Vec<Vec<(S, f64)>> = Vec::new();
    let mut moves = Vec::new();
    while next < states.len() {
        moves.clear();
        successors(states[next], &mut moves);
        let mut out = Vec::new();
        for &(t, p) in &moves {
            if is_transient(t) {
                let j = enter(t, &mut local, &mut states);
                inner.push((j, p));
            } else {
                out.push((t, p));
            }
        }
        inner.finish_row();
        outer.push(out);
        next += 1;
    }
    mass.resize(states.len(), 0.0);
    let n = states.len();
    // Live: can reach an exit. Backward search from the states with an exit.
    let predecessors = Csr::<u32, u32>::group(
        n,
        (0..n as u32).flat_map(|i| inner.row(i).iter().map(move |&(j, _)| (j, i))),
    );
    let mut live = vec![false; n];
    let mut queue: Vec<u32> = (0..n as u32)
        .filter(|&i| !outer[i as usize].is_empty())
        .collect();
    for &i in &queue {
        live[i as usize] = true;
    }
    while let Some(j) = queue.pop() {
        for &i in predecessors.row(j) {
            if !live[i as usize] {
                live[i as usize] = true;
                queue.push(i);
            }
        }
    }
    // Visits of the live states, component by component in topological order (the graph is
    // restricted to live states: mass into a dead one stays there forever).
    let graph: Csr<u32, u32> = Csr::group(
        n,
        (0..n as u32).filter(|&i| live[i as usize]).flat_map(|i| {
            inner
                .row(i)
                .iter()
                .filter(|&&(j, _)| live[j as usize])
                .map(move |&(j, _)| (i, j))
        }),
    );
    let components = strongly_connected_components(&graph);
    let mut visits = vec![0.0; n];
    let mut inflow = mass;
    for component in components.rows().rev() {
        let members = components.row(component);
        if !live[members[0] as usize] {
            continue;
        }
        solve_component(members, &inner, &inflow, &mut visits);
        for &c in members {
            let y = visits[c as usize];
            for &(j, p) in inner.row(c) {
                if !members.contains(&j) {
                    inflow[j as usize] += y * p;
                }
            }
            for &(t, p) in &outer[c as usize] {
                *exits.entry(t).or_default() += y * p;
            }
        }
    }
    // A dead state keeps what flows into it (from live states and the start only: the graph
    // leaves its edges out, so it is ordered anywhere among the components).
    let forever: f64 = (0..n).filter(|&c| !live[c]).map(|c| inflow[c]).sum();
    let mut result: Vec<(Option<S>, f64)> = exits.into_iter().map(|(s, p)| (Some(s), p)).collect();
    if forever > 0.0 {
        result.push((None, forever));
    }
    result
}

/// The moves of MDP state `s` by its first choice, into `out`: how [`first_exits`] moves
/// through an MDP's transient states.
pub fn choice_successors(mdp: &Mdp, s: MdpState, out: &mut Vec<(MdpState, f64)>) {
    out.extend(mdp.successors(mdp.choices(s).start()));
}

/// The visits `y` of a component's members: `y(c) = inflow(c) + Σ_{c' in the component}
/// y(c') · P(c', c)`.
fn solve_component(
    members: &[u32],
    inner: &Csr<u32, (u32, f64)>,
    inflow: &[f64],
    visits: &mut [f64],
) {
    let m = members.len();
    let position: HashMap<u32, usize> = members.iter().enumerate().map(|(i, &c)| (c, i)).collect();
    if m <= EXACT_LIMIT {
        // (I − Qᵀ) y = inflow, row i for member i: y_i − Σ_j Q(j, i) y_j.
        let mut a = vec![vec![0.0; m + 1]; m];
        for (i, &c) in members.iter().enumerate() {
            a[i][i] += 1.0;
            a[i][m] = inflow[c as usize];
        }
        for (j, &c) in members.iter().enumerate() {
            for &(t, p) in inner.row(c) {
                if let Some(&i) = position.get(&t) {
                    a[i][j] -= p;
                }
            }
        }
        for col in 0..m {
            let pivot = (col..m)
                .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
                .expect("a non-empty column");
            a.swap(col, pivot);
            let pivot_row = a[col].clone();
            for (row, values) in a.iter_mut().enumerate() {
                if row != col && values[col] != 0.0 {
                    let factor = values[col] / pivot_row[col];
                    for (x, &p) in values[col..].iter_mut().zip(&pivot_row[col..]) {
                        *x -= factor * p;
                    }
                }
            }
        }
        for (i, &c) in members.iter().enumerate() {
            visits[c as usize] = (a[i][m] / a[i][i]).max(0.0);
        }
        return;
    }
    // Gauss–Seidel on y = inflow + Qᵀ y, from 0 (monotone from below).
    let position = &position;
    let predecessors = Csr::<u32, (u32, f64)>::group(
        m,
        members.iter().flat_map(|&c| {
            inner
                .row(c)
                .iter()
                .filter_map(move |&(t, p)| position.get(&t).map(|&i| (i as u32, (c, p))))
        }),
    );
    for _ in 0..MAX_SWEEPS {
        let mut change: f64 = 0.0;
        for (i, &c) in members.iter().enumerate() {
            let y = inflow[c as usize]
                + predecessors
                    .row(i as u32)
                    .iter()
                    .map(|&(from, p)| visits[from as usize] * p)
                    .sum::<f64>();
            let old = visits[c as usize];
            change = change.max((y - old).abs() / y.max(f64::MIN_POSITIVE));
            visits[c as usize] = y;
        }
        if change < 1e-15 {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::model::MdpBuilder;
    use crate::mdp::testing::ms;

    /// An MDP of chance states (one choice each) given as `(state, [(target, p)])`, plus
    /// absorbing exits; `transient` lists the chance states.
    fn chain(n: usize, moves: &[(usize, &[(usize, f64)])]) -> Mdp {
        let mut b = MdpBuilder::new();
        let go = b.action("go").unwrap();
        for s in 0..n {
            match moves.iter().find(|(from, _)| *from == s) {
                Some((_, targets)) => {
                    b.add_decision_state().unwrap();
                    let targets: Vec<(MdpState, f64)> =
                        targets.iter().map(|&(t, p)| (ms(t as u32), p)).collect();
                    b.add_instant_choice(go, &targets).unwrap();
                }
                None => {
                    b.add_absorbing_state(1.0).unwrap();
                }
            }
        }
        b.set_initial(ms(0));
        b.build().unwrap()
    }

    fn exits(mdp: &Mdp, start: &[(u32, f64)], transient: &[u32]) -> Vec<(Option<u32>, f64)> {
        first_exits(
            start.iter().map(|&(s, p)| (ms(s), p)),
            |s| transient.contains(&s.as_u32()),
            |s, out| choice_successors(mdp, s, out),
        )
        .into_iter()
        .map(|(s, p)| (s.map(MdpState::as_u32), p))
        .collect()
    }

    fn assert_close(found: &[(Option<u32>, f64)], expected: &[(Option<u32>, f64)]) {
        assert_eq!(found.len(), expected.len(), "{found:?}");
        for (f, e) in found.iter().zip(expected) {
            assert_eq!(f.0, e.0, "{found:?}");
            assert!((f.1 - e.1).abs() < 1e-12, "{found:?} vs {expected:?}");
        }
    }

    #[test]
    fn a_cycle_of_chance_states_is_left_with_certainty() {
        // x0: 1/2 x0, 1/2 x1; x1: 1/3 x0, 1/3 x1, 1/3 r2. From x0, r2 surely.
        let mdp = chain(
            3,
            &[
                (0, &[(0, 0.5), (1, 0.5)]),
                (1, &[(0, 1.0 / 3.0), (1, 1.0 / 3.0), (2, 1.0 / 3.0)]),
            ],
        );
        assert_close(&exits(&mdp, &[(0, 1.0)], &[0, 1]), &[(Some(2), 1.0)]);
    }

    #[test]
    fn a_diamond_adds_up_its_paths() {
        // c0 → c1, c2 (1/2 each); c1 → e3 (1/4), e4 (3/4); c2 → e4. So e3 1/8, e4 7/8.
        let mdp = chain(
            5,
            &[
                (0, &[(1, 0.5), (2, 0.5)]),
                (1, &[(3, 0.25), (4, 0.75)]),
                (2, &[(4, 1.0)]),
            ],
        );
        assert_close(
            &exits(&mdp, &[(0, 1.0)], &[0, 1, 2]),
            &[(Some(3), 0.125), (Some(4), 0.875)],
        );
    }

    #[test]
    fn a_closed_set_keeps_its_mass_and_start_mass_on_exits_counts() {
        // Start: 0.4 on exit e3, 0.6 on c0; c0 → c1 (1/2), e3 (1/2); c1 ⇄ c2 never left.
        let mdp = chain(
            4,
            &[
                (0, &[(1, 0.5), (3, 0.5)]),
                (1, &[(2, 1.0)]),
                (2, &[(1, 1.0)]),
            ],
        );
        assert_close(
            &exits(&mdp, &[(3, 0.4), (0, 0.6)], &[0, 1, 2]),
            &[(Some(3), 0.7), (None, 0.3)],
        );
    }

    #[test]
    fn a_large_cycle_is_iterated_to_the_same_answer() {
        // A ring of 400 chance states, each going on with 0.9 and exiting to its own exit
        // (states 400..800) with 0.1: from state 0 the exit of state i gets 0.1·0.9^i / (1 −
        // 0.9^400).
        let n = 400;
        let moves: Vec<(usize, Vec<(usize, f64)>)> = (0..n)
            .map(|i| (i, vec![((i + 1) % n, 0.9), (n + i, 0.1)]))
            .collect();
        let moves: Vec<(usize, &[(usize, f64)])> =
            moves.iter().map(|(i, m)| (*i, m.as_slice())).collect();
        let mdp = chain(2 * n, &moves);
        let transient: Vec<u32> = (0..n as u32).collect();
        let found = exits(&mdp, &[(0, 1.0)], &transient);
        let norm = 1.0 - 0.9f64.powi(n as i32);
        for (i, &(s, p)) in found.iter().enumerate() {
            assert_eq!(s, Some((n + i) as u32));
            let expected = 0.1 * 0.9f64.powi(i as i32) / norm;
            assert!((p - expected).abs() < 1e-12, "{i}: {p} vs {expected}");
        }
    }
}
