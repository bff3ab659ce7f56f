//! The one home of the test helpers that more than one test binary or benchmark uses: the
//! crate's integration tests, its benchmarks and the command's tests (compiled for the crate's
//! own tests, and elsewhere with the `testing` feature; not part of the API). Helpers that one
//! binary alone uses stay in its `tests/common/`. The automata written as tables live in
//! [`crate::automata::testing`], where the crate's unit tests below this layer reach them; they
//! are re-exported here.

pub use crate::automata::testing::{avoid_until, dfa_from_table, eventually};

use crate::game::{Belief, Hypergame, Payoffs, SubsetPayoffs, TaskRegions, TaskSet};
use crate::opportunistic::presentation::Presentation;
use crate::opportunistic::view::SolvedHypergame;
use crate::render::figure;

/// The paper's `phi1` (the task the adversary believes), `phi2` and `phi` as sets of its two
/// sub-tasks.
pub const PHI1: TaskSet = TaskSet(0b01);
/// `phi2`.
pub const PHI2: TaskSet = TaskSet(0b10);
/// `phi = phi1 & phi2`.
pub const PHI: TaskSet = TaskSet(0b11);
/// The paper's tasks with their names, in the order of the win-label triple.
pub const PAPER_TASKS: [(&str, TaskSet); 3] = [("phi1", PHI1), ("phi2", PHI2), ("phi", PHI)];

/// The paper's three winning regions `Win(phi1)`, `Win(phi2)`, `Win(phi)` of a product of its two
/// tasks (the adversary believing phi1).
pub fn paper_regions(game: &Hypergame) -> TaskRegions {
    TaskRegions::compute(game, 2, Belief::Tasks(PHI1))
}

/// What a [`SolvedHypergame`] of the paper's form borrows, for a product of its two tasks: the
/// regions, the payoffs on the sets and the paper's presentation.
pub struct PaperGame {
    /// [`paper_regions`] of the product.
    pub regions: TaskRegions,
    /// The payoffs on the sets of the two sub-tasks.
    pub payoffs: SubsetPayoffs,
    /// The paper's names.
    pub presentation: Presentation,
}

impl PaperGame {
    /// With the case study's payoffs.
    pub fn new(game: &Hypergame) -> PaperGame {
        PaperGame::with_payoffs(game, Payoffs::default())
    }

    /// With the paper's payoffs `payoffs`.
    pub fn with_payoffs(game: &Hypergame, payoffs: Payoffs) -> PaperGame {
        let presentation = Presentation::paper("phi");
        PaperGame {
            regions: paper_regions(game),
            payoffs: payoffs.subsets(presentation.names()),
            presentation,
        }
    }

    /// The MDP stage's view of `game` with these regions.
    pub fn view<'g, 'a>(&'g self, game: &'g Hypergame<'a>) -> SolvedHypergame<'g, 'a> {
        SolvedHypergame::new(game, &self.regions, &self.payoffs, &self.presentation)
    }
}

/// The overlaps of a picture (`figure::overlaps`), after checking that `svg` reads back
/// (`figure::read`) with more than ten texts in it; `name` says which picture in the panics.
pub fn picture_overlaps(svg: &str, name: &str) -> Vec<String> {
    let items = figure::read(svg).unwrap_or_else(|e| panic!("{name}: {e}"));
    let texts = items
        .iter()
        .filter(|i| i.role == figure::Role::Text)
        .count();
    assert!(texts > 10, "{name}: only {texts} texts read");
    figure::overlaps(&items)
}

/// A hostile formula, `F((p0 & X q0) | … | (pk & X qk))` (k + 1 disjuncts): the unfolding of
/// the `|` over the propositions and the next step tells the 2^(k+1) sets of `q`s apart, and its
/// first `|` is at column 15.
pub fn disjunction_of_next_steps(disjuncts: usize) -> String {
    let terms: Vec<String> = (0..disjuncts).map(|i| format!("(p{i} & X q{i})")).collect();
    format!("F({})", terms.join(" | "))
}

/// The retry arena of the learnt adversary's tests: robot `r` moves `go` to adversary `a` (where
/// `C` holds, so the adversary, believing the task is `F C`, plays sigma_L there), which answers
/// `x` to `g` (task `A` done: payoff 100) or `y` to `b`, from which the robot moves `back` to `r`
/// and tries again.
pub const RETRY_ARENA: &str = "initial r
state r robot {}
state a adversary {C}
state g robot {A}
state b robot {}
edge r go a
edge a x g
edge a y b
edge g stay g
edge b back r
";

/// The data an explorer page embeds ([`crate::explorer::Page`], as JSON): its base 64
/// (RFC 4648, padded) decoded and inflated (zlib) here, independently of the page's writer.
pub fn explorer_data(html: &str) -> serde_json::Value {
    const MARK: &str = "<script id=\"data\" type=\"application/octet-stream\">";
    let start = html.find(MARK).expect("the page's data") + MARK.len();
    let text = &html[start..start + html[start..].find('<').expect("closed")];
    let digit = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base 64: {c}"),
    };
    let mut bytes = Vec::with_capacity(text.len() / 4 * 3);
    for chunk in text.as_bytes().chunks(4) {
        let digits: Vec<u8> = chunk
            .iter()
            .filter(|&&c| c != b'=')
            .map(|&c| digit(c))
            .collect();
        let word = digits
            .iter()
            .enumerate()
            .fold(0u32, |word, (i, &d)| word | u32::from(d) << (18 - 6 * i));
        bytes.extend((0..digits.len() - 1).map(|i| (word >> (16 - 8 * i)) as u8));
    }
    let json = miniz_oxide::inflate::decompress_to_vec_zlib(&bytes).expect("zlib data");
    serde_json::from_slice(&json).expect("JSON data")
}
