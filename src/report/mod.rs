//! Reports of every stage as text tables and JSON.
