//! From co-safe LTL to the minimal complete DFA of its good prefixes.
//!
//! A [`Translator`] turns a [`Formula`] into a [`Dfa`]; both implementations reject formulas that
//! are not syntactically co-safe (with [`ltl::check_co_safe`]'s error) and return a minimised DFA
//! over the formula's propositions, so their results are interchangeable:
//! - [`Builtin`]: formula progression with BDD-canonical states, in process;
//! - [`Spot`] ([`spot`]): runs Spot's `ltl2tgba` and reads its HOA output.
//!
//! [`resolve`] picks one from a [`TranslatorChoice`]: `auto` is Spot when an `ltl2tgba`
//! executable was found, the built-in translation otherwise.

use std::path::PathBuf;
use std::time::Duration;

use crate::automata::{Dfa, MAX_PROPOSITIONS};
use crate::ltl::{self, Formula, Span};
use crate::position::Position;

mod builtin;
pub mod spot;

pub use builtin::{Builtin, DEFAULT_MAX_STATES, Limits, STEPS_PER_SECOND};
pub use spot::{Spot, SpotError};

/// A translation from co-safe LTL to the minimal complete DFA of good prefixes.
pub trait Translator {
    /// A short name for messages: `builtin`, or `spot (PATH)` with the executable's path.
    fn name(&self) -> &str;

    /// The minimal complete DFA accepting exactly the good prefixes of `formula`, over its
    /// atomic propositions in order of first appearance.
    fn translate(&self, formula: &Formula) -> Result<Dfa, TranslateError>;
}

/// Which translator to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TranslatorChoice {
    /// Spot when `ltl2tgba` is found, the built-in translation otherwise.
    #[default]
    Auto,
    /// Spot's `ltl2tgba`; an error when it is not found.
    Spot,
    /// The built-in translation.
    Builtin,
}

/// The translator `choice` designates. `ltl2tgba` is the executable found by
/// [`spot::locate_ltl2tgba`], if any; `timeout` bounds each of its runs, and the built-in
/// translation's work by [`Limits::for_timeout`]; neither returns a DFA of more than
/// `max_states` states.
pub fn resolve(
    choice: TranslatorChoice,
    ltl2tgba: Option<PathBuf>,
    timeout: Duration,
    max_states: usize,
) -> Result<Box<dyn Translator>, TranslateError> {
    match (choice, ltl2tgba) {
        (TranslatorChoice::Builtin, _) | (TranslatorChoice::Auto, None) => Ok(Box::new(
            Builtin::new(Limits::for_timeout(max_states, timeout)),
        )),
        (TranslatorChoice::Spot | TranslatorChoice::Auto, Some(path)) => Ok(Box::new(
            Spot::new(path, timeout).with_max_states(max_states),
        )),
        (TranslatorChoice::Spot, None) => Err(SpotError::NotFound.into()),
    }
}

/// Why a formula could not be translated.
#[derive(Debug, thiserror::Error)]
pub enum TranslateError {
    /// The formula is not co-safe (syntactically), so no DFA of good prefixes is attempted.
    #[error(transparent)]
    NotCoSafe(#[from] ltl::CoSafetyError),
    /// The formula has the given number of propositions, more than [`MAX_PROPOSITIONS`].
    #[error(
        "the formula has {0} atomic propositions, more than the {MAX_PROPOSITIONS} an automaton \
         may have"
    )]
    TooManyPropositions(usize),
    /// The automaton before minimisation would have more states than the state limit (given).
    #[error(
        "the automaton needs more than {0} states before minimisation, the state limit (raise it \
         with --max-states)"
    )]
    TooManyStates(usize),
    /// The built-in translation needed more BDD nodes than the limit that comes with the state
    /// limit.
    #[error(
        "the built-in translation needs more than {nodes} BDD nodes for its states and guards, \
         the limit that comes with {states} states (raise it with --max-states)"
    )]
    NodeLimit {
        /// The most BDD nodes allowed.
        nodes: usize,
        /// The state limit the node limit was derived from.
        states: usize,
    },
    /// The automaton before minimisation would have more edges than the limit that comes with
    /// the state limit.
    #[error(
        "the automaton needs more than {edges} edges before minimisation, the limit that comes \
         with {states} states (raise it with --max-states)"
    )]
    EdgeLimit {
        /// The most edges allowed.
        edges: usize,
        /// The state limit the edge limit was derived from.
        states: usize,
    },
    /// The built-in translation took more BDD steps than the translator timeout allows; the number
    /// of steps allowed.
    #[error(
        "the built-in translation gave up after {0} BDD steps, the work allowed by the \
         translator timeout (raise it with --translator-timeout)"
    )]
    WorkLimit(u64),
    /// The node limit, reached while unfolding one subformula (expanding it over the
    /// propositions and the next step: the guards of every state it occurs in).
    #[error(
        "unfolding this subformula over the propositions and the next step needs more than \
         {nodes} BDD nodes, the limit that comes with {states} states (raise it with \
         --max-states)"
    )]
    SubformulaNodeLimit {
        /// The subformula being unfolded.
        span: Span,
        /// The node limit.
        nodes: usize,
        /// The state limit it comes with.
        states: usize,
    },
    /// The work limit, reached while unfolding one subformula.
    #[error(
        "unfolding this subformula over the propositions and the next step took more than \
         {steps} BDD steps, the work allowed by the translator timeout (raise it with \
         --translator-timeout)"
    )]
    SubformulaWorkLimit {
        /// The subformula being unfolded.
        span: Span,
        /// The step limit.
        steps: u64,
    },
    /// Running Spot's `ltl2tgba` gave no automaton.
    #[error(transparent)]
    Spot(#[from] SpotError),
}

impl TranslateError {
    /// The subformula the error is about, if it is about one: the operator that is not
    /// co-safe, or the subformula whose unfolding reached a limit. Limits on the whole
    /// automaton (states, edges, its nodes and steps) and Spot's failures have none.
    pub fn span(&self) -> Option<Span> {
        match self {
            TranslateError::NotCoSafe(error) => Some(error.span),
            TranslateError::SubformulaNodeLimit { span, .. }
            | TranslateError::SubformulaWorkLimit { span, .. } => Some(*span),
            _ => None,
        }
    }

    /// Where [`TranslateError::span`] is in `source`, the text the formula was parsed from.
    pub fn position(&self, source: &str) -> Option<Position> {
        self.span()
            .map(|span| Position::of_offset(source, span.start))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_means_spot_when_found_and_builtin_otherwise() {
        let found = || Some(PathBuf::from("/opt/spot/bin/ltl2tgba"));
        let timeout = spot::DEFAULT_TIMEOUT;
        let name = |choice, path| {
            resolve(choice, path, timeout, DEFAULT_MAX_STATES).map(|t| t.name().to_string())
        };
        let spot_name = "spot (/opt/spot/bin/ltl2tgba)".to_string();
        assert_eq!(name(TranslatorChoice::Auto, found()).unwrap(), spot_name);
        assert_eq!(name(TranslatorChoice::Auto, None).unwrap(), "builtin");
        assert_eq!(name(TranslatorChoice::Spot, found()).unwrap(), spot_name);
        assert_eq!(name(TranslatorChoice::Builtin, found()).unwrap(), "builtin");
        assert!(matches!(
            name(TranslatorChoice::Spot, None),
            Err(TranslateError::Spot(SpotError::NotFound))
        ));
    }
}
