//! Spot's LTL syntax: the lexer (nom) and an operator-precedence parser with explicit stacks.
//!
//! Lexical rules follow Spot's scanner (`spot/parsetl/scantl.ll`) and manual (`doc/tl/tl.pdf`):
//! - whitespace (space, tab, `\n`, `\r`) separates tokens and is otherwise ignored;
//! - a *word* is a maximal run of `[A-Za-z0-9_.]`. Where a formula is expected, a word is
//!   `1`/`0`; `true`/`false` in any case; `xor`; one of the single letters `U R V W M` (binary
//!   operators, an error there); `F`, `G` or `X` followed by a digit and anything (`X1`,
//!   `F100ZX`) is an atomic proposition; otherwise a word starting with `F`, `G` or `X` is that
//!   unary operator followed by the rest of the word, lexed again (`XXFd` = `X X F d`,
//!   `FOO` = `F OO`, `Xfoo` = `X foo`), except that `False…` in any case after an `F` is the
//!   constant false; any other word is an atomic proposition (`aUb`, `a_U_b`, `O`, `Ub`,
//!   `True1`). After an operand (atomic proposition, constant or `)`), a word starting with
//!   `U R V W M` is that binary operator followed by the rest (`a Ub` = `a U b`), and `xor`
//!   alone is the operator;
//! - a double-quoted string is an atomic proposition named by its content, where a backslash
//!   makes the next character literal (`"a\"b"` is `a"b`); control characters and the empty
//!   name are rejected;
//! - operators: `! ~`, `& && /\`, `| || \/ +`, `xor ^`, `-> => -->`, `<-> <=> <-->`,
//!   `X ()`, `F <>`, `G []`, `U`, `R V`, `W`, `M`.
//!
//! Precedence, lowest first (Spot's parser, `parsetl.yy`): `->` and `<->` (one level,
//! right-associative), `|`, `xor`, `&` (left-associative), `U R W M` (one level,
//! right-associative), then the unary operators `! X F G`, which bind tighter than every
//! binary operator (`X a U b` = `(X a) U b`). Spot's manual lists `xor` below `|`; its parser,
//! which decides what Spot reads, puts it above, and so do we: `a | b xor c` = `a | (b xor c)`.
//!
//! Spot also reads PSL and SERE (`{…}`, `[*]`, `[]->`, `;`, …), Wring's `=0`/`=1`, comments,
//! bracketed operators (`X[3]`, `F[1:2]`) and Unicode operators. These are rejected with an
//! error naming them. Two corners differ from Spot's scanner on purpose: after a constant, Spot
//! does not split `Ub` (so `1 Ub` is an error there), we split it as after a proposition; and
//! Spot's manual omits `.` from bare names, but its scanner and printer allow it, as we do.
//!
//! Invariants: [`parse`] never panics and never recurses on the input's nesting (parentheses,
//! unary operators and right-associative chains go on explicit stacks), so 1 MB of `(` is a
//! clean error and 100000 nested `X` a valid formula. Spans are byte offsets into the input;
//! errors carry 1-based line and character-column positions, located in one pass however many
//! there are ([`parse_with_limit`] says how the parser recovers from them).

use nom::branch::alt;
use nom::bytes::complete::{tag, take_while, take_while1};
use nom::combinator::value;
use nom::{IResult, Parser};

use super::formula::{BinaryOp, Formula, FormulaKind, NaryOp, Span, UnaryOp, flatten};
use crate::diagnostic::{Collector, DEFAULT_LIMIT, Diagnostics, brief};
use crate::position::{Locator, Position};

/// A lexical error: the byte offset where it is and the message.
type LexError = (usize, String);

// ---------------------------------------------------------------------------------------------
// Precedence, shared with the printer.

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Assoc {
    Left,
    Right,
}

/// Binding strength of unary operators: tighter than every binary operator.
pub(super) const PREFIX_LEVEL: u8 = 6;
/// Binding strength of atoms, constants and parenthesised formulas.
pub(super) const ATOM_LEVEL: u8 = 7;

pub(super) fn binary_binding(op: BinaryOp) -> (u8, Assoc) {
    match op {
        BinaryOp::Implies | BinaryOp::Equiv => (1, Assoc::Right),
        BinaryOp::Xor => (3, Assoc::Left),
        BinaryOp::Until | BinaryOp::Release | BinaryOp::WeakUntil | BinaryOp::StrongRelease => {
            (5, Assoc::Right)
        }
    }
}

pub(super) fn nary_level(op: NaryOp) -> u8 {
    match op {
        NaryOp::Or => 2,
        NaryOp::And => 4,
    }
}

// ---------------------------------------------------------------------------------------------
// Lexer.

#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum Token {
    Open,
    Close,
    Prefix(UnaryOp),
    Binary(BinaryOp),
    Nary(NaryOp),
    Const(bool),
    Atom(String),
    End,
}

/// A symbol: a token, or the reason why Spot syntax we do not support is rejected.
type Symbol = Result<Token, &'static str>;

const PSL_SUFFIX: &str = "PSL suffix operators (`[]->`, `<>->`, `|->`, ...) are not supported";
const BRACKETS: &str = "bracketed operators (`X[n]`, `F[n:m]`, `G[n:m]`) and SERE repetitions \
                        (`[*]`, `[+]`, `[=n]`, `[->n]`) are not supported";
const SERE: &str = "SERE (PSL) operators (`{...}`, `;`, `:`, `*`, `##`) are not supported; \
                    use `&` for conjunction";
const WRING: &str = "Wring's `=0` and `=1` suffixes are not supported; write `!a` or `a`";

fn symbol(input: &str) -> IResult<&str, Symbol, ()> {
    let logic = alt((
        value(Ok(Token::Binary(BinaryOp::Equiv)), tag("<-->")),
        value(Ok(Token::Binary(BinaryOp::Equiv)), tag("<->")),
        value(Ok(Token::Binary(BinaryOp::Equiv)), tag("<=>")),
        value(Err(PSL_SUFFIX), alt((tag("<>->"), tag("<>=>")))),
        value(Ok(Token::Prefix(UnaryOp::Finally)), tag("<>")),
        value(Err(PSL_SUFFIX), alt((tag("[]->"), tag("[]=>")))),
        value(Ok(Token::Prefix(UnaryOp::Globally)), tag("[]")),
        value(Err(BRACKETS), tag("[")),
        value(Err(PSL_SUFFIX), alt((tag("|->"), tag("|=>")))),
        value(Ok(Token::Nary(NaryOp::Or)), alt((tag("||"), tag("|")))),
        value(Ok(Token::Binary(BinaryOp::Implies)), tag("-->")),
        value(Ok(Token::Binary(BinaryOp::Implies)), tag("->")),
        value(Ok(Token::Binary(BinaryOp::Implies)), tag("=>")),
        value(Err(WRING), alt((tag("=0"), tag("=1")))),
    ));
    let rest = alt((
        value(
            Ok(Token::Nary(NaryOp::And)),
            alt((tag("&&"), tag("&"), tag("/\\"))),
        ),
        value(Err("comments (`/* ... */`) are not supported"), tag("/*")),
        value(Ok(Token::Nary(NaryOp::Or)), alt((tag("\\/"), tag("+")))),
        value(Ok(Token::Binary(BinaryOp::Xor)), tag("^")),
        value(Ok(Token::Prefix(UnaryOp::Not)), alt((tag("!"), tag("~")))),
        value(Ok(Token::Prefix(UnaryOp::Next)), tag("()")),
        value(Ok(Token::Open), tag("(")),
        value(Ok(Token::Close), tag(")")),
        value(
            Err(SERE),
            alt((tag("{"), tag("}"), tag("*"), tag(";"), tag(":"), tag("##"))),
        ),
    ));
    alt((logic, rest)).parse(input)
}

pub(super) fn is_word_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '.'
}

fn word(input: &str) -> IResult<&str, &str, ()> {
    take_while1(is_word_char).parse(input)
}

fn whitespace(input: &str) -> IResult<&str, &str, ()> {
    take_while(|c| matches!(c, ' ' | '\t' | '\n' | '\r')).parse(input)
}

fn unary_letter(letter: u8) -> Option<UnaryOp> {
    match letter {
        b'X' => Some(UnaryOp::Next),
        b'F' => Some(UnaryOp::Finally),
        b'G' => Some(UnaryOp::Globally),
        _ => None,
    }
}

fn binary_letter(letter: u8) -> Option<BinaryOp> {
    match letter {
        b'U' => Some(BinaryOp::Until),
        b'R' | b'V' => Some(BinaryOp::Release),
        b'W' => Some(BinaryOp::WeakUntil),
        b'M' => Some(BinaryOp::StrongRelease),
        _ => None,
    }
}

/// The first token of `input` (which starts with a word character) where a formula is
/// expected, and its length in bytes. Only atomic propositions consume a whole word, so lexing
/// `XXX…Xa` stays linear.
pub(super) fn operand_word(input: &str) -> Result<(Token, usize), &'static str> {
    let bytes = input.as_bytes();
    let word = || match word(input) {
        Ok((_, word)) => word,
        Err(_) => "",
    };
    match bytes[0] {
        b'0' => Ok((Token::Const(false), 1)),
        b'1' => Ok((Token::Const(true), 1)),
        b'2'..=b'9' => {
            Err("atomic propositions cannot start with a digit (unless quoted, as in \"2a\")")
        }
        first @ (b'F' | b'G' | b'X') => {
            if bytes.get(1).is_some_and(u8::is_ascii_digit) {
                let word = word();
                Ok((Token::Atom(word.to_string()), word.len()))
            } else if first == b'F'
                && bytes
                    .get(..5)
                    .is_some_and(|prefix| prefix.eq_ignore_ascii_case(b"false"))
            {
                Ok((Token::Const(false), 5))
            } else {
                let op = unary_letter(first).unwrap_or(UnaryOp::Next);
                Ok((Token::Prefix(op), 1))
            }
        }
        first => {
            let word = word();
            if word.eq_ignore_ascii_case("true") {
                Ok((Token::Const(true), 4))
            } else if word.eq_ignore_ascii_case("false") {
                Ok((Token::Const(false), 5))
            } else if word == "xor" {
                Ok((Token::Binary(BinaryOp::Xor), 3))
            } else if word == "first_match" {
                Err("PSL's `first_match` is not supported (quote it to name an atomic proposition)")
            } else if let (Some(op), 1) = (binary_letter(first), word.len()) {
                Ok((Token::Binary(op), 1))
            } else {
                Ok((Token::Atom(word.to_string()), word.len()))
            }
        }
    }
}

/// The first token of `input` (which starts with a word character) after an operand, where a
/// binary operator is expected.
fn operator_word(input: &str) -> Result<(Token, usize), &'static str> {
    if let Some(op) = binary_letter(input.as_bytes()[0]) {
        Ok((Token::Binary(op), 1))
    } else {
        operand_word(input)
    }
}

/// The name inside a double-quoted atomic proposition starting at `start` (on the `"`), and
/// the offset just past the closing quote.
fn quoted(text: &str, start: usize) -> Result<(String, usize), LexError> {
    let mut name = String::new();
    let mut chars = text[start + 1..].char_indices();
    while let Some((index, c)) = chars.next() {
        let c = match c {
            '"' if name.is_empty() => {
                return Err((
                    start,
                    "an atomic proposition cannot be empty (`\"\"`)".to_string(),
                ));
            }
            '"' => return Ok((name, start + 1 + index + 1)),
            '\\' => match chars.next() {
                Some((_, escaped)) => escaped,
                None => break,
            },
            c => c,
        };
        if c.is_control() {
            return Err((
                start + 1 + index,
                "control characters are not allowed in atomic propositions".to_string(),
            ));
        }
        name.push(c);
    }
    Err((
        start,
        "unterminated quoted atomic proposition: missing the closing `\"`".to_string(),
    ))
}

/// The next token at or after byte `offset`. `after_operand` selects how words split (see the
/// module documentation).
fn lex(text: &str, offset: usize, after_operand: bool) -> Result<(Token, Span), LexError> {
    let rest = &text[offset..];
    let start = match whitespace(rest) {
        Ok((after, _)) => text.len() - after.len(),
        Err(_) => offset,
    };
    let rest = &text[start..];
    let span = |length: usize| Span {
        start,
        end: start + length,
    };
    let Some(first) = rest.chars().next() else {
        return Ok((Token::End, span(0)));
    };
    if first == '"' {
        let (name, end) = quoted(text, start)?;
        return Ok((Token::Atom(name), Span { start, end }));
    }
    if is_word_char(first) {
        let classified = if after_operand {
            operator_word(rest)
        } else {
            operand_word(rest)
        };
        return match classified {
            Ok((token, length)) => Ok((token, span(length))),
            Err(message) => Err((start, message.to_string())),
        };
    }
    match symbol(rest) {
        Ok((after, Ok(token))) => Ok((token, span(rest.len() - after.len()))),
        Ok((_, Err(message))) => Err((start, message.to_string())),
        Err(_) if !first.is_ascii() => Err((
            start,
            format!(
                "unexpected non-ASCII character `{first}` (Spot's Unicode operators are not \
                 supported; quote atomic propositions that contain it)"
            ),
        )),
        Err(_) => Err((
            start,
            format!("unexpected character `{}`", first.escape_default()),
        )),
    }
}

// ---------------------------------------------------------------------------------------------
// Parser.

/// An operator waiting for its operands, or an open parenthesis.
enum Pending {
    Open(Span),
    Prefix(UnaryOp, Span),
    Binary(BinaryOp, Span),
    Nary(NaryOp, Span),
}

impl Pending {
    /// Binding strength of a pending infix operator.
    fn level(&self) -> Option<u8> {
        match self {
            Pending::Binary(op, _) => Some(binary_binding(*op).0),
            Pending::Nary(op, _) => Some(nary_level(*op)),
            Pending::Open(_) | Pending::Prefix(..) => None,
        }
    }
}

/// Parses one LTL formula in Spot's syntax. See the module documentation for the rules; errors
/// are reported as [`parse_with_limit`] says, with the default limit.
pub fn parse(text: &str) -> Result<Formula, Diagnostics> {
    parse_with_limit(text, DEFAULT_LIMIT)
}

/// Tokens to read without an error after one before the next error is reported: what comes
/// right after an error is often its consequence (`a U xor` lacks an operand after `xor` only
/// because `xor` was not one).
const RECOVERY_TOKENS: u8 = 2;

/// Errors found so far, and whether the next one should be reported.
struct Errors<'a> {
    locator: Locator<'a>,
    found: Collector<String>,
    /// Tokens still to read without an error before another error is reported.
    quiet: u8,
}

impl Errors<'_> {
    /// A syntax error at byte `offset`: reported unless it follows another too closely (the
    /// message is only made if it is reported).
    fn syntax(&mut self, offset: usize, message: impl FnOnce() -> String) {
        if self.quiet == 0 {
            let position = self.locator.position(offset);
            self.found.add(position, message());
        }
        self.quiet = RECOVERY_TOKENS;
    }

    /// The errors, after one that ends the reading (always reported).
    fn last(mut self, offset: usize, message: String) -> Diagnostics {
        let position = self.locator.position(offset);
        self.found.add(position, message);
        self.found.failed()
    }

    /// A token read without an error.
    fn accepted(&mut self) {
        self.quiet = self.quiet.saturating_sub(1);
    }
}

/// Parses one LTL formula in Spot's syntax, reporting at most `limit` errors (the others are
/// counted).
///
/// Errors of the grammar are recovered from, so that one reading reports the independent ones:
/// a missing operand is assumed where a formula was expected, a missing binary operator (`&`)
/// between two operands, an unmatched `)` is skipped, and a missing `)` is assumed at the end.
/// An error is not reported within two tokens of the previous one (yacc's rule, shortened:
/// those are mostly its consequences). A lexical error (a character or construct outside the
/// supported syntax, an unterminated or malformed quoted name) ends the reading: where the bad
/// token ends, and so where to resume, is unknown.
pub fn parse_with_limit(text: &str, limit: usize) -> Result<Formula, Diagnostics> {
    let mut errors = Errors {
        locator: Locator::new(text),
        found: Collector::new(limit),
        quiet: 0,
    };
    let mut operands: Vec<Formula> = Vec::new();
    let mut pending: Vec<Pending> = Vec::new();
    // How many `Pending::Open` are in `pending`.
    let mut open = 0usize;
    let mut offset = 0;
    // The last token read, to say what a missing formula should follow.
    let mut last: Option<Span> = None;
    // Whether a formula is expected (prefix operators and `(` until an atomic proposition or
    // a constant), or, after an operand, `)`s, then a binary operator or the end.
    let mut expect_operand = true;
    // A token to handle again in the other state, after an error.
    let mut retry: Option<(Token, Span)> = None;
    loop {
        let (token, span) = match retry.take() {
            Some(token) => token,
            None => match lex(text, offset, !expect_operand) {
                Ok(token) => token,
                Err((at, message)) => return Err(errors.last(at, message)),
            },
        };
        offset = span.end;
        if expect_operand {
            match token {
                Token::Open => {
                    pending.push(Pending::Open(span));
                    open += 1;
                }
                Token::Prefix(op) => pending.push(Pending::Prefix(op, span)),
                Token::Const(value) => {
                    operands.push(Formula::new(FormulaKind::Const(value), span));
                    expect_operand = false;
                }
                Token::Atom(name) => {
                    operands.push(Formula::new(FormulaKind::Atom(name), span));
                    expect_operand = false;
                }
                Token::End if last.is_none() => {
                    return Err(errors.last(span.start, "empty formula".to_string()));
                }
                other => {
                    let after = |last: Option<Span>| match last {
                        Some(last) => format!(" after `{}`", brief(&text[last.start..last.end])),
                        None => String::new(),
                    };
                    errors.syntax(span.start, || {
                        let found = describe(text, &other, span);
                        format!("expected a formula{}, found {found}", after(last))
                    });
                    // Read on as if a formula had been there.
                    let missing = Span {
                        start: span.start,
                        end: span.start,
                    };
                    operands.push(Formula::new(FormulaKind::Const(true), missing));
                    expect_operand = false;
                    retry = Some((other, span));
                    continue;
                }
            }
            errors.accepted();
            last = Some(span);
            continue;
        }
        match token {
            Token::Binary(op) => {
                reduce_before(&mut operands, &mut pending, binary_binding(op));
                pending.push(Pending::Binary(op, span));
                expect_operand = true;
            }
            Token::Nary(op) => {
                reduce_before(&mut operands, &mut pending, (nary_level(op), Assoc::Left));
                pending.push(Pending::Nary(op, span));
                expect_operand = true;
            }
            Token::Close => loop {
                match pending.pop() {
                    Some(Pending::Open(_)) => {
                        open -= 1;
                        break;
                    }
                    Some(operator) => reduce(&mut operands, operator),
                    None => {
                        // Skipped.
                        errors.syntax(span.start, || "unmatched `)`".to_string());
                        break;
                    }
                }
            },
            Token::End => {
                while let Some(operator) = pending.pop() {
                    if let Pending::Open(paren) = operator {
                        // Closed here.
                        errors.syntax(span.start, || {
                            let opened = describe_position(Position::of_offset(text, paren.start));
                            format!("missing `)` to close the `(` at {opened}")
                        });
                    }
                    reduce(&mut operands, operator);
                }
                let root = operands
                    .pop()
                    .expect("one operand is left once all reduced");
                return errors.found.or_ok(flatten(root));
            }
            other => {
                errors.syntax(span.start, || {
                    let close = if open > 0 { ", `)`" } else { "" };
                    let found = describe(text, &other, span);
                    format!(
                        "expected a binary operator{close} or the end of the formula, found \
                         {found}"
                    )
                });
                // Read on as if `&` had been there.
                let and = (nary_level(NaryOp::And), Assoc::Left);
                reduce_before(&mut operands, &mut pending, and);
                pending.push(Pending::Nary(NaryOp::And, span));
                expect_operand = true;
                retry = Some((other, span));
                continue;
            }
        }
        errors.accepted();
        last = Some(span);
    }
}

fn describe_position(position: Position) -> String {
    if position.line == 1 {
        format!("column {}", position.column)
    } else {
        format!("line {}, column {}", position.line, position.column)
    }
}

/// How a token is named in an error message.
fn describe(text: &str, token: &Token, span: Span) -> String {
    let written = brief(&text[span.start..span.end]);
    match token {
        Token::End => "the end of the formula".to_string(),
        Token::Atom(_) => format!("atomic proposition `{written}`"),
        Token::Const(_) => format!("constant `{written}`"),
        Token::Prefix(_) => format!("unary operator `{written}`"),
        Token::Binary(_) | Token::Nary(_) => format!("binary operator `{written}`"),
        Token::Open | Token::Close => format!("`{written}`"),
    }
}

/// Reduces the pending operators that bind at least as tightly as an incoming binary operator
/// of the given binding (all prefix operators; infix ones of higher level, or of the same level
/// when it is left-associative), stopping at an open parenthesis.
fn reduce_before(operands: &mut Vec<Formula>, pending: &mut Vec<Pending>, incoming: (u8, Assoc)) {
    let (level, assoc) = incoming;
    while let Some(top) = pending.last() {
        let reduces = match top {
            Pending::Open(_) => false,
            Pending::Prefix(..) => true,
            _ => top.level().is_some_and(|top_level| {
                top_level > level || (top_level == level && assoc == Assoc::Left)
            }),
        };
        if !reduces {
            break;
        }
        if let Some(operator) = pending.pop() {
            reduce(operands, operator);
        }
    }
}

/// Applies a pending operator to the operands on top of the stack. The parser only pushes an
/// operator after its left operand and only reduces after a right operand, so they are there.
fn reduce(operands: &mut Vec<Formula>, operator: Pending) {
    let mut pop = || operands.pop().expect("operator reduced after its operands");
    let formula = match operator {
        Pending::Open(_) => return,
        Pending::Prefix(op, span) => Formula::new(FormulaKind::Unary(op, Box::new(pop())), span),
        Pending::Binary(op, span) => {
            let right = pop();
            let left = pop();
            Formula::new(
                FormulaKind::Binary(op, Box::new(left), Box::new(right)),
                span,
            )
        }
        Pending::Nary(op, span) => {
            let right = pop();
            let left = pop();
            // Flattened once the whole formula is read (in linear time).
            Formula::new(FormulaKind::Nary(op, vec![left, right]), span)
        }
    };
    operands.push(formula);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ap(name: &str) -> Formula {
        Formula::atom(name)
    }
    fn not(f: Formula) -> Formula {
        !f
    }
    fn bin(op: BinaryOp, l: Formula, r: Formula) -> Formula {
        Formula::binary(op, l, r)
    }
    fn until(l: Formula, r: Formula) -> Formula {
        bin(BinaryOp::Until, l, r)
    }
    fn and(operands: Vec<Formula>) -> Formula {
        Formula::and(operands)
    }
    fn or(operands: Vec<Formula>) -> Formula {
        Formula::or(operands)
    }
    fn parsed(text: &str) -> Formula {
        parse(text).unwrap_or_else(|e| panic!("{text:?} should parse: {e}"))
    }

    #[test]
    fn temporal_binary_operators_are_right_associative() {
        assert_eq!(parsed("a U b U c"), until(ap("a"), until(ap("b"), ap("c"))));
        assert_eq!(
            parsed("a U b R c W d M e"),
            until(
                ap("a"),
                bin(
                    BinaryOp::Release,
                    ap("b"),
                    bin(
                        BinaryOp::WeakUntil,
                        ap("c"),
                        bin(BinaryOp::StrongRelease, ap("d"), ap("e"))
                    )
                )
            )
        );
        assert_eq!(
            parsed("(a U b) U c"),
            until(until(ap("a"), ap("b")), ap("c"))
        );
    }

    #[test]
    fn boolean_precedence_follows_spots_parser() {
        // `->` and `<->` share the lowest level and group to the right; then `|`, `xor`, `&`.
        assert_eq!(
            parsed("!a & b | c -> d <-> e"),
            bin(
                BinaryOp::Implies,
                or(vec![and(vec![not(ap("a")), ap("b")]), ap("c")]),
                bin(BinaryOp::Equiv, ap("d"), ap("e"))
            )
        );
        assert_eq!(
            parsed("a -> b -> c"),
            bin(
                BinaryOp::Implies,
                ap("a"),
                bin(BinaryOp::Implies, ap("b"), ap("c"))
            )
        );
        assert_eq!(
            parsed("a <-> b -> c"),
            bin(
                BinaryOp::Equiv,
                ap("a"),
                bin(BinaryOp::Implies, ap("b"), ap("c"))
            )
        );
        assert_eq!(
            parsed("a | b xor c"),
            or(vec![ap("a"), bin(BinaryOp::Xor, ap("b"), ap("c"))])
        );
        assert_eq!(
            parsed("a xor b | c"),
            or(vec![bin(BinaryOp::Xor, ap("a"), ap("b")), ap("c")])
        );
        assert_eq!(
            parsed("a xor b & c"),
            bin(BinaryOp::Xor, ap("a"), and(vec![ap("b"), ap("c")]))
        );
        assert_eq!(
            parsed("a xor b xor c"),
            bin(BinaryOp::Xor, bin(BinaryOp::Xor, ap("a"), ap("b")), ap("c"))
        );
        assert_eq!(
            parsed("a & b | c & d"),
            or(vec![
                and(vec![ap("a"), ap("b")]),
                and(vec![ap("c"), ap("d")])
            ])
        );
    }

    #[test]
    fn temporal_operators_bind_tighter_than_boolean_ones() {
        assert_eq!(
            parsed("a U b & c"),
            and(vec![until(ap("a"), ap("b")), ap("c")])
        );
        assert_eq!(
            parsed("a & b U c"),
            and(vec![ap("a"), until(ap("b"), ap("c"))])
        );
        assert_eq!(
            parsed("a U (b & c)"),
            until(ap("a"), and(vec![ap("b"), ap("c")]))
        );
    }

    #[test]
    fn unary_operators_bind_tighter_than_binary_ones() {
        assert_eq!(parsed("X a U b"), until(Formula::next(ap("a")), ap("b")));
        assert_eq!(parsed("F a U b"), until(Formula::finally(ap("a")), ap("b")));
        assert_eq!(parsed("!a U b"), until(not(ap("a")), ap("b")));
        assert_eq!(
            parsed("a U !b U c"),
            until(ap("a"), until(not(ap("b")), ap("c")))
        );
        assert_eq!(
            parsed("G a R b"),
            bin(BinaryOp::Release, Formula::globally(ap("a")), ap("b"))
        );
        assert_eq!(
            parsed("F G a"),
            Formula::finally(Formula::globally(ap("a")))
        );
    }

    #[test]
    fn conjunctions_and_disjunctions_are_flat_whatever_the_parentheses() {
        let abc = and(vec![ap("a"), ap("b"), ap("c")]);
        assert_eq!(parsed("(a & b) & c"), abc);
        assert_eq!(parsed("a & (b & c)"), abc);
        assert_eq!(parsed("a & b & c"), abc);
        match &parsed("a | (b | c) | ((d))").kind {
            FormulaKind::Nary(NaryOp::Or, operands) => assert_eq!(operands.len(), 4),
            other => panic!("expected a flat disjunction, got {other:?}"),
        }
    }

    #[test]
    fn operator_letters_split_off_words_as_spot_does() {
        let x = Formula::next;
        let f = Formula::finally;
        let g = Formula::globally;
        assert_eq!(parsed("XXFd"), x(x(f(ap("d")))));
        assert_eq!(parsed("GFa"), g(f(ap("a"))));
        assert_eq!(parsed("F!Xf"), f(not(x(ap("f")))));
        assert_eq!(parsed("Fab"), f(ap("ab")));
        assert_eq!(parsed("FOO"), f(ap("OO")));
        assert_eq!(parsed("FINISHED"), f(ap("INISHED")));
        assert_eq!(parsed("Xfoo"), x(ap("foo")));
        assert_eq!(parsed("FX100"), f(ap("X100")));
        assert_eq!(parsed("X_1"), x(ap("_1")));
        // After an operand, U R V W M start a binary operator.
        assert_eq!(parsed("a Ub"), until(ap("a"), ap("b")));
        assert_eq!(parsed("(a)Ub"), until(ap("a"), ap("b")));
        assert_eq!(parsed("a UFXb"), until(ap("a"), f(x(ap("b")))));
        assert_eq!(parsed("a Vb"), bin(BinaryOp::Release, ap("a"), ap("b")));
    }

    #[test]
    fn words_that_are_atomic_propositions() {
        for name in [
            "aUb", "a_U_b", "O", "A", "B", "Ub", "Ua", "X1", "F100ZX", "G0x", "Truex", "falsey",
            "xorb", "a.b", "_", "S", "first", "T",
        ] {
            assert_eq!(parsed(name), ap(name), "{name}");
        }
        assert_eq!(parsed("\"a b\" U c"), until(ap("a b"), ap("c")));
        assert_eq!(parsed("\"F\""), ap("F"));
        assert_eq!(parsed("\"true\""), ap("true"));
        assert_eq!(parsed(r#""a\"b\\c""#), ap("a\"b\\c"));
        assert_eq!(parsed("\"é ∧ x\""), ap("é ∧ x"));
    }

    #[test]
    fn constants_in_every_spelling() {
        for text in ["1", "true", "True", "TRUE", "tRuE"] {
            assert_eq!(parsed(text), Formula::constant(true), "{text}");
        }
        for text in ["0", "false", "False", "FALSE", "fAlSe"] {
            assert_eq!(parsed(text), Formula::constant(false), "{text}");
        }
        assert_eq!(parsed("Xtrue"), Formula::next(Formula::constant(true)));
        assert_eq!(parsed("X(0)"), Formula::next(Formula::constant(false)));
    }

    #[test]
    fn every_alias_means_its_operator() {
        let same = [
            ("!a", vec!["~a"]),
            ("a & b", vec!["a && b", "a /\\ b", "a&b"]),
            ("a | b", vec!["a || b", "a \\/ b", "a + b", "a|b"]),
            ("a -> b", vec!["a => b", "a --> b", "a->b"]),
            ("a <-> b", vec!["a <=> b", "a <--> b", "a<->b"]),
            ("a xor b", vec!["a ^ b", "a^b"]),
            ("F a", vec!["<> a", "<>a", "Fa"]),
            ("G a", vec!["[] a", "[]a", "Ga", "G\t\na"]),
            ("X a", vec!["() a", "()a", "Xa"]),
            ("a R b", vec!["a V b"]),
            ("X G a", vec!["X[]a", "X [] a"]),
        ];
        for (canonical, aliases) in same {
            for alias in aliases {
                assert_eq!(parsed(alias), parsed(canonical), "{alias} vs {canonical}");
            }
        }
        assert_eq!(parsed("a & b"), and(vec![ap("a"), ap("b")]));
        assert_eq!(parsed("a | b"), or(vec![ap("a"), ap("b")]));
        assert_eq!(parsed("a -> b"), bin(BinaryOp::Implies, ap("a"), ap("b")));
        assert_eq!(parsed("a <-> b"), bin(BinaryOp::Equiv, ap("a"), ap("b")));
        assert_eq!(parsed("a xor b"), bin(BinaryOp::Xor, ap("a"), ap("b")));
        assert_eq!(parsed("a W b"), bin(BinaryOp::WeakUntil, ap("a"), ap("b")));
        assert_eq!(
            parsed("a M b"),
            bin(BinaryOp::StrongRelease, ap("a"), ap("b"))
        );
    }

    #[test]
    fn spans_index_operator_tokens_in_the_original_text() {
        let formula = parsed("  a  U  <>b");
        assert_eq!(formula.span, Span { start: 5, end: 6 });
        let FormulaKind::Binary(_, left, right) = &formula.kind else {
            panic!("expected U, got {formula:?}");
        };
        assert_eq!(left.span, Span { start: 2, end: 3 });
        assert_eq!(right.span, Span { start: 8, end: 10 });
        // The flattened conjunction keeps its leftmost `&`.
        assert_eq!(parsed("a & (b && c)").span, Span { start: 2, end: 3 });
        assert_eq!(parsed("(a && b) & c").span, Span { start: 3, end: 5 });
        assert_eq!(parsed("\"x y\"").span, Span { start: 0, end: 5 });
    }

    #[test]
    fn malformed_formulas_report_the_expected_column_and_message() {
        let cases: &[(&str, usize, usize, &str)] = &[
            ("", 1, 1, "empty formula"),
            ("   ", 1, 4, "empty formula"),
            (
                "a U",
                1,
                4,
                "expected a formula after `U`, found the end of the formula",
            ),
            (
                "a U U b",
                1,
                5,
                "expected a formula after `U`, found binary operator `U`",
            ),
            ("U a", 1, 1, "expected a formula, found binary operator `U`"),
            ("!", 1, 2, "expected a formula after `!`"),
            ("G", 1, 2, "expected a formula after `G`"),
            ("()", 1, 3, "expected a formula after `()`"),
            ("( )", 1, 3, "expected a formula after `(`, found `)`"),
            ("(a", 1, 3, "missing `)` to close the `(` at column 1"),
            (
                "a\n& (b",
                2,
                5,
                "missing `)` to close the `(` at line 2, column 3",
            ),
            ("a)", 1, 2, "unmatched `)`"),
            ("a U b)", 1, 6, "unmatched `)`"),
            (
                "a b",
                1,
                3,
                "expected a binary operator or the end of the formula, found atomic proposition `b`",
            ),
            (
                "(a b)",
                1,
                4,
                "expected a binary operator, `)` or the end of the formula",
            ),
            ("a <> b", 1, 3, "found unary operator `<>`"),
            ("1 U 10", 1, 6, "found constant `0`"),
            ("Falsey", 1, 6, "found atomic proposition `y`"),
            ("a U xor", 1, 5, "found binary operator `xor`"),
            ("V", 1, 1, "found binary operator `V`"),
            ("\"ab", 1, 1, "unterminated quoted atomic proposition"),
            ("a & \"b\\", 1, 5, "unterminated quoted atomic proposition"),
            ("\"\"", 1, 1, "cannot be empty"),
            ("\"a\u{1}b\"", 1, 3, "control characters"),
            ("a & é", 1, 5, "non-ASCII character `é`"),
            ("□a", 1, 1, "Unicode operators are not supported"),
            ("{a}", 1, 1, "SERE"),
            ("a * b", 1, 3, "SERE"),
            ("a ; b", 1, 3, "SERE"),
            ("a[*]", 1, 2, "bracketed operators"),
            ("X[2] a", 1, 2, "bracketed operators"),
            ("a |-> b", 1, 3, "PSL suffix"),
            ("{a} []-> b", 1, 1, "SERE"),
            ("a=0", 1, 2, "Wring"),
            ("2a", 1, 1, "cannot start with a digit"),
            ("a $ b", 1, 3, "unexpected character `$`"),
            ("first_match(a)", 1, 1, "first_match"),
            ("a /* c */", 1, 3, "comments"),
        ];
        for &(text, line, column, fragment) in cases {
            let errors = parse(text).expect_err(text);
            let error = errors.first();
            assert_eq!(
                error.position,
                Position { line, column },
                "position for {text:?}: {errors}"
            );
            assert!(
                error.message.contains(fragment),
                "message for {text:?}: {:?} lacks {fragment:?}",
                error.message
            );
        }
    }

    /// The errors of `text`, each as `LINE:COL: message`.
    fn errors(text: &str) -> Vec<String> {
        let errors = parse(text).expect_err(text);
        errors.iter().map(ToString::to_string).collect()
    }

    #[test]
    fn independent_errors_in_one_formula_are_all_reported() {
        // A missing right operand, then (after `& (`, `b`, `U`) a missing one before `)`, an
        // operand with no operator before it, a stray `)`, and an unclosed `(` at the end.
        let text = "(a U) & (b U) & c d)\n| (e";
        assert_eq!(
            errors(text),
            [
                "1:5: expected a formula after `U`, found `)`",
                "1:13: expected a formula after `U`, found `)`",
                "1:19: expected a binary operator or the end of the formula, found atomic \
                 proposition `d`",
                "2:5: missing `)` to close the `(` at line 2, column 3",
            ]
        );
        // The stray `)` at 1:20 comes right after the error at `d` (one token, `d` itself, was
        // read since): not reported, as errors that close are mostly consequences:
        assert_eq!(
            errors("a U xor"),
            ["1:5: expected a formula after `U`, found binary operator `xor`"]
        );
        assert_eq!(
            errors("a & & b & & c"),
            [
                "1:5: expected a formula after `&`, found binary operator `&`",
                "1:11: expected a formula after `&`, found binary operator `&`",
            ]
        );
        // A lexical error ends the reading; the errors before it stay.
        assert_eq!(
            errors("(a U) & b $ c U U"),
            [
                "1:5: expected a formula after `U`, found `)`",
                "1:11: unexpected character `$`",
            ]
        );
    }

    #[test]
    fn the_error_limit_keeps_the_first_errors_and_counts_the_others() {
        let text = "a & & b & & c & & d";
        let errors = parse_with_limit(text, 2).expect_err(text);
        let columns: Vec<usize> = errors.iter().map(|e| e.position.column).collect();
        assert_eq!(columns, [5, 11]);
        assert_eq!(errors.total(), 3);
    }

    #[test]
    fn errors_display_as_line_column_and_message() {
        let errors = parse("a U U b").expect_err("invalid");
        assert_eq!(
            errors.to_string(),
            "1:5: expected a formula after `U`, found binary operator `U`"
        );
    }

    #[test]
    fn long_inputs_are_located_without_quadratic_work() {
        let text = "(".repeat(1_000_000);
        let errors = parse(&text).expect_err("no formula");
        assert_eq!(
            errors.first().position,
            Position {
                line: 1,
                column: 1_000_001
            }
        );
        assert_eq!(errors.total(), 1);
        // An error every three tokens over a long line: each located from the previous one.
        let text = "a & & ".repeat(100_000);
        let errors = parse(&text).expect_err("invalid");
        assert_eq!(errors.total(), 100_000);
        assert_eq!(errors.as_slice()[19].position.column, 19 * 6 + 5);
    }
}
