//! A small reduced ordered binary decision diagram (BDD) package: the canonical form of the
//! built-in translation's states and the engine behind [`crate::automata::Guard`]'s operations.
//!
//! Nodes live in one arena and are hash-consed, so two nodes are equal iff they denote the same
//! Boolean function: comparing functions is comparing `u32`s. Variables are ordered by their
//! number. The unique table is an open-addressing table of node numbers (4 bytes a slot, with a
//! cheap multiplicative hash); `ite` results are memoised in a direct-mapped, lossy cache whose size follows the
//! number of nodes (at most [`MAX_CACHE_SLOTS`]), as in CUDD and BuDDy: memory stays
//! proportional to the diagrams kept, not to the operations performed. Operations use explicit
//! stacks, not recursion, so deep diagrams cannot overflow the call stack.
//!
//! Costs: `ite(f, g, h)` is O(|f|·|g|·|h|) at worst, usually near |f| + |g| + |h| with the
//! cache; `compose` one `ite` per node of `f`, memoised across calls by the caller's map.
//! [`Bdd::with_limits`] bounds the work (counted `ite` steps) and the number of nodes,
//! [`Bdd::set_max_bytes`] the bytes of its arrays (checked before they grow, so never exceeded)
//! and [`Bdd::set_deadline`] the wall-clock time (read every few thousand steps); past any
//! bound the manager is *exhausted*: every further operation returns [`FALSE`] at once, and the
//! caller, which checks [`Bdd::exhausted`] after each unit of work, reports the limit.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use crate::limits::{Clock, Deadline};

/// A node of a [`Bdd`]: a Boolean function.
pub type Node = u32;

pub const FALSE: Node = 0;
pub const TRUE: Node = 1;

/// The variable of the two terminal nodes: after every real variable.
const TERMINAL: u32 = u32::MAX;

/// The largest number of slots of the `ite` cache (16 bytes each).
pub const MAX_CACHE_SLOTS: usize = 1 << 22;
const MIN_CACHE_SLOTS: usize = 1 << 5;
const MIN_UNIQUE_SLOTS: usize = 1 << 4;

#[derive(Clone, Copy)]
struct Entry {
    var: u32,
    low: Node,
    high: Node,
}

/// One slot of the `ite` cache; `f == FALSE` marks an empty slot (no cached call has a
/// constant condition).
#[derive(Clone, Copy)]
struct CacheSlot {
    f: Node,
    g: Node,
    h: Node,
    result: Node,
}

const EMPTY_SLOT: CacheSlot = CacheSlot {
    f: FALSE,
    g: FALSE,
    h: FALSE,
    result: FALSE,
};

/// Which bound was reached: of [`Bdd::with_limits`], [`Bdd::set_max_bytes`] or
/// [`Bdd::set_deadline`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exhausted {
    Steps(u64),
    Nodes(usize),
    Bytes(u64),
    Time,
}

impl Default for Bdd {
    fn default() -> Self {
        Bdd::new()
    }
}

/// A pending step of [`Bdd::ite`].
enum Task {
    Call(Node, Node, Node),
    /// Combine the two results on top of the stack into a node on `var`.
    Join((Node, Node, Node), u32),
}

pub struct Bdd {
    nodes: Vec<Entry>,
    tasks: Vec<Task>,
    results: Vec<Node>,
    /// The unique table: node numbers by open addressing (linear probing, `FALSE` marks an
    /// empty slot), a power of two at most half full. It stores 4 bytes per slot and reads
    /// the nodes' own entries to compare, where a hash map stored the key beside the value.
    unique: Vec<Node>,
    cache: Vec<CacheSlot>,
    steps: u64,
    max_steps: u64,
    max_nodes: usize,
    max_bytes: u64,
    clock: Clock,
    exhausted: Option<Exhausted>,
}

impl Bdd {
    /// A manager without limits.
    pub fn new() -> Bdd {
        Bdd::with_limits(u64::MAX, usize::MAX)
    }

    /// A manager that gives up after `max_steps` `ite` steps or past `max_nodes` nodes.
    pub fn with_limits(max_steps: u64, max_nodes: usize) -> Bdd {
        let terminal = Entry {
            var: TERMINAL,
            low: FALSE,
            high: FALSE,
        };
        Bdd {
            nodes: vec![terminal; 2],
            tasks: Vec::new(),
            results: Vec::new(),
            unique: vec![FALSE; MIN_UNIQUE_SLOTS],
            cache: vec![EMPTY_SLOT; MIN_CACHE_SLOTS],
            steps: 0,
            max_steps,
            max_nodes,
            max_bytes: u64::MAX,
            clock: Clock::new(Deadline::NONE),
            exhausted: None,
        }
    }

    /// Stops the manager before its arrays would grow past `bytes` in all ([`Bdd::bytes`]).
    pub fn set_max_bytes(&mut self, bytes: u64) {
        self.max_bytes = bytes;
    }

    /// Stops the manager once `deadline` has passed (noticed within a few thousand steps).
    pub fn set_deadline(&mut self, deadline: Deadline) {
        self.clock = Clock::new(deadline);
    }

    /// The bytes the manager's arrays hold (allocated, not only used): nodes, unique table,
    /// cache and the `ite` stacks.
    pub fn bytes(&self) -> u64 {
        (self.nodes.capacity() * size_of::<Entry>()
            + self.unique.len() * size_of::<Node>()
            + self.cache.len() * size_of::<CacheSlot>()
            + self.tasks.capacity() * size_of::<Task>()
            + self.results.capacity() * size_of::<Node>()) as u64
    }

    /// The most [`Bdd::bytes`] can reach before the node array grows again: it doubles, the
    /// unique table (at most half full) doubles within as many new nodes, and so does the
    /// cache below its largest size.
    fn bytes_after_growth(&self) -> u64 {
        let cache_growth = if self.cache.len() < MAX_CACHE_SLOTS {
            self.cache.len() * size_of::<CacheSlot>()
        } else {
            0
        };
        self.bytes()
            + (self.nodes.capacity().max(1) * size_of::<Entry>()
                + self.unique.len() * size_of::<Node>()
                + cache_growth) as u64
    }

    /// The steps counted so far (by `ite` and [`Bdd::charge`]).
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The number of nodes, the two constants included.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The limit reached, if any; the results of operations since then are meaningless.
    pub fn exhausted(&self) -> Option<Exhausted> {
        self.exhausted
    }

    /// Counts `steps` steps of work done outside `ite` (walks over diagrams), so that the step
    /// limit bounds them too.
    pub fn charge(&mut self, steps: u64) {
        self.steps = self.steps.saturating_add(steps);
        if self.steps > self.max_steps {
            self.exhausted
                .get_or_insert(Exhausted::Steps(self.max_steps));
        }
        if self.clock.tick(steps) {
            self.exhausted.get_or_insert(Exhausted::Time);
        }
    }

    /// The function that is true iff variable `var` is.
    pub fn var(&mut self, var: u32) -> Node {
        self.make(var, FALSE, TRUE)
    }

    /// The variable `node` tests first, `None` for the constants.
    pub fn top(&self, node: Node) -> Option<u32> {
        let var = self.nodes[node as usize].var;
        (var != TERMINAL).then_some(var)
    }

    /// The cofactors of a non-terminal `node` on its top variable: (false branch, true branch).
    pub fn branches(&self, node: Node) -> (Node, Node) {
        let entry = self.nodes[node as usize];
        (entry.low, entry.high)
    }

    pub fn and(&mut self, f: Node, g: Node) -> Node {
        self.ite(f, g, FALSE)
    }

    pub fn or(&mut self, f: Node, g: Node) -> Node {
        self.ite(f, TRUE, g)
    }

    pub fn not(&mut self, f: Node) -> Node {
        self.ite(f, FALSE, TRUE)
    }

    /// If `f` then `g` else `h`. Iterative (an explicit stack instead of recursion), so that
    /// diagrams over very many variables cannot overflow the call stack.
    pub fn ite(&mut self, f: Node, g: Node, h: Node) -> Node {
        if let Some(result) = self.ite_shortcut(f, g, h) {
            return result;
        }
        // The stacks are reused from call to call: most calls are small, and allocating them
        // every time dominated the cost.
        let mut tasks = std::mem::take(&mut self.tasks);
        let mut results = std::mem::take(&mut self.results);
        tasks.push(Task::Call(f, g, h));
        while let Some(task) = tasks.pop() {
            match task {
                Task::Call(f, g, h) => {
                    if let Some(result) = self.ite_shortcut(f, g, h) {
                        results.push(result);
                        continue;
                    }
                    self.steps += 1;
                    if self.steps > self.max_steps {
                        self.exhausted
                            .get_or_insert(Exhausted::Steps(self.max_steps));
                    }
                    if self.clock.tick(1) {
                        self.exhausted.get_or_insert(Exhausted::Time);
                    }
                    if self.exhausted.is_some() {
                        results.push(FALSE);
                        continue;
                    }
                    let var = [f, g, h]
                        .iter()
                        .map(|&n| self.nodes[n as usize].var)
                        .min()
                        .unwrap_or(TERMINAL);
                    let (f0, f1) = self.cofactors(f, var);
                    let (g0, g1) = self.cofactors(g, var);
                    let (h0, h1) = self.cofactors(h, var);
                    tasks.push(Task::Join((f, g, h), var));
                    tasks.push(Task::Call(f1, g1, h1));
                    tasks.push(Task::Call(f0, g0, h0));
                }
                Task::Join((f, g, h), var) => {
                    let high = results.pop().expect("the true branch was computed");
                    let low = results.pop().expect("the false branch was computed");
                    let result = self.make(var, low, high);
                    let slot = self.slot(f, g, h);
                    self.cache[slot] = CacheSlot { f, g, h, result };
                    results.push(result);
                }
            }
        }
        let result = results.pop().expect("the call computed its result");
        self.tasks = tasks;
        self.results = results;
        result
    }

    fn slot(&self, f: Node, g: Node, h: Node) -> usize {
        let mut hasher = NodeHasher::default();
        hasher.write_u32(f);
        hasher.write_u32(g);
        hasher.write_u32(h);
        (hasher.finish() >> 32) as usize & (self.cache.len() - 1)
    }

    /// The result of `ite(f, g, h)` when a terminal case or the cache gives it at once.
    fn ite_shortcut(&self, f: Node, g: Node, h: Node) -> Option<Node> {
        match (f, g, h) {
            (TRUE, _, _) => Some(g),
            (FALSE, _, _) => Some(h),
            _ if g == h => Some(g),
            (_, TRUE, FALSE) => Some(f),
            _ => {
                let slot = self.cache[self.slot(f, g, h)];
                (slot.f == f && slot.g == g && slot.h == h).then_some(slot.result)
            }
        }
    }

    /// `f` with every variable `v` replaced by the function `substitute(v)` (all variables at
    /// once), iteratively like [`Bdd::ite`]. `memo` remembers the result for every node
    /// composed: callers that compose many functions with the same substitution keep it
    /// between calls, so shared subdiagrams are composed once.
    pub fn compose(
        &mut self,
        f: Node,
        mut substitute: impl FnMut(u32) -> Node,
        memo: &mut NodeMap<Node>,
    ) -> Node {
        enum Task {
            Call(Node),
            Join(Node),
        }
        let mut tasks = vec![Task::Call(f)];
        let mut results: Vec<Node> = Vec::new();
        while let Some(task) = tasks.pop() {
            match task {
                Task::Call(node) => {
                    if node <= TRUE {
                        results.push(node);
                    } else if let Some(&result) = memo.get(&node) {
                        results.push(result);
                    } else {
                        let entry = self.nodes[node as usize];
                        tasks.push(Task::Join(node));
                        tasks.push(Task::Call(entry.high));
                        tasks.push(Task::Call(entry.low));
                    }
                }
                Task::Join(node) => {
                    let high = results.pop().expect("the true branch was composed");
                    let low = results.pop().expect("the false branch was composed");
                    let replacement = substitute(self.nodes[node as usize].var);
                    let result = self.ite(replacement, high, low);
                    if self.exhausted.is_none() {
                        memo.insert(node, result);
                    }
                    results.push(result);
                }
            }
        }
        results.pop().expect("the call composed its result")
    }

    /// Doubles the unique table and puts every node back.
    fn grow_unique(&mut self) {
        let size = 2 * self.unique.len();
        let mask = size - 1;
        let mut unique = vec![FALSE; size];
        for (node, entry) in self.nodes.iter().enumerate().skip(2) {
            let mut slot = unique_hash(entry.var, entry.low, entry.high) & mask;
            while unique[slot] != FALSE {
                slot = (slot + 1) & mask;
            }
            unique[slot] = node as Node;
        }
        self.unique = unique;
    }

    /// The cofactors of `node` on `var`, which is at or above its top variable.
    fn cofactors(&self, node: Node, var: u32) -> (Node, Node) {
        let entry = self.nodes[node as usize];
        if entry.var == var {
            (entry.low, entry.high)
        } else {
            (node, node)
        }
    }

    /// The node testing `var` (above the variables of `low` and `high`) with these branches.
    pub fn make(&mut self, var: u32, low: Node, high: Node) -> Node {
        if low == high {
            return low;
        }
        let mask = self.unique.len() - 1;
        let mut slot = unique_hash(var, low, high) & mask;
        loop {
            let node = self.unique[slot];
            if node == FALSE {
                break;
            }
            let entry = self.nodes[node as usize];
            if entry.var == var && entry.low == low && entry.high == high {
                return node;
            }
            slot = (slot + 1) & mask;
        }
        if self.nodes.len() >= self.max_nodes {
            self.exhausted
                .get_or_insert(Exhausted::Nodes(self.max_nodes));
            return FALSE;
        }
        if self.nodes.len() == self.nodes.capacity() && self.bytes_after_growth() > self.max_bytes {
            self.exhausted
                .get_or_insert(Exhausted::Bytes(self.max_bytes));
            return FALSE;
        }
        let next = self.nodes.len() as Node;
        self.unique[slot] = next;
        self.nodes.push(Entry { var, low, high });
        if 2 * self.nodes.len() > self.unique.len() {
            self.grow_unique();
        }
        if self.nodes.len() > self.cache.len() / 2 && self.cache.len() < MAX_CACHE_SLOTS {
            // Keep the cache about as large as the diagram; resizing forgets it.
            self.cache = vec![EMPTY_SLOT; 2 * self.cache.len()];
        }
        next
    }
}

/// The unique table's hash of a node.
fn unique_hash(var: u32, low: Node, high: Node) -> usize {
    let mut hasher = NodeHasher::default();
    hasher.write_u32(var);
    hasher.write_u32(low);
    hasher.write_u32(high);
    (hasher.finish() >> 32) as usize
}

/// A map to nodes (or, as `NodeMap<u32>` keyed by nodes, from them), with the cheap hasher.
pub type NodeMap<K> = HashMap<K, Node, BuildHasherDefault<NodeHasher>>;

/// A multiplicative hash for keys made of a few `u32`s (the default SipHash guards against
/// adversarial keys, which node numbers are not, at several times the cost).
#[derive(Default)]
pub struct NodeHasher(u64);

impl Hasher for NodeHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            self.write_u32(u32::from(byte));
        }
    }

    fn write_u32(&mut self, value: u32) {
        self.0 = (self.0.rotate_left(5) ^ u64::from(value)).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The truth table of `f` over variables `0..n`, by walking the diagram.
    fn truth_table(bdd: &Bdd, f: Node, n: u32) -> Vec<bool> {
        (0..1u32 << n)
            .map(|assignment| {
                let mut node = f;
                while let Some(var) = bdd.top(node) {
                    let (low, high) = bdd.branches(node);
                    node = if assignment & (1 << var) != 0 {
                        high
                    } else {
                        low
                    };
                }
                node == TRUE
            })
            .collect()
    }

    #[test]
    fn operations_follow_truth_tables_and_equal_functions_share_a_node() {
        let mut bdd = Bdd::new();
        let (a, b, c) = (bdd.var(0), bdd.var(1), bdd.var(2));
        let ab = bdd.and(a, b);
        let f = bdd.or(ab, c); // a & b | c
        let table = truth_table(&bdd, f, 3);
        for (assignment, value) in table.iter().enumerate() {
            let bit = |i: usize| assignment & (1 << i) != 0;
            assert_eq!(*value, (bit(0) && bit(1)) || bit(2));
        }
        // De Morgan, built another way, gives the very same node.
        let (na, nb, nc) = (bdd.not(a), bdd.not(b), bdd.not(c));
        let nab = bdd.or(na, nb);
        let g = bdd.and(nab, nc);
        assert_eq!(bdd.not(g), f);
        let excluded_middle = bdd.or(a, na);
        assert_eq!(excluded_middle, TRUE);
        assert_eq!(bdd.and(a, na), FALSE);
        assert_eq!(bdd.top(f), Some(0));
        assert_eq!(bdd.top(TRUE), None);
    }
}
