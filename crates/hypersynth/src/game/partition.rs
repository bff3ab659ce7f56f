//! The product's states by label: [`LabelClass`]es (which sets of sub-tasks a state wins, and
//! whether it is in `Win(psi)`), from which both vocabularies' tables are read: the paper's
//! [`Partition`] by win-label, and the general form's rows by maximal winnable sets
//! ([`label_rows`]).

use crate::game::Wins;
use std::collections::BTreeMap;

use serde::ser::{Serialize, SerializeMap, Serializer};

use super::labels::{LabelCounts, WinLabel};
use super::product::Hypergame;
use super::regions::{SubsetLabel, TaskRegions};
use super::sets::TaskSet;
use crate::arena::Owner;

/// The states that win exactly the sets `won` (every non-empty set T with the state in
/// `Win(T)`, in mask order) and are in `Win(psi)` or not.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LabelClass {
    /// The sets the states win, in increasing mask order.
    pub won: Vec<TaskSet>,
    /// Whether the states are in `Win(psi)`.
    pub psi: bool,
    /// How many robot, adversary and all states there are.
    pub counts: LabelCounts,
}

/// The states of `game` grouped by the sets they win and `Win(psi)`, sorted by those. One pass;
/// a state costs a membership test per set.
pub fn label_classes(game: &Hypergame, regions: &TaskRegions) -> Vec<LabelClass> {
    let k = regions.num_tasks();
    classes_of(
        k,
        game.states().map(|h| {
            let won = won_bits(k, |set| regions.win(set).contains(h));
            (game.owner(h), won, regions.believed().contains(h))
        }),
    )
}

/// The sets of the `k` sub-tasks a state wins, as bits by mask (255 sets at most).
pub(crate) fn won_bits(k: usize, wins: impl Fn(TaskSet) -> bool) -> [u64; 4] {
    let mut won = [0u64; 4];
    for set in TaskSet::non_empty(k).filter(|&set| wins(set)) {
        won[set.0 as usize / 64] |= 1 << (set.0 % 64);
    }
    won
}

/// The classes of `states`, each given by its owner, the sets it wins ([`won_bits`]) and
/// whether it is in `Win(psi)`, sorted by sets and psi: the counting both engines share.
pub(crate) fn classes_of(
    k: usize,
    states: impl Iterator<Item = (Owner, [u64; 4], bool)>,
) -> Vec<LabelClass> {
    let mut keys: Vec<([u64; 4], bool, LabelCounts)> = Vec::new();
    let mut last = 0;
    for (owner, won, psi) in states {
        let at = match keys.get(last) {
            Some(&(w, p, _)) if w == won && p == psi => last,
            _ => match keys.iter().position(|&(w, p, _)| w == won && p == psi) {
                Some(at) => at,
                None => {
                    keys.push((won, psi, LabelCounts::default()));
                    keys.len() - 1
                }
            },
        };
        keys[at].2.add(owner);
        last = at;
    }
    let mut classes: Vec<LabelClass> = keys
        .into_iter()
        .map(|(won, psi, counts)| LabelClass {
            won: TaskSet::non_empty(k)
                .filter(|set| won[set.0 as usize / 64] >> (set.0 % 64) & 1 == 1)
                .collect(),
            psi,
            counts,
        })
        .collect();
    classes.sort_by(|a, b| (&a.won, a.psi).cmp(&(&b.won, b.psi)));
    classes
}

/// The number of robot, adversary and all states per win-label (the paper's `phi1`, `phi2`,
/// `phi` are the sets `{1}`, `{2}`, `{1,2}`), impossible labels included.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Partition {
    counts: [LabelCounts; 8],
}

impl Partition {
    /// The paper's partition of the product `game` by the win-labels of `regions`.
    pub fn compute(game: &Hypergame, regions: &TaskRegions) -> Partition {
        Partition::of(&label_classes(game, regions))
    }

    /// The paper's partition read from the classes of a product of two sub-tasks.
    pub fn of(classes: &[LabelClass]) -> Partition {
        let mut counts = [LabelCounts::default(); 8];
        for class in classes {
            let [phi1, phi2, phi] =
                [0b01, 0b10, 0b11].map(|mask| class.won.contains(&TaskSet(mask)));
            let sum = &mut counts[WinLabel { phi1, phi2, phi }.index()];
            sum.robot += class.counts.robot;
            sum.adversary += class.counts.adversary;
            sum.total += class.counts.total;
        }
        Partition { counts }
    }

    /// The counts of one win-label.
    pub fn get(&self, label: WinLabel) -> LabelCounts {
        self.counts[label.index()]
    }

    /// Every win-label with its counts, in the order of [`WinLabel::ALL`].
    pub fn iter(&self) -> impl Iterator<Item = (WinLabel, LabelCounts)> + '_ {
        WinLabel::ALL.into_iter().zip(self.counts.iter().copied())
    }
}

impl Serialize for Partition {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.counts.len()))?;
        for (label, counts) in self.iter() {
            map.serialize_entry(label.code(), &counts)?;
        }
        map.end()
    }
}

/// One row of the general form's partition: a generalised win-label and its states.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LabelRow {
    /// The inclusion-maximal winnable sets, each as its sub-tasks' names.
    pub maximal: Vec<Vec<String>>,
    /// Whether the states are in `Win(psi)`.
    pub psi: bool,
    /// How many robot, adversary and all states have the label.
    pub counts: LabelCounts,
}

/// The general form's partition: the states per generalised label (the inclusion-maximal
/// winnable sets, and psi), sorted by the labels' sets, then psi; sub-tasks named `names`.
pub fn label_rows(classes: &[LabelClass], names: &[String]) -> Vec<LabelRow> {
    let mut rows: BTreeMap<SubsetLabel, LabelCounts> = BTreeMap::new();
    for class in classes {
        let maximal = class
            .won
            .iter()
            .copied()
            .filter(|&set| {
                !class
                    .won
                    .iter()
                    .any(|&other| other != set && set.is_subset(other))
            })
            .collect();
        let label = SubsetLabel {
            maximal,
            psi: class.psi,
        };
        let sum = rows.entry(label).or_default();
        sum.robot += class.counts.robot;
        sum.adversary += class.counts.adversary;
        sum.total += class.counts.total;
    }
    rows.into_iter()
        .map(|(label, counts)| LabelRow {
            maximal: label.maximal.iter().map(|set| set.names(names)).collect(),
            psi: label.psi,
            counts,
        })
        .collect()
}
