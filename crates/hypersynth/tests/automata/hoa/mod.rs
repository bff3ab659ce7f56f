mod errors;
mod fixtures;
mod mutations;
mod reader;
mod writer;
