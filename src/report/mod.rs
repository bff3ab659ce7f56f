//! Reports of every stage as text tables and JSON.

mod games;

pub use games::{
    ArenaSummary, AutomataSummary, AutomatonSummary, GamesReport, InitialSummary, PerTask,
    StrategyExport, TaskAutomaton,
};

mod opportunistic;

pub use opportunistic::{
    InitialDecision, MdpConfig, MdpSettings, OpportunisticReport, SolverSummary, StageError,
    TracedRun, opportunistic_report,
};
