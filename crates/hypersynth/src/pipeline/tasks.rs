//! The robot's tasks as automata, with how reports name them.

use crate::automata::{Dfa, minimize};
use crate::game::{Operand, SplitError, split_task};
use crate::ltl::Formula;
use crate::report::TaskAutomaton;
use crate::translate::{TranslateError, Translator};

/// A task's DFA (of good prefixes, minimal) and where it came from.
#[derive(Clone, Debug)]
pub struct Task {
    /// How reports name the task: its formula as printed, or the automaton's file name.
    pub name: String,
    /// The minimal complete DFA of the task's good prefixes.
    pub dfa: Dfa,
    /// What made the DFA: a translator's name, or `hoa` for an automaton read from a file.
    pub translator: String,
    /// The task's formula, when it was given as one.
    pub formula: Option<Formula>,
}

impl Task {
    /// `formula` translated by `translator`.
    pub fn from_formula(
        formula: Formula,
        translator: &dyn Translator,
    ) -> Result<Task, TranslateError> {
        Ok(Task {
            name: formula.to_string(),
            dfa: translator.translate(&formula)?,
            translator: translator.name().to_string(),
            formula: Some(formula),
        })
    }

    /// A DFA read from an automaton file called `name`, minimised (so that a file the
    /// translation wrote gives exactly the formula's DFA).
    pub fn from_automaton(name: &str, dfa: &Dfa) -> Task {
        Task {
            name: name.to_string(),
            dfa: minimize(dfa),
            translator: "hoa".to_string(),
            formula: None,
        }
    }

    /// The task as the reports show it.
    pub fn automaton(&self) -> TaskAutomaton<'_> {
        TaskAutomaton {
            formula: &self.name,
            dfa: &self.dfa,
            translator: &self.translator,
        }
    }

    /// The task as an operand of a conjunction's name: formulas in parentheses.
    fn operand(&self) -> String {
        match self.formula {
            Some(_) => format!("({})", self.name),
            None => self.name.clone(),
        }
    }
}

/// The paper's two tasks: `phi1` (what the adversary believes, psi) and `phi2`, with the
/// robot's task `phi = phi1 & phi2` as reports name it.
#[derive(Clone, Debug)]
pub struct PaperTasks {
    /// `phi` as printed.
    pub phi: String,
    /// The task the adversary believes the robot has.
    pub phi1: Task,
    /// The rest of the robot's task.
    pub phi2: Task,
}

/// Why formulas do not give the paper's two tasks.
#[derive(Debug, thiserror::Error)]
pub enum TasksError {
    /// psi (or phi2) is not made of conjuncts of phi.
    #[error(transparent)]
    Split(#[from] SplitError),
    /// A task did not translate; `operand` is the formula whose text it comes from.
    #[error("{error}")]
    Translate {
        /// The formula the failing task's text is part of.
        operand: Operand,
        /// The translation's error.
        error: TranslateError,
    },
}

impl PaperTasks {
    /// `phi` split into `phi1 = psi` and `phi2` (the other conjuncts of phi, or `phi2` when
    /// given; see [`split_task`]), both translated by `translator`.
    pub fn from_formulas(
        phi: &Formula,
        psi: &Formula,
        phi2: Option<&Formula>,
        translator: &dyn Translator,
    ) -> Result<PaperTasks, TasksError> {
        let split = split_task(phi, psi, phi2)?;
        // phi2's subformulas come from phi2's text when given, else from phi's.
        let phi2_operand = if phi2.is_some() {
            Operand::Phi2
        } else {
            Operand::Phi
        };
        let task = |formula: Formula, operand| {
            Task::from_formula(formula, translator)
                .map_err(|error| TasksError::Translate { operand, error })
        };
        Ok(PaperTasks {
            phi: split.phi.to_string(),
            phi1: task(split.phi1, Operand::Psi)?,
            phi2: task(split.phi2, phi2_operand)?,
        })
    }

    /// Two tasks given separately; phi is their conjunction: printed as a formula when both
    /// are formulas, else named after both (formulas in parentheses, files by name).
    pub fn new(phi1: Task, phi2: Task) -> PaperTasks {
        let phi = match (&phi1.formula, &phi2.formula) {
            (Some(f1), Some(f2)) => Formula::and(vec![f1.clone(), f2.clone()]).to_string(),
            _ => format!("{} & {}", phi1.operand(), phi2.operand()),
        };
        PaperTasks { phi, phi1, phi2 }
    }
}
