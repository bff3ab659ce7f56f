//! A certificate made from approximate values (docs/semantics.md §9.4, "Where they come from"):
//! the values are repaired, with the checker's own inequalities and exact comparisons, until
//! every inequality holds; ranks come from a backward search over the controller's chain.
//! Nothing here is trusted: the checker checks what it makes.

use super::check::{
    Inequality, Step, chain_successors, lower_inequality, reach, steps, upper_inequalities,
    upper_successors,
};
use super::model::{Model, NONE};

/// Passes over the states after which a repair that still changes a value gives up.
const MAX_PASSES: usize = 10_000;

/// The largest double `q ≤ start` (`below`) or smallest `q ≥ start` that satisfies `inequality`
/// as the node's value: stepped one unit in the last place at a time from its approximation.
fn repaired(inequality: &Inequality, below: bool) -> f64 {
    let mut q = inequality.approximate().max(0.0);
    if below {
        while q > 0.0 && !inequality.holds(q, true) {
            q = q.next_down().max(0.0);
        }
    } else {
        while !inequality.holds(q, false) {
            q = q.next_up();
        }
    }
    q
}

/// The repaired lower values (over the model's nodes; 0 outside D_L), and the ranks (`NONE`
/// where none is needed), from approximate lower values `x0` per node. `None` if the repair
/// does not settle.
pub(crate) fn lower(model: &Model, x0: &[f64]) -> Option<(Vec<f64>, Vec<u32>)> {
    let g = model.checked.file.discount;
    let steps = steps(model);
    let order = reach(model, |u| match steps[u as usize] {
        Some(step) => chain_successors(model, step, u).collect(),
        None => Vec::new(),
    });
    let mut x: Vec<f64> = vec![0.0; model.len()];
    for &u in &order {
        let start = x0[u as usize];
        x[u as usize] = if start.is_finite() && start > 0.0 {
            start
        } else {
            0.0
        };
    }
    // Predecessors in the chain, for the ranks' backward search.
    let mut reverse: Vec<Vec<u32>> = vec![Vec::new(); model.len()];
    for &u in &order {
        if let Some(step) = steps[u as usize] {
            for t in chain_successors(model, step, u) {
                reverse[t as usize].push(u);
            }
        }
    }
    for _ in 0..MAX_PASSES {
        let mut changed = false;
        for &u in order.iter().rev() {
            let Some(step) = steps[u as usize] else {
                continue;
            };
            let xu = x[u as usize];
            let inequality = lower_inequality(model, step, u, |t| x[t as usize], g);
            if !inequality.holds(xu, true) {
                x[u as usize] = repaired(&inequality, true).min(xu);
                changed = true;
            }
        }
        if changed {
            continue;
        }
        let ranks = ranks(model, &steps, &order, &reverse, &x);
        let mut unranked = false;
        for &u in &order {
            let needs = matches!(steps[u as usize], Some(Step::Move(_) | Step::Chance));
            if needs && x[u as usize] > 0.0 && ranks[u as usize] == NONE {
                x[u as usize] = 0.0;
                unranked = true;
            }
        }
        if !unranked {
            return Some((x, ranks));
        }
    }
    None
}

/// Ranks by a backward search over the chain from the states that pay: a state of positive x
/// that moves or is a chance node gets rank 0 next to a paying state, `k + 1` next to a state
/// of rank `k` and positive x.
fn ranks(
    model: &Model,
    steps: &[Option<Step>],
    order: &[u32],
    reverse: &[Vec<u32>],
    x: &[f64],
) -> Vec<u32> {
    let mut ranks = vec![NONE; model.len()];
    let needs = |u: u32| {
        x[u as usize] > 0.0 && matches!(steps[u as usize], Some(Step::Move(_) | Step::Chance))
    };
    let mut layer: Vec<u32> = Vec::new();
    for &t in order {
        if matches!(steps[t as usize], Some(Step::End(p, _)) if p > 0.0) {
            for &p in &reverse[t as usize] {
                if needs(p) && ranks[p as usize] == NONE {
                    ranks[p as usize] = 0;
                    layer.push(p);
                }
            }
        }
    }
    let mut rank = 0;
    while !layer.is_empty() {
        rank += 1;
        let mut next = Vec::new();
        for &t in &layer {
            for &p in &reverse[t as usize] {
                if needs(p) && ranks[p as usize] == NONE {
                    ranks[p as usize] = rank;
                    next.push(p);
                }
            }
        }
        layer = next;
    }
    ranks
}

/// The repaired upper values (over the model's nodes; unused outside D_U) from approximate
/// upper values `y0` per node. `None` if the repair does not settle.
pub(crate) fn upper(model: &Model, y0: &[f64]) -> Option<Vec<f64>> {
    let g = model.checked.file.discount;
    let rules = model.robot_rules();
    let order = reach(model, |u| {
        upper_successors(model, rules[u as usize].as_ref(), u).collect()
    });
    let top = model.all();
    let mut y: Vec<f64> = y0
        .iter()
        .map(|&v| if v.is_finite() { v.max(0.0) } else { top })
        .collect();
    for _ in 0..MAX_PASSES {
        let mut changed = false;
        for &u in order.iter().rev() {
            let yu = y[u as usize];
            let inequalities =
                upper_inequalities(model, rules[u as usize].as_ref(), u, |t| y[t as usize], g);
            let needed = inequalities
                .iter()
                .filter(|inequality| !inequality.holds(yu, false))
                .map(|inequality| repaired(inequality, false))
                .fold(yu, f64::max);
            if needed > yu {
                y[u as usize] = needed;
                changed = true;
            }
        }
        if !changed {
            return Some(y);
        }
    }
    None
}
