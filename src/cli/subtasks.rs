//! The main form's general options (docs/semantics.md §8, "beyond the paper"): named sub-tasks
//! (`--task NAME=FORMULA`, `--task-hoa NAME=FILE`), payoffs on sets of them
//! (`--payoff NAMES=VALUE`), the adversary's belief (`--believed FORMULA`, `--believed-hoa FILE`)
//! and the risk rule (`--risk`). Any `--task`/`--task-hoa` selects this form; the paper's
//! options (`--phi`, `--psi`, `--phi2`, `--phi1-hoa`, `--phi2-hoa`, `--r1`, `--r2`, `--r`) then
//! conflict. The sub-tasks are numbered `--task` first, then `--task-hoa`, each in command-line
//! order; that order breaks ties between sets of equal payoff. The arena, translator, sigma_L,
//! discount, solver and output options are the paper form's. Tasks that are the paper's preset
//! (two sub-tasks, one of them believed, `--risk paper`, payoffs with `r >= r1 + r2`) are
//! reported in the paper's form: the library recognises them.
//!
//! Errors in an option's text are located as `--task:LINE:COL` (or `--payoff`, `--believed`)
//! with a caret under the column, relative to the option's value.

use anyhow::anyhow;

use hypersynth::game::{MAX_TASKS, SubsetPayoffs, TaskSet};
use hypersynth::pipeline::{Believed, Subtask, Task, Tasks};
use hypersynth::position::Position;
use hypersynth::translate::Translator;

use super::choices::RiskArg;
use super::synth::{Source, read_task};

/// The payoff of a sub-task without `--payoff NAME=VALUE`.
const DEFAULT_PAYOFF: f64 = 100.0;

/// Options of the general form.
#[derive(clap::Args, Debug, Default)]
#[group(id = "general")]
pub struct Args {
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
    pub fn is_active(&self) -> bool {
        !self.tasks.is_empty() || !self.task_hoa.is_empty()
    }

    /// A general option given without any sub-task.
    pub fn stray_option(&self) -> Option<&'static str> {
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
    pub fn check_usage(&self, arena: Option<&str>) -> Result<(), String> {
        if self.believed.is_none() && self.believed_hoa.is_none() {
            return Err(
                "the adversary's belief is missing: give --believed FORMULA or --believed-hoa \
                 FILE"
                    .to_string(),
            );
        }
        let count = self.tasks.len() + self.task_hoa.len();
        if count > MAX_TASKS {
            return Err(format!(
                "at most {MAX_TASKS} sub-tasks are supported, got {count}"
            ));
        }
        let hoa_files = self
            .task_hoa
            .iter()
            .map(|spec| spec.split_once('=').map_or("", |(_, file)| file));
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
}

/// `NAME=REST` split at the first `=`, the name checked (letters, digits, `_`, not starting with
/// a digit); errors are located in the option's value.
fn named<'a>(option: &'a str, spec: &'a str) -> anyhow::Result<(&'a str, &'a str)> {
    let source = Source { option, text: spec };
    let Some((name, rest)) = spec.split_once('=') else {
        return Err(source.error_at(
            Position::of_offset(spec, spec.len()),
            &"expected NAME=VALUE",
        ));
    };
    check_name(&source, name, 0)?;
    Ok((name, rest))
}

fn check_name(source: &Source, name: &str, offset: usize) -> anyhow::Result<()> {
    let valid = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if valid {
        Ok(())
    } else {
        Err(source.error_at(
            Position::of_offset(source.text, offset),
            &format!(
                "`{name}` is not a sub-task name (letters, digits and `_`, not starting with a \
                 digit)"
            ),
        ))
    }
}

/// Reads the sub-tasks, translating formulas with one translator resolved on first need.
fn subtasks(
    args: &super::synth::Args,
    translator: &mut Option<Box<dyn Translator>>,
) -> anyhow::Result<Vec<Subtask>> {
    let general = &args.general;
    let mut out: Vec<Subtask> = Vec::new();
    for spec in &general.tasks {
        let (name, text) = named("--task", spec)?;
        // Errors in the formula are prefixed with the sub-task's name.
        let option = format!("{name}: --task");
        let source = Source {
            option: &option,
            text,
        };
        let formula = source.parse()?;
        let translator = match translator {
            Some(translator) => translator,
            None => translator.insert(args.translation.resolve()?),
        };
        let task = Task::from_formula(formula, translator.as_ref())
            .map_err(|e| source.translate_error(e))?;
        out.push(Subtask {
            name: name.to_string(),
            task,
        });
    }
    for spec in &general.task_hoa {
        let (name, file) = named("--task-hoa", spec)?;
        out.push(Subtask {
            name: name.to_string(),
            task: read_task(file)?,
        });
    }
    for (i, task) in out.iter().enumerate() {
        if out[..i].iter().any(|other| other.name == task.name) {
            anyhow::bail!("sub-task `{}` is given twice", task.name);
        }
    }
    Ok(out)
}

/// `--payoff NAMES=VALUE` options: per-task payoffs and overrides of sets.
fn payoffs(specs: &[String], names: &[String]) -> anyhow::Result<SubsetPayoffs> {
    let mut per_task = vec![DEFAULT_PAYOFF; names.len()];
    let mut overrides: Vec<(TaskSet, f64)> = Vec::new();
    let mut seen: Vec<TaskSet> = Vec::new();
    for spec in specs {
        let source = Source {
            option: "--payoff",
            text: spec,
        };
        let at = |offset: usize| Position::of_offset(spec, offset);
        let Some((set_text, value_text)) = spec.split_once('=') else {
            return Err(source.error_at(at(spec.len()), &"expected NAMES=VALUE, e.g. A,B=350"));
        };
        let mut set = TaskSet::default();
        let mut offset = 0;
        for name in set_text.split(',') {
            check_name(&source, name, offset)?;
            let Some(i) = names.iter().position(|n| n == name) else {
                return Err(source.error_at(
                    at(offset),
                    &format!("no sub-task is named `{name}` (give it with --task)"),
                ));
            };
            if set.contains(i) {
                return Err(source.error_at(at(offset), &format!("`{name}` is listed twice")));
            }
            set = TaskSet(set.0 | 1 << i);
            offset += name.len() + 1;
        }
        let value_offset = set_text.len() + 1;
        let value = value_text
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v >= 0.0)
            .ok_or_else(|| {
                source.error_at(
                    at(value_offset),
                    &format!("invalid payoff `{value_text}` (a finite number >= 0)"),
                )
            })?;
        if seen.contains(&set) {
            return Err(source.error_at(at(0), &"the payoff of this set is given twice"));
        }
        seen.push(set);
        if set.len() == 1 {
            per_task[set.iter().next().expect("one member")] = value;
        } else {
            overrides.push((set, value));
        }
    }
    SubsetPayoffs::new(&per_task, &overrides, names).map_err(|e| anyhow!("--payoff: {e}"))
}

/// The general form's tasks: the sub-tasks, their payoffs, the belief and the risk rule
/// (recognised by the library as the paper's form when they are its preset).
pub fn tasks(args: &super::synth::Args) -> anyhow::Result<Tasks> {
    let general = &args.general;
    let mut translator = None;
    let subtasks = subtasks(args, &mut translator)?;
    let names: Vec<String> = subtasks.iter().map(|t| t.name.clone()).collect();
    let payoffs = payoffs(&general.payoffs, &names)?;
    let believed = match (&general.believed, &general.believed_hoa) {
        (Some(text), _) => {
            let source = Source {
                option: "--believed",
                text,
            };
            let formula = source.parse()?;
            let translator = match &mut translator {
                Some(translator) => translator,
                None => translator.insert(args.translation.resolve()?),
            };
            Believed::from_formula(formula, &subtasks, translator.as_ref())
                .map_err(|e| source.translate_error(e))?
        }
        (None, Some(file)) => Believed::Automaton(Box::new(read_task(file)?)),
        (None, None) => anyhow::bail!("the adversary's belief is missing"),
    };
    Ok(Tasks::new(subtasks, payoffs, believed, general.risk.into()))
}
