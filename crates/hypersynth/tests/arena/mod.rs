mod case_study;
mod map;
