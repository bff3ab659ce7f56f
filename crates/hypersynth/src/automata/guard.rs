//! Guards: Boolean functions over an automaton's atomic propositions, kept symbolic.
//!
//! A guard is a reduced ordered binary decision diagram (BDD) over propositions numbered `0..64`
//! in the order of the automaton's `aps` list, stored on its own (a small shared slice of
//! nodes, in a canonical order), so it is a plain value: equal functions are equal guards (`==`
//! and `Hash` are semantic), `not` is O(size), `evaluate` walks at most 64 nodes. A *letter* (a valuation of
//! the propositions) is a `u64` whose bit `i` says whether proposition `i` holds. Binary
//! operations run in the translation's BDD manager (the private `bdd` module): O(|f|·|g|) at
//! worst. The thread keeps one manager for them between operations (a `Lease`), so that its
//! tables and cache serve every operation on the same few guards.
//! Conjunctions of disjunctions such as `(0|1)&(2|3)&…&(30|31)` take a node per proposition,
//! where a list of cubes took 2^16 cubes.
//!
//! [`GuardUnion`] checks that many guards are pairwise disjoint without comparing pairs: it keeps
//! their union in one manager, so `k` edges of a state cost `k` conjunctions and disjunctions
//! with the union (near-linear for the labels automata have), not `k²/2` intersections.
//!
//! For output, [`Guard::cubes`] gives an irredundant sum of products (Minato–Morreale), the
//! form HOA and DOT print.

use std::cell::Cell;
use std::fmt;
use std::ops::{Deref, DerefMut};
use std::sync::Arc;

use crate::bdd::{self, Bdd, NodeMap};

/// The largest number of atomic propositions an automaton may have.
pub const MAX_PROPOSITIONS: usize = 64;

/// A conjunction of literals: the propositions in `positive` hold and those in `negative` do not.
/// Invariant: `positive & negative == 0` (a contradictory cube is never stored).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Cube {
    /// The propositions (bit `i` for proposition `i`) that must hold.
    pub positive: u64,
    /// The propositions that must not hold.
    pub negative: u64,
}

impl Cube {
    /// The cube with no literals, true everywhere.
    pub const TRUE: Cube = Cube {
        positive: 0,
        negative: 0,
    };

    /// The one-literal cube of the proposition whose bit is `bit`: it holds if `positive`, it
    /// does not otherwise.
    pub fn literal(bit: u64, positive: bool) -> Cube {
        if positive {
            Cube {
                positive: bit,
                negative: 0,
            }
        } else {
            Cube {
                positive: 0,
                negative: bit,
            }
        }
    }

    /// The conjunction of two cubes, or `None` when it is contradictory.
    pub fn and(self, other: Cube) -> Option<Cube> {
        let cube = Cube {
            positive: self.positive | other.positive,
            negative: self.negative | other.negative,
        };
        (cube.positive & cube.negative == 0).then_some(cube)
    }

    /// Whether `letter` satisfies every literal of the cube.
    pub fn evaluate(self, letter: u64) -> bool {
        letter & self.positive == self.positive && letter & self.negative == 0
    }

    /// The propositions the cube mentions.
    pub fn support(self) -> u64 {
        self.positive | self.negative
    }
}

/// A node of a [`Guard`]: branches are `0` (false), `1` (true) or `2 + i` for `nodes[i]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct GuardNode {
    var: u32,
    low: u32,
    high: u32,
}

/// A Boolean function of the propositions, as a canonical BDD: nodes in depth-first post-order
/// from the root (false branch first), the root last. `root` is `0`/`1` for the constants,
/// else `nodes.len() + 1`. The nodes are shared (`None` for the constants): automata have few
/// distinct guards on many edges, and cloning one is a reference count, not a copy.
#[derive(Clone, Default, PartialEq, Eq, Hash)]
pub struct Guard {
    nodes: Option<Arc<[GuardNode]>>,
    root: u32,
}

const NEVER: u32 = 0;
const ALWAYS: u32 = 1;

/// A branch of one of a guard's [`Guard::node_definitions`]: a constant, or the node listed at
/// that index.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Branch {
    Constant(bool),
    Node(usize),
}

impl Guard {
    /// The guard every letter satisfies (`true`).
    pub fn always() -> Guard {
        Guard {
            nodes: None,
            root: ALWAYS,
        }
    }

    /// The guard no letter satisfies (`false`).
    pub fn never() -> Guard {
        Guard {
            nodes: None,
            root: NEVER,
        }
    }

    /// Proposition `proposition` (`< 64`) if `positive`, its negation otherwise.
    pub fn literal(proposition: u32, positive: bool) -> Guard {
        debug_assert!((proposition as usize) < MAX_PROPOSITIONS);
        let (low, high) = if positive {
            (NEVER, ALWAYS)
        } else {
            (ALWAYS, NEVER)
        };
        Guard::from_nodes(
            vec![GuardNode {
                var: proposition,
                low,
                high,
            }],
            2,
        )
    }

    /// The disjunction of `cubes` (contradictory cubes denote nothing).
    pub fn from_cubes(cubes: impl IntoIterator<Item = Cube>) -> Guard {
        let mut bdd = Lease::take();
        let mut union = bdd::FALSE;
        for cube in cubes {
            if cube.positive & cube.negative != 0 {
                continue;
            }
            let term = cube_node(&mut bdd, cube);
            union = bdd.or(union, term);
        }
        Guard::export(&bdd, union)
    }

    fn from_nodes(nodes: Vec<GuardNode>, root: u32) -> Guard {
        Guard {
            nodes: (!nodes.is_empty()).then(|| nodes.into()),
            root,
        }
    }

    fn nodes(&self) -> &[GuardNode] {
        self.nodes.as_deref().unwrap_or_default()
    }

    /// The heap bytes of a guard per node ([`Guard::size`]), for callers that count memory.
    pub(crate) const BYTES_PER_NODE: usize = size_of::<GuardNode>();
    /// The heap bytes of a guard besides its nodes (the shared allocation's counts).
    pub(crate) const BYTES_PER_GUARD: usize = 2 * size_of::<usize>();

    /// The number of BDD nodes (the constants not counted): the guard's size.
    pub fn size(&self) -> usize {
        self.nodes().len()
    }

    /// The guard's nodes, branches before the nodes above them and the root last, as
    /// (proposition, false branch, true branch): for writers that name each node once, so
    /// that the text stays as small as the diagram. Empty for the constants.
    pub(crate) fn node_definitions(&self) -> impl Iterator<Item = (u32, Branch, Branch)> + '_ {
        let branch = |reference: u32| match reference {
            NEVER => Branch::Constant(false),
            ALWAYS => Branch::Constant(true),
            node => Branch::Node(node as usize - 2),
        };
        (self.nodes().iter()).map(move |node| (node.var, branch(node.low), branch(node.high)))
    }

    /// The guard as a manager's node.
    pub(crate) fn import(&self, bdd: &mut Bdd) -> bdd::Node {
        let mut mapped: Vec<bdd::Node> = Vec::with_capacity(self.nodes().len() + 2);
        mapped.extend([bdd::FALSE, bdd::TRUE]);
        for node in self.nodes() {
            let (low, high) = (mapped[node.low as usize], mapped[node.high as usize]);
            mapped.push(bdd.make(node.var, low, high));
        }
        mapped[self.root as usize]
    }

    /// The function of a manager's `node`, whose variables must be propositions (`< 64`).
    pub(crate) fn export(bdd: &Bdd, root: bdd::Node) -> Guard {
        if root <= bdd::TRUE {
            return Guard { nodes: None, root };
        }
        let mut number: NodeMap<u32> = NodeMap::default();
        let mut nodes = Vec::new();
        let reference = |number: &NodeMap<u32>, node: bdd::Node| {
            if node <= bdd::TRUE {
                node
            } else {
                number[&node]
            }
        };
        // Post-order: a node is numbered once both branches are.
        let mut stack = vec![(root, false)];
        while let Some((node, expanded)) = stack.pop() {
            if node <= bdd::TRUE || number.contains_key(&node) {
                continue;
            }
            let (low, high) = bdd.branches(node);
            if expanded {
                let var = bdd.top(node).expect("a non-terminal node");
                debug_assert!((var as usize) < MAX_PROPOSITIONS);
                nodes.push(GuardNode {
                    var,
                    low: reference(&number, low),
                    high: reference(&number, high),
                });
                number.insert(node, nodes.len() as u32 + 1);
            } else {
                stack.push((node, true));
                stack.push((high, false));
                stack.push((low, false));
            }
        }
        let root = nodes.len() as u32 + 1;
        Guard::from_nodes(nodes, root)
    }

    /// `combine` of the two guards, in the thread's spare manager.
    fn apply(
        &self,
        other: &Guard,
        combine: impl FnOnce(&mut Bdd, bdd::Node, bdd::Node) -> bdd::Node,
    ) -> Guard {
        let mut bdd = Lease::take();
        let (f, g) = (self.import(&mut bdd), other.import(&mut bdd));
        let result = combine(&mut bdd, f, g);
        Guard::export(&bdd, result)
    }

    /// An irredundant sum of products of the guard (Minato–Morreale): no cube can be dropped
    /// nor lose a literal. `false` has no cubes, `true` the empty cube alone. There can be
    /// exponentially many in the guard's size (the parity of `n` propositions: 2^(n−1)):
    /// [`Guard::cubes_at_most`] stops early.
    pub fn cubes(&self) -> Vec<Cube> {
        self.cubes_at_most(usize::MAX)
            .expect("no limit on the number of cubes")
    }

    /// [`Guard::cubes`] if there are at most `limit`, else `None`, found after listing at most
    /// `limit + 1` of them.
    pub fn cubes_at_most(&self, limit: usize) -> Option<Vec<Cube>> {
        // A conjunction of literals, or the negation of one (a clause), is its own irredundant
        // cover: most guards are one or the other, and need no manager.
        if let Some(cube) = self.as_cube() {
            return (limit >= 1).then(|| vec![cube]);
        }
        if let Some(Cube { positive, negative }) = self.not().as_cube() {
            let literals = (0..MAX_PROPOSITIONS as u32).filter_map(|var| {
                let bit = 1u64 << var;
                (positive & bit != 0)
                    .then(|| Cube::literal(bit, false))
                    .or((negative & bit != 0).then(|| Cube::literal(bit, true)))
            });
            let cubes: Vec<Cube> = literals.collect();
            return (cubes.len() <= limit).then_some(cubes);
        }
        let mut bdd = Lease::take();
        let f = self.import(&mut bdd);
        let mut cubes = Vec::new();
        isop(&mut bdd, f, f, Cube::TRUE, &mut cubes, limit);
        (cubes.len() <= limit).then_some(cubes)
    }

    /// The guard as one cube, if it is a satisfiable conjunction of literals: a single path to
    /// `true`, every node having `false` as one branch.
    fn as_cube(&self) -> Option<Cube> {
        if self.root == NEVER {
            return None;
        }
        let mut cube = Cube::TRUE;
        let mut at = self.root;
        while at > ALWAYS {
            let node = self.nodes()[at as usize - 2];
            let bit = 1u64 << node.var;
            (cube, at) = match (node.low, node.high) {
                (NEVER, high) => (Cube::literal(bit, true).and(cube)?, high),
                (low, NEVER) => (Cube::literal(bit, false).and(cube)?, low),
                _ => return None,
            };
        }
        Some(cube)
    }

    /// The numerically smallest letter satisfying the guard. Disjoint guards have distinct
    /// smallest letters, so this orders the edges of a state independently of how their guards
    /// were built.
    pub fn smallest_letter(&self) -> Option<u64> {
        // Children come before parents: one pass. A branch's letters only set higher bits.
        let mut smallest: Vec<Option<u64>> = Vec::with_capacity(self.nodes().len() + 2);
        smallest.extend([None, Some(0)]);
        for node in self.nodes() {
            let low = smallest[node.low as usize];
            let high = smallest[node.high as usize].map(|l| l | 1u64 << node.var);
            smallest.push(match (low, high) {
                (Some(x), Some(y)) => Some(x.min(y)),
                (x, y) => x.or(y),
            });
        }
        smallest[self.root as usize]
    }

    /// Calls `f` with every letter over the propositions of `support` (a mask containing the
    /// guard's own) that satisfies the guard, the other propositions false. Recursion one level
    /// per proposition of `support` (at most 64).
    pub(crate) fn for_each_letter(&self, support: u64, mut f: impl FnMut(u64)) {
        debug_assert_eq!(self.support() & !support, 0);
        fn walk(guard: &Guard, at: u32, rest: u64, letter: u64, f: &mut dyn FnMut(u64)) {
            if at == NEVER {
                return;
            }
            if rest == 0 {
                f(letter);
                return;
            }
            let var = rest.trailing_zeros();
            let bit = 1u64 << var;
            let node = (at > ALWAYS).then(|| guard.nodes()[at as usize - 2]);
            let (low, high) = match node {
                Some(node) if node.var == var => (node.low, node.high),
                _ => (at, at),
            };
            walk(guard, low, rest & !bit, letter, f);
            walk(guard, high, rest & !bit, letter | bit, f);
        }
        walk(self, self.root, support, 0, &mut f);
    }

    /// Whether `letter` satisfies the guard. Linear in the number of propositions.
    pub fn evaluate(&self, letter: u64) -> bool {
        let mut at = self.root;
        while at > ALWAYS {
            let node = self.nodes()[at as usize - 2];
            at = if letter & (1u64 << node.var) != 0 {
                node.high
            } else {
                node.low
            };
        }
        at == ALWAYS
    }

    /// The propositions the guard mentions.
    pub fn support(&self) -> u64 {
        self.nodes().iter().fold(0, |acc, n| acc | 1u64 << n.var)
    }

    /// The disjunction of the two guards.
    pub fn or(&self, other: &Guard) -> Guard {
        self.apply(other, Bdd::or)
    }

    /// The conjunction of the two guards.
    pub fn and(&self, other: &Guard) -> Guard {
        self.apply(other, Bdd::and)
    }

    /// The complement: the same diagram with the constants swapped.
    pub fn not(&self) -> Guard {
        let swap = |r: u32| match r {
            NEVER => ALWAYS,
            ALWAYS => NEVER,
            other => other,
        };
        Guard {
            nodes: self.nodes.as_ref().map(|nodes| {
                (nodes.iter())
                    .map(|n| GuardNode {
                        var: n.var,
                        low: swap(n.low),
                        high: swap(n.high),
                    })
                    .collect()
            }),
            root: swap(self.root),
        }
    }

    /// Whether some letter satisfies the guard.
    pub fn is_satisfiable(&self) -> bool {
        self.root != NEVER
    }

    /// Whether every letter satisfies the guard.
    pub fn is_valid(&self) -> bool {
        self.root == ALWAYS
    }

    /// Whether some letter satisfies both guards.
    pub fn intersects(&self, other: &Guard) -> bool {
        let mut bdd = Lease::take();
        let (f, g) = (self.import(&mut bdd), other.import(&mut bdd));
        bdd.and(f, g) != bdd::FALSE
    }

    /// Whether the two guards denote the same Boolean function (guards are canonical: `==`).
    pub fn equivalent(&self, other: &Guard) -> bool {
        self == other
    }

    /// A letter satisfying the guard (the smallest: propositions it need not set are false).
    pub fn witness(&self) -> Option<u64> {
        self.smallest_letter()
    }

    /// The same function with proposition `i` renumbered `positions[i]` (`< 64`), for moving a
    /// guard into another automaton's numbering. Only the entries of propositions the guard
    /// mentions are read.
    pub fn remap(&self, positions: &[u32]) -> Guard {
        let mut bdd = Lease::take();
        let mut mapped: Vec<bdd::Node> = vec![bdd::FALSE, bdd::TRUE];
        for node in self.nodes() {
            let var = bdd.var(positions[node.var as usize]);
            let (low, high) = (mapped[node.low as usize], mapped[node.high as usize]);
            mapped.push(bdd.ite(var, high, low));
        }
        Guard::export(&bdd, mapped[self.root as usize])
    }

    /// The guard as text, cubes joined by ` | `, e.g. `!0&1 | 2` (HOA) or `!a & b | c`.
    pub fn display<'a>(&'a self, style: GuardStyle<'a>) -> GuardDisplay<'a> {
        GuardDisplay { guard: self, style }
    }
}

impl fmt::Debug for Guard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Guard({})", self.display(GuardStyle::Hoa))
    }
}

/// The conjunction of `cube`'s literals in `bdd`.
fn cube_node(bdd: &mut Bdd, cube: Cube) -> bdd::Node {
    let mut node = bdd::TRUE;
    for var in (0..MAX_PROPOSITIONS as u32).rev() {
        let bit = 1u64 << var;
        if cube.positive & bit != 0 {
            node = bdd.make(var, bdd::FALSE, node);
        } else if cube.negative & bit != 0 {
            node = bdd.make(var, node, bdd::FALSE);
        }
    }
    node
}

/// Minato–Morreale: pushes onto `out` (each within `context`) the cubes of an irredundant sum
/// of products of some function between `lower` and `upper` (`lower` ⊆ `upper`), and returns
/// that function. Recursion depth at most one per proposition. Once `out` holds more than
/// `limit` cubes, every call returns at once (and the result means nothing).
fn isop(
    bdd: &mut Bdd,
    lower: bdd::Node,
    upper: bdd::Node,
    context: Cube,
    out: &mut Vec<Cube>,
    limit: usize,
) -> bdd::Node {
    if lower == bdd::FALSE || out.len() > limit {
        return bdd::FALSE;
    }
    if upper == bdd::TRUE {
        out.push(context);
        return bdd::TRUE;
    }
    let var = match (bdd.top(lower), bdd.top(upper)) {
        (Some(x), Some(y)) => x.min(y),
        (x, y) => x.or(y).expect("lower is not false and upper not true"),
    };
    let cofactors = |bdd: &Bdd, node: bdd::Node| match bdd.top(node) {
        Some(v) if v == var => bdd.branches(node),
        _ => (node, node),
    };
    let ((lower0, lower1), (upper0, upper1)) = (cofactors(bdd, lower), cofactors(bdd, upper));
    let bit = 1u64 << var;
    // The cubes that need the literal `var = positive`: the letters of `lower` on that side
    // that the other side's `upper` cannot cover.
    let branch = |bdd: &mut Bdd, out: &mut Vec<Cube>, positive: bool| {
        let (lower, upper, other_upper) = if positive {
            (lower1, upper1, upper0)
        } else {
            (lower0, upper0, upper1)
        };
        let uncovered = bdd.not(other_upper);
        let only = bdd.and(lower, uncovered);
        let context = Cube::literal(bit, positive)
            .and(context)
            .expect("the context does not mention the variable split on");
        isop(bdd, only, upper, context, out, limit)
    };
    let f0 = branch(bdd, out, false);
    let f1 = branch(bdd, out, true);
    let (not_f0, not_f1) = (bdd.not(f0), bdd.not(f1));
    let rest0 = bdd.and(lower0, not_f0);
    let rest1 = bdd.and(lower1, not_f1);
    let rest = bdd.or(rest0, rest1);
    let both = bdd.and(upper0, upper1);
    let shared = isop(bdd, rest, both, context, out, limit);
    let split = bdd.make(var, f0, f1);
    bdd.or(split, shared)
}

thread_local! {
    /// The manager that guard operations lease (see [`Lease`]), kept between them.
    static SPARE: Cell<Option<Bdd>> = const { Cell::new(None) };
}

/// The most nodes a leased manager may have and still be kept for the next operation (about
/// 3 MB with its tables); a larger one is dropped, so memory stays bounded.
const MAX_SPARE_NODES: usize = 1 << 16;

/// A BDD manager lent to one guard operation (or one [`GuardUnion`]) by the thread, and given
/// back when dropped. Guard operations import their operands, combine them and export the
/// result, all canonical whatever else the manager holds; so one manager can serve them all,
/// and its unique table and `ite` cache carry over from operation to operation: the guards of
/// an automaton are few distinct functions, and a fresh manager for each operation (its
/// tables allocated and grown from empty every time) cost most of the time of writing or
/// checking a large automaton. A lease taken while another is out gets a fresh manager.
struct Lease(Option<Bdd>);

impl Lease {
    fn take() -> Lease {
        Lease(Some(SPARE.take().unwrap_or_default()))
    }
}

impl Deref for Lease {
    type Target = Bdd;

    fn deref(&self) -> &Bdd {
        self.0
            .as_ref()
            .expect("a lease holds its manager until dropped")
    }
}

impl DerefMut for Lease {
    fn deref_mut(&mut self) -> &mut Bdd {
        self.0
            .as_mut()
            .expect("a lease holds its manager until dropped")
    }
}

impl Drop for Lease {
    fn drop(&mut self) {
        if let Some(bdd) = self.0.take()
            && bdd.node_count() <= MAX_SPARE_NODES
        {
            SPARE.set(Some(bdd));
        }
    }
}

/// Checks that guards are pairwise disjoint by keeping their union: each [`GuardUnion::insert`]
/// is one conjunction and one disjunction with the union, never a comparison with every guard
/// inserted before.
pub struct GuardUnion {
    bdd: Lease,
    union: bdd::Node,
}

impl Default for GuardUnion {
    fn default() -> Self {
        GuardUnion {
            bdd: Lease::take(),
            union: bdd::FALSE,
        }
    }
}

impl GuardUnion {
    /// An empty union (no letter covered).
    pub fn new() -> GuardUnion {
        GuardUnion::default()
    }

    /// Adds `guard` to the union if it is disjoint from it; `false` (and nothing added) if it
    /// overlaps some guard inserted before.
    pub fn insert(&mut self, guard: &Guard) -> bool {
        let node = guard.import(&mut self.bdd);
        if self.bdd.and(node, self.union) != bdd::FALSE {
            return false;
        }
        self.union = self.bdd.or(node, self.union);
        true
    }

    /// The union of the guards inserted.
    pub fn union(&self) -> Guard {
        Guard::export(&self.bdd, self.union)
    }

    /// Whether the guards inserted cover every letter.
    pub fn is_valid(&self) -> bool {
        self.union == bdd::TRUE
    }
}

/// How [`Guard::display`] writes propositions and constants.
#[derive(Clone, Copy, Debug)]
pub enum GuardStyle<'a> {
    /// HOA label syntax: proposition numbers, `&` without spaces, constants `t` and `f`.
    Hoa,
    /// Proposition names (quoted unless they are plain identifiers), ` & `, `true` and `false`.
    Names(&'a [String]),
}

/// A guard formatted in a [`GuardStyle`]; a valid guard prints as the constant true.
pub struct GuardDisplay<'a> {
    guard: &'a Guard,
    style: GuardStyle<'a>,
}

impl fmt::Display for GuardDisplay<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (truth, falsity) = match self.style {
            GuardStyle::Hoa => ("t", "f"),
            GuardStyle::Names(_) => ("true", "false"),
        };
        if !self.guard.is_satisfiable() {
            return f.write_str(falsity);
        }
        if self.guard.is_valid() {
            return f.write_str(truth);
        }
        write_cubes(f, &self.guard.cubes(), self.style)
    }
}

/// Writes `cubes` (at least one, none empty) joined by ` | `, each as its literals joined by
/// `&`, in `style`: the text of [`Guard::display`] when they are the guard's cubes.
pub(crate) fn write_cubes(
    f: &mut impl fmt::Write,
    cubes: &[Cube],
    style: GuardStyle<'_>,
) -> fmt::Result {
    let and = match style {
        GuardStyle::Hoa => "&",
        GuardStyle::Names(_) => " & ",
    };
    for (i, cube) in cubes.iter().enumerate() {
        if i > 0 {
            f.write_str(" | ")?;
        }
        let literals = (0..MAX_PROPOSITIONS as u32).filter(|&p| cube.support() & (1u64 << p) != 0);
        for (j, proposition) in literals.enumerate() {
            if j > 0 {
                f.write_str(and)?;
            }
            if cube.negative & (1u64 << proposition) != 0 {
                f.write_str("!")?;
            }
            match style {
                GuardStyle::Hoa => write!(f, "{proposition}")?,
                GuardStyle::Names(names) => write_name(f, &names[proposition as usize])?,
            }
        }
    }
    Ok(())
}

/// Writes a proposition name, double-quoted unless it is a plain identifier that cannot be
/// mistaken for a constant.
fn write_name(f: &mut impl fmt::Write, name: &str) -> fmt::Result {
    let plain = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !matches!(name, "true" | "false");
    if plain {
        f.write_str(name)
    } else {
        f.write_str(&quoted(name))
    }
}

/// `text` as a C-like double-quoted string (`"` and `\` escaped by `\`), the string syntax of
/// HOA, DOT and Spot's atomic propositions.
pub fn quoted(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('"');
    for c in text.chars() {
        if matches!(c, '"' | '\\') {
            out.push('\\');
        }
        out.push(c);
    }
    out.push('"');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every letter over the first `n` propositions.
    fn letters(n: u32) -> impl Iterator<Item = u64> {
        0..(1u64 << n)
    }

    fn truth_table(guard: &Guard, n: u32) -> Vec<bool> {
        letters(n).map(|l| guard.evaluate(l)).collect()
    }

    #[test]
    fn connectives_match_their_truth_tables() {
        let a = Guard::literal(0, true);
        let b = Guard::literal(1, true);
        let not_c = Guard::literal(2, false);
        let f = a.and(&b).or(&not_c); // (a & b) | !c
        for letter in letters(3) {
            let (va, vb, vc) = (letter & 1 != 0, letter & 2 != 0, letter & 4 != 0);
            assert_eq!(f.evaluate(letter), (va && vb) || !vc);
            assert_eq!(f.not().evaluate(letter), !((va && vb) || !vc));
        }
        assert!(f.or(&f.not()).is_valid());
        assert!(!f.intersects(&f.not()));
        assert!(!f.is_valid());
        assert!(Guard::always().is_valid());
        assert!(!Guard::never().is_satisfiable());
        assert!(Guard::never().not().is_valid());
        assert!(Guard::always().not().cubes().is_empty());
    }

    #[test]
    fn cube_covers_are_irredundant_and_keep_the_function() {
        let (a, b, c) = (
            Guard::literal(0, true),
            Guard::literal(1, true),
            Guard::literal(2, true),
        );
        let cube = |positive: u64, negative: u64| Cube { positive, negative };
        // a & b | a & !b is a: one cube, one literal.
        let split = a.and(&b).or(&a.and(&b.not()));
        assert_eq!(split.cubes(), [cube(1, 0)]);
        // a | !a & b is a | b.
        let mut cover = a.or(&a.not().and(&b)).cubes();
        cover.sort();
        assert_eq!(cover, [cube(1, 0), cube(2, 0)]);
        // The eight full cubes over a, b, c are `true`: the empty cube.
        let everything = Guard::from_cubes((0..8u64).map(|l| cube(l, !l & 7)));
        assert_eq!(everything, Guard::always());
        assert_eq!(everything.cubes(), [Cube::TRUE]);
        assert!(Guard::never().cubes().is_empty());
        // A function with no shorter form keeps its truth table.
        let parity = a.and(&b.not()).or(&a.not().and(&b)).and(&c);
        let cover = Guard::from_cubes(parity.cubes());
        assert_eq!(truth_table(&cover, 3), truth_table(&parity, 3));
        assert_eq!(parity.cubes().len(), 2);
        assert_eq!(parity.smallest_letter(), Some(0b101));
        assert_eq!(Guard::never().smallest_letter(), None);
        // `(0|1) & (2|3) & ... & (30|31)`: 2^16 cubes, but 32 nodes.
        let pairs = (0..16).fold(Guard::always(), |acc, i| {
            acc.and(&Guard::literal(2 * i, true).or(&Guard::literal(2 * i + 1, true)))
        });
        assert_eq!(pairs.size(), 32);
        assert_eq!(pairs.smallest_letter(), Some(0x5555_5555));
    }

    #[test]
    fn a_union_detects_overlap_without_comparing_pairs() {
        let mut union = GuardUnion::new();
        for letter in 0..16u64 {
            assert!(union.insert(&Guard::from_cubes([Cube {
                positive: letter,
                negative: !letter & 15,
            }])));
            assert_eq!(union.is_valid(), letter == 15);
        }
        assert!(!union.insert(&Guard::literal(3, true)));
        assert_eq!(union.union(), Guard::always());
    }

    #[test]
    fn complement_follows_the_truth_table() {
        let conj = Guard::literal(0, true)
            .and(&Guard::literal(1, true))
            .and(&Guard::literal(2, true));
        let complement = conj.not();
        assert_eq!(complement.cubes().len(), 3);
        assert_eq!(
            truth_table(&complement, 3),
            truth_table(&conj, 3).iter().map(|v| !v).collect::<Vec<_>>()
        );
    }

    #[test]
    fn equality_is_semantic() {
        let a = Guard::literal(0, true);
        let ab = a.and(&Guard::literal(1, true));
        assert_eq!(a.or(&ab), a);
        // a&b | a&!b is a, built differently.
        let split = ab.or(&a.and(&Guard::literal(1, false)));
        assert_eq!(split, a);
        assert!(split.equivalent(&a));
        assert_eq!(a.witness(), Some(1));
        assert!(a.evaluate(a.witness().unwrap()));
        assert_eq!(a.not().not(), a);
    }

    #[test]
    fn remapping_moves_propositions() {
        // (a & !b) | c over [a, b, c], moved to positions [3, 0, 5].
        let f = Guard::literal(0, true)
            .and(&Guard::literal(1, false))
            .or(&Guard::literal(2, true));
        let moved = f.remap(&[3, 0, 5]);
        for letter in letters(6) {
            let bit = |i: u32| letter & (1 << i) != 0;
            assert_eq!(moved.evaluate(letter), (bit(3) && !bit(0)) || bit(5));
        }
    }

    #[test]
    fn guards_print_in_hoa_and_named_styles() {
        let names: Vec<String> = ["a", "b c", "true"].map(String::from).to_vec();
        let f = Guard::literal(0, false)
            .and(&Guard::literal(1, true))
            .or(&Guard::literal(2, true));
        assert_eq!(f.display(GuardStyle::Hoa).to_string(), "!0&1 | 2");
        assert_eq!(
            f.display(GuardStyle::Names(&names)).to_string(),
            "!a & \"b c\" | \"true\""
        );
        // A valid guard prints as the constant, however it is split into cubes.
        let split = Guard::literal(0, true).or(&Guard::literal(0, false));
        assert_eq!(split.display(GuardStyle::Hoa).to_string(), "t");
        assert_eq!(split.display(GuardStyle::Names(&names)).to_string(), "true");
        assert_eq!(Guard::never().display(GuardStyle::Hoa).to_string(), "f");
    }
}
