//! Adversary weights: reading never panics, and a table that reads is resolved against a small
//! fixed game with quoted names without panicking; every resolved distribution sums to 1.
#![no_main]

use std::sync::OnceLock;

use hypersynth::arena::{self, Arena};
use hypersynth::game::{Hypergame, Payoffs, States, TaskRegions};
use hypersynth::ltl;
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL, WeightTable};
use hypersynth::opportunistic::view::{GameView, SolvedHypergame};
use hypersynth::pipeline::Tasks;
use hypersynth::translate::Builtin;
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

/// The arena, the paper's tasks `F A & F B` believed `F A`, their product and regions, built
/// once and kept for the process.
fn game() -> &'static (&'static Tasks, Hypergame<'static>, TaskRegions) {
    static GAME: OnceLock<(&'static Tasks, Hypergame<'static>, TaskRegions)> = OnceLock::new();
    GAME.get_or_init(|| {
        let arena: &'static Arena = Box::leak(Box::new(arena::parse(ARENA).unwrap().arena));
        let translator = Builtin::new(hypersynth_fuzz::limits());
        let tasks: &'static Tasks = Box::leak(Box::new(
            Tasks::from_formulas(
                &ltl::parse("F A & F B").unwrap(),
                &ltl::parse("F A").unwrap(),
                None,
                &translator,
                Payoffs::default(),
            )
            .unwrap(),
        ));
        let product = tasks.hypergame(arena, States::Full).unwrap();
        let regions = tasks.regions(&product);
        (tasks, product, regions)
    })
}

fuzz_target!(|data: &[u8]| {
    let Some(text) = hypersynth_fuzz::text(data) else {
        return;
    };
    let Ok(table) = WeightTable::parse(text) else {
        return;
    };
    let (tasks, product, regions) = game();
    let names = tasks.names();
    let game = SolvedHypergame::new(product, regions, tasks.payoffs(), &names, tasks.form());
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
