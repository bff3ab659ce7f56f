//! The robust policy, from the certified lower bounds `L`.
//!
//! With g < 1, a choice of largest robust Q-value at `L` in every decision state: since `L` is a
//! sub-fixed-point of the robust Bellman operator (value iteration from below gives one), the
//! discounted lower bound of the state reached is a submartingale whatever the adversary does,
//! and a run that is never absorbed makes infinitely many moves (a run kept among chance nodes
//! forever is kept in states worth 0), so the policy collects at least `L` from every state.
//!
//! With g = 1 many choices tie and a choice of largest value may let the adversary keep the run
//! in a loop forever (a value-optimal choice into a chance node that can send the run back).
//! The policy therefore plays, among the choices whose robust Q-value at `L` is at least `L` of
//! its state (*safe* choices, up to a relative `TIE_TOLERANCE`), one that makes progress in the
//! robust attractor of the positive payoffs over safe choices: the attractor's choice, through
//! which the state joined (a choice every admissible reply of the adversary sends into states
//! that joined earlier with positive probability). Every state of positive lower bound is in
//! that attractor (a state outside it, of largest lower bound, could only have got it from
//! another such state); so along a run the robot either reaches a positive payoff or reaches
//! states of lower bound 0, and the expected payoff is at least `L` against any adversary.
//! States outside the attractor (lower bound 0, or rounding) play a choice of largest value.
//! Ties between attractor choices go to the first that reaches the attractor, i.e. the one
//! closest to a payoff in the worst case.

use super::qualitative::{Incoming, attractor};
use super::{Intervals, choice_value};

use crate::mdp::model::{ChoiceId, Mdp, MdpState};
// The relative slack within which a choice's robust Q-value counts as reaching its state's lower
// bound at g = 1: the policy loses at most this fraction of the value per robot move.
use crate::mdp::solve::TIE_TOLERANCE;

pub(super) fn choose(
    mdp: &Mdp,
    intervals: &Intervals,
    g: f64,
    lower: &[f64],
    incoming: &Incoming,
    owners: &[MdpState],
) -> Vec<ChoiceId> {
    let q: Vec<f64> = mdp
        .all_choices()
        .map(|choice| choice_value(mdp, intervals, g, lower, choice))
        .collect();
    let mut policy: Vec<ChoiceId> = mdp
        .states()
        .map(|state| {
            let mut best = ChoiceId::NONE;
            for choice in mdp.choices(state) {
                if best.is_none() || q[choice.index()] > q[best.index()] {
                    best = choice;
                }
            }
            best
        })
        .collect();
    if g < 1.0 {
        return policy;
    }
    let safe = |choice: ChoiceId| {
        let own = lower[owners[choice.index()].index()];
        q[choice.index()] >= own - TIE_TOLERANCE * own.abs()
    };
    let targets = mdp
        .states()
        .filter(|&s| mdp.payoff(s).is_some_and(|payoff| payoff > 0.0));
    let (_, through) = attractor(mdp, intervals, incoming, owners, targets, safe);
    for state in mdp.states() {
        if !through[state.index()].is_none() {
            policy[state.index()] = through[state.index()];
        }
    }
    policy
}
