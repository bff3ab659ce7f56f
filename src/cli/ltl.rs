//! `hypersynth ltl`: parse formulas, print them in positive normal form and classify them.
//!
//! Every formula gets one line on stdout, in input order: its class and, tab-separated, its
//! positive normal form (or, for `error`, where the error is). Errors and the reason a formula
//! is not co-safe go to stderr as `hypersynth: error: WHERE:LINE:COL: ...` with a caret under
//! the column. The exit status is 1 when any formula is invalid or not co-safe, after all are
//! reported.

use std::io::Write;
use std::process::ExitCode;

use anyhow::Context;
use hypersynth::ltl::{self, Formula};

use super::{FAILURE, print_error};

/// Positive normal forms larger than this are not built: nested `<->` and `xor` double their
/// operands at each level.
const PNF_NODE_LIMIT: u64 = 1_000_000;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Formulas in Spot's LTL syntax.
    #[arg(value_name = "FORMULA", required_unless_present = "files")]
    formulas: Vec<String>,

    /// Read formulas from FILE, one per line (`-` for standard input); blank lines and lines
    /// starting with `#` are skipped. May be repeated; files are read after the arguments.
    #[arg(short = 'f', long = "file", value_name = "FILE")]
    files: Vec<String>,

    /// Output: `tsv` (CLASS<TAB>FORMULA per line) or `json` (one JSON object per line).
    #[arg(long, value_enum, default_value_t = Format::Tsv)]
    format: Format,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum Format {
    Tsv,
    Json,
}

/// One formula to check and where it comes from.
struct Input {
    /// `FILE` or `argument N`: the start of error locations.
    origin: String,
    /// Added to the line of a position in `text` to make the line of `origin`.
    line_offset: usize,
    text: String,
}

impl Input {
    /// `origin:LINE:COL` for a position in `text`.
    fn location(&self, position: hypersynth::position::Position) -> String {
        format!(
            "{}:{}:{}",
            self.origin,
            position.line + self.line_offset,
            position.column
        )
    }

    /// What the JSON output calls the input: `FILE:LINE` or `argument N`.
    fn source(&self) -> String {
        if self.line_offset == 0 && self.origin.starts_with("argument ") {
            self.origin.clone()
        } else {
            format!("{}:{}", self.origin, self.line_offset + 1)
        }
    }
}

/// The verdict on one formula.
enum Verdict {
    CoSafe(Formula),
    /// The normal form, and the explanation (already located).
    NotCoSafe(Formula, Problem),
    Invalid(Problem),
}

/// An error located in the input: `WHERE:LINE:COL`, the message and the caret context.
struct Problem {
    location: String,
    line: usize,
    column: usize,
    message: String,
    context: String,
}

impl Problem {
    fn new(input: &Input, offset: usize, message: String) -> Problem {
        let position = hypersynth::position::Position::of_offset(&input.text, offset);
        let line_text = input
            .text
            .lines()
            .nth(position.line - 1)
            .unwrap_or_default();
        Problem {
            location: input.location(position),
            line: position.line + input.line_offset,
            column: position.column,
            message,
            context: ltl::caret_context(line_text, position.column),
        }
    }
}

fn check(input: &Input) -> Verdict {
    let formula = match ltl::parse(&input.text) {
        Ok(formula) => formula,
        Err(error) => {
            return Verdict::Invalid(Problem {
                location: input.location(error.position),
                line: error.position.line + input.line_offset,
                column: error.position.column,
                context: error.context(),
                message: error.message,
            });
        }
    };
    let size = ltl::positive_normal_form_size_bound(&formula);
    if size > PNF_NODE_LIMIT {
        let message = format!(
            "the positive normal form would have up to {size} nodes (more than \
             {PNF_NODE_LIMIT}): nested `<->` and `xor` double their operands"
        );
        return Verdict::Invalid(Problem::new(input, formula.span.start, message));
    }
    let pnf = ltl::positive_normal_form(&formula);
    match ltl::check_co_safe(&formula) {
        Ok(()) => Verdict::CoSafe(pnf),
        Err(error) => Verdict::NotCoSafe(
            pnf,
            Problem::new(input, error.span.start, error.to_string()),
        ),
    }
}

fn read_inputs(args: &Args) -> anyhow::Result<Vec<Input>> {
    let mut inputs: Vec<Input> = args
        .formulas
        .iter()
        .enumerate()
        .map(|(index, text)| Input {
            origin: format!("argument {}", index + 1),
            line_offset: 0,
            text: text.clone(),
        })
        .collect();
    for path in &args.files {
        let text =
            hypersynth::io::read_input(path).with_context(|| format!("{path}: cannot read"))?;
        let origin = if path == "-" { "<stdin>" } else { path };
        for (index, line) in text.lines().enumerate() {
            let content = line.trim_start();
            if content.is_empty() || content.starts_with('#') {
                continue;
            }
            inputs.push(Input {
                origin: origin.to_string(),
                line_offset: index,
                text: line.to_string(),
            });
        }
    }
    Ok(inputs)
}

fn json_line(input: &Input, verdict: &Verdict) -> serde_json::Value {
    let problem_json = |problem: &Problem| {
        serde_json::json!({
            "line": problem.line,
            "column": problem.column,
            "message": problem.message,
        })
    };
    let mut object = serde_json::json!({
        "source": input.source(),
        "input": input.text,
    });
    let fields = match verdict {
        Verdict::CoSafe(pnf) => serde_json::json!({
            "class": "co-safe",
            "formula": pnf.to_string(),
            "atomic_propositions": ltl::atomic_propositions(pnf),
        }),
        Verdict::NotCoSafe(pnf, problem) => serde_json::json!({
            "class": "not-co-safe",
            "formula": pnf.to_string(),
            "atomic_propositions": ltl::atomic_propositions(pnf),
            "error": problem_json(problem),
        }),
        Verdict::Invalid(problem) => serde_json::json!({
            "class": "error",
            "error": problem_json(problem),
        }),
    };
    if let (Some(object), serde_json::Value::Object(fields)) = (object.as_object_mut(), fields) {
        object.extend(fields);
    }
    object
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let inputs = read_inputs(&args)?;
    let mut out = std::io::stdout().lock();
    let mut all_co_safe = true;
    for input in &inputs {
        let verdict = check(input);
        if let Verdict::NotCoSafe(_, problem) | Verdict::Invalid(problem) = &verdict {
            all_co_safe = false;
            print_error(format_args!(
                "{}: {}\n{}",
                problem.location, problem.message, problem.context
            ));
        }
        match args.format {
            Format::Tsv => match &verdict {
                Verdict::CoSafe(pnf) => writeln!(out, "co-safe\t{pnf}"),
                Verdict::NotCoSafe(pnf, _) => writeln!(out, "not-co-safe\t{pnf}"),
                Verdict::Invalid(problem) => writeln!(out, "error\t{}", problem.location),
            },
            Format::Json => writeln!(out, "{}", json_line(input, &verdict)),
        }
        .context("cannot write to standard output")?;
    }
    Ok(if all_co_safe {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(FAILURE)
    })
}
