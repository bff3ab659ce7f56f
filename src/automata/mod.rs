//! Deterministic finite automata over 2^AP with symbolic guards, minimisation, language
//! comparison, and the HOA and DOT formats.
