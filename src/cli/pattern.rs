//! Spot's FORMAT strings: text in which `%` sequences stand for facts about one automaton. Used
//! by `--stats FORMAT` (one line per automaton, on `translate` and `hoa`) and by `-o FORMAT` on
//! `translate` (the file each automaton goes to). A format is parsed when the options are, so an
//! unknown sequence is a usage error that lists the sequences the command knows.

use std::fmt::Write as _;

use hypersynth::automata::Dfa;

/// What a `%` sequence stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// States.
    States,
    /// Edges, as written: one per pair of states.
    Edges,
    /// Transitions, one per letter: states × 2^APs for a complete DFA.
    Transitions,
    /// Acceptance sets: always 1 (`Inf(0)`). In Spot `%a` counts acceptance sets, not
    /// propositions.
    AcceptanceSets,
    /// Atomic propositions.
    Propositions,
    /// The automaton's name: the formula as hypersynth prints it for `translate`, the `name:`
    /// header for `hoa`.
    Name,
    /// The input file as given (empty for a formula given on the command line).
    File,
    /// The formula's line in its file, or its number among the formulas given directly.
    Location,
}

/// The sequences every automaton has: `%s %e %t %a %x`.
pub const COUNTS: [(char, Field); 5] = [
    ('s', Field::States),
    ('e', Field::Edges),
    ('t', Field::Transitions),
    ('a', Field::AcceptanceSets),
    ('x', Field::Propositions),
];

/// The counts and the sequences `extra` a command adds.
pub fn with_counts(extra: &[(char, Field)]) -> Vec<(char, Field)> {
    [COUNTS.as_slice(), extra].concat()
}

/// A parsed FORMAT.
#[derive(Clone, Debug)]
pub struct Pattern {
    pieces: Vec<Piece>,
}

#[derive(Clone, Debug)]
enum Piece {
    Text(String),
    Field(Field),
}

/// One automaton, and where it came from, as the sequences see it.
pub struct Subject<'a> {
    pub dfa: &'a Dfa,
    pub name: &'a str,
    pub file: &'a str,
    pub location: usize,
}

impl Pattern {
    /// Parses `text`, whose `%` sequences must be `%%` or among `known`.
    pub fn parse(text: &str, known: &[(char, Field)]) -> Result<Pattern, String> {
        if text.is_empty() {
            return Err("empty format string".to_string());
        }
        let mut pieces = Vec::new();
        let mut literal = String::new();
        let mut chars = text.chars();
        while let Some(c) = chars.next() {
            if c != '%' {
                literal.push(c);
                continue;
            }
            let field = match chars.next() {
                Some('%') => {
                    literal.push('%');
                    continue;
                }
                Some(letter) => match known.iter().find(|(k, _)| *k == letter) {
                    Some(&(_, field)) => field,
                    None => {
                        let list: Vec<String> =
                            known.iter().map(|(k, _)| format!("%{k}")).collect();
                        return Err(format!(
                            "`%{letter}` is not supported (use {} or %%)",
                            list.join(" ")
                        ));
                    }
                },
                None => return Err("the format ends with a lone `%`".to_string()),
            };
            if !literal.is_empty() {
                pieces.push(Piece::Text(std::mem::take(&mut literal)));
            }
            pieces.push(Piece::Field(field));
        }
        if !literal.is_empty() {
            pieces.push(Piece::Text(literal));
        }
        Ok(Pattern { pieces })
    }

    /// The text with no sequence replaced: `%%` read as `%`, `None` when a sequence other than
    /// `%%` appears.
    pub fn as_literal(&self) -> Option<String> {
        let mut text = String::new();
        for piece in &self.pieces {
            match piece {
                Piece::Text(part) => text.push_str(part),
                Piece::Field(_) => return None,
            }
        }
        Some(text)
    }

    /// The format with every sequence replaced by what it stands for in `subject`. The counts
    /// are those Spot gives for the automata it prints: `%e` one edge per pair of states, `%t`
    /// one transition per letter.
    pub fn expand(&self, subject: &Subject) -> String {
        let dfa = subject.dfa;
        let mut text = String::new();
        for piece in &self.pieces {
            let _ = match piece {
                Piece::Text(part) => write!(text, "{part}"),
                Piece::Field(Field::States) => write!(text, "{}", dfa.num_states()),
                Piece::Field(Field::Edges) => write!(text, "{}", dfa.num_edges()),
                Piece::Field(Field::Transitions) => {
                    write!(text, "{}", (dfa.num_states() as u128) << dfa.aps().len())
                }
                Piece::Field(Field::AcceptanceSets) => write!(text, "1"),
                Piece::Field(Field::Propositions) => write!(text, "{}", dfa.aps().len()),
                Piece::Field(Field::Name) => write!(text, "{}", subject.name),
                Piece::Field(Field::File) => write!(text, "{}", subject.file),
                Piece::Field(Field::Location) => write!(text, "{}", subject.location),
            };
        }
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hypersynth::automata::testing::eventually;

    #[test]
    fn every_sequence_is_replaced_and_percent_percent_is_a_percent() {
        let known = with_counts(&[
            ('f', Field::Name),
            ('F', Field::File),
            ('L', Field::Location),
        ]);
        let pattern = Pattern::parse("%F:%L [%f] %s %e %t %a %x 100%%", &known).unwrap();
        // `F p`: 0 waits for `p`, 1 is final; 3 edges (0 -!p-> 0, 0 -p-> 1, 1 -t-> 1).
        let dfa = eventually("p");
        let subject = Subject {
            dfa: &dfa,
            name: "F p",
            file: "tasks.ltl",
            location: 7,
        };
        // 2 states x 2^1 letters = 4 transitions.
        assert_eq!(pattern.expand(&subject), "tasks.ltl:7 [F p] 2 3 4 1 1 100%");
        assert_eq!(pattern.as_literal(), None);
        assert_eq!(
            Pattern::parse("out%%.hoa", &known)
                .unwrap()
                .as_literal()
                .as_deref(),
            Some("out%.hoa")
        );
    }

    #[test]
    fn unknown_sequences_and_a_lone_percent_are_refused() {
        assert_eq!(
            Pattern::parse("%s %q", &COUNTS).unwrap_err(),
            "`%q` is not supported (use %s %e %t %a %x or %%)"
        );
        assert_eq!(
            Pattern::parse("phi%", &COUNTS).unwrap_err(),
            "the format ends with a lone `%`"
        );
        assert_eq!(
            Pattern::parse("", &COUNTS).unwrap_err(),
            "empty format string"
        );
    }
}
