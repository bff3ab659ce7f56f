//! Observed runs: reading never panics, and runs that read are followed in a small fixed game
//! with quoted names (`hypersynth_fuzz::quoted_game`) without panicking. What resolves is
//! consistent: the counts per edge add up to the counted steps, misfits are among the steps of
//! sigma_W, counting is deterministic and a prefix of the runs counts no more on any edge (the
//! whole file as its own prefix counts the same); the confidence region made from the counts
//! has intervals within [0, 1] around its estimates, estimates that sum to 1 per adversary
//! state, [0, 1] where nothing was seen and [1, 1] for a single action.
#![no_main]

use hypersynth::arena::Owner;
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::observations::{Counts, Observations, Region};
use hypersynth::opportunistic::view::{GameView, SolvedHypergame};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some(text) = hypersynth_fuzz::text(data) else {
        return;
    };
    let Ok(observations) = Observations::parse(text) else {
        return;
    };
    let (tasks, product, regions) = hypersynth_fuzz::quoted_game();
    let game = SolvedHypergame::new(product, regions, tasks.payoffs(), tasks.presentation());
    let adversary = AdversaryModel::new(&game, &SigmaL::Uniform).unwrap();
    let Ok(counts) = observations.count(&game, &adversary) else {
        return;
    };
    let arena = game.arena();
    let total = |counts: &Counts| -> u64 {
        arena
            .states()
            .map(|s| {
                counts
                    .of(s)
                    .unwrap_or_default()
                    .iter()
                    .map(|&c| u64::from(c))
                    .sum::<u64>()
            })
            .sum()
    };
    assert_eq!(total(&counts), counts.counted, "{text:?}");
    assert!(
        u64::from(counts.misfits) <= counts.sigma_w_steps,
        "{text:?}"
    );
    assert_eq!(counts.runs as usize, observations.num_runs());
    // Only the adversary states observed have counts, one per edge, some positive.
    for s in arena.states() {
        match counts.of(s) {
            None => {}
            Some(row) => {
                assert_eq!(arena.owner(s), Owner::Adversary);
                assert_eq!(row.len(), arena.edges(s).len());
                assert!(row.iter().any(|&c| c > 0));
            }
        }
    }
    assert_eq!(observations.count(&game, &adversary).as_ref(), Ok(&counts));
    let whole = observations.prefix(observations.num_runs());
    assert_eq!(whole.count(&game, &adversary).as_ref(), Ok(&counts));
    let half = observations
        .prefix(observations.num_runs() / 2)
        .count(&game, &adversary)
        .expect("a prefix of runs that count counts");
    for s in arena.states() {
        let (all, some) = (counts.of(s), half.of(s));
        assert!(some.is_none() || all.is_some());
        let all = all.unwrap_or_default().iter();
        assert!(
            all.zip(some.unwrap_or_default())
                .all(|(all, some)| some <= all)
        );
    }
    let region = Region::new(&counts, 0.05).expect("a valid delta");
    for s in arena.states() {
        if arena.owner(s) != Owner::Adversary {
            continue;
        }
        let edges = arena.edges(s).len();
        let mut sum = 0.0;
        for edge in 0..edges {
            let p = region.estimate(s, edge, edges);
            let [lower, upper] = region.interval(s, edge, edges);
            assert!(
                0.0 <= lower && lower <= p && p <= upper && upper <= 1.0,
                "{text:?}: {lower} {p} {upper}"
            );
            if edges == 1 {
                assert_eq!([lower, upper], [1.0, 1.0]);
            } else if !region.is_observed(s) {
                assert_eq!([lower, upper], [0.0, 1.0]);
            }
            sum += p;
        }
        assert!(edges == 0 || (sum - 1.0).abs() < 1e-9, "{text:?}: {sum}");
        assert_eq!(region.is_observed(s), counts.of(s).is_some(), "{text:?}");
    }
});
