//! The hypergame: the product of an arena with two DFAs, attractors with ranks, win-labels and
//! the reactive strategies.
