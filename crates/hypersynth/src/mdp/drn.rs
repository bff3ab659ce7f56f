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
//! - a discount `g < 1` is encoded exactly: every *move* moves to its successors with `g` times
//!   their probability and to the sink with probability `1 − g`; instant choices (chance nodes,
//!   `stop`) keep their probabilities. Total reward then counts a payoff reached after `t` moves
//!   with weight `g^t`, as the solver does;
//! - labels: `init` on the initial state, `absorbing` on the absorbing states, `sink` on the sink;
//!   a state's display name, if any, is a `//` comment line just before it;
//! - `@nr_choices` is the number of actions written: the MDP's choices, plus one per absorbing
//!   state and one for the sink.
//!
//! Storm reads transitions as `TARGET : PROBABILITY` (one space either side of the colon), with
//! targets ascending within an action, which the model's invariants give (the sink is last).
//! Numbers are printed with Rust's shortest round-trip formatting, so they read back exactly.

use std::fmt::{self, Write};

use super::model::{ChoiceId, Mdp, MdpState};
use super::solve::Discount;

/// The name of the reward model that holds the payoffs.
pub const REWARD_MODEL: &str = "r";

/// Writes `mdp` in DRN, with the discount encoded as described in the module documentation;
/// `name` gives a state's display name, written as a comment line before it (control
/// characters escaped, so that a name stays on its line).
pub fn write_drn(
    mdp: &Mdp,
    discount: Discount,
    name: impl Fn(MdpState) -> Option<String>,
) -> String {
    let mut out = String::new();
    write_model(&mut out, mdp, discount.get(), &name, None)
        .expect("formatting into a String does not fail");
    out
}

/// [`write_drn`] with only the choices `keep` accepts, one per decision state: the Markov chain
/// a policy induces, so that Storm's `R{"r"}max=? [C]` is the policy's own expected payoff.
/// Every decision state must keep exactly one choice.
pub fn write_induced_drn(
    mdp: &Mdp,
    discount: Discount,
    name: impl Fn(MdpState) -> Option<String>,
    keep: impl Fn(ChoiceId) -> bool,
) -> String {
    let mut out = String::new();
    write_model(&mut out, mdp, discount.get(), &name, Some(&keep))
        .expect("formatting into a String does not fail");
    out
}

fn write_model(
    out: &mut impl Write,
    mdp: &Mdp,
    g: f64,
    name: &dyn Fn(MdpState) -> Option<String>,
    keep: Option<&dyn Fn(ChoiceId) -> bool>,
) -> fmt::Result {
    let kept = |choice: ChoiceId| keep.is_none_or(|keep| keep(choice));
    let n = mdp.num_states();
    // The DRN model's extra state, after the MDP's.
    let sink = n;
    let absorbing = mdp.states().filter(|&s| mdp.is_absorbing(s)).count();
    match keep {
        None => writeln!(
            out,
            "// hypersynth MDP: R{{\"{REWARD_MODEL}\"}}max=? [C] is the maximal expected payoff"
        )?,
        Some(_) => writeln!(
            out,
            "// hypersynth MDP, the controller's choices only: R{{\"{REWARD_MODEL}\"}}max=? [C] \
             is its expected payoff"
        )?,
    }
    if g < 1.0 {
        writeln!(
            out,
            "// discount {g}: each move also goes to the sink (state {sink}) with probability {}",
            1.0 - g
        )?;
    }
    writeln!(out, "@type: MDP")?;
    writeln!(out, "@parameters")?;
    writeln!(out)?;
    writeln!(out, "@reward_models")?;
    writeln!(out, "{REWARD_MODEL}")?;
    writeln!(out, "@nr_states")?;
    writeln!(out, "{}", n + 1)?;
    writeln!(out, "@nr_choices")?;
    let choices = mdp.all_choices().filter(|&c| kept(c)).count();
    writeln!(out, "{}", choices + absorbing + 1)?;
    writeln!(out, "@model")?;
    for state in mdp.states() {
        if let Some(name) = name(state) {
            write!(out, "// ")?;
            for c in name.chars() {
                if c.is_control() {
                    write!(out, "{}", c.escape_default())?;
                } else {
                    out.write_char(c)?;
                }
            }
            writeln!(out)?;
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
                for choice in mdp.choices(state).filter(|&c| kept(c)) {
                    writeln!(out, "\taction {} [0]", Token(mdp.action_name(choice)))?;
                    let factor = mdp.discount_factor(choice, g);
                    for (target, probability) in mdp.successors(choice) {
                        writeln!(out, "\t\t{target} : {}", factor * probability)?;
                    }
                    if factor < 1.0 {
                        writeln!(out, "\t\t{sink} : {}", 1.0 - factor)?;
                    }
                }
            }
        }
    }
    writeln!(out, "state {sink} sink")?;
    write_self_loop(out, sink)
}

/// An action name as one DRN token: white space and control characters escaped as `\u{..}`.
struct Token<'a>(&'a str);

impl fmt::Display for Token<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for c in self.0.chars() {
            if c.is_whitespace() || c.is_control() {
                write!(f, "{}", c.escape_unicode())?;
            } else {
                f.write_char(c)?;
            }
        }
        Ok(())
    }
}

fn write_self_loop(out: &mut impl Write, state: impl fmt::Display) -> fmt::Result {
    writeln!(out, "\taction __NOLABEL__ [0]")?;
    writeln!(out, "\t\t{state} : 1")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::model::MdpBuilder;
    use crate::mdp::solve::{SolveOptions, solve};
    use crate::mdp::testing::{ms, random_mdp, rng};

    #[test]
    fn small_mdp_is_written_as_storm_expects() {
        let mut builder = MdpBuilder::new();
        let [north, stop, east] = ["N", "stop", "E"].map(|name| builder.action(name).unwrap());
        builder.add_decision_state().unwrap();
        builder
            .add_choice(north, &[(ms(2), 0.5), (ms(1), 0.5)])
            .unwrap();
        builder.add_instant_choice(stop, &[(ms(3), 1.0)]).unwrap();
        builder.add_decision_state().unwrap();
        builder.add_choice(east, &[(ms(1), 1.0)]).unwrap();
        builder.add_absorbing_state(0.0).unwrap();
        builder.add_absorbing_state(200.0).unwrap();
        builder.set_initial(ms(0));
        let mdp = builder.build().unwrap();
        // g = 0.5 keeps every product exact: 0.5 · 0.5 = 0.25, and 1 − g = 0.5 to the sink 4.
        // 3 choices + 2 absorbing states + the sink = 6 actions.
        let expected = "\
// hypersynth MDP: R{\"r\"}max=? [C] is the maximal expected payoff
// discount 0.5: each move also goes to the sink (state 4) with probability 0.5
@type: MDP
@parameters

@reward_models
r
@nr_states
5
@nr_choices
6
@model
// h0 (W, L, L)
state 0 init
\taction N [0]
\t\t1 : 0.25
\t\t2 : 0.25
\t\t4 : 0.5
\taction stop [0]
\t\t3 : 1
state 1
\taction E [0]
\t\t1 : 0.5
\t\t4 : 0.5
state 2 absorbing
\taction __NOLABEL__ [0]
\t\t2 : 1
state 3 absorbing
\taction collect [200]
\t\t4 : 1
state 4 sink
\taction __NOLABEL__ [0]
\t\t4 : 1
";
        assert_eq!(
            write_drn(&mdp, Discount::new(0.5).unwrap(), |s| {
                (s == ms(0)).then(|| "h0 (W, L, L)".to_string())
            }),
            expected
        );
        // Undiscounted: no sink transitions on decision choices, probabilities as given.
        let undiscounted = write_drn(&mdp, Discount::NONE, |_| None);
        assert!(undiscounted.contains(
            "state 0 init\n\taction N [0]\n\t\t1 : 0.5\n\t\t2 : 0.5\n\taction stop [0]\n\t\t3 : 1\n"
        ));
        assert!(!undiscounted.contains("// discount"));
    }

    /// A DRN MDP as Storm's parser reads it: per state its labels and actions.
    struct Drn {
        states: Vec<DrnState>,
    }

    struct DrnState {
        labels: Vec<String>,
        actions: Vec<DrnAction>,
    }

    struct DrnAction {
        reward: f64,
        transitions: Vec<(usize, f64)>,
    }

    /// Parses the subset of DRN that `write_drn` promises, asserting its structural rules: the
    /// header, consecutive state ids, `@nr_states` and `@nr_choices` matching, one reward per
    /// action (the model `r`), `TARGET : PROBABILITY` with targets ascending and in range,
    /// probabilities summing to 1, exactly one `init` state, every state with an action.
    fn parse_drn(text: &str) -> Drn {
        let lines: Vec<&str> = text
            .lines()
            .filter(|line| !line.starts_with("//"))
            .collect();
        let header = [
            "@type: MDP",
            "@parameters",
            "",
            "@reward_models",
            REWARD_MODEL,
            "@nr_states",
        ];
        assert_eq!(lines[..6], header);
        let nr_states: usize = lines[6].parse().unwrap();
        assert_eq!(lines[7], "@nr_choices");
        let nr_choices: usize = lines[8].parse().unwrap();
        assert_eq!(lines[9], "@model");
        let mut states: Vec<DrnState> = Vec::new();
        for line in &lines[10..] {
            if let Some(rest) = line.strip_prefix("state ") {
                let mut words = rest.split(' ');
                assert_eq!(
                    words.next().unwrap().parse::<usize>().unwrap(),
                    states.len()
                );
                let labels = words.map(str::to_owned).collect();
                states.push(DrnState {
                    labels,
                    actions: Vec::new(),
                });
            } else if let Some(rest) = line.strip_prefix("\taction ") {
                let (name, reward) = rest.split_once(' ').unwrap();
                assert!(!name.is_empty());
                let reward = reward.strip_prefix('[').unwrap().strip_suffix(']').unwrap();
                let reward: f64 = reward.parse().unwrap();
                assert!(reward >= 0.0);
                let actions = &mut states.last_mut().unwrap().actions;
                actions.push(DrnAction {
                    reward,
                    transitions: Vec::new(),
                });
            } else {
                let (target, probability) = line
                    .strip_prefix("\t\t")
                    .unwrap()
                    .split_once(" : ")
                    .unwrap();
                let state = states.last_mut().unwrap();
                let action = state.actions.last_mut().unwrap();
                action
                    .transitions
                    .push((target.parse().unwrap(), probability.parse().unwrap()));
            }
        }
        assert_eq!(states.len(), nr_states);
        assert_eq!(
            states.iter().map(|s| s.actions.len()).sum::<usize>(),
            nr_choices
        );
        let initial = states
            .iter()
            .filter(|s| s.labels.iter().any(|l| l == "init"));
        assert_eq!(initial.count(), 1);
        for state in &states {
            assert!(!state.actions.is_empty());
            for action in &state.actions {
                let targets: Vec<usize> = action.transitions.iter().map(|&(t, _)| t).collect();
                assert!(
                    targets.windows(2).all(|w| w[0] < w[1])
                        && targets.iter().all(|&t| t < nr_states)
                );
                assert!(action.transitions.iter().all(|&(_, p)| p > 0.0 && p <= 1.0));
                let sum: f64 = action.transitions.iter().map(|&(_, p)| p).sum();
                assert!((sum - 1.0).abs() < 1e-12, "{sum}");
            }
        }
        Drn { states }
    }

    /// Storm's `R{"r"}max=? [C]` by plain value iteration from 0, which converges from below to
    /// the maximal total reward when rewards are ≥ 0.
    fn max_total_reward(drn: &Drn) -> Vec<f64> {
        let mut values = vec![0.0; drn.states.len()];
        for _ in 0..100_000 {
            let next: Vec<f64> = drn
                .states
                .iter()
                .map(|state| {
                    state
                        .actions
                        .iter()
                        .map(|a| {
                            a.reward
                                + a.transitions
                                    .iter()
                                    .map(|&(t, p)| p * values[t])
                                    .sum::<f64>()
                        })
                        .fold(0.0, f64::max)
                })
                .collect();
            let change = next
                .iter()
                .zip(&values)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            values = next;
            if change < 1e-13 {
                break;
            }
        }
        values
    }

    #[test]
    fn total_reward_of_the_written_drn_equals_the_solved_values() {
        let mut rng = rng(11);
        for instance in 0..100 {
            let mdp = random_mdp(&mut rng, 8);
            let discount = Discount::new(if instance % 2 == 0 { 1.0 } else { 0.9 }).unwrap();
            let drn = parse_drn(&write_drn(&mdp, discount, |_| None));
            let n = mdp.num_states();
            assert_eq!(drn.states.len(), n + 1);
            assert!(
                drn.states[mdp.initial().index()]
                    .labels
                    .contains(&"init".to_owned())
            );
            for state in mdp.states() {
                let absorbing = drn.states[state.index()]
                    .labels
                    .contains(&"absorbing".to_owned());
                assert_eq!(absorbing, mdp.is_absorbing(state));
            }
            let options = SolveOptions {
                discount,
                ..SolveOptions::default()
            };
            let solution = solve(&mdp, &options).unwrap();
            let total = max_total_reward(&drn);
            for state in mdp.states() {
                let value = solution.value(state);
                assert!(
                    value.lower - 1e-9 <= total[state.index()]
                        && total[state.index()] <= value.upper + 1e-9,
                    "instance {instance}, state {state}: DRN {} vs [{}, {}]",
                    total[state.index()],
                    value.lower,
                    value.upper
                );
            }
            assert_eq!(total[n], 0.0);
        }
    }
}
