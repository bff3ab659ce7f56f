//! The reader of the arena format (`grammar/arena.ebnf`, docs/formats.md): text → [`Arena`].
//!
//! The format has one item per line, so the reader is a hand-written lexer over lines, not a
//! parser combinator: it allocates only for what the arena keeps (names, labels) and for quoted
//! names that contain escapes; everything else borrows from the text.
//!
//! Reading takes two passes over the text, so that `edge` and `initial` lines may name states
//! defined further down without the reader keeping a record per edge:
//! 1. every line's syntax is checked; declarations and states go into the [`ArenaBuilder`];
//! 2. `initial` and `edge` lines are read again and their state names resolved.
//!
//! Errors do not stop the reading: every line is read, and the errors of both passes are
//! returned together in file order, up to a limit (the others are counted). A line is read up
//! to its first syntax error (the rest of a line after one is not trusted); errors of meaning
//! within a line (a name declared twice, a proposition repeated or undeclared) do not stop it.
//! So that one error does not cause others, pass two skips the lines pass one found malformed
//! and the `initial` lines after the first, a state whose `state` line is malformed counts as
//! defined (edges naming it are not checked further), and a malformed `propositions` or
//! `actions` line turns off the check that names are declared. Every stuck and every unreachable
//! state is returned with the arena ([`Parsed::warnings`], for a detailed listing), and
//! [`summarise`] counts them in one line per kind.

use std::borrow::Cow;
use std::fmt;

use crate::diagnostic::{Collector, DEFAULT_LIMIT, Diagnostic, Diagnostics, brief};
use crate::position::Position;
use crate::stage::{Meter, Stage};

use super::model::{Arena, ArenaBuilder, BuildError, HashSet, Owner, StateId};
use super::syntax::{self, Name, QuoteError, Quoted, lines};

/// A successfully read arena with the warnings about it.
#[derive(Clone, Debug)]
pub struct Parsed {
    /// The arena read.
    pub arena: Arena,
    /// Every stuck state, then every unreachable state, each in file order ([`defects`]), located
    /// at their `state` lines; [`summarise`] counts them.
    pub warnings: Vec<Warning>,
}

/// One reason why a text is not an arena, and where: `message` is the kind of error.
pub type ParseError = Diagnostic<ParseErrorKind>;

/// What is wrong in an arena text; its `Display` is the message.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ParseErrorKind {
    /// A quoted name is not closed on its line.
    #[error("unterminated quoted name: the closing `\"` is missing on this line")]
    UnterminatedQuote,
    /// A backslash in a quoted name escapes the given letter, which has no escape.
    #[error(
        "unknown escape `\\{}` in a quoted name (the escapes are `\\\\`, `\\\"`, `\\n`, `\\r` \
         and `\\t`)",
        .0.escape_debug()
    )]
    UnknownEscape(char),
    /// A character, given, that cannot start a token here (names with it must be quoted).
    #[error(
        "unexpected character `{}`: a name with characters other than letters, digits, `_`, \
         `.` and `-` must be double-quoted",
        .0.escape_debug()
    )]
    UnexpectedCharacter(char),
    /// Two tokens are not separated by a space before the given character.
    #[error("missing space before `{}`", .0.escape_debug())]
    MissingSpace(char),
    /// The text at this place is not what the syntax allows.
    #[error("expected {expected}, found {found}")]
    Expected {
        /// What the syntax allows, in words.
        expected: &'static str,
        /// What was found, in words or quoted.
        found: String,
    },
    /// A line that may appear once (`propositions`, `actions`, `initial`) appears again.
    #[error("second `{item}` line (the first is on line {first_line})")]
    RepeatedLine {
        /// The line's keyword.
        item: &'static str,
        /// The line of its first occurrence.
        first_line: usize,
    },
    /// A declaration line comes after the first `state` or `edge` line.
    #[error("`{item}` must come before the first `state` or `edge` line (line {line})")]
    LateDeclaration {
        /// The declaration's keyword: `propositions` or `actions`.
        item: &'static str,
        /// The line of the first `state` or `edge` line.
        line: usize,
    },
    /// A name declared twice on a declaration line.
    #[error("{what} `{}` is declared twice", Name(.name))]
    DeclaredTwice {
        /// What the name is: `proposition` or `action`.
        what: &'static str,
        /// The name.
        name: String,
    },
    /// A proposition repeated in one state's label; its name.
    #[error("proposition `{}` appears twice in the label", Name(.0))]
    RepeatedInLabel(String),
    /// A name is used in a `state` or `edge` line but missing from its declaration line.
    #[error("{what} `{}` is not declared on the `{item}` line (line {line})", Name(.name))]
    Undeclared {
        /// What the name is: `proposition` or `action`.
        what: &'static str,
        /// The name.
        name: String,
        /// The declaration line's keyword: `propositions` or `actions`.
        item: &'static str,
        /// The number of the declaration line.
        line: usize,
    },
    /// Two `state` lines define one name.
    #[error("state `{}` is already defined on line {first_line}", Name(.name))]
    DuplicateState {
        /// The state's name.
        name: String,
        /// The line of the first definition.
        first_line: usize,
    },
    /// An `initial` or `edge` line names a state that no `state` line defines; the name.
    #[error("state `{}` is not defined", Name(.0))]
    UnknownState(String),
    /// A state has two `edge` lines with the same action.
    #[error(
        "state `{}` already has a successor for action `{}` (line {first_line})",
        Name(.state),
        Name(.action)
    )]
    DuplicateTransition {
        /// The state's name.
        state: String,
        /// The action's name.
        action: String,
        /// The line of the first of the two edges.
        first_line: usize,
    },
    /// The text has no `initial` line.
    #[error("no `initial` line: the initial state must be declared")]
    MissingInitial,
    /// The arena builder refused the arena.
    #[error(transparent)]
    Build(#[from] BuildError),
}

/// Something suspicious but legal about a state, located at its name in its `state` line when
/// the arena was read from a text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Warning {
    /// The position of the state's name in its `state` line; `None` for an arena built in
    /// memory (from a map, say).
    pub position: Option<Position>,
    /// The state.
    pub state: StateId,
    /// The state's name.
    pub name: String,
    /// What is suspicious.
    pub kind: WarningKind,
}

/// What a [`Warning`] is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WarningKind {
    /// No enabled action: its owner is stuck there (docs/semantics.md §3).
    Stuck(Owner),
    /// Not reachable from the initial state.
    Unreachable,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = Name(&self.name);
        if let Some(position) = self.position {
            write!(f, "{position}: ")?;
        }
        match self.kind {
            WarningKind::Stuck(Owner::Robot) => write!(
                f,
                "robot state `{name}` has no enabled action: the robot is stuck there and \
                 cannot progress"
            ),
            WarningKind::Stuck(Owner::Adversary) => write!(
                f,
                "adversary state `{name}` has no enabled action: the adversary is stuck there, \
                 which counts as a win for the robot whatever its task"
            ),
            WarningKind::Unreachable => {
                write!(f, "state `{name}` is unreachable from the initial state")
            }
        }
    }
}

/// Every stuck state, then every state unreachable from the initial state, each in state order,
/// without positions (an arena built in memory has no text to point into). Linear in the
/// arena's size.
pub fn defects(arena: &Arena) -> Vec<Warning> {
    located_defects(arena, |_| None)
}

/// [`defects`], each located by `position`.
fn located_defects(arena: &Arena, position: impl Fn(StateId) -> Option<Position>) -> Vec<Warning> {
    let warning = |state: StateId, kind| Warning {
        position: position(state),
        state,
        name: arena.name(state).to_string(),
        kind,
    };
    let mut warnings: Vec<Warning> = arena
        .stuck_states()
        .map(|s| warning(s, WarningKind::Stuck(arena.owner(s))))
        .collect();
    let reachable = arena.reachable_states();
    warnings.extend(
        arena
            .states()
            .filter(|&s| !reachable.contains(s.index()))
            .map(|s| warning(s, WarningKind::Unreachable)),
    );
    warnings
}

/// One warning line about an arena: how many of its states are of one [`WarningKind`], how
/// many of those the initial state reaches, and the first of them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Summary {
    /// The kind.
    pub kind: WarningKind,
    /// How many states are of it.
    pub count: usize,
    /// How many of them are reachable from the initial state (0 for unreachable states).
    pub reachable: usize,
    /// The first, in the order of [`defects`].
    pub first: Warning,
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (count, plural) = (self.count, self.count != 1);
        let states = if plural { "states" } else { "state" };
        match self.kind {
            WarningKind::Stuck(owner) => {
                let (who, consequence) = match owner {
                    Owner::Robot => ("robot", "the robot is stuck there and cannot progress"),
                    Owner::Adversary => (
                        "adversary",
                        "the adversary is stuck there, which counts as a win for the robot",
                    ),
                };
                let have = if plural { "have" } else { "has" };
                write!(
                    f,
                    "{count} {who} {states} {have} no enabled action ({} reachable from the \
                     initial state): {consequence}",
                    self.reachable
                )?;
            }
            WarningKind::Unreachable => {
                let are = if plural { "are" } else { "is" };
                write!(
                    f,
                    "{count} {states} {are} unreachable from the initial state"
                )?;
            }
        }
        write!(f, "; the first: `{}`", Name(&self.first.name))?;
        match self.first.position {
            Some(position) => write!(f, " at {position}"),
            None => Ok(()),
        }
    }
}

/// The warnings of `defects` (as [`defects`] lists them) in one line per kind: the stuck robot
/// states, the stuck adversary states, the unreachable states, each with its count, in that
/// order, kinds without states left out.
pub fn summarise(defects: &[Warning]) -> Vec<Summary> {
    let unreachable: HashSet<StateId> = defects
        .iter()
        .filter(|w| w.kind == WarningKind::Unreachable)
        .map(|w| w.state)
        .collect();
    let kinds = [
        WarningKind::Stuck(Owner::Robot),
        WarningKind::Stuck(Owner::Adversary),
        WarningKind::Unreachable,
    ];
    kinds
        .into_iter()
        .filter_map(|kind| {
            let of_kind: Vec<&Warning> = defects.iter().filter(|w| w.kind == kind).collect();
            let first = (*of_kind.first()?).clone();
            let reachable = match kind {
                WarningKind::Unreachable => 0,
                WarningKind::Stuck(_) => of_kind
                    .iter()
                    .filter(|w| !unreachable.contains(&w.state))
                    .count(),
            };
            Some(Summary {
                kind,
                count: of_kind.len(),
                reachable,
                first,
            })
        })
        .collect()
}

/// Reads an arena from its text; on errors, the first 20 in file order (see
/// [`parse_with_limit`]).
pub fn parse(text: &str) -> Result<Parsed, Diagnostics<ParseErrorKind>> {
    parse_with_limit(text, DEFAULT_LIMIT)
}

/// Reads an arena from its text; on errors, the first `limit` in file order and the number of
/// the others. See the module documentation for how reading goes on after an error.
pub fn parse_with_limit(text: &str, limit: usize) -> Result<Parsed, Diagnostics<ParseErrorKind>> {
    read(text, limit, &mut Meter::unobserved(Stage::Parse))
}

/// [`parse`], reporting to `meter` the bytes read out of twice the text's length (it is read
/// twice).
pub fn parse_metered(
    text: &str,
    meter: &mut Meter<'_>,
) -> Result<Parsed, Diagnostics<ParseErrorKind>> {
    read(text, DEFAULT_LIMIT, meter)
}

fn read(
    text: &str,
    limit: usize,
    meter: &mut Meter<'_>,
) -> Result<Parsed, Diagnostics<ParseErrorKind>> {
    let length = text.len() as u64;
    let offset = |line: &str| (line.as_ptr() as usize - text.as_ptr() as usize) as u64;
    meter.set_total(2 * length);
    let mut reader = Reader::new(limit);
    for (number, line) in lines(text) {
        meter.set(offset(line));
        if let Err(error) = reader.declare(Lexer::new(line, number)) {
            reader.errors.push(error);
        }
    }
    if reader.initial_line.is_none() {
        let end = Position::of_offset(text, text.len());
        reader.errors.add(end, ParseErrorKind::MissingInitial);
    }
    reader.builder.reserve_transitions(reader.edges);
    for (number, line) in lines(text) {
        meter.set(length + offset(line));
        reader.connect(text, Lexer::new(line, number));
    }
    reader.finish(text)
}

/// The names on one line (numbered `number`) under the format's lexical rules (bare or quoted,
/// `#` comments), with their positions: other files keyed by arena names (the adversary's
/// weights file) read them exactly as the arena reader does. Braces are an error.
pub(crate) fn line_names(
    line: &str,
    number: usize,
) -> Result<Vec<(Position, Cow<'_, str>)>, ParseError> {
    let mut lexer = Lexer::new(line, number);
    let mut names = Vec::new();
    loop {
        match lexer.next()? {
            (_, Token::End) => return Ok(names),
            (at, Token::Name(name, _)) => names.push((lexer.position(at), name)),
            (at, other) => return Err(lexer.expected(at, "a name", &other)),
        }
    }
}

#[derive(Debug)]
enum Token<'a> {
    /// A name; `true` when it was quoted (quoted names are never keywords).
    Name(Cow<'a, str>, bool),
    Open,
    Close,
    /// The end of the line or the start of a comment.
    End,
}

impl Token<'_> {
    /// The token as an error message quotes it.
    fn describe(&self) -> String {
        match self {
            Token::Name(name, false) => format!("`{}`", brief(name)),
            Token::Name(name, true) => format!("`{}`", Quoted(name)),
            Token::Open => "`{`".to_string(),
            Token::Close => "`}`".to_string(),
            Token::End => "end of line".to_string(),
        }
    }
}

/// The tokens of one line. Positions are byte offsets into the line, always on character
/// boundaries: the lexer only steps over ASCII bytes and whole quoted names.
struct Lexer<'a> {
    line: &'a str,
    number: usize,
    pos: usize,
}

impl<'a> Lexer<'a> {
    fn new(line: &'a str, number: usize) -> Self {
        Lexer {
            line,
            number,
            pos: 0,
        }
    }

    fn position(&self, at: usize) -> Position {
        Position {
            line: self.number,
            column: self.line[..at].chars().count() + 1,
        }
    }

    fn error(&self, at: usize, kind: ParseErrorKind) -> ParseError {
        Diagnostic::new(self.position(at), kind)
    }

    fn char_at(&self, at: usize) -> char {
        self.line[at..].chars().next().unwrap_or('\n')
    }

    /// The next token and the offset where it starts.
    fn next(&mut self) -> Result<(usize, Token<'a>), ParseError> {
        let bytes = self.line.as_bytes();
        while self.pos < bytes.len() && matches!(bytes[self.pos], b' ' | b'\t') {
            self.pos += 1;
        }
        let at = self.pos;
        let token = match bytes.get(at) {
            None | Some(b'#') => return Ok((at, Token::End)),
            Some(b'{') => {
                self.pos += 1;
                Token::Open
            }
            Some(b'}') => {
                self.pos += 1;
                Token::Close
            }
            _ => match syntax::read_name(self.line, at).map_err(|(at, error)| {
                let kind = match error {
                    QuoteError::Unterminated => ParseErrorKind::UnterminatedQuote,
                    QuoteError::UnknownEscape(letter) => ParseErrorKind::UnknownEscape(letter),
                };
                self.error(at, kind)
            })? {
                Some(token) => {
                    self.pos = token.end;
                    self.separator(!token.quoted)?;
                    Token::Name(token.name, token.quoted)
                }
                None => {
                    let found = self.char_at(at);
                    return Err(self.error(at, ParseErrorKind::UnexpectedCharacter(found)));
                }
            },
        };
        Ok((at, token))
    }

    /// Checks that a name ends where a separator (or a brace, or a comment) starts.
    fn separator(&self, after_identifier: bool) -> Result<(), ParseError> {
        match self.line.as_bytes().get(self.pos) {
            None | Some(b' ' | b'\t' | b'{' | b'}' | b'#') => Ok(()),
            Some(b'"') => Err(self.error(self.pos, ParseErrorKind::MissingSpace('"'))),
            Some(_) if after_identifier => Err(self.error(
                self.pos,
                ParseErrorKind::UnexpectedCharacter(self.char_at(self.pos)),
            )),
            Some(_) => Err(self.error(
                self.pos,
                ParseErrorKind::MissingSpace(self.char_at(self.pos)),
            )),
        }
    }

    /// The next token, which must be a name (quoted or not).
    fn name(&mut self, expected: &'static str) -> Result<(usize, Cow<'a, str>), ParseError> {
        match self.next()? {
            (at, Token::Name(name, _)) => Ok((at, name)),
            (at, other) => Err(self.expected(at, expected, &other)),
        }
    }

    /// Checks that nothing but a comment is left on the line.
    fn end(&mut self) -> Result<(), ParseError> {
        match self.next()? {
            (_, Token::End) => Ok(()),
            (at, other) => Err(self.expected(at, "end of line", &other)),
        }
    }

    fn expected(&self, at: usize, expected: &'static str, found: &Token<'_>) -> ParseError {
        self.error(
            at,
            ParseErrorKind::Expected {
                expected,
                found: found.describe(),
            },
        )
    }
}

const EXPECTED_ITEM: &str = "`propositions`, `actions`, `initial`, `state` or `edge`";

/// The first token of a line: the item keyword, or `None` for a blank or comment line.
fn item<'a>(lexer: &mut Lexer<'a>) -> Result<Option<(usize, Cow<'a, str>)>, ParseError> {
    match lexer.next()? {
        (_, Token::End) => Ok(None),
        (at, Token::Name(keyword, false)) if syntax::ITEMS.contains(&keyword.as_ref()) => {
            Ok(Some((at, keyword)))
        }
        (at, other) => Err(lexer.expected(at, EXPECTED_ITEM, &other)),
    }
}

/// The rest of an `edge` line: source, action and target with their offsets.
struct Edge<'a> {
    source: (usize, Cow<'a, str>),
    action: (usize, Cow<'a, str>),
    target: (usize, Cow<'a, str>),
}

fn edge<'a>(lexer: &mut Lexer<'a>) -> Result<Edge<'a>, ParseError> {
    let source = lexer.name("the source state")?;
    let action = lexer.name("an action")?;
    let target = lexer.name("the target state")?;
    lexer.end()?;
    Ok(Edge {
        source,
        action,
        target,
    })
}

struct Reader<'a> {
    errors: Collector<ParseErrorKind>,
    builder: ArenaBuilder,
    /// Where each state's name is, by state id: for duplicate errors and warnings.
    state_positions: Vec<(u32, u32)>,
    propositions_line: Option<usize>,
    actions_line: Option<usize>,
    /// Whether the `propositions` or `actions` line is malformed: names are then not checked
    /// against it (those after the error would all be undeclared).
    propositions_broken: bool,
    actions_broken: bool,
    /// States whose `state` line is malformed after their name: they are not in the arena,
    /// and edges naming them are not checked further.
    broken_states: HashSet<Cow<'a, str>>,
    /// Whether a `state` line is malformed before its name ends, or a line's keyword is (it
    /// may be a misspelt `state`): that line may define any state, so undefined states are not
    /// reported.
    unnamed_state: bool,
    initial_line: Option<usize>,
    /// The first `state` or `edge` line: declarations must come before it.
    body_line: Option<usize>,
    /// The label being read, reused from line to line, and its propositions as a set (so a
    /// label of a million propositions costs linear time to check for repetitions).
    label: Vec<Cow<'a, str>>,
    label_set: HashSet<Cow<'a, str>>,
    /// How many `edge` lines pass one saw, to size the transition table once.
    edges: usize,
    /// The source of the previous edge: edges come grouped by source, and comparing the name
    /// with it is cheaper than looking it up.
    last_source: Option<(Cow<'a, str>, StateId)>,
    /// Per action, the source and target of its last edge. Generated arenas list states in a
    /// regular order, so the next edge with that action usually leads as far from the last
    /// target as its source is from the last source: that state's name is compared first, a
    /// cache hit where a hash lookup costs several misses (a wrong guess costs one compare).
    guesses: Vec<Option<(StateId, StateId)>>,
}

impl<'a> Reader<'a> {
    fn new(limit: usize) -> Reader<'a> {
        Reader {
            errors: Collector::new(limit),
            builder: ArenaBuilder::default(),
            state_positions: Vec::new(),
            propositions_line: None,
            actions_line: None,
            propositions_broken: false,
            actions_broken: false,
            broken_states: HashSet::default(),
            unnamed_state: false,
            initial_line: None,
            body_line: None,
            label: Vec::new(),
            label_set: HashSet::default(),
            edges: 0,
            last_source: None,
            guesses: Vec::new(),
        }
    }

    /// Pass one: checks the syntax of a line and records its declarations and state. Returns
    /// the error that ends the line, if any (others are collected on the way).
    fn declare(&mut self, mut lexer: Lexer<'a>) -> Result<(), ParseError> {
        let Some((at, keyword)) = item(&mut lexer).inspect_err(|_| self.unnamed_state = true)?
        else {
            return Ok(());
        };
        match keyword.as_ref() {
            "propositions" => self.declaration(lexer, at, "propositions"),
            "actions" => self.declaration(lexer, at, "actions"),
            "initial" => {
                if let Some(first_line) = self.initial_line {
                    let kind = ParseErrorKind::RepeatedLine {
                        item: "initial",
                        first_line,
                    };
                    return Err(lexer.error(at, kind));
                }
                self.initial_line = Some(lexer.number);
                lexer.name("the initial state")?;
                lexer.end()
            }
            "state" => {
                self.body_line.get_or_insert(lexer.number);
                self.state(lexer)
            }
            // `edge`, the only item left.
            _ => {
                self.body_line.get_or_insert(lexer.number);
                self.edges += 1;
                let edge = edge(&mut lexer)?;
                let (at, action) = &edge.action;
                match self.actions_line {
                    Some(line)
                        if !self.actions_broken && self.builder.find_action(action).is_none() =>
                    {
                        let kind = ParseErrorKind::Undeclared {
                            what: "action",
                            name: action.to_string(),
                            item: "actions",
                            line,
                        };
                        Err(lexer.error(*at, kind))
                    }
                    _ => Ok(()),
                }
            }
        }
    }

    /// A `propositions` or `actions` line.
    fn declaration(
        &mut self,
        mut lexer: Lexer<'a>,
        at: usize,
        item: &'static str,
    ) -> Result<(), ParseError> {
        if let Some(line) = self.body_line {
            return Err(lexer.error(at, ParseErrorKind::LateDeclaration { item, line }));
        }
        let propositions = item == "propositions";
        let (seen, what) = if propositions {
            (&mut self.propositions_line, "proposition")
        } else {
            (&mut self.actions_line, "action")
        };
        if let Some(first_line) = *seen {
            return Err(lexer.error(at, ParseErrorKind::RepeatedLine { item, first_line }));
        }
        *seen = Some(lexer.number);
        loop {
            let read = match lexer.next() {
                Ok((_, Token::End)) => return Ok(()),
                Ok((at, Token::Name(name, _))) => Ok((at, name)),
                Ok((at, other)) => Err(lexer.expected(at, "a name", &other)),
                Err(error) => Err(error),
            };
            let (at, name) = match read {
                Ok(name) => name,
                Err(error) => {
                    if propositions {
                        self.propositions_broken = true;
                    } else {
                        self.actions_broken = true;
                    }
                    return Err(error);
                }
            };
            let known = if propositions {
                self.builder.find_proposition(&name).is_some()
            } else {
                self.builder.find_action(&name).is_some()
            };
            if known {
                let name = name.into_owned();
                let error = lexer.error(at, ParseErrorKind::DeclaredTwice { what, name });
                self.errors.push(error);
            } else if propositions {
                self.builder.proposition(&name);
            } else {
                self.builder.action(&name);
            }
        }
    }

    /// A `state` line: name, owner, label and optional display name. A state whose line is
    /// malformed after its name is remembered as broken.
    fn state(&mut self, mut lexer: Lexer<'a>) -> Result<(), ParseError> {
        let (name_at, name) = lexer
            .name("a state name")
            .inspect_err(|_| self.unnamed_state = true)?;
        let duplicate =
            self.builder
                .find_state(&name)
                .map(|existing| ParseErrorKind::DuplicateState {
                    name: name.to_string(),
                    first_line: self.state_positions[existing.index()].0 as usize,
                });
        if let Some(kind) = duplicate {
            // The rest of the line is still checked.
            self.errors.push(lexer.error(name_at, kind));
            return self.state_rest(&mut lexer).map(|_| ());
        }
        let (owner, display) = match self.state_rest(&mut lexer) {
            Ok(rest) => rest,
            Err(error) => {
                self.broken_states.insert(name);
                return Err(error);
            }
        };
        let label = self.label.iter().map(|p| p.as_ref());
        self.builder
            .add_state(&name, owner, label, display)
            .map_err(|e| lexer.error(name_at, e.into()))?;
        let position = lexer.position(name_at);
        self.state_positions
            .push((position.line as u32, position.column as u32));
        Ok(())
    }

    /// A `state` line after the name: the owner and display name; the label in `self.label`.
    fn state_rest(&mut self, lexer: &mut Lexer<'a>) -> Result<(Owner, Option<String>), ParseError> {
        let (at, token) = lexer.next()?;
        let owner = match &token {
            Token::Name(keyword, false) => syntax::owner(keyword),
            _ => None,
        }
        .ok_or_else(|| lexer.expected(at, "`robot` or `adversary`", &token))?;
        match lexer.next()? {
            (_, Token::Open) => {}
            (at, other) => {
                return Err(lexer.expected(at, "a label such as `{}` or `{A B}`", &other));
            }
        }
        self.label.clear();
        self.label_set.clear();
        loop {
            let (at, proposition) = match lexer.next()? {
                (_, Token::Close) => break,
                (at, Token::Name(proposition, _)) => (at, proposition),
                (at, other) => return Err(lexer.expected(at, "a proposition or `}`", &other)),
            };
            if !self.label_set.insert(proposition.clone()) {
                let kind = ParseErrorKind::RepeatedInLabel(proposition.into_owned());
                self.errors.push(lexer.error(at, kind));
                continue;
            }
            if let Some(line) = self.propositions_line
                && !self.propositions_broken
                && self.builder.find_proposition(&proposition).is_none()
            {
                let kind = ParseErrorKind::Undeclared {
                    what: "proposition",
                    name: proposition.into_owned(),
                    item: "propositions",
                    line,
                };
                self.errors.push(lexer.error(at, kind));
                continue;
            }
            self.label.push(proposition);
        }
        let display = match lexer.next()? {
            (_, Token::End) => None,
            (_, Token::Name(display, _)) => {
                lexer.end()?;
                Some(display.into_owned())
            }
            (at, other) => {
                return Err(lexer.expected(at, "a display name or end of line", &other));
            }
        };
        Ok((owner, display))
    }

    /// Pass two: resolves the states named by the first `initial` line and by `edge` lines.
    /// Lines with a syntax error (reported by pass one) are skipped.
    fn connect(&mut self, text: &str, mut lexer: Lexer<'a>) {
        let Ok(Some((_, keyword))) = item(&mut lexer) else {
            return;
        };
        match keyword.as_ref() {
            "initial" if self.initial_line == Some(lexer.number) => {
                let Ok(initial) = lexer.name("the initial state") else {
                    return;
                };
                if let Some(state) = self.resolve(&lexer, &initial) {
                    self.builder.set_initial(state);
                }
            }
            "edge" => {
                let Ok(edge) = edge(&mut lexer) else {
                    return;
                };
                let source = match &self.last_source {
                    Some((name, id)) if *name == edge.source.1 => Some(*id),
                    _ => {
                        let id = self.resolve(&lexer, &edge.source);
                        if let Some(id) = id {
                            self.last_source = Some((edge.source.1.clone(), id));
                        }
                        id
                    }
                };
                let target = match source {
                    Some(source) => self.resolve_target(&lexer, &edge, source),
                    None => self.resolve(&lexer, &edge.target),
                };
                let (Some(source), Some(target)) = (source, target) else {
                    return;
                };
                let (action_at, action) = &edge.action;
                let error = match self.builder.add_transition(source, action, target) {
                    Ok(()) => return,
                    // Finding the first edge costs a pass over the lines before: only for the
                    // errors that are shown (pass two goes in file order, so once `limit`
                    // errors come before this line, none after is).
                    Err(BuildError::DuplicateAction { .. })
                        if !self.errors.keeps(lexer.position(*action_at)) =>
                    {
                        self.errors.count();
                        return;
                    }
                    Err(BuildError::DuplicateAction { state, action }) => {
                        let first_line = self.first_edge_line(text, lexer.number, source, &action);
                        ParseErrorKind::DuplicateTransition {
                            state,
                            action,
                            first_line,
                        }
                    }
                    Err(other) => other.into(),
                };
                self.errors.push(lexer.error(*action_at, error));
            }
            _ => {}
        }
    }

    /// The state `name` names; `None` if there is none, which is an error unless its `state`
    /// line (or any `state` line before its name ended) was malformed: already reported.
    fn resolve(
        &mut self,
        lexer: &Lexer<'_>,
        (at, name): &(usize, Cow<'_, str>),
    ) -> Option<StateId> {
        let state = self.builder.find_state(name);
        if state.is_none() && !self.unnamed_state && !self.broken_states.contains(name.as_ref()) {
            let kind = ParseErrorKind::UnknownState(name.to_string());
            self.errors.push(lexer.error(*at, kind));
        }
        state
    }

    /// [`Self::resolve`] for the target of an edge from `source`, trying the state that the
    /// last edge with the same action suggests first (see `guesses`).
    fn resolve_target(
        &mut self,
        lexer: &Lexer<'_>,
        edge: &Edge<'_>,
        source: StateId,
    ) -> Option<StateId> {
        let name = edge.target.1.as_ref();
        // An action not interned yet (no `actions` line) has no last edge.
        let Some(action) = self.builder.find_action(&edge.action.1) else {
            return self.resolve(lexer, &edge.target);
        };
        let action = action as usize;
        if action >= self.guesses.len() {
            self.guesses.resize(action + 1, None);
        }
        let guessed = self.guesses[action].and_then(|(last_source, last_target)| {
            let guess = (last_target.index() + source.index()).checked_sub(last_source.index())?;
            (self.builder.state_name(guess) == Some(name)).then(|| StateId::new(guess))
        });
        let target = guessed.or_else(|| self.resolve(lexer, &edge.target))?;
        self.guesses[action] = Some((source, target));
        Some(target)
    }

    /// The line of the first `edge` from `source` with `action`, which a duplicate on line
    /// `duplicate` repeats (only called on that error).
    fn first_edge_line(
        &self,
        text: &str,
        duplicate: usize,
        source: StateId,
        action: &str,
    ) -> usize {
        for (number, line) in lines(text).take(duplicate) {
            let mut lexer = Lexer::new(line, number);
            if let Ok(Some((_, keyword))) = item(&mut lexer)
                && keyword == "edge"
                && let Ok(edge) = edge(&mut lexer)
                && edge.action.1 == action
                && self.builder.find_state(&edge.source.1) == Some(source)
                && self.builder.find_state(&edge.target.1).is_some()
            {
                return number;
            }
        }
        duplicate
    }

    fn finish(self, text: &str) -> Result<Parsed, Diagnostics<ParseErrorKind>> {
        let positions = self.state_positions;
        self.errors.or_ok(())?;
        let arena = self.builder.build().map_err(|e| {
            let end = Position::of_offset(text, text.len());
            Diagnostics::from(Diagnostic::new(end, e.into()))
        })?;
        let warnings = located_defects(&arena, |state| {
            let (line, column) = positions[state.index()];
            Some(Position {
                line: line as usize,
                column: column as usize,
            })
        });
        Ok(Parsed { arena, warnings })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parsed(text: &str) -> Parsed {
        match parse(text) {
            Ok(parsed) => parsed,
            Err(e) => panic!("{e}\nin:\n{text}"),
        }
    }

    fn edges(arena: &Arena, state: &str) -> Vec<(String, String)> {
        let state = arena.find_state(state).expect("state exists");
        arena
            .edges(state)
            .map(|(a, t)| (arena.action_name(a).to_string(), arena.name(t).to_string()))
            .collect()
    }

    fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter()
            .map(|&(a, t)| (a.to_string(), t.to_string()))
            .collect()
    }

    #[test]
    fn reads_declarations_states_labels_displays_and_edges() {
        let arena = parsed(
            "# an example\n\
             propositions A B\n\
             actions go stay\n\
             initial s0\n\
             state s0 robot {A}\n\
             state s1 adversary {B A} \"the other\"\n\
             edge s0 go s1\n\
             edge s1 stay s0\n\
             edge s1 go s1\n",
        )
        .arena;
        assert_eq!(arena.propositions(), ["A", "B"]);
        assert_eq!(arena.actions(), ["go", "stay"]);
        assert_eq!(arena.num_states(), 2);
        let (s0, s1) = (StateId::new(0), StateId::new(1));
        assert_eq!(arena.initial(), s0);
        assert_eq!(arena.name(s1), "s1");
        assert_eq!(arena.owner(s0), Owner::Robot);
        assert_eq!(arena.owner(s1), Owner::Adversary);
        assert_eq!(arena.label(s0).iter().collect::<Vec<_>>(), [0]);
        assert_eq!(arena.label(s1).iter().collect::<Vec<_>>(), [0, 1]);
        assert_eq!(arena.display(s0), None);
        assert_eq!(arena.display(s1), Some("the other"));
        assert_eq!(edges(&arena, "s0"), pairs(&[("go", "s1")]));
        assert_eq!(edges(&arena, "s1"), pairs(&[("stay", "s0"), ("go", "s1")]));
    }

    #[test]
    fn targets_guessed_from_the_last_edge_of_the_action_are_checked_by_name() {
        // Ids: s0 0, s1 1, s2 2, t0 3, t1 4. The guess for s1's `a` (t0 + 1) is right; for s2's
        // it is past the last state; for t0's it is s1, the wrong name; for `b` there is none.
        let text = "initial s0\n\
                    state s0 robot {}\nstate s1 robot {}\nstate s2 robot {}\n\
                    state t0 robot {}\nstate t1 robot {}\n\
                    edge s0 a t0\nedge s1 a t1\nedge s2 a s0\nedge t0 a s2\nedge t0 b t1\n";
        let arena = parsed(text).arena;
        assert_eq!(edges(&arena, "s0"), pairs(&[("a", "t0")]));
        assert_eq!(edges(&arena, "s1"), pairs(&[("a", "t1")]));
        assert_eq!(edges(&arena, "s2"), pairs(&[("a", "s0")]));
        assert_eq!(edges(&arena, "t0"), pairs(&[("a", "s2"), ("b", "t1")]));
        // A wrong guess (s2) still reports an undefined target.
        let text = "initial s0\nstate s0 robot {}\nstate s1 robot {}\nstate s2 robot {}\n\
                    edge s0 a s1\nedge s1 a nowhere\n";
        assert_eq!(errors(text), ["6:11: state `nowhere` is not defined"]);
    }

    #[test]
    fn edges_and_initial_may_name_states_defined_further_down() {
        let arena = parsed(
            "edge b x a\n\
             initial a\n\
             edge a x b\n\
             edge b y b\n\
             state a robot {}\n\
             state b adversary {}\n",
        )
        .arena;
        assert_eq!(arena.initial(), arena.find_state("a").unwrap());
        // File order within a state, whatever came between.
        assert_eq!(edges(&arena, "b"), pairs(&[("x", "a"), ("y", "b")]));
        assert_eq!(edges(&arena, "a"), pairs(&[("x", "b")]));
        assert_eq!(arena.actions(), ["x", "y"]);
    }

    #[test]
    fn lexical_details_comments_blanks_tabs_crlf_quotes_and_escapes() {
        let text = "  # indented comment\r\n\
                    \r\n\
                    initial \"((0,2),(4,2),0)\"   # trailing comment\r\n\
                    state\t\"((0,2),(4,2),0)\"\trobot\t{p\t\"q r\"}\t\"say \\\"hi\\\" # not a comment\"\n\
                    state \"\\\\\\n\\r\\t\" adversary {\"p\"}\n\
                    state \"\" robot {}\n\
                    state x.y-z_0 robot{}\"d\"\n\
                    edge \"((0,2),(4,2),0)\" \"go north\" \"\\\\\\n\\r\\t\"\n\
                    edge \"\" \"\" \"\"";
        let arena = parsed(text).arena;
        let start = arena.find_state("((0,2),(4,2),0)").unwrap();
        assert_eq!(arena.initial(), start);
        assert_eq!(arena.propositions(), ["p", "q r"]);
        assert_eq!(arena.label(start).count(), 2);
        assert_eq!(arena.display(start), Some("say \"hi\" # not a comment"));
        let odd = arena.find_state("\\\n\r\t").unwrap();
        assert_eq!(arena.label(odd).iter().collect::<Vec<_>>(), [0]);
        assert_eq!(
            arena.display(arena.find_state("x.y-z_0").unwrap()),
            Some("d")
        );
        assert_eq!(
            edges(&arena, "((0,2),(4,2),0)"),
            pairs(&[("go north", "\\\n\r\t")])
        );
        assert_eq!(edges(&arena, ""), pairs(&[("", "")]));
    }

    #[test]
    fn the_documented_example_reads_as_described() {
        let formats = include_str!("../../../../docs/formats.md");
        let section = &formats[formats.find("## Arena format").expect("section")..];
        let start = section.find("```text\n").expect("example") + "```text\n".len();
        let end = start + section[start..].find("```").expect("end of example");
        let arena = parsed(&section[start..end]).arena;
        assert_eq!(arena.num_states(), 2);
        assert_eq!(arena.propositions(), ["A", "B", "O"]);
        assert_eq!(arena.actions(), ["N", "E", "STAY"]);
        assert_eq!(arena.name(arena.initial()), "((0,2),(4,2),0)");
        assert_eq!(edges(&arena, "((0,2),(4,2),0)"), pairs(&[("N", "s1")]));
        assert_eq!(edges(&arena, "s1"), pairs(&[("STAY", "((0,2),(4,2),0)")]));
        let s1 = arena.find_state("s1").unwrap();
        assert_eq!(arena.owner(s1), Owner::Adversary);
        assert_eq!(arena.label(s1).iter().collect::<Vec<_>>(), [0]);
    }

    #[test]
    fn without_a_propositions_line_propositions_are_interned_in_order_of_first_use() {
        let arena = parsed("initial s\nstate s robot {b a}\nstate t robot {c a}\n").arena;
        assert_eq!(arena.propositions(), ["b", "a", "c"]);
    }

    #[test]
    fn declared_but_unused_propositions_and_actions_are_kept() {
        let arena = parsed("propositions O\nactions N\ninitial s\nstate s robot {}\n").arena;
        assert_eq!(arena.propositions(), ["O"]);
        assert_eq!(arena.actions(), ["N"]);
        assert_eq!(arena.num_transitions(), 0);
    }

    #[test]
    fn warns_about_stuck_and_unreachable_states_at_their_definitions() {
        let text = "initial r\n\
                    state r robot {}\n\
                    state e adversary {}\n\
                    state  far robot {}\n\
                    state lost adversary {}\n\
                    edge r go e\n\
                    edge lost go far\n\
                    edge far go lost\n";
        let warnings = parsed(text).warnings;
        let summary: Vec<(usize, usize, &str, WarningKind)> = warnings
            .iter()
            .map(|w| {
                let position = w.position.unwrap();
                (position.line, position.column, w.name.as_str(), w.kind)
            })
            .collect();
        assert_eq!(
            summary,
            [
                (3, 7, "e", WarningKind::Stuck(Owner::Adversary)),
                (4, 8, "far", WarningKind::Unreachable),
                (5, 7, "lost", WarningKind::Unreachable),
            ]
        );
        assert_eq!(
            warnings[0].to_string(),
            "3:7: adversary state `e` has no enabled action: the adversary is stuck there, \
             which counts as a win for the robot whatever its task"
        );
        let stuck_robot = parsed("initial r\nstate r robot {}\n").warnings;
        assert_eq!(stuck_robot.len(), 1);
        assert!(
            stuck_robot[0]
                .to_string()
                .contains("robot state `r` has no enabled action")
        );
    }

    #[test]
    fn defects_are_summarised_one_line_per_kind_with_counts() {
        // r <-> a1 -> {r1 (stuck), r2 -> a2 (stuck)}; u1 (robot, stuck), u2 (adversary, stuck)
        // and u3 are unreachable.
        let text = "initial r\n\
                    state r robot {}\n\
                    state a1 adversary {}\n\
                    state r1 robot {}\n\
                    state r2 robot {}\n\
                    state a2 adversary {}\n\
                    state u1 robot {}\n\
                    state u2 adversary {}\n\
                    state u3 robot {}\n\
                    edge r go a1\n\
                    edge a1 back r\n\
                    edge a1 x r1\n\
                    edge a1 y r2\n\
                    edge r2 go a2\n\
                    edge u3 go u2\n";
        let read = parsed(text);
        // Stuck: r1, a2, u1, u2 (r2 moves to a2); unreachable: u1, u2, u3.
        let kinds: Vec<(&str, WarningKind)> = read
            .warnings
            .iter()
            .map(|w| (w.name.as_str(), w.kind))
            .collect();
        assert_eq!(
            kinds,
            [
                ("r1", WarningKind::Stuck(Owner::Robot)),
                ("a2", WarningKind::Stuck(Owner::Adversary)),
                ("u1", WarningKind::Stuck(Owner::Robot)),
                ("u2", WarningKind::Stuck(Owner::Adversary)),
                ("u1", WarningKind::Unreachable),
                ("u2", WarningKind::Unreachable),
                ("u3", WarningKind::Unreachable),
            ]
        );
        let summaries: Vec<String> = summarise(&read.warnings)
            .iter()
            .map(Summary::to_string)
            .collect();
        assert_eq!(
            summaries,
            [
                "2 robot states have no enabled action (1 reachable from the initial state): \
                 the robot is stuck there and cannot progress; the first: `r1` at 4:7",
                "2 adversary states have no enabled action (1 reachable from the initial \
                 state): the adversary is stuck there, which counts as a win for the robot; the \
                 first: `a2` at 6:7",
                "3 states are unreachable from the initial state; the first: `u1` at 7:7",
            ]
        );
        // Built in memory: the same defects without positions.
        let unlocated = defects(&read.arena);
        assert!(unlocated.iter().all(|w| w.position.is_none()));
        assert_eq!(unlocated.len(), read.warnings.len());
        assert_eq!(
            unlocated[0].to_string(),
            "robot state `r1` has no enabled action: the robot is stuck there and cannot progress"
        );
        // One of a kind; none of another.
        let one = parsed("initial r\nstate r robot {}\nstate u robot {}\nedge r go r\n");
        let summaries = summarise(&one.warnings);
        assert_eq!(summaries.len(), 2);
        assert_eq!(
            summaries[0].to_string(),
            "1 robot state has no enabled action (0 reachable from the initial state): the \
             robot is stuck there and cannot progress; the first: `u` at 3:7"
        );
        assert_eq!(
            summaries[1].to_string(),
            "1 state is unreachable from the initial state; the first: `u` at 3:7"
        );
        let clean = parsed("initial r\nstate r robot {}\nedge r go r\n");
        assert!(summarise(&clean.warnings).is_empty());
    }

    /// Malformed arenas: the text, then the line, column and a fragment of the message.
    const MALFORMED: &[(&str, usize, usize, &str)] = &[
        (
            "initial s0\nstate s0 robot {A\n",
            2,
            18,
            "expected a proposition or `}`, found end of line",
        ),
        (
            "initial s0\nstate \"s0 robot {}\n",
            2,
            7,
            "unterminated quoted name",
        ),
        (
            "initial s0\nstate \"s\\q\" robot {}\n",
            2,
            9,
            "unknown escape `\\q`",
        ),
        (
            "initial s0\nstate s@0 robot {}\n",
            2,
            8,
            "unexpected character `@`: a name with",
        ),
        (
            "initial s0\nstate \"s0\"x robot {}\n",
            2,
            11,
            "missing space before `x`",
        ),
        (
            "initial s0\nstat s0 robot {}\n",
            2,
            1,
            "expected `propositions`, `actions`, `initial`, `state` or `edge`, found `stat`",
        ),
        (
            "initial s0\nstate s0 robto {}\n",
            2,
            10,
            "expected `robot` or `adversary`, found `robto`",
        ),
        (
            "initial s0\nstate s0 robot\n",
            2,
            15,
            "expected a label such as `{}` or `{A B}`, found end",
        ),
        (
            "initial s0\nstate s0 robot {} \"d\" extra\n",
            2,
            23,
            "expected end of line, found `extra`",
        ),
        (
            "initial s0\nstate s0 robot {}\nstate s0 adversary {}\n",
            3,
            7,
            "state `s0` is already defined on line 2",
        ),
        (
            "initial s0\nstate s0 robot {}\nedge s0 go s9\n",
            3,
            12,
            "state `s9` is not defined",
        ),
        (
            "initial s0\nstate s0 robot {}\nedge s9 go s0\n",
            3,
            6,
            "state `s9` is not defined",
        ),
        (
            "initial s9\nstate s0 robot {}\n",
            1,
            9,
            "state `s9` is not defined",
        ),
        (
            "propositions A\ninitial s0\nstate s0 robot {A C}\n",
            3,
            19,
            "proposition `C` is not declared on the `propositions` line (line 1)",
        ),
        (
            "actions go\ninitial s0\nstate s0 robot {}\nedge s0 fly s0\n",
            4,
            9,
            "action `fly` is not declared on the `actions` line (line 1)",
        ),
        (
            "initial s0\nstate s0 robot {}\nedge s0 go s0\nedge s0 go s0\n",
            4,
            9,
            "state `s0` already has a successor for action `go` (line 3)",
        ),
        ("state s0 robot {}\n", 2, 1, "no `initial` line"),
        ("", 1, 1, "no `initial` line"),
        (
            "initial s0\nstate s0 robot {}\ninitial s0\n",
            3,
            1,
            "second `initial` line (the first is on line 1)",
        ),
        (
            "initial s0\nstate s0 robot {}\npropositions A\n",
            3,
            1,
            "`propositions` must come before the first `state` or `edge` line (line 2)",
        ),
        (
            "initial s0\nedge s0 go s0\nactions go\nstate s0 robot {}\n",
            3,
            1,
            "`actions` must come before the first `state` or `edge` line (line 2)",
        ),
        (
            "propositions A\npropositions B\n",
            2,
            1,
            "second `propositions` line (the first is on line 1)",
        ),
        (
            "actions a\n  actions b\n",
            2,
            3,
            "second `actions` line (the first is on line 1)",
        ),
        (
            "propositions A B A\n",
            1,
            18,
            "proposition `A` is declared twice",
        ),
        ("actions go go\n", 1, 12, "action `go` is declared twice"),
        (
            "initial s0\nstate s0 robot {A A}\n",
            2,
            19,
            "proposition `A` appears twice in the label",
        ),
        (
            "propositions\ninitial s0\nstate s0 robot {A}\n",
            3,
            17,
            "proposition `A` is not declared",
        ),
        (
            "initial s0\nstate s0 robot {}\nedge s0 go\n",
            3,
            11,
            "expected the target state, found end",
        ),
        (
            "initial s0\nstate s0 robot {}\nedge\n",
            3,
            5,
            "expected the source state, found end of line",
        ),
        (
            "initial\n",
            1,
            8,
            "expected the initial state, found end of line",
        ),
        ("{}\n", 1, 1, "found `{`"),
        ("\"state\" s0 robot {}\n", 1, 1, "found `\"state\"`"),
        (
            "initial s0\nstate s0 \"robot\" {}\n",
            2,
            10,
            "found `\"robot\"`",
        ),
        (
            "initial s0\nstate é robot {}\n",
            2,
            7,
            "unexpected character `é`",
        ),
        // Columns count characters, not bytes.
        (
            "initial \"é\"\nstate \"é\" robot {} \"ü\" y\n",
            2,
            24,
            "expected end of line, found `y`",
        ),
        (
            "initial s0\nstate s0 robot {} {\n",
            2,
            19,
            "expected a display name or end of line",
        ),
        ("initial s0\nstate s0 robot }\n", 2, 16, "found `}`"),
        ("propositions A {\n", 1, 16, "expected a name, found `{`"),
        (
            "initial s0\nstate \"abc\\\n",
            2,
            7,
            "unterminated quoted name",
        ),
        (
            "initial s0\nstate s0\rrobot {}\n",
            2,
            9,
            "unexpected character `\\r`",
        ),
        // CRLF line ends are not part of the line.
        (
            "initial s0\r\nstate s0 robot {A\r\n",
            2,
            18,
            "expected a proposition or `}`",
        ),
        // A quoted name and a bare one are the same name.
        (
            "initial a\nstate \"a\" robot {}\nstate a robot {}\n",
            3,
            7,
            "state `a` is already defined on line 2",
        ),
        (
            "initial \"x y\"\nstate \"x y\" robot {}\nedge \"x y\" \"go on\" \"x y\"\nedge \"x y\" \"go on\" \"x y\"\n",
            4,
            12,
            "state `\"x y\"` already has a successor for action `\"go on\"` (line 3)",
        ),
    ];

    #[test]
    fn malformed_arenas_give_located_clear_errors() {
        assert!(MALFORMED.len() >= 25);
        for &(text, line, column, fragment) in MALFORMED {
            let errors = match parse(text) {
                Ok(_) => panic!("accepted:\n{text}"),
                Err(errors) => errors,
            };
            // One error each, and the missing `initial` line of the short ones.
            let others = &errors.as_slice()[1..];
            assert!(
                others
                    .iter()
                    .all(|e| e.message == ParseErrorKind::MissingInitial),
                "{errors}\nin:\n{text}"
            );
            let error = errors.first();
            let message = error.message.to_string();
            assert_eq!(
                (error.position.line, error.position.column),
                (line, column),
                "position of `{message}` in:\n{text}"
            );
            assert!(
                message.contains(fragment),
                "`{message}` lacks `{fragment}` in:\n{text}"
            );
            assert!(!message.contains('\n'), "multi-line message `{message}`");
            assert_eq!(error.to_string(), format!("{line}:{column}: {message}"));
        }
    }

    /// The errors of `text`, each as `LINE:COL: message`.
    fn errors(text: &str) -> Vec<String> {
        let errors = parse(text).expect_err(text);
        errors.iter().map(ToString::to_string).collect()
    }

    #[test]
    fn every_error_is_reported_in_file_order_without_its_consequences() {
        let text = "\
propositions A B A
actions go {
initial s9
state s0 robot {A C A}
state s1 robto {}
state s0 adversary {} \"x\" y
edge s0 fly s1
edge s0 go s2
edge s0 go s0
edge s0 go s0
edge s0 go
initial s0
";
        assert_eq!(
            errors(text),
            [
                "1:18: proposition `A` is declared twice",
                "2:12: expected a name, found `{`",
                "3:9: state `s9` is not defined",
                "4:19: proposition `C` is not declared on the `propositions` line (line 1)",
                "4:21: proposition `A` appears twice in the label",
                "5:10: expected `robot` or `adversary`, found `robto`",
                "6:7: state `s0` is already defined on line 4",
                "6:27: expected end of line, found `y`",
                "8:12: state `s2` is not defined",
                "10:9: state `s0` already has a successor for action `go` (line 9)",
                "11:11: expected the target state, found end of line",
                "12:1: second `initial` line (the first is on line 3)",
            ]
        );
        // Not reported: `fly` (line 7; the `actions` line is malformed, so names are not checked
        // against it), `s1` (line 7; its `state` line is malformed), the `initial` line 12 in
        // pass two (only the first is resolved).
    }

    #[test]
    fn after_a_line_that_may_define_any_state_undefined_states_are_not_reported() {
        for line in ["stat s1 robot {}", "state \"s1 robot {}", "{ s1"] {
            let text = format!("initial s0\nstate s0 robot {{}}\n{line}\nedge s0 go s1\n");
            let errors = parse(&text).unwrap_err();
            assert_eq!(errors.total(), 1, "{errors}");
            assert_eq!(errors.first().position.line, 3);
        }
    }

    #[test]
    fn reference_errors_come_in_file_order_with_syntax_errors_and_without_an_initial_line() {
        assert_eq!(
            errors("state s0 robot {\nedge s0 go s1\nedge s1 go s0 extra\n"),
            [
                "1:17: expected a proposition or `}`, found end of line",
                "2:12: state `s1` is not defined",
                "3:15: expected end of line, found `extra`",
                "4:1: no `initial` line: the initial state must be declared",
            ]
        );
    }

    #[test]
    fn the_error_limit_keeps_the_first_errors_in_file_order() {
        // Pass two's errors (lines 2..=31) and pass one's (lines 32..=61) interleave by line.
        let mut text = String::from("initial s0\n");
        for i in 0..30 {
            text.push_str(&format!("edge s0 go{i} t{i}\n"));
        }
        for _ in 0..30 {
            text.push_str("actions a\n");
        }
        let errors = parse_with_limit(&text, 5).unwrap_err();
        let lines: Vec<usize> = errors.iter().map(|e| e.position.line).collect();
        assert_eq!(lines, [1, 2, 2, 3, 3]);
        assert_eq!(errors.total(), 1 + 60 + 30);
        assert_eq!(parse(&text).unwrap_err().as_slice().len(), DEFAULT_LIMIT);
    }

    mod random_input {
        use super::*;
        use proptest::prelude::*;

        /// Fragments that make the lexer and parser take their rarer paths.
        const FRAGMENTS: &[&str] = &[
            "state",
            "edge",
            "initial",
            "propositions",
            "actions",
            "robot",
            "adversary",
            "s0",
            "s1",
            "A",
            "go",
            "{",
            "}",
            "\"",
            "\\",
            "\\n",
            "\\q",
            "#",
            " ",
            "\t",
            "\r",
            "\n",
            "é",
            "@",
            "\"x y\"",
            "{}",
        ];

        /// The errors, if any, must be located within the text, in order.
        fn check(text: &str) {
            if let Err(errors) = parse(text) {
                let lines = text.split('\n').count();
                for error in &errors {
                    assert!(error.position.line >= 1 && error.position.line <= lines + 1);
                    assert!(error.position.column >= 1);
                    assert!(!error.to_string().contains('\n'));
                }
                assert!(errors.as_slice().is_sorted_by_key(|e| e.position));
            }
        }

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(256))]

            #[test]
            fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
                check(&String::from_utf8_lossy(&bytes));
            }

            #[test]
            fn random_token_soup_never_panics(
                fragments in proptest::collection::vec(proptest::sample::select(FRAGMENTS), 0..60)
            ) {
                check(&fragments.concat());
            }
        }
    }
}
