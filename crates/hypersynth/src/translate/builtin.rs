//! The built-in translation: co-safe LTL to the minimal complete DFA of its good prefixes, by
//! formula progression with states kept canonical as BDDs.
//!
//! The formula's subformulas become hash-consed *terms* (operands of `&` and `|` sorted and
//! deduplicated, constants absorbed, double negations removed). Each term `t` has a BDD
//! variable, read as "`t` holds from here on", and an *unfolding*: a Boolean function of the
//! current letter's propositions and of the variables of the terms that must hold from the next
//! step, by the expansion laws
//! - `X p` = next(p);
//! - `p U q` = `p W q` = q | (p & next(itself)), with `F q` = `true U q`;
//! - `p M q` = `p R q` = q & (p | next(itself)), with `G q` = `false R q`;
//! - `!`, `&`, `|`, `->`, `<->`, `xor` unfold to the same connective of the unfoldings.
//!
//! So negations need not be pushed to the atoms first, and `<->` costs no duplication.
//!
//! A state is a Boolean function of term variables. One step of a state is its composition with
//! every variable's unfolding. In the BDD variable order the propositions (numbers `0..aps`)
//! come before the term variables, so the composed diagram first branches on the letter and
//! then reaches the successors: each path through the proposition levels is a cube of letters,
//! the node where it leaves them the successor state. Guards therefore split only on the
//! propositions a state's unfolding depends on, never on all 2^AP letters, and letters with
//! equal successors share one guard.
//!
//! Among themselves the term variables are ordered by how long their obligations tend to last,
//! the shortest first ([`TermVariables`]): an obligation `X^k p` lives `k` steps, so the
//! operands of `X` and other terms come first, in increasing term number (`X p` before
//! `X X p`); `U` and `M` obligations can last for ever and come last, from the root down (in
//! `a U (b U c)` the inner obligation outlives the outer one, which hands over to it). States
//! then differ from their predecessors near the top of their diagrams and share the lower
//! parts, so the composition memo kept across states composes each shared part once. With
//! operands first throughout, the `U` chain `a0 U a1 U … U a4 U a0 …` has states
//! `v_j | v_{j+5} | …` over ranges of the chain that share nothing, and every state recomposed
//! its whole diagram: 1000 operands took 32 s instead of 0.05 s. With the root first
//! throughout, the issue's `!a M ((a & !c & !X^18(!c & d)) U !b)` puts its two lasting
//! obligations above the sliding window of `X` terms and needs 40% more nodes.
//!
//! Acceptance: a word satisfies a co-safe formula iff its run reaches the state `true` (every
//! eventuality met; `U` and `W` differ only in this, and they share a term because co-safety
//! allows `U` only positively and `W` only negated, where `!v` is the strong `!p M !q`; the
//! same goes for `M` and `R`). A prefix is good iff every continuation of its run reaches
//! `true`, which includes valid states other than `true` itself (`a & X(F b | F !b)` after
//! `a`): a state is final iff it is in the least fixpoint of "is `true`, or has only such
//! successors". Final states are absorbing, since successors of valid states are valid.
//!
//! BDDs are canonical, so two states are equal iff they are the same Boolean function of the
//! term variables, and the states are finitely many. Different functions may still have the
//! same language: [`minimize`] merges them and numbers the result canonically.
//!
//! Nothing here recurses on the depth of the formula: terms are built by the formula's
//! iterative fold, unfoldings in term order (a term's operands have smaller numbers), and the
//! BDD operations use explicit stacks.

use std::collections::HashMap;
use std::hash::BuildHasherDefault;
use std::time::Instant;

use bit_set::BitSet;

use super::{Limit, LimitError, Phase, Progress, TranslateError, Translator};
use crate::automata::minimize_within;
use crate::automata::{Dfa, DfaState, Guard, MAX_PROPOSITIONS};
use crate::bdd::{self, Bdd, Exhausted, Node, NodeHasher, NodeMap};
use crate::csr::Csr;
use crate::limits::{Deadline, Stop, Work};
use crate::ltl::{self, BinaryOp, Formula, FormulaKind, NaryOp, Span, UnaryOp};

/// Bounds on a translation, so that no formula makes it run for minutes or exhaust memory.
///
/// Every limit but the deadline is counted: a translation that succeeds under them once
/// succeeds every time on every machine (tests and the fuzzers use only those). The deadline is
/// wall-clock time, checked throughout (unfolding, exploration, minimisation; Spot's process
/// is killed at it), so a translation stops at about the deadline whatever the formula, but
/// near it the outcome depends on the machine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TranslationLimits {
    /// The most states the DFA may have before minimisation (Spot: after reading its output).
    pub max_states: usize,
    /// The most BDD nodes (states and guards together; about 40 bytes each in all).
    pub max_nodes: usize,
    /// The most edges of the DFA before minimisation (one per state and successor; a state of
    /// `F p1 & … & F pn` has 2^n).
    pub max_edges: usize,
    /// The most work, counted: BDD steps (`ite` calls that neither a terminal case nor the
    /// cache answers), nodes walked over, and the minimiser's units (a state or table entry
    /// visited).
    pub max_steps: u64,
    /// The most bytes the translation may hold, as it counts them from its sizes (the BDD
    /// manager's arrays, states, edges, guards, the DFA and the minimiser's tables): counted
    /// too, and checked before the large arrays grow.
    pub max_bytes: u64,
    /// When the translation stops, whatever the counts.
    pub deadline: Deadline,
}

/// The default state limit, 2^20.
pub const DEFAULT_MAX_STATES: usize = 1 << 20;

/// The default work limit: 1.2 × 10^9 steps, between 20 s and a minute of a release build.
pub const DEFAULT_MAX_STEPS: u64 = 1_200_000_000;

impl TranslationLimits {
    /// `max_states` states, 8 BDD nodes and 4 edges per state allowed, `max_steps` steps, no
    /// limit on bytes (beyond what the nodes and edges imply) and no deadline.
    pub fn new(max_states: usize, max_steps: u64) -> TranslationLimits {
        TranslationLimits {
            max_states,
            max_nodes: max_states.saturating_mul(8),
            max_edges: max_states.saturating_mul(4),
            max_steps,
            max_bytes: u64::MAX,
            deadline: Deadline::NONE,
        }
    }

    /// The same limits with the deadline `deadline`.
    pub fn with_deadline(self, deadline: Deadline) -> TranslationLimits {
        TranslationLimits { deadline, ..self }
    }

    /// The same limits with at most `bytes` bytes.
    pub fn with_max_bytes(self, bytes: u64) -> TranslationLimits {
        TranslationLimits {
            max_bytes: bytes,
            ..self
        }
    }
}

impl Default for TranslationLimits {
    /// 2^20 states, 2^23 nodes, 2^22 edges, `DEFAULT_MAX_STEPS` steps, no byte limit or deadline.
    fn default() -> Self {
        TranslationLimits::new(DEFAULT_MAX_STATES, DEFAULT_MAX_STEPS)
    }
}

/// The built-in translation.
#[derive(Clone, Copy, Debug, Default)]
pub struct Builtin {
    limits: TranslationLimits,
}

impl Builtin {
    /// The built-in translation under `limits`.
    pub fn new(limits: TranslationLimits) -> Builtin {
        Builtin { limits }
    }
}

impl Translator for Builtin {
    fn name(&self) -> &str {
        "builtin"
    }

    fn translate(&self, formula: &Formula) -> Result<Dfa, TranslateError> {
        let started = Instant::now();
        ltl::check_co_safe(formula)?;
        let aps = ltl::atomic_propositions(formula);
        if aps.len() > MAX_PROPOSITIONS {
            return Err(TranslateError::TooManyPropositions(aps.len()));
        }
        let mut terms = Terms::default();
        let root = terms.build(formula, &aps);
        let (dfa, steps) =
            explore(aps, &terms, root, self.limits, started).map_err(TranslateError::Limit)?;
        let mut work = Work::new(
            self.limits.max_steps.saturating_sub(steps),
            self.limits.deadline,
        );
        minimize_within(&dfa, &mut work, self.limits.max_bytes)
            .map_err(|stop| minimising_stopped(stop, &dfa, self.limits, started).into())
    }
}

/// The error of a minimisation of `dfa` stopped by `stop`.
pub(super) fn minimising_stopped(
    stop: Stop,
    dfa: &Dfa,
    limits: TranslationLimits,
    started: Instant,
) -> LimitError {
    LimitError {
        limit: match stop {
            Stop::Count => Limit::Steps(limits.max_steps),
            Stop::Bytes => Limit::Bytes(limits.max_bytes),
            Stop::Time => Limit::Time(started.elapsed()),
        },
        span: None,
        phase: Phase::Minimising,
        progress: Progress {
            found: dfa.num_states(),
            explored: dfa.num_states(),
            edges: dfa.num_edges(),
            ..Progress::default()
        },
        limits,
        note: None,
    }
}

/// A hash-consed subformula. Operators that unfold alike share a term: `U` and `W` (and `F`,
/// which is `true U p`) unfold to `q | (p & next)`, `M` and `R` (and `G`, which is `false R p`)
/// to `q & (p | next)`. They differ only in whether the eventuality must be met, and that is
/// decided by acceptance (reaching the state `true`), which reads every eventuality strongly:
/// right for co-safe formulas, where `U`, `F`, `M` occur only positively and `W`, `G`, `R` only
/// negated (`!(p W q)` is `!p M !q`, and `!v` for the shared term's variable `v` means just
/// that).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Term {
    Const(bool),
    /// Proposition number.
    Proposition(u32),
    Not(TermId),
    Next(TermId),
    Until(TermId, TermId),
    StrongRelease(TermId, TermId),
    /// Sorted operands.
    Equiv(TermId, TermId),
    /// Two or more operands, sorted, without duplicates.
    And(Vec<TermId>),
    Or(Vec<TermId>),
}

type TermId = u32;

/// The terms of one formula, numbered so that a term's operands come before it.
#[derive(Default)]
struct Terms {
    terms: Vec<Term>,
    /// `spans[t]`: where in the formula term `t` comes from, for locating errors.
    spans: Vec<Span>,
    numbers: HashMap<Term, TermId>,
}

impl Terms {
    fn intern(&mut self, term: Term) -> TermId {
        if let Some(&id) = self.numbers.get(&term) {
            return id;
        }
        let id = self.terms.len() as TermId;
        self.terms.push(term.clone());
        self.numbers.insert(term, id);
        id
    }

    fn negation(&mut self, id: TermId) -> TermId {
        match self.terms[id as usize] {
            Term::Not(inner) => inner,
            Term::Const(value) => self.intern(Term::Const(!value)),
            _ => self.intern(Term::Not(id)),
        }
    }

    /// `&` or `|` of `operands`, flattened, sorted and deduplicated, with constants absorbed.
    fn junction(&mut self, op: NaryOp, operands: Vec<TermId>) -> TermId {
        let neutral = op.identity();
        let mut flat = Vec::with_capacity(operands.len());
        for id in operands {
            match &self.terms[id as usize] {
                Term::Const(value) if *value == neutral => {}
                Term::Const(_) => return self.intern(Term::Const(!neutral)),
                Term::And(inner) if op == NaryOp::And => flat.extend_from_slice(inner),
                Term::Or(inner) if op == NaryOp::Or => flat.extend_from_slice(inner),
                _ => flat.push(id),
            }
        }
        flat.sort_unstable();
        flat.dedup();
        match flat.len() {
            0 => self.intern(Term::Const(neutral)),
            1 => flat[0],
            _ if op == NaryOp::And => self.intern(Term::And(flat)),
            _ => self.intern(Term::Or(flat)),
        }
    }

    /// The terms of `formula`, whose propositions `aps` lists; returns the root's number. A
    /// term's span is that of the formula node it was first made for.
    fn build(&mut self, formula: &Formula, aps: &[String]) -> TermId {
        formula.fold(|node, operands: Vec<TermId>| {
            let id = self.node(node, operands, aps);
            self.spans.resize(self.terms.len(), node.span);
            id
        })
    }

    /// The term of `node`, whose operands' terms are `operands`.
    fn node(&mut self, node: &Formula, operands: Vec<TermId>, aps: &[String]) -> TermId {
        {
            let term = match &node.kind {
                FormulaKind::Const(value) => Term::Const(*value),
                FormulaKind::Atom(name) => {
                    let index = aps.iter().position(|ap| ap == name);
                    Term::Proposition(index.expect("the propositions list every atom") as u32)
                }
                FormulaKind::Unary(UnaryOp::Not, _) => return self.negation(operands[0]),
                FormulaKind::Unary(UnaryOp::Next, _) => Term::Next(operands[0]),
                FormulaKind::Unary(UnaryOp::Finally, _) => {
                    Term::Until(self.intern(Term::Const(true)), operands[0])
                }
                FormulaKind::Unary(UnaryOp::Globally, _) => {
                    Term::StrongRelease(self.intern(Term::Const(false)), operands[0])
                }
                FormulaKind::Binary(op, _, _) => {
                    let (left, right) = (operands[0], operands[1]);
                    match op {
                        BinaryOp::Until | BinaryOp::WeakUntil => Term::Until(left, right),
                        BinaryOp::StrongRelease | BinaryOp::Release => {
                            Term::StrongRelease(left, right)
                        }
                        BinaryOp::Implies => {
                            let not_left = self.negation(left);
                            return self.junction(NaryOp::Or, vec![not_left, right]);
                        }
                        BinaryOp::Equiv => Term::Equiv(left.min(right), left.max(right)),
                        BinaryOp::Xor => {
                            let equiv = self.intern(Term::Equiv(left.min(right), left.max(right)));
                            return self.negation(equiv);
                        }
                    }
                }
                FormulaKind::Nary(op, _) => return self.junction(*op, operands),
            };
            self.intern(term)
        }
    }
}

/// The DFA of good prefixes of the formula whose terms are `terms` (`root` the whole formula),
/// unminimised (states in breadth-first order, the start state first), and the steps it took.
fn explore(
    aps: Vec<String>,
    terms: &Terms,
    root: TermId,
    limits: TranslationLimits,
    started: Instant,
) -> Result<(Dfa, u64), Box<LimitError>> {
    let mut bdd = Bdd::with_limits(limits.max_steps, limits.max_nodes);
    bdd.set_max_bytes(limits.max_bytes);
    bdd.set_deadline(limits.deadline);
    let variables = TermVariables::new(aps.len(), &terms.terms);
    let first_term_variable = variables.first();
    let stopped = |limit: Limit, span: Option<Span>, progress: Progress| {
        Box::new(LimitError {
            limit,
            span,
            phase: if span.is_some() {
                Phase::Unfolding
            } else {
                Phase::Exploring
            },
            progress,
            limits,
            note: None,
        })
    };
    let exhausted = |bdd: &Bdd| match bdd.exhausted() {
        None => None,
        Some(Exhausted::Steps(steps)) => Some(Limit::Steps(steps)),
        Some(Exhausted::Nodes(nodes)) => Some(Limit::Nodes(nodes)),
        // The manager's own ceiling is what the rest leaves of the translation's.
        Some(Exhausted::Bytes(_)) => Some(Limit::Bytes(limits.max_bytes)),
        Some(Exhausted::Time) => Some(Limit::Time(started.elapsed())),
    };
    // A limit reached while unfolding is the fault of the term being unfolded: its expansion
    // over the propositions and next-step variables, the guards of every state it occurs in.
    let unfoldings = unfold(&mut bdd, &terms.terms, &variables).map_err(|term| {
        let limit = exhausted(&bdd).expect("unfolding stops only at a limit");
        let progress = Progress {
            nodes: bdd.node_count(),
            bytes: bdd.bytes(),
            ..Progress::default()
        };
        stopped(limit, Some(terms.spans[term as usize]), progress)
    })?;
    let substitute = |var: u32| unfoldings[variables.term(var) as usize];
    let mut composed = NodeMap::default();

    // Breadth-first exploration; `number[node]` is the state of BDD node `node`, if any.
    const UNNUMBERED: DfaState = DfaState::MAX;
    let mut number: Vec<DfaState> = Vec::new();
    let mut states: Vec<Node> = vec![bdd.var(variables.of(root))];
    let mut edges: Vec<Vec<(Guard, DfaState)>> = Vec::new();
    let mut levels = StepLevels::default();
    let mut sizes = Sizes::default();
    // The guard of each node the guards are built as: automata have few distinct guards. Their
    // nodes count towards the node limit (each guard is stored whole).
    let mut guards: HashMap<Node, Guard, BuildHasherDefault<NodeHasher>> = HashMap::default();
    while let Some(&state) = states.get(edges.len()) {
        // What the exploration holds besides the BDD manager, which may grow into the rest of
        // the bytes allowed.
        sizes.held = sizes.count_held(&number, &states, &edges, &guards, &composed, &levels);
        let progress = |bdd: &Bdd, sizes: &Sizes, found: usize| Progress {
            explored: edges.len(),
            found,
            edges: sizes.edges,
            nodes: bdd.node_count() + sizes.guard_nodes,
            bytes: bdd.bytes() + sizes.held,
        };
        if bdd.bytes() + sizes.held > limits.max_bytes {
            let bytes = Limit::Bytes(limits.max_bytes);
            return Err(stopped(bytes, None, progress(&bdd, &sizes, states.len())));
        }
        bdd.set_max_bytes(limits.max_bytes - sizes.held);
        let step = bdd.compose(state, substitute, &mut composed);
        levels.split(&mut bdd, step, first_term_variable);
        if let Some(limit) = exhausted(&bdd) {
            return Err(stopped(limit, None, progress(&bdd, &sizes, states.len())));
        }
        if sizes.edges + levels.leaves.len() > limits.max_edges {
            let limit = Limit::Edges(limits.max_edges);
            return Err(stopped(limit, None, progress(&bdd, &sizes, states.len())));
        }
        let mut state_edges: Vec<(Guard, DfaState)> = Vec::with_capacity(levels.leaves.len());
        for k in 0..levels.order.len() {
            let leaf = levels.order[k];
            let node = levels.leaves[leaf as usize];
            if number.len() <= node as usize {
                number.resize(node as usize + 1, UNNUMBERED);
            }
            if number[node as usize] == UNNUMBERED {
                if states.len() >= limits.max_states {
                    let limit = Limit::States(limits.max_states);
                    return Err(stopped(limit, None, progress(&bdd, &sizes, states.len())));
                }
                number[node as usize] = states.len() as DfaState;
                states.push(node);
            }
            let letters = levels.letters_to(&mut bdd, leaf);
            if let Some(limit) = exhausted(&bdd) {
                return Err(stopped(limit, None, progress(&bdd, &sizes, states.len())));
            }
            let guard = guards.entry(letters).or_insert_with(|| {
                let guard = Guard::export(&bdd, letters);
                sizes.guard_nodes += guard.size();
                bdd.charge(guard.size() as u64);
                guard
            });
            state_edges.push((guard.clone(), number[node as usize]));
            if bdd.node_count() + sizes.guard_nodes > limits.max_nodes {
                let limit = Limit::Nodes(limits.max_nodes);
                return Err(stopped(limit, None, progress(&bdd, &sizes, states.len())));
            }
        }
        sizes.edges += state_edges.len();
        edges.push(state_edges);
    }
    let steps = bdd.steps();
    // The DFA's arrays are built while the exploration's are held (counted above).
    drop((bdd, composed, guards, number, levels));
    let finals = surely_accepting(&states, &edges);
    // BDD paths give every state disjoint guards covering every letter.
    let dfa = Dfa::from_disjoint(aps, 0, finals, edges);
    Ok((dfa, steps))
}

/// What the exploration has counted so far, for the limits and their messages.
#[derive(Default)]
struct Sizes {
    /// Edges of the explored states.
    edges: usize,
    /// Nodes of the distinct guards (each stored whole).
    guard_nodes: usize,
    /// The bytes held outside the BDD manager, as last counted.
    held: u64,
}

impl Sizes {
    /// The bytes the exploration holds outside its BDD manager, counted from the capacities of
    /// its arrays, plus the DFA's own arrays of the edges so far (built at the end while
    /// these are held).
    fn count_held(
        &self,
        number: &Vec<DfaState>,
        states: &Vec<Node>,
        edges: &Vec<Vec<(Guard, DfaState)>>,
        guards: &HashMap<Node, Guard, BuildHasherDefault<NodeHasher>>,
        composed: &NodeMap<Node>,
        levels: &StepLevels,
    ) -> u64 {
        // A hash table holds a control byte per slot, and one slot in eight is spare.
        let table = |capacity: usize, entry: usize| capacity * 8 / 7 * (entry + 1);
        let held = number.capacity() * size_of::<DfaState>()
            + states.capacity() * size_of::<Node>()
            + edges.capacity() * size_of::<Vec<(Guard, DfaState)>>()
            + self.edges * size_of::<(Guard, DfaState)>()
            + table(guards.capacity(), size_of::<(Node, Guard)>())
            + self.guard_nodes * Guard::BYTES_PER_NODE
            + guards.len() * Guard::BYTES_PER_GUARD
            + table(composed.capacity(), size_of::<(Node, Node)>())
            + levels.bytes()
            + self.edges * (size_of::<Guard>() + size_of::<DfaState>());
        held as u64
    }
}

/// The BDD variables of terms, after the propositions' (see the module documentation): first
/// every term that is neither `U` nor `M` in increasing term number, then the `U` and `M` terms
/// in decreasing term number.
struct TermVariables {
    propositions: u32,
    /// `var_of[t]` is the variable of term `t`.
    var_of: Vec<u32>,
    /// `term_of[v - propositions]` is the term of variable `v`.
    term_of: Vec<TermId>,
}

impl TermVariables {
    fn new(propositions: usize, terms: &[Term]) -> TermVariables {
        let propositions = propositions as u32;
        let lasting = |t: &TermId| {
            matches!(
                terms[*t as usize],
                Term::Until(..) | Term::StrongRelease(..)
            )
        };
        let numbers = 0..terms.len() as TermId;
        let term_of: Vec<TermId> = numbers
            .clone()
            .filter(|t| !lasting(t))
            .chain(numbers.rev().filter(lasting))
            .collect();
        let mut var_of = vec![0; terms.len()];
        for (i, &t) in term_of.iter().enumerate() {
            var_of[t as usize] = propositions + i as u32;
        }
        TermVariables {
            propositions,
            var_of,
            term_of,
        }
    }

    /// The first variable of a term: the variables below it are propositions.
    fn first(&self) -> u32 {
        self.propositions
    }

    /// The variable of term `term`.
    fn of(&self, term: TermId) -> u32 {
        self.var_of[term as usize]
    }

    /// The term of variable `var` (not a proposition).
    fn term(&self, var: u32) -> TermId {
        self.term_of[(var - self.propositions) as usize]
    }
}

/// The unfolding of every term, in term order; the variable `variables.of(t)` stands for
/// "term `t` holds from the next step". `Err(t)` if `bdd` reached a limit while unfolding
/// term `t`.
fn unfold(bdd: &mut Bdd, terms: &[Term], variables: &TermVariables) -> Result<Vec<Node>, TermId> {
    let mut unfoldings: Vec<Node> = Vec::with_capacity(terms.len());
    for (id, term) in terms.iter().enumerate() {
        let next_self = variables.of(id as TermId);
        let node = match term {
            Term::Const(true) => bdd::TRUE,
            Term::Const(false) => bdd::FALSE,
            Term::Proposition(index) => bdd.var(*index),
            Term::Not(operand) => bdd.not(unfoldings[*operand as usize]),
            Term::Next(operand) => bdd.var(variables.of(*operand)),
            Term::Until(left, right) => {
                let next = bdd.var(next_self);
                let stay = bdd.and(unfoldings[*left as usize], next);
                bdd.or(unfoldings[*right as usize], stay)
            }
            Term::StrongRelease(left, right) => {
                let next = bdd.var(next_self);
                let release = bdd.or(unfoldings[*left as usize], next);
                bdd.and(unfoldings[*right as usize], release)
            }
            Term::Equiv(left, right) => {
                let (left, right) = (unfoldings[*left as usize], unfoldings[*right as usize]);
                let not_right = bdd.not(right);
                bdd.ite(left, right, not_right)
            }
            Term::And(operands) => operands.iter().fold(bdd::TRUE, |acc, &operand| {
                bdd.and(acc, unfoldings[operand as usize])
            }),
            Term::Or(operands) => operands.iter().fold(bdd::FALSE, |acc, &operand| {
                bdd.or(acc, unfoldings[operand as usize])
            }),
        };
        if bdd.exhausted().is_some() {
            return Err(id as TermId);
        }
        unfoldings.push(node);
    }
    Ok(unfoldings)
}

/// The proposition levels of one step diagram, taken apart once: the successors (the nodes
/// where the diagram leaves the proposition levels) and the proposition-level nodes in
/// post-order, with their branches and parents as positions. A successor's guard is then
/// built from the nodes above it alone (its ancestors), so that a state's guards cost about
/// their own size, not the number of successors times the size of the diagram: the state of
/// `(a1 U b1) & … & (a12 U b12)` with every `U` pending has 2^12 + 1 successors under as many
/// proposition-level nodes. (Walking the whole diagram once per successor, with a hash map of
/// visited nodes, took as long as composing the states.)
#[derive(Default)]
struct StepLevels {
    /// The successor nodes, in the order first reached.
    leaves: Vec<Node>,
    /// The indices of `leaves` in increasing order of node: the order the successors are
    /// numbered in.
    order: Vec<u32>,
    /// Proposition-level nodes, branches before the nodes above them, as (variable, low, high)
    /// with branches `LEAF | i` for `leaves[i]` or `j` for `inner[j]`; the root is last.
    inner: Vec<(u32, u32, u32)>,
    /// The parents of `inner[j]` (index `j`) and of `leaves[i]` (index `inner.len() + i`):
    /// `parents[parent_offsets[k]..parent_offsets[k + 1]]`.
    parent_offsets: Vec<u32>,
    parents: Vec<u32>,
    /// `mark[j] == generation` iff `inner[j]` is above the successor being built.
    mark: Vec<u32>,
    generation: u32,
    /// The ancestors of the successor being built, then their results (`results[j]`).
    ancestors: Vec<u32>,
    results: Vec<Node>,
    /// Scratch: the position of each node visited, the walk's stack.
    position: NodeMap<u32>,
    stack: Vec<(Node, bool)>,
}

/// Marks a branch of [`StepLevels::inner`] as a leaf.
const LEAF: u32 = 1 << 31;

impl StepLevels {
    /// The bytes of its arrays (the largest step so far sets them).
    fn bytes(&self) -> usize {
        self.leaves.capacity() * size_of::<Node>()
            + self.order.capacity() * size_of::<u32>()
            + self.inner.capacity() * size_of::<(u32, u32, u32)>()
            + (self.parent_offsets.capacity() + self.parents.capacity() + self.mark.capacity())
                * size_of::<u32>()
            + self.ancestors.capacity() * size_of::<u32>()
            + self.results.capacity() * size_of::<Node>()
            + self.position.capacity() * 8 / 7 * (size_of::<(Node, u32)>() + 1)
            + self.stack.capacity() * size_of::<(Node, bool)>()
    }

    /// Takes `step` apart; the nodes visited are charged to `bdd` as steps.
    fn split(&mut self, bdd: &mut Bdd, step: Node, first_term_variable: u32) {
        self.leaves.clear();
        self.inner.clear();
        self.position.clear();
        self.stack.clear();
        self.stack.push((step, false));
        while let Some((node, expanded)) = self.stack.pop() {
            match bdd.top(node) {
                Some(var) if var < first_term_variable => {
                    let (low, high) = bdd.branches(node);
                    if expanded {
                        let entry = (var, self.position[&low], self.position[&high]);
                        self.position.insert(node, self.inner.len() as u32);
                        self.inner.push(entry);
                    } else if !self.position.contains_key(&node) {
                        self.stack
                            .extend([(node, true), (high, false), (low, false)]);
                    }
                }
                _ => {
                    if !self.position.contains_key(&node) {
                        self.position.insert(node, LEAF | self.leaves.len() as u32);
                        self.leaves.push(node);
                    }
                }
            }
        }
        self.order.clear();
        self.order.extend(0..self.leaves.len() as u32);
        let leaves = &self.leaves;
        self.order.sort_unstable_by_key(|&i| leaves[i as usize]);

        // Parents in CSR form.
        let inner = self.inner.len();
        let index = |branch: u32| {
            if branch & LEAF == 0 {
                branch as usize
            } else {
                inner + (branch & !LEAF) as usize
            }
        };
        self.parent_offsets.clear();
        self.parent_offsets.resize(inner + self.leaves.len() + 1, 0);
        for &(_, low, high) in &self.inner {
            self.parent_offsets[index(low) + 1] += 1;
            self.parent_offsets[index(high) + 1] += 1;
        }
        for k in 0..inner + self.leaves.len() {
            self.parent_offsets[k + 1] += self.parent_offsets[k];
        }
        self.parents.clear();
        self.parents.resize(2 * inner, 0);
        let fill = &mut self.results;
        fill.clear();
        fill.extend_from_slice(&self.parent_offsets);
        for (j, &(_, low, high)) in self.inner.iter().enumerate() {
            for child in [index(low), index(high)] {
                self.parents[fill[child] as usize] = j as u32;
                fill[child] += 1;
            }
        }
        if self.mark.len() < inner {
            self.mark.resize(inner, self.generation);
        }
        self.results.clear();
        self.results.resize(inner, bdd::FALSE);
        bdd.charge((inner + self.leaves.len()) as u64);
    }

    /// The letters on which the step goes to `leaves[leaf]`: the proposition levels with that
    /// successor replaced by `true` and every other by `false`, built in `bdd` from the nodes
    /// above that successor (charged as steps).
    fn letters_to(&mut self, bdd: &mut Bdd, leaf: u32) -> Node {
        if self.inner.is_empty() {
            return bdd::TRUE;
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.mark.fill(0);
            self.generation = 1;
        }
        let generation = self.generation;
        // The ancestors, by a search up the parent lists; in increasing position they come
        // branches first.
        self.ancestors.clear();
        let start = self.inner.len() + leaf as usize;
        let mut at = 0;
        let mut node = start;
        loop {
            let range = self.parent_offsets[node] as usize..self.parent_offsets[node + 1] as usize;
            for &parent in &self.parents[range] {
                if self.mark[parent as usize] != generation {
                    self.mark[parent as usize] = generation;
                    self.ancestors.push(parent);
                }
            }
            match self.ancestors.get(at) {
                Some(&next) => {
                    node = next as usize;
                    at += 1;
                }
                None => break,
            }
        }
        self.ancestors.sort_unstable();
        for &j in &self.ancestors {
            let (var, low, high) = self.inner[j as usize];
            let value = |branch: u32| {
                if branch & LEAF != 0 {
                    Node::from(branch == LEAF | leaf)
                } else if self.mark[branch as usize] == generation {
                    self.results[branch as usize]
                } else {
                    bdd::FALSE
                }
            };
            let (low, high) = (value(low), value(high));
            self.results[j as usize] = bdd.make(var, low, high);
        }
        bdd.charge(self.ancestors.len() as u64);
        self.results[self.inner.len() - 1]
    }
}

/// The states from which every infinite run reaches the state `true`: the least fixpoint of
/// "is `true`, or has only such successors", by a backward worklist over predecessor lists (CSR)
/// so that long chains of states cost linear time.
fn surely_accepting(states: &[Node], edges: &[Vec<(Guard, DfaState)>]) -> BitSet {
    let n = states.len();
    // `edges` has one edge per distinct target, so counting edges counts successors.
    let mut pending: Vec<usize> = edges.iter().map(Vec::len).collect();
    let predecessors: Csr<DfaState, DfaState> = Csr::group(
        n,
        edges.iter().enumerate().flat_map(|(source, out)| {
            out.iter()
                .map(move |&(_, target)| (target, source as DfaState))
        }),
    );
    let mut accepting = BitSet::with_capacity(n);
    let mut worklist: Vec<usize> = states
        .iter()
        .position(|&node| node == bdd::TRUE)
        .into_iter()
        .collect();
    accepting.extend(worklist.iter().copied());
    while let Some(state) = worklist.pop() {
        for &source in predecessors.row(state as DfaState) {
            let source = source as usize;
            pending[source] -= 1;
            if pending[source] == 0 && accepting.insert(source) {
                worklist.push(source);
            }
        }
    }
    accepting
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use std::time::Duration;

    use super::*;
    use crate::automata::Cube;
    use crate::automata::compare::equivalence_counterexample;
    use crate::automata::minimize;

    fn translate(text: &str) -> Dfa {
        let formula = ltl::parse(text).unwrap_or_else(|e| panic!("{text}: {e}"));
        Builtin::default()
            .translate(&formula)
            .unwrap_or_else(|e| panic!("{text}: {e}"))
    }

    /// Whether `dfa` accepts the word whose letters list the propositions that hold.
    fn accepts(dfa: &Dfa, word: &[&[&str]]) -> bool {
        dfa.accepts(word.iter().map(|letter| dfa.letter(letter.iter().copied())))
    }

    fn assert_same_language(x: &str, y: &str) {
        let counterexample = equivalence_counterexample(&translate(x), &translate(y)).unwrap();
        assert_eq!(counterexample, None, "{x} and {y}");
    }

    /// The same translation done naively: term variables in term order, no memo kept between
    /// states, one successor per letter (all 2^AP of them) from the unfoldings restricted to
    /// that letter, finals by iterating the fixpoint to stability; then minimised.
    fn naive(formula: &Formula) -> Dfa {
        let aps = ltl::atomic_propositions(formula);
        let mut terms = Terms::default();
        let root = terms.build(formula, &aps);
        let terms = terms.terms;
        let first = aps.len() as u32;
        let mut bdd = Bdd::new();
        let vars: Vec<Node> = (0..first + terms.len() as u32)
            .map(|v| bdd.var(v))
            .collect();
        let mut unfoldings: Vec<Node> = Vec::new();
        for (id, term) in terms.iter().enumerate() {
            let u = |t: &TermId| unfoldings[*t as usize];
            let node = match term {
                Term::Const(value) => Node::from(*value),
                Term::Proposition(index) => vars[*index as usize],
                Term::Not(operand) => bdd.not(u(operand)),
                Term::Next(operand) => vars[(first + operand) as usize],
                Term::Until(left, right) => {
                    let stay = bdd.and(u(left), vars[first as usize + id]);
                    bdd.or(u(right), stay)
                }
                Term::StrongRelease(left, right) => {
                    let release = bdd.or(u(left), vars[first as usize + id]);
                    bdd.and(u(right), release)
                }
                Term::Equiv(left, right) => {
                    let not_right = bdd.not(u(right));
                    bdd.ite(u(left), u(right), not_right)
                }
                Term::And(operands) => operands.iter().fold(bdd::TRUE, |acc, t| {
                    let operand = u(t);
                    bdd.and(acc, operand)
                }),
                Term::Or(operands) => operands.iter().fold(bdd::FALSE, |acc, t| {
                    let operand = u(t);
                    bdd.or(acc, operand)
                }),
            };
            unfoldings.push(node);
        }
        let letters = 1u64 << aps.len();
        // The unfoldings on each letter: functions of the next-step variables alone.
        let on_letter: Vec<Vec<Node>> = (0..letters)
            .map(|letter| {
                let fixed = |v: u32| {
                    if v < first {
                        Node::from(letter & (1 << v) != 0)
                    } else {
                        vars[v as usize]
                    }
                };
                let mut memo = NodeMap::default();
                (unfoldings.iter())
                    .map(|&u| bdd.compose(u, fixed, &mut memo))
                    .collect()
            })
            .collect();
        let mut states = vec![vars[(first + root) as usize]];
        let mut number: HashMap<Node, DfaState> = HashMap::from([(states[0], 0)]);
        let mut successors: Vec<Vec<DfaState>> = Vec::new();
        while let Some(&state) = states.get(successors.len()) {
            let mut targets = Vec::new();
            for letter in &on_letter {
                let mut memo = NodeMap::default();
                let next = bdd.compose(state, |v| letter[(v - first) as usize], &mut memo);
                let target = *number.entry(next).or_insert_with(|| {
                    states.push(next);
                    states.len() as DfaState - 1
                });
                targets.push(target);
            }
            successors.push(targets);
        }
        let mut finals: Vec<bool> = states.iter().map(|&s| s == bdd::TRUE).collect();
        loop {
            let next: Vec<bool> = (0..states.len())
                .map(|q| finals[q] || successors[q].iter().all(|&t| finals[t as usize]))
                .collect();
            if next == finals {
                break;
            }
            finals = next;
        }
        let edges = successors
            .iter()
            .map(|targets| {
                let cube = |letter: u64| Cube {
                    positive: letter,
                    negative: !letter & (letters - 1),
                };
                (0..letters)
                    .map(|l| (Guard::from_cubes([cube(l)]), targets[l as usize]))
                    .collect()
            })
            .collect();
        let finals = (0..states.len()).filter(|&q| finals[q]).collect();
        minimize(&Dfa::new(aps, 0, finals, edges).unwrap())
    }

    /// Random co-safe formulas over three propositions: `X` chains, `F`, `U`, `M`, `&`, `|`
    /// over literals, each temporal operator also written through its dual (`!G!`, `!(!l R
    /// !r)`, `!(!l W !r)`), and `<->`/`xor` between `X`-only formulas.
    fn formulas() -> impl Strategy<Value = String> {
        let literal = (0..3usize, any::<bool>()).prop_map(|(p, positive)| {
            format!("{}{}", if positive { "" } else { "!" }, ["a", "b", "c"][p])
        });
        let next_only = (literal.clone(), 0..3usize, literal.clone(), 0..2usize)
            .prop_map(|(l, n, r, op)| format!("({l} {} {}{r})", ["<->", "xor"][op], "X".repeat(n)));
        let leaf = prop_oneof![4 => literal, 1 => next_only, 1 => Just("1".to_string())];
        leaf.prop_recursive(6, 48, 2, |inner| {
            prop_oneof![
                (0..4usize, inner.clone()).prop_map(|(n, f)| format!("{}({f})", "X".repeat(n + 1))),
                (any::<bool>(), inner.clone()).prop_map(|(dual, f)| if dual {
                    format!("!G!({f})")
                } else {
                    format!("F({f})")
                }),
                (0..6usize, inner.clone(), inner).prop_map(|(op, l, r)| match op {
                    0 => format!("({l}) U ({r})"),
                    1 => format!("!(!({l}) R !({r}))"),
                    2 => format!("({l}) M ({r})"),
                    3 => format!("!(!({l}) W !({r}))"),
                    4 => format!("({l}) & ({r})"),
                    _ => format!("({l}) | ({r})"),
                }),
            ]
        })
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]

        #[test]
        fn the_translation_equals_the_naive_construction(text in formulas()) {
            let formula = ltl::parse(&text).unwrap();
            proptest::prop_assume!(ltl::check_co_safe(&formula).is_ok());
            let dfa = Builtin::default().translate(&formula).unwrap();
            // Minimal DFAs of one language over the same propositions are equal, guards and
            // numbering included.
            proptest::prop_assert_eq!(dfa, naive(&formula), "{}", text);
        }
    }

    #[test]
    fn until_has_a_start_an_accepting_and_a_rejecting_state() {
        let dfa = translate("a U b");
        assert_eq!(dfa.aps(), ["a", "b"]);
        assert_eq!(dfa.num_states(), 3);
        assert!(accepts(&dfa, &[&["b"]]));
        assert!(accepts(&dfa, &[&["a"], &["a"], &["a", "b"], &[]]));
        assert!(!accepts(&dfa, &[]));
        assert!(!accepts(&dfa, &[&["a"], &["a"]]));
        assert!(!accepts(&dfa, &[&["a"], &[], &["b"]]));
        let dfa = translate("!a U b");
        assert!(accepts(&dfa, &[&[], &[], &["a", "b"]]));
        assert!(!accepts(&dfa, &[&[], &["a"], &["b"]]));
    }

    #[test]
    fn strong_release_needs_the_release_point() {
        // a M b: b holds until and including a point where a holds.
        let dfa = translate("a M b");
        assert_eq!(dfa.num_states(), 3);
        assert!(accepts(&dfa, &[&["b"], &["a", "b"]]));
        assert!(!accepts(&dfa, &[&["b"], &["a"]]));
        assert!(!accepts(&dfa, &[&["a"]]));
        assert!(!accepts(&dfa, &[&["b"], &["b"]]));
    }

    #[test]
    fn eventualities_are_remembered_without_a_rejecting_sink() {
        // Start, a seen, b seen, both seen; nothing is ever lost.
        let dfa = translate("F a & F b");
        assert_eq!(dfa.num_states(), 4);
        assert!(accepts(&dfa, &[&["a"], &[], &["b"]]));
        assert!(accepts(&dfa, &[&["a", "b"]]));
        assert!(!accepts(&dfa, &[&["a"], &["a"]]));
    }

    #[test]
    fn next_chains_count_steps() {
        // Three steps, then a decides: 4 + accepting + rejecting.
        let dfa = translate("XXXa");
        assert_eq!(dfa.num_states(), 6);
        assert!(accepts(&dfa, &[&[], &[], &[], &["a"]]));
        assert!(!accepts(&dfa, &[&["a"], &["a"], &["a"], &[]]));
        assert!(!accepts(&dfa, &[&[], &[], &[]]));
    }

    #[test]
    fn constants_and_repeated_operands_collapse() {
        let dfa = translate("true");
        assert_eq!((dfa.num_states(), dfa.is_final(0)), (1, true));
        let dfa = translate("0");
        assert_eq!((dfa.num_states(), dfa.is_final(0)), (1, false));
        assert_eq!(translate("a | 1").num_states(), 1);
        let dfa = translate("a & a & (b | false)");
        assert_eq!(dfa.num_states(), 3);
        assert!(accepts(&dfa, &[&["a", "b"]]));
        assert!(!accepts(&dfa, &[&["a"], &["a", "b"]]));
    }

    #[test]
    fn a_valid_state_is_final_even_when_not_the_constant_true() {
        // Every word starting with a is a good prefix, although after the first letter the
        // state is the obligation `F b | F !b`, not `true`.
        let dfa = translate("a & X(F b | F !b)");
        assert_eq!(dfa.num_states(), 3);
        assert!(!accepts(&dfa, &[]));
        assert!(accepts(&dfa, &[&["a"]]));
        assert!(!accepts(&dfa, &[&["b"], &["a"]]));
        // A valid formula accepts the empty word.
        let dfa = translate("X(F a | F !a)");
        assert_eq!((dfa.num_states(), dfa.is_final(0)), (1, true));
    }

    #[test]
    fn negated_and_derived_operators_read_as_their_positive_normal_form() {
        assert_same_language("!(a W b)", "!a M !b");
        assert_same_language("!(a R b)", "!a U !b");
        assert_same_language("!G a", "F !a");
        assert_same_language("!X(a & G b)", "X(!a | F !b) | !1 & a");
        assert_same_language("a -> F b", "!a | F b");
        assert_same_language("Xa <-> Xb", "X(a & b) | X(!a & !b)");
        assert_same_language("Xa xor b", "(Xa & !b) | (X!a & b)");
        assert_same_language("!!(a U b)", "a U b");
    }

    #[test]
    fn non_co_safe_formulas_are_rejected_with_the_offending_operator() {
        let formula = ltl::parse("F a & G b").unwrap();
        match Builtin::default().translate(&formula) {
            Err(TranslateError::NotCoSafe(error)) => {
                assert_eq!(error.operator, "G");
                assert_eq!(error.span.start, 6);
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn guards_split_only_on_the_propositions_a_state_needs() {
        // F p0 | ... | F p39: two states, whatever 2^40 is.
        let names: Vec<String> = (0..40).map(|i| format!("p{i}")).collect();
        let text: Vec<String> = names.iter().map(|n| format!("F {n}")).collect();
        let dfa = translate(&text.join(" | "));
        assert_eq!(dfa.num_states(), 2);
        assert_eq!(dfa.aps(), names);
        let start: Vec<_> = dfa.edges(0).collect();
        assert_eq!(start.len(), 2);
        assert_eq!(start[1].0.cubes().len(), 40);
        assert!(accepts(&dfa, &[&[], &["p39"]]));
        // 65 propositions are too many for a letter.
        let text: Vec<String> = (0..65).map(|i| format!("q{i}")).collect();
        let formula = ltl::parse(&text.join(" & ")).unwrap();
        assert!(matches!(
            Builtin::default().translate(&formula),
            Err(TranslateError::TooManyPropositions(65))
        ));
    }

    #[test]
    fn parity_of_many_propositions_has_small_guards() {
        // Which successor `p1 <-> (p2 <-> ... X q)` goes to depends on the parity of p1..p20:
        // 2^19 cubes per guard, but a BDD of two nodes per proposition. Start, q next or not,
        // and the two sinks.
        let text = format!(
            "{}X q{}",
            (1..=20).map(|i| format!("(p{i} <-> ")).collect::<String>(),
            ")".repeat(20)
        );
        let dfa = translate(&text);
        assert_eq!(dfa.num_states(), 5);
        // Even parity of p1..p20 (all false) needs q next; so does an even number of them.
        let none: &[&str] = &[];
        assert!(accepts(&dfa, &[none, &["q"]]));
        assert!(!accepts(&dfa, &[none, none]));
        assert!(accepts(&dfa, &[&["p1", "p7"], &["q"]]));
        assert!(accepts(&dfa, &[&["p3"], &[]]));
        assert!(!accepts(&dfa, &[&["p3"], &["q"]]));
    }

    /// The limit that stopped the translation of `text` under `limits`.
    fn limit_reached(text: &str, limits: TranslationLimits) -> LimitError {
        let formula = ltl::parse(text).unwrap();
        match Builtin::new(limits).translate(&formula) {
            Err(TranslateError::Limit(error)) => *error,
            other => panic!("{text}: {other:?}"),
        }
    }

    #[test]
    fn limits_stop_exponential_formulas_with_the_limit_named() {
        // F(a & X^22 b) remembers the last 22 letters: 2^22 states.
        let window = format!("F(a & {}b)", "X".repeat(22));
        let states = limit_reached(&window, TranslationLimits::new(1000, u64::MAX));
        assert_eq!(states.limit, Limit::States(1000));
        assert_eq!((states.phase, states.span), (Phase::Exploring, None));
        // Breadth first: the states found so far are the windows of the first letters, and
        // every state explored has two successors (a or not, for the window).
        assert_eq!(states.progress.found, 1000);
        assert_eq!(states.progress.edges, 2 * states.progress.explored);
        assert_eq!(states.progress.explored, 500);
        let work = limit_reached(&window, TranslationLimits::new(usize::MAX / 8, 10_000));
        assert_eq!(work.limit, Limit::Steps(10_000));
        let nodes = TranslationLimits {
            max_nodes: 500,
            ..TranslationLimits::default()
        };
        assert_eq!(limit_reached(&window, nodes).limit, Limit::Nodes(500));
        // F p0 & … & F p5: 2^6 states (and the start), 2^6 + 3^6 edges (a state with k
        // eventualities pending has 2^k successors).
        let text: Vec<String> = (0..6).map(|i| format!("F p{i}")).collect();
        let text = text.join(" & ");
        let many_nodes = TranslationLimits {
            max_nodes: 1 << 24,
            ..TranslationLimits::new(1 << 7, u64::MAX)
        };
        let edges = limit_reached(&text, many_nodes);
        assert_eq!(edges.limit, Limit::Edges(512));
        let enough = TranslationLimits {
            max_edges: 64 + 729,
            ..many_nodes
        };
        let formula = ltl::parse(&text).unwrap();
        assert_eq!(
            Builtin::new(enough)
                .translate(&formula)
                .unwrap()
                .num_states(),
            64
        );
        // X^5 gives 2^5 = 32 live windows, plus the accepting sink; within every limit.
        let small = ltl::parse("F(a & XXXXXb)").unwrap();
        assert_eq!(
            Builtin::new(TranslationLimits::new(1000, 1_000_000))
                .translate(&small)
                .unwrap()
                .num_states(),
            33
        );
    }

    #[test]
    fn the_byte_limit_is_counted_and_never_exceeded_by_the_count() {
        let window = format!("F(a & {}b)", "X".repeat(22));
        let bytes = TranslationLimits::default().with_max_bytes(4 << 20);
        let error = limit_reached(&window, bytes);
        assert_eq!(error.limit, Limit::Bytes(4 << 20));
        assert!(error.progress.bytes <= 4 << 20, "{error:?}");
        assert!(error.progress.explored > 1000, "{error:?}");
        // Counted, so the same every time.
        assert_eq!(limit_reached(&window, bytes), error);
        // A small formula fits in little.
        let formula = ltl::parse("F(a & XXXXXb)").unwrap();
        let small = TranslationLimits::default().with_max_bytes(1 << 20);
        assert_eq!(
            Builtin::new(small)
                .translate(&formula)
                .unwrap()
                .num_states(),
            33
        );
    }

    #[test]
    fn a_passed_deadline_stops_the_translation_at_once() {
        let window = format!("F(a & {}b)", "X".repeat(22));
        let past = TranslationLimits::default().with_deadline(Deadline::after(Duration::ZERO));
        let error = limit_reached(&window, past);
        assert!(matches!(error.limit, Limit::Time(_)), "{error:?}");
        // Within the first few thousand steps.
        assert!(error.progress.explored < 10_000, "{error:?}");
        // A deadline that has not passed changes nothing.
        let formula = ltl::parse("F(a & XXXXXb)").unwrap();
        let later =
            TranslationLimits::default().with_deadline(Deadline::after(Duration::from_secs(3600)));
        assert_eq!(
            Builtin::new(later)
                .translate(&formula)
                .unwrap()
                .num_states(),
            33
        );
    }

    #[test]
    fn messages_name_the_binding_limit_and_what_raising_it_would_cost() {
        let window = format!("F(a & {}b)", "X".repeat(22));
        let states = limit_reached(&window, TranslationLimits::new(1000, u64::MAX)).to_string();
        assert!(
            states.starts_with(
                "the automaton needs more than 1000 states before minimisation (the state \
                 limit); it had explored "
            ),
            "{states}"
        );
        assert!(
            states.contains("twice as many states would take about"),
            "{states}"
        );
        // With a node limit that twice the states would pass, raising the state limit alone
        // would not do, and the message says so.
        let tight = TranslationLimits {
            max_nodes: 5000,
            ..TranslationLimits::new(1000, u64::MAX)
        };
        let states = limit_reached(&window, tight).to_string();
        assert!(
            states.contains("would reach the node limit too, so raising the state limit alone"),
            "{states}"
        );
        let nodes = TranslationLimits {
            max_nodes: 500,
            ..TranslationLimits::default()
        };
        let nodes = limit_reached(&window, nodes).to_string();
        assert!(
            nodes.starts_with(
                "the built-in translation needs more than 500 BDD nodes for its states and \
                 guards (the node limit); it had explored "
            ),
            "{nodes}"
        );
        assert!(
            nodes.contains("the automaton was still growing ("),
            "{nodes}"
        );
    }

    #[test]
    fn deep_formulas_do_not_overflow_the_stack() {
        // X^1000 a: a chain of 1000 steps.
        let dfa = translate(&format!("{}a", "X".repeat(1000)));
        assert_eq!(dfa.num_states(), 1003);
        // a U (a U (... U b)), 500 deep, is a U b.
        let text = format!("{}b{}", "a U (".repeat(500), ")".repeat(500));
        assert_eq!(translate(&text).num_states(), 3);
    }
}
