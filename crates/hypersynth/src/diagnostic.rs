//! Located diagnostics, the one error type of every reader of text (LTL formulas, HOA, arenas,
//! maps, weights files), and the one renderer that shows them under their source line.
//!
//! A reader returns [`Diagnostics`]: every error it found, in text order, up to a limit
//! ([`DEFAULT_LIMIT`] unless the reader is asked for another), and how many there were in all.
//! [`Source::render`] turns them into messages for a person: `NAME:LINE:COL: message`, the line
//! of the text and a caret under the column.
//!
//! A message that quotes its input back (a name, a token, a line) quotes it with [`brief`]: at
//! most [`QUOTE_WIDTH`] characters, cut ones marked with `...`, so that no input, however long
//! its lines, makes a long message; a dependency's message that may quote input goes through
//! [`brief_quotes`].

use std::fmt;

use crate::position::Position;

/// How many diagnostics a reader keeps unless told otherwise; the others are only counted.
pub const DEFAULT_LIMIT: usize = 20;

/// What is wrong at one place of a text.
///
/// `M` is the message: a `String`, or a reader's typed kind of error (such as
/// [`crate::arena::ParseErrorKind`]) whose `Display` is the message, for callers that match on
/// it. Messages are one line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic<M = String> {
    /// Line and column (in characters) in the text read.
    pub position: Position,
    /// What is wrong, one line.
    pub message: M,
}

impl<M> Diagnostic<M> {
    /// The diagnostic `message` at `position`.
    pub fn new(position: Position, message: M) -> Diagnostic<M> {
        Diagnostic { position, message }
    }

    /// The same diagnostic with its message converted.
    pub fn map<N>(self, convert: impl FnOnce(M) -> N) -> Diagnostic<N> {
        Diagnostic {
            position: self.position,
            message: convert(self.message),
        }
    }
}

impl<M: fmt::Display> fmt::Display for Diagnostic<M> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.position, self.message)
    }
}

impl<M: fmt::Display + fmt::Debug> std::error::Error for Diagnostic<M> {}

/// The errors found in one text: at least one, in text order (by position; errors at one
/// position in the order the reader found them), at most the reader's limit, and how many were
/// found in all.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostics<M = String> {
    kept: Vec<Diagnostic<M>>,
    total: usize,
}

impl<M> Diagnostics<M> {
    /// The first error in the text.
    pub fn first(&self) -> &Diagnostic<M> {
        &self.kept[0]
    }

    /// The errors kept, in text order.
    pub fn as_slice(&self) -> &[Diagnostic<M>] {
        &self.kept
    }

    /// The errors kept, in text order.
    pub fn iter(&self) -> std::slice::Iter<'_, Diagnostic<M>> {
        self.kept.iter()
    }

    /// How many errors were found, kept or not.
    pub fn total(&self) -> usize {
        self.total
    }

    /// How many errors were found beyond those kept.
    pub fn omitted(&self) -> usize {
        self.total - self.kept.len()
    }

    /// The same diagnostics with their messages converted.
    pub fn map<N>(self, mut convert: impl FnMut(M) -> N) -> Diagnostics<N> {
        Diagnostics {
            kept: self.kept.into_iter().map(|d| d.map(&mut convert)).collect(),
            total: self.total,
        }
    }
}

impl<M> From<Diagnostic<M>> for Diagnostics<M> {
    fn from(diagnostic: Diagnostic<M>) -> Diagnostics<M> {
        Diagnostics {
            kept: vec![diagnostic],
            total: 1,
        }
    }
}

impl<'a, M> IntoIterator for &'a Diagnostics<M> {
    type Item = &'a Diagnostic<M>;
    type IntoIter = std::slice::Iter<'a, Diagnostic<M>>;

    fn into_iter(self) -> Self::IntoIter {
        self.kept.iter()
    }
}

/// The errors kept, one `LINE:COL: message` per line, then `N more errors not shown` if some
/// were omitted. A single error displays as [`Diagnostic`] does.
impl<M: fmt::Display> fmt::Display for Diagnostics<M> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, diagnostic) in self.kept.iter().enumerate() {
            if i > 0 {
                f.write_str("\n")?;
            }
            write!(f, "{diagnostic}")?;
        }
        if self.omitted() > 0 {
            write!(f, "\n{}", more_errors(self.omitted()))?;
        }
        Ok(())
    }
}

impl<M: fmt::Display + fmt::Debug> std::error::Error for Diagnostics<M> {}

fn more_errors(omitted: usize) -> String {
    let plural = if omitted == 1 { "" } else { "s" };
    format!("{omitted} more error{plural} not shown")
}

/// Gathers a reader's diagnostics in any order and keeps the first `limit` in text order,
/// counting the others. Memory stays within `2 × limit` diagnostics whatever the input; a push
/// costs amortised O(log limit).
#[derive(Debug)]
pub(crate) struct Collector<M> {
    limit: usize,
    kept: Vec<Diagnostic<M>>,
    total: usize,
}

impl<M> Collector<M> {
    /// A collector keeping at most `limit` diagnostics (at least one).
    pub(crate) fn new(limit: usize) -> Collector<M> {
        Collector {
            limit: limit.max(1),
            kept: Vec::new(),
            total: 0,
        }
    }

    pub(crate) fn push(&mut self, diagnostic: Diagnostic<M>) {
        self.total += 1;
        self.kept.push(diagnostic);
        if self.kept.len() >= 2 * self.limit {
            self.compact();
        }
    }

    /// Pushes `message` at `position`.
    pub(crate) fn add(&mut self, position: Position, message: M) {
        self.push(Diagnostic::new(position, message));
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.total == 0
    }

    /// Adds every diagnostic of `other` (kept or only counted) to this collector.
    pub(crate) fn absorb(&mut self, other: Collector<M>) {
        let counted = other.total - other.kept.len();
        for diagnostic in other.kept {
            self.push(diagnostic);
        }
        self.total += counted;
    }

    /// Whether a diagnostic at `position` pushed now would be kept (else it would only be
    /// counted, as one pushed with [`Collector::count`]): for readers whose messages are costly
    /// to make. O(limit).
    pub(crate) fn keeps(&self, position: Position) -> bool {
        self.kept.iter().filter(|d| d.position <= position).count() < self.limit
    }

    /// Counts a diagnostic that would not be kept, without making it.
    pub(crate) fn count(&mut self) {
        self.total += 1;
    }

    /// How many diagnostics were pushed.
    pub(crate) fn total(&self) -> usize {
        self.total
    }

    /// Keeps the first `limit` in text order; the sort is stable, so errors at one position
    /// stay in the order they were pushed.
    fn compact(&mut self) {
        self.kept.sort_by_key(|d| d.position);
        self.kept.truncate(self.limit);
    }

    /// The diagnostics, or `None` if there were none.
    pub(crate) fn finish(mut self) -> Option<Diagnostics<M>> {
        if self.total == 0 {
            return None;
        }
        self.compact();
        Some(Diagnostics {
            kept: self.kept,
            total: self.total,
        })
    }

    /// The diagnostics, when at least one was pushed.
    pub(crate) fn failed(self) -> Diagnostics<M> {
        self.finish().expect("a diagnostic was pushed")
    }

    /// `value` if no diagnostic was pushed, else the diagnostics.
    pub(crate) fn or_ok<T>(self, value: T) -> Result<T, Diagnostics<M>> {
        match self.finish() {
            None => Ok(value),
            Some(diagnostics) => Err(diagnostics),
        }
    }
}

/// A text that diagnostics point into, and the name messages give it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Source<'a> {
    /// A file name, `<stdin>`, an option (`--phi`), `argument 2`...
    pub name: &'a str,
    /// The whole text read, whose lines the diagnostics point into.
    pub text: &'a str,
    /// Added to every line number shown: a text that is line `n + 1` of a file has offset `n`.
    pub line_offset: usize,
}

/// The widest excerpt of a line shown under a message, in characters.
const CONTEXT_WIDTH: usize = 72;

/// The most characters of its input a message quotes ([`brief`]).
pub const QUOTE_WIDTH: usize = 80;

/// What marks a cut in a quote or an excerpt.
const CUT: &str = "...";

/// `value` displayed for a message that quotes it: its first [`QUOTE_WIDTH`] characters, then
/// `...` if it has more; control characters escaped (`\n`, `\u{1b}`), so that the message
/// stays one line and the terminal shows what the input holds. Displaying it costs
/// O([`QUOTE_WIDTH`]) whatever the length of `value`.
pub fn brief<T: fmt::Display>(value: T) -> Brief<T> {
    Brief(value)
}

/// See [`brief`].
#[derive(Clone, Copy, Debug)]
pub struct Brief<T>(T);

impl<T: fmt::Display> fmt::Display for Brief<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut out = Shortened {
            out: f,
            left: QUOTE_WIDTH,
            cut: false,
        };
        let written = fmt::write(&mut out, format_args!("{}", self.0));
        match (written, out.cut) {
            (_, true) => f.write_str(CUT),
            (result, false) => result,
        }
    }
}

/// Passes on at most `left` characters (control characters escaped), then fails, noting the
/// cut, so that the value being displayed stops at once.
struct Shortened<'a, 'b> {
    out: &'a mut fmt::Formatter<'b>,
    left: usize,
    cut: bool,
}

impl fmt::Write for Shortened<'_, '_> {
    fn write_str(&mut self, text: &str) -> fmt::Result {
        for c in text.chars() {
            if self.left == 0 {
                self.cut = true;
                return Err(fmt::Error);
            }
            self.left -= 1;
            if c.is_control() {
                write!(self.out, "{}", c.escape_debug())?;
            } else {
                self.out.write_char(c)?;
            }
        }
        Ok(())
    }
}

/// A message made by a dependency (a JSON reader's, say) that may quote its input between
/// backquotes or double quotes: each quoted span of more than [`QUOTE_WIDTH`] characters cut
/// as [`brief`] cuts, and the whole to at most four times that (a span whose closing quote is
/// missing runs to the end).
pub fn brief_quotes(message: &str) -> String {
    let mut out = String::new();
    let mut rest = message;
    while let Some(open) = rest.find(['`', '"']) {
        let quote = rest.as_bytes()[open] as char;
        out.push_str(&rest[..=open]);
        let inside = &rest[open + 1..];
        let (span, after) = match inside.find(quote) {
            Some(close) => inside.split_at(close),
            None => (inside, ""),
        };
        out.push_str(&brief(span).to_string());
        rest = after;
        if let Some(after) = rest.strip_prefix(quote) {
            out.push(quote);
            rest = after;
        }
    }
    out.push_str(rest);
    brief_to(&out, 4 * QUOTE_WIDTH)
}

/// `text`'s first `width` characters, then `...` if it has more.
fn brief_to(text: &str, width: usize) -> String {
    match text.char_indices().nth(width) {
        Some((end, _)) => format!("{}{CUT}", &text[..end]),
        None => text.to_string(),
    }
}

impl<'a> Source<'a> {
    /// The text `text` named `name`, its line numbers shown unchanged (no offset).
    pub fn new(name: &'a str, text: &'a str) -> Source<'a> {
        Source {
            name,
            text,
            line_offset: 0,
        }
    }

    /// The same source, its text being the lines of a file after the first `lines`.
    pub fn with_line_offset(self, lines: usize) -> Source<'a> {
        Source {
            line_offset: lines,
            ..self
        }
    }

    /// `NAME:LINE:COL` for a position in the text.
    pub fn location(&self, position: Position) -> String {
        format!(
            "{}:{}:{}",
            self.name,
            position.line + self.line_offset,
            position.column
        )
    }

    /// One message per diagnostic, in order: `NAME:LINE:COL: message`, then on two lines
    /// indented by four spaces the line of the text (a window of it around the column if it is
    /// long) and a caret under the column; and when some diagnostics were omitted, a last
    /// message `NAME: N more errors not shown`. Messages have no final line break.
    ///
    /// Columns count characters. Tabs and other control characters show as one space, so that
    /// the caret stays under its character; a line longer than 72 characters is cut to the 72
    /// around the column, cuts marked with `...`. A position past the end of its line (or of
    /// the text) puts the caret just after the line's last character.
    pub fn render<M: fmt::Display>(&self, diagnostics: &Diagnostics<M>) -> Vec<String> {
        // The diagnostics are in text order, so one pass over the lines finds all of theirs.
        let mut lines = self.text.lines().enumerate();
        let mut current: Option<(usize, &str)> = None;
        let mut out = Vec::with_capacity(diagnostics.kept.len() + 1);
        for diagnostic in diagnostics {
            let wanted = diagnostic.position.line.saturating_sub(1);
            if current.is_none_or(|(index, _)| index > wanted) {
                lines = self.text.lines().enumerate();
                current = None;
            }
            while current.is_none_or(|(index, _)| index < wanted) {
                match lines.next() {
                    Some(line) => current = Some(line),
                    None => break,
                }
            }
            let line = match current {
                Some((index, line)) if index == wanted => line,
                _ => "",
            };
            out.push(format!(
                "{}: {}\n{}",
                self.location(diagnostic.position),
                diagnostic.message,
                excerpt(line, diagnostic.position.column)
            ));
        }
        if diagnostics.omitted() > 0 {
            out.push(format!(
                "{}: {}",
                self.name,
                more_errors(diagnostics.omitted())
            ));
        }
        out
    }
}

/// The excerpt of `line` around 1-based character `column` and a caret under it, as two lines
/// indented by four spaces.
fn excerpt(line: &str, column: usize) -> String {
    let chars: Vec<char> = line
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    let index = column.saturating_sub(1).min(chars.len());
    let (start, end) = if chars.len() <= CONTEXT_WIDTH {
        (0, chars.len())
    } else {
        let start = index
            .saturating_sub(CONTEXT_WIDTH / 2)
            .min(chars.len() - CONTEXT_WIDTH);
        (start, start + CONTEXT_WIDTH)
    };
    let before = if start > 0 { CUT } else { "" };
    let after = if end < chars.len() { CUT } else { "" };
    let shown: String = chars[start..end].iter().collect();
    let caret_at = before.len() + index - start;
    format!("    {before}{shown}{after}\n    {}^", " ".repeat(caret_at))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(line: usize, column: usize) -> Position {
        Position { line, column }
    }

    fn collected(limit: usize, found: &[(usize, usize, &str)]) -> Diagnostics {
        let mut collector = Collector::new(limit);
        for &(line, column, message) in found {
            collector.add(at(line, column), message.to_string());
        }
        collector.finish().expect("some diagnostics")
    }

    /// The messages the renderer makes for `found` in a text named `name`.
    fn rendered(name: &str, text: &str, found: &[(usize, usize, &str)]) -> Vec<String> {
        Source::new(name, text).render(&collected(20, found))
    }

    #[test]
    fn one_diagnostic_renders_as_location_message_line_and_caret() {
        let text = "initial s0\nstate s0 robot {A\n";
        let found = [(2, 18, "expected a proposition or `}`")];
        assert_eq!(
            rendered("arena.txt", text, &found),
            [
                "arena.txt:2:18: expected a proposition or `}`\n    state s0 robot {A\n                     ^"
            ]
        );
        assert_eq!(
            collected(20, &found).to_string(),
            "2:18: expected a proposition or `}`"
        );
    }

    #[test]
    fn the_caret_counts_characters_and_shows_tabs_as_one_space() {
        // `é` is two bytes and `🙂` four, but one column each; the tab is one column too.
        assert_eq!(
            rendered("<stdin>", "é🙂\tx y\n", &[(1, 4, "here")]),
            ["<stdin>:1:4: here\n    é🙂 x y\n       ^"]
        );
    }

    #[test]
    fn a_line_offset_shifts_the_line_numbers_shown() {
        let source = Source::new("formulas.ltl", "a U U b").with_line_offset(5);
        let diagnostics = collected(20, &[(1, 5, "bad")]);
        assert_eq!(
            source.render(&diagnostics),
            ["formulas.ltl:6:5: bad\n    a U U b\n        ^"]
        );
        assert_eq!(source.location(at(1, 5)), "formulas.ltl:6:5");
    }

    #[test]
    fn positions_past_the_line_or_the_text_put_the_caret_after_its_end() {
        let found = [(1, 9, "past the line"), (3, 1, "at the end")];
        assert_eq!(
            rendered("f", "ab\ncd\n", &found),
            [
                "f:1:9: past the line\n    ab\n      ^",
                "f:3:1: at the end\n    \n    ^"
            ]
        );
    }

    #[test]
    fn long_lines_are_cut_to_a_window_around_the_column() {
        assert_eq!(
            rendered("--phi", &"(".repeat(1_000), &[(1, 1_001, "end")])[0],
            format!(
                "--phi:1:1001: end\n    ...{}\n    {}^",
                "(".repeat(CONTEXT_WIDTH),
                " ".repeat(3 + 72)
            )
        );
        assert_eq!(
            rendered("f", &"x".repeat(200), &[(1, 100, "middle")])[0],
            format!(
                "f:1:100: middle\n    ...{}...\n    {}^",
                "x".repeat(72),
                " ".repeat(3 + 36)
            )
        );
    }

    #[test]
    fn quotes_are_cut_after_their_width_and_escape_control_characters() {
        assert_eq!(brief("short").to_string(), "short");
        let exact = "é".repeat(QUOTE_WIDTH);
        assert_eq!(brief(&exact).to_string(), exact);
        let long = "é".repeat(QUOTE_WIDTH + 1);
        assert_eq!(brief(&long).to_string(), format!("{exact}..."));
        // A value displayed through other displays, cut without displaying the rest.
        let quoted = format!("{:?}", "x".repeat(200));
        assert_eq!(
            brief(format_args!("{:?}", "x".repeat(200))).to_string(),
            format!("{}...", &quoted[..QUOTE_WIDTH])
        );
        assert_eq!(brief("a\nb\u{1b}c").to_string(), "a\\nb\\u{1b}c");
    }

    #[test]
    fn a_dependencys_message_has_its_long_quotes_cut() {
        let long = "y".repeat(500);
        let cut = format!("{}...", "y".repeat(QUOTE_WIDTH));
        assert_eq!(
            brief_quotes(&format!("unknown field `{long}`, expected `a` or `b`")),
            format!("unknown field `{cut}`, expected `a` or `b`")
        );
        assert_eq!(
            brief_quotes(&format!("invalid type: string \"{long}\", expected f64")),
            format!("invalid type: string \"{cut}\", expected f64")
        );
        assert_eq!(
            brief_quotes(&format!("open `{long}")),
            format!("open `{cut}")
        );
        // Text outside quotes is cut as a whole.
        let message = brief_quotes(&"z".repeat(1000));
        assert_eq!(message, format!("{}...", "z".repeat(4 * QUOTE_WIDTH)));
    }

    #[test]
    fn the_first_errors_in_text_order_are_kept_and_the_others_counted() {
        // Pushed out of order (as a two-pass reader does), 25 errors on lines 1..=25.
        let mut found: Vec<(usize, usize, String)> = (1..=25)
            .rev()
            .map(|line| (line, 1, format!("error {line}")))
            .collect();
        found.swap(0, 12);
        let found: Vec<(usize, usize, &str)> =
            found.iter().map(|(l, c, m)| (*l, *c, m.as_str())).collect();
        let diagnostics = collected(3, &found);
        let lines: Vec<usize> = diagnostics.iter().map(|d| d.position.line).collect();
        assert_eq!(lines, [1, 2, 3]);
        assert_eq!((diagnostics.total(), diagnostics.omitted()), (25, 22));
        let text = (1..=25).map(|i| format!("line {i}\n")).collect::<String>();
        let rendered = Source::new("big.txt", &text).render(&diagnostics);
        assert_eq!(rendered.len(), 4);
        assert_eq!(rendered[2], "big.txt:3:1: error 3\n    line 3\n    ^");
        assert_eq!(rendered[3], "big.txt: 22 more errors not shown");
        assert_eq!(
            diagnostics.to_string(),
            "1:1: error 1\n2:1: error 2\n3:1: error 3\n22 more errors not shown"
        );
        // The default limit.
        let many: Vec<(usize, usize, &str)> = (1..=30).map(|line| (line, 2, "e")).collect();
        let diagnostics = collected(DEFAULT_LIMIT, &many);
        assert_eq!(diagnostics.as_slice().len(), 20);
        assert_eq!(diagnostics.omitted(), 10);
        let one_more = collected(1, &[(1, 1, "a"), (1, 2, "b")]);
        assert_eq!(one_more.to_string(), "1:1: a\n1 more error not shown");
    }

    #[test]
    fn errors_at_one_position_keep_the_order_they_were_found_in() {
        let diagnostics = collected(20, &[(2, 1, "second"), (1, 1, "a"), (1, 1, "b")]);
        let messages: Vec<&str> = diagnostics.iter().map(|d| d.message.as_str()).collect();
        assert_eq!(messages, ["a", "b", "second"]);
    }

    #[test]
    fn a_collector_tells_which_diagnostics_it_would_keep() {
        let mut collector = Collector::new(2);
        collector.add(at(3, 1), "c".to_string());
        collector.add(at(1, 1), "a".to_string());
        assert!(collector.keeps(at(2, 1)));
        assert!(!collector.keeps(at(3, 1)));
        assert!(!collector.keeps(at(4, 1)));
        collector.count();
        let diagnostics = collector.finish().unwrap();
        assert_eq!((diagnostics.as_slice().len(), diagnostics.total()), (2, 3));
    }

    #[test]
    fn absorbing_a_collector_adds_its_counted_errors() {
        let mut outer = Collector::new(2);
        outer.add(at(5, 1), "outer".to_string());
        let mut inner = Collector::new(2);
        for line in 1..=4 {
            inner.add(at(line, 1), format!("inner {line}"));
        }
        outer.absorb(inner);
        let diagnostics = outer.finish().unwrap();
        assert_eq!(diagnostics.total(), 5);
        let lines: Vec<usize> = diagnostics.iter().map(|d| d.position.line).collect();
        assert_eq!(lines, [1, 2]);
    }
}
