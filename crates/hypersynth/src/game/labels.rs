//! Win-labels and the partition of the hypergame by them.
//!
//! The win-label of `h` is `(h ∈ Win(phi1), h ∈ Win(phi2), h ∈ Win(phi))`, written `(W, L, L)`
//! or compactly `WLL`. Since `F12 ⊆ F1 ∩ F2` and attractors are monotone in their targets,
//! `Win(phi) ⊆ Win(phi1) ∩ Win(phi2)`: the labels `WLW`, `LWW` and `LLW` cannot occur. The
//! partition ([`super::Partition`]) counts them anyway (a non-zero count would reveal a bug), and
//! lists the eight labels in the fixed order of [`WinLabel::ALL`]: the five possible ones first.

use std::fmt;

use serde::ser::{Serialize, Serializer};

use crate::arena::Owner;

/// Membership of a state in `Win(phi1)`, `Win(phi2)` and `Win(phi)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct WinLabel {
    /// Whether the state is in `Win(phi1)`.
    pub phi1: bool,
    /// Whether the state is in `Win(phi2)`.
    pub phi2: bool,
    /// Whether the state is in `Win(phi)`.
    pub phi: bool,
}

impl WinLabel {
    /// The eight labels: the possible ones, then `WLW`, `LWW`, `LLW`.
    pub const ALL: [WinLabel; 8] = [
        WinLabel::new(true, true, true),
        WinLabel::new(true, true, false),
        WinLabel::new(true, false, false),
        WinLabel::new(false, true, false),
        WinLabel::new(false, false, false),
        WinLabel::new(true, false, true),
        WinLabel::new(false, true, true),
        WinLabel::new(false, false, true),
    ];

    /// The label with these three memberships, in the order `(phi1, phi2, phi)`.
    pub const fn new(phi1: bool, phi2: bool, phi: bool) -> WinLabel {
        WinLabel { phi1, phi2, phi }
    }

    /// Whether the label is consistent with `Win(phi) ⊆ Win(phi1) ∩ Win(phi2)`.
    pub fn is_possible(self) -> bool {
        !self.phi || (self.phi1 && self.phi2)
    }

    /// The compact form, e.g. `WLL`.
    pub fn code(self) -> &'static str {
        const CODES: [&str; 8] = ["LLL", "LLW", "LWL", "LWW", "WLL", "WLW", "WWL", "WWW"];
        CODES[(self.phi1 as usize) << 2 | (self.phi2 as usize) << 1 | self.phi as usize]
    }

    /// The position of the label in [`WinLabel::ALL`].
    pub(super) fn index(self) -> usize {
        WinLabel::ALL
            .iter()
            .position(|&label| label == self)
            .expect("ALL lists every label")
    }
}

/// `(W, L, L)`.
impl fmt::Display for WinLabel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [a, b, c] = [self.phi1, self.phi2, self.phi].map(|w| if w { 'W' } else { 'L' });
        write!(f, "({a}, {b}, {c})")
    }
}

/// Serialized in its compact form.
impl Serialize for WinLabel {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.code())
    }
}

/// How many states carry one label.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct LabelCounts {
    /// Number of robot states with the label.
    pub robot: usize,
    /// Number of adversary states with the label.
    pub adversary: usize,
    /// Number of states with the label (`robot + adversary`).
    pub total: usize,
}

impl LabelCounts {
    /// Counts one more state, owned by `owner`.
    pub fn add(&mut self, owner: Owner) {
        match owner {
            Owner::Robot => self.robot += 1,
            Owner::Adversary => self.adversary += 1,
        }
        self.total += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_print_in_both_forms_and_know_which_are_impossible() {
        let wll = WinLabel::new(true, false, false);
        assert_eq!(wll.to_string(), "(W, L, L)");
        assert_eq!(wll.code(), "WLL");
        assert_eq!(WinLabel::new(false, false, true).code(), "LLW");
        assert_eq!(WinLabel::new(true, true, true).to_string(), "(W, W, W)");
        let codes: Vec<&str> = WinLabel::ALL.iter().map(|l| l.code()).collect();
        assert_eq!(
            codes,
            ["WWW", "WWL", "WLL", "LWL", "LLL", "WLW", "LWW", "LLW"]
        );
        let possible: Vec<bool> = WinLabel::ALL.iter().map(|l| l.is_possible()).collect();
        assert_eq!(
            possible,
            [true, true, true, true, true, false, false, false]
        );
        for (i, label) in WinLabel::ALL.iter().enumerate() {
            assert_eq!(label.index(), i);
        }
    }
}
