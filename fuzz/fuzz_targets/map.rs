//! Map: reading never panics, and a map that reads (of at most 400 cells) builds an arena or
//! gives the generator's clean error.
#![no_main]

use hypersynth::arena::map;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some(text) = hypersynth_fuzz::text(data) else {
        return;
    };
    if let Ok(world) = map::parse(text)
        && u64::from(world.width) * u64::from(world.height) <= 400
    {
        let _ = world.build();
    }
});
