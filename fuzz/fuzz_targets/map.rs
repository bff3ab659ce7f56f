//! Map: reading never panics; a map that reads is written and read back as the same map; and a
//! map that reads (of at most 100 cells, or 400 for one input
//! in 16) builds an arena or gives the generator's clean error. A map of 400 cells builds an
//! arena of up to 320 000 states (past the 2-byte ids), tens of milliseconds: built for every
//! input, such maps held a grown corpus at under a thousand inputs a second.
#![no_main]

use hypersynth::arena::map;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some(text) = hypersynth_fuzz::text(data) else {
        return;
    };
    let Ok(world) = map::parse(text) else {
        return;
    };
    let written = map::write(&world);
    match map::parse(&written) {
        Ok(again) => assert_eq!(again, world, "the map written was\n{written}"),
        Err(error) => panic!("the map written does not read: {error:?}\n{written}"),
    }
    let cells_allowed = if data.len() % 16 == 0 { 400 } else { 100 };
    if u64::from(world.width) * u64::from(world.height) <= cells_allowed {
        let _ = world.build();
    }
});
