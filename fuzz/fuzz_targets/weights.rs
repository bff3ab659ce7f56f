//! Adversary weights: reading never panics, and a table that reads is resolved against a small
//! fixed game with quoted names (`hypersynth_fuzz::quoted_game`) without panicking; every
//! resolved distribution sums to 1.
#![no_main]

use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL, WeightTable};
use hypersynth::opportunistic::view::{GameView, SolvedHypergame};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some(text) = hypersynth_fuzz::text(data) else {
        return;
    };
    let Ok(table) = WeightTable::parse(text) else {
        return;
    };
    let (tasks, product, regions) = hypersynth_fuzz::quoted_game();
    let game = SolvedHypergame::new(product, regions, tasks.payoffs(), tasks.presentation());
    let sigma = SigmaL::Weights {
        table,
        file: "fuzz".to_string(),
    };
    let Ok(model) = AdversaryModel::new(&game, &sigma) else {
        return;
    };
    let mut distribution = Vec::new();
    for h in game.states() {
        model.distribution(&game, h, &mut distribution);
        if !distribution.is_empty() {
            let sum: f64 = distribution.iter().sum();
            assert!((sum - 1.0).abs() < 1e-9, "{text}: {distribution:?}");
        }
    }
});
