//! The main form's tasks, in the paper's form or the general one, mapped onto the library's
//! [`TasksSpec`], and the spec's errors in them told in the options' terms.
//!
//! The paper's form: `--phi PHI --psi PSI [--phi2 PHI2]` (phi split into `phi1 = psi` and
//! `phi2`), or the tasks' automata `--phi1-hoa FILE`, `--phi2-hoa FILE` (or one file and one
//! formula), with the payoffs `--r1`, `--r2`, `--r`.
//!
//! The general form (docs/semantics.md §8, "beyond the paper"): named sub-tasks
//! (`--task NAME=FORMULA`, `--task-hoa NAME=FILE`), payoffs on sets of them
//! (`--payoff NAMES=VALUE`), the adversary's belief (`--believed FORMULA`, `--believed-hoa FILE`)
//! and the risk rule (`--risk`). Any `--task`/`--task-hoa` selects this form; the paper's
//! options then conflict. The sub-tasks are numbered `--task` first, then `--task-hoa`, each in
//! command-line order; that order breaks ties between sets of equal payoff. Tasks that are the
//! paper's preset (two sub-tasks, one of them believed, `--risk paper`, payoffs with
//! `r >= r1 + r2`) are reported in the paper's form: the library recognises them.
//!
//! HOA files are read here (`-` for standard input, named `<stdin>`); every rule on the tasks is
//! the library's ([`hypersynth::pipeline::spec`]). Errors in an option's text are located as
//! `--phi:LINE:COL` (or `--psi`, `--phi2`, `--task`, `--payoff`, `--believed`; a sub-task's
//! formula as `NAME: --task`), errors in a HOA file as `FILE:LINE:COL`, each with the line and
//! a caret under the column, relative to the option's value.

use anyhow::{Context as _, anyhow};
use hypersynth::diagnostic::Source;
use hypersynth::pipeline::spec::{
    self, Field, GeneralSpec, NamedTask, PaperPayoffs, PayoffPart, SetPayoff, SpecError,
    SpecErrorKind, TaskSource, TasksSpec,
};
use hypersynth::position::Position;

use super::choices::RiskArg;
use super::output::{located, located_at};

/// The tasks' options: the paper's, and the general form's.
#[derive(clap::Args, Debug)]
#[group(id = "task-options")]
pub struct Args {
    /// The robot's task, a co-safe LTL formula `phi1 & phi2`.
    #[arg(help_heading = "Tasks (the paper's form)", long, value_name = "PHI")]
    pub phi: Option<String>,
    /// The task the adversary believes the robot has (`phi1`): one or several conjuncts of PHI.
    #[arg(help_heading = "Tasks (the paper's form)", long, value_name = "PSI")]
    pub psi: Option<String>,
    /// The rest of PHI (`phi2`) [default: the conjuncts of PHI not in PSI]; PSI and PHI2
    /// together must give exactly PHI's conjuncts.
    #[arg(help_heading = "Tasks (the paper's form)", long, value_name = "PHI2")]
    pub phi2: Option<String>,
    /// Read phi1 (what the adversary believes the task is) from FILE, a DFA of good prefixes
    /// in HOA (`-` for standard input), instead of giving --psi; phi is phi1 & phi2.
    #[arg(help_heading = "Tasks (the paper's form)", long, value_name = "FILE", conflicts_with_all = ["psi", "phi"])]
    pub phi1_hoa: Option<String>,
    /// Read phi2 from FILE, a DFA of good prefixes in HOA (`-` for standard input), instead of
    /// giving --phi2; phi is phi1 & phi2.
    #[arg(help_heading = "Tasks (the paper's form)", long, value_name = "FILE", conflicts_with_all = ["phi2", "phi"])]
    pub phi2_hoa: Option<String>,
    /// Beyond the paper: named sub-tasks, payoffs on sets of them, any believed task.
    #[command(
        flatten,
        next_help_heading = "Tasks beyond the paper (k named sub-tasks)"
    )]
    pub general: GeneralArgs,
}

/// Options of the general form.
#[derive(clap::Args, Debug, Default)]
#[group(id = "general")]
pub struct GeneralArgs {
    /// A named sub-task of the robot (repeatable, at most 8 in all): `NAME=FORMULA`, a co-safe
    /// LTL formula. Selects the general form (instead of --phi/--psi).
    #[arg(
        long = "task",
        value_name = "NAME=FORMULA",
        conflicts_with_all = ["phi", "psi", "phi2", "phi1_hoa", "phi2_hoa", "r1", "r2", "r"]
    )]
    pub tasks: Vec<String>,
    /// A named sub-task read from a HOA file (`NAME=FILE`, `-` for standard input).
    #[arg(
        long = "task-hoa",
        value_name = "NAME=FILE",
        conflicts_with_all = ["phi", "psi", "phi2", "phi1_hoa", "phi2_hoa", "r1", "r2", "r"]
    )]
    pub task_hoa: Vec<String>,
    /// The payoff of a set of sub-tasks (repeatable): `A=200` for one, `A,B=350` for a set.
    /// Sets default to the sum of their members' payoffs; sub-tasks to 100. Payoffs must be
    /// monotone (a set pays at least what any subset pays).
    #[arg(long = "payoff", value_name = "NAMES=VALUE", conflicts_with_all = ["r1", "r2", "r"])]
    pub payoffs: Vec<String>,
    /// The task the adversary believes the robot has (psi), any co-safe formula. When it is
    /// the conjunction of some sub-tasks, Win(psi) is theirs; otherwise psi's automaton joins
    /// the product.
    #[arg(long, value_name = "FORMULA")]
    pub believed: Option<String>,
    /// psi from a HOA file (`-` for standard input) instead of --believed.
    #[arg(long, value_name = "FILE", conflicts_with = "believed")]
    pub believed_hoa: Option<String>,
    /// Which arena actions a robot state that can settle for something keeps: `paper` (none
    /// that may lead to a robot state of guarantee 0), `strict` (none that may lead to a lower
    /// guarantee) or `neutral` (all).
    #[arg(long, value_enum, default_value_t = RiskArg::Paper)]
    pub risk: RiskArg,
}

impl Args {
    /// Whether the general form is selected.
    fn is_general(&self) -> bool {
        !self.general.tasks.is_empty() || !self.general.task_hoa.is_empty()
    }

    /// What clap cannot say about the tasks' options: which task is missing, too many
    /// sub-tasks, and inputs that would read standard input twice (`arena` is the main form's
    /// ARENA). The message of a usage error (exit status 2).
    pub fn check_usage(&self, arena: Option<&str>) -> Result<(), String> {
        if self.is_general() {
            return self.general.check_usage(arena);
        }
        if let Some(option) = self.general.stray_option() {
            return Err(format!(
                "{option} belongs to the general form: give the sub-tasks with --task NAME=FORMULA \
                 or --task-hoa NAME=FILE"
            ));
        }
        let from_files = self.phi1_hoa.is_some() || self.phi2_hoa.is_some();
        if !from_files && self.phi.is_none() {
            return Err(
                "the robot's task is missing: give --phi PHI (with --psi PSI), the tasks' \
                 automata with --phi1-hoa FILE and --phi2-hoa FILE, or sub-tasks with --task \
                 NAME=FORMULA (and --believed FORMULA)"
                    .to_string(),
            );
        }
        if self.psi.is_none() && self.phi1_hoa.is_none() {
            return Err(
                "--psi PSI is missing: the task the adversary believes the robot has \
                 (phi1), one or several conjuncts of PHI (or give --phi1-hoa FILE)"
                    .to_string(),
            );
        }
        if from_files && self.phi2.is_none() && self.phi2_hoa.is_none() {
            return Err(
                "phi2 is missing: with --phi1-hoa or --phi2-hoa, give the other task \
                 as --phi2 PHI2 or --phi2-hoa FILE (--psi for phi1)"
                    .to_string(),
            );
        }
        let stdin_readers = [&self.phi1_hoa, &self.phi2_hoa]
            .into_iter()
            .map(Option::as_deref)
            .chain([arena])
            .filter(|&input| input == Some("-"))
            .count();
        if stdin_readers > 1 {
            return Err(
                "only one of ARENA, --phi1-hoa and --phi2-hoa can be `-` (standard \
                 input)"
                    .to_string(),
            );
        }
        Ok(())
    }

    /// The tasks as the library's specification, with the paper's `payoffs` (`--r1`, `--r2`,
    /// `--r`); HOA files are read here.
    pub fn spec(&self, payoffs: PaperPayoffs) -> anyhow::Result<TasksSpec> {
        if self.is_general() {
            return self.general.spec().map(TasksSpec::General);
        }
        let formula = |text: &Option<String>| text.clone().map(TaskSource::Formula);
        if self.phi1_hoa.is_none() && self.phi2_hoa.is_none() {
            let (Some(phi), Some(psi)) = (&self.phi, &self.psi) else {
                anyhow::bail!("the main form needs --phi PHI and --psi PSI");
            };
            return Ok(TasksSpec::Paper {
                phi: phi.clone(),
                psi: psi.clone(),
                phi2: self.phi2.clone(),
                payoffs,
            });
        }
        let phi1 = match &self.phi1_hoa {
            Some(file) => read_hoa(file)?,
            None => formula(&self.psi).context("--psi is missing")?,
        };
        let phi2 = match &self.phi2_hoa {
            Some(file) => read_hoa(file)?,
            None => formula(&self.phi2).context("--phi2 is missing")?,
        };
        Ok(TasksSpec::PaperParts {
            phi1,
            phi2,
            payoffs,
        })
    }

    /// An error of the tasks of `spec` (the one [`Args::spec`] made) in the options' terms.
    pub fn error(&self, spec: &TasksSpec, error: SpecError) -> anyhow::Error {
        let (field, position, kind) = error.into_parts();
        match (field, spec) {
            (Field::Phi, TasksSpec::Paper { phi, .. }) => {
                in_text(&Source::new("--phi", phi), position, kind)
            }
            (Field::Psi, TasksSpec::Paper { psi, .. }) => {
                in_text(&Source::new("--psi", psi), position, kind)
            }
            (
                Field::Phi2,
                TasksSpec::Paper {
                    phi2: Some(phi2), ..
                },
            ) => in_text(&Source::new("--phi2", phi2), position, kind),
            (Field::Psi, TasksSpec::PaperParts { phi1, .. }) => {
                in_task("--psi", phi1, position, kind)
            }
            (Field::Phi2, TasksSpec::PaperParts { phi2, .. }) => {
                in_task("--phi2", phi2, position, kind)
            }
            (Field::Task { index, name }, TasksSpec::General(general)) => self
                .general
                .task_error(general, index, &name, position, kind),
            (Field::Payoff { index, part }, _) => self.general.payoff_error(index, part, kind),
            (Field::Payoffs, _) => anyhow!("--payoff: {kind}"),
            (Field::Believed, TasksSpec::General(general)) => {
                in_task("--believed", &general.believed, position, kind)
            }
            _ => plain(kind),
        }
    }
}

impl GeneralArgs {
    /// A general option given without any sub-task.
    fn stray_option(&self) -> Option<&'static str> {
        if !self.payoffs.is_empty() {
            Some("--payoff")
        } else if self.believed.is_some() {
            Some("--believed")
        } else if self.believed_hoa.is_some() {
            Some("--believed-hoa")
        } else {
            None
        }
    }

    /// The usage rules clap cannot state for the general form.
    fn check_usage(&self, arena: Option<&str>) -> Result<(), String> {
        if self.believed.is_none() && self.believed_hoa.is_none() {
            return Err(
                "the adversary's belief is missing: give --believed FORMULA or --believed-hoa \
                 FILE"
                    .to_string(),
            );
        }
        spec::check_count(self.tasks.len() + self.task_hoa.len())
            .map_err(|error| error.kind.to_string())?;
        let hoa_files = self
            .task_hoa
            .iter()
            .map(|value| value.split_once('=').map_or("", |(_, file)| file));
        let stdin_readers = hoa_files
            .chain(self.believed_hoa.as_deref())
            .chain(arena)
            .filter(|&input| input == "-")
            .count();
        if stdin_readers > 1 {
            return Err(
                "only one of ARENA, --task-hoa and --believed-hoa can be `-` (standard input)"
                    .to_string(),
            );
        }
        Ok(())
    }

    /// The general form's specification: `--task` sub-tasks first, then `--task-hoa` ones,
    /// each in command-line order.
    fn spec(&self) -> anyhow::Result<GeneralSpec> {
        let mut tasks = Vec::new();
        for value in &self.tasks {
            let (name, formula) = named("--task", value)?;
            tasks.push(NamedTask {
                name: name.to_string(),
                task: TaskSource::Formula(formula.to_string()),
            });
        }
        for value in &self.task_hoa {
            let (name, file) = named("--task-hoa", value)?;
            tasks.push(NamedTask {
                name: name.to_string(),
                task: read_hoa(file)?,
            });
        }
        let payoffs = self
            .payoffs
            .iter()
            .map(|value| payoff(value))
            .collect::<anyhow::Result<_>>()?;
        let believed = match (&self.believed, &self.believed_hoa) {
            (Some(text), _) => TaskSource::Formula(text.clone()),
            (None, Some(file)) => read_hoa(file)?,
            (None, None) => anyhow::bail!("the adversary's belief is missing"),
        };
        Ok(GeneralSpec {
            tasks,
            payoffs,
            believed,
            risk: self.risk.into(),
        })
    }

    /// The error of sub-task `index` (named `name`): its name at the start of its option's
    /// value, its formula in `NAME: --task`, its automaton in its file.
    fn task_error(
        &self,
        spec: &GeneralSpec,
        index: usize,
        name: &str,
        position: Option<Position>,
        kind: SpecErrorKind,
    ) -> anyhow::Error {
        let (option, value) = match self.tasks.get(index) {
            Some(value) => ("--task", value),
            None => ("--task-hoa", &self.task_hoa[index - self.tasks.len()]),
        };
        match kind {
            SpecErrorKind::TaskName(_) => located_at(
                &Source::new(option, value),
                Position::of_offset(value, 0),
                kind,
            ),
            SpecErrorKind::DuplicateTask(_) => anyhow!("{kind}"),
            // Errors in the formula are prefixed with the sub-task's name.
            kind => in_task(
                &format!("{name}: {option}"),
                &spec.tasks[index].task,
                position,
                kind,
            ),
        }
    }

    /// The error of `--payoff` number `index`, located in its value.
    fn payoff_error(&self, index: usize, part: PayoffPart, kind: SpecErrorKind) -> anyhow::Error {
        let value = &self.payoffs[index];
        let (names, number) = value.split_once('=').unwrap_or((value, ""));
        let offset = match part {
            PayoffPart::Member(member) => names.split(',').take(member).map(|n| n.len() + 1).sum(),
            PayoffPart::Set => 0,
            PayoffPart::Value => names.len() + 1,
        };
        let message = match &kind {
            SpecErrorKind::UnknownTask(_) => format!("{kind} (give it with --task)"),
            SpecErrorKind::InvalidPayoff(_) => {
                format!("invalid payoff `{number}` (a finite number >= 0)")
            }
            _ => kind.to_string(),
        };
        located_at(
            &Source::new("--payoff", value),
            Position::of_offset(value, offset),
            message,
        )
    }
}

/// `NAME=REST` split at the first `=` (the name is the library's to check); an error located in
/// the option's value without one.
fn named<'a>(option: &str, value: &'a str) -> anyhow::Result<(&'a str, &'a str)> {
    value.split_once('=').ok_or_else(|| {
        located_at(
            &Source::new(option, value),
            Position::of_offset(value, value.len()),
            "expected NAME=VALUE",
        )
    })
}

/// `--payoff NAMES=VALUE`: the names split at `,`; a value that is not a number is given as
/// NaN, which the library refuses as it refuses any payoff that is not a finite number >= 0
/// (in its place among the option's errors), and which [`GeneralArgs::payoff_error`] shows as
/// written.
fn payoff(value: &str) -> anyhow::Result<SetPayoff> {
    let Some((names, number)) = value.split_once('=') else {
        return Err(located_at(
            &Source::new("--payoff", value),
            Position::of_offset(value, value.len()),
            "expected NAMES=VALUE, e.g. A,B=350",
        ));
    };
    Ok(SetPayoff {
        set: names.split(',').map(str::to_string).collect(),
        value: number.trim().parse().unwrap_or(f64::NAN),
    })
}

/// The one automaton of a HOA file (`-` for standard input), named after the file in reports
/// and messages (`<stdin>` for `-`).
fn read_hoa(file: &str) -> anyhow::Result<TaskSource> {
    let shown = if file == "-" { "<stdin>" } else { file };
    let text = super::io::read_input(file).with_context(|| format!("{shown}: cannot read"))?;
    Ok(TaskSource::Hoa {
        name: shown.to_string(),
        text,
    })
}

/// An error in `task`, a formula of the option `option` or an automaton of a file.
fn in_task(
    option: &str,
    task: &TaskSource,
    position: Option<Position>,
    kind: SpecErrorKind,
) -> anyhow::Error {
    match task {
        TaskSource::Formula(text) => in_text(&Source::new(option, text), position, kind),
        TaskSource::Hoa { name, text } => in_text(&Source::new(name, text), position, kind),
        TaskSource::Automaton(_) => plain(kind),
    }
}

/// An error in the text of `source`: located with a caret where it has a place, else after the
/// source's name.
fn in_text(source: &Source, position: Option<Position>, kind: SpecErrorKind) -> anyhow::Error {
    match kind {
        SpecErrorKind::Formula(errors)
        | SpecErrorKind::Hoa(errors)
        | SpecErrorKind::NotCoSafe(errors) => located(source, &errors),
        SpecErrorKind::Translate(error) => {
            let error = super::translate::noted(error);
            match position {
                Some(position) => located_at(source, position, error),
                None => anyhow!("{}: {error}", source.name),
            }
        }
        SpecErrorKind::Split(error) => match position {
            Some(position) => located_at(source, position, error),
            None => anyhow!("{}: {error}", source.name),
        },
        SpecErrorKind::AutomatonCount(_) => anyhow!("{}: {kind}", source.name),
        kind => plain(kind),
    }
}

/// An error with no place in a text, as the command line has always shown it: the library's
/// error itself (with its causes, if any).
fn plain(kind: SpecErrorKind) -> anyhow::Error {
    match kind {
        SpecErrorKind::Translator(error) => error.into(),
        SpecErrorKind::PaperPayoffs(error) => error.into(),
        other => other.into(),
    }
}
