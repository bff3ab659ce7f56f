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
//! Even with the masks, a backup from the rules still computes each successor's index from
//! the arena's rules and the automata's tables and finds its live index by counting bits:
//! about 430 instructions per backup (callgrind, the 16x16 map of `scripts/bench-vs-storm` at
//! g = 0.99), most of a sweep's time. So a component of more than one state, which is swept
//! again and again, is *compiled* first ([`Backup::compile`], on all threads): per member,
//! the references of the successors its mask keeps, a live successor's live index or an
//! absorbing successor's payoff level ([`Compiled`]); its sweeps read the bounds through them
//! ([`Backup::apply_at`]). The sums and maxima are those of the rules, in the same order:
//! an absorbing successor worth 0 is left out, and it adds `+0` to a sum of non-negative terms
//! and nothing to a maximum from 0, so the bounds are the same bit for bit. Measured at
//! g = 0.99, relative 1e-6: on the 24x24 map of `scripts/bench-vs-storm`, the component of
//! 318k states (145 sweeps) 1.51 s from the rules, 0.58 s compiled (9.1 MB of references);
//! on the 40x40 map of the `implicit` bench, the component of 2.99 M states (230 sweeps)
//! 19.2 s, then 11.7 s (87 MB, 29 bytes per member).
//!
//! Memory: two bytes per live state; while a component is swept, four bytes per member and
//! four per reference, refused beyond a budget (the solve's is [`COMPILED_PER_LIVE`] bytes
//! per live state): a component whose references would take more is backed up from the
//! rules.

use bit_set::BitSet;
use rayon::prelude::*;

use super::ends::successors_within;
use super::mdp::{Choice, Distribution, Model};
use super::moves::Moves;
use super::numbering::Numbering;
use super::solve::Solution;
use super::space::Space;
use crate::arena::Owner;

/// The mask bit of `stop` (a decision node).
pub(crate) const STOP: u16 = 1 << 14;
/// The mask of a state backed up from the rules.
pub(crate) const RULES: u16 = 1 << 15;
/// The most edges a mask holds.
pub(crate) const MASKED: usize = 14;

/// The bytes per live state of the model that the compiled edges of the component the implicit
/// solve sweeps may take: a component whose edges would take more is backed up from the
/// rules, more slowly (docs/engines.md, Memory).
pub const COMPILED_PER_LIVE: usize = 8;

/// The tag of a [`Compiled`] reference to an absorbing successor (its level in the low bits);
/// the other references are live indices.
const ABSORBING: u32 = 1 << 31;

/// The members a thread of [`Backup::compile`] takes at a time.
const CHUNK: usize = 1 << 12;

/// `1 / k` for `k` in `0..=MASKED`, as a uniform distribution's probabilities (`[0]` unused).
pub(crate) type Inverses = [f64; MASKED + 1];

/// The [`Inverses`].
pub(crate) fn inverses() -> Inverses {
    let mut inverse = [0.0; MASKED + 1];
    for (k, p) in inverse.iter_mut().enumerate().skip(1) {
        *p = 1.0 / k as f64;
    }
    inverse
}

/// The mask of live state `h`: the edges that count, [`STOP`] when a decision node offers
/// `stop`, or [`RULES`] (module documentation); `inverse` is [`inverses`], `distribution` a
/// buffer.
pub(crate) fn edge_mask<M: Moves>(
    model: &Model<'_, '_, M>,
    h: u32,
    inverse: &Inverses,
    distribution: &mut Distribution,
) -> u16 {
    let space = model.space();
    if space.degree(h) as usize > MASKED {
        return RULES;
    }
    if space.owner(h) == Owner::Adversary {
        model.distribution(h, distribution);
        return uniform_mask(distribution, inverse);
    }
    let mut mask = 0u16;
    model.choices_by_edge(h, |position, c| match (position, c) {
        (Some(k), Choice::Move { .. }) => mask |= 1 << k,
        _ => mask |= STOP,
    });
    mask
}

/// The mask of a chance node's `distribution` (filled by [`Model::distribution`]): its edges
/// of positive probability when they are at most [`MASKED`] and the probabilities are, bit for
/// bit, `1 / count` ([`Inverses`]); [`RULES`] otherwise.
pub(crate) fn uniform_mask(distribution: &Distribution, inverse: &Inverses) -> u16 {
    let weights = distribution.edge_weights();
    if weights.len() > MASKED {
        return RULES;
    }
    let mut mask = 0u16;
    for (k, &p) in weights.iter().enumerate() {
        if p > 0.0 {
            mask |= 1 << k;
        }
    }
    let p = inverse[mask.count_ones() as usize];
    if weights
        .iter()
        .any(|&w| w > 0.0 && w.to_bits() != p.to_bits())
    {
        return RULES;
    }
    mask
}

/// Calls `f` with each successor of `h` whose edge is in `mask`, in edge order.
#[inline(always)]
pub(crate) fn masked_edges<M: Moves>(
    space: &Space<'_, M>,
    h: u32,
    mask: u16,
    mut f: impl FnMut(u32),
) {
    let mut bit = 1u16;
    space.edges(h, |_, t| {
        if mask & bit != 0 {
            f(t);
        }
        bit <<= 1;
    });
}

/// One component's edges, read from the rules once before it is swept (module
/// documentation): per member, by position in the component, the references of its successors
/// that count, in edge order. For the solve's backup ([`Backup::compile`]): a live
/// successor's live index, or an absorbing successor's level tagged [`ABSORBING`]; absorbing
/// successors worth 0 are left out (they change no sum and no maximum), and so are the edges
/// of a member backed up from the rules ([`RULES`]). The policy's expected moves compile
/// their eligible edges alike (`policy.rs`).
pub(crate) struct Compiled {
    /// By position: where the member's references start in `refs` (one more at the end).
    starts: Vec<u32>,
    refs: Vec<u32>,
}

impl Compiled {
    /// The references `references(h, f)` calls `f` with for each of `members`, found on all
    /// threads, unless they would take more than `budget` bytes.
    pub(crate) fn new(
        members: &[u32],
        budget: usize,
        references: impl Fn(u32, &mut dyn FnMut(u32)) + Sync,
    ) -> Option<Compiled> {
        let n = members.len();
        if (n + 1).saturating_mul(4) > budget {
            return None;
        }
        let mut starts = vec![0u32; n + 1];
        starts[1..]
            .par_chunks_mut(CHUNK)
            .zip(members.par_chunks(CHUNK))
            .for_each(|(counts, run)| {
                for (count, &h) in counts.iter_mut().zip(run) {
                    references(h, &mut |_| *count += 1);
                }
            });
        let mut total = 0u64;
        for start in &mut starts {
            total += u64::from(*start);
            *start = u32::try_from(total).ok()?;
        }
        if (n + 1 + total as usize).saturating_mul(4) > budget {
            return None;
        }
        let mut refs = vec![0u32; total as usize];
        let mut parts = Vec::with_capacity(n.div_ceil(CHUNK));
        let mut rest = refs.as_mut_slice();
        for (k, run) in members.chunks(CHUNK).enumerate() {
            let len = starts[k * CHUNK + run.len()] - starts[k * CHUNK];
            let (part, tail) = std::mem::take(&mut rest).split_at_mut(len as usize);
            parts.push((run, part));
            rest = tail;
        }
        parts.into_par_iter().for_each(|(run, part)| {
            let mut at = 0;
            for &h in run {
                references(h, &mut |r| {
                    part[at] = r;
                    at += 1;
                });
            }
        });
        Some(Compiled { starts, refs })
    }

    /// The references of the member at `position`.
    #[inline(always)]
    pub(crate) fn get(&self, position: usize) -> &[u32] {
        let (start, end) = (self.starts[position], self.starts[position + 1]);
        &self.refs[start as usize..end as usize]
    }
}

/// The Bellman operator on both bounds: see the module documentation. Threads may share it,
/// each with its own buffer for the distributions computed from the rules.
pub(crate) struct Backup<'s, 'a, 'm, M> {
    model: &'s Model<'a, 'm, M>,
    g: f64,
    /// By live index: the edges that count, [`STOP`], or [`RULES`].
    masks: Vec<u16>,
    inverse: Inverses,
}

impl<'s, 'a, 'm, M: Moves> Backup<'s, 'a, 'm, M> {
    /// The operator at discount `g`, with the masks of the live states (numbered by `live`)
    /// that `swept` holds, found on all threads (the others are backed up from the rules).
    pub(crate) fn new(
        model: &'s Model<'a, 'm, M>,
        g: f64,
        live: &Numbering,
        swept: impl Fn(u32) -> bool + Sync + Send,
    ) -> Backup<'s, 'a, 'm, M> {
        let inverse = inverses();
        let mut masks = vec![RULES; live.len()];
        live.update(
            &mut masks,
            Distribution::default,
            |h, mask, distribution| {
                if swept(h) {
                    *mask = edge_mask(model, h, &inverse, distribution);
                }
            },
        );
        Backup {
            model,
            g,
            masks,
            inverse,
        }
    }

    /// The edges of the component `members` (live states numbered by `live`, in increasing
    /// order) compiled for its sweeps on all threads, unless they would take more than
    /// `budget` bytes.
    pub(crate) fn compile(
        &self,
        live: &Numbering,
        members: &[u32],
        budget: usize,
    ) -> Option<Compiled> {
        if live.len() >= ABSORBING as usize {
            return None;
        }
        Compiled::new(members, budget, |h, f| self.references(live, h, f))
    }

    /// Calls `f` with the [`Compiled`] reference of each successor live state `h` keeps.
    fn references(&self, live: &Numbering, h: u32, f: &mut dyn FnMut(u32)) {
        let mask = self.masks[live.index(h)];
        if mask & RULES != 0 {
            return;
        }
        let model = self.model;
        masked_edges(model.space(), h, mask, |t| match live.get(t) {
            Some(j) => f(j as u32),
            None => {
                let level = model.level(t);
                if model.payoff_of_level(level) != 0.0 {
                    f(ABSORBING | u32::from(level));
                }
            }
        });
    }

    /// Fills `out` with the successors in `set` of live state `h` (live index `i`) through
    /// the edges that count, in edge order: those [`successors_within`] lists, read from the
    /// mask where there is one (`distribution`: a buffer).
    pub(crate) fn successors_within(
        &self,
        (i, h): (usize, u32),
        set: &BitSet,
        distribution: &mut Distribution,
        out: &mut Vec<u32>,
    ) {
        let mask = self.masks[i];
        if mask & RULES != 0 {
            return successors_within(self.model, h, set, distribution, out);
        }
        out.clear();
        masked_edges(self.model.space(), h, mask, |t| {
            if set.contains(t as usize) {
                out.push(t);
            }
        });
    }

    /// The backup of live state `h` (live index `i`) on both bounds, those of its successors
    /// read from `solution` (`distribution`: a buffer).
    #[inline(always)]
    pub(crate) fn apply(
        &self,
        solution: &Solution,
        (i, h): (usize, u32),
        distribution: &mut Distribution,
    ) -> (f64, f64) {
        let live = solution.numbering();
        self.apply_at(None, (i, h), (live, distribution), |j| {
            solution.live_bounds(j)
        })
    }

    /// The backup of live state `h` (live index `i`) on both bounds, the bounds of its live
    /// successors given by live index (`bounds`; `live` numbers the live states): through the
    /// references of the member at `position` of a compiled component (`member`), else
    /// through its mask, else from the rules. The same sums and maxima, in the same order,
    /// whichever path (module documentation).
    #[inline(always)]
    pub(crate) fn apply_at(
        &self,
        member: Option<(&Compiled, usize)>,
        (i, h): (usize, u32),
        (live, distribution): (&Numbering, &mut Distribution),
        bounds: impl Fn(usize) -> [f64; 2],
    ) -> (f64, f64) {
        let model = self.model;
        let of_state = |t: u32| match live.get(t) {
            Some(j) => bounds(j),
            None => [model.absorbing_payoff(t); 2],
        };
        let mask = self.masks[i];
        if mask & RULES != 0 {
            return self.by_rules(h, of_state, distribution);
        }
        match member {
            Some((compiled, position)) => self.combine(h, mask, |f| {
                for &r in compiled.get(position) {
                    f(match r & ABSORBING {
                        0 => bounds(r as usize),
                        _ => [model.payoff_of_level((r & !ABSORBING) as u8); 2],
                    });
                }
            }),
            None => self.combine(h, mask, |f| {
                masked_edges(model.space(), h, mask, |t| f(of_state(t)));
            }),
        }
    }

    /// The Bellman update of live state `h` with edge mask `mask` (not [`RULES`]) from the
    /// bounds `successors` hands its argument, in edge order: a chance node's uniform sum, a
    /// decision node's discounted maximum with its `stop`.
    #[inline(always)]
    fn combine(
        &self,
        h: u32,
        mask: u16,
        successors: impl FnOnce(&mut dyn FnMut([f64; 2])),
    ) -> (f64, f64) {
        let (mut l, mut u) = (0.0f64, 0.0f64);
        if self.model.space().owner(h) == Owner::Adversary {
            let p = self.inverse[mask.count_ones() as usize];
            successors(&mut |[lt, ut]| {
                l += p * lt;
                u += p * ut;
            });
        } else {
            let g = self.g;
            successors(&mut |[lt, ut]| {
                l = l.max(g * lt);
                u = u.max(g * ut);
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
    fn by_rules(
        &self,
        h: u32,
        bounds: impl Fn(u32) -> [f64; 2],
        distribution: &mut Distribution,
    ) -> (f64, f64) {
        let model = self.model;
        match model.space().owner(h) {
            Owner::Adversary => {
                model.distribution(h, distribution);
                distribution.iter().fold((0.0, 0.0), |(l, u), (t, p)| {
                    let [lt, ut] = bounds(t);
                    (l + p * lt, u + p * ut)
                })
            }
            Owner::Robot => {
                let g = self.g;
                let (mut l, mut u) = (0.0f64, 0.0f64);
                model.choices(h, |choice| {
                    let (lc, uc) = match choice {
                        Choice::Move { target, .. } => {
                            let [lt, ut] = bounds(target);
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
