//! The library's option-like enums as clap value enums. The library does not depend on clap, so
//! the command line names the values (and documents them for `--help`) here and converts.

use clap::ValueEnum;
use hypersynth::game::{Engine, States};
use hypersynth::opportunistic::build::Risk;
use hypersynth::opportunistic::export::Scope;
use hypersynth::translate::TranslatorChoice;

/// `--states`: which product states to enumerate.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum StatesArg {
    /// Every arena state × every pair of DFA states reachable by arena labels.
    Full,
    /// Only the states reachable from the initial state.
    Reachable,
}

impl From<StatesArg> for States {
    fn from(states: StatesArg) -> States {
        match states {
            StatesArg::Full => States::Full,
            StatesArg::Reachable => States::Reachable,
        }
    }
}

/// `--engine`: which engine holds the product.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum EngineArg {
    /// The explicit engine when its estimate fits the memory limit (it is faster and makes
    /// every output), the implicit one otherwise.
    Auto,
    /// The stored product: every output, about 150 bytes per product state.
    Explicit,
    /// The product computed, never stored: about 20 bytes per product state; the report only.
    Implicit,
}

impl From<EngineArg> for Option<Engine> {
    fn from(engine: EngineArg) -> Option<Engine> {
        match engine {
            EngineArg::Auto => None,
            EngineArg::Explicit => Some(Engine::Explicit),
            EngineArg::Implicit => Some(Engine::Implicit),
        }
    }
}

/// `--translator`: which translator to use.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TranslatorArg {
    /// Spot when `ltl2tgba` is found, the built-in translation otherwise.
    Auto,
    /// Spot's `ltl2tgba`; an error when it is not found.
    Spot,
    /// The built-in translation.
    Builtin,
}

impl From<TranslatorArg> for TranslatorChoice {
    fn from(choice: TranslatorArg) -> TranslatorChoice {
        match choice {
            TranslatorArg::Auto => TranslatorChoice::Auto,
            TranslatorArg::Spot => TranslatorChoice::Spot,
            TranslatorArg::Builtin => TranslatorChoice::Builtin,
        }
    }
}

/// `--risk`: which actions a robot state that can settle for something keeps.
#[derive(ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RiskArg {
    /// Once `gr(h) > 0`, no action with a positive probability of a next robot state of
    /// guarantee 0 (the paper's rule).
    #[default]
    Paper,
    /// No action with a positive probability of a next robot state of lower guarantee.
    Strict,
    /// Every action.
    Neutral,
}

impl From<RiskArg> for Risk {
    fn from(risk: RiskArg) -> Risk {
        match risk {
            RiskArg::Paper => Risk::Paper,
            RiskArg::Strict => Risk::Strict,
            RiskArg::Neutral => Risk::Neutral,
        }
    }
}

/// `--controller-scope`: which robot states the exported controller decides at.
#[derive(ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ScopeArg {
    /// Those that can occur from h0 when the robot follows the controller (any adversary move).
    #[default]
    Reachable,
    /// Every robot state, so that a play goes on after the robot's own slips (a larger file).
    All,
}

impl From<ScopeArg> for Scope {
    fn from(scope: ScopeArg) -> Scope {
        match scope {
            ScopeArg::Reachable => Scope::Reachable,
            ScopeArg::All => Scope::All,
        }
    }
}
