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

mod subtasks;

pub use subtasks::{
    BeliefSummary, RegionSummary, SetPayoff, SubtaskConfig, SubtaskDecisionSummary,
    SubtaskGamesReport, SubtaskInitial, SubtaskReport, SubtaskSettings, SubtaskSummary,
    subtask_report,
};
