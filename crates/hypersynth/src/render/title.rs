//! Pictures' titles: the default lines a picture describes itself with, replaced or left out on
//! request, and formulas set with logical symbols instead of their ASCII spelling.

/// Which title a picture shows.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum TitleChoice {
    /// The picture's own description (what it shows, the tasks, the settings).
    #[default]
    Default,
    /// This text instead, one line per line of it.
    Text(String),
    /// No title (for a figure whose caption is elsewhere).
    None,
}

/// A picture's title: the lines shown above it, and its description (the SVG's `<title>`, the
/// accessible name), which is the default title even when another or none is shown.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Title {
    /// The lines shown, the first one larger.
    pub lines: Vec<String>,
    /// The description.
    pub description: String,
}

impl Title {
    /// The title `choice` asks for, given the picture's default lines.
    pub fn new(default: Vec<String>, choice: &TitleChoice) -> Title {
        let description = default.join(". ");
        let lines = match choice {
            TitleChoice::Default => default,
            TitleChoice::Text(text) => text.lines().map(str::to_string).collect(),
            TitleChoice::None => Vec::new(),
        };
        Title { lines, description }
    }
}

/// `formula`, as hypersynth prints formulas, with the connectives as logical symbols: `!` ¬,
/// `&` ∧, `|` ∨, `->` →, `<->` ↔ (their doubled and slashed spellings too). Names are left
/// alone, so a file name stays readable.
pub fn typeset(formula: &str) -> String {
    const SYMBOLS: [(&str, &str); 12] = [
        ("<->", "↔"),
        ("<=>", "↔"),
        ("-->", "→"),
        ("->", "→"),
        ("=>", "→"),
        ("&&", "∧"),
        ("/\\", "∧"),
        ("||", "∨"),
        ("\\/", "∨"),
        ("&", "∧"),
        ("|", "∨"),
        ("!", "¬"),
    ];
    let mut out = String::with_capacity(formula.len());
    let mut rest = formula;
    'scan: while let Some(c) = rest.chars().next() {
        for (ascii, symbol) in SYMBOLS {
            if let Some(after) = rest.strip_prefix(ascii) {
                out.push_str(symbol);
                rest = after;
                continue 'scan;
            }
        }
        if c == '~' {
            out.push('¬');
        } else {
            out.push(c);
        }
        rest = &rest[c.len_utf8()..];
    }
    out
}

/// `text` with the paper's names set as symbols, word by word: `phi` φ, `phi1` φ₁, `phi2` φ₂,
/// `psi` ψ, `sigma_L` σ_L, `q1` q₁, `q2` q₂.
pub fn symbols(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut word = String::new();
    let flush = |word: &mut String, out: &mut String| {
        out.push_str(match word.as_str() {
            "phi" => "φ",
            "phi1" => "φ₁",
            "phi2" => "φ₂",
            "psi" => "ψ",
            "sigma_L" => "σ_L",
            "q1" => "q₁",
            "q2" => "q₂",
            other => other,
        });
        word.clear();
    };
    for c in text.chars() {
        if c.is_alphanumeric() || c == '_' {
            word.push(c);
        } else {
            flush(&mut word, &mut out);
            out.push(c);
        }
    }
    flush(&mut word, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn connectives_become_symbols_and_names_stay() {
        assert_eq!(typeset("!O U A & !O U B"), "¬O U A ∧ ¬O U B");
        assert_eq!(typeset("a -> b <-> c | d"), "a → b ↔ c ∨ d");
        assert_eq!(typeset("a && b || ~c"), "a ∧ b ∨ ¬c");
        assert_eq!(
            typeset("phi1.hoa & tasks/b-c.hoa"),
            "phi1.hoa ∧ tasks/b-c.hoa"
        );
        assert_eq!(
            symbols("phi = phi1 & phi2, psi; sigma_L uniform"),
            "φ = φ₁ & φ₂, ψ; σ_L uniform"
        );
        assert_eq!(symbols("phi1x q1"), "phi1x q₁");
    }

    #[test]
    fn a_title_can_be_replaced_or_left_out_and_keeps_its_description() {
        let default = vec!["What".to_string(), "tasks".to_string()];
        let shown = Title::new(default.clone(), &TitleChoice::Default);
        assert_eq!(shown.lines, default);
        assert_eq!(shown.description, "What. tasks");
        let custom = Title::new(default.clone(), &TitleChoice::Text("Fig. 3\nsecond".into()));
        assert_eq!(custom.lines, ["Fig. 3", "second"]);
        assert_eq!(custom.description, "What. tasks");
        assert!(Title::new(default, &TitleChoice::None).lines.is_empty());
    }
}
