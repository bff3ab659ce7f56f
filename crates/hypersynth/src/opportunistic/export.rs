//! The controller as an artefact (docs/semantics.md §9): the opportunistic controller written as
//! one versioned JSON document ([`ControllerFile`], format [`FORMAT`], JSON Schema in
//! `schema/controller.schema.json`, reference in docs/formats.md) that an executor
//! ([`super::executor::Executor`]) runs without the solver, the product or the MDP. Reading it
//! back, every part checked against the others, is [`super::load`]'s.
//!
//! What the file holds:
//! - the model, everything a reader needs to build the hypergame MDP again: the sub-tasks and
//!   the payoff of every set of them, what the adversary believes (a set of sub-tasks or its own
//!   automaton), the discount, the risk rule, and the adversary's rules (`sigma_W` by its name,
//!   `sigma_L` uniform, random with its seed, its table of weights, or learnt: the counted
//!   observations and the confidence parameter of its region);
//! - the arena, as its map or its text in the arena format (what the executor reads state names
//!   and moves from), and its distinct labels as sets of proposition names (the letters);
//! - every automaton of the product (the sub-tasks', then psi's) as a transition table over
//!   those letters, with its initial and final states;
//! - the *automata tuples* (one state per automaton, the product's enumerated combinations) and
//!   one name table of *choices*: arena moves, `stop` or `commit` to a set of sub-tasks (a bit
//!   mask over `tasks`), and `give_up`;
//! - one *mode* per way of playing: the uncommitted controller (set 0) and the reactive strategy
//!   of every set it may commit to. A mode is a dense table over (robot arena state, automata
//!   tuple): entry `rank(s) · |tuples| + t`, `rank(s)` the number of robot states before `s` in
//!   the arena's order, holds the index of the choice made there, written as `width` base-64
//!   digits (`0-9 A-Z a-z - _`, most significant first), `width` dots where nothing is
//!   exported, or `~N~` for a run of N such entries;
//! - for every adversary arena state and tuple reached, one number (base 64 again): bit 0 says
//!   whether the state is worth 0 (nothing can be gained: the controller gives up there), bits
//!   1 and up are the moves of positive probability under the adversary model, edge `e` (in
//!   arena order) at bit `e + 1`, so that an executor can tell an off-model move (for a state
//!   of more than [`MAX_MASKED_EDGES`] edges, every move is recorded possible).
//!
//! Coverage (the file's `scope`): with [`Scope::Reachable`], the decisions of every robot
//! product state that can occur from h0 when the robot follows the controller and the adversary
//! makes *any* move (not only moves of positive probability), and the reactive moves of every
//! state that can occur after committing, by a search over (product state, mode); with
//! [`Scope::All`], the same search from every robot product state, so that a play goes on after
//! a robot move other than the one answered. Cost: linear in the product states covered and
//! their edges; the file takes one character per (robot arena state, tuple) and mode, and per
//! (adversary arena state, tuple).

use bit_set::BitSet;
use serde::{Deserialize, Serialize};

use super::adversary::{AdversaryModel, SigmaL, Weight};
use super::build::Risk;
use super::controller::{Controller, Decision, clamped};
use super::observations::Count;
use super::presentation::{Form, Presentation};
use super::view::{GameView, SolvedGame, SolvedHypergame};
use crate::arena::{ActionId, Arena, Owner, StateId};
use crate::automata::Dfa;
use crate::game::{HState, SubsetPayoffs, TaskSet};
use crate::mdp::Interval;

/// The most edges of an adversary state whose moves of positive probability the adversary table
/// lists one by one; a state with more is recorded with every move possible.
pub const MAX_MASKED_EDGES: usize = 62;

/// The format and version every exported controller declares.
pub const FORMAT: &str = "hypersynth-controller/2";

/// An exported controller (see the module documentation for each part).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerFile {
    /// [`FORMAT`].
    pub format: String,
    /// The paper's form or the general one (how sets are named).
    pub form: Form,
    /// Which robot states the tables decide at.
    pub scope: Scope,
    /// The sub-tasks' names; a set of sub-tasks is a bit mask over them.
    pub tasks: Vec<String>,
    /// What the adversary believes.
    pub believed: Believed,
    /// `r(T)` for every set, indexed by its mask (entry 0, the empty set, is 0).
    pub payoffs: Vec<f64>,
    /// The discount factor the controller was computed for.
    pub discount: f64,
    /// The risk rule the hypergame MDP was built with.
    pub risk: Risk,
    /// How the adversary plays where it believes it is winning.
    pub sigma_w: SigmaW,
    /// How the adversary plays where it believes it has lost.
    pub sigma_l: SigmaLRule,
    /// The certified bounds on the value of h0, `[lower, upper]`.
    pub value: [f64; 2],
    /// The arena.
    pub arena: ArenaSource,
    /// The distinct labels of the arena's states, each as its propositions' names: the letters
    /// the automata tables are indexed by.
    pub labels: Vec<Vec<String>>,
    /// The product's automata: the sub-tasks' in order, then psi's when it has one.
    pub automata: Vec<AutomatonTable>,
    /// The automata tuples, one state per automaton.
    pub tuples: Vec<Vec<u32>>,
    /// The choices the modes refer to.
    pub choices: Vec<Choice>,
    /// The uncommitted controller (set 0) and the reactive strategies of the sets committed to.
    pub modes: Vec<Mode>,
    /// Per (adversary arena state, tuple): worth 0 (bit 0), moves of positive probability
    /// (bits 1 and up).
    pub adversary: Table,
    /// Bounds on the controller's value and the MDP's that a reader can check
    /// (docs/semantics.md §9.4), when the export was asked for them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub certificate: Option<CertificateTables>,
}

/// A certificate (docs/semantics.md §9.4): the values of the states that carry one, in the
/// checker's breadth-first order over D_L and D_U (the others' values are derived), as indices
/// into a table of the distinct values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CertificateTables {
    /// The distinct values, each the 64 bits of a double, non-negative and finite (so read
    /// back exactly), in 11 base-64 digits.
    pub values: Table,
    /// Per state of D_L that carries its x (a robot state that moves, a chance node with an
    /// adversary successor), in order: the index of x in `values`.
    pub lower: Table,
    /// Per state of D_U that carries its y (a decision node, a chance node with an adversary
    /// successor), in order: the index of y in `values`.
    pub upper: Table,
}

/// Which robot states a file's tables decide at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scope {
    /// The states that can occur from h0 when the robot follows the controller and the
    /// adversary makes any move (the module documentation): the default.
    #[default]
    Reachable,
    /// Every robot product state (the policy is defined at each), and every state the reactive
    /// strategies reach after committing from any of them: a play goes on after the robot's
    /// own slips (a move other than the one answered).
    All,
}

/// What the adversary believes (psi), named as reports name it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Believed {
    /// psi as reports name it (its formula, or its automaton's name).
    pub name: String,
    /// psi is the conjunction of this set of sub-tasks (a mask) and has no automaton of its
    /// own; exactly one of `set` and `automaton` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub set: Option<u8>,
    /// psi has its own automaton, `automata[automaton]` (the one after the sub-tasks').
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub automaton: Option<u32>,
}

/// How the adversary plays where it believes it is winning (outside `Win(psi)`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SigmaW {
    /// Uniform over its safe actions, those whose successor stays outside `Win(psi)`
    /// (docs/semantics.md §6.2).
    UniformSafe,
}

/// How the adversary plays where it believes it has lost: [`SigmaL`] as data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum SigmaLRule {
    /// Uniform over the enabled actions.
    Uniform,
    /// Random weights drawn by the rule `draws` from `seed`.
    Random {
        /// The seed.
        seed: u64,
        /// How the weights are drawn.
        draws: Draws,
    },
    /// A weight per listed (adversary state, enabled action), all positive; a listed state's
    /// other actions have weight 0, unlisted states play uniformly.
    Weights(Vec<Weight>),
    /// Learnt from observations (docs/semantics.md §10): any distribution within the
    /// confidence region the counts give at confidence `1 − delta`, chosen against the robot
    /// at every visit (the file's controller is the robust one). The support is every enabled
    /// action, as with `Uniform`.
    Learnt {
        /// The confidence parameter, in `(0, 1)`.
        delta: f64,
        /// The counted observations, positive, each (state, action) once; unlisted pairs 0.
        counts: Vec<Count>,
    },
}

/// How random weights are drawn from a seed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Draws {
    /// The weight of an action in a state is a hash of the seed, the state's name and the
    /// action's name, a whole number in `[1, 2^53]` ([`super::adversary::random_weight`],
    /// docs/semantics.md §6).
    #[serde(rename = "name-hash")]
    NameHash,
}

impl SigmaLRule {
    /// `sigma_l` as the file writes it (a weights table without its weights of 0, which a
    /// listed state's unlisted actions have anyway).
    pub fn of(sigma_l: &SigmaL) -> SigmaLRule {
        match sigma_l {
            SigmaL::Uniform => SigmaLRule::Uniform,
            &SigmaL::Random { seed } => SigmaLRule::Random {
                seed,
                draws: Draws::NameHash,
            },
            SigmaL::Weights { table, .. } => SigmaLRule::Weights(
                table
                    .entries()
                    .iter()
                    .filter(|entry| entry.weight > 0.0)
                    .cloned()
                    .collect(),
            ),
        }
    }

    /// The rule as the adversary model takes it (a weights table named `file`; a learnt
    /// sigma_L as its support, `Uniform`).
    pub fn to_sigma_l(&self) -> SigmaL {
        match self {
            SigmaLRule::Uniform | SigmaLRule::Learnt { .. } => SigmaL::Uniform,
            &SigmaLRule::Random { seed, .. } => SigmaL::Random { seed },
            SigmaLRule::Weights(weights) => {
                let mut table = super::adversary::WeightTable::new();
                for w in weights {
                    table.add(w.state.clone(), w.action.clone(), w.weight);
                }
                SigmaL::Weights {
                    table,
                    file: "file".to_string(),
                }
            }
        }
    }
}

/// Where the arena comes from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum ArenaSource {
    /// A map (`hypersynth map v1`), built as the generator builds it.
    Map(String),
    /// An arena in the arena text format.
    Text(String),
}

/// One automaton as a table over the letters of `labels`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AutomatonTable {
    /// The automaton's name in the product (a sub-task's, or `psi`).
    pub name: String,
    /// Its initial state.
    pub initial: u32,
    /// Its final (accepting, absorbing) states.
    pub finals: Vec<u32>,
    /// `step[q][l]`: the state after reading label `l` in state `q`.
    pub step: Vec<Vec<u32>>,
}

/// What the controller does in a robot state.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Choice {
    /// Play this arena action.
    Move(String),
    /// Play `stop` (instant) and commit to this set (a mask), then play its strategy.
    Stop(u8),
    /// Commit to this set (a mask) without moving, then play its strategy.
    Commit(u8),
    /// Nothing can be gained.
    GiveUp,
}

/// A mode's table of choices.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mode {
    /// 0 for the uncommitted controller, else the set committed to (a mask).
    pub set: u8,
    /// The table over (robot arena state, tuple).
    #[serde(flatten)]
    pub table: Table,
}

/// A table of base-64 codes: `width` digits per entry; `width` dots for one absent entry, and
/// `~N~` (N in base-64 digits) for a run of N absent entries, so that tables where the play
/// reaches few states stay small.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Table {
    /// Digits per entry.
    pub width: usize,
    /// The entries, end to end.
    pub codes: String,
}

/// The base-64 digits of the tables, in order of value.
pub const DIGITS: &[u8; 64] = b"0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz-_";

/// The digit of a missing entry.
pub const NONE: u8 = b'.';

/// What opens and closes the count of a run of missing entries.
pub const RUN: u8 = b'~';

/// The shortest run of missing entries written as a count.
const SHORTEST_RUN: usize = 4;

impl Table {
    /// The table of `entries` (`None`: no entry), with as few digits per entry as the largest
    /// needs.
    pub fn encode<I: Iterator<Item = Option<u64>>>(entries: impl Fn() -> I) -> Table {
        Table::encode_wide(1, entries)
    }

    /// [`Table::encode`] with at least `width` digits per entry (at most 11).
    pub fn encode_wide<I: Iterator<Item = Option<u64>>>(
        width: usize,
        entries: impl Fn() -> I,
    ) -> Table {
        let largest = entries().flatten().max().unwrap_or(0);
        let width = digits_for(largest).max(width.min(11));
        let mut codes = Vec::new();
        let mut missing = 0usize;
        let flush = |codes: &mut Vec<u8>, missing: &mut usize| {
            if *missing >= SHORTEST_RUN {
                codes.push(RUN);
                push_digits(codes, *missing as u64, digits_for(*missing as u64));
                codes.push(RUN);
            } else {
                codes.extend(std::iter::repeat_n(NONE, *missing * width));
            }
            *missing = 0;
        };
        for entry in entries() {
            match entry {
                Some(value) => {
                    flush(&mut codes, &mut missing);
                    push_digits(&mut codes, value, width);
                }
                None => missing += 1,
            }
        }
        flush(&mut codes, &mut missing);
        Table {
            width,
            codes: String::from_utf8(codes).expect("ASCII digits"),
        }
    }

    /// The entries, read back: runs of present entries with the index of each run's first,
    /// for random access in the run's order. Refuses malformed codes.
    pub fn decode(&self) -> Result<Entries, String> {
        let width = self.width;
        if width == 0 || width > 11 {
            return Err(format!("width {width} is not between 1 and 11"));
        }
        let bytes = self.codes.as_bytes();
        let mut entries = Entries::default();
        let (mut at, mut index) = (0usize, 0usize);
        while at < bytes.len() {
            if bytes[at] == RUN {
                let close = bytes[at + 1..]
                    .iter()
                    .position(|&b| b == RUN)
                    .ok_or(format!("an unclosed run at character {at}"))?;
                let count = read_digits(&bytes[at + 1..at + 1 + close])
                    .filter(|_| close > 0)
                    .ok_or(format!("a run of no count at character {at}"))?;
                index = index
                    .checked_add(count as usize)
                    .ok_or("too many entries")?;
                at += close + 2;
                continue;
            }
            let digits = bytes
                .get(at..at + width)
                .ok_or(format!("a cut entry at character {at}"))?;
            if digits.iter().all(|&d| d == NONE) {
                index += 1;
            } else {
                let value = read_digits(digits).ok_or(format!(
                    "an entry that is no base-64 number at character {at}"
                ))?;
                if entries.starts.last().is_none_or(|_| entries.next != index) {
                    entries.starts.push(index);
                    entries.offsets.push(entries.values.len());
                }
                entries.values.push(value);
                entries.next = index + 1;
                index += 1;
            }
            at += width;
        }
        entries.len = index;
        Ok(entries)
    }
}

/// A decoded [`Table`]: its present entries in runs of consecutive indices.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Entries {
    /// The index of each run's first entry, ascending.
    starts: Vec<usize>,
    /// The position of each run's first value in `values`.
    offsets: Vec<usize>,
    values: Vec<u64>,
    /// The index after the last present entry.
    next: usize,
    len: usize,
}

impl Entries {
    /// The number of entries, present or not.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the table has no entry.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Entry `i`, if present.
    pub fn get(&self, i: usize) -> Option<u64> {
        let run = self
            .starts
            .partition_point(|&start| start <= i)
            .checked_sub(1)?;
        let end = self
            .offsets
            .get(run + 1)
            .copied()
            .unwrap_or(self.values.len());
        let at = self.offsets[run] + (i - self.starts[run]);
        (at < end).then(|| self.values[at])
    }

    /// The present entries' values.
    pub fn values(&self) -> &[u64] {
        &self.values
    }
}

/// The fewest base-64 digits that write `value`.
fn digits_for(value: u64) -> usize {
    let mut width = 1;
    while width < 11 && value >> (6 * width) != 0 {
        width += 1;
    }
    width
}

fn push_digits(codes: &mut Vec<u8>, value: u64, width: usize) {
    for digit in (0..width).rev() {
        codes.push(DIGITS[(value >> (6 * digit) & 63) as usize]);
    }
}

/// The number written by base-64 `digits`, if they all are digits and it fits in 64 bits.
fn read_digits(digits: &[u8]) -> Option<u64> {
    digits.iter().try_fold(0u64, |value, &d| {
        let digit = digit_value(d)?;
        value.checked_mul(64).map(|v| v | digit)
    })
}

/// The value of a base-64 digit.
pub fn digit_value(digit: u8) -> Option<u64> {
    DIGITS.iter().position(|&d| d == digit).map(|v| v as u64)
}

/// What an export needs besides the controller: how the arena travels, what psi is, the
/// product's automata (in product order), and the rules the MDP was built with.
pub struct ExportInputs<'a> {
    /// The arena as the file carries it.
    pub arena: ArenaSource,
    /// What the adversary believes.
    pub believed: Believed,
    /// The product's automata, named, in product order.
    pub automata: &'a [(&'a str, &'a Dfa)],
    /// Which robot states to decide at.
    pub scope: Scope,
}

/// The rules the hypergame MDP of an exported controller was built with.
#[derive(Clone, Debug)]
pub struct ModelRules {
    /// The risk rule.
    pub risk: Risk,
    /// sigma_L (sigma_W has one rule), as the file writes it.
    pub sigma_l: SigmaLRule,
}

/// What an export reads of a solved problem, whichever engine solved it: the arena's owners and
/// letters, the product's automata tuples, and per product state (numbered `0..num_states()`,
/// the product's full enumeration or the explicit engine's own) its place in the tables, its
/// moves, the adversary's distribution and the controller's decision.
pub trait Exportable {
    /// The number of arena states.
    fn num_arena_states(&self) -> usize;
    /// Who moves in arena state `s`.
    fn arena_owner(&self, s: u32) -> Owner;
    /// The arena's distinct labels, each a set of indices into [`Exportable::propositions`].
    fn labels(&self) -> &[BitSet];
    /// The arena's propositions.
    fn propositions(&self) -> &[String];
    /// The name of arena action `action`.
    fn action_name(&self, action: ActionId) -> &str;
    /// The number of automata tuples.
    fn num_tuples(&self) -> u32;
    /// The automata's states in tuple `tuple`, one per automaton.
    fn tuple(&self, tuple: u32) -> Vec<u32>;
    /// The problem's presentation (its form and sub-tasks' names).
    fn presentation(&self) -> &Presentation;
    /// The payoff of every set of sub-tasks.
    fn payoffs(&self) -> &SubsetPayoffs;
    /// The discount the controller was computed for.
    fn discount(&self) -> f64;
    /// The number of product states.
    fn num_states(&self) -> usize;
    /// The initial product state.
    fn initial(&self) -> HState;
    /// The certified bounds on the value of `h`.
    fn value(&self, h: HState) -> Interval;
    /// Whether the robot moves in `h`.
    fn is_robot(&self, h: HState) -> bool;
    /// The arena state and the automata tuple of `h`.
    fn position(&self, h: HState) -> (u32, u32);
    /// Fills `out` with the successors of `h`, in edge order.
    fn successors(&self, h: HState, out: &mut Vec<HState>);
    /// Fills `out` with the adversary's probability of each edge of adversary state `h`, in
    /// edge order.
    fn probabilities(&self, h: HState, out: &mut Vec<f64>);
    /// The controller's decision in robot state `h` before committing.
    fn decide(&self, h: HState) -> Decision;
    /// Whether `h` satisfies every sub-task of `set`.
    fn is_target(&self, set: TaskSet, h: HState) -> bool;
    /// The move of the reactive strategy of `set` in robot state `h` (`None` outside
    /// `Win(set)`).
    fn reactive_move(&self, set: TaskSet, h: HState) -> Option<(ActionId, HState)>;

    /// Whether `h` is worth exactly 0.
    fn is_worthless(&self, h: HState) -> bool {
        self.value(h).upper == 0.0
    }

    /// Whether the product enumerates `h` (a state below [`Exportable::num_states`] may be
    /// one it leaves out, not reachable from h0).
    fn is_enumerated(&self, _h: HState) -> bool {
        true
    }
}

/// The explicit engine's controller with its adversary model, as an export reads it.
pub struct Explicit<'c, 'g, 'a> {
    /// The controller.
    pub controller: &'c Controller<'c, SolvedHypergame<'g, 'a>>,
    /// The adversary's model the MDP was built with.
    pub adversary: &'c AdversaryModel,
}

impl Exportable for Explicit<'_, '_, '_> {
    fn num_arena_states(&self) -> usize {
        self.controller.game.arena().num_states()
    }
    fn arena_owner(&self, s: u32) -> Owner {
        self.controller.game.arena().owner(StateId::from_u32(s))
    }
    fn labels(&self) -> &[BitSet] {
        self.controller.game.arena().labels()
    }
    fn propositions(&self) -> &[String] {
        self.controller.game.arena().propositions()
    }
    fn action_name(&self, action: ActionId) -> &str {
        self.controller.game.action_name(action)
    }
    fn num_tuples(&self) -> u32 {
        self.controller.game.game().num_automata_slots()
    }
    fn tuple(&self, tuple: u32) -> Vec<u32> {
        self.controller.game.game().automata_of_slot(tuple)
    }
    fn presentation(&self) -> &Presentation {
        self.controller.game.presentation()
    }
    fn payoffs(&self) -> &SubsetPayoffs {
        self.controller.game.payoffs()
    }
    fn discount(&self) -> f64 {
        self.controller.solution.discount().get()
    }
    fn num_states(&self) -> usize {
        self.controller.game.num_states()
    }
    fn initial(&self) -> HState {
        self.controller.game.initial()
    }
    fn value(&self, h: HState) -> Interval {
        self.controller.value(h)
    }
    fn is_robot(&self, h: HState) -> bool {
        self.controller.game.is_robot(h)
    }
    fn position(&self, h: HState) -> (u32, u32) {
        let game = self.controller.game;
        (game.arena_state(h).as_u32(), game.game().automata_slot(h))
    }
    fn successors(&self, h: HState, out: &mut Vec<HState>) {
        out.clear();
        out.extend(self.controller.game.edges(h).map(|(_, t)| t));
    }
    fn probabilities(&self, h: HState, out: &mut Vec<f64>) {
        self.adversary.distribution(self.controller.game, h, out);
    }
    fn decide(&self, h: HState) -> Decision {
        self.controller.decide(h)
    }
    fn is_target(&self, set: TaskSet, h: HState) -> bool {
        self.controller.game.is_target(set, h)
    }
    fn reactive_move(&self, set: TaskSet, h: HState) -> Option<(ActionId, HState)> {
        self.controller.game.reactive_move(set, h)
    }
    fn is_worthless(&self, h: HState) -> bool {
        self.controller.is_worthless(h)
    }
}

/// The exported controller of `controller` (on the product of `game`, whose MDP was built with
/// `rules`), with the adversary's moves of positive probability from `adversary`.
pub fn export(
    controller: &Controller<'_, SolvedHypergame<'_, '_>>,
    adversary: &AdversaryModel,
    rules: ModelRules,
    inputs: &ExportInputs,
) -> ControllerFile {
    export_from(
        &Explicit {
            controller,
            adversary,
        },
        rules,
        inputs,
    )
}

/// The exported controller of `solved`, whose MDP was built with `rules`: what [`export`] makes
/// of the explicit engine's controller, from either engine. The search keeps a bit per product
/// state and mode it visits, and the tables' entries only where they are present.
pub fn export_from(
    solved: &impl Exportable,
    rules: ModelRules,
    inputs: &ExportInputs,
) -> ControllerFile {
    let tuples = solved.num_tuples() as u64;
    let ranks = Ranks::by_owner(solved.num_arena_states(), |s| solved.arena_owner(s));
    let payoffs = solved.payoffs();
    let k = payoffs.num_tasks();
    let n = solved.num_states();
    let h0 = solved.initial();
    let mut choices = Choices::default();
    // Per mode (0 and each mask), its present entries: (entry, choice); `None` until used.
    let mut modes: Vec<Option<Vec<(u64, u64)>>> = vec![None; 1 << k];
    let mut support: Vec<(u64, u64)> = Vec::new();
    let mut visited: Vec<Option<BitSet>> = vec![None; 1 << k];
    let mut stack = match inputs.scope {
        Scope::Reachable => vec![(h0, 0u8)],
        // Every robot product state, h0 last so that it is searched first.
        Scope::All => HState::range(n)
            .filter(|&h| solved.is_enumerated(h) && solved.is_robot(h) && h != h0)
            .chain([h0])
            .map(|h| (h, 0u8))
            .collect(),
    };
    let (mut scratch, mut successors) = (Vec::new(), Vec::new());
    while let Some((h, mode)) = stack.pop() {
        let seen = visited[mode as usize].get_or_insert_with(|| BitSet::with_capacity(n));
        if !seen.insert(h.index()) {
            continue;
        }
        let (s, tuple) = solved.position(h);
        let entry = ranks.of_state(s) * tuples + u64::from(tuple);
        if !solved.is_robot(h) {
            solved.successors(h, &mut successors);
            if successors.is_empty() {
                continue;
            }
            solved.probabilities(h, &mut scratch);
            let mask = if scratch.len() > MAX_MASKED_EDGES {
                u64::MAX >> 1
            } else {
                scratch
                    .iter()
                    .enumerate()
                    .filter(|&(_, &p)| p > 0.0)
                    .fold(0u64, |mask, (edge, _)| mask | 1 << edge)
            };
            let worthless = solved.is_worthless(h);
            support.push((entry, mask << 1 | u64::from(worthless)));
            stack.extend(successors.iter().map(|&t| (t, mode)));
            continue;
        }
        let table = modes[mode as usize].get_or_insert_with(Vec::new);
        if mode == 0 {
            let choice = match solved.decide(h) {
                Decision::Move { action, successor } => {
                    stack.push((successor, 0));
                    Choice::Move(solved.action_name(action).to_string())
                }
                Decision::Commit(set) => {
                    stack.push((h, set.0));
                    Choice::Commit(set.0)
                }
                Decision::Stop(set) => {
                    stack.push((h, set.0));
                    Choice::Stop(set.0)
                }
                Decision::GiveUp => Choice::GiveUp,
            };
            table.push((entry, u64::from(choices.index(choice))));
        } else if !solved.is_target(TaskSet(mode), h)
            && let Some((action, successor)) = solved.reactive_move(TaskSet(mode), h)
        {
            let choice = Choice::Move(solved.action_name(action).to_string());
            table.push((entry, u64::from(choices.index(choice))));
            stack.push((successor, mode));
        }
    }
    // The uncommitted mode always, even when the play reaches no robot state (readers
    // require it).
    modes[0].get_or_insert_with(Vec::new);
    let value = clamped(solved.value(h0), payoffs.all());
    let labels = solved.labels();
    let propositions = solved.propositions();
    ControllerFile {
        format: FORMAT.to_string(),
        form: solved.presentation().form(),
        scope: inputs.scope,
        tasks: solved.presentation().names().to_vec(),
        believed: inputs.believed.clone(),
        payoffs: (0..1usize << k)
            .map(|m| payoffs.get(TaskSet(m as u8)))
            .collect(),
        discount: solved.discount(),
        risk: rules.risk,
        sigma_w: SigmaW::UniformSafe,
        sigma_l: rules.sigma_l,
        value: [value.lower, value.upper],
        arena: inputs.arena.clone(),
        labels: labels
            .iter()
            .map(|label| label.iter().map(|p| propositions[p].clone()).collect())
            .collect(),
        automata: inputs
            .automata
            .iter()
            .map(|(name, dfa)| automaton_table(name, dfa, labels, propositions))
            .collect(),
        tuples: (0..tuples as u32).map(|t| solved.tuple(t)).collect(),
        choices: choices.list,
        modes: modes
            .iter_mut()
            .enumerate()
            .filter_map(|(set, table)| {
                let table = table.as_mut()?;
                Some(Mode {
                    set: set as u8,
                    table: sparse_table(ranks.robot * tuples, table),
                })
            })
            .collect(),
        adversary: sparse_table(ranks.adversary * tuples, &mut support),
        certificate: None,
    }
}

/// The table of `len` entries of which `present` lists those present, `(index, value)` in any
/// order and each index once.
fn sparse_table(len: u64, present: &mut [(u64, u64)]) -> Table {
    present.sort_unstable_by_key(|&(entry, _)| entry);
    let present = &*present;
    Table::encode(|| {
        let mut next = present.iter().peekable();
        (0..len).map(move |i| next.next_if(|&&(entry, _)| entry == i).map(|&(_, v)| v))
    })
}

/// The table of `dfa` over the arena's letters: its `labels`, sets of indices into
/// `propositions`.
pub fn automaton_table(
    name: &str,
    dfa: &Dfa,
    labels: &[BitSet],
    propositions: &[String],
) -> AutomatonTable {
    let letters: Vec<u64> = labels
        .iter()
        .map(|label| dfa.letter(label.iter().map(|p| propositions[p].as_str())))
        .collect();
    AutomatonTable {
        name: name.to_string(),
        initial: dfa.initial(),
        finals: dfa.finals().iter().map(|q| q as u32).collect(),
        step: (0..dfa.num_states() as u32)
            .map(|q| letters.iter().map(|&letter| dfa.step(q, letter)).collect())
            .collect(),
    }
}

/// The choices met so far, each once, in order of first use.
#[derive(Default)]
struct Choices {
    list: Vec<Choice>,
    index: std::collections::HashMap<Choice, u16>,
}

impl Choices {
    fn index(&mut self, choice: Choice) -> u16 {
        if let Some(&i) = self.index.get(&choice) {
            return i;
        }
        // At most an arena action per choice besides 3 per set: far below u16::MAX.
        let i = self.list.len() as u16;
        self.list.push(choice.clone());
        self.index.insert(choice, i);
        i
    }
}

/// Each arena state's rank among the states of its owner, in arena order: the row of its
/// entries in the tables. A bit per state (robot or not) and a count per 64 states, so that an
/// arena of a large map costs a few bytes per 64 states.
pub(crate) struct Ranks {
    /// Bit `s % 64` of word `s / 64`: state `s` is the robot's.
    robot_bits: Vec<u64>,
    /// The robot states before each word's first state.
    before: Vec<u64>,
    /// The number of robot states.
    pub(crate) robot: u64,
    /// The number of adversary states.
    pub(crate) adversary: u64,
}

impl Ranks {
    pub(crate) fn new(arena: &Arena) -> Ranks {
        Ranks::by_owner(arena.num_states(), |s| arena.owner(StateId::from_u32(s)))
    }

    /// The ranks of `n` states owned as `owner` says.
    pub(crate) fn by_owner(n: usize, owner: impl Fn(u32) -> Owner) -> Ranks {
        let mut robot_bits = vec![0u64; n.div_ceil(64)];
        for s in 0..n as u32 {
            if owner(s) == Owner::Robot {
                robot_bits[s as usize / 64] |= 1 << (s % 64);
            }
        }
        let mut robot = 0u64;
        let before = robot_bits
            .iter()
            .map(|word| {
                let here = robot;
                robot += u64::from(word.count_ones());
                here
            })
            .collect();
        Ranks {
            robot_bits,
            before,
            robot,
            adversary: n as u64 - robot,
        }
    }

    /// The rank of arena state `s` among the states of its owner.
    pub(crate) fn of_state(&self, s: u32) -> u64 {
        let (word, bit) = (s as usize / 64, s % 64);
        let robot_before = self.before[word]
            + u64::from((self.robot_bits[word] & ((1u64 << bit) - 1)).count_ones());
        match self.robot_bits[word] >> bit & 1 {
            1 => robot_before,
            _ => u64::from(s) - robot_before,
        }
    }

    pub(crate) fn of(&self, s: crate::arena::StateId) -> usize {
        self.of_state(s.as_u32()) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_encode_in_as_few_base_64_digits_as_needed_and_read_back() {
        let encode = |entries: &[Option<u64>]| Table::encode(|| entries.iter().copied());
        let read = |table: &Table| {
            let entries = table.decode().unwrap();
            (0..entries.len())
                .map(|i| entries.get(i))
                .collect::<Vec<_>>()
        };
        let table = encode(&[Some(0), None, Some(63)]);
        assert_eq!((table.width, table.codes.as_str()), (1, "0._"));
        let entries = [Some(64), None, Some(4095), Some(5)];
        let table = encode(&entries);
        assert_eq!((table.width, table.codes.as_str()), (2, "10..__05"));
        assert_eq!(read(&table), entries);
        // Runs of four or more absent entries are counted: 70 = "16" in base 64.
        let mut entries = vec![Some(7)];
        entries.extend([None; 70]);
        entries.extend([Some(1), Some(2), None, None, None]);
        let table = encode(&entries);
        assert_eq!(table.codes, "7~16~12...");
        assert_eq!(read(&table), entries);
        assert_eq!(encode(&[]).decode().unwrap().len(), 0);
        for bad in ["~", "~~", "1~2", "*", "12~"] {
            let table = Table {
                width: 1,
                codes: bad.to_string(),
            };
            assert!(table.decode().is_err(), "{bad}");
        }
        let cut = Table {
            width: 2,
            codes: "123".to_string(),
        };
        assert!(cut.decode().is_err());
    }
}
