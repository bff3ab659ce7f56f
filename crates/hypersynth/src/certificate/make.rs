//! A certificate made from approximate values (docs/semantics.md §9.4, "Where they come from"):
//! the values are repaired, with the checker's own inequalities and exact comparisons, until
//! every inequality holds, the values the checker derives set as it derives them; a state of
//! positive x from which no path of positive x leads to a payoff gets x = 0. Nothing here is
//! trusted: the checker checks what it makes.

use super::check::{
    Step, chain_successors, lower_carries, lower_inequality, ranks, reach, steps, upper_carries,
    upper_inequalities, upper_successors,
};
use super::model::{Model, NONE, RobotRule};

/// Passes over the states after which a repair that still changes a value gives up.
const MAX_PASSES: usize = 10_000;

/// The repaired lower values over the model's nodes (0 outside D_L) from approximate lower
/// values `x0` per node. `None` if the repair does not settle.
pub(crate) fn lower(model: &Model, x0: &[f64]) -> Option<Vec<f64>> {
    let g = model.checked.file.discount;
    let steps = steps(model);
    let order = reach(model, |u| match steps[u as usize] {
        Some(step) => chain_successors(model, step, u).collect(),
        None => Vec::new(),
    });
    let mut x: Vec<f64> = vec![0.0; model.len()];
    for &u in &order {
        let start = x0[u as usize];
        x[u as usize] = match steps[u as usize] {
            Some(Step::End(p, _)) => p,
            _ if start.is_finite() && start > 0.0 => start,
            _ => 0.0,
        };
    }
    for _ in 0..MAX_PASSES {
        let mut changed = false;
        for &u in order.iter().rev() {
            let Some(step) = steps[u as usize] else {
                continue;
            };
            if matches!(step, Step::End(..)) {
                continue;
            }
            let xu = x[u as usize];
            let inequality = lower_inequality(model, step, u, |t| x[t as usize], g);
            let repaired = if lower_carries(model, step, u) {
                match inequality.holds(xu, true) {
                    true => xu,
                    false => inequality.tightest(true).min(xu),
                }
            } else {
                inequality.tightest(true)
            };
            if repaired != xu {
                x[u as usize] = repaired;
                changed = true;
            }
        }
        if changed {
            continue;
        }
        let ranks = ranks(model, &steps, &order, &x);
        let mut unranked = false;
        for &u in &order {
            let Some(step) = steps[u as usize] else {
                continue;
            };
            let needs = matches!(step, Step::Move(_) | Step::Chance);
            if needs && x[u as usize] > 0.0 && ranks[u as usize] == NONE {
                unranked = true;
                if lower_carries(model, step, u) {
                    x[u as usize] = 0.0;
                }
            }
        }
        if !unranked {
            return Some(x);
        }
    }
    None
}

/// The repaired upper values over the model's nodes (unused outside D_U) from approximate
/// upper values `y0` per node. `None` if the repair does not settle.
pub(crate) fn upper(model: &Model, y0: &[f64]) -> Option<Vec<f64>> {
    let g = model.checked.file.discount;
    let rules = model.robot_rules();
    let rule = |u: u32| rules[u as usize].as_ref();
    let order = reach(model, |u| upper_successors(model, rule(u), u).collect());
    let top = model.all();
    let mut y: Vec<f64> = y0
        .iter()
        .map(|&v| if v.is_finite() { v.max(0.0) } else { top })
        .collect();
    for &u in &order {
        match rule(u) {
            Some(RobotRule::Absorbing(p)) => y[u as usize] = *p,
            None if model.edges(u).is_empty() => y[u as usize] = top,
            _ => {}
        }
    }
    for _ in 0..MAX_PASSES {
        let mut changed = false;
        for &u in order.iter().rev() {
            let fixed = matches!(rule(u), Some(RobotRule::Absorbing(_)))
                || (rule(u).is_none() && model.edges(u).is_empty());
            if fixed {
                continue;
            }
            let yu = y[u as usize];
            let inequalities = upper_inequalities(model, rule(u), u, |t| y[t as usize], g);
            let repaired = if upper_carries(model, rule(u), u) {
                inequalities
                    .iter()
                    .filter(|inequality| !inequality.holds(yu, false))
                    .map(|inequality| inequality.tightest(false))
                    .fold(yu, f64::max)
            } else {
                inequalities
                    .iter()
                    .map(|inequality| inequality.tightest(false))
                    .fold(0.0, f64::max)
            };
            if repaired != yu {
                y[u as usize] = repaired;
                changed = true;
            }
        }
        if !changed {
            return Some(y);
        }
    }
    None
}
