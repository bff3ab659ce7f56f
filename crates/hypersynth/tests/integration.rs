//! The library's integration tests, in one test binary: one module per file, the directories
//! mirroring `src/` (`automata/hoa/` tests `src/automata/hoa/`), files that span modules at the
//! top (`hostile_inputs.rs`, `module_dependencies.rs`), helpers in `common`. They use the library
//! alone; the command's tests are the root package's `tests/`. One binary links the library and
//! the test dependencies once instead of once per file (the crate's `Cargo.toml` turns off
//! Cargo's one-binary-per-file discovery and names this file). The modules share one process:
//! none of them may change its environment, working directory or global thread pool (they build
//! local pools).

mod common;

mod arena;
mod automata;
mod certificate;
mod game;
mod hostile_inputs;
mod implicit;
mod ltl;
mod module_dependencies;
mod opportunistic;
mod pipeline;
mod render;
mod report;
mod stage;
mod translate;

/// Every `.rs` file under `tests/` is a module of this binary, declared by its parent (this
/// file, or the directory's `mod.rs`): Cargo no longer compiles such a file on its own, so a file
/// left out would silently never run.
#[test]
fn every_test_file_is_a_module_of_this_binary() {
    use std::path::Path;
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests"));
    let mut missing = Vec::new();
    for path in common::rust_files(root) {
        let directory = path.parent().unwrap();
        let stem = path.file_stem().unwrap().to_str().unwrap();
        // `a/mod.rs` is module `a`, declared beside `a/`; `a/b.rs` is `b`, declared in `a/mod.rs`.
        let (module, declared_in) = if stem == "mod" {
            (
                directory.file_name().unwrap().to_str().unwrap(),
                directory.parent().unwrap(),
            )
        } else {
            (stem, directory)
        };
        if module == "integration" && declared_in == root {
            continue;
        }
        let parent = if declared_in == root {
            root.join("integration.rs")
        } else {
            declared_in.join("mod.rs")
        };
        let text = std::fs::read_to_string(&parent).unwrap_or_default();
        let declared = text
            .lines()
            .any(|line| line == format!("mod {module};") || line == format!("pub mod {module};"));
        if !declared {
            missing.push(path.strip_prefix(root).unwrap().display().to_string());
        }
    }
    assert!(
        missing.is_empty(),
        "not declared in their parent module: {missing:?}"
    );
}
