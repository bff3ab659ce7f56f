mod case_study;
mod controller;
pub(crate) mod executor;
mod subtasks;
