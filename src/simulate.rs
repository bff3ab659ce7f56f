//! Runs of the controller against the adversary model.
