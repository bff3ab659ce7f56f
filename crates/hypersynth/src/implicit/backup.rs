//! The Bellman backup of the implicit solve, with what the rules say about each live state's
//! edges computed once (docs/semantics.md §13.2).
//!
//! A backup needs a live state's successors and which of them count: the moves the risk rule
//! allows and whether `stop` is offered (a decision node), the adversary's moves of positive
//! probability and their probability (a chance node). The successors are cheap to compute
//! from the arena's rules; the rest costs a look-up per successor in tables spread over the
//! whole index space (the next robot level, `Win(psi)`) and, for a chance node, the
//! distribution's buffers. So [`Backup`] keeps per live state a 16-bit mask of the edges that
//! count, by position in edge order, and a bit for `stop`, found once from [`Model::choices`]
//! and [`Model::distribution`]: a backup then walks the state's edges and reads the bounds of
//! those in the mask. A chance node's mask is used only when its distribution is uniform over
//! the masked edges, bit for bit `1 / count` (`sigma_W`, `sigma_L` uniform); a state with a
//! weighted distribution or more edges than the mask holds is marked to be backed up from the
//! rules, as is everything on arenas where that is the common case. Either way the sums and
//! maxima are the same, in the same order: the bounds do not depend on which path computed them.
//!
//! Measured (callgrind, 20x20 map of the `implicit` bench at g = 0.99): rebuilding the
//! distribution cost about 430 instructions per chance node backup.
//!
//! Memory: two bytes per live state.

use super::mdp::{Choice, Distribution, Model};
use super::moves::Moves;
use super::solve::Solution;
use crate::arena::{ActionId, Owner};

/// The mask bit of `stop` (a decision node).
const STOP: u16 = 1 << 14;
/// The mask of a state backed up from the rules.
const RULES: u16 = 1 << 15;
/// The most edges a mask holds.
const MASKED: usize = 14;

/// The Bellman operator on both bounds: see the module documentation.
pub(crate) struct Backup<'s, 'a, 'm, M> {
    model: &'s Model<'a, 'm, M>,
    g: f64,
    /// By live index: the edges that count, [`STOP`], or [`RULES`].
    masks: Vec<u16>,
    /// `1 / k` for `k` in `0..=MASKED`, as a uniform distribution's probabilities.
    inverse: [f64; MASKED + 1],
    distribution: Distribution,
}

impl<'s, 'a, 'm, M: Moves> Backup<'s, 'a, 'm, M> {
    /// The operator at discount `g`, with the masks of the live states `states` gives (each
    /// with its live index, every live index below `count` at most once; the others are backed
    /// up from the rules).
    pub(crate) fn new(
        model: &'s Model<'a, 'm, M>,
        g: f64,
        count: usize,
        states: impl Iterator<Item = (usize, u32)>,
    ) -> Backup<'s, 'a, 'm, M> {
        let mut inverse = [0.0; MASKED + 1];
        for (k, p) in inverse.iter_mut().enumerate().skip(1) {
            *p = 1.0 / k as f64;
        }
        let mut backup = Backup {
            model,
            g,
            masks: vec![RULES; count],
            inverse,
            distribution: Distribution::default(),
        };
        let mut chosen = Vec::new();
        for (i, h) in states {
            backup.masks[i] = backup.mask(h, &mut chosen);
        }
        backup
    }

    /// The mask of live state `h`.
    fn mask(&mut self, h: u32, chosen: &mut Vec<(ActionId, u32)>) -> u16 {
        let space = self.model.space();
        if space.degree(h) as usize > MASKED {
            return RULES;
        }
        let mut mask = 0u16;
        if space.owner(h) == Owner::Adversary {
            self.model.distribution(h, &mut self.distribution);
            let weights = self.distribution.edge_weights();
            for (k, &p) in weights.iter().enumerate() {
                if p > 0.0 {
                    mask |= 1 << k;
                }
            }
            let p = self.inverse[mask.count_ones() as usize];
            if weights
                .iter()
                .any(|&w| w > 0.0 && w.to_bits() != p.to_bits())
            {
                return RULES;
            }
        } else {
            chosen.clear();
            self.model.choices(h, |c| match c {
                Choice::Move { action, target } => chosen.push((action, target)),
                Choice::Stop { .. } => mask |= STOP,
            });
            let mut k = 0;
            space.edges(h, |a, t| {
                if chosen.contains(&(a, t)) {
                    mask |= 1 << k;
                }
                k += 1;
            });
        }
        mask
    }

    /// The backup of live state `h` (live index `i`) on both bounds, those of its successors
    /// read from `solution`.
    #[inline(always)]
    pub(crate) fn apply(&mut self, solution: &Solution, i: usize, h: u32) -> (f64, f64) {
        let model = self.model;
        let bounds = |t: u32| {
            let [lower, upper] = solution.bounds(model, t);
            (lower, upper)
        };
        let mask = self.masks[i];
        if mask & RULES != 0 {
            return self.by_rules(h, bounds);
        }
        let space = self.model.space();
        let (mut l, mut u) = (0.0f64, 0.0f64);
        let mut bit = 1u16;
        if space.owner(h) == Owner::Adversary {
            let p = self.inverse[mask.count_ones() as usize];
            space.edges(h, |_, t| {
                if mask & bit != 0 {
                    let (lt, ut) = bounds(t);
                    l += p * lt;
                    u += p * ut;
                }
                bit <<= 1;
            });
        } else {
            let g = self.g;
            space.edges(h, |_, t| {
                if mask & bit != 0 {
                    let (lt, ut) = bounds(t);
                    l = l.max(g * lt);
                    u = u.max(g * ut);
                }
                bit <<= 1;
            });
            if mask & STOP != 0 {
                let payoff = self.model.absorbing_payoff(h);
                l = l.max(payoff);
                u = u.max(payoff);
            }
        }
        (l, u)
    }

    /// The backup of live state `h` computed from the model's rules.
    fn by_rules(&mut self, h: u32, bounds: impl Fn(u32) -> (f64, f64)) -> (f64, f64) {
        let model = self.model;
        match model.space().owner(h) {
            Owner::Adversary => {
                model.distribution(h, &mut self.distribution);
                self.distribution.iter().fold((0.0, 0.0), |(l, u), (t, p)| {
                    let (lt, ut) = bounds(t);
                    (l + p * lt, u + p * ut)
                })
            }
            Owner::Robot => {
                let g = self.g;
                let (mut l, mut u) = (0.0f64, 0.0f64);
                model.choices(h, |choice| {
                    let (lc, uc) = match choice {
                        Choice::Move { target, .. } => {
                            let (lt, ut) = bounds(target);
                            (g * lt, g * ut)
                        }
                        Choice::Stop { payoff } => (payoff, payoff),
                    };
                    l = l.max(lc);
                    u = u.max(uc);
                });
                (l, u)
            }
        }
    }
}
