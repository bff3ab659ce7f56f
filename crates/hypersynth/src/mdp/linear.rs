//! Exact solution of a small transient linear system `x = W x + b`, the values of a Markov
//! chain on a set of states it leaves with probability 1 (a component of a policy's chain, or
//! of a controller's).
//!
//! Gaussian elimination in the subtraction-free form of Grassmann, Taksar and Heyman: the matrix
//! is `I − W`, an M-matrix, and every diagonal entry is kept as the row's *leak* (its weight of
//! leaving: the probability of an exit, or of the discount's end) plus its remaining off-diagonal
//! weights, so that no difference of nearly equal numbers is ever formed and a leak of 1e-12 is
//! as accurate as any other. Cost: `O(m³)` time and `O(m²)` memory for `m` states, so callers
//! keep it to small components.
//!
//! ```text
//! m = 1, W = [0.999999999], leak = [1e-9], b = [3e-7]  =>  x = [300]
//! ```

/// A transient system of `m` unknowns: `weights[i * m + j]` is `W(i, j)` for `j ≠ i` (the
/// diagonal is implicit: `1 − leak − Σ_j W(i, j)`), `leak[i]` row `i`'s weight of leaving, and
/// `rhs[i]` its `R` right-hand sides.
pub(crate) struct Transient<const R: usize> {
    m: usize,
    weights: Vec<f64>,
    leak: Vec<f64>,
    rhs: Vec<[f64; R]>,
}

impl<const R: usize> Transient<R> {
    /// A system of `m` unknowns with no weight, no leak and zero right-hand sides.
    pub(crate) fn new(m: usize) -> Self {
        Transient {
            m,
            weights: vec![0.0; m * m],
            leak: vec![0.0; m],
            rhs: vec![[0.0; R]; m],
        }
    }

    /// Adds `w` to `W(i, j)`; a weight from `i` to itself is not one (it is what stays).
    pub(crate) fn add_weight(&mut self, i: usize, j: usize, w: f64) {
        if i != j {
            self.weights[i * self.m + j] += w;
        }
    }

    /// Adds `w` to row `i`'s weight of leaving.
    pub(crate) fn add_leak(&mut self, i: usize, w: f64) {
        self.leak[i] += w;
    }

    /// Adds `b` to row `i`'s right-hand sides.
    pub(crate) fn add_rhs(&mut self, i: usize, b: [f64; R]) {
        for (r, b) in self.rhs[i].iter_mut().zip(b) {
            *r += b;
        }
    }

    /// The solution, or `None` if some set of rows never leaks (the chain stays there for ever).
    pub(crate) fn solve(mut self) -> Option<Vec<[f64; R]>> {
        let m = self.m;
        let weights = &mut self.weights;
        for k in 0..m {
            let pivot = self.leak[k] + weights[k * m + k + 1..(k + 1) * m].iter().sum::<f64>();
            if pivot <= 0.0 {
                return None;
            }
            for i in k + 1..m {
                let w_ik = weights[i * m + k];
                if w_ik == 0.0 {
                    continue;
                }
                let factor = w_ik / pivot;
                weights[i * m + k] = 0.0;
                for j in k + 1..m {
                    if j != i {
                        weights[i * m + j] += factor * weights[k * m + j];
                    }
                }
                self.leak[i] += factor * self.leak[k];
                let rhs_k = self.rhs[k];
                for (r, b) in self.rhs[i].iter_mut().zip(rhs_k) {
                    *r += factor * b;
                }
            }
        }
        let mut x = vec![[0.0; R]; m];
        for k in (0..m).rev() {
            let row = &weights[k * m + k + 1..(k + 1) * m];
            let pivot = self.leak[k] + row.iter().sum::<f64>();
            let mut sum = self.rhs[k];
            for (w, x) in row.iter().zip(&x[k + 1..]) {
                for (s, x) in sum.iter_mut().zip(x) {
                    *s += w * x;
                }
            }
            x[k] = sum.map(|s| s / pivot);
        }
        Some(x)
    }
}

#[cfg(test)]
mod tests {
    use super::Transient;

    #[test]
    fn a_loop_left_with_a_tiny_probability_is_solved_exactly() {
        // x = (1 − 1e-9) x + 1e-9 · 300.
        let mut system = Transient::<1>::new(1);
        system.add_leak(0, 1e-9);
        system.add_rhs(0, [1e-9 * 300.0]);
        assert_eq!(system.solve().unwrap()[0][0], 300.0);
    }

    #[test]
    fn a_two_state_chain_matches_the_hand_solution() {
        // x0 = 0.5 x1 + 0.5 · 10, x1 = 0.25 x0 + 0.75 · 2: x0 = 0.5 (0.25 x0 + 1.5) + 5, so
        // 0.875 x0 = 5.75, x0 = 46/7, x1 = 0.25 · 46/7 + 1.5 = 22/7. Second side: b doubled.
        let mut system = Transient::<2>::new(2);
        system.add_weight(0, 1, 0.5);
        system.add_leak(0, 0.5);
        system.add_rhs(0, [5.0, 10.0]);
        system.add_weight(1, 0, 0.25);
        system.add_leak(1, 0.75);
        system.add_rhs(1, [1.5, 3.0]);
        let x = system.solve().unwrap();
        for (got, want) in [(x[0][0], 46.0 / 7.0), (x[1][0], 22.0 / 7.0)] {
            assert!((got - want).abs() < 1e-12, "{got} {want}");
        }
        assert!((x[0][1] - 92.0 / 7.0).abs() < 1e-12);
    }

    #[test]
    fn rows_that_never_leak_have_no_solution() {
        let mut system = Transient::<1>::new(2);
        system.add_weight(0, 1, 1.0);
        system.add_weight(1, 0, 1.0);
        assert!(system.solve().is_none());
    }
}
