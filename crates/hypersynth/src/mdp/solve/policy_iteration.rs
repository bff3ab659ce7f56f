//! Policy iteration with exact linear solves, for small components.

use super::system::NominalSystem;
use super::{Precision, VERIFICATION_SLACK};
use crate::mdp::linear::Transient;
use crate::mdp::operator::Payoff;

impl NominalSystem<'_> {
    /// elimination, with the successors' upper bounds) and improved until stable, at most 100
    /// rounds. Its value with the successors' lower bounds is a lower bound (after the end
    /// component collapse every policy leaves the component, so that value is what it
    /// collects); its value with the upper bounds plus ε/2 is offered as the upper bound and
    /// kept only if verified as a super-fixed-point. The caller falls back to iteration if the
    /// width is not within the precision. Returns the rounds (counted as sweeps), the width and
    /// its ratio to the precision ([`System::gap`]).
    pub(super) fn policy_iteration(
        &mut self,
        component: &[u32],
        g: f64,
        precision: Precision,
        scale: f64,
    ) -> (u32, f64, f64) {
        let size = component.len();
        let mut index = std::collections::HashMap::with_capacity(size);
        for (i, &node) in component.iter().enumerate() {
            index.insert(node, i);
        }
        // Start from the choice of largest upper Q-value, which leaves no closed loop unless
        // every choice loops (then the values solve to the loop's exits anyway).
        let mut policy: Vec<usize> = component
            .iter()
            .map(|&node| self.best_upper_choice(node as usize, g))
            .collect();
        let mut rounds = 0u32;
        let upper = loop {
            rounds += 1;
            let Some(values) = self.evaluate_policy(component, &index, &policy, g, 1) else {
                return (rounds, f64::INFINITY, f64::INFINITY);
            };
            // Improve on the upper values (the two bounds differ only through the exits).
            let mut changed = false;
            for (i, &node) in component.iter().enumerate() {
                let mut best = (policy[i], self.choice_value(policy[i], g, &index, &values));
                for choice in self.choices(node as usize) {
                    let q = self.choice_value(choice, g, &index, &values);
                    if q > best.1 + 1e-12 * scale {
                        best = (choice, q);
                    }
                }
                changed |= best.0 != policy[i];
                policy[i] = best.0;
            }
            if !changed || rounds == 100 {
                break values;
            }
        };
        let Some(lower) = self.evaluate_policy(component, &index, &policy, g, 0) else {
            return (rounds, f64::INFINITY, f64::INFINITY);
        };
        let saved: Vec<[f64; 2]> = component.iter().map(|&n| self.values[n as usize]).collect();
        // The policy's own value is a lower bound (every policy is proper here); the upper
        // bound is offered with a margin and verified.
        for (i, &node) in component.iter().enumerate() {
            let [old_lower, old_upper] = self.values[node as usize];
            let new_upper = old_upper.min(upper[i] + 0.5 * precision.allowed(lower[i]));
            // Rounding in the solve may put the policy's value a few ulps above a bound.
            self.values[node as usize] = [old_lower.max(lower[i]).min(new_upper), new_upper];
        }
        let verified = component.iter().all(|&node| {
            let upper = self.values[node as usize][1];
            self.bellman(node as usize, g)[1] <= upper + VERIFICATION_SLACK * upper.abs()
        });
        if !verified {
            for (&node, values) in component.iter().zip(saved) {
                self.values[node as usize] = values;
            }
            return (rounds, f64::INFINITY, f64::INFINITY);
        }
        let (width, ratio) = self.gap(component, precision);
        (rounds, width, ratio)
    }

    /// The choice of `node` of largest upper Q-value.
    fn best_upper_choice(&self, node: usize, g: f64) -> usize {
        let choices = self.choices(node);
        let mut best = (choices.start, f64::NEG_INFINITY);
        for choice in choices {
            let [q] = self
                .operator
                .q(choice, &Payoff { g }, &|t| [self.values[t as usize][1]]);
            if q > best.1 {
                best = (choice, q);
            }
        }
        best.0
    }

    /// The Q-value of `choice` with the component's nodes valued by `inside` and the other
    /// targets by their upper bounds.
    fn choice_value(
        &self,
        choice: usize,
        g: f64,
        index: &std::collections::HashMap<u32, usize>,
        inside: &[f64],
    ) -> f64 {
        let value = |t: u32| {
            [index
                .get(&t)
                .map_or(self.values[t as usize][1], |&i| inside[i])]
        };
        self.operator.q(choice, &Payoff { g }, &value)[0]
    }

    /// The exact values of `policy` on the component, with the targets outside valued by side
    /// `side` of their bounds: `x = f · P_inside x + f · P_outside v`, solved by
    /// [`Transient`] (its leak per row is `f · P_outside + 1 − f`). `None` if some row has no
    /// leak (the policy keeps the run inside forever; impossible once end components are
    /// collapsed, or with g < 1).
    fn evaluate_policy(
        &self,
        component: &[u32],
        index: &std::collections::HashMap<u32, usize>,
        policy: &[usize],
        g: f64,
        side: usize,
    ) -> Option<Vec<f64>> {
        let mut system = Transient::<1>::new(component.len());
        for (i, &choice) in policy.iter().enumerate() {
            let f = if self.operator.is_instant(choice) {
                1.0
            } else {
                g
            };
            let mut outside = 0.0;
            for (t, p) in self.operator.transitions(choice) {
                match index.get(&t) {
                    Some(&j) => system.add_weight(i, j, f * p),
                    None => {
                        outside += p;
                        system.add_rhs(i, [f * p * self.values[t as usize][side]]);
                    }
                }
            }
            system.add_leak(i, f * outside + (1.0 - f));
        }
        Some(system.solve()?.into_iter().map(|[x]| x).collect())
    }
}
