//! Formula inputs as Spot's tools take them: `-f FORMULA` (repeatable), `-F FILE` (one formula
//! per line, `-` for standard input; repeatable) and bare FORMULA arguments, processed in
//! command-line order. Used by `ltl` and `translate`.

use anyhow::Context as _;
use clap::ArgMatches;
use hypersynth::diagnostic::Source;
use hypersynth::position::Position;

#[derive(clap::Args, Debug)]
#[group(id = "inputs", required = true, multiple = true)]
pub struct FormulaArgs {
    /// Formulas in Spot's LTL syntax (as with -f).
    #[arg(value_name = "FORMULA")]
    arguments: Vec<String>,

    /// Process FORMULA (repeatable).
    #[arg(short = 'f', long = "formula", value_name = "FORMULA")]
    formulas: Vec<String>,

    /// Process each line of FILE as a formula (`-` for standard input; repeatable). Empty lines
    /// and lines whose first non-blank character is `#` are skipped.
    #[arg(short = 'F', long = "file", value_name = "FILE")]
    files: Vec<String>,
}

/// One formula to process and where it comes from.
pub struct Input {
    /// `FILE` or `argument N`: the start of error locations.
    pub origin: String,
    /// Added to the line of a position in `text` to make the line of `origin`.
    pub line_offset: usize,
    pub text: String,
    /// The file as given on the command line (`-` for standard input); `None` for a formula
    /// given directly.
    pub file: Option<String>,
    /// The formula's line in its file (from 1), or N for `argument N`.
    pub location: usize,
}

impl Input {
    /// `text` as errors locate it: `origin:LINE:COL`, lines counted in `origin`.
    pub fn located(&self) -> Source<'_> {
        Source::new(&self.origin, &self.text).with_line_offset(self.line_offset)
    }

    /// `origin:LINE:COL: MESSAGE` and a caret under the column, for a position in `text`.
    pub fn error_at(&self, position: Position, message: &dyn std::fmt::Display) -> anyhow::Error {
        super::output::located_at(&self.located(), position, message)
    }

    /// What JSON output calls the input: `FILE:LINE` or `argument N`.
    pub fn source(&self) -> String {
        if self.line_offset == 0 && self.origin.starts_with("argument ") {
            self.origin.clone()
        } else {
            format!("{}:{}", self.origin, self.line_offset + 1)
        }
    }
}

/// Every formula of the command line, in the order its arguments and options were given.
/// Formulas given directly are numbered `argument 1`, `argument 2`, ... in that order.
pub fn read(args: &FormulaArgs, matches: &ArgMatches) -> anyhow::Result<Vec<Input>> {
    enum Item<'a> {
        Formula(&'a str),
        File(&'a str),
    }
    let positions = |id: &str| -> Vec<usize> {
        matches
            .indices_of(id)
            .map(Iterator::collect)
            .unwrap_or_default()
    };
    let mut items: Vec<(usize, Item)> = Vec::new();
    for (id, values, is_file) in [
        ("arguments", &args.arguments, false),
        ("formulas", &args.formulas, false),
        ("files", &args.files, true),
    ] {
        // Without matches (a caller building Args by hand), keep the fields' order.
        let indices = positions(id);
        for (i, value) in values.iter().enumerate() {
            let index = indices.get(i).copied().unwrap_or(usize::MAX);
            let item = if is_file {
                Item::File(value)
            } else {
                Item::Formula(value)
            };
            items.push((index, item));
        }
    }
    items.sort_by_key(|(index, _)| *index);

    let mut inputs = Vec::new();
    let mut argument_number = 0;
    for (_, item) in items {
        match item {
            Item::Formula(text) => {
                argument_number += 1;
                inputs.push(Input {
                    origin: format!("argument {argument_number}"),
                    line_offset: 0,
                    text: text.to_string(),
                    file: None,
                    location: argument_number,
                });
            }
            Item::File(path) => {
                let shown = if path == "-" { "<stdin>" } else { path };
                let text =
                    super::io::read_input(path).with_context(|| format!("{shown}: cannot read"))?;
                for (index, line) in text.lines().enumerate() {
                    let content = line.trim_start();
                    if content.is_empty() || content.starts_with('#') {
                        continue;
                    }
                    inputs.push(Input {
                        origin: shown.to_string(),
                        line_offset: index,
                        text: line.to_string(),
                        file: Some(path.to_string()),
                        location: index + 1,
                    });
                }
            }
        }
    }
    Ok(inputs)
}
