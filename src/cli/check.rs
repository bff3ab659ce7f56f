//! `hypersynth check CONTROLLER`: checks the certificate an exported controller carries
//! (`--export-controller FILE --certificate`, docs/semantics.md §9.4) from the file alone, and
//! prints the bounds it certifies, or the first state and inequality that fail (exit status
//! 1). A file that does not read is an error as `hypersynth execute` reports it.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use hypersynth::certificate::{CheckError, check_json};

/// Options of `hypersynth check`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The exported controller, written by `--export-controller FILE --certificate`.
    #[arg(value_name = "CONTROLLER")]
    pub controller: PathBuf,
    /// How to print the verdict.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
}

/// How `hypersynth check` prints its verdict.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// One line.
    Text,
    /// One JSON object: `certified`, and the bounds or the failure.
    Json,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let shown = args.controller.display().to_string();
    let text = super::io::read_input(&shown).with_context(|| format!("{shown}: cannot read"))?;
    let verdict = check_json(&text);
    let refusal = match &verdict {
        Err(CheckError::Unreadable(error)) => {
            return Err(super::execute::file_error(&shown, &text, error));
        }
        Err(CheckError::Refused(refusal)) => Some(refusal),
        Err(error) => return Err(anyhow::anyhow!("{shown}: {error}")),
        Ok(_) => None,
    };
    let line = match (&verdict, args.format) {
        (Ok(bounds), Format::Text) => format!(
            "certified: the controller collects at least {} from h0; no controller collects \
             more than {}",
            bounds.lower, bounds.upper
        ),
        (Ok(bounds), Format::Json) => serde_json::json!({
            "certified": true,
            "lower": bounds.lower,
            "upper": bounds.upper,
            "lower_states": bounds.lower_states,
            "upper_states": bounds.upper_states,
        })
        .to_string(),
        (Err(_), Format::Text) => {
            let refusal = refusal.expect("a refusal");
            return Err(anyhow::anyhow!("{shown}: {refusal}"));
        }
        (Err(_), Format::Json) => {
            let refusal = refusal.expect("a refusal");
            serde_json::json!({
                "certified": false,
                "certificate": refusal.bound.to_string(),
                "state": refusal.state,
                "inequality": refusal.inequality,
            })
            .to_string()
        }
    };
    println!("{line}");
    Ok(match refusal {
        Some(_) => ExitCode::from(super::output::FAILURE),
        None => ExitCode::SUCCESS,
    })
}
