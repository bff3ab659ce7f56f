//! Tokens of the HOA format (its "common tokens" section), read on demand, so that errors are
//! found in text order and the parser can resume after one ([`Lexer::skip_line`]).
//!
//! Whitespace is `[ \t\n\r]`; comments are `/* ... */` and nest. `t` and `f` are Booleans, not
//! identifiers; an identifier or Boolean immediately followed by `:` is a header name. Integers
//! are `0|[1-9][0-9]*` below 2^31. Strings are double-quoted with `\` escaping any character.
//! Errors carry byte offsets; the parser turns them into line and column.

use std::fmt;

use crate::diagnostic::brief;

/// A syntax error at a byte offset of the text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Located {
    pub offset: usize,
    pub message: String,
}

impl Located {
    pub fn new(offset: usize, message: impl Into<String>) -> Located {
        Located {
            offset,
            message: message.into(),
        }
    }
}

/// The largest integer the format allows, 2^31 - 1.
const MAX_INT: u32 = (1 << 31) - 1;

#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum Token<'a> {
    /// `name:`, stored without the colon.
    Header(&'a str),
    Identifier(&'a str),
    Boolean(bool),
    /// `@name`, stored without the `@`.
    Alias(&'a str),
    Int(u32),
    /// The string's value, escapes resolved.
    Str(String),
    /// One of `! & | ( ) [ ] { }`.
    Symbol(char),
    Body,
    End,
    Abort,
    Eof,
}

impl fmt::Display for Token<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Token::Header(name) => write!(f, "`{}:`", brief(name)),
            Token::Identifier(name) => write!(f, "`{}`", brief(name)),
            Token::Boolean(value) => write!(f, "`{}`", if *value { 't' } else { 'f' }),
            Token::Alias(name) => write!(f, "`@{}`", brief(name)),
            Token::Int(value) => write!(f, "`{value}`"),
            Token::Str(value) => write!(f, "the string {}", brief(format_args!("{value:?}"))),
            Token::Symbol(c) => write!(f, "`{c}`"),
            Token::Body => f.write_str("`--BODY--`"),
            Token::End => f.write_str("`--END--`"),
            Token::Abort => f.write_str("`--ABORT--`"),
            Token::Eof => f.write_str("the end of the input"),
        }
    }
}

/// A token and the byte offset where it starts.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Spanned<'a> {
    pub token: Token<'a>,
    pub offset: usize,
}

pub(super) struct Lexer<'a> {
    text: &'a str,
    position: usize,
    /// The token read ahead, and the offset where it ends.
    peeked: Option<(Spanned<'a>, usize)>,
    /// The offset where the last token handed out by `next` ends.
    consumed: usize,
}

fn is_identifier_start(c: u8) -> bool {
    c.is_ascii_alphabetic() || c == b'_'
}

fn is_identifier_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b'-'
}

impl<'a> Lexer<'a> {
    pub fn new(text: &'a str) -> Lexer<'a> {
        Lexer {
            text,
            position: 0,
            peeked: None,
            consumed: 0,
        }
    }

    pub fn peek(&mut self) -> Result<&Spanned<'a>, Located> {
        if self.peeked.is_none() {
            let token = self.lex()?;
            self.peeked = Some((token, self.position));
        }
        Ok(&self.peeked.as_ref().expect("just filled").0)
    }

    pub fn next(&mut self) -> Result<Spanned<'a>, Located> {
        let (token, end) = match self.peeked.take() {
            Some(peeked) => peeked,
            None => (self.lex()?, self.position),
        };
        self.consumed = end;
        Ok(token)
    }

    /// The token after `HOA:`: the format version is an identifier that may contain dots, as
    /// in `v1.1`, which Spot writes; anything else is lexed as usual.
    pub fn next_version(&mut self) -> Result<Spanned<'a>, Located> {
        if self.peeked.is_some() {
            return self.next();
        }
        self.skip_blanks()?;
        let start = self.position;
        let bytes = self.text.as_bytes();
        if !bytes.get(start).is_some_and(|&c| is_identifier_start(c)) {
            return self.next();
        }
        let mut end = start;
        while end < bytes.len() && (is_identifier_char(bytes[end]) || bytes[end] == b'.') {
            end += 1;
        }
        if bytes.get(end) == Some(&b':') {
            return self.next(); // a header name: the version is missing
        }
        self.position = end;
        self.consumed = end;
        Ok(Spanned {
            token: Token::Identifier(&self.text[start..end]),
            offset: start,
        })
    }

    /// The text between two offsets, for quoting input in messages.
    pub fn slice(&self, start: usize, end: usize) -> &'a str {
        &self.text[start..end]
    }

    /// The offset just past the last token consumed.
    pub fn consumed_end(&self) -> usize {
        self.consumed
    }

    /// Resumes reading at the start of the line after the one holding `offset` (or where the
    /// lexer is, if that is further): what a reader does after an error at `offset`. A token
    /// read ahead is kept if it starts there or after.
    pub fn skip_line(&mut self, offset: usize) {
        let next_line = self.text[offset.min(self.text.len())..]
            .find('\n')
            .map_or(self.text.len(), |i| offset + i + 1);
        if let Some((peeked, _)) = &self.peeked {
            if peeked.offset >= next_line {
                return;
            }
            self.peeked = None;
        }
        self.position = self.position.max(next_line);
    }

    fn skip_blanks(&mut self) -> Result<(), Located> {
        let bytes = self.text.as_bytes();
        loop {
            while self.position < bytes.len()
                && matches!(bytes[self.position], b' ' | b'\t' | b'\n' | b'\r')
            {
                self.position += 1;
            }
            if !self.text[self.position..].starts_with("/*") {
                return Ok(());
            }
            let start = self.position;
            let mut depth = 0usize;
            loop {
                let rest = &self.text[self.position..];
                if rest.starts_with("/*") {
                    depth += 1;
                    self.position += 2;
                } else if rest.starts_with("*/") {
                    depth -= 1;
                    self.position += 2;
                    if depth == 0 {
                        break;
                    }
                } else if let Some(c) = rest.chars().next() {
                    self.position += c.len_utf8();
                } else {
                    // Nothing after it can be read.
                    return Err(Located::new(start, "unterminated comment"));
                }
            }
        }
    }

    fn lex(&mut self) -> Result<Spanned<'a>, Located> {
        self.skip_blanks()?;
        let start = self.position;
        let bytes = self.text.as_bytes();
        let spanned = |token| Spanned {
            token,
            offset: start,
        };
        let Some(&first) = bytes.get(start) else {
            return Ok(spanned(Token::Eof));
        };
        let token = match first {
            b'!' | b'&' | b'|' | b'(' | b')' | b'[' | b']' | b'{' | b'}' => {
                self.position += 1;
                Token::Symbol(first as char)
            }
            b'"' => self.string()?,
            b'0'..=b'9' => self.integer()?,
            b'@' => {
                let end = self.word_end(start + 1);
                if end == start + 1 {
                    return Err(Located::new(start, "expected an alias name after `@`"));
                }
                self.position = end;
                Token::Alias(&self.text[start + 1..end])
            }
            b'-' => {
                let end = self.word_end(start);
                let word = &self.text[start..end];
                self.position = end;
                match word {
                    "--BODY--" => Token::Body,
                    "--END--" => Token::End,
                    "--ABORT--" => Token::Abort,
                    _ => {
                        return Err(Located::new(
                            start,
                            format!("malformed token `{}`", brief(word)),
                        ));
                    }
                }
            }
            c if is_identifier_start(c) => {
                let end = self.word_end(start);
                let word = &self.text[start..end];
                if bytes.get(end) == Some(&b':') {
                    self.position = end + 1;
                    Token::Header(word)
                } else {
                    self.position = end;
                    match word {
                        "t" => Token::Boolean(true),
                        "f" => Token::Boolean(false),
                        _ => Token::Identifier(word),
                    }
                }
            }
            _ => {
                let c = self.text[start..].chars().next().unwrap_or('?');
                return Err(Located::new(start, format!("unexpected character `{c}`")));
            }
        };
        Ok(spanned(token))
    }

    /// The end of the run of identifier characters starting at `from`.
    fn word_end(&self, from: usize) -> usize {
        let bytes = self.text.as_bytes();
        let mut end = from;
        while end < bytes.len() && is_identifier_char(bytes[end]) {
            end += 1;
        }
        end
    }

    fn integer(&mut self) -> Result<Token<'a>, Located> {
        let start = self.position;
        let end = self.word_end(start);
        let word = &self.text[start..end];
        self.position = end;
        if !word.bytes().all(|b| b.is_ascii_digit()) {
            return Err(Located::new(
                start,
                format!("malformed number `{}`", brief(word)),
            ));
        }
        if word.len() > 1 && word.starts_with('0') {
            return Err(Located::new(
                start,
                format!("malformed number `{}` (leading zero)", brief(word)),
            ));
        }
        match word.parse::<u32>() {
            Ok(value) if value <= MAX_INT => Ok(Token::Int(value)),
            _ => Err(Located::new(
                start,
                format!(
                    "number `{}` is too large (the format allows up to {MAX_INT})",
                    brief(word)
                ),
            )),
        }
    }

    fn string(&mut self) -> Result<Token<'a>, Located> {
        let start = self.position;
        let mut value = String::new();
        let mut chars = self.text[start + 1..].char_indices();
        while let Some((i, c)) = chars.next() {
            match c {
                '"' => {
                    self.position = start + 1 + i + 1;
                    return Ok(Token::Str(value));
                }
                '\\' => match chars.next() {
                    Some((_, escaped)) => value.push(escaped),
                    None => break,
                },
                _ => value.push(c),
            }
        }
        // Nothing after it can be read.
        self.position = self.text.len();
        Err(Located::new(start, "unterminated string"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tokens(text: &str) -> Result<Vec<Token<'_>>, Located> {
        let mut lexer = Lexer::new(text);
        let mut out = Vec::new();
        loop {
            let token = lexer.next()?.token;
            if token == Token::Eof {
                return Ok(out);
            }
            out.push(token);
        }
    }

    #[test]
    fn tokens_follow_the_common_token_rules() {
        assert_eq!(
            tokens("AP: 2 \"a\" \"b\\\"c\" /* c /* nested */ still */ t f tf [!0&@x_1] --BODY--"),
            Ok(vec![
                Token::Header("AP"),
                Token::Int(2),
                Token::Str("a".into()),
                Token::Str("b\"c".into()),
                Token::Boolean(true),
                Token::Boolean(false),
                Token::Identifier("tf"),
                Token::Symbol('['),
                Token::Symbol('!'),
                Token::Int(0),
                Token::Symbol('&'),
                Token::Alias("x_1"),
                Token::Symbol(']'),
                Token::Body,
            ])
        );
        // A Boolean followed by a colon is a header name; `foo--ABORT--` is one identifier.
        assert_eq!(
            tokens("t: foo--ABORT-- --ABORT--"),
            Ok(vec![
                Token::Header("t"),
                Token::Identifier("foo--ABORT--"),
                Token::Abort
            ])
        );
        // A header name needs its colon attached.
        assert_eq!(
            tokens("acc-name : x"),
            Err(Located::new(9, "unexpected character `:`"))
        );
    }

    #[test]
    fn malformed_tokens_are_located() {
        let error = |text| tokens(text).unwrap_err();
        assert_eq!(
            error("1 01"),
            Located::new(2, "malformed number `01` (leading zero)")
        );
        assert_eq!(
            error("2147483648"),
            Located::new(
                0,
                "number `2147483648` is too large (the format allows up to 2147483647)"
            )
        );
        assert_eq!(error("  \"abc"), Located::new(2, "unterminated string"));
        assert_eq!(error("/* /* */"), Located::new(0, "unterminated comment"));
        assert_eq!(
            error("--BOD--"),
            Located::new(0, "malformed token `--BOD--`")
        );
        assert_eq!(error("3a"), Located::new(0, "malformed number `3a`"));
        assert_eq!(error("é"), Located::new(0, "unexpected character `é`"));
        assert_eq!(
            error("@ x"),
            Located::new(0, "expected an alias name after `@`")
        );
    }
}
