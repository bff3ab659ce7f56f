//! The implicit engine's hypergame MDP as Storm's DRN (docs/formats.md): the stored MDP's
//! states, choices and numbers, computed from the [`Model`]'s rules state by state, so the file
//! is the explicit engine's byte for byte and nothing of it is held in memory but the line being
//! written.
//!
//! MDP states `0..n` are the product states (the same numbers; with the reachable
//! enumeration, the reachable states numbered in the explicit engine's order, breadth-first
//! from `h0`, which takes two numbers per reachable state and a bit per index while the file is
//! written: [`Drn::bytes`]), then the stop sinks in order;
//! a chance node has one instant choice `adversary`, its adversary's moves of positive
//! probability merged and normalised as the stored build does it ([`merge`]); a decision node
//! its [`Model::choices`] (a move to its successor, `stop` to its sink), or the policy's one
//! choice for the Markov chain it induces.

use std::fmt;

use super::mdp::{Choice, Distribution, Kind, Model};
use super::moves::Moves;
use super::numbering::Numbering;
use super::policy::Policy;
use super::robust::Intervals;
use super::space::Space;
use crate::game::States;
use crate::mdp::MdpState;
use crate::mdp::drn::{ChoiceWriter, DrnModel};
use crate::mdp::model::merge;
use crate::opportunistic::build::{CHANCE, STOP};

/// A solved [`Model`] as the DRN writer ([`crate::mdp::drn::write_model`]) reads it: the whole
/// MDP, or with a policy the Markov chain it induces.
pub struct Drn<'a, 'b, 'm, M> {
    model: &'a Model<'b, 'm, M>,
    policy: Option<&'a Policy>,
    /// sigma_L's intervals, for the interval MDP of the robust stage.
    intervals: Option<&'a Intervals>,
    /// With the reachable enumeration, the product states by number and their numbers.
    renumbered: Option<Renumbering>,
}

/// The reachable states' numbers: by number its index, by index (dense among the reachable
/// ones) its number.
struct Renumbering {
    index: Vec<u32>,
    reachable: Numbering,
    number: Vec<u32>,
}

impl<'a, 'b, 'm, M: Moves> Drn<'a, 'b, 'm, M> {
    /// The MDP of `model`, or with `policy` only the choices it makes.
    pub fn new(model: &'a Model<'b, 'm, M>, policy: Option<&'a Policy>) -> Self {
        let space = model.space();
        let renumbered = (space.enumeration() == States::Reachable).then(|| {
            let mut index = Vec::with_capacity(space.num_enumerated());
            space.for_each_state(|h| index.push(h));
            let reachable = Numbering::new(index.iter().map(|&h| h as usize).collect());
            let mut number = vec![0; index.len()];
            for (i, &h) in index.iter().enumerate() {
                number[reachable.index(h)] = i as u32;
            }
            Renumbering {
                index,
                reachable,
                number,
            }
        });
        Drn {
            model,
            policy,
            intervals: None,
            renumbered,
        }
    }

    /// The interval MDP of this one's model (built with sigma_L's full support) against
    /// `intervals`: each chance node where sigma_L rules has, per successor, the sum of its
    /// edges' intervals, the upper bound cut at 1, as the explicit robust stage's model has
    /// them (written whole, not a policy's chain).
    pub fn with_intervals(self, intervals: &'a Intervals) -> Self {
        Drn {
            intervals: Some(intervals),
            policy: None,
            ..self
        }
    }

    /// About the bytes [`Drn::new`] holds for the product `space`: none for the full
    /// enumeration, for the reachable one eight per reachable state and a bit and a half per
    /// index.
    pub fn bytes(space: &Space<'_, M>) -> u64 {
        match space.enumeration() {
            States::Full => 0,
            States::Reachable => {
                8 * space.num_enumerated() as u64 + (space.num_states() as u64).div_ceil(32) * 6
            }
        }
    }

    /// The number of product states in the file.
    fn num_product_states(&self) -> u32 {
        self.model.space().num_enumerated() as u32
    }

    /// The product state numbered `state`.
    fn index(&self, state: u32) -> u32 {
        self.renumbered
            .as_ref()
            .map_or(state, |r| r.index[state as usize])
    }

    /// The number of product state `h`.
    fn number(&self, h: u32) -> u32 {
        self.renumbered
            .as_ref()
            .map_or(h, |r| r.number[r.reachable.index(h)])
    }
}

impl<M: Moves> DrnModel for Drn<'_, '_, '_, M> {
    fn num_states(&self) -> usize {
        self.num_product_states() as usize + self.model.sinks().len()
    }

    fn initial(&self) -> u32 {
        self.number(self.model.space().initial())
    }

    fn payoff(&self, state: u32) -> Option<f64> {
        let n = self.num_product_states();
        if state >= n {
            return Some(self.model.sinks()[(state - n) as usize].payoff);
        }
        match self.model.kind(self.index(state)) {
            Kind::Absorbing(payoff) => Some(payoff),
            Kind::Chance | Kind::Decision => None,
        }
    }

    fn choices(&self, state: u32, f: &mut ChoiceWriter<'_>) -> fmt::Result {
        let model = self.model;
        let state = self.index(state);
        if model.kind(state) == Kind::Chance
            && let Some(intervals) = self.intervals.filter(|_| !model.plays_sigma_w(state))
        {
            let space = model.space();
            let mut row = Vec::new();
            intervals.row(
                space.arena_state(state),
                space.degree(state) as usize,
                &mut row,
            );
            let mut successors: Vec<(u32, [f64; 2])> = Vec::with_capacity(row.len());
            let mut k = 0;
            space.edges(state, |_, t| {
                successors.push((self.number(t), row[k]));
                k += 1;
            });
            successors.sort_by_key(|&(t, _)| t);
            successors.dedup_by(|(t, b), (first, sum)| {
                let same = t == first;
                if same {
                    sum[0] += b[0];
                    sum[1] += b[1];
                }
                same
            });
            for (_, [lower, upper]) in &mut successors {
                *upper = upper.min(1.0);
                *lower = lower.min(*upper);
            }
            return f(CHANCE, false, &successors);
        }
        if model.kind(state) == Kind::Chance {
            let mut distribution = Distribution::default();
            model.distribution(state, &mut distribution);
            let moves: Vec<(MdpState, f64)> = distribution
                .iter()
                .map(|(t, p)| (MdpState::from_u32(self.number(t)), p))
                .collect();
            let mut merged = Vec::new();
            merge(&moves, &mut merged);
            let successors: Vec<_> = merged.iter().map(|&(t, p)| (t.as_u32(), [p, p])).collect();
            return f(CHANCE, false, &successors);
        }
        let mut choices = Vec::new();
        model.choices(state, |choice| choices.push(choice));
        let chosen = self.policy.map(|policy| policy.mdp_choice(state));
        for (i, choice) in choices.into_iter().enumerate() {
            if chosen.is_some_and(|c| c != Some(i as u8)) {
                continue;
            }
            match choice {
                Choice::Move { action, target } => {
                    let name = &model.space().moves().actions()[action as usize];
                    f(name, true, &[(self.number(target), [1.0, 1.0])])?;
                }
                Choice::Stop { .. } => {
                    let sink = self.num_product_states() + model.stop_sink(state) as u32;
                    f(STOP, false, &[(sink, [1.0, 1.0])])?;
                }
            }
        }
        Ok(())
    }

    fn name(&self, state: u32) -> Option<String> {
        let n = self.num_product_states();
        Some(match state < n {
            true => self.model.space().name(self.index(state)),
            false => self.model.sinks()[(state - n) as usize].name.clone(),
        })
    }

    fn is_chain(&self) -> bool {
        self.policy.is_some()
    }

    fn is_interval(&self) -> bool {
        self.intervals.is_some()
    }
}
