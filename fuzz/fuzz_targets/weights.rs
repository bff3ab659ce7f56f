//! Adversary weights: reading never panics, and a table that reads is resolved against a small
//! fixed game with quoted names without panicking; every resolved distribution sums to 1.
#![no_main]

use std::sync::OnceLock;

use hypersynth::arena::{self, Arena};
use hypersynth::automata::Dfa;
use hypersynth::game::{Hypergame, States, WinningRegions};
use hypersynth::ltl;
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL, WeightTable};
use hypersynth::opportunistic::view::{GameView, SolvedHypergame};
use hypersynth::translate::{Builtin, Translator};
use libfuzzer_sys::fuzz_target;

const ARENA: &str = "initial r\n\
    state r robot {}\n\
    state \"a b\" adversary {}\n\
    state \"c\\nd\" adversary {A}\n\
    state g robot {A B}\n\
    edge r \"go north\" \"a b\"\n\
    edge r x \"c\\nd\"\n\
    edge \"a b\" x g\n\
    edge \"a b\" y r\n\
    edge \"c\\nd\" x r\n\
    edge \"c\\nd\" \"w e\" g\n\
    edge g stay g\n";

/// The arena and its product with `F A` and `F B`, built once and kept for the process.
fn game() -> &'static (Hypergame<'static>, WinningRegions) {
    static GAME: OnceLock<(Hypergame<'static>, WinningRegions)> = OnceLock::new();
    GAME.get_or_init(|| {
        let arena: &'static Arena = Box::leak(Box::new(arena::parse(ARENA).unwrap().arena));
        let translate = |text: &str| -> &'static Dfa {
            let formula = ltl::parse(text).unwrap();
            Box::leak(Box::new(
                Builtin::new(hypersynth_fuzz::limits())
                    .translate(&formula)
                    .unwrap(),
            ))
        };
        let product =
            Hypergame::new(arena, translate("F A"), translate("F B"), States::Full).unwrap();
        let regions = WinningRegions::compute(&product);
        (product, regions)
    })
}

fuzz_target!(|data: &[u8]| {
    let Some(text) = hypersynth_fuzz::text(data) else {
        return;
    };
    let Ok(table) = WeightTable::parse(text) else {
        return;
    };
    let (product, regions) = game();
    let game = SolvedHypergame::new(product, regions);
    let Ok(model) = AdversaryModel::new(&game, &SigmaL::Weights(table)) else {
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
