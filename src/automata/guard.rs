//! Guards: Boolean functions over an automaton's atomic propositions, kept symbolic.
//!
//! A guard is a disjunction of [`Cube`]s (conjunctions of literals). Propositions are numbered
//! `0..64` in the order of the automaton's `aps` list, and a *letter* (a valuation of the
//! propositions) is a `u64` whose bit `i` says whether proposition `i` holds. So an automaton
//! has at most [`MAX_PROPOSITIONS`] propositions; in exchange a cube is two machine words and
//! evaluating a guard on a letter is a few bit operations, which is what the product with an
//! arena does for every DFA state and distinct arena label.
//!
//! The representation is not canonical (two guards may denote the same function with different
//! cubes): compare functions with [`Guard::equivalent`], not `==`. Negation splits on variables
//! (Shannon expansion), so it is exponential only in the propositions the guard mentions.

use std::fmt;

/// The largest number of atomic propositions an automaton may have.
pub const MAX_PROPOSITIONS: usize = 64;

/// A conjunction of literals: the propositions in `positive` hold and those in `negative` do not.
/// Invariant: `positive & negative == 0` (a contradictory cube is never stored).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Cube {
    pub positive: u64,
    pub negative: u64,
}

impl Cube {
    /// The cube with no literals, true everywhere.
    pub const TRUE: Cube = Cube {
        positive: 0,
        negative: 0,
    };

    /// The one-literal cube of the proposition whose bit is `bit`: it holds if `positive`, it
    /// does not otherwise.
    pub fn literal(bit: u64, positive: bool) -> Cube {
        if positive {
            Cube {
                positive: bit,
                negative: 0,
            }
        } else {
            Cube {
                positive: 0,
                negative: bit,
            }
        }
    }

    /// The conjunction of two cubes, or `None` when it is contradictory.
    pub fn and(self, other: Cube) -> Option<Cube> {
        let cube = Cube {
            positive: self.positive | other.positive,
            negative: self.negative | other.negative,
        };
        (cube.positive & cube.negative == 0).then_some(cube)
    }

    pub fn evaluate(self, letter: u64) -> bool {
        letter & self.positive == self.positive && letter & self.negative == 0
    }

    /// The propositions the cube mentions.
    pub fn support(self) -> u64 {
        self.positive | self.negative
    }

    /// The cube without its literals on the propositions in `propositions`.
    fn without(self, propositions: u64) -> Cube {
        Cube {
            positive: self.positive & !propositions,
            negative: self.negative & !propositions,
        }
    }
}

/// A disjunction of cubes; no cubes is `false`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct Guard {
    cubes: Vec<Cube>,
}

impl Guard {
    pub fn always() -> Guard {
        Guard {
            cubes: vec![Cube::TRUE],
        }
    }

    pub fn never() -> Guard {
        Guard { cubes: Vec::new() }
    }

    /// Proposition `proposition` (`< 64`) if `positive`, its negation otherwise.
    pub fn literal(proposition: u32, positive: bool) -> Guard {
        debug_assert!((proposition as usize) < MAX_PROPOSITIONS);
        Guard {
            cubes: vec![Cube::literal(1u64 << proposition, positive)],
        }
    }

    pub fn from_cubes(cubes: impl IntoIterator<Item = Cube>) -> Guard {
        let mut guard = Guard {
            cubes: cubes
                .into_iter()
                .filter(|c| c.positive & c.negative == 0)
                .collect(),
        };
        guard.normalise();
        guard
    }

    pub fn cubes(&self) -> &[Cube] {
        &self.cubes
    }

    /// The numerically smallest letter satisfying the guard: a cube's smallest letter sets only
    /// its positive literals. Disjoint guards have distinct smallest letters, so this orders the
    /// edges of a state independently of how their guards are written.
    pub fn smallest_letter(&self) -> Option<u64> {
        self.cubes.iter().map(|c| c.positive).min()
    }

    /// The same function with fewer literals, for readable output: repeatedly, when two cubes
    /// clash on exactly one proposition and the rest of one is contained in the rest of the
    /// other (`x & r` and `!x & r & s`), the literal on that proposition is dropped from the
    /// second (`r & s`), which is sound because `r & s & x` is already covered by `x & r`. This
    /// merges `a & b | a & !b` into `a` and turns `a | !a & b` into `a | b`; it does not always
    /// reach a minimal cover.
    pub fn simplified(&self) -> Guard {
        let mut cubes = self.cubes.clone();
        loop {
            let mut changed = false;
            for i in 0..cubes.len() {
                for j in 0..cubes.len() {
                    let (x, y) = (cubes[i], cubes[j]);
                    let clash = (x.positive & y.negative) | (x.negative & y.positive);
                    if clash.count_ones() != 1 {
                        continue;
                    }
                    let (x_rest, y_rest) = (x.without(clash), y.without(clash));
                    if x_rest.positive & !y_rest.positive == 0
                        && x_rest.negative & !y_rest.negative == 0
                    {
                        cubes[j] = y_rest;
                        changed = true;
                    }
                }
            }
            if !changed {
                return Guard::from_cubes(cubes);
            }
            cubes = Guard::from_cubes(cubes).cubes;
        }
    }

    /// Sorts the cubes and drops those subsumed by another, so that simple guards print simply.
    fn normalise(&mut self) {
        self.cubes.sort_unstable();
        self.cubes.dedup();
        if self.cubes.contains(&Cube::TRUE) {
            self.cubes = vec![Cube::TRUE];
            return;
        }
        let cubes = std::mem::take(&mut self.cubes);
        // `a` subsumes `b` when every literal of `a` is in `b`.
        let subsumes = |a: &Cube, b: &Cube| {
            a.positive & b.positive == a.positive && a.negative & b.negative == a.negative
        };
        for (i, cube) in cubes.iter().enumerate() {
            let redundant = cubes
                .iter()
                .enumerate()
                .any(|(j, other)| j != i && subsumes(other, cube) && (other != cube || j < i));
            if !redundant {
                self.cubes.push(*cube);
            }
        }
    }

    pub fn evaluate(&self, letter: u64) -> bool {
        self.cubes.iter().any(|c| c.evaluate(letter))
    }

    /// The propositions the guard mentions.
    pub fn support(&self) -> u64 {
        self.cubes.iter().fold(0, |acc, c| acc | c.support())
    }

    pub fn or(&self, other: &Guard) -> Guard {
        Guard::from_cubes(self.cubes.iter().chain(&other.cubes).copied())
    }

    pub fn and(&self, other: &Guard) -> Guard {
        Guard::from_cubes(
            self.cubes
                .iter()
                .flat_map(|a| other.cubes.iter().filter_map(move |b| a.and(*b))),
        )
    }

    /// The complement, as disjoint cubes.
    pub fn not(&self) -> Guard {
        let mut cubes = Vec::new();
        complement_into(&self.cubes, Cube::TRUE, &mut cubes);
        Guard::from_cubes(cubes)
    }

    /// Whether some letter satisfies the guard (every stored cube is consistent).
    pub fn is_satisfiable(&self) -> bool {
        !self.cubes.is_empty()
    }

    /// Whether every letter satisfies the guard.
    pub fn is_valid(&self) -> bool {
        !self.not().is_satisfiable()
    }

    pub fn intersects(&self, other: &Guard) -> bool {
        self.and(other).is_satisfiable()
    }

    /// Whether the two guards denote the same Boolean function.
    pub fn equivalent(&self, other: &Guard) -> bool {
        !self.and(&other.not()).is_satisfiable() && !other.and(&self.not()).is_satisfiable()
    }

    /// A letter satisfying the guard (propositions it does not constrain are false).
    pub fn witness(&self) -> Option<u64> {
        self.cubes.first().map(|c| c.positive)
    }

    /// The same function with proposition `i` renumbered `positions[i]` (`< 64`), for moving a
    /// guard into another automaton's numbering. Only the entries of propositions the guard
    /// mentions are read.
    pub fn remap(&self, positions: &[u32]) -> Guard {
        let move_bits = |bits: u64| {
            (0..MAX_PROPOSITIONS)
                .filter(|&i| bits & (1u64 << i) != 0)
                .fold(0u64, |acc, i| acc | (1u64 << positions[i]))
        };
        Guard::from_cubes(self.cubes.iter().map(|c| Cube {
            positive: move_bits(c.positive),
            negative: move_bits(c.negative),
        }))
    }

    /// The guard as text, cubes joined by ` | `, e.g. `!0&1 | 2` (HOA) or `!a & b | c`.
    pub fn display<'a>(&'a self, style: GuardStyle<'a>) -> GuardDisplay<'a> {
        GuardDisplay { guard: self, style }
    }
}

/// How [`Guard::display`] writes propositions and constants.
#[derive(Clone, Copy, Debug)]
pub enum GuardStyle<'a> {
    /// HOA label syntax: proposition numbers, `&` without spaces, constants `t` and `f`.
    Hoa,
    /// Proposition names (quoted unless they are plain identifiers), ` & `, `true` and `false`.
    Names(&'a [String]),
}

/// A guard formatted in a [`GuardStyle`]; a valid guard prints as the constant true.
pub struct GuardDisplay<'a> {
    guard: &'a Guard,
    style: GuardStyle<'a>,
}

impl fmt::Display for GuardDisplay<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (truth, falsity, and) = match self.style {
            GuardStyle::Hoa => ("t", "f", "&"),
            GuardStyle::Names(_) => ("true", "false", " & "),
        };
        if !self.guard.is_satisfiable() {
            return f.write_str(falsity);
        }
        if self.guard.is_valid() {
            return f.write_str(truth);
        }
        for (i, cube) in self.guard.cubes.iter().enumerate() {
            if i > 0 {
                f.write_str(" | ")?;
            }
            let literals =
                (0..MAX_PROPOSITIONS as u32).filter(|&p| cube.support() & (1u64 << p) != 0);
            for (j, proposition) in literals.enumerate() {
                if j > 0 {
                    f.write_str(and)?;
                }
                if cube.negative & (1u64 << proposition) != 0 {
                    f.write_str("!")?;
                }
                match self.style {
                    GuardStyle::Hoa => write!(f, "{proposition}")?,
                    GuardStyle::Names(names) => {
                        write_name(f, &names[proposition as usize])?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// Writes a proposition name, double-quoted unless it is a plain identifier that cannot be
/// mistaken for a constant.
fn write_name(f: &mut fmt::Formatter<'_>, name: &str) -> fmt::Result {
    let plain = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !matches!(name, "true" | "false");
    if plain {
        f.write_str(name)
    } else {
        f.write_str(&quoted(name))
    }
}

/// `text` as a C-like double-quoted string (`"` and `\` escaped by `\`), the string syntax of
/// HOA, DOT and Spot's atomic propositions.
pub fn quoted(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('"');
    for c in text.chars() {
        if matches!(c, '"' | '\\') {
            out.push('\\');
        }
        out.push(c);
    }
    out.push('"');
    out
}

/// Pushes onto `out` disjoint cubes, all within `context`, covering exactly the letters of
/// `context` that no cube of `cubes` covers.
fn complement_into(cubes: &[Cube], context: Cube, out: &mut Vec<Cube>) {
    let live: Vec<Cube> = cubes.iter().filter_map(|c| c.and(context)).collect();
    if live.is_empty() {
        out.push(context);
        return;
    }
    if live.iter().any(|c| c.support() & !context.support() == 0) {
        return; // some cube covers all of `context`
    }
    // Split on a variable that the first live cube constrains beyond `context` (there is one,
    // or that cube would cover `context`).
    let pending = live[0].support() & !context.support();
    let bit = pending & pending.wrapping_neg();
    for positive in [true, false] {
        if let Some(branch) = context.and(Cube::literal(bit, positive)) {
            complement_into(&live, branch, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every letter over the first `n` propositions.
    fn letters(n: u32) -> impl Iterator<Item = u64> {
        0..(1u64 << n)
    }

    fn truth_table(guard: &Guard, n: u32) -> Vec<bool> {
        letters(n).map(|l| guard.evaluate(l)).collect()
    }

    #[test]
    fn connectives_match_their_truth_tables() {
        let a = Guard::literal(0, true);
        let b = Guard::literal(1, true);
        let not_c = Guard::literal(2, false);
        let f = a.and(&b).or(&not_c); // (a & b) | !c
        for letter in letters(3) {
            let (va, vb, vc) = (letter & 1 != 0, letter & 2 != 0, letter & 4 != 0);
            assert_eq!(f.evaluate(letter), (va && vb) || !vc);
            assert_eq!(f.not().evaluate(letter), !((va && vb) || !vc));
        }
        assert!(f.or(&f.not()).is_valid());
        assert!(!f.intersects(&f.not()));
        assert!(!f.is_valid());
        assert!(Guard::always().is_valid());
        assert!(!Guard::never().is_satisfiable());
        assert!(Guard::never().not().is_valid());
        assert!(Guard::always().not().cubes().is_empty());
    }

    #[test]
    fn simplification_keeps_the_function_and_drops_literals() {
        let (a, b, c) = (
            Guard::literal(0, true),
            Guard::literal(1, true),
            Guard::literal(2, true),
        );
        // a & b | a & !b is a.
        let split = a.and(&b).or(&a.and(&b.not()));
        assert_eq!(split.simplified(), a);
        // a | !a & b is a | b.
        assert_eq!(a.or(&a.not().and(&b)).simplified(), a.or(&b));
        // The eight full cubes over a, b, c are `true`.
        let everything = Guard::from_cubes((0..8u64).map(|l| Cube {
            positive: l,
            negative: !l & 7,
        }));
        assert_eq!(everything.simplified(), Guard::always());
        // A function with no shorter form keeps its truth table.
        let parity = a.and(&b.not()).or(&a.not().and(&b)).and(&c);
        let simplified = parity.simplified();
        assert_eq!(truth_table(&simplified, 3), truth_table(&parity, 3));
        assert_eq!(simplified.cubes().len(), 2);
        assert_eq!(parity.smallest_letter(), Some(0b101));
        assert_eq!(Guard::never().smallest_letter(), None);
    }

    #[test]
    fn complement_cubes_are_disjoint() {
        // !(a | b | c) has one cube; !(a & b & c) three disjoint ones.
        let conj = Guard::literal(0, true)
            .and(&Guard::literal(1, true))
            .and(&Guard::literal(2, true));
        let complement = conj.not();
        for (i, x) in complement.cubes().iter().enumerate() {
            for y in &complement.cubes()[i + 1..] {
                assert!(x.and(*y).is_none());
            }
        }
        assert_eq!(
            truth_table(&complement, 3),
            truth_table(&conj, 3).iter().map(|v| !v).collect::<Vec<_>>()
        );
    }

    #[test]
    fn normalisation_drops_subsumed_cubes_and_equivalence_is_semantic() {
        let a = Guard::literal(0, true);
        let ab = a.and(&Guard::literal(1, true));
        assert_eq!(a.or(&ab), a);
        // a&b | a&!b is a, with different cubes.
        let split = ab.or(&a.and(&Guard::literal(1, false)));
        assert_ne!(split, a);
        assert!(split.equivalent(&a));
        assert_eq!(a.witness(), Some(1));
        assert!(a.evaluate(a.witness().unwrap()));
    }

    #[test]
    fn remapping_moves_propositions() {
        // (a & !b) | c over [a, b, c], moved to positions [3, 0, 5].
        let f = Guard::literal(0, true)
            .and(&Guard::literal(1, false))
            .or(&Guard::literal(2, true));
        let moved = f.remap(&[3, 0, 5]);
        for letter in letters(6) {
            let bit = |i: u32| letter & (1 << i) != 0;
            assert_eq!(moved.evaluate(letter), (bit(3) && !bit(0)) || bit(5));
        }
    }

    #[test]
    fn guards_print_in_hoa_and_named_styles() {
        let names: Vec<String> = ["a", "b c", "true"].map(String::from).to_vec();
        let f = Guard::literal(0, false)
            .and(&Guard::literal(1, true))
            .or(&Guard::literal(2, true));
        assert_eq!(f.display(GuardStyle::Hoa).to_string(), "!0&1 | 2");
        assert_eq!(
            f.display(GuardStyle::Names(&names)).to_string(),
            "!a & \"b c\" | \"true\""
        );
        // A valid guard prints as the constant, however it is split into cubes.
        let split = Guard::literal(0, true).or(&Guard::literal(0, false));
        assert_eq!(split.display(GuardStyle::Hoa).to_string(), "t");
        assert_eq!(split.display(GuardStyle::Names(&names)).to_string(), "true");
        assert_eq!(Guard::never().display(GuardStyle::Hoa).to_string(), "f");
    }
}
