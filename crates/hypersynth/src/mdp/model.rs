//! The explicit MDP: states `0..n` (u32), each either a *decision state* with at least one choice
//! or an *absorbing state* with a payoff.
//!
//! Invariants that [`MdpBuilder::build`] establishes and every consumer may rely on:
//! - a state is absorbing iff it has no choices; a decision state without choices is rejected
//!   (the hypergame construction makes such states absorbing with payoff 0 instead);
//! - payoffs are finite and ≥ 0; decision states carry no payoff;
//! - every choice names an interned action and has a non-empty distribution whose targets are
//!   distinct, in range and sorted ascending, whose probabilities are positive and were given
//!   summing to 1 within [`PROBABILITY_TOLERANCE`]; they are then divided by their sum, so the
//!   stored distribution sums to 1 up to rounding;
//! - every choice is either a *move* (one robot move: it costs one factor of the discount and
//!   counts in the expected number of moves) or *instant* (the adversary's chance move, or the
//!   robot's `stop`, which collects its payoff at once);
//! - there is exactly one initial state;
//! - action names are non-empty (any name the arena format accepts; `drn` escapes white space
//!   and control characters). States have no names: a model built from a game names them on demand from
//!   the game, so that no string is kept per state.
//!
//! Layout: compressed sparse rows, two levels. `choice_offsets[s]..choice_offsets[s + 1]` are the
//! global ids of the choices of state `s`; `transition_offsets[c]..transition_offsets[c + 1]`
//! index the `targets` and `probabilities` of choice `c`. Choices of one state are consecutive,
//! so a state's transitions are one contiguous range too.

use std::collections::HashMap;
use std::ops::Range;

use bit_set::BitSet;

use thiserror::Error;

/// How far the probabilities of one choice may sum away from 1 before the builder rejects them.
pub const PROBABILITY_TOLERANCE: f64 = 1e-9;

/// An explicit MDP whose absorbing states carry payoffs. Build it with [`MdpBuilder`].
#[derive(Clone, Debug, PartialEq)]
pub struct Mdp {
    action_names: Vec<String>,
    choice_offsets: Vec<u32>,
    choice_actions: Vec<u32>,
    transition_offsets: Vec<u32>,
    targets: Vec<u32>,
    probabilities: Vec<f64>,
    /// The instant choices (all others are moves).
    instant: BitSet,
    /// One entry per state; 0 for decision states.
    payoffs: Vec<f64>,
    initial: u32,
}

impl Mdp {
    pub fn num_states(&self) -> u32 {
        self.payoffs.len() as u32
    }

    pub fn num_choices(&self) -> u32 {
        self.choice_actions.len() as u32
    }

    pub fn num_transitions(&self) -> u32 {
        self.targets.len() as u32
    }

    pub fn initial(&self) -> u32 {
        self.initial
    }

    /// The global ids of the choices of `state`; empty iff the state is absorbing.
    pub fn choices(&self, state: u32) -> Range<u32> {
        self.choice_offsets[state as usize]..self.choice_offsets[state as usize + 1]
    }

    pub fn is_absorbing(&self, state: u32) -> bool {
        self.choices(state).is_empty()
    }

    /// The payoff of an absorbing state; `None` for a decision state.
    pub fn payoff(&self, state: u32) -> Option<f64> {
        self.is_absorbing(state)
            .then(|| self.payoffs[state as usize])
    }

    /// The interned action id of `choice` (an index into [`Mdp::action_names`]).
    pub fn action(&self, choice: u32) -> u32 {
        self.choice_actions[choice as usize]
    }

    pub fn action_name(&self, choice: u32) -> &str {
        &self.action_names[self.action(choice) as usize]
    }

    pub fn action_names(&self) -> &[String] {
        &self.action_names
    }

    /// Whether `choice` is instant (no robot move: no discount, no time) rather than a move.
    pub fn is_instant(&self, choice: u32) -> bool {
        self.instant.contains(choice as usize)
    }

    /// The factor `choice` applies to the values of its successors: `g` for a move, 1 for an
    /// instant choice.
    pub fn discount_factor(&self, choice: u32, g: f64) -> f64 {
        if self.is_instant(choice) { 1.0 } else { g }
    }

    /// The successors of `choice` with their probabilities, targets ascending and distinct.
    pub fn successors(
        &self,
        choice: u32,
    ) -> impl ExactSizeIterator<Item = (u32, f64)> + Clone + '_ {
        let range = self.transition_range(choice);
        self.targets[range.clone()]
            .iter()
            .copied()
            .zip(self.probabilities[range].iter().copied())
    }

    /// The successor states of `choice`, ascending and distinct.
    pub fn targets(&self, choice: u32) -> &[u32] {
        &self.targets[self.transition_range(choice)]
    }

    fn transition_range(&self, choice: u32) -> Range<usize> {
        self.transition_offsets[choice as usize] as usize
            ..self.transition_offsets[choice as usize + 1] as usize
    }
}

/// Why an [`Mdp`] could not be built. States and actions are named as the builder saw them.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum MdpError {
    #[error("invalid action name {name:?}: action names are non-empty")]
    InvalidActionName { name: String },
    #[error("unknown action id {action} ({count} actions are interned)")]
    UnknownAction { action: u32, count: u32 },
    #[error("a choice was added while no decision state was open")]
    NoOpenDecisionState,
    #[error("state {state}: action {action} has no successors")]
    EmptyDistribution { state: u32, action: String },
    #[error(
        "state {state}: action {action} gives state {target} probability {probability}; \
         probabilities must be positive and finite"
    )]
    InvalidProbability {
        state: u32,
        action: String,
        target: u32,
        probability: f64,
    },
    #[error("state {state}: the probabilities of action {action} sum to {sum}, not 1")]
    ProbabilitySum {
        state: u32,
        action: String,
        sum: f64,
    },
    #[error(
        "state {state}: action {action} leads to state {target}, but there are only {states} states"
    )]
    TargetOutOfRange {
        state: u32,
        action: String,
        target: u32,
        states: u32,
    },
    #[error("state {state} is a decision state without choices (make it absorbing with payoff 0)")]
    NoChoices { state: u32 },
    #[error("state {state}: payoff {payoff} is not a finite number ≥ 0")]
    InvalidPayoff { state: u32, payoff: f64 },
    #[error("state {state} does not exist ({states} states)")]
    UnknownState { state: u32, states: u32 },
    #[error("no initial state was set")]
    NoInitialState,
    #[error("the MDP has more than 2^32 - 1 states, choices or transitions")]
    TooLarge,
}

/// Builds an [`Mdp`] state by state, in index order: `add_decision_state` opens a decision state
/// that the following `add_choice` calls fill; `add_absorbing_state` adds an absorbing one.
/// Targets may name states that are added later; they are checked by [`MdpBuilder::build`].
/// An error leaves the builder unchanged.
#[derive(Clone, Debug, Default)]
pub struct MdpBuilder {
    action_names: Vec<String>,
    action_ids: HashMap<String, u32>,
    choice_offsets: Vec<u32>,
    choice_actions: Vec<u32>,
    transition_offsets: Vec<u32>,
    targets: Vec<u32>,
    probabilities: Vec<f64>,
    instant: BitSet,
    payoffs: Vec<f64>,
    absorbing: Vec<bool>,
    initial: Option<u32>,
    /// Reused by `add_choice` to sort and merge a distribution.
    scratch: Vec<(u32, f64)>,
}

impl MdpBuilder {
    pub fn new() -> Self {
        MdpBuilder {
            choice_offsets: vec![0],
            transition_offsets: vec![0],
            ..MdpBuilder::default()
        }
    }

    /// Interns an action name and returns its id (the same id for the same name).
    pub fn action(&mut self, name: &str) -> Result<u32, MdpError> {
        if let Some(&id) = self.action_ids.get(name) {
            return Ok(id);
        }
        if name.is_empty() {
            return Err(MdpError::InvalidActionName {
                name: name.to_owned(),
            });
        }
        let id = to_u32(self.action_names.len())?;
        self.action_names.push(name.to_owned());
        self.action_ids.insert(name.to_owned(), id);
        Ok(id)
    }

    /// Adds a decision state; the following [`MdpBuilder::add_choice`] calls give its choices.
    pub fn add_decision_state(&mut self) -> Result<u32, MdpError> {
        self.add_state(0.0, false)
    }

    /// Adds an absorbing state with a finite payoff ≥ 0.
    pub fn add_absorbing_state(&mut self, payoff: f64) -> Result<u32, MdpError> {
        if !(payoff.is_finite() && payoff >= 0.0) {
            return Err(MdpError::InvalidPayoff {
                state: to_u32(self.payoffs.len())?,
                payoff,
            });
        }
        self.add_state(payoff, true)
    }

    /// Adds a move (a choice that takes one robot move) to the decision state added last.
    /// Duplicate targets are merged (their probabilities added); the distribution is normalised
    /// to sum to 1. Returns the choice id.
    pub fn add_choice(&mut self, action: u32, successors: &[(u32, f64)]) -> Result<u32, MdpError> {
        self.add_timed_choice(action, successors, false)
    }

    /// Adds an instant choice (no robot move: not discounted, not counted as time), otherwise
    /// like [`MdpBuilder::add_choice`].
    pub fn add_instant_choice(
        &mut self,
        action: u32,
        successors: &[(u32, f64)],
    ) -> Result<u32, MdpError> {
        self.add_timed_choice(action, successors, true)
    }

    fn add_timed_choice(
        &mut self,
        action: u32,
        successors: &[(u32, f64)],
        instant: bool,
    ) -> Result<u32, MdpError> {
        let state = match self.absorbing.last() {
            Some(false) => to_u32(self.absorbing.len() - 1)?,
            _ => return Err(MdpError::NoOpenDecisionState),
        };
        let action_name = match self.action_names.get(action as usize) {
            Some(name) => name.clone(),
            None => {
                return Err(MdpError::UnknownAction {
                    action,
                    count: to_u32(self.action_names.len())?,
                });
            }
        };
        if successors.is_empty() {
            return Err(MdpError::EmptyDistribution {
                state,
                action: action_name,
            });
        }
        if let Some(&(target, probability)) = successors
            .iter()
            .find(|(_, probability)| !(probability.is_finite() && *probability > 0.0))
        {
            return Err(MdpError::InvalidProbability {
                state,
                action: action_name,
                target,
                probability,
            });
        }
        let sum: f64 = successors.iter().map(|(_, probability)| probability).sum();
        if (sum - 1.0).abs() > PROBABILITY_TOLERANCE {
            return Err(MdpError::ProbabilitySum {
                state,
                action: action_name,
                sum,
            });
        }
        self.scratch.clear();
        self.scratch.extend_from_slice(successors);
        self.scratch.sort_by_key(|&(target, _)| target);
        self.scratch.dedup_by(|next, kept| {
            let same = next.0 == kept.0;
            if same {
                kept.1 += next.1;
            }
            same
        });
        // Check every count before mutating, so that an error leaves the builder unchanged.
        let transitions_end = to_u32(self.targets.len() + self.scratch.len())?;
        let choice = to_u32(self.choice_actions.len())?;
        let choices_end = to_u32(self.choice_actions.len() + 1)?;
        for &(target, probability) in &self.scratch {
            self.targets.push(target);
            self.probabilities.push(probability / sum);
        }
        if instant {
            self.instant.insert(choice as usize);
        }
        self.choice_actions.push(action);
        self.transition_offsets.push(transitions_end);
        let open_state_end = self.choice_offsets.len() - 1;
        self.choice_offsets[open_state_end] = choices_end;
        Ok(choice)
    }

    /// Sets the initial state (checked by [`MdpBuilder::build`]).
    pub fn set_initial(&mut self, state: u32) {
        self.initial = Some(state);
    }

    /// Checks what could not be checked while adding (targets and the initial state in range,
    /// every decision state with a choice) and returns the MDP.
    pub fn build(self) -> Result<Mdp, MdpError> {
        let states = to_u32(self.payoffs.len())?;
        for state in 0..states {
            let choices =
                self.choice_offsets[state as usize]..self.choice_offsets[state as usize + 1];
            if choices.is_empty() && !self.absorbing[state as usize] {
                return Err(MdpError::NoChoices { state });
            }
            for choice in choices {
                let transitions = self.transition_offsets[choice as usize] as usize
                    ..self.transition_offsets[choice as usize + 1] as usize;
                if let Some(&target) = self.targets[transitions].iter().find(|&&t| t >= states) {
                    return Err(MdpError::TargetOutOfRange {
                        state,
                        action: self.action_names[self.choice_actions[choice as usize] as usize]
                            .clone(),
                        target,
                        states,
                    });
                }
            }
        }
        let initial = self.initial.ok_or(MdpError::NoInitialState)?;
        if initial >= states {
            return Err(MdpError::UnknownState {
                state: initial,
                states,
            });
        }
        Ok(Mdp {
            action_names: self.action_names,
            choice_offsets: self.choice_offsets,
            choice_actions: self.choice_actions,
            transition_offsets: self.transition_offsets,
            targets: self.targets,
            probabilities: self.probabilities,
            instant: self.instant,
            payoffs: self.payoffs,
            initial,
        })
    }

    fn add_state(&mut self, payoff: f64, absorbing: bool) -> Result<u32, MdpError> {
        let state = self.payoffs.len();
        // The state count itself must fit in a u32 (`num_states`).
        to_u32(state + 1)?;
        self.payoffs.push(payoff);
        self.absorbing.push(absorbing);
        let choices_so_far = self.choice_offsets[self.choice_offsets.len() - 1];
        self.choice_offsets.push(choices_so_far);
        Ok(state as u32)
    }
}

fn to_u32(count: usize) -> Result<u32, MdpError> {
    u32::try_from(count).map_err(|_| MdpError::TooLarge)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A decision state 0 with actions N and stop, an absorbing state 1 with payoff 200.
    fn two_states() -> MdpBuilder {
        let mut builder = MdpBuilder::new();
        let north = builder.action("N").unwrap();
        let stop = builder.action("stop").unwrap();
        builder.add_decision_state().unwrap();
        builder
            .add_choice(north, &[(0, 0.25), (1, 0.5), (0, 0.25)])
            .unwrap();
        builder.add_choice(stop, &[(1, 1.0)]).unwrap();
        builder.add_absorbing_state(200.0).unwrap();
        builder.set_initial(0);
        builder
    }

    #[test]
    fn builder_lays_out_csr_and_merges_duplicate_targets() {
        let mdp = two_states().build().unwrap();
        assert_eq!(
            (mdp.num_states(), mdp.num_choices(), mdp.num_transitions()),
            (2, 2, 3)
        );
        assert_eq!(mdp.choices(0), 0..2);
        assert_eq!(mdp.choices(1), 2..2);
        assert!(!mdp.is_absorbing(0) && mdp.is_absorbing(1));
        assert_eq!((mdp.payoff(0), mdp.payoff(1)), (None, Some(200.0)));
        assert_eq!((mdp.action_name(0), mdp.action_name(1)), ("N", "stop"));
        assert_eq!(mdp.action_names(), ["N", "stop"]);
        // The two entries for state 0 (0.25 + 0.25) become one, targets ascending.
        assert_eq!(mdp.successors(0).collect::<Vec<_>>(), [(0, 0.5), (1, 0.5)]);
        assert_eq!(mdp.targets(1), [1]);
        assert_eq!(mdp.initial(), 0);
    }

    #[test]
    fn probabilities_within_tolerance_are_normalised() {
        let mut builder = MdpBuilder::new();
        let a = builder.action("a").unwrap();
        builder.add_decision_state().unwrap();
        builder
            .add_choice(a, &[(0, 0.5), (1, 0.5 + 1e-10)])
            .unwrap();
        builder.add_absorbing_state(1.0).unwrap();
        builder.set_initial(0);
        let mdp = builder.build().unwrap();
        let sum: f64 = mdp.successors(0).map(|(_, p)| p).sum();
        assert!((sum - 1.0).abs() <= f64::EPSILON);
    }

    #[test]
    fn interning_returns_one_id_per_name() {
        let mut builder = MdpBuilder::new();
        assert_eq!(builder.action("N"), Ok(0));
        assert_eq!(builder.action("S"), Ok(1));
        assert_eq!(builder.action("N"), Ok(0));
        assert_eq!(
            builder.action(""),
            Err(MdpError::InvalidActionName { name: "".into() })
        );
        // Every name the arena format accepts is an action name (DRN escapes what it must).
        assert_eq!(builder.action("go north"), Ok(2));
        assert_eq!(builder.action("tab\there"), Ok(3));
    }

    #[test]
    fn invalid_choices_are_rejected_without_changing_the_builder() {
        let mut builder = MdpBuilder::new();
        let a = builder.action("a").unwrap();
        assert_eq!(
            builder.add_choice(a, &[(0, 1.0)]),
            Err(MdpError::NoOpenDecisionState)
        );
        builder.add_decision_state().unwrap();
        assert_eq!(
            builder.add_choice(7, &[(0, 1.0)]),
            Err(MdpError::UnknownAction {
                action: 7,
                count: 1
            })
        );
        assert_eq!(
            builder.add_choice(a, &[]),
            Err(MdpError::EmptyDistribution {
                state: 0,
                action: "a".into()
            })
        );
        for bad in [0.0, -0.5, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                builder.add_choice(a, &[(0, bad), (0, 1.0)]),
                Err(MdpError::InvalidProbability {
                    state: 0,
                    target: 0,
                    ..
                })
            ));
        }
        assert_eq!(
            builder.add_choice(a, &[(0, 0.5), (0, 0.4)]),
            Err(MdpError::ProbabilitySum {
                state: 0,
                action: "a".into(),
                sum: 0.9
            })
        );
        builder.add_choice(a, &[(0, 1.0)]).unwrap();
        builder.set_initial(0);
        let mdp = builder.build().unwrap();
        assert_eq!(mdp.num_choices(), 1);
        assert_eq!(mdp.num_transitions(), 1);
    }

    #[test]
    fn build_checks_targets_choices_payoffs_and_the_initial_state() {
        let mut builder = MdpBuilder::new();
        let a = builder.action("a").unwrap();
        builder.add_decision_state().unwrap();
        builder.add_choice(a, &[(3, 1.0)]).unwrap();
        builder.set_initial(0);
        assert_eq!(
            builder.clone().build(),
            Err(MdpError::TargetOutOfRange {
                state: 0,
                action: "a".into(),
                target: 3,
                states: 1
            })
        );

        let mut builder = MdpBuilder::new();
        builder.add_decision_state().unwrap();
        builder.set_initial(0);
        assert_eq!(builder.build(), Err(MdpError::NoChoices { state: 0 }));

        let mut builder = MdpBuilder::new();
        for bad in [-1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                builder.add_absorbing_state(bad),
                Err(MdpError::InvalidPayoff { state: 0, .. })
            ));
        }
        builder.add_absorbing_state(0.0).unwrap();
        assert_eq!(builder.clone().build(), Err(MdpError::NoInitialState));
        builder.set_initial(1);
        assert_eq!(
            builder.build(),
            Err(MdpError::UnknownState {
                state: 1,
                states: 1
            })
        );
    }
}
