//! Exact sums of products of non-negative doubles, for comparing the two sides of a
//! certificate's inequalities without rounding (docs/semantics.md §9.4).
//!
//! A finite double is a dyadic rational `m · 2^e` (`m < 2^53`, `-1074 ≤ e ≤ 971`), so the product
//! of two is `m · 2^e` with `m < 2^106` and `-2148 ≤ e ≤ 1942`. [`Sum`] holds `2^2148` times a
//! sum of such products as an integer of [`LIMBS`] 64-bit limbs: wide enough for the largest
//! product (`2^4196`) added `2^64` times, so no term is rounded and no sum overflows.

use std::cmp::Ordering;

/// The limbs of a [`Sum`]: 4196 bits of the largest product, 64 of carries, rounded up.
const LIMBS: usize = 67;

/// The power of two every term is scaled by: the smallest product's exponent.
const SCALE: i32 = 2148;

/// An exact sum of products of two non-negative finite doubles.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Sum {
    limbs: [u64; LIMBS],
}

impl Default for Sum {
    fn default() -> Sum {
        Sum { limbs: [0; LIMBS] }
    }
}

/// `value` as `(m, e)` with `value = m · 2^e`; `value` non-negative and finite.
fn parts(value: f64) -> (u64, i32) {
    debug_assert!(value.is_finite() && value >= 0.0);
    let bits = value.to_bits() & !(1 << 63);
    let exponent = (bits >> 52) as i32;
    let fraction = bits & ((1 << 52) - 1);
    if exponent == 0 {
        (fraction, -1074)
    } else {
        (fraction | 1 << 52, exponent - 1075)
    }
}

impl Sum {
    /// The sum of `a · b` over `terms`, each factor non-negative and finite.
    pub fn of(terms: impl IntoIterator<Item = (f64, f64)>) -> Sum {
        let mut sum = Sum::default();
        for (a, b) in terms {
            sum.add(a, b);
        }
        sum
    }

    /// Adds `a · b` (both non-negative and finite) exactly.
    pub fn add(&mut self, a: f64, b: f64) {
        let ((ma, ea), (mb, eb)) = (parts(a), parts(b));
        let m = u128::from(ma) * u128::from(mb);
        if m == 0 {
            return;
        }
        let shift = (ea + eb + SCALE) as u32;
        let (limb, offset) = ((shift / 64) as usize, shift % 64);
        let (low, high) = (m as u64, (m >> 64) as u64);
        let words = if offset == 0 {
            [low, high, 0]
        } else {
            [
                low << offset,
                (low >> (64 - offset)) | (high << offset),
                high >> (64 - offset),
            ]
        };
        let mut carry = 0u64;
        for (i, limb) in self.limbs[limb..].iter_mut().enumerate() {
            let word = words.get(i).copied().unwrap_or(0);
            if word == 0 && carry == 0 && i >= words.len() {
                break;
            }
            let (s1, c1) = limb.overflowing_add(word);
            let (s2, c2) = s1.overflowing_add(carry);
            *limb = s2;
            carry = u64::from(c1) + u64::from(c2);
        }
        debug_assert_eq!(carry, 0, "a sum within the limbs");
    }
}

impl PartialOrd for Sum {
    fn partial_cmp(&self, other: &Sum) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Sum {
    fn cmp(&self, other: &Sum) -> Ordering {
        self.limbs.iter().rev().cmp(other.limbs.iter().rev())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_compare_exactly_where_doubles_round() {
        // 0.1 + 0.2 rounds to 0.30000000000000004 in doubles; the exact sum of the two doubles
        // lies strictly between 0.3 (a double below it) and that.
        let exact = Sum::of([(0.1, 1.0), (0.2, 1.0)]);
        assert!(Sum::of([(0.3, 1.0)]) < exact);
        assert!(exact < Sum::of([(0.1 + 0.2, 1.0)]));
        // Three thirds: 3 · (1/3 rounded) is not 1.
        let third = 1.0 / 3.0;
        assert!(Sum::of([(third, 3.0)]) < Sum::of([(1.0, 1.0)]));
        assert_eq!(
            Sum::of([(third, 1.0), (third, 2.0)]),
            Sum::of([(third, 3.0)])
        );
        // The extremes: the smallest subnormal squared, the largest double squared, and a
        // carry through every limb.
        let tiny = f64::from_bits(1);
        assert!(Sum::default() < Sum::of([(tiny, tiny)]));
        let huge = Sum::of([(f64::MAX, f64::MAX), (f64::MAX, f64::MAX)]);
        assert!(Sum::of([(f64::MAX, f64::MAX)]) < huge);
        assert_eq!(huge, Sum::of([(f64::MAX, f64::MAX * 0.5); 4]));
        // The smallest product added 1024 times is one product 1024 times larger.
        let mut many = Sum::default();
        for _ in 0..1024 {
            many.add(tiny, tiny);
        }
        assert_eq!(many, Sum::of([(tiny, f64::from_bits(1) * 1024.0)]));
        assert_eq!(Sum::of([(0.0, 5.0)]), Sum::default());
    }
}
