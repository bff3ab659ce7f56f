//! The lexical rules of the arena format shared by the reader and the writer: which names may be
//! written bare, the escapes of quoted names, and how a name is written back.
//!
//! Invariant: for every string `s`, reading the output of [`write_name`] gives back `s`; a name
//! is written bare exactly when it is a non-empty identifier, so the written form is canonical.

use std::borrow::Cow;
use std::fmt;

use super::model::Owner;
use crate::diagnostic::brief;

/// The keywords that start a line.
pub const ITEMS: [&str; 5] = ["propositions", "actions", "initial", "state", "edge"];
/// The keywords of the owner field of a `state` line.
pub const OWNERS: [(&str, Owner); 2] = [("robot", Owner::Robot), ("adversary", Owner::Adversary)];

/// The escapes of a quoted name: the letter after the backslash and the character it stands for.
/// The writer escapes exactly these characters, so no written line contains a raw line break.
const ESCAPES: [(char, char); 5] = [
    ('\\', '\\'),
    ('"', '"'),
    ('n', '\n'),
    ('r', '\r'),
    ('t', '\t'),
];

/// Whether `byte` may appear in a bare (unquoted) name: ASCII letters, digits, `_`, `.`, `-`.
pub fn is_identifier_byte(byte: u8) -> bool {
    byte.is_ascii_alphanumeric() || matches!(byte, b'_' | b'.' | b'-')
}

/// Whether `name` can be written without quotes.
pub fn is_identifier(name: &str) -> bool {
    !name.is_empty() && name.bytes().all(is_identifier_byte)
}

/// The owner that `keyword` names.
pub fn owner(keyword: &str) -> Option<Owner> {
    OWNERS.iter().find(|(k, _)| *k == keyword).map(|&(_, o)| o)
}

/// The keyword that names `owner`.
pub fn owner_keyword(owner: Owner) -> &'static str {
    OWNERS
        .iter()
        .find(|(_, o)| *o == owner)
        .map_or("", |&(k, _)| k)
}

/// The lines of `text` with their 1-based numbers, without line terminators (`\n` or `\r\n`).
pub fn lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.split('\n').enumerate().map(|(i, line)| {
        let line = line.strip_suffix('\r').unwrap_or(line);
        (i + 1, line)
    })
}

/// The character that `\letter` stands for inside a quoted name.
pub fn unescape(letter: char) -> Option<char> {
    ESCAPES.iter().find(|&&(l, _)| l == letter).map(|&(_, c)| c)
}

fn escape(c: char) -> Option<char> {
    ESCAPES.iter().find(|&&(_, e)| e == c).map(|&(l, _)| l)
}

/// Writes `name` as the format spells it: bare if it is an identifier, else double-quoted with
/// escapes.
pub fn write_name<W: fmt::Write>(out: &mut W, name: &str) -> fmt::Result {
    if is_identifier(name) {
        out.write_str(name)
    } else {
        write_quoted(out, name)
    }
}

/// Writes `text` double-quoted with escapes, whatever it is.
pub fn write_quoted<W: fmt::Write>(out: &mut W, text: &str) -> fmt::Result {
    out.write_char('"')?;
    let mut run_start = 0;
    for (i, c) in text.char_indices() {
        if let Some(letter) = escape(c) {
            out.write_str(&text[run_start..i])?;
            out.write_char('\\')?;
            out.write_char(letter)?;
            run_start = i + c.len_utf8();
        }
    }
    out.write_str(&text[run_start..])?;
    out.write_char('"')
}

/// Why a quoted name could not be read: the quote is not closed on its line, or a backslash
/// escapes a letter that has no escape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QuoteError {
    /// The closing quote is missing from the line.
    Unterminated,
    /// A backslash before the letter given, which has no escape.
    UnknownEscape(char),
}

/// Reads the double-quoted name whose opening quote is at byte `at` of `line`: the name
/// (borrowed from the line unless it contains escapes) and the byte offset just after the
/// closing quote; an error with the byte offset it concerns (the opening quote, or the
/// backslash of an unknown escape). Linear in the name's length. Every reader of the format's
/// names (arenas, weights files) goes through this, so they share its quoting rules.
pub fn read_quoted(line: &str, at: usize) -> Result<(Cow<'_, str>, usize), (usize, QuoteError)> {
    let bytes = line.as_bytes();
    let start = at + 1;
    let special = |from: usize| {
        bytes[from..]
            .iter()
            .position(|&b| b == b'"' || b == b'\\')
            .map(|i| from + i)
    };
    let unterminated = (at, QuoteError::Unterminated);
    let mut i = special(start).ok_or(unterminated)?;
    if bytes[i] == b'"' {
        return Ok((Cow::Borrowed(&line[start..i]), i + 1));
    }
    let mut name = String::from(&line[start..i]);
    loop {
        if bytes[i] == b'"' {
            return Ok((Cow::Owned(name), i + 1));
        }
        // A backslash: the escaped letter follows.
        let letter = line[i + 1..].chars().next().ok_or(unterminated)?;
        let c = unescape(letter).ok_or((i, QuoteError::UnknownEscape(letter)))?;
        name.push(c);
        let after = i + 1 + letter.len_utf8();
        i = special(after).ok_or(unterminated)?;
        name.push_str(&line[after..i]);
    }
}

/// A name read by [`read_name`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NameToken<'a> {
    /// The name, unescaped (borrowed from the line unless it contained escapes).
    pub name: Cow<'a, str>,
    /// The byte offset just after the name (after the closing quote, if quoted).
    pub end: usize,
    /// Whether the name was written between double quotes.
    pub quoted: bool,
}

/// Reads the name starting at byte `at` of `line`, bare or quoted; `None` when no name starts
/// there. The caller checks what may follow (a separator, in the arena format).
pub fn read_name(line: &str, at: usize) -> Result<Option<NameToken<'_>>, (usize, QuoteError)> {
    let bytes = line.as_bytes();
    match bytes.get(at) {
        Some(b'"') => read_quoted(line, at).map(|(name, end)| {
            Some(NameToken {
                name,
                end,
                quoted: true,
            })
        }),
        Some(&b) if is_identifier_byte(b) => {
            let length = bytes[at..]
                .iter()
                .position(|&b| !is_identifier_byte(b))
                .unwrap_or(bytes.len() - at);
            Ok(Some(NameToken {
                name: Cow::Borrowed(&line[at..at + length]),
                end: at + length,
                quoted: false,
            }))
        }
        _ => Ok(None),
    }
}

/// A name displayed as the format spells it, whole: for writers (`write_name`).
pub struct Spelled<'a>(pub &'a str);

impl fmt::Display for Spelled<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_name(f, self.0)
    }
}

/// A name displayed as the format spells it, for messages that quote the input back: cut after
/// [`crate::diagnostic::QUOTE_WIDTH`] characters ([`brief`]).
pub struct Name<'a>(pub &'a str);

impl fmt::Display for Name<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", brief(Spelled(self.0)))
    }
}

/// A text displayed double-quoted with escapes, as a quoted name of the format, for messages:
/// cut as [`Name`] is.
pub struct Quoted<'a>(pub &'a str);

impl fmt::Display for Quoted<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        struct Whole<'a>(&'a str);
        impl fmt::Display for Whole<'_> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write_quoted(f, self.0)
            }
        }
        write!(f, "{}", brief(Whole(self.0)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers_are_bare_and_everything_else_is_quoted_with_escapes() {
        assert_eq!(Name("s1").to_string(), "s1");
        assert_eq!(Name("x.y-z_0").to_string(), "x.y-z_0");
        assert_eq!(Name("state").to_string(), "state");
        assert_eq!(Name("").to_string(), r#""""#);
        assert_eq!(Name("((0,2),(4,2),0)").to_string(), r#""((0,2),(4,2),0)""#);
        assert_eq!(
            Name("a\"b\\c\nd\re\tf é").to_string(),
            r#""a\"b\\c\nd\re\tf é""#
        );
    }

    /// The terminals of each production of `grammar/arena.ebnf`, comments removed.
    fn grammar() -> Vec<(String, Vec<String>)> {
        let mut text = include_str!("../../../../grammar/arena.ebnf").to_string();
        while let Some(start) = text.find("(*") {
            let end = text[start..].find("*)").expect("closed comment") + start + 2;
            text.replace_range(start..end, "");
        }
        let mut productions = Vec::new();
        for production in text.split(';').filter(|p| p.contains('=')) {
            let (name, body) = production.split_once('=').unwrap();
            let mut terminals = Vec::new();
            let mut rest = body;
            while let Some(start) = rest.find(['"', '\'']) {
                let quote = rest[start..].chars().next().unwrap();
                let end = rest[start + 1..].find(quote).expect("closed terminal") + start + 1;
                terminals.push(rest[start + 1..end].to_string());
                rest = &rest[end + 1..];
            }
            productions.push((name.trim().to_string(), terminals));
        }
        productions
    }

    fn terminals(production: &str) -> Vec<String> {
        grammar()
            .into_iter()
            .find(|(name, _)| name == production)
            .map(|(_, terminals)| terminals)
            .unwrap_or_else(|| panic!("no production {production}"))
    }

    #[test]
    fn the_grammar_has_the_readers_keywords_identifier_characters_and_escapes() {
        let mut keywords: Vec<String> = grammar()
            .into_iter()
            .flat_map(|(_, terminals)| terminals)
            .filter(|t| t.len() > 1 && t.chars().all(|c| c.is_ascii_alphabetic()))
            .collect();
        keywords.sort();
        let mut expected: Vec<String> = ITEMS
            .iter()
            .chain(OWNERS.iter().map(|(k, _)| k))
            .map(|k| k.to_string())
            .collect();
        expected.sort();
        assert_eq!(keywords, expected);

        let punctuation: Vec<u8> = (0..128u8)
            .filter(|&b| is_identifier_byte(b) && !b.is_ascii_alphanumeric())
            .collect();
        let mut idchar: Vec<u8> = terminals("idchar")
            .iter()
            .map(|t| t.as_bytes()[0])
            .collect();
        idchar.sort();
        assert_eq!(idchar, punctuation);
        assert!(
            (0..128u8)
                .filter(u8::is_ascii_alphanumeric)
                .all(is_identifier_byte)
        );

        let escape = terminals("escape");
        assert_eq!(escape[0], "\\");
        let letters: Vec<char> = escape[1..].iter().flat_map(|t| t.chars()).collect();
        let accepted: Vec<char> = (0..128u8)
            .map(char::from)
            .filter(|&c| unescape(c).is_some())
            .collect();
        let mut sorted = letters.clone();
        sorted.sort();
        assert_eq!(sorted, accepted);
    }

    #[test]
    fn names_are_read_bare_or_quoted_with_located_errors() {
        let line = r#"edge s.1 "go \"north\"" "t" "x\q" "open"#;
        let token = |at| {
            let token: NameToken<'_> = read_name(line, at).unwrap().unwrap();
            (token.name.into_owned(), token.end, token.quoted)
        };
        assert_eq!(token(0), ("edge".to_string(), 4, false));
        assert_eq!(read_name(line, 4), Ok(None));
        assert_eq!(token(5), ("s.1".to_string(), 8, false));
        assert_eq!(token(9), ("go \"north\"".to_string(), 23, true));
        assert!(matches!(
            read_name(line, 24).unwrap().unwrap().name,
            Cow::Borrowed("t")
        ));
        assert_eq!(
            read_name(line, 28),
            Err((30, QuoteError::UnknownEscape('q')))
        );
        assert_eq!(read_name(line, 34), Err((34, QuoteError::Unterminated)));
        // Writing then reading gives the name back, escapes included.
        for name in ["plain", "", "a\"b\\c\nd\re\tf é", "x y"] {
            let written = Spelled(name).to_string();
            let read = read_name(&written, 0).unwrap().unwrap();
            assert_eq!((read.name.as_ref(), read.end), (name, written.len()));
        }
    }

    #[test]
    fn escapes_are_inverse_to_each_other() {
        for (letter, c) in ESCAPES {
            assert_eq!(unescape(letter), Some(c));
            assert_eq!(escape(c), Some(letter));
        }
        assert_eq!(unescape('x'), None);
        assert_eq!(escape('x'), None);
    }
}
