//! The risk rule: part of the model's definition (docs/semantics.md §8.5), which the MDP's build
//! applies and a certificate's checker re-derives on its own.

use serde::{Deserialize, Serialize};

/// Which arena actions a robot state that can settle for something keeps (docs/semantics.md
/// §8.5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Risk {
    /// Once `gr(h) > 0`, no action with a positive probability of a next robot state of
    /// guarantee 0 (the paper's rule).
    #[default]
    Paper,
    /// No action with a positive probability of a next robot state of lower guarantee.
    Strict,
    /// Every action.
    Neutral,
}

impl Risk {
    /// Whether this rule lets a robot state of level `own` take an action whose next robot
    /// state has least level `least_next` (`u16::MAX`: no robot state can come next, a closed
    /// set of chance nodes, worth 0 and never lowering a guarantee: always allowed).
    pub(crate) fn allows(self, own: u32, least_next: u16) -> bool {
        least_next == u16::MAX
            || match self {
                Risk::Paper => own == 0 || least_next > 0,
                Risk::Strict => u32::from(least_next) >= own,
                Risk::Neutral => true,
            }
    }

    /// `paper`, `strict` or `neutral`, as reports and options name the rule.
    pub fn name(self) -> &'static str {
        match self {
            Risk::Paper => "paper",
            Risk::Strict => "strict",
            Risk::Neutral => "neutral",
        }
    }
}
