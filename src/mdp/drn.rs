//! Storm's explicit DRN format, so that Storm can recompute the values:
//! `storm --explicit-drn FILE --prop 'R{"r"}max=? [C]'` gives, for the state labelled `init`, the
//! value that [`solve`](super::solve()) computes for the initial state.
//!
//! Encoding (an MDP with `n` states becomes a DRN MDP with `n + 1`):
//! - states keep their numbers `0..n`; state `n` is an extra zero-reward *sink* with a self-loop;
//! - a decision state keeps its choices, in order, each as `action NAME [0]`;
//! - an absorbing state with payoff `p > 0` gets one action `collect [p]` to the sink, so its
//!   payoff is collected exactly once as an action reward of the reward model `r`; an absorbing
//!   state with payoff 0 gets a self-loop (Storm's `__NOLABEL__` action, reward 0);
//! - a discount `g < 1` is encoded exactly: every decision choice moves to its successors with
//!   `g` times their probability and to the sink with probability `1 − g`. Total reward then
//!   counts a payoff reached after `t` moves with weight `g^t`, as the solver does;
//! - labels: `init` on the initial state, `absorbing` on the absorbing states, `sink` on the sink;
//!   a state's display name, if any, is a `//` comment line just before it;
//! - `@nr_choices` is the number of actions written: the MDP's choices, plus one per absorbing
//!   state and one for the sink.
//!
//! Storm reads transitions as `TARGET : PROBABILITY` (one space either side of the colon), with
//! targets ascending within an action, which the model's invariants give (the sink is last).
//! Numbers are printed with Rust's shortest round-trip formatting, so they read back exactly.

use std::fmt::{self, Write};

use super::model::Mdp;
use super::solve::Discount;

/// The name of the reward model that holds the payoffs.
pub const REWARD_MODEL: &str = "r";

/// Writes `mdp` in DRN, with the discount encoded as described in the module documentation.
pub fn write_drn(mdp: &Mdp, discount: Discount) -> String {
    let mut out = String::new();
    write_model(&mut out, mdp, discount.get()).expect("formatting into a String does not fail");
    out
}

fn write_model(out: &mut impl Write, mdp: &Mdp, g: f64) -> fmt::Result {
    let n = mdp.num_states();
    let sink = n;
    let absorbing = (0..n).filter(|&s| mdp.is_absorbing(s)).count() as u64;
    writeln!(
        out,
        "// hypersynth MDP: R{{\"{REWARD_MODEL}\"}}max=? [C] is the maximal expected payoff"
    )?;
    if g < 1.0 {
        writeln!(
            out,
            "// discount {g}: each decision choice also moves to the sink (state {sink}) with probability {}",
            1.0 - g
        )?;
    }
    writeln!(out, "@type: MDP")?;
    writeln!(out, "@parameters")?;
    writeln!(out)?;
    writeln!(out, "@reward_models")?;
    writeln!(out, "{REWARD_MODEL}")?;
    writeln!(out, "@nr_states")?;
    writeln!(out, "{}", u64::from(n) + 1)?;
    writeln!(out, "@nr_choices")?;
    writeln!(out, "{}", u64::from(mdp.num_choices()) + absorbing + 1)?;
    writeln!(out, "@model")?;
    for state in 0..n {
        if let Some(name) = mdp.state_name(state) {
            writeln!(out, "// {name}")?;
        }
        write!(out, "state {state}")?;
        if state == mdp.initial() {
            write!(out, " init")?;
        }
        match mdp.payoff(state) {
            Some(payoff) => {
                writeln!(out, " absorbing")?;
                if payoff > 0.0 {
                    writeln!(out, "\taction collect [{payoff}]")?;
                    writeln!(out, "\t\t{sink} : 1")?;
                } else {
                    write_self_loop(out, state)?;
                }
            }
            None => {
                writeln!(out)?;
                for choice in mdp.choices(state) {
                    writeln!(out, "\taction {} [0]", mdp.action_name(choice))?;
                    for (target, probability) in mdp.successors(choice) {
                        writeln!(out, "\t\t{target} : {}", g * probability)?;
                    }
                    if g < 1.0 {
                        writeln!(out, "\t\t{sink} : {}", 1.0 - g)?;
                    }
                }
            }
        }
    }
    writeln!(out, "state {sink} sink")?;
    write_self_loop(out, sink)
}

fn write_self_loop(out: &mut impl Write, state: u32) -> fmt::Result {
    writeln!(out, "\taction __NOLABEL__ [0]")?;
    writeln!(out, "\t\t{state} : 1")
}
