//! The robot's tasks as automata, with how reports name them: [`Tasks`], the one description
//! of what the robot must do (k named sub-tasks, payoffs on their sets, what the adversary
//! believes, the risk rule), of which the paper's form is a preset recognised here.

use crate::automata::{Dfa, hoa, minimize};
use crate::diagnostic::Diagnostics;
use crate::game::{
    Belief, Operand, Payoffs, SplitError, SubsetPayoffs, TaskSet, match_belief, split_task,
};
use crate::ltl::Formula;
use crate::opportunistic::build::Risk;
use crate::opportunistic::presentation::Presentation;
use crate::report::TaskAutomaton;
use crate::translate::{TranslateError, Translator};

/// A task's DFA (of good prefixes, minimal) and where it came from.
#[derive(Clone, Debug, PartialEq)]
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

    /// The one automaton of the HOA text `text`, read as a DFA of good prefixes and minimised
    /// ([`Task::from_automaton`]); reports name it `name`.
    pub fn from_hoa(name: &str, text: &str) -> Result<Task, HoaTaskError> {
        let automata = hoa::parse(text).map_err(HoaTaskError::Parse)?;
        let [automaton] = automata.as_slice() else {
            return Err(HoaTaskError::Count(automata.len()));
        };
        Ok(Task::from_automaton(name, &automaton.dfa))
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

/// Why a HOA text does not give a task.
#[derive(Debug, thiserror::Error)]
pub enum HoaTaskError {
    /// The text does not read as HOA.
    #[error(transparent)]
    Parse(Diagnostics),
    /// The text holds this many automata, not one.
    #[error("expected one automaton, found {0}")]
    Count(usize),
}

/// Whether `name` can name a sub-task: letters, digits and `_`, not starting with a digit (so
/// that a set of them reads unambiguously as `A,B`).
pub fn is_task_name(name: &str) -> bool {
    name.chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// A named sub-task.
#[derive(Clone, Debug)]
pub struct Subtask {
    /// Its name (`A` in `--task A=…`).
    pub name: String,
    /// Its automaton.
    pub task: Task,
}

/// The adversary's belief psi.
#[derive(Clone, Debug)]
pub enum Believed {
    /// psi is the conjunction of these sub-tasks (named as `formula`).
    Tasks {
        /// psi as printed.
        formula: String,
        /// The sub-tasks whose conjunction psi is.
        set: TaskSet,
    },
    /// psi has its own automaton.
    Automaton(Box<Task>),
}

impl Believed {
    /// psi given as a formula: the set of sub-tasks whose conjunction it is (up to the order of
    /// conjuncts), or else its own automaton translated by `translator`.
    pub fn from_formula(
        formula: Formula,
        tasks: &[Subtask],
        translator: &dyn Translator,
    ) -> Result<Believed, TranslateError> {
        let formulas: Vec<Option<&Formula>> =
            tasks.iter().map(|t| t.task.formula.as_ref()).collect();
        Ok(match match_belief(&formulas, &formula) {
            Some(set) => Believed::Tasks {
                formula: formula.to_string(),
                set,
            },
            None => Believed::Automaton(Box::new(Task::from_formula(formula, translator)?)),
        })
    }

    /// Where `Win(psi)` comes from.
    pub fn belief(&self) -> Belief {
        match self {
            Believed::Tasks { set, .. } => Belief::Tasks(*set),
            Believed::Automaton(_) => Belief::Automaton,
        }
    }

    /// psi as reports name it: its formula, or its automaton's name.
    pub fn name(&self) -> &str {
        match self {
            Believed::Tasks { formula, .. } => formula,
            Believed::Automaton(task) => &task.name,
        }
    }

    /// psi as an exported controller names it, among `k` sub-tasks: its set, or its automaton
    /// (the product's after the sub-tasks').
    pub fn as_file(&self, k: usize) -> crate::opportunistic::export::Believed {
        let (set, automaton) = match self {
            Believed::Tasks { set, .. } => (Some(set.0), None),
            Believed::Automaton(_) => (None, Some(k as u32)),
        };
        crate::opportunistic::export::Believed {
            name: self.name().to_string(),
            set,
            automaton,
        }
    }
}

/// What the robot must do and what the adversary believes (docs/semantics.md §8): k named
/// sub-tasks (at most [`crate::game::MAX_TASKS`]), the payoff of every set of them, the belief
/// psi and the risk rule. The paper's preset (two sub-tasks, psi the first, the paper's risk
/// rule and payoffs with `r >= r1 + r2`) is recognised by [`Tasks::new`], whatever way the tasks
/// were given: it gets the paper's [`Presentation`] (`phi1`, `phi2`, win-labels) and so its MDP
/// (docs/semantics.md §6); its values are the general form's. This is the one place the paper's
/// preset is recognised.
#[derive(Clone, Debug)]
pub struct Tasks {
    subtasks: Vec<Subtask>,
    payoffs: SubsetPayoffs,
    believed: Believed,
    risk: Risk,
    presentation: Presentation,
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

impl Tasks {
    /// The tasks of the general form, presented in the paper's terms when they are its preset
    /// (two sub-tasks, psi one of them, `risk` the paper's rule, payoffs the paper accepts), the
    /// believed sub-task then first, as `phi1`.
    pub fn new(
        subtasks: Vec<Subtask>,
        payoffs: SubsetPayoffs,
        believed: Believed,
        risk: Risk,
    ) -> Tasks {
        let paper = match (subtasks.as_slice(), &believed) {
            ([a, b], Believed::Tasks { set, .. })
                if risk == Risk::Paper && (set.0 == 0b01 || set.0 == 0b10) =>
            {
                let (phi1, phi2, set1, set2) = if set.0 == 0b01 {
                    (a, b, TaskSet(0b01), TaskSet(0b10))
                } else {
                    (b, a, TaskSet(0b10), TaskSet(0b01))
                };
                Payoffs::new(
                    payoffs.get(set1),
                    payoffs.get(set2),
                    payoffs.get(TaskSet(0b11)),
                )
                .ok()
                .map(|payoffs| (phi1.clone(), phi2.clone(), payoffs))
            }
            _ => None,
        };
        match paper {
            Some((phi1, phi2, payoffs)) => {
                let phi = conjunction_name(&phi1.task, &phi2.task);
                Tasks::paper(phi, phi1.task, phi2.task, payoffs)
            }
            None => {
                let names = subtasks.iter().map(|t| t.name.clone()).collect();
                Tasks {
                    subtasks,
                    payoffs,
                    believed,
                    risk,
                    presentation: Presentation::general(names),
                }
            }
        }
    }

    /// The paper's tasks: the robot's task `phi` (as reports name it) made of `phi1`, which the
    /// adversary believes is the whole task, and `phi2`, with the paper's payoffs.
    pub fn paper(phi: String, phi1: Task, phi2: Task, payoffs: Payoffs) -> Tasks {
        let presentation = Presentation::paper(phi);
        let names = presentation.names();
        let payoffs = payoffs.subsets(names);
        let believed = Believed::Tasks {
            formula: phi1.name.clone(),
            set: TaskSet(0b01),
        };
        let subtasks = names
            .iter()
            .cloned()
            .zip([phi1, phi2])
            .map(|(name, task)| Subtask { name, task })
            .collect();
        Tasks {
            subtasks,
            payoffs,
            believed,
            risk: Risk::Paper,
            presentation,
        }
    }

    /// The paper's tasks from formulas: `phi` split into `phi1 = psi` and `phi2` (the other
    /// conjuncts of phi, or `phi2` when given; see [`split_task`]), both translated by
    /// `translator`.
    pub fn from_formulas(
        phi: &Formula,
        psi: &Formula,
        phi2: Option<&Formula>,
        translator: &dyn Translator,
        payoffs: Payoffs,
    ) -> Result<Tasks, TasksError> {
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
        Ok(Tasks::paper(
            split.phi.to_string(),
            task(split.phi1, Operand::Psi)?,
            task(split.phi2, phi2_operand)?,
            payoffs,
        ))
    }

    /// The paper's tasks given separately (formulas or automata); phi is their conjunction.
    pub fn from_parts(phi1: Task, phi2: Task, payoffs: Payoffs) -> Tasks {
        Tasks::paper(conjunction_name(&phi1, &phi2), phi1, phi2, payoffs)
    }

    /// How the tasks are named (the paper's terms when they are its preset).
    pub fn presentation(&self) -> &Presentation {
        &self.presentation
    }

    /// The sub-tasks, in the product's order (the paper's form: phi1, then phi2).
    pub fn subtasks(&self) -> &[Subtask] {
        &self.subtasks
    }

    /// The sub-tasks' names, in order.
    pub fn names(&self) -> Vec<String> {
        self.subtasks.iter().map(|t| t.name.clone()).collect()
    }

    /// `r(T)` for every set of sub-tasks.
    pub fn payoffs(&self) -> &SubsetPayoffs {
        &self.payoffs
    }

    /// What the adversary believes.
    pub fn believed(&self) -> &Believed {
        &self.believed
    }

    /// The risk rule.
    pub fn risk(&self) -> Risk {
        self.risk
    }

    /// The automata of the product, named: the sub-tasks', then psi's when it has one.
    pub fn automata(&self) -> Vec<(&str, &Dfa)> {
        let mut automata: Vec<(&str, &Dfa)> = self
            .subtasks
            .iter()
            .map(|t| (t.name.as_str(), &t.task.dfa))
            .collect();
        if let Believed::Automaton(psi) = &self.believed {
            automata.push(("psi", &psi.dfa));
        }
        automata
    }
}

/// phi as the conjunction of two tasks given separately: printed as a formula when both are
/// formulas, else named after both (formulas in parentheses, files by name).
fn conjunction_name(phi1: &Task, phi2: &Task) -> String {
    match (&phi1.formula, &phi2.formula) {
        (Some(f1), Some(f2)) => Formula::and(vec![f1.clone(), f2.clone()]).to_string(),
        _ => format!("{} & {}", phi1.operand(), phi2.operand()),
    }
}
