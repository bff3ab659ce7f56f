//! The adversary's inner problem at one choice: the distribution within the intervals that
//! minimises the expected value of the successors.
//!
//! Every successor first gets its lower bound; the mass still to place (`1 − Σ l`) goes to the
//! successors in increasing order of value, each filled up to its upper bound before the next.
//! This is optimal: moving mass from a successor of lower value to one of higher value never
//! lowers the expectation, and the greedy order leaves no such move available. Successors of
//! equal value may be filled in any order without changing the expectation; ties keep the
//! successors' order (the sort is stable), so the distribution is deterministic.
//!
//! Cost: a sort of the choice's successors (a handful in the hypergame MDPs).

/// One successor of an interval choice: its current value and its probability interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Entry {
    pub(crate) value: f64,
    pub(crate) lower: f64,
    pub(crate) upper: f64,
}

/// `min Σ p_i · value_i` over `lower_i ≤ p_i ≤ upper_i`, `Σ p_i = 1`; sorts `entries` by value.
/// The region must be feasible (`Σ lower ≤ 1 ≤ Σ upper`, up to rounding: mass that rounding
/// leaves over after every upper bound is reached is dropped, mass that the lower bounds
/// overshoot is not taken back).
pub(crate) fn minimum(entries: &mut [Entry]) -> f64 {
    sort(entries);
    let mut left = 1.0;
    let mut sum = 0.0;
    for entry in entries.iter() {
        sum += entry.lower * entry.value;
        left -= entry.lower;
    }
    for entry in entries.iter() {
        if left <= 0.0 {
            break;
        }
        let more = (entry.upper - entry.lower).min(left);
        sum += more * entry.value;
        left -= more;
    }
    sum
}

/// The minimising distribution itself: `out[i]` for the successor `i` of `values` and
/// `bounds` (the same length), in their order.
pub(crate) fn distribution(values: &[f64], bounds: &[[f64; 2]], out: &mut Vec<f64>) {
    out.clear();
    out.extend(bounds.iter().map(|b| b[0]));
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&i, &j| values[i].total_cmp(&values[j]));
    let mut left = 1.0 - out.iter().sum::<f64>();
    for i in order {
        if left <= 0.0 {
            break;
        }
        let more = (bounds[i][1] - bounds[i][0]).min(left);
        out[i] += more;
        left -= more;
    }
}

/// Stable sort by value; insertion sort for the short rows of hypergame MDPs.
fn sort(entries: &mut [Entry]) {
    if entries.len() <= 16 {
        for i in 1..entries.len() {
            let mut j = i;
            while j > 0 && entries[j - 1].value > entries[j].value {
                entries.swap(j - 1, j);
                j -= 1;
            }
        }
    } else {
        entries.sort_by(|a, b| a.value.total_cmp(&b.value));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(rows: &[(f64, f64, f64)]) -> Vec<Entry> {
        rows.iter()
            .map(|&(value, lower, upper)| Entry {
                value,
                lower,
                upper,
            })
            .collect()
    }

    #[test]
    fn the_lowest_values_get_the_free_mass_first() {
        // Values 3, 1, 2 with [0.1, 0.6], [0.2, 0.5], [0.1, 0.9]: lower bounds 0.4 of mass,
        // 0.6 left: 0.3 to value 1 (up to 0.5), 0.3 to value 2. Expectation
        // 0.1·3 + 0.5·1 + 0.4·2 = 1.6.
        let rows = [(3.0, 0.1, 0.6), (1.0, 0.2, 0.5), (2.0, 0.1, 0.9)];
        assert!((minimum(&mut entries(&rows)) - 1.6).abs() < 1e-15);
        let mut out = Vec::new();
        distribution(
            &[3.0, 1.0, 2.0],
            &[[0.1, 0.6], [0.2, 0.5], [0.1, 0.9]],
            &mut out,
        );
        let expected = [0.1, 0.5, 0.4];
        assert!(out.iter().zip(expected).all(|(p, e)| (p - e).abs() < 1e-15));
    }

    #[test]
    fn point_intervals_give_the_plain_expectation_and_unit_intervals_the_minimum() {
        let rows = [(4.0, 0.25, 0.25), (8.0, 0.75, 0.75)];
        assert_eq!(minimum(&mut entries(&rows)), 7.0);
        let rows = [(4.0, 0.0, 1.0), (8.0, 0.0, 1.0), (2.0, 0.0, 1.0)];
        assert_eq!(minimum(&mut entries(&rows)), 2.0);
    }

    #[test]
    fn a_long_row_is_sorted_too() {
        // 20 successors of value 20..1, each [0, 0.1]: the ten lowest (1..10) take 0.1 each.
        let rows: Vec<(f64, f64, f64)> = (0..20).map(|i| (f64::from(20 - i), 0.0, 0.1)).collect();
        let expected = (1..=10).map(f64::from).sum::<f64>() * 0.1;
        assert!((minimum(&mut entries(&rows)) - expected).abs() < 1e-12);
    }
}
