//! Runs an exported controller ([`ControllerFile`]) without the solver (docs/semantics.md §9.2):
//! fed the arena states of a play as they occur, the [`Executor`] tracks the automata from the
//! states' labels and answers the robot's action at each robot turn.
//!
//! Per observed state: the first must be the arena's initial state; each next one must follow
//! the previous one by an arena transition (else [`ExecutionError::NotATransition`], naming the
//! step). A move of the adversary that the model gives probability 0 (an unsafe move where
//! sigma_W rules, an action of weight 0), or a robot move other than the one answered, is
//! reported with the turn ([`OffModel`]) and play goes on from the state it leads to. At a robot
//! state the answer is the mode's choice: uncommitted, a move, a commitment (by `stop` or
//! because the state is absorbing) followed at once by the committed set's first move, or
//! giving up; committed, the set's reactive move, or [`Answer::Done`] once every sub-task of the
//! set holds. Giving up and being done last for the rest of the play. A robot state the file
//! has no choice for (the play left the states it was exported for) is an error.
//!
//! [`Executor::plan`] reads the same tables as a [`Plan`] on a product of the same arena and
//! automata, so that the controller of a file can be evaluated and simulated with the
//! library's own evaluation and simulation.

use thiserror::Error;

use super::evaluate::{Plan, Step, Steps};
use super::export::{Choice, ControllerFile, Scope};
use super::load::{self, Checked};
use super::presentation::Presentation;
use super::view::{GameView, SolvedHypergame};
use crate::arena::{ActionId, Arena, Owner, StateId};
use crate::diagnostic::brief;
use crate::game::{HState, TaskSet};

pub use super::load::{ControllerError, Problem, Problems};

/// Why a play cannot go on.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum ExecutionError {
    /// The name is no arena state.
    #[error("step {step}: `{}` is not a state of the arena", brief(.name))]
    UnknownState {
        /// The step (0 for the first state).
        step: usize,
        /// The name read.
        name: String,
    },
    /// The first state is not the arena's initial state.
    #[error(
        "step 0: the play must start in the initial state `{}`, not `{}`",
        brief(.initial),
        brief(.name)
    )]
    NotInitial {
        /// The initial state's name.
        initial: String,
        /// The state given.
        name: String,
    },
    /// No arena transition leads from the previous state to this one.
    #[error("step {step}: no move leads from `{}` to `{}`", brief(.from), brief(.to))]
    NotATransition {
        /// The step.
        step: usize,
        /// The previous state.
        from: String,
        /// The state given.
        to: String,
    },
    /// The controller has no choice at this robot state: the play left the states it was
    /// exported for.
    #[error(
        "step {step}: the controller has no choice at `{}` (automata at {}): the play left the \
         states it was exported for{}",
        brief(.state),
        brief(format_args!("{:?}", .automata)),
        match .scope {
            Scope::Reachable => " (scope `reachable`: a controller of scope `all` decides at \
                                 every robot state)",
            Scope::All => "",
        }
    )]
    NotCovered {
        /// The step.
        step: usize,
        /// The state.
        state: String,
        /// The automata's states.
        automata: Vec<u32>,
        /// The file's scope.
        scope: Scope,
    },
}

/// A move the model or the controller did not make, at `step`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OffModel {
    /// The adversary played an action of probability 0 under the model.
    Adversary {
        /// The step of the state it led to.
        step: usize,
        /// The action's name.
        action: String,
    },
    /// The robot played another action than the one answered.
    Robot {
        /// The step of the state it led to.
        step: usize,
        /// The action answered.
        expected: String,
        /// The file's scope (with `all`, play goes on from any robot state).
        scope: Scope,
    },
}

impl std::fmt::Display for OffModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OffModel::Adversary { step, action } => write!(
                f,
                "step {step}: off-model move: the adversary played `{}`, which the model \
                 gives probability 0; play goes on",
                brief(action)
            ),
            OffModel::Robot {
                step,
                expected,
                scope,
            } => write!(
                f,
                "step {step}: the robot did not play `{}` as answered; play goes on{}",
                brief(expected),
                match scope {
                    Scope::All => " from here (the controller decides at every robot state)",
                    Scope::Reachable => "",
                }
            ),
        }
    }
}

/// The controller's answer at a robot turn.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Answer {
    /// Play this arena action.
    Move(ActionId),
    /// Commit to `set` (by `stop` when `stop`), then play `then`.
    Commit {
        /// The set committed to.
        set: TaskSet,
        /// Whether the robot plays `stop` to commit (otherwise the state is absorbing).
        stop: bool,
        /// What follows at once.
        then: Then,
    },
    /// Every sub-task of the set committed to holds.
    Done,
    /// Nothing can be gained.
    GiveUp,
}

/// What follows a commitment in the same turn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Then {
    /// The committed set's first move.
    Move(ActionId),
    /// The set already holds.
    Done,
}

/// What one observed state gives: the answer at a robot state (`None` at the adversary's), and
/// a move off the model that led to it, if any.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Turn {
    /// The controller's answer, at a robot state.
    pub answer: Option<Answer>,
    /// The move to this state, if the model or the controller did not make it.
    pub off_model: Option<OffModel>,
}

/// An exported controller, checked and ready to run.
pub struct Executor {
    checked: Checked,
    play: Play,
}

/// Where a play is.
#[derive(Clone, Debug, Default)]
struct Play {
    step: usize,
    state: Option<StateId>,
    automata: Vec<u32>,
    committed: Option<TaskSet>,
    gave_up: bool,
    /// The move answered at the previous robot state, to compare with the observed one.
    answered: Option<ActionId>,
}

impl Executor {
    /// Reads and checks an exported controller (see [`load`]: every part, also those the
    /// executor does not use, each problem located by its JSON path).
    pub fn from_json(text: &str) -> Result<Executor, ControllerError> {
        Executor::new(load::read(text)?)
    }

    /// Checks `file` (see [`load`]).
    pub fn new(file: ControllerFile) -> Result<Executor, ControllerError> {
        Ok(Executor {
            checked: load::check(file)?,
            play: Play::default(),
        })
    }

    /// The file.
    pub fn file(&self) -> &ControllerFile {
        &self.checked.file
    }

    /// The arena the controller plays in.
    pub fn arena(&self) -> &Arena {
        &self.checked.arena
    }

    /// Starts a new play.
    pub fn reset(&mut self) {
        self.play = Play::default();
    }

    /// The automata's states after the states observed so far (empty before the first).
    pub fn automata(&self) -> &[u32] {
        &self.play.automata
    }

    /// The set committed to, if any.
    pub fn committed(&self) -> Option<TaskSet> {
        self.play.committed
    }

    /// Whether every sub-task of the set committed to holds (`false` before committing).
    pub fn is_done(&self) -> bool {
        self.play.committed.is_some_and(|set| self.holds(set))
    }

    /// Whether the current state is an adversary state worth 0 (nothing can be gained from it:
    /// the controller gives up there before committing).
    pub fn is_worthless(&self) -> bool {
        let Some(s) = self
            .play
            .state
            .filter(|&s| self.checked.arena.owner(s) == Owner::Adversary)
        else {
            return false;
        };
        self.adversary_entry(s, self.tuple())
            .is_some_and(|entry| entry & 1 == 1)
    }

    /// The adversary table's entry of adversary arena state `s` with the automata at `tuple`.
    fn adversary_entry(&self, s: StateId, tuple: Option<usize>) -> Option<u64> {
        let tuples = self.checked.file.tuples.len();
        self.checked
            .adversary
            .get(self.checked.ranks.of(s) * tuples + tuple?)
    }

    /// The next state of the play, by name (bare or quoted as in the arena format).
    pub fn observe(&mut self, name: &str) -> Result<Turn, ExecutionError> {
        let state =
            self.checked
                .arena
                .find_state(name)
                .ok_or_else(|| ExecutionError::UnknownState {
                    step: self.play.step,
                    name: name.to_string(),
                })?;
        self.observe_state(state)
    }

    /// The next state of the play.
    pub fn observe_state(&mut self, state: StateId) -> Result<Turn, ExecutionError> {
        let step = self.play.step;
        let label = self.checked.letters[self.checked.arena.label_id(state) as usize];
        let mut off_model = None;
        match self.play.state {
            None => {
                if state != self.checked.arena.initial() {
                    return Err(ExecutionError::NotInitial {
                        initial: self
                            .checked
                            .arena
                            .name(self.checked.arena.initial())
                            .to_string(),
                        name: self.checked.arena.name(state).to_string(),
                    });
                }
                self.play.automata = self
                    .checked
                    .file
                    .automata
                    .iter()
                    .map(|a| a.step[a.initial as usize][label])
                    .collect();
            }
            Some(from) => {
                let edges: Vec<(usize, ActionId)> = self
                    .checked
                    .arena
                    .edges(from)
                    .enumerate()
                    .filter(|&(_, (_, t))| t == state)
                    .map(|(e, (a, _))| (e, a))
                    .collect();
                if edges.is_empty() {
                    return Err(ExecutionError::NotATransition {
                        step,
                        from: self.checked.arena.name(from).to_string(),
                        to: self.checked.arena.name(state).to_string(),
                    });
                }
                off_model = match self.checked.arena.owner(from) {
                    Owner::Adversary => {
                        let support = self.adversary_entry(from, self.tuple());
                        let possible = support.is_none_or(|entry| {
                            edges.iter().any(|&(e, _)| entry >> (e + 1) & 1 == 1)
                        });
                        (!possible).then(|| OffModel::Adversary {
                            step,
                            action: self.checked.arena.action_name(edges[0].1).to_string(),
                        })
                    }
                    Owner::Robot => self
                        .play
                        .answered
                        .filter(|&a| edges.iter().all(|&(_, b)| b != a))
                        .map(|a| OffModel::Robot {
                            step,
                            expected: self.checked.arena.action_name(a).to_string(),
                            scope: self.checked.file.scope,
                        }),
                };
                for (q, automaton) in self
                    .play
                    .automata
                    .iter_mut()
                    .zip(&self.checked.file.automata)
                {
                    *q = automaton.step[*q as usize][label];
                }
            }
        }
        self.play.state = Some(state);
        self.play.step += 1;
        self.play.answered = None;
        if self.checked.arena.owner(state) == Owner::Adversary {
            return Ok(Turn {
                answer: None,
                off_model,
            });
        }
        let answer = self.answer(state, step)?;
        self.play.answered = match answer {
            Answer::Move(a)
            | Answer::Commit {
                then: Then::Move(a),
                ..
            } => Some(a),
            _ => None,
        };
        Ok(Turn {
            answer: Some(answer),
            off_model,
        })
    }

    /// The index of the automata's current tuple, if the file has it.
    fn tuple(&self) -> Option<usize> {
        self.checked.tuples.get(&self.play.automata).copied()
    }

    /// The choice of `mode` at robot state `state`, with the automata where they are.
    fn choice(&self, mode: u8, state: StateId) -> Option<usize> {
        self.choice_at(mode, state, self.tuple())
    }

    /// Whether every sub-task of `set` holds with the automata where they are.
    fn holds(&self, set: TaskSet) -> bool {
        set.iter().all(|i| {
            let automaton = &self.checked.file.automata[i];
            automaton.finals.contains(&self.play.automata[i])
        })
    }

    fn answer(&mut self, state: StateId, step: usize) -> Result<Answer, ExecutionError> {
        if self.play.gave_up {
            return Ok(Answer::GiveUp);
        }
        let not_covered = || ExecutionError::NotCovered {
            step,
            state: self.checked.arena.name(state).to_string(),
            automata: self.play.automata.clone(),
            scope: self.checked.file.scope,
        };
        if let Some(set) = self.play.committed {
            if self.holds(set) {
                return Ok(Answer::Done);
            }
            let choice = self.choice(set.0, state).ok_or_else(not_covered)?;
            return Ok(Answer::Move(
                self.checked.moves[choice].expect("a committed mode moves"),
            ));
        }
        let choice = self.choice(0, state).ok_or_else(not_covered)?;
        Ok(match &self.checked.file.choices[choice] {
            Choice::Move(_) => Answer::Move(self.checked.moves[choice].expect("a move")),
            &Choice::Stop(set) | &Choice::Commit(set) => {
                let stop = matches!(self.checked.file.choices[choice], Choice::Stop(_));
                let set = TaskSet(set);
                self.play.committed = Some(set);
                let then = if self.holds(set) {
                    Then::Done
                } else {
                    let choice = self.choice(set.0, state).ok_or_else(not_covered)?;
                    Then::Move(self.checked.moves[choice].expect("a committed mode moves"))
                };
                Answer::Commit { set, stop, then }
            }
            Choice::GiveUp => {
                self.play.gave_up = true;
                Answer::GiveUp
            }
        })
    }

    /// How reports name a set of sub-tasks: `phi1`, `phi2`, `phi` in the paper's form, `A,B`
    /// in general.
    pub fn set_name(&self, set: TaskSet) -> String {
        Presentation::of_form(self.checked.file.form, self.checked.file.tasks.clone()).set_name(set)
    }

    /// The answer as one line of `hypersynth execute`: `ACTION`, `commit SET ACTION`, `stop SET
    /// ACTION` (or `done` for ACTION when the set already holds), `done`, or `give up`.
    pub fn answer_line(&self, answer: &Answer) -> String {
        let action = |a: ActionId| self.checked.arena.action_name(a).to_string();
        match answer {
            Answer::Move(a) => action(*a),
            Answer::Commit { set, stop, then } => {
                let then = match then {
                    Then::Move(a) => action(*a),
                    Then::Done => "done".to_string(),
                };
                let verb = if *stop { "stop" } else { "commit" };
                format!("{verb} {} {then}", self.set_name(*set))
            }
            Answer::Done => "done".to_string(),
            Answer::GiveUp => "give up".to_string(),
        }
    }

    /// The file's controller as a [`Plan`] on `game`, a product of the same arena and automata
    /// (in the same order), for the library's evaluation and simulation.
    pub fn plan<'e, 'g, 'a>(&'e self, game: &'e SolvedHypergame<'g, 'a>) -> FilePlan<'e, 'g, 'a> {
        let product = game.game();
        // The product's automata slots as the file's tuples.
        let tuples = (0..product.num_automata_slots())
            .map(|slot| {
                self.checked
                    .tuples
                    .get(&product.automata_of_slot(slot))
                    .copied()
            })
            .collect();
        FilePlan {
            executor: self,
            game,
            tuples,
        }
    }

    /// The choice of `mode` at robot arena state `s` with the automata at tuple `tuple`.
    fn choice_at(&self, mode: u8, s: StateId, tuple: Option<usize>) -> Option<usize> {
        let table = self.checked.modes[mode as usize].as_ref()?;
        table
            .get(self.checked.ranks.of(s) * self.checked.file.tuples.len() + tuple?)
            .map(|c| c as usize)
    }
}

/// An exported controller read as a [`Plan`] on a product of its arena and automata: its
/// decisions and reactive moves from the file's tables, targets from the file's final states.
pub struct FilePlan<'e, 'g, 'a> {
    executor: &'e Executor,
    game: &'e SolvedHypergame<'g, 'a>,
    /// Per automata slot of the product, the file's tuple.
    tuples: Vec<Option<usize>>,
}

impl FilePlan<'_, '_, '_> {
    fn tuple(&self, h: HState) -> Option<usize> {
        self.tuples[self.game.game().automata_slot(h) as usize]
    }

    fn file(&self) -> &ControllerFile {
        &self.executor.checked.file
    }
}

impl<'g, 'a> Plan for FilePlan<'_, 'g, 'a> {
    type Game = SolvedHypergame<'g, 'a>;
    fn game(&self) -> &Self::Game {
        self.game
    }
}

impl Steps for FilePlan<'_, '_, '_> {
    fn num_goals(&self) -> usize {
        self.file().payoffs.len()
    }
    fn is_goal_target(&self, goal: usize, h: HState) -> bool {
        let product = self.game.game();
        TaskSet(goal as u8).iter().all(|i| {
            let q = product.automaton_state(h, i);
            self.file().automata[i].finals.contains(&q)
        })
    }
    fn goal_move(&self, goal: usize, h: HState) -> Option<(ActionId, HState)> {
        let s = self.game.arena_state(h);
        let choice = self.executor.choice_at(goal as u8, s, self.tuple(h))?;
        let action = self.executor.checked.moves[choice]?;
        self.game.edges(h).find(|&(a, _)| a == action)
    }
    fn step(&self, h: HState) -> Step {
        let s = self.game.arena_state(h);
        let Some(choice) = self.executor.choice_at(0, s, self.tuple(h)) else {
            // Not exported: unreachable from h0 under the controller.
            return Step::GiveUp;
        };
        let commit = |set: u8, stop| Step::Commit {
            goal: set as usize,
            payoff: self.file().payoffs[set as usize],
            stop,
        };
        match self.file().choices[choice] {
            Choice::Move(_) => {
                let action = self.executor.checked.moves[choice].expect("a move");
                let successor = self
                    .game
                    .edges(h)
                    .find(|&(a, _)| a == action)
                    .map(|(_, t)| t)
                    .expect("the exported move is enabled");
                Step::Move { action, successor }
            }
            Choice::Stop(set) => commit(set, true),
            Choice::Commit(set) => commit(set, false),
            Choice::GiveUp => Step::GiveUp,
        }
    }
    fn stuck_payoff(&self) -> f64 {
        *self.file().payoffs.last().expect("payoffs of every set")
    }
    fn is_worthless(&self, h: HState) -> bool {
        !self.game.is_robot(h)
            && self
                .executor
                .adversary_entry(self.game.arena_state(h), self.tuple(h))
                .is_some_and(|entry| entry & 1 == 1)
    }
    fn discount(&self) -> f64 {
        self.file().discount
    }
}
