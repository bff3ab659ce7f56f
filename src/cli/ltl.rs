//! `hypersynth ltl`: parse formulas, print them in positive normal form and classify them.
//!
//! Every formula gets one line on stdout, in input order: its class and, tab-separated, its
//! positive normal form (or, for `error`, where the first error is). Errors (all of a formula's,
//! up to the parser's limit) and the reason a formula is not co-safe go to stderr as
//! `hypersynth: error: WHERE:LINE:COL: ...` with a caret under the column. The exit status is 1
//! when any formula is invalid or not co-safe, after all are reported.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use hypersynth::diagnostic::{Diagnostic, Diagnostics};
use hypersynth::ltl::{self, Formula};

use super::batch::{self, FormulaArgs, Input};
use super::output::{FAILURE, print_error};

/// Positive normal forms larger than this (and than twice the formula) are not built: nested
/// `<->` and `xor` double their operands at each level.
const PNF_NODE_LIMIT: u64 = 1_000_000;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    inputs: FormulaArgs,

    /// Output: `tsv` (CLASS<TAB>FORMULA per line) or `json` (one JSON object per line).
    #[arg(long, value_enum, default_value_t = Format::Tsv)]
    format: Format,

    /// Write the lines to FILE (atomically, once every formula is checked) instead of standard
    /// output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum Format {
    Tsv,
    Json,
}

/// The verdict on one formula.
enum Verdict {
    CoSafe(Formula),
    /// The normal form, and why it is not co-safe.
    NotCoSafe(Formula, Diagnostics),
    /// The errors of the formula.
    Invalid(Diagnostics),
}

/// One problem at byte `offset` of the input's text.
fn problem(input: &Input, offset: usize, message: String) -> Diagnostics {
    let position = hypersynth::position::Position::of_offset(&input.text, offset);
    Diagnostics::from(Diagnostic::new(position, message))
}

fn check(input: &Input) -> Verdict {
    let formula = match ltl::parse(&input.text) {
        Ok(formula) => formula,
        Err(errors) => return Verdict::Invalid(errors),
    };
    // Without `<->` and `xor`, the normal form has at most twice the nodes of the formula;
    // with them, the error points at the (deepest) operator whose normal form passes the limit.
    if let Some((span, size)) = ltl::positive_normal_form_blowup(&formula, PNF_NODE_LIMIT) {
        let message = format!(
            "the positive normal form of this subformula would have up to {size} nodes (more \
             than {PNF_NODE_LIMIT}): nested `<->` and `xor` double their operands"
        );
        return Verdict::Invalid(problem(input, span.start, message));
    }
    let pnf = ltl::positive_normal_form(&formula);
    match ltl::check_co_safe(&formula) {
        Ok(()) => Verdict::CoSafe(pnf),
        Err(error) => Verdict::NotCoSafe(pnf, problem(input, error.span.start, error.to_string())),
    }
}

fn json_line(input: &Input, verdict: &Verdict) -> serde_json::Value {
    // The first error (later ones are on stderr).
    let problem_json = |problems: &Diagnostics| {
        let first = problems.first();
        serde_json::json!({
            "line": first.position.line + input.line_offset,
            "column": first.position.column,
            "message": first.message,
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

pub fn run(args: Args, matches: &clap::ArgMatches) -> anyhow::Result<ExitCode> {
    let inputs = batch::read(&args.inputs, matches)?;
    let mut stdout = std::io::stdout().lock();
    // With -o, the lines gather here; without, each goes out as its formula is checked.
    let mut gathered = String::new();
    let mut all_co_safe = true;
    for input in &inputs {
        let verdict = check(input);
        if let Verdict::NotCoSafe(_, problems) | Verdict::Invalid(problems) = &verdict {
            all_co_safe = false;
            for message in input.located().render(problems) {
                print_error(message);
            }
        }
        let line = match args.format {
            Format::Tsv => match &verdict {
                Verdict::CoSafe(pnf) => format!("co-safe\t{pnf}\n"),
                Verdict::NotCoSafe(pnf, _) => format!("not-co-safe\t{pnf}\n"),
                Verdict::Invalid(problems) => {
                    let first = problems.first().position;
                    format!("error\t{}\n", input.located().location(first))
                }
            },
            Format::Json => format!("{}\n", json_line(input, &verdict)),
        };
        match args.output {
            Some(_) => gathered.push_str(&line),
            None => stdout
                .write_all(line.as_bytes())
                .context("cannot write to standard output")?,
        }
    }
    if let Some(path) = &args.output {
        super::output::write_output(Some(path.as_path()), &gathered)?;
    }
    Ok(if all_co_safe {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(FAILURE)
    })
}
