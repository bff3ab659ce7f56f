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
use crate::limits::Bytes;
use crate::ltl::{self, Formula, Span};
use crate::position::Position;

mod builtin;
pub mod spot;

pub use builtin::{Builtin, DEFAULT_MAX_STATES, TranslationLimits};
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

/// The translator `choice` designates, under `limits`. `ltl2tgba` is the executable found by
/// [`spot::locate_ltl2tgba`], if any; Spot's runs are killed at the deadline of `limits` (or
/// after [`spot::DEFAULT_TIMEOUT`] without one), and neither translator returns a DFA of more
/// than `limits.max_states` states.
pub fn resolve(
    choice: TranslatorChoice,
    ltl2tgba: Option<PathBuf>,
    limits: TranslationLimits,
) -> Result<Box<dyn Translator>, TranslateError> {
    match (choice, ltl2tgba) {
        (TranslatorChoice::Builtin, _) | (TranslatorChoice::Auto, None) => {
            Ok(Box::new(Builtin::new(limits)))
        }
        (TranslatorChoice::Spot | TranslatorChoice::Auto, Some(path)) => Ok(Box::new(
            Spot::new(path, spot::DEFAULT_TIMEOUT).with_limits(limits),
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
    /// A limit stopped the translation: which, where, and how far it had come.
    #[error(transparent)]
    Limit(Box<LimitError>),
    /// Running Spot's `ltl2tgba` gave no automaton.
    #[error(transparent)]
    Spot(#[from] SpotError),
}

/// One of the [`TranslationLimits`], with its value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limit {
    /// States before minimisation ([`TranslationLimits::max_states`]).
    States(usize),
    /// BDD nodes, of the states and the guards ([`TranslationLimits::max_nodes`]).
    Nodes(usize),
    /// Edges before minimisation ([`TranslationLimits::max_edges`]).
    Edges(usize),
    /// Counted work ([`TranslationLimits::max_steps`]).
    Steps(u64),
    /// Bytes, as the translation counts them ([`TranslationLimits::max_bytes`]).
    Bytes(u64),
    /// The deadline ([`TranslationLimits::deadline`]), reached this long after the translation started.
    Time(Duration),
}

/// What the translation was doing when a limit stopped it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Unfolding the subformulas over the propositions and the next step (the built-in
    /// translation's first phase).
    Unfolding,
    /// Exploring the states of the automaton.
    Exploring,
    /// Reading the automaton that Spot printed.
    Reading,
    /// Minimising the automaton.
    Minimising,
}

/// How far a translation had come when a limit stopped it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Progress {
    /// States whose successors were computed.
    pub explored: usize,
    /// States found (explored or waiting to be).
    pub found: usize,
    /// Edges of the explored states (of all states, after the exploration).
    pub edges: usize,
    /// BDD nodes, of the states and the guards.
    pub nodes: usize,
    /// Bytes the translation held, as it counts them.
    pub bytes: u64,
}

/// A limit stopped the translation. The message names the limit that bound, says how far the
/// translation had come, and what raising the limit would cost (or which other limit would
/// bind then); it never names a command-line option: see [`LimitError::limit`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LimitError {
    /// The limit reached.
    pub limit: Limit,
    /// The subformula being unfolded, when the limit was reached then: its unfolding is the
    /// guard skeleton of every state it occurs in.
    pub span: Option<Span>,
    /// What the translation was doing.
    pub phase: Phase,
    /// How far it had come.
    pub progress: Progress,
    /// Every limit of the translation, to say which would bind next.
    pub limits: TranslationLimits,
    /// What the caller adds at the end of the message, in parentheses (how its users raise
    /// the limit, say); none from the library.
    pub note: Option<String>,
}

impl std::error::Error for LimitError {}

impl From<LimitError> for TranslateError {
    fn from(error: LimitError) -> TranslateError {
        TranslateError::Limit(Box::new(error))
    }
}

impl std::fmt::Display for LimitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.fmt_message(f)?;
        match &self.note {
            Some(note) => write!(f, " ({note})"),
            None => Ok(()),
        }
    }
}

impl LimitError {
    fn fmt_message(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let progress = &self.progress;
        let subject = match (self.phase, self.span) {
            (Phase::Unfolding, Some(_)) => {
                "unfolding this subformula over the propositions and the next step"
            }
            (Phase::Reading | Phase::Minimising, _) if matches!(self.limit, Limit::Time(_)) => {
                "the translation"
            }
            _ => "the built-in translation",
        };
        match self.limit {
            Limit::States(n) => write!(
                f,
                "the automaton needs more than {n} states before minimisation (the state limit)"
            )?,
            Limit::Edges(n) => write!(
                f,
                "the automaton needs more than {n} edges before minimisation (the edge limit)"
            )?,
            Limit::Nodes(n) if self.phase == Phase::Unfolding => write!(
                f,
                "{subject} needs more than {n} BDD nodes (the node limit)"
            )?,
            Limit::Nodes(n) => write!(
                f,
                "{subject} needs more than {n} BDD nodes for its states and guards (the node limit)"
            )?,
            Limit::Bytes(b) => write!(
                f,
                "{subject} needs more than {} (the memory limit)",
                Bytes(b)
            )?,
            Limit::Steps(n) => write!(f, "{subject} gave up after {n} BDD steps (the work limit)")?,
            Limit::Time(elapsed) => write!(
                f,
                "{subject} did not finish before the time limit ({:.2} s)",
                elapsed.as_secs_f64()
            )?,
        }
        match self.phase {
            Phase::Unfolding => return Ok(()),
            Phase::Reading => return f.write_str(" while reading the output of ltl2tgba"),
            Phase::Minimising => {
                return write!(
                    f,
                    " while minimising an automaton of {} states and {} edges",
                    progress.found, progress.edges
                );
            }
            Phase::Exploring => {}
        }
        write!(
            f,
            "; it had explored {} of the {} states found, with {} edges and {} BDD nodes \
             (about {})",
            progress.explored,
            progress.found,
            progress.edges,
            progress.nodes,
            Bytes(progress.bytes)
        )?;
        if let Some(advice) = self.advice() {
            write!(f, "; {advice}")?;
        }
        Ok(())
    }

    /// What raising the binding limit would cost, from the rate at which the exploration used
    /// states, edges, nodes and bytes so far, or why raising it alone would not help.
    fn advice(&self) -> Option<String> {
        let progress = &self.progress;
        let explored = progress.explored.max(1) as u64;
        let per_state = progress.bytes / explored;
        let waiting = progress.found.saturating_sub(progress.explored);
        match self.limit {
            Limit::States(n) => {
                // At twice the states, the other counts at the same rate per state.
                let limits = &self.limits;
                let scale = |count: usize| (count as u64).saturating_mul(2 * n as u64) / explored;
                let next = [
                    (scale(progress.nodes) > limits.max_nodes as u64).then_some("node"),
                    (scale(progress.edges) > limits.max_edges as u64).then_some("edge"),
                    (progress.bytes.saturating_mul(2 * n as u64) / explored > limits.max_bytes)
                        .then_some("memory"),
                ];
                let cost = Bytes(per_state.saturating_mul(2 * n as u64));
                Some(match next.iter().flatten().next() {
                    Some(other) => format!(
                        "each state took about {} so far: twice as many states would reach \
                         the {other} limit too, so raising the state limit alone would not \
                         do",
                        Bytes(per_state)
                    ),
                    None => format!(
                        "each state took about {} so far: twice as many states would take \
                         about {cost}",
                        Bytes(per_state)
                    ),
                })
            }
            Limit::Nodes(_) | Limit::Edges(_) | Limit::Bytes(_) => Some(format!(
                "the automaton was still growing ({waiting} states waiting): at about {} a \
                 state, the {} states found would take about {}{}",
                Bytes(per_state),
                progress.found,
                Bytes(per_state.saturating_mul(progress.found as u64)),
                if self.limits.max_states <= 2 * progress.found {
                    format!(", and the state limit ({}) is near", self.limits.max_states)
                } else {
                    String::new()
                }
            )),
            Limit::Steps(_) | Limit::Time(_) => (waiting > 0)
                .then(|| format!("the automaton was still growing ({waiting} states waiting)")),
        }
    }
}

impl TranslateError {
    /// The subformula the error is about, if it is about one: the operator that is not
    /// co-safe, or the subformula whose unfolding reached a limit. Limits on the whole
    /// automaton (states, edges, its nodes and steps) and Spot's failures have none.
    pub fn span(&self) -> Option<Span> {
        match self {
            TranslateError::NotCoSafe(error) => Some(error.span),
            TranslateError::Limit(error) => error.span,
            _ => None,
        }
    }

    /// Where [`TranslateError::span`] is in `source`, the text the formula was parsed from.
    pub fn position(&self, source: &str) -> Option<Position> {
        self.span()
            .map(|span| Position::of_offset(source, span.start))
    }

    /// The limit that stopped the translation, if one did (Spot's own timeout included, as
    /// [`Limit::Time`]).
    pub fn limit(&self) -> Option<Limit> {
        match self {
            TranslateError::Limit(error) => Some(error.limit),
            TranslateError::Spot(SpotError::Timeout { timeout, .. }) => Some(Limit::Time(*timeout)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_means_spot_when_found_and_builtin_otherwise() {
        let found = || Some(PathBuf::from("/opt/spot/bin/ltl2tgba"));
        let name = |choice, path| {
            resolve(choice, path, TranslationLimits::default()).map(|t| t.name().to_string())
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
