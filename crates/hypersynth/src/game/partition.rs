//! The partition of the hypergame by win-labels: how many robot and adversary states carry each
//! of the eight labels.

use serde::ser::{Serialize, SerializeMap, Serializer};

use super::labels::{LabelCounts, WinLabel};
use super::product::Hypergame;
use super::regions::TaskRegions;

/// The number of product states with each win-label, robot-turn and adversary-turn separately.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Partition {
    /// Indexed like [`WinLabel::ALL`].
    counts: [LabelCounts; 8],
}

impl Partition {
    /// Counts every product state of `game` under its win-label in `regions` (of the paper's
    /// two sub-tasks).
    pub fn compute(game: &Hypergame, regions: &TaskRegions) -> Partition {
        let mut counts = [LabelCounts::default(); 8];
        for h in game.states() {
            counts[regions.win_label(h).index()].add(game.owner(h));
        }
        Partition { counts }
    }

    /// The counts of `label` (zero for a label no state carries).
    pub fn get(&self, label: WinLabel) -> LabelCounts {
        self.counts[label.index()]
    }

    /// The labels with their counts, in the order of [`WinLabel::ALL`].
    pub fn iter(&self) -> impl Iterator<Item = (WinLabel, LabelCounts)> + '_ {
        WinLabel::ALL.into_iter().zip(self.counts.iter().copied())
    }
}

/// A map from the compact label (`"WWW"`, ...) to its counts, in the order of [`WinLabel::ALL`].
impl Serialize for Partition {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.counts.len()))?;
        for (label, counts) in self.iter() {
            map.serialize_entry(label.code(), &counts)?;
        }
        map.end()
    }
}
