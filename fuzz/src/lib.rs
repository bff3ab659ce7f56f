//! What the fuzz targets share: turning bytes into text, the bounded translation limits, and
//! the small fixed game with quoted names that the readers of game-bound files (`weights`,
//! `observations`) resolve against. Each target in `fuzz_targets/` feeds one reader and checks
//! its round trip or its consistency, except `pipeline`, which runs small random problems
//! through the whole main form.

use std::sync::OnceLock;

use hypersynth::arena::{self, Arena};
use hypersynth::game::{Hypergame, Payoffs, States, TaskRegions};
use hypersynth::ltl;
use hypersynth::pipeline::Tasks;
use hypersynth::translate::{Builtin, TranslationLimits};

/// The input as text: readers take `&str`, so invalid UTF-8 is skipped (the CLI reports it
/// before any reader runs).
pub fn text(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

/// Small counted limits, so that no input costs much more than a millisecond whatever it says
/// (at most 128 states and 10 000 units of work, minimisation included; over a corpus the
/// `ltl` target grew in 120 s, its checks took 93 µs an input on average and 1.1 ms at most,
/// uninstrumented): a formula that needs more is refused with a limit, which the targets
/// accept. Every formula of the Spot fixtures
/// translates within a quarter of them (the most work one needs is 2 665 units), and so does
/// every problem of the `pipeline` target (under 700 units).
pub fn limits() -> TranslationLimits {
    TranslationLimits::new(128, 10_000)
}

/// The arena of [`quoted_game`]: quoted names with a space and a newline, an action with a
/// space, two adversary states (one labelled `A`), and a robot state where `A` and `B` hold.
pub const QUOTED_ARENA: &str = "initial r\n\
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

/// [`QUOTED_ARENA`] with the paper's tasks `F A & F B` believed `F A`: the tasks, their
/// product and regions, built once and kept for the process.
pub fn quoted_game() -> &'static (&'static Tasks, Hypergame<'static>, TaskRegions) {
    static GAME: OnceLock<(&'static Tasks, Hypergame<'static>, TaskRegions)> = OnceLock::new();
    GAME.get_or_init(|| {
        let arena: &'static Arena = Box::leak(Box::new(arena::parse(QUOTED_ARENA).unwrap().arena));
        let translator = Builtin::new(limits());
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
