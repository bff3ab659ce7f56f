//! The HOA reader: text in the HOA v1 format to DFAs of good prefixes.
//!
//! Accepted: what Spot and other tools write for deterministic terminal automata (see the module
//! documentation of [`super`] for the subset and the rules). The reader checks rather than
//! trusts: determinism is established by intersecting the guards of each state's edges, whatever
//! `properties:` claims. The first error in the text stops the reading; it carries a line and a
//! column. Nothing here panics, whatever the input: nesting of labels and acceptance conditions
//! is bounded ([`MAX_NESTING`]), and so is the number of states ([`MAX_STATES`]).

use std::collections::{HashMap, HashSet};

use crate::automata::guard::GuardUnion;
use crate::automata::{Cube, Dfa, DfaState, Guard, MAX_PROPOSITIONS};
use crate::bdd::{self, Bdd, Node};
use crate::position::Position;

use super::build::{Declared, Edge, to_dfa};
use super::lexer::{Lexer, Located, Spanned, Token};

/// The largest number of states an automaton may declare or reference.
pub const MAX_STATES: u32 = 1 << 20;

/// The deepest nesting of `!` and parentheses in a label or acceptance condition.
pub const MAX_NESTING: usize = 100;

/// Why a HOA text could not be read, and where.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{position}: {message}")]
pub struct HoaError {
    pub position: Position,
    pub message: String,
}

/// One automaton of a HOA text, as a DFA of good prefixes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HoaAutomaton {
    /// The `name:` header, if any.
    pub name: Option<String>,
    /// The DFA: the HOA states keep their numbers; a rejecting sink, if needed, comes last.
    pub dfa: Dfa,
    /// The number of states of the HOA automaton (without the sink).
    pub declared_states: usize,
    /// The number of edges listed in the body, `[f]` edges excluded.
    pub declared_edges: usize,
    /// The rejecting sink added to complete the automaton, if it was incomplete.
    pub sink: Option<DfaState>,
}

/// Reads every automaton of a HOA text (automata aborted with `--ABORT--` are skipped, as the
/// format requires). A text with no complete automaton is an error.
pub fn parse(text: &str) -> Result<Vec<HoaAutomaton>, HoaError> {
    let locate = |error: Located| HoaError {
        position: Position::of_offset(text, error.offset),
        message: error.message,
    };
    let mut parser = Parser {
        lexer: Lexer::new(text),
        text,
    };
    let mut automata = Vec::new();
    let mut last_abort = None;
    loop {
        let next = parser.lexer.peek().map_err(locate)?;
        if next.token == Token::Eof {
            return match (automata.is_empty(), last_abort) {
                (false, _) => Ok(automata),
                (true, Some(offset)) => Err(locate(Located::new(
                    offset,
                    "no automaton: every automaton of the input was aborted with `--ABORT--`",
                ))),
                (true, None) => Err(locate(Located::new(
                    next.offset,
                    "expected `HOA:`, found the end of the input",
                ))),
            };
        }
        match parser.automaton() {
            Ok(automaton) => automata.push(automaton),
            Err(Failure::Aborted(offset)) => last_abort = Some(offset),
            Err(Failure::Syntax(error)) => return Err(locate(error)),
        }
    }
}

/// Why reading an automaton stopped: an error, or `--ABORT--` at the given offset.
enum Failure {
    Syntax(Located),
    Aborted(usize),
}

impl From<Located> for Failure {
    fn from(error: Located) -> Failure {
        Failure::Syntax(error)
    }
}

type Parsed<T> = Result<T, Failure>;

fn fail<T>(offset: usize, message: impl Into<String>) -> Parsed<T> {
    Err(Failure::Syntax(Located::new(offset, message)))
}

/// A label expression as written; resolved into a [`Guard`] once the propositions and aliases
/// it may refer to are known. `&` and `|` chains are flat, so only `!` and parentheses nest.
enum Label<'a> {
    Constant(bool),
    Proposition { index: u32, offset: usize },
    Alias { name: &'a str, offset: usize },
    Not(Box<Label<'a>>),
    And(Vec<Label<'a>>),
    Or(Vec<Label<'a>>),
}

/// The acceptance conditions a DFA can be read from.
#[derive(Clone, Copy, Debug)]
enum Acceptance {
    /// `t`: every run is accepting.
    All,
    /// `f`: no run is accepting.
    Never,
    /// `Inf(set)`: Büchi acceptance on one set.
    Buchi { set: u32 },
}

impl Acceptance {
    fn accepts(self, marks: &[u32]) -> bool {
        match self {
            Acceptance::All => true,
            Acceptance::Never => false,
            Acceptance::Buchi { set } => marks.contains(&set),
        }
    }
}

/// The shape of an acceptance condition, as far as telling the supported ones apart needs.
enum Condition {
    Constant(bool),
    Set {
        infinitely: bool,
        complemented: bool,
        set: u32,
    },
    Compound,
}

/// What the header says, once complete.
struct Header<'a> {
    offset: usize,
    name: Option<String>,
    states: Option<u32>,
    initial: u32,
    aps: Vec<String>,
    aliases: Aliases<'a>,
    sets: u32,
    acceptance: Acceptance,
}

/// The aliases resolved so far: their guards in order of definition, found by name through a
/// hash map (a header may define very many).
#[derive(Default)]
struct Aliases<'a> {
    number: HashMap<&'a str, usize>,
    guards: Vec<Guard>,
}

impl Aliases<'_> {
    fn get(&self, name: &str) -> Option<&Guard> {
        self.number.get(name).map(|&i| &self.guards[i])
    }
}

/// How the edges of the state being read get their labels.
enum Labelling {
    /// Not known before the first edge.
    Undecided,
    Explicit,
    /// The `i`-th edge is labelled by the valuation whose bits are `i`.
    Implicit,
    /// Every edge carries the state's label.
    State(Guard),
}

/// The state being read in the body.
struct OpenState {
    number: u32,
    offset: usize,
    /// The acceptance sets of the state, which its edges share.
    marks: Vec<u32>,
    labelling: Labelling,
    /// Edges listed so far, `[f]` edges included (implicit labels count them).
    listed: usize,
    /// The edges kept (satisfiable labels), with their offsets.
    edges: Vec<(Edge, usize)>,
    /// The union of their labels, which checks determinism without comparing pairs of edges.
    covered: GuardUnion,
}

struct Parser<'a> {
    lexer: Lexer<'a>,
    text: &'a str,
}

impl<'a> Parser<'a> {
    /// The next token; `--ABORT--` abandons the automaton.
    fn next(&mut self) -> Parsed<Spanned<'a>> {
        let spanned = self.lexer.next()?;
        match spanned.token {
            Token::Abort => Err(Failure::Aborted(spanned.offset)),
            _ => Ok(spanned),
        }
    }

    fn peek(&mut self) -> Parsed<Spanned<'a>> {
        if self.lexer.peek()?.token == Token::Abort {
            return self.next();
        }
        Ok(self.lexer.peek()?.clone())
    }

    fn peek_is(&mut self, symbol: char) -> Parsed<bool> {
        Ok(self.peek()?.token == Token::Symbol(symbol))
    }

    fn expect_symbol(&mut self, symbol: char, context: &str) -> Parsed<usize> {
        let spanned = self.next()?;
        if spanned.token != Token::Symbol(symbol) {
            return fail(
                spanned.offset,
                format!("expected `{symbol}` {context}, found {}", spanned.token),
            );
        }
        Ok(spanned.offset)
    }

    fn expect_int(&mut self, what: &str) -> Parsed<(u32, usize)> {
        let spanned = self.next()?;
        match spanned.token {
            Token::Int(value) => Ok((value, spanned.offset)),
            other => fail(spanned.offset, format!("expected {what}, found {other}")),
        }
    }

    fn position(&self, offset: usize) -> Position {
        Position::of_offset(self.text, offset)
    }

    fn automaton(&mut self) -> Parsed<HoaAutomaton> {
        let first = self.next()?;
        if first.token != Token::Header("HOA") {
            return fail(
                first.offset,
                format!("expected `HOA:`, found {}", first.token),
            );
        }
        let version = self.lexer.next_version()?;
        match version.token {
            Token::Identifier(v) if v == "v1" || v.starts_with("v1.") => {}
            Token::Identifier(v) => {
                return fail(
                    version.offset,
                    format!("unsupported HOA version `{v}` (this reader knows v1)"),
                );
            }
            Token::Abort => return Err(Failure::Aborted(version.offset)),
            other => {
                return fail(
                    version.offset,
                    format!("expected the format version after `HOA:`, found {other}"),
                );
            }
        }
        let header = self.header(first.offset)?;
        let (states, max_state) = self.body(&header)?;
        let num_states = match header.states {
            Some(n) => n,
            None => max_state.max(header.initial) + 1,
        };
        let declared_edges = states.iter().map(Vec::len).sum();
        let declared = Declared {
            aps: header.aps,
            initial: header.initial,
            num_states,
            edges: states,
        };
        let (dfa, sink) = to_dfa(declared).map_err(|error| {
            // The reader checks everything the DFA constructor checks; this is a safety net.
            Failure::Syntax(Located::new(header.offset, error.to_string()))
        })?;
        Ok(HoaAutomaton {
            name: header.name,
            dfa,
            declared_states: num_states as usize,
            declared_edges,
            sink,
        })
    }

    fn header(&mut self, offset: usize) -> Parsed<Header<'a>> {
        let mut name = None;
        let mut states = None;
        let mut starts: Vec<(u32, usize)> = Vec::new();
        let mut aps: Option<Vec<String>> = None;
        let mut aliases: Vec<(&'a str, Label<'a>)> = Vec::new();
        let mut alias_names: HashSet<&'a str> = HashSet::new();
        let mut acceptance: Option<(u32, Acceptance)> = None;
        let mut once: Vec<&str> = Vec::new();
        let body_offset = loop {
            let item = self.next()?;
            let header = match item.token {
                Token::Header(header) => header,
                Token::Body => break item.offset,
                Token::Eof => {
                    return fail(
                        item.offset,
                        "missing `--BODY--`: the input ends inside the header",
                    );
                }
                other => {
                    return fail(
                        item.offset,
                        format!("expected a header item or `--BODY--`, found {other}"),
                    );
                }
            };
            let single = matches!(
                header,
                "HOA" | "States" | "AP" | "Acceptance" | "name" | "tool" | "acc-name"
            );
            if single {
                if once.contains(&header) {
                    return fail(item.offset, format!("`{header}:` is given twice"));
                }
                once.push(header);
            }
            match header {
                "States" => {
                    let (n, at) = self.expect_int("a number of states")?;
                    if n > MAX_STATES {
                        return fail(
                            at,
                            format!(
                                "{n} states are more than the {MAX_STATES} this reader accepts"
                            ),
                        );
                    }
                    states = Some(n);
                }
                "Start" => {
                    let (state, at) = self.expect_int("an initial state")?;
                    let next = self.peek()?;
                    if next.token == Token::Symbol('&') {
                        return fail(
                            next.offset,
                            "universal branching (`&` in `Start:`) is not supported: a DFA has \
                             one initial state",
                        );
                    }
                    starts.push((state, at));
                }
                "AP" => aps = Some(self.propositions(item.offset)?),
                "Alias" => {
                    let spanned = self.next()?;
                    let Token::Alias(alias) = spanned.token else {
                        return fail(
                            spanned.offset,
                            format!("expected an alias name (`@name`), found {}", spanned.token),
                        );
                    };
                    if !alias_names.insert(alias) {
                        return fail(spanned.offset, format!("alias `@{alias}` is defined twice"));
                    }
                    let label = self.label_expression(0)?;
                    aliases.push((alias, label));
                }
                "Acceptance" => acceptance = Some(self.acceptance()?),
                "name" => {
                    let spanned = self.next()?;
                    let Token::Str(value) = spanned.token else {
                        return fail(
                            spanned.offset,
                            format!("expected a string after `name:`, found {}", spanned.token),
                        );
                    };
                    name = Some(value);
                }
                "HOA" => return fail(item.offset, "`HOA:` is given twice (missing `--BODY--`?)"),
                "State" => return fail(item.offset, "missing `--BODY--` before `State:`"),
                _ if header.starts_with(|c: char| c.is_ascii_uppercase()) => {
                    return fail(
                        item.offset,
                        format!(
                            "unknown header `{header}:` (a header starting with an upper-case \
                             letter may change the automaton's meaning, so it cannot be ignored)"
                        ),
                    );
                }
                // `tool:`, `acc-name:`, `properties:` and other lower-case headers are
                // informative only: their values are skipped.
                _ => self.skip_values()?,
            }
        };
        let Some((sets, acceptance)) = acceptance else {
            return fail(
                body_offset,
                "missing `Acceptance:` header before `--BODY--` (it is mandatory)",
            );
        };
        let aps = aps.unwrap_or_default();
        let mut resolved = Aliases::default();
        for (alias, label) in aliases {
            // An alias may only use the aliases defined before it.
            let guard = resolve(&label, aps.len(), &resolved)?;
            resolved.number.insert(alias, resolved.guards.len());
            resolved.guards.push(guard);
        }
        let Some(&(initial, _)) = starts.first() else {
            return fail(
                body_offset,
                "no `Start:` header before `--BODY--`: a DFA needs one initial state",
            );
        };
        for &(state, at) in &starts {
            self.check_state(state, at, states)?;
            if state != initial {
                return fail(
                    at,
                    format!(
                        "several initial states ({initial} and {state}): a DFA has exactly one"
                    ),
                );
            }
        }
        Ok(Header {
            offset,
            name,
            states,
            initial,
            aps,
            aliases: resolved,
            sets,
            acceptance,
        })
    }

    /// `AP:` count and names.
    fn propositions(&mut self, offset: usize) -> Parsed<Vec<String>> {
        let (count, count_at) = self.expect_int("the number of atomic propositions")?;
        let mut names: Vec<String> = Vec::new();
        let mut seen: HashSet<String> = HashSet::new();
        while let Token::Str(name) = self.peek()?.token {
            let at = self.next()?.offset;
            if !seen.insert(name.clone()) {
                return fail(at, format!("atomic proposition \"{name}\" is listed twice"));
            }
            names.push(name);
        }
        if names.len() != count as usize {
            return fail(
                count_at,
                format!(
                    "`AP:` announces {count} atomic propositions but lists {}",
                    names.len()
                ),
            );
        }
        if names.len() > MAX_PROPOSITIONS {
            return fail(
                offset,
                format!(
                    "{} atomic propositions are more than the {MAX_PROPOSITIONS} an automaton may have",
                    names.len()
                ),
            );
        }
        Ok(names)
    }

    /// Skips the values of an informative header item.
    fn skip_values(&mut self) -> Parsed<()> {
        loop {
            match self.peek()?.token {
                Token::Header(_) | Token::Body | Token::End | Token::Eof => return Ok(()),
                _ => {
                    self.next()?;
                }
            }
        }
    }

    /// `Acceptance:` set count and condition, checked to be one a DFA can be read from.
    fn acceptance(&mut self) -> Parsed<(u32, Acceptance)> {
        let (sets, _) = self.expect_int("the number of acceptance sets")?;
        let start = self.peek()?.offset;
        let condition = self.condition(sets, 0)?;
        let end = self.lexer.consumed_end();
        match condition {
            Condition::Constant(true) => Ok((sets, Acceptance::All)),
            Condition::Constant(false) => Ok((sets, Acceptance::Never)),
            Condition::Set {
                infinitely: true,
                complemented: false,
                set,
            } => Ok((sets, Acceptance::Buchi { set })),
            _ => fail(
                start,
                format!(
                    "unsupported acceptance condition `{}`: a DFA can be read only from `t`, `f` \
                     or Büchi `Inf(n)` acceptance",
                    self.lexer.slice(start, end)
                ),
            ),
        }
    }

    /// One or more operands separated by `symbol`, each read by `operand`.
    fn separated<T>(
        &mut self,
        symbol: char,
        mut operand: impl FnMut(&mut Self) -> Parsed<T>,
    ) -> Parsed<Vec<T>> {
        let mut operands = vec![operand(self)?];
        while self.peek_is(symbol)? {
            self.next()?;
            operands.push(operand(self)?);
        }
        Ok(operands)
    }

    /// An acceptance condition: `&` binds tighter than `|`.
    fn condition(&mut self, sets: u32, depth: usize) -> Parsed<Condition> {
        let operands = self.separated('|', |p| {
            let operands = p.separated('&', |p| p.condition_atom(sets, depth))?;
            Ok(single_or_compound(operands))
        })?;
        Ok(single_or_compound(operands))
    }

    fn condition_atom(&mut self, sets: u32, depth: usize) -> Parsed<Condition> {
        let spanned = self.next()?;
        match spanned.token {
            Token::Boolean(value) => Ok(Condition::Constant(value)),
            Token::Symbol('(') => {
                if depth >= MAX_NESTING {
                    return fail(spanned.offset, "acceptance condition nested too deeply");
                }
                let inner = self.condition(sets, depth + 1)?;
                self.expect_symbol(')', "to close the parenthesis")?;
                Ok(inner)
            }
            Token::Identifier(kind @ ("Inf" | "Fin")) => {
                self.expect_symbol('(', &format!("after `{kind}`"))?;
                let complemented = self.peek_is('!')?;
                if complemented {
                    self.next()?;
                }
                let (set, at) = self.expect_int("an acceptance set number")?;
                if set >= sets {
                    return fail(at, missing_set(set, sets));
                }
                self.expect_symbol(')', &format!("to close `{kind}(`"))?;
                Ok(Condition::Set {
                    infinitely: kind == "Inf",
                    complemented,
                    set,
                })
            }
            other => fail(
                spanned.offset,
                format!(
                    "expected `Inf(…)`, `Fin(…)`, `t`, `f` or `(` in the acceptance condition, \
                     found {other}"
                ),
            ),
        }
    }

    /// A label expression: `!` binds tighter than `&`, which binds tighter than `|`.
    fn label_expression(&mut self, depth: usize) -> Parsed<Label<'a>> {
        let operands = self.separated('|', |p| {
            let operands = p.separated('&', |p| p.label_atom(depth))?;
            Ok(single_or(operands, Label::And))
        })?;
        Ok(single_or(operands, Label::Or))
    }

    fn label_atom(&mut self, depth: usize) -> Parsed<Label<'a>> {
        let spanned = self.next()?;
        if matches!(spanned.token, Token::Symbol('!' | '(')) && depth >= MAX_NESTING {
            return fail(spanned.offset, "label nested too deeply");
        }
        match spanned.token {
            Token::Boolean(value) => Ok(Label::Constant(value)),
            Token::Int(index) => Ok(Label::Proposition {
                index,
                offset: spanned.offset,
            }),
            Token::Alias(name) => Ok(Label::Alias {
                name,
                offset: spanned.offset,
            }),
            Token::Symbol('!') => Ok(Label::Not(Box::new(self.label_atom(depth + 1)?))),
            Token::Symbol('(') => {
                let inner = self.label_expression(depth + 1)?;
                self.expect_symbol(')', "to close the parenthesis")?;
                Ok(inner)
            }
            other => fail(
                spanned.offset,
                format!(
                    "expected a proposition number, an alias, `t`, `f`, `!` or `(` in the label, \
                     found {other}"
                ),
            ),
        }
    }

    /// `[ label ]`, resolved, if the next token opens one.
    fn optional_label(&mut self, header: &Header<'a>) -> Parsed<Option<Guard>> {
        if !self.peek_is('[')? {
            return Ok(None);
        }
        self.next()?;
        let label = self.label_expression(0)?;
        self.expect_symbol(']', "to close the label")?;
        Ok(Some(resolve(&label, header.aps.len(), &header.aliases)?))
    }

    /// `{ set* }`, if the next token opens one: the acceptance sets listed (none otherwise).
    fn optional_marks(&mut self, header: &Header<'a>) -> Parsed<Vec<u32>> {
        let mut marks = Vec::new();
        if !self.peek_is('{')? {
            return Ok(marks);
        }
        self.next()?;
        loop {
            let spanned = self.next()?;
            match spanned.token {
                Token::Int(set) if set < header.sets => marks.push(set),
                Token::Int(set) => return fail(spanned.offset, missing_set(set, header.sets)),
                Token::Symbol('}') => return Ok(marks),
                other => {
                    return fail(
                        spanned.offset,
                        format!("expected an acceptance set number or `}}`, found {other}"),
                    );
                }
            }
        }
    }

    fn check_state(&self, state: u32, offset: usize, declared: Option<u32>) -> Parsed<()> {
        match declared {
            Some(n) if state >= n => fail(
                offset,
                format!("state {state} does not exist (`States: {n}`)"),
            ),
            None if state >= MAX_STATES => fail(
                offset,
                format!("state {state} is beyond the {MAX_STATES} states this reader accepts"),
            ),
            _ => Ok(()),
        }
    }

    /// The body: the kept edges of every state (indexed by state number, up to the largest
    /// number seen) and the largest state number referenced.
    fn body(&mut self, header: &Header<'a>) -> Parsed<(Vec<Vec<Edge>>, u32)> {
        let mut states: Vec<Vec<Edge>> = Vec::new();
        let mut declared_at: Vec<Option<usize>> = Vec::new();
        let mut max_state = 0;
        let mut open: Option<OpenState> = None;
        loop {
            let spanned = self.peek()?;
            match spanned.token {
                Token::Header("State") => {
                    self.next()?;
                    if let Some(state) = open.take() {
                        self.close_state(state, header, &mut states)?;
                    }
                    let label = self.optional_label(header)?;
                    let (number, at) = self.expect_int("a state number")?;
                    self.check_state(number, at, header.states)?;
                    max_state = max_state.max(number);
                    let slot = number as usize;
                    if declared_at.len() <= slot {
                        declared_at.resize(slot + 1, None);
                    }
                    if let Some(first) = declared_at[slot] {
                        return fail(
                            at,
                            format!(
                                "state {number} is declared twice (first at {})",
                                self.position(first)
                            ),
                        );
                    }
                    declared_at[slot] = Some(at);
                    if let Token::Str(_) = self.peek()?.token {
                        self.next()?;
                    }
                    let marks = self.optional_marks(header)?;
                    open = Some(OpenState {
                        number,
                        offset: spanned.offset,
                        marks,
                        labelling: label.map_or(Labelling::Undecided, Labelling::State),
                        listed: 0,
                        edges: Vec::new(),
                        covered: GuardUnion::new(),
                    });
                }
                Token::Int(_) | Token::Symbol('[') => {
                    let Some(state) = open.as_mut() else {
                        return fail(spanned.offset, "edge before the first `State:`");
                    };
                    let target = self.edge(state, header)?;
                    max_state = max_state.max(target);
                }
                Token::End => {
                    self.next()?;
                    if let Some(state) = open.take() {
                        self.close_state(state, header, &mut states)?;
                    }
                    return Ok((states, max_state));
                }
                Token::Eof => {
                    return fail(
                        spanned.offset,
                        "missing `--END--`: the input ends inside the automaton's body",
                    );
                }
                Token::Header("HOA") => {
                    return fail(spanned.offset, "missing `--END--` before the next `HOA:`");
                }
                other => {
                    return fail(
                        spanned.offset,
                        format!("expected `State:`, an edge or `--END--`, found {other}"),
                    );
                }
            }
        }
    }

    /// Reads one edge of `state`; returns its target.
    fn edge(&mut self, state: &mut OpenState, header: &Header<'a>) -> Parsed<u32> {
        let offset = self.peek()?.offset;
        let label = self.optional_label(header)?;
        let (target, at) = self.expect_int("a target state")?;
        self.check_state(target, at, header.states)?;
        let next = self.peek()?;
        if next.token == Token::Symbol('&') {
            return fail(
                next.offset,
                "universal branching (`&` in an edge's target) is not supported: a DFA has one \
                 successor per letter",
            );
        }
        let mut marks = self.optional_marks(header)?;
        marks.extend_from_slice(&state.marks);
        let accepting = header.acceptance.accepts(&marks);
        let index = state.listed;
        state.listed += 1;
        let k = header.aps.len() as u32;
        let guard = match (&state.labelling, label) {
            (Labelling::Undecided, Some(guard)) => {
                state.labelling = Labelling::Explicit;
                guard
            }
            (Labelling::Undecided | Labelling::Implicit, None) => {
                state.labelling = Labelling::Implicit;
                if 1u64.checked_shl(k).is_some_and(|n| index as u64 >= n) {
                    return fail(
                        offset,
                        format!(
                            "too many edges without labels: implicit labels give state {} \
                             exactly 2^{k} edges",
                            state.number
                        ),
                    );
                }
                implicit_label(index, k as usize)
            }
            (Labelling::Explicit, Some(guard)) => guard,
            (Labelling::Explicit, None) => {
                return fail(
                    offset,
                    "edge without a label in a state whose first edge has one",
                );
            }
            (Labelling::State(guard), None) => guard.clone(),
            (Labelling::State(_), Some(_)) => {
                return fail(offset, "labelled edge in a state that has a state label");
            }
            (Labelling::Implicit, Some(_)) => {
                return fail(
                    offset,
                    "labelled edge in a state whose first edge has no label (implicit labels)",
                );
            }
        };
        // `[f]` edges (and any unsatisfiable label) carry no letter: dropped.
        if !guard.is_satisfiable() {
            return Ok(target);
        }
        if !state.covered.insert(&guard) {
            // Only now look for the edge it overlaps.
            let other = state
                .edges
                .iter()
                .find(|(e, _)| e.guard.intersects(&guard))
                .map_or(offset, |&(_, other)| other);
            return fail(
                offset,
                format!(
                    "nondeterministic: this edge's label overlaps that of the edge at {} (state \
                     {})",
                    self.position(other),
                    state.number
                ),
            );
        }
        state.edges.push((
            Edge {
                guard,
                target,
                accepting,
            },
            offset,
        ));
        Ok(target)
    }

    fn close_state(
        &self,
        state: OpenState,
        header: &Header<'a>,
        states: &mut Vec<Vec<Edge>>,
    ) -> Parsed<()> {
        if let Labelling::Implicit = state.labelling {
            let k = header.aps.len() as u32;
            if 1u64.checked_shl(k) != Some(state.listed as u64) {
                return fail(
                    state.offset,
                    format!(
                        "state {} lists {} edges without labels; implicit labels need exactly \
                         2^{k} edges",
                        state.number, state.listed
                    ),
                );
            }
        }
        let slot = state.number as usize;
        if states.len() <= slot {
            states.resize_with(slot + 1, Vec::new);
        }
        states[slot] = state.edges.into_iter().map(|(edge, _)| edge).collect();
        Ok(())
    }
}

/// The only operand, or `combine` of all of them.
fn single_or<T>(mut operands: Vec<T>, combine: impl FnOnce(Vec<T>) -> T) -> T {
    if operands.len() == 1 {
        operands.pop().expect("one operand")
    } else {
        combine(operands)
    }
}

fn single_or_compound(operands: Vec<Condition>) -> Condition {
    single_or(operands, |_| Condition::Compound)
}

fn missing_set(set: u32, sets: u32) -> String {
    let plural = if sets == 1 { "" } else { "s" };
    format!("acceptance set {set} does not exist (`Acceptance:` declares {sets} set{plural})")
}

/// The valuation `index` (bit `j` = proposition `j`) as a full cube over `k` propositions.
fn implicit_label(index: usize, k: usize) -> Guard {
    let all = if k == MAX_PROPOSITIONS {
        u64::MAX
    } else {
        (1u64 << k) - 1
    };
    let positive = index as u64 & all;
    Guard::from_cubes([Cube {
        positive,
        negative: all & !positive,
    }])
}

/// The guard of a label, given the number of propositions and the aliases defined so far. The
/// whole label is built in one BDD manager: a disjunction of `k` cubes costs `k` cube-sized
/// operations, not `k` operations on a growing guard.
fn resolve(label: &Label<'_>, aps: usize, aliases: &Aliases<'_>) -> Result<Guard, Located> {
    let mut bdd = Bdd::new();
    let node = resolve_into(&mut bdd, label, aps, aliases)?;
    Ok(Guard::export(&bdd, node))
}

/// [`resolve`] into `bdd`; recursion as deep as the label's nesting ([`MAX_NESTING`]).
fn resolve_into(
    bdd: &mut Bdd,
    label: &Label<'_>,
    aps: usize,
    aliases: &Aliases<'_>,
) -> Result<Node, Located> {
    Ok(match label {
        Label::Constant(true) => bdd::TRUE,
        Label::Constant(false) => bdd::FALSE,
        Label::Proposition { index, offset } => {
            if *index as usize >= aps {
                let plural = if aps == 1 { "" } else { "s" };
                return Err(Located::new(
                    *offset,
                    format!(
                        "atomic proposition {index} does not exist (`AP:` declares {aps} \
                         proposition{plural})"
                    ),
                ));
            }
            bdd.var(*index)
        }
        Label::Alias { name, offset } => match aliases.get(name) {
            Some(guard) => guard.import(bdd),
            None => {
                return Err(Located::new(*offset, format!("undefined alias `@{name}`")));
            }
        },
        Label::Not(inner) => {
            let inner = resolve_into(bdd, inner, aps, aliases)?;
            bdd.not(inner)
        }
        Label::And(operands) => operands.iter().try_fold(bdd::TRUE, |acc, operand| {
            let operand = resolve_into(bdd, operand, aps, aliases)?;
            Ok(bdd.and(acc, operand))
        })?,
        Label::Or(operands) => operands.iter().try_fold(bdd::FALSE, |acc, operand| {
            let operand = resolve_into(bdd, operand, aps, aliases)?;
            Ok(bdd.or(acc, operand))
        })?,
    })
}
