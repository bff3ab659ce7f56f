//! The HOA reader: text in the HOA v1 format to DFAs of good prefixes.
//!
//! Accepted: what Spot and other tools write for deterministic terminal automata (see the module
//! documentation of [`super`] for the subset and the rules). The reader checks rather than
//! trusts: determinism is established by intersecting the guards of each state's edges, whatever
//! `properties:` claims. Nothing here panics, whatever the input: nesting of labels and acceptance
//! conditions is bounded ([`MAX_NESTING`]), and so is the number of states ([`MAX_STATES`]).
//!
//! Errors carry a line and a column and do not stop the reading (see [`parse_with_limit`] for
//! where it resumes). Two kinds are told apart: an error *of meaning* (a state out of range,
//! overlapping labels, a header given twice...) is found once the construct is read, so the
//! reader records it and goes on; a *syntax* error leaves the reader in the middle of something,
//! so it records it and skips to a point it can resume from.

use std::collections::{HashMap, HashSet};

use crate::automata::guard::GuardUnion;
use crate::automata::{Cube, Dfa, DfaState, Guard, MAX_PROPOSITIONS};
use crate::bdd::{self, Bdd, Node};
use crate::diagnostic::{Collector, DEFAULT_LIMIT, Diagnostic, Diagnostics, brief};
use crate::position::{Locator, Position};

use super::build::{Declared, Edge, to_dfa};
use super::lexer::{Lexer, Located, Spanned, Token};

/// The largest number of states an automaton may declare or reference.
pub const MAX_STATES: u32 = 1 << 20;

/// The deepest nesting of `!` and parentheses in a label or acceptance condition.
pub const MAX_NESTING: usize = 100;

/// One reason why a HOA text could not be read, and where.
pub type HoaError = Diagnostic;

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
/// format requires). A text with no complete automaton is an error. On errors, the first 20 in
/// text order (see [`parse_with_limit`]).
pub fn parse(text: &str) -> Result<Vec<HoaAutomaton>, Diagnostics> {
    parse_with_limit(text, DEFAULT_LIMIT)
}

/// [`parse`], keeping at most `limit` errors (the others are counted).
///
/// After a syntax error the reader resumes: in the header, at the next header item; in a
/// `State:` line, at the next `State:` (its edges are skipped); in an edge, at the next line;
/// between automata, at the next `HOA:`; after a lexical error, at the next line (after an
/// unterminated string or comment, nowhere). The body is read only after a header without
/// errors: its meaning depends on the header (the numbers of propositions, acceptance sets and
/// states, the aliases), so after a broken header most of its errors would be consequences. In
/// one state, only the first overlap of labels is reported (finding the edge it overlaps costs
/// a pass over the state's edges). The errors of an automaton aborted with `--ABORT--` are
/// dropped with it.
pub fn parse_with_limit(text: &str, limit: usize) -> Result<Vec<HoaAutomaton>, Diagnostics> {
    let mut parser = Parser {
        lexer: Lexer::new(text),
        locator: Locator::new(text),
        limit,
        errors: Collector::new(limit),
        bdd: Bdd::new(),
    };
    let mut all_errors = Collector::new(limit);
    let mut automata = Vec::new();
    let mut last_abort = None;
    loop {
        let next = match parser.lexer.peek() {
            Ok(next) => next.clone(),
            Err(error) => {
                parser.error(error.offset, error.message);
                parser.lexer.skip_line(error.offset);
                all_errors.absorb(parser.take_errors());
                continue;
            }
        };
        if next.token == Token::Eof {
            if !all_errors.is_empty() || !automata.is_empty() {
                return all_errors.or_ok(automata);
            }
            let (offset, message) = match last_abort {
                Some(offset) => (
                    offset,
                    "no automaton: every automaton of the input was aborted with `--ABORT--`",
                ),
                None => (next.offset, "expected `HOA:`, found the end of the input"),
            };
            parser.error(offset, message.to_string());
            return Err(parser.take_errors().failed());
        }
        match parser.automaton() {
            Ok(Some(automaton)) => automata.push(automaton),
            Ok(None) => {}
            Err(Failure::Aborted(offset)) => {
                // Its errors go with it.
                parser.take_errors();
                last_abort = Some(offset);
                continue;
            }
            Err(Failure::Syntax(error)) => {
                // Not an automaton: go on at the next `HOA:` (a `--ABORT--` on the way aborts
                // nothing).
                parser.error(error.offset, error.message);
                if let Err(Failure::Aborted(offset)) =
                    parser.skip_until(|token| *token == Token::Header("HOA"))
                {
                    last_abort = Some(offset);
                }
            }
        }
        all_errors.absorb(parser.take_errors());
    }
}

/// Why reading stopped: a syntax error (to be reported, then resumed after), or `--ABORT--` at
/// the given offset.
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

/// The aliases resolved so far: their functions as nodes of the parser's manager (see
/// [`Parser::bdd`]), found by name through a hash map (a header may define very many).
#[derive(Default)]
struct Aliases<'a> {
    nodes: HashMap<&'a str, Node>,
}

impl Aliases<'_> {
    fn get(&self, name: &str) -> Option<Node> {
        self.nodes.get(name).copied()
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
    /// The edges kept (satisfiable labels), with their positions.
    edges: Vec<(Edge, Position)>,
    /// The union of their labels, which checks determinism without comparing pairs of edges.
    covered: GuardUnion,
    /// Whether an error about the state's edges as a whole (too many implicit labels, an
    /// overlap) was reported: it is not reported again for its later edges.
    reported: bool,
}

/// How reading a header ended.
enum HeaderEnd<'a> {
    /// A header without errors; the body follows.
    Read(Header<'a>),
    /// A header with errors (reported); its body, if any, is to be skipped.
    Broken,
    /// The automaton ended in its header (errors reported).
    Over,
}

/// What the header items say so far.
#[derive(Default)]
struct HeaderItems<'a> {
    name: Option<String>,
    states: Option<u32>,
    starts: Vec<(u32, usize)>,
    /// Whether a `Start:` item was given, well-formed or not.
    start_given: bool,
    aps: Option<Vec<String>>,
    aliases: Vec<(&'a str, Label<'a>)>,
    alias_names: HashSet<&'a str>,
    acceptance: Option<(u32, Acceptance)>,
    /// The items that may be given once, as given.
    once: Vec<&'a str>,
}

struct Parser<'a> {
    lexer: Lexer<'a>,
    locator: Locator<'a>,
    limit: usize,
    /// The errors of the automaton being read (dropped with it if it is aborted).
    errors: Collector<String>,
    /// The manager every alias and label of the text is resolved in: an alias is a node there,
    /// so using it costs nothing, and its tables and cache serve every label. (An alias kept
    /// as a guard, imported into a fresh manager by each label or alias using it, made the
    /// writer's one alias per node of a guard quadratic in the guard's size.)
    bdd: Bdd,
}

/// Whether `token` starts a header item or ends the header: where reading resumes after a
/// syntax error in the header.
fn ends_header_item(token: &Token<'_>) -> bool {
    matches!(token, Token::Header(_) | Token::Body | Token::End)
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

    /// The next token if it is `symbol` (any other is left to be read again after the error).
    fn expect_symbol(&mut self, symbol: char, context: &str) -> Parsed<usize> {
        let spanned = self.peek()?;
        if spanned.token != Token::Symbol(symbol) {
            return fail(
                spanned.offset,
                format!("expected `{symbol}` {context}, found {}", spanned.token),
            );
        }
        self.next()?;
        Ok(spanned.offset)
    }

    /// The value `take` finds in the next token, and its offset; a token it refuses is left
    /// to be read again after the error (`expected WHAT, found ...`).
    fn expect<T>(
        &mut self,
        what: &str,
        take: impl FnOnce(Token<'a>) -> Option<T>,
    ) -> Parsed<(T, usize)> {
        let spanned = self.peek()?;
        let Some(value) = take(spanned.token.clone()) else {
            let found = &spanned.token;
            return fail(spanned.offset, format!("expected {what}, found {found}"));
        };
        self.next()?;
        Ok((value, spanned.offset))
    }

    /// The next token if it is an integer.
    fn expect_int(&mut self, what: &str) -> Parsed<(u32, usize)> {
        self.expect(what, |token| match token {
            Token::Int(value) => Some(value),
            _ => None,
        })
    }

    fn position(&mut self, offset: usize) -> Position {
        self.locator.position(offset)
    }

    /// Records an error at `offset`: one of meaning, or a syntax error being recovered from.
    fn error(&mut self, offset: usize, message: impl Into<String>) {
        let position = self.position(offset);
        self.errors.add(position, message.into());
    }

    /// The errors of the automaton read, leaving none for the next.
    fn take_errors(&mut self) -> Collector<String> {
        std::mem::replace(&mut self.errors, Collector::new(self.limit))
    }

    /// Skips tokens (and, silently, lines with lexical errors) up to the first one for which
    /// `stop` holds, or the end of the input; that token is not consumed.
    fn skip_until(&mut self, stop: impl Fn(&Token<'a>) -> bool) -> Parsed<()> {
        loop {
            match self.lexer.peek() {
                Err(error) => {
                    let offset = error.offset;
                    self.lexer.skip_line(offset);
                }
                Ok(spanned) if spanned.token == Token::Eof || stop(&spanned.token) => {
                    return Ok(());
                }
                Ok(_) => {
                    self.next()?;
                }
            }
        }
    }

    /// Skips the rest of an automaton: up to its `--END--` (consumed) or the next `HOA:`.
    fn skip_automaton(&mut self) -> Parsed<()> {
        self.skip_until(|token| matches!(token, Token::End | Token::Header("HOA")))?;
        if self.peek()?.token == Token::End {
            self.next()?;
        }
        Ok(())
    }

    /// Reads one automaton; `None` if it has errors (recorded in `self.errors`). A syntax error
    /// is returned only when the next token is not `HOA:` (nothing is consumed then).
    fn automaton(&mut self) -> Parsed<Option<HoaAutomaton>> {
        let first = self.peek()?;
        if first.token != Token::Header("HOA") {
            return fail(
                first.offset,
                format!("expected `HOA:`, found {}", first.token),
            );
        }
        self.next()?;
        let version = self.lexer.next_version()?;
        let version_error = match version.token {
            Token::Identifier(v) if v == "v1" || v.starts_with("v1.") => None,
            Token::Identifier(v) => Some(format!(
                "unsupported HOA version `{}` (this reader knows v1)",
                brief(v)
            )),
            Token::Abort => return Err(Failure::Aborted(version.offset)),
            other => Some(format!(
                "expected the format version after `HOA:`, found {other}"
            )),
        };
        if let Some(message) = version_error {
            // Not an automaton this reader can make sense of.
            self.error(version.offset, message);
            self.skip_automaton()?;
            return Ok(None);
        }
        let header = match self.header(first.offset)? {
            HeaderEnd::Read(header) => header,
            HeaderEnd::Broken => {
                self.skip_automaton()?;
                return Ok(None);
            }
            HeaderEnd::Over => return Ok(None),
        };
        let Some((states, max_state)) = self.body(&header)? else {
            return Ok(None);
        };
        if !self.errors.is_empty() {
            return Ok(None);
        }
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
        match to_dfa(declared) {
            Ok((dfa, sink)) => Ok(Some(HoaAutomaton {
                name: header.name,
                dfa,
                declared_states: num_states as usize,
                declared_edges,
                sink,
            })),
            Err(error) => {
                // The reader checks everything the DFA constructor checks; this is a safety net.
                self.error(header.offset, error.to_string());
                Ok(None)
            }
        }
    }

    /// The header, after `HOA: v1`, up to and including `--BODY--`. A syntax error in an item
    /// is recorded, and reading goes on at the next item.
    fn header(&mut self, offset: usize) -> Parsed<HeaderEnd<'a>> {
        let errors_before = self.errors.total();
        let mut items = HeaderItems::default();
        let body_offset = loop {
            let item = match self.peek() {
                Ok(item) => item,
                Err(Failure::Syntax(error)) => {
                    self.error(error.offset, error.message);
                    self.skip_until(ends_header_item)?;
                    continue;
                }
                Err(abort) => return Err(abort),
            };
            let header = match item.token {
                Token::Header("HOA") => {
                    // Left for the next automaton to start with.
                    self.error(item.offset, "`HOA:` is given twice (missing `--BODY--`?)");
                    return Ok(HeaderEnd::Over);
                }
                Token::Header("State") => {
                    self.error(item.offset, "missing `--BODY--` before `State:`");
                    return Ok(HeaderEnd::Broken);
                }
                Token::Header(header) => header,
                Token::Body => {
                    self.next()?;
                    break item.offset;
                }
                Token::Eof => {
                    self.error(
                        item.offset,
                        "missing `--BODY--`: the input ends inside the header",
                    );
                    return Ok(HeaderEnd::Over);
                }
                Token::End => {
                    self.next()?;
                    self.error(
                        item.offset,
                        "expected a header item or `--BODY--`, found `--END--`",
                    );
                    return Ok(HeaderEnd::Over);
                }
                other => {
                    self.error(
                        item.offset,
                        format!("expected a header item or `--BODY--`, found {other}"),
                    );
                    self.skip_until(ends_header_item)?;
                    continue;
                }
            };
            self.next()?;
            match self.header_item(header, item.offset, &mut items) {
                Ok(()) => {}
                Err(Failure::Syntax(error)) => {
                    self.error(error.offset, error.message);
                    self.skip_until(ends_header_item)?;
                }
                Err(abort) => return Err(abort),
            }
        };
        // Items given but malformed are reported already: not as missing too.
        if items.acceptance.is_none() && !items.once.contains(&"Acceptance") {
            self.error(
                body_offset,
                "missing `Acceptance:` header before `--BODY--` (it is mandatory)",
            );
        }
        let aps = items.aps.unwrap_or_default();
        let mut resolved = Aliases::default();
        for (alias, label) in items.aliases {
            // An alias may only use the aliases defined before it.
            let node = match resolve_into(&mut self.bdd, &label, aps.len(), &resolved) {
                Ok(node) => node,
                Err(error) => {
                    self.error(error.offset, error.message);
                    bdd::FALSE
                }
            };
            resolved.nodes.insert(alias, node);
        }
        if !items.start_given {
            self.error(
                body_offset,
                "no `Start:` header before `--BODY--`: a DFA needs one initial state",
            );
        }
        let initial = items.starts.first().map_or(0, |&(state, _)| state);
        for &(state, at) in &items.starts {
            if let Some(message) = state_error(state, items.states) {
                self.error(at, message);
            } else if state != initial {
                self.error(
                    at,
                    format!(
                        "several initial states ({initial} and {state}): a DFA has exactly one"
                    ),
                );
            }
        }
        let (Some((sets, acceptance)), false) = (items.acceptance, items.starts.is_empty()) else {
            return Ok(HeaderEnd::Broken);
        };
        if self.errors.total() > errors_before {
            return Ok(HeaderEnd::Broken);
        }
        Ok(HeaderEnd::Read(Header {
            offset,
            name: items.name,
            states: items.states,
            initial,
            aps,
            aliases: resolved,
            sets,
            acceptance,
        }))
    }

    /// One header item, after its name. Errors of meaning are recorded (the item is read on);
    /// a syntax error is returned.
    fn header_item(
        &mut self,
        header: &'a str,
        offset: usize,
        items: &mut HeaderItems<'a>,
    ) -> Parsed<()> {
        let single = matches!(
            header,
            "HOA" | "States" | "AP" | "Acceptance" | "name" | "tool" | "acc-name"
        );
        if single {
            if items.once.contains(&header) {
                self.error(offset, format!("`{}:` is given twice", brief(header)));
                return self.skip_values();
            }
            items.once.push(header);
        }
        match header {
            "States" => {
                let (n, at) = self.expect_int("a number of states")?;
                if n > MAX_STATES {
                    self.error(
                        at,
                        format!("{n} states are more than the {MAX_STATES} this reader accepts"),
                    );
                } else {
                    items.states = Some(n);
                }
            }
            "Start" => {
                items.start_given = true;
                let (state, at) = self.expect_int("an initial state")?;
                let next = self.peek()?;
                if next.token == Token::Symbol('&') {
                    return fail(
                        next.offset,
                        "universal branching (`&` in `Start:`) is not supported: a DFA has \
                         one initial state",
                    );
                }
                items.starts.push((state, at));
            }
            "AP" => items.aps = Some(self.propositions(offset)?),
            "Alias" => {
                let (alias, at) = self.expect("an alias name (`@name`)", |token| match token {
                    Token::Alias(alias) => Some(alias),
                    _ => None,
                })?;
                let label = self.label_expression(0)?;
                if items.alias_names.insert(alias) {
                    items.aliases.push((alias, label));
                } else {
                    self.error(at, format!("alias `@{}` is defined twice", brief(alias)));
                }
            }
            "Acceptance" => items.acceptance = Some(self.acceptance()?),
            "name" => {
                let (value, _) = self.expect("a string after `name:`", |token| match token {
                    Token::Str(value) => Some(value),
                    _ => None,
                })?;
                items.name = Some(value);
            }
            _ if header.starts_with(|c: char| c.is_ascii_uppercase()) => {
                self.error(
                    offset,
                    format!(
                        "unknown header `{}:` (a header starting with an upper-case \
                         letter may change the automaton's meaning, so it cannot be ignored)",
                        brief(header)
                    ),
                );
                self.skip_values()?;
            }
            // `tool:`, `acc-name:`, `properties:` and other lower-case headers are
            // informative only: their values are skipped.
            _ => self.skip_values()?,
        }
        Ok(())
    }

    /// `AP:` count and names.
    fn propositions(&mut self, offset: usize) -> Parsed<Vec<String>> {
        let (count, count_at) = self.expect_int("the number of atomic propositions")?;
        let mut names: Vec<String> = Vec::new();
        let mut seen: HashSet<String> = HashSet::new();
        while let Token::Str(name) = self.peek()?.token {
            let at = self.next()?.offset;
            if !seen.insert(name.clone()) {
                return fail(
                    at,
                    format!(
                        "atomic proposition {} is listed twice",
                        brief(format_args!("{name:?}"))
                    ),
                );
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
        let node = resolve_into(&mut self.bdd, &label, header.aps.len(), &header.aliases)?;
        Ok(Some(Guard::export(&self.bdd, node)))
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

    /// The body, up to and including `--END--`: the kept edges of every state (indexed by
    /// state number, up to the largest number seen) and the largest state number referenced;
    /// `None` if the automaton ends without `--END--`. Errors are recorded; after a syntax
    /// error reading goes on at the next `State:` (in a `State:` line) or the next line (in an
    /// edge).
    fn body(&mut self, header: &Header<'a>) -> Parsed<Option<(Vec<Vec<Edge>>, u32)>> {
        let mut states: Vec<Vec<Edge>> = Vec::new();
        let mut declared_at: Vec<Option<Position>> = Vec::new();
        let mut max_state = 0;
        let mut open: Option<OpenState> = None;
        loop {
            let spanned = match self.peek() {
                Ok(spanned) => spanned,
                Err(Failure::Syntax(error)) => {
                    self.error(error.offset, error.message);
                    self.lexer.skip_line(error.offset);
                    continue;
                }
                Err(abort) => return Err(abort),
            };
            match spanned.token {
                Token::Header("State") => {
                    self.next()?;
                    if let Some(state) = open.take() {
                        self.close_state(state, header, &mut states);
                    }
                    match self.state(spanned.offset, header, &mut declared_at) {
                        Ok(state) => {
                            max_state = max_state.max(state.number);
                            open = Some(state);
                        }
                        Err(Failure::Syntax(error)) => {
                            // Its edges are skipped.
                            self.error(error.offset, error.message);
                            self.skip_until(|token| {
                                matches!(token, Token::Header("State" | "HOA") | Token::End)
                            })?;
                        }
                        Err(abort) => return Err(abort),
                    }
                }
                Token::Int(_) | Token::Symbol('[') => {
                    let Some(state) = open.as_mut() else {
                        self.error(spanned.offset, "edge before the first `State:`");
                        self.lexer.skip_line(spanned.offset);
                        continue;
                    };
                    match self.edge(state, header) {
                        Ok(target) => max_state = max_state.max(target),
                        Err(Failure::Syntax(error)) => {
                            self.error(error.offset, error.message);
                            self.lexer.skip_line(spanned.offset);
                        }
                        Err(abort) => return Err(abort),
                    }
                }
                Token::End => {
                    self.next()?;
                    if let Some(state) = open.take() {
                        self.close_state(state, header, &mut states);
                    }
                    return Ok(Some((states, max_state)));
                }
                Token::Eof => {
                    self.error(
                        spanned.offset,
                        "missing `--END--`: the input ends inside the automaton's body",
                    );
                    return Ok(None);
                }
                Token::Header("HOA") => {
                    // Left for the next automaton to start with.
                    self.error(spanned.offset, "missing `--END--` before the next `HOA:`");
                    return Ok(None);
                }
                other => {
                    self.error(
                        spanned.offset,
                        format!("expected `State:`, an edge or `--END--`, found {other}"),
                    );
                    self.lexer.skip_line(spanned.offset);
                }
            }
        }
    }

    /// A `State:` line after `State:` (at `offset`). A state number out of range is returned
    /// as a syntax error, so that its edges are skipped.
    fn state(
        &mut self,
        offset: usize,
        header: &Header<'a>,
        declared_at: &mut Vec<Option<Position>>,
    ) -> Parsed<OpenState> {
        let label = self.optional_label(header)?;
        let (number, at) = self.expect_int("a state number")?;
        if let Some(message) = state_error(number, header.states) {
            return fail(at, message);
        }
        let slot = number as usize;
        if declared_at.len() <= slot {
            declared_at.resize(slot + 1, None);
        }
        let position = self.position(at);
        match declared_at[slot] {
            Some(first) => self.error(
                at,
                format!("state {number} is declared twice (first at {first})"),
            ),
            None => declared_at[slot] = Some(position),
        }
        if let Token::Str(_) = self.peek()?.token {
            self.next()?;
        }
        let marks = self.optional_marks(header)?;
        Ok(OpenState {
            number,
            offset,
            marks,
            labelling: label.map_or(Labelling::Undecided, Labelling::State),
            listed: 0,
            edges: Vec::new(),
            covered: GuardUnion::new(),
            reported: false,
        })
    }

    /// Reads one edge of `state`; returns its target. An edge that breaks a rule once read
    /// (labelling, determinism) is recorded as an error and dropped; a syntax error, or a
    /// target out of range, is returned.
    fn edge(&mut self, state: &mut OpenState, header: &Header<'a>) -> Parsed<u32> {
        let offset = self.peek()?.offset;
        let label = self.optional_label(header)?;
        let (target, at) = self.expect_int("a target state")?;
        if let Some(message) = state_error(target, header.states) {
            return fail(at, message);
        }
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
                    if !state.reported {
                        state.reported = true;
                        self.error(
                            offset,
                            format!(
                                "too many edges without labels: implicit labels give state {} \
                                 exactly 2^{k} edges",
                                state.number
                            ),
                        );
                    }
                    return Ok(target);
                }
                implicit_label(index, k as usize)
            }
            (Labelling::Explicit, Some(guard)) => guard,
            (Labelling::Explicit, None) => {
                self.error(
                    offset,
                    "edge without a label in a state whose first edge has one",
                );
                return Ok(target);
            }
            (Labelling::State(guard), None) => guard.clone(),
            (Labelling::State(_), Some(_)) => {
                self.error(offset, "labelled edge in a state that has a state label");
                return Ok(target);
            }
            (Labelling::Implicit, Some(_)) => {
                self.error(
                    offset,
                    "labelled edge in a state whose first edge has no label (implicit labels)",
                );
                return Ok(target);
            }
        };
        // `[f]` edges (and any unsatisfiable label) carry no letter: dropped.
        if !guard.is_satisfiable() {
            return Ok(target);
        }
        let position = self.position(offset);
        if !state.covered.insert(&guard) {
            if !state.reported {
                state.reported = true;
                // Only now look for the edge it overlaps.
                let other = state
                    .edges
                    .iter()
                    .find(|(e, _)| e.guard.intersects(&guard))
                    .map_or(position, |&(_, other)| other);
                self.error(
                    offset,
                    format!(
                        "nondeterministic: this edge's label overlaps that of the edge at \
                         {other} (state {})",
                        state.number
                    ),
                );
            }
            return Ok(target);
        }
        state.edges.push((
            Edge {
                guard,
                target,
                accepting,
            },
            position,
        ));
        Ok(target)
    }

    /// Stores the edges of a state once all are read (checking the number of implicit labels).
    fn close_state(&mut self, state: OpenState, header: &Header<'a>, states: &mut Vec<Vec<Edge>>) {
        if let Labelling::Implicit = state.labelling {
            let k = header.aps.len() as u32;
            if 1u64.checked_shl(k) != Some(state.listed as u64) && !state.reported {
                self.error(
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
    }
}

/// Why `state` cannot be a state number, given the number of states declared, if it cannot.
fn state_error(state: u32, declared: Option<u32>) -> Option<String> {
    match declared {
        Some(n) if state >= n => Some(format!("state {state} does not exist (`States: {n}`)")),
        None if state >= MAX_STATES => Some(format!(
            "state {state} is beyond the {MAX_STATES} states this reader accepts"
        )),
        _ => None,
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

/// The function of a label in `bdd`, given the number of propositions and the aliases defined
/// so far. The whole label is built in the one manager: a disjunction of `k` cubes costs `k`
/// cube-sized operations, not `k` operations on a growing guard. Recursion as deep as the
/// label's nesting ([`MAX_NESTING`]).
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
            Some(node) => node,
            None => {
                return Err(Located::new(
                    *offset,
                    format!("undefined alias `@{}`", brief(name)),
                ));
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
