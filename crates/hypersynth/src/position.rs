//! Positions in input text, shared by every parser's error type.

use std::fmt;

/// A 1-based line and column in a text. Columns count characters, not bytes, so that a caret
/// printed under the line points at the right place.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Position {
    /// The line, from 1.
    pub line: usize,
    /// The column, from 1, in characters (not bytes).
    pub column: usize,
}

impl Position {
    /// The position of byte offset `offset` in `text`. Offsets past the end (or inside a
    /// multi-byte character) are clamped to the nearest character boundary before them.
    pub fn of_offset(text: &str, offset: usize) -> Position {
        let mut end = offset.min(text.len());
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let before = &text[..end];
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        Position {
            line: before.matches('\n').count() + 1,
            column: before[line_start..].chars().count() + 1,
        }
    }
}

/// Positions of many byte offsets of one text, for readers that report several errors: each
/// costs time proportional to the distance from the previous offset asked for (plus, going
/// backwards to another line, that line's length), so offsets asked for in increasing order
/// cost one pass over the text in all.
#[derive(Clone, Debug)]
pub(crate) struct Locator<'a> {
    text: &'a str,
    offset: usize,
    position: Position,
}

impl<'a> Locator<'a> {
    pub(crate) fn new(text: &'a str) -> Locator<'a> {
        Locator {
            text,
            offset: 0,
            position: Position { line: 1, column: 1 },
        }
    }

    /// The position of byte offset `offset`, clamped as [`Position::of_offset`] does.
    pub(crate) fn position(&mut self, offset: usize) -> Position {
        let text = self.text;
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        if offset >= self.offset {
            for c in text[self.offset..offset].chars() {
                if c == '\n' {
                    self.position.line += 1;
                    self.position.column = 1;
                } else {
                    self.position.column += 1;
                }
            }
        } else {
            let between = &text[offset..self.offset];
            let lines = between.matches('\n').count();
            if lines == 0 {
                self.position.column -= between.chars().count();
            } else {
                let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
                self.position = Position {
                    line: self.position.line - lines,
                    column: text[line_start..offset].chars().count() + 1,
                };
            }
        }
        self.offset = offset;
        self.position
    }
}

impl fmt::Display for Position {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_map_to_lines_and_character_columns() {
        let text = "ab\ncé d\n";
        assert_eq!(
            Position::of_offset(text, 0),
            Position { line: 1, column: 1 }
        );
        assert_eq!(
            Position::of_offset(text, 3),
            Position { line: 2, column: 1 }
        );
        // 'é' is two bytes (offsets 4 and 5); 'd' at offset 7 is the fourth character of line 2.
        assert_eq!(
            Position::of_offset(text, 7),
            Position { line: 2, column: 4 }
        );
        // Inside 'é': clamped back to its start.
        assert_eq!(
            Position::of_offset(text, 5),
            Position { line: 2, column: 2 }
        );
        assert_eq!(
            Position::of_offset(text, 100),
            Position { line: 3, column: 1 }
        );
    }

    #[test]
    fn a_locator_agrees_with_of_offset_forwards_and_backwards() {
        let text = "ab\ncé d\n\nxyz";
        let mut locator = Locator::new(text);
        for offset in [0, 1, 3, 5, 7, 9, 12, 100, 10, 7, 4, 2, 0, 8, 3] {
            assert_eq!(
                locator.position(offset),
                Position::of_offset(text, offset),
                "offset {offset}"
            );
        }
    }
}
