//! Arena I/O benchmark: generates a large gridworld, writes it, and reads it back, reporting
//! lines per second and peak memory (VmHWM from /proc/self/status, Linux only).
//!
//! `cargo bench --bench arena_io [-- SIDE]` uses a SIDE×SIDE grid without obstacles (default
//! 20: 320,000 states and about 2.3 million transitions). Reading is measured a second time in a
//! child process that only reads the file, so that its peak memory is that of the reader alone.

mod memory;

use std::time::Instant;

use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::arena::{self, Arena};

fn read(text: &str) -> Arena {
    let lines = text.lines().count();
    let start = Instant::now();
    let parsed = arena::parse(text).expect("the generated arena reads back");
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "read      {lines} lines, {:.1} MB in {seconds:.3} s: {:.2} million lines/s, {:.0} MB/s; \
         {} warnings",
        text.len() as f64 / 1e6,
        lines as f64 / seconds / 1e6,
        text.len() as f64 / seconds / 1e6,
        parsed.warnings.len()
    );
    parsed.arena
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    if let [mode, path] = &args[..]
        && mode == "read-only"
    {
        let text = std::fs::read_to_string(path).expect("readable file");
        drop(read(&text));
        println!(
            "read-only peak memory (text + arena + reader): {} MiB",
            memory::peak_text()
        );
        return;
    }
    let side: u32 = args
        .first()
        .map_or(20, |a| a.parse().expect("SIDE is a number"));

    let start = Instant::now();
    let world = Gridworld::new(
        side,
        side,
        Cell { x: 0, y: 0 },
        Cell {
            x: side - 1,
            y: side - 1,
        },
    );
    let generated = world.build().expect("a valid gridworld");
    println!(
        "generate  {side}x{side} grid: {} states, {} transitions in {:.3} s",
        generated.num_states(),
        generated.num_transitions(),
        start.elapsed().as_secs_f64()
    );

    let start = Instant::now();
    let text = arena::write(&generated);
    let seconds = start.elapsed().as_secs_f64();
    let lines = text.lines().count();
    println!(
        "write     {lines} lines in {seconds:.3} s: {:.2} million lines/s",
        lines as f64 / seconds / 1e6
    );

    let read_back = read(&text);
    assert!(
        read_back == generated,
        "reading what was written gives the same arena"
    );
    println!(
        "peak memory of generate + write + read: {} MiB",
        memory::peak_text()
    );

    let file = tempfile::NamedTempFile::new().expect("a temporary file");
    std::fs::write(file.path(), &text).expect("writable temporary file");
    drop((text, generated, read_back));
    let status = std::process::Command::new(std::env::current_exe().expect("own path"))
        .arg("read-only")
        .arg(file.path())
        .status()
        .expect("the benchmark runs itself");
    assert!(status.success());
}
