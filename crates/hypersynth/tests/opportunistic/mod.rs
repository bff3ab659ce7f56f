mod case_study;
mod controller;
mod executor;
mod subtasks;
