mod fixtures;
mod semantics;
mod spot;
