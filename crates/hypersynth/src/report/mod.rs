//! Reports of every stage as text tables and JSON.

mod games;

pub use games::{
    ArenaSummary, AutomataSummary, AutomatonSummary, GamesReport, InitialSummary, PerTask,
    StrategyExport, TaskAutomaton,
};

mod opportunistic;

pub use opportunistic::{
    InitialDecision, MdpSettings, OpportunisticReport, SolverSummary, StageError, TracedRun,
};

mod subtasks;

pub use subtasks::{
    BeliefSummary, GoalTrace, RegionSummary, SetPayoff, SubtaskDecisionSummary, SubtaskGamesReport,
    SubtaskInitial, SubtaskReport, SubtaskSettings, SubtaskStrategyExport, SubtaskSummary,
};
