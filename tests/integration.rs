//! The command's integration tests in one test binary: one module per file of `tests/`, helpers
//! in `common`. They run the `hypersynth` binary (the library's own tests, which use the library
//! alone, are `crates/hypersynth/tests/`). One binary links the library, clap and the test
//! dependencies once instead of once per file (the crate's `Cargo.toml` turns off Cargo's
//! one-binary-per-file discovery and names this file). The modules share one process: none of
//! them may change its environment, working directory or global thread pool (they run the
//! command as a child process, or build local pools).

mod common;

mod arena_cli;
mod certificate_cli;
mod clean_run;
mod cli_conventions;
mod cli_hoa;
mod cli_ltl;
mod cli_translate;
mod controller_export;
mod controller_schema;
mod explorer_browser;
mod explorer_cli;
mod games_cli;
mod gridworld_cli;
mod guide;
mod hostile_cli;
mod interrupt;
mod learning_curve;
mod long_lines;
mod main_form;
mod manual_cli;
mod map_cli;
mod readme;
mod regression;
mod render_cli;
mod render_geometry;
mod render_png;
mod render_raster;
mod robust;
mod subtasks_cli;
mod subtasks_render;

/// Every `.rs` file directly in `tests/` is a module of this binary: Cargo no longer compiles
/// such a file on its own, so a file left out here would silently never run.
#[test]
fn every_test_file_is_a_module_of_this_binary() {
    let this = include_str!("integration.rs");
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests");
    let mut missing = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
            continue;
        };
        let Some(module) = name.strip_suffix(".rs") else {
            continue;
        };
        if module != "integration" && !this.lines().any(|line| line == format!("mod {module};")) {
            missing.push(name.to_string());
        }
    }
    assert!(
        missing.is_empty(),
        "not declared in tests/integration.rs: {missing:?}"
    );
}
