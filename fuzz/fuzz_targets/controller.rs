//! Exported controller: the input's first line is a controller file, its next lines (at most
//! 64) are a play as `hypersynth execute` reads it on standard input, one arena state per
//! line. Reading the file never panics and refuses it with short located messages (no line of
//! an error over 1 KiB, whatever the input); a file that reads is written again and reads back
//! as the same file; and the play's states are observed by the executor (as `execute` does,
//! going on after an off-model move and starting a new play after an error) without panicking,
//! its errors short too, and every answer names an action the arena enables at the state. A
//! file whose map has more than 100 cells is skipped before it is built (its arena has
//! 2·cells² states: the `map` target builds those).
#![no_main]

use hypersynth::arena::map;
use hypersynth::opportunistic::executor::{Answer, Executor, Then};
use hypersynth::opportunistic::export::ArenaSource;
use hypersynth::opportunistic::load;
use libfuzzer_sys::fuzz_target;

/// The longest line an error message may have.
const LONGEST: usize = 1024;

fn short(error: &impl std::fmt::Display) {
    let message = error.to_string();
    for line in message.lines() {
        assert!(
            line.len() <= LONGEST,
            "a line of {} bytes: {line:.300}",
            line.len()
        );
    }
}

fuzz_target!(|data: &[u8]| {
    let Some(text) = hypersynth_fuzz::text(data) else {
        return;
    };
    let (json, play) = text.split_once('\n').unwrap_or((text, ""));
    let file = match load::read(json) {
        Ok(file) => file,
        Err(error) => return short(&error),
    };
    if let ArenaSource::Map(map) = &file.arena
        && map::parse(map).is_ok_and(|world| u64::from(world.width) * u64::from(world.height) > 100)
    {
        return;
    }
    let mut executor = match Executor::new(file) {
        Ok(executor) => executor,
        Err(error) => return short(&error),
    };
    let written = serde_json::to_string(executor.file()).expect("a file writes");
    match load::read(&written) {
        Ok(again) => assert_eq!(&again, executor.file(), "written as {written:.300}"),
        Err(error) => panic!("the file written does not read: {error}"),
    }
    for line in play.lines().take(64) {
        let name = line.trim();
        if name.is_empty() {
            continue;
        }
        match executor.observe(name) {
            Ok(turn) => {
                let state = executor.arena().find_state(name).expect("a state observed");
                let action = match turn.answer {
                    Some(Answer::Move(action)) => Some(action),
                    Some(Answer::Commit {
                        then: Then::Move(action),
                        ..
                    }) => Some(action),
                    _ => None,
                };
                if let Some(action) = action {
                    assert!(executor.arena().successor(state, action).is_some());
                }
                if let Some(answer) = &turn.answer {
                    let _ = executor.answer_line(answer);
                }
                if let Some(off_model) = &turn.off_model {
                    short(off_model);
                }
            }
            Err(error) => {
                short(&error);
                executor.reset();
            }
        }
    }
});
