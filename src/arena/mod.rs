//! Two-player turn-based arenas: the model, its text format (reader and writer) and the
//! gridworld generator.
