//! The implicit engine's hypergame MDP as Storm's DRN (docs/formats.md): the stored MDP's
//! states, choices and numbers, computed from the [`Model`]'s rules state by state, so the file
//! is the explicit engine's byte for byte and nothing of it is held in memory but the line being
//! written.
//!
//! MDP states `0..n` are the product states (the same numbers), then the stop sinks in order;
//! a chance node has one instant choice `adversary`, its adversary's moves of positive
//! probability merged and normalised as the stored build does it ([`merge`]); a decision node
//! its [`Model::choices`] (a move to its successor, `stop` to its sink), or the policy's one
//! choice for the Markov chain it induces.

use std::fmt;

use super::mdp::{Choice, Distribution, Kind, Model};
use super::moves::Moves;
use super::policy::Policy;
use crate::mdp::MdpState;
use crate::mdp::drn::{ChoiceWriter, DrnModel};
use crate::mdp::model::merge;
use crate::opportunistic::build::{CHANCE, STOP};

/// A solved [`Model`] as the DRN writer ([`crate::mdp::drn::write_model`]) reads it: the whole
/// MDP, or with a policy the Markov chain it induces.
pub struct Drn<'a, 'b, 'm, M> {
    model: &'a Model<'b, 'm, M>,
    policy: Option<&'a Policy>,
}

impl<'a, 'b, 'm, M: Moves> Drn<'a, 'b, 'm, M> {
    /// The MDP of `model`, or with `policy` only the choices it makes.
    pub fn new(model: &'a Model<'b, 'm, M>, policy: Option<&'a Policy>) -> Self {
        Drn { model, policy }
    }

    fn num_product_states(&self) -> u32 {
        self.model.space().num_states() as u32
    }
}

impl<M: Moves> DrnModel for Drn<'_, '_, '_, M> {
    fn num_states(&self) -> usize {
        self.model.space().num_states() + self.model.sinks().len()
    }

    fn initial(&self) -> u32 {
        self.model.space().initial()
    }

    fn payoff(&self, state: u32) -> Option<f64> {
        let n = self.num_product_states();
        if state >= n {
            return Some(self.model.sinks()[(state - n) as usize].payoff);
        }
        match self.model.kind(state) {
            Kind::Absorbing(payoff) => Some(payoff),
            Kind::Chance | Kind::Decision => None,
        }
    }

    fn choices(&self, state: u32, f: &mut ChoiceWriter<'_>) -> fmt::Result {
        let model = self.model;
        if model.kind(state) == Kind::Chance {
            let mut distribution = Distribution::default();
            model.distribution(state, &mut distribution);
            let moves: Vec<(MdpState, f64)> = distribution
                .iter()
                .map(|(t, p)| (MdpState::from_u32(t), p))
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
                    f(name, true, &[(target, [1.0, 1.0])])?;
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
            true => self.model.space().name(state),
            false => self.model.sinks()[(state - n) as usize].name.clone(),
        })
    }

    fn is_chain(&self) -> bool {
        self.policy.is_some()
    }
}
