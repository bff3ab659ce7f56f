//! Storm's explicit DRN format, so that Storm can recompute the values, in one of two
//! [`DrnForm`]s. In *reward form* `storm --explicit-drn FILE --prop 'R{"r"}max=? [C]'` gives, for
//! the state labelled `init`, the value that [`solve`](super::solve()) computes for the initial
//! state; in *reachability form* `r_max · Pmax=? [F "goal"]` does (`r_max` the largest payoff,
//! written in the file's first comment line). An interval MDP ([`write_interval_drn`]) is
//! written in either form with `@value_type: double-interval`; Storm 2.0 reads both, but its
//! interval checker takes reachability and refuses total-reward formulas, so only the
//! reachability form of an interval MDP can be checked by Storm (`uncertainty_resolution_mode`
//! `ROBUST` for the robust value).
//!
//! Encoding of an MDP with `n` states; states keep their numbers `0..n`:
//! - *reward form* (`n + 1` states): state `n` is an extra zero-reward *sink* with a self-loop;
//!   an absorbing state with payoff `p > 0` gets one action `collect [p]` to the sink, so its
//!   payoff is collected exactly once as an action reward of the reward model `r`; every other
//!   action has reward 0;
//! - *reachability form* (`n + 2` states): state `n` is `goal`, state `n + 1` is `fail`, both
//!   with self-loops; an absorbing state with payoff `p > 0` gets one action `collect` that
//!   moves to `goal` with probability `p / r_max` and to `fail` otherwise, so that the
//!   probability of reaching `goal`, times `r_max`, is the expected payoff; no reward model;
//! - in both forms: an absorbing state with payoff 0 gets a self-loop (Storm's `__NOLABEL__`
//!   action); a decision state keeps its choices, in order, each as `action NAME`; a discount
//!   `g < 1` is encoded exactly: every *move* goes to its successors with `g` times their
//!   probability and to the sink (reward form) or to `fail` (reachability form) with
//!   probability `1 − g`; instant choices (chance nodes, `stop`) keep their probabilities. A
//!   payoff reached after `t` moves then counts with weight `g^t`, as the solver does;
//! - with intervals, an interval choice's successors get their intervals scaled by the
//!   discount factor (exactly the distributions `g · q + (1 − g) · sink` for `q` within the
//!   intervals), and every other probability `p` is written `[p,p]`; intervals are written
//!   `[l,u]` without a space, as Storm's reader needs;
//! - labels: `init` on the initial state, `absorbing` on the absorbing states, `sink` on the
//!   sink, `goal` and `fail` on the reachability form's two; a state's display name, if any,
//!   is a `//` comment line just before it;
//! - `@nr_choices` is the number of actions written: the MDP's choices (those kept), plus one
//!   per absorbing state and one per extra state.
//!
//! Storm reads transitions as `TARGET : PROBABILITY` (one space either side of the colon), with
//! targets ascending within an action, which the model's invariants give (the extra states are
//! last). Numbers are printed with Rust's shortest round-trip formatting, so they read back
//! exactly.
//!
//! **Invariant:** both forms of every writer have the same value at every state of the model
//! (tested by naive value iteration on the written text, on random nominal and interval models).

use std::fmt::{self, Write};

use super::model::{ChoiceId, Mdp, MdpState};
use super::robust::Intervals;
use super::solve::Discount;

/// The name of the reward model that holds the payoffs (reward form).
pub const REWARD_MODEL: &str = "r";

/// The label of the reachability form's target state.
pub const GOAL_LABEL: &str = "goal";

/// How a written model encodes the payoffs, that is which property of Storm gives its value
/// (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DrnForm {
    /// Payoffs as action rewards of the reward model `r`: `R{"r"}max=? [C]` is the value.
    #[default]
    Reward,
    /// Payoffs as probabilities of reaching the state labelled `goal`: `r_max · Pmax=? [F
    /// "goal"]` is the value, `r_max` the largest payoff.
    Reachability,
}

/// Writes `mdp` in DRN in `form`, with the discount encoded as described in the module
/// documentation; `name` gives a state's display name, written as a comment line before it
/// (control characters escaped, so that a name stays on its line).
pub fn write_drn(
    mdp: &Mdp,
    discount: Discount,
    form: DrnForm,
    name: impl Fn(MdpState) -> Option<String>,
) -> String {
    let model = Model {
        mdp,
        intervals: None,
        keep: None,
        name: &name,
    };
    write(&model, discount.get(), form)
}

/// [`write_drn`] with only the choices `keep` accepts, one per decision state: the Markov chain
/// a policy induces, so that Storm's value of it (`R{"r"}max=? [C]`, or `r_max · Pmax=? [F
/// "goal"]`) is the policy's own expected payoff. Every decision state must keep exactly one
/// choice.
pub fn write_induced_drn(
    mdp: &Mdp,
    discount: Discount,
    form: DrnForm,
    name: impl Fn(MdpState) -> Option<String>,
    keep: impl Fn(ChoiceId) -> bool,
) -> String {
    let model = Model {
        mdp,
        intervals: None,
        keep: Some(&keep),
        name: &name,
    };
    write(&model, discount.get(), form)
}

/// Writes `mdp` with `intervals` as an interval MDP (`@value_type: double-interval`) in `form`:
/// the robust value of the initial state (the adversary resolving the intervals against the
/// robot) is `R{"r"}max=? [C]` in reward form and `r_max · Pmax=? [F "goal"]` in reachability
/// form, the one Storm 2.0's interval checker takes (`uncertainty_resolution_mode=ROBUST`).
pub fn write_interval_drn(
    mdp: &Mdp,
    intervals: &Intervals,
    discount: Discount,
    form: DrnForm,
    name: impl Fn(MdpState) -> Option<String>,
) -> String {
    let model = Model {
        mdp,
        intervals: Some(intervals),
        keep: None,
        name: &name,
    };
    write(&model, discount.get(), form)
}

/// What [`DrnModel::choices`] calls per choice: its action's name, whether it is a move, its
/// successors with their bounds.
pub type ChoiceWriter<'f> = dyn FnMut(&str, bool, &[(u32, [f64; 2])]) -> fmt::Result + 'f;

/// What the DRN writer reads of a model, whichever engine holds it: states `0..num_states()`,
/// each absorbing with its payoff or with its choices (those written), each choice with its
/// action's name, whether it is a move (discounted) or instant, and its successors, targets
/// ascending and distinct, with their probabilities as bounds (`[p, p]` but in an interval
/// MDP).
pub trait DrnModel {
    /// The number of states.
    fn num_states(&self) -> usize;
    /// The initial state.
    fn initial(&self) -> u32;
    /// The payoff of `state` if it is absorbing.
    fn payoff(&self, state: u32) -> Option<f64>;
    /// Calls `f(name, is_move, successors)` for each choice of non-absorbing `state` that is
    /// written, in order; stops at the first error `f` returns.
    fn choices(&self, state: u32, f: &mut ChoiceWriter<'_>) -> fmt::Result;
    /// The display name of `state`, if any.
    fn name(&self, state: u32) -> Option<String>;
    /// Whether the probabilities are intervals (an interval MDP).
    fn is_interval(&self) -> bool {
        false
    }
    /// Whether each decision state has one choice written, a policy's (its Markov chain).
    fn is_chain(&self) -> bool {
        false
    }
}

/// An explicit [`Mdp`] as the writer reads it: its intervals (an interval MDP) and the choices
/// kept (a policy's chain).
struct Model<'a> {
    mdp: &'a Mdp,
    intervals: Option<&'a Intervals>,
    keep: Option<&'a dyn Fn(ChoiceId) -> bool>,
    name: &'a dyn Fn(MdpState) -> Option<String>,
}

impl DrnModel for Model<'_> {
    fn num_states(&self) -> usize {
        self.mdp.num_states()
    }
    fn initial(&self) -> u32 {
        self.mdp.initial().as_u32()
    }
    fn payoff(&self, state: u32) -> Option<f64> {
        self.mdp.payoff(MdpState::from_u32(state))
    }
    fn choices(&self, state: u32, f: &mut ChoiceWriter<'_>) -> fmt::Result {
        let mdp = self.mdp;
        let mut successors = Vec::new();
        let kept = |choice: ChoiceId| self.keep.is_none_or(|keep| keep(choice));
        for choice in mdp.choices(MdpState::from_u32(state)).filter(|&c| kept(c)) {
            let bounds = self.intervals.and_then(|i| i.get(mdp, choice));
            successors.clear();
            successors.extend(
                mdp.successors(choice)
                    .enumerate()
                    .map(|(i, (t, p))| (t.as_u32(), bounds.map_or([p, p], |b| b[i]))),
            );
            f(
                mdp.action_name(choice),
                !mdp.is_instant(choice),
                &successors,
            )?;
        }
        Ok(())
    }
    fn name(&self, state: u32) -> Option<String> {
        (self.name)(MdpState::from_u32(state))
    }
    fn is_interval(&self) -> bool {
        self.intervals.is_some()
    }
    fn is_chain(&self) -> bool {
        self.keep.is_some()
    }
}

fn write(model: &Model, g: f64, form: DrnForm) -> String {
    let mut out = String::new();
    write_model(&mut out, model, g, form).expect("formatting into a String does not fail");
    out
}

/// Writes `model` in DRN in `form` at discount `g` (the module documentation): what
/// [`write_drn`] and its variants write of an explicit [`Mdp`], for any [`DrnModel`]. It reads
/// the model twice: once for the header's counts, once to write it.
pub fn write_model(
    out: &mut impl Write,
    model: &impl DrnModel,
    g: f64,
    form: DrnForm,
) -> fmt::Result {
    let number = Number {
        interval: model.is_interval(),
    };
    let n = model.num_states();
    let reward = form == DrnForm::Reward;
    // The extra states, after the MDP's: the sink (reward form), or goal and fail; `fail`
    // takes the discount's `1 − g` in both forms.
    let (goal, fail) = (n, if reward { n } else { n + 1 });
    let (mut top, mut absorbing, mut choices) = (0.0f64, 0usize, 0usize);
    for state in 0..n as u32 {
        match model.payoff(state) {
            Some(payoff) => {
                top = top.max(payoff);
                absorbing += 1;
            }
            None => model.choices(state, &mut |_, _, _| {
                choices += 1;
                Ok(())
            })?,
        }
    }
    let scale = if top > 0.0 { top } else { 1.0 };
    let interval = model.is_interval();
    let (what, value) = match (interval, model.is_chain()) {
        (true, _) => ("interval MDP", "(robust) is the value"),
        (false, false) => ("MDP", "is the maximal expected payoff"),
        (false, true) => (
            "MDP, the controller's choices only",
            "is its expected payoff",
        ),
    };
    match form {
        DrnForm::Reward => {
            let refused = if interval {
                " (Storm 2.0's interval checker refuses total-reward formulas: write the \
                 reachability form to check it)"
            } else {
                ""
            };
            writeln!(
                out,
                "// hypersynth {what}: R{{\"{REWARD_MODEL}\"}}max=? [C] {value}{refused}"
            )?;
        }
        DrnForm::Reachability => writeln!(
            out,
            "// hypersynth {what}, reachability form: {scale} * Pmax=? [F \"{GOAL_LABEL}\"] {value}"
        )?,
    }
    if g < 1.0 {
        let extra = if reward { "sink" } else { "fail" };
        writeln!(
            out,
            "// discount {g}: each move also goes to the {extra} (state {fail}) with probability {}",
            1.0 - g
        )?;
    }
    writeln!(out, "@type: MDP")?;
    if interval {
        writeln!(out, "@value_type: double-interval")?;
    }
    writeln!(out, "@parameters")?;
    writeln!(out)?;
    writeln!(out, "@reward_models")?;
    writeln!(out, "{}", if reward { REWARD_MODEL } else { "" })?;
    writeln!(out, "@nr_states")?;
    let extra = if reward { 1 } else { 2 };
    writeln!(out, "{}", n + extra)?;
    writeln!(out, "@nr_choices")?;
    writeln!(out, "{}", choices + absorbing + extra)?;
    writeln!(out, "@model")?;
    // An action's header: its name, and its reward in reward form.
    let action = |out: &mut dyn Write, name: &str, payoff: f64| {
        write!(out, "\taction {}", Token(name))?;
        if reward {
            write!(out, " [{payoff}]")?;
        }
        writeln!(out)
    };
    let initial = model.initial();
    for state in 0..n as u32 {
        write_name(out, model.name(state))?;
        write!(out, "state {state}")?;
        if state == initial {
            write!(out, " init")?;
        }
        match model.payoff(state) {
            Some(payoff) => {
                writeln!(out, " absorbing")?;
                if payoff > 0.0 && reward {
                    action(out, "collect", payoff)?;
                    writeln!(out, "\t\t{fail} : {}", number.point(1.0))?;
                } else if payoff > 0.0 {
                    let p = payoff / scale;
                    action(out, "collect", 0.0)?;
                    writeln!(out, "\t\t{goal} : {}", number.point(p))?;
                    if p < 1.0 {
                        writeln!(out, "\t\t{fail} : {}", number.point(1.0 - p))?;
                    }
                } else {
                    write_self_loop(out, state, reward, number)?;
                }
            }
            None => {
                writeln!(out)?;
                model.choices(state, &mut |name, is_move, successors| {
                    action(out, name, 0.0)?;
                    let f = if is_move { g } else { 1.0 };
                    for &(target, [l, u]) in successors {
                        writeln!(out, "\t\t{target} : {}", number.bounds([f * l, f * u]))?;
                    }
                    if f < 1.0 {
                        writeln!(out, "\t\t{fail} : {}", number.point(1.0 - f))?;
                    }
                    Ok(())
                })?;
            }
        }
    }
    if reward {
        writeln!(out, "state {fail} sink")?;
        write_self_loop(out, fail, reward, number)
    } else {
        writeln!(out, "state {goal} {GOAL_LABEL}")?;
        write_self_loop(out, goal, reward, number)?;
        writeln!(out, "state {fail} fail")?;
        write_self_loop(out, fail, reward, number)
    }
}

/// [`write_model`] into `out` as it goes (a large model's file is never held in memory), the
/// first error of `out` returned.
pub fn stream_model(
    out: &mut dyn std::io::Write,
    model: &impl DrnModel,
    g: f64,
    form: DrnForm,
) -> std::io::Result<()> {
    /// `out` as a [`Write`], keeping its error.
    struct Adapter<'a> {
        out: &'a mut dyn std::io::Write,
        error: Option<std::io::Error>,
    }
    impl Write for Adapter<'_> {
        fn write_str(&mut self, text: &str) -> fmt::Result {
            self.out.write_all(text.as_bytes()).map_err(|error| {
                self.error = Some(error);
                fmt::Error
            })
        }
    }
    let mut adapter = Adapter { out, error: None };
    match write_model(&mut adapter, model, g, form) {
        Ok(()) => Ok(()),
        Err(fmt::Error) => Err(adapter
            .error
            .unwrap_or_else(|| std::io::Error::other("formatting failed"))),
    }
}

/// A state's display name as a `//` comment line, control characters escaped so that it stays
/// on its line.
fn write_name(out: &mut impl Write, name: Option<String>) -> fmt::Result {
    if let Some(name) = name {
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
    Ok(())
}

fn write_self_loop(
    out: &mut impl Write,
    state: impl fmt::Display,
    reward: bool,
    number: Number,
) -> fmt::Result {
    writeln!(
        out,
        "\taction __NOLABEL__{}",
        if reward { " [0]" } else { "" }
    )?;
    writeln!(out, "\t\t{state} : {}", number.point(1.0))
}

/// How probabilities are written: plain numbers, or intervals (an interval MDP).
#[derive(Clone, Copy)]
struct Number {
    interval: bool,
}

impl Number {
    fn point(self, p: f64) -> Bounds {
        self.bounds([p, p])
    }

    fn bounds(self, bounds: [f64; 2]) -> Bounds {
        Bounds {
            bounds,
            interval: self.interval,
        }
    }
}

/// A probability as Storm reads it: `p` in a plain model, `[l,u]` (no space) in an interval
/// one.
struct Bounds {
    bounds: [f64; 2],
    interval: bool,
}

impl fmt::Display for Bounds {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [l, u] = self.bounds;
        if self.interval {
            write!(f, "[{l},{u}]")
        } else {
            write!(f, "{l}")
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::model::MdpBuilder;
    use crate::mdp::robust;
    use crate::mdp::solve::{Interval, SolveOptions, solve};
    use crate::mdp::testing::{
        ms, policy_value, random_intervals, random_mdp, rng, vertex_minimum,
    };

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
        let discount = Discount::new(0.5).unwrap();
        let h0 = |s| (s == ms(0)).then(|| "h0 (W, L, L)".to_string());
        assert_eq!(write_drn(&mdp, discount, DrnForm::Reward, h0), expected);
        // Undiscounted: no sink transitions on decision choices, probabilities as given.
        let undiscounted = write_drn(&mdp, Discount::NONE, DrnForm::Reward, |_| None);
        assert!(undiscounted.contains(
            "state 0 init\n\taction N [0]\n\t\t1 : 0.5\n\t\t2 : 0.5\n\taction stop [0]\n\t\t3 : 1\n"
        ));
        assert!(!undiscounted.contains("// discount"));
        // Reachability form: r_max = 200, so state 3 goes to goal (4) surely; the discount
        // goes to fail (5); 3 choices + 2 absorbing states + goal and fail = 7 actions.
        let expected = "\
// hypersynth MDP, reachability form: 200 * Pmax=? [F \"goal\"] is the maximal expected payoff
// discount 0.5: each move also goes to the fail (state 5) with probability 0.5
@type: MDP
@parameters

@reward_models

@nr_states
6
@nr_choices
7
@model
// h0 (W, L, L)
state 0 init
\taction N
\t\t1 : 0.25
\t\t2 : 0.25
\t\t5 : 0.5
\taction stop
\t\t3 : 1
state 1
\taction E
\t\t1 : 0.5
\t\t5 : 0.5
state 2 absorbing
\taction __NOLABEL__
\t\t2 : 1
state 3 absorbing
\taction collect
\t\t4 : 1
state 4 goal
\taction __NOLABEL__
\t\t4 : 1
state 5 fail
\taction __NOLABEL__
\t\t5 : 1
";
        assert_eq!(
            write_drn(&mdp, discount, DrnForm::Reachability, h0),
            expected
        );
    }

    /// A DRN MDP as Storm's parser reads it: whether it is in reachability form, per state its
    /// labels and actions.
    struct Drn {
        reachability: bool,
        /// `r_max` of the first comment line (reachability form).
        scale: f64,
        states: Vec<DrnState>,
    }

    struct DrnState {
        labels: Vec<String>,
        actions: Vec<DrnAction>,
    }

    struct DrnAction {
        reward: f64,
        /// Per target, its probability interval (`[p, p]` for a plain probability).
        transitions: Vec<(usize, [f64; 2])>,
    }

    /// Parses the subset of DRN that the writers promise, asserting its structural rules: the
    /// header (`@value_type: double-interval` exactly when `interval`, the reward model `r`
    /// exactly in reward form), consecutive state ids, `@nr_states` and `@nr_choices`
    /// matching, one reward per action in reward form and none in reachability form, `TARGET :
    /// PROBABILITY` (or `[l,u]`) with targets ascending and in range, probabilities summing to
    /// 1 (bounds around 1), exactly one `init` state, every state with an action.
    fn parse_drn(text: &str, interval: bool) -> Drn {
        let first = text.lines().next().unwrap();
        let reachability = first.contains("reachability form: ");
        let scale = match first.split_once("reachability form: ") {
            Some((_, rest)) => rest.split(' ').next().unwrap().parse().unwrap(),
            None => 1.0,
        };
        let mut lines = text.lines().filter(|line| !line.starts_with("//"));
        let mut expect = |line: &str| assert_eq!(lines.next(), Some(line));
        expect("@type: MDP");
        if interval {
            expect("@value_type: double-interval");
        }
        expect("@parameters");
        expect("");
        expect("@reward_models");
        expect(if reachability { "" } else { REWARD_MODEL });
        expect("@nr_states");
        let nr_states: usize = lines.next().unwrap().parse().unwrap();
        assert_eq!(lines.next(), Some("@nr_choices"));
        let nr_choices: usize = lines.next().unwrap().parse().unwrap();
        assert_eq!(lines.next(), Some("@model"));
        let probability = |text: &str| -> [f64; 2] {
            match text.strip_prefix('[') {
                Some(rest) => {
                    assert!(interval, "{text}");
                    let (l, u) = rest.strip_suffix(']').unwrap().split_once(',').unwrap();
                    [l.parse().unwrap(), u.parse().unwrap()]
                }
                None => {
                    assert!(!interval, "{text}");
                    let p = text.parse().unwrap();
                    [p, p]
                }
            }
        };
        let mut states: Vec<DrnState> = Vec::new();
        for line in lines {
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
                let reward = match rest.split_once(' ') {
                    Some((name, reward)) => {
                        assert!(!name.is_empty() && !reachability);
                        let reward = reward.strip_prefix('[').unwrap().strip_suffix(']').unwrap();
                        reward.parse().unwrap()
                    }
                    None => {
                        assert!(!rest.is_empty() && reachability);
                        0.0
                    }
                };
                assert!(reward >= 0.0);
                let actions = &mut states.last_mut().unwrap().actions;
                actions.push(DrnAction {
                    reward,
                    transitions: Vec::new(),
                });
            } else {
                let (target, p) = line
                    .strip_prefix("\t\t")
                    .unwrap()
                    .split_once(" : ")
                    .unwrap();
                let state = states.last_mut().unwrap();
                let action = state.actions.last_mut().unwrap();
                action
                    .transitions
                    .push((target.parse().unwrap(), probability(p)));
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
                assert!(
                    action
                        .transitions
                        .iter()
                        .all(|&(_, [l, u])| 0.0 <= l && l <= u && u <= 1.0 && u > 0.0)
                );
                let lower: f64 = action.transitions.iter().map(|&(_, p)| p[0]).sum();
                let upper: f64 = action.transitions.iter().map(|&(_, p)| p[1]).sum();
                assert!(
                    lower <= 1.0 + 1e-12 && upper >= 1.0 - 1e-12,
                    "{lower} {upper}"
                );
            }
        }
        Drn {
            reachability,
            scale,
            states,
        }
    }

    /// Storm's value of the model by plain value iteration from 0, the adversary choosing the
    /// worst vertex of each action's intervals: `R{"r"}max=? [C]` in reward form (which
    /// converges from below to the maximal total reward, rewards being ≥ 0), `r_max ·
    /// Pmax=? [F "goal"]` in reachability form (`goal` fixed at 1, then scaled). With whether
    /// it converged.
    fn storm_value(drn: &Drn) -> (Vec<f64>, bool) {
        let goal = |state: &DrnState| state.labels.iter().any(|l| l == GOAL_LABEL);
        let mut values: Vec<f64> = drn
            .states
            .iter()
            .map(|s| if goal(s) { 1.0 } else { 0.0 })
            .collect();
        let mut converged = false;
        for _ in 0..200_000 {
            let next: Vec<f64> = drn
                .states
                .iter()
                .map(|state| {
                    if goal(state) {
                        return 1.0;
                    }
                    state
                        .actions
                        .iter()
                        .map(|a| {
                            let successors: Vec<f64> =
                                a.transitions.iter().map(|&(t, _)| values[t]).collect();
                            let bounds: Vec<[f64; 2]> =
                                a.transitions.iter().map(|&(_, b)| b).collect();
                            a.reward + vertex_minimum(&successors, &bounds)
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
                converged = true;
                break;
            }
        }
        if drn.reachability {
            for v in &mut values {
                *v *= drn.scale;
            }
        }
        (values, converged)
    }

    /// The model's states in `drn` are labelled as the model says; Storm's value of every
    /// state lies within the solver's bounds (from below only, if the naive iteration did not
    /// converge).
    fn assert_storm_agrees(drn: &Drn, mdp: &Mdp, bounds: impl Fn(MdpState) -> Interval) {
        let n = mdp.num_states();
        assert_eq!(drn.states.len(), n + if drn.reachability { 2 } else { 1 });
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
        let (values, converged) = storm_value(drn);
        for state in mdp.states() {
            let value = bounds(state);
            let v = values[state.index()];
            let slack = 1e-9 * value.upper.max(1.0);
            assert!(
                v <= value.upper + slack && (!converged || value.lower - slack <= v),
                "state {state}: DRN {v} vs [{}, {}]",
                value.lower,
                value.upper
            );
        }
    }

    fn options(g: f64) -> SolveOptions {
        SolveOptions {
            discount: Discount::new(g).unwrap(),
            epsilon: 1e-9,
            ..SolveOptions::default()
        }
    }

    #[test]
    fn the_written_drn_has_the_solved_values_in_both_forms() {
        let mut rng = rng(11);
        for instance in 0..100 {
            let mdp = random_mdp(&mut rng, 8);
            let g = if instance % 2 == 0 { 1.0 } else { 0.9 };
            let solution = solve(&mdp, &options(g)).unwrap();
            for form in [DrnForm::Reward, DrnForm::Reachability] {
                let drn = parse_drn(&write_drn(&mdp, options(g).discount, form, |_| None), false);
                assert_eq!(drn.reachability, form == DrnForm::Reachability);
                assert_storm_agrees(&drn, &mdp, |s| solution.value(s));
            }
        }
    }

    #[test]
    fn the_written_chain_of_a_policy_has_its_value_in_both_forms() {
        let mut rng = rng(12);
        for instance in 0..50 {
            let mdp = random_mdp(&mut rng, 8);
            let g = if instance % 2 == 0 { 1.0 } else { 0.9 };
            let solution = solve(&mdp, &options(g)).unwrap();
            let policy: Vec<Option<ChoiceId>> = mdp.states().map(|s| solution.policy(s)).collect();
            let exact = policy_value(&mdp, &policy, g);
            let keep = |c: ChoiceId| policy.contains(&Some(c));
            for form in [DrnForm::Reward, DrnForm::Reachability] {
                let text = write_induced_drn(&mdp, options(g).discount, form, |_| None, keep);
                let drn = parse_drn(&text, false);
                assert!(
                    drn.states
                        .iter()
                        .take(mdp.num_states())
                        .all(|s| s.actions.len() == 1)
                );
                assert_storm_agrees(&drn, &mdp, |s| Interval {
                    lower: exact[s.index()] - 1e-9,
                    upper: exact[s.index()] + 1e-9,
                });
            }
        }
    }

    #[test]
    fn the_written_interval_drn_has_the_robust_values_in_both_forms() {
        let mut rng = rng(26);
        let mut uncertain = 0;
        for instance in 0..100 {
            let mdp = random_mdp(&mut rng, 8);
            let intervals = random_intervals(&mut rng, &mdp);
            uncertain += intervals.num_uncertain();
            let g = if instance % 2 == 0 { 1.0 } else { 0.9 };
            let solution = robust::solve(&mdp, &intervals, &options(g)).unwrap();
            for form in [DrnForm::Reward, DrnForm::Reachability] {
                let text =
                    write_interval_drn(&mdp, &intervals, options(g).discount, form, |_| None);
                let drn = parse_drn(&text, true);
                assert_storm_agrees(&drn, &mdp, |s| solution.value(s));
            }
        }
        assert!(uncertain >= 100, "{uncertain} interval choices");
    }

    #[test]
    fn an_interval_mdp_is_written_in_reachability_form() {
        // State 0: `go` (a move) to chance node 1, `stop` (instant) to the payoff 100 (state
        // 3); state 1 sends the run to the payoff 200 (state 2) within [0.25, 1] or back to 0
        // within [0, 0.75]. r_max = 200: state 2 reaches goal surely, state 3 with 1/2. At
        // g = 0.5 the move `go` goes to 1 with 0.5 and to fail (5) with 0.5; the chance node's
        // choice is instant and keeps its intervals.
        let mut builder = MdpBuilder::new();
        let [go, stop, chance] = ["go", "stop", "adversary"].map(|n| builder.action(n).unwrap());
        builder.add_decision_state().unwrap();
        builder.add_choice(go, &[(ms(1), 1.0)]).unwrap();
        builder.add_instant_choice(stop, &[(ms(3), 1.0)]).unwrap();
        builder.add_decision_state().unwrap();
        builder
            .add_instant_choice(chance, &[(ms(0), 0.5), (ms(2), 0.5)])
            .unwrap();
        builder.add_absorbing_state(200.0).unwrap();
        builder.add_absorbing_state(100.0).unwrap();
        builder.set_initial(ms(0));
        let mdp = builder.build().unwrap();
        let mut intervals = Intervals::exact(&mdp);
        let choice = mdp.choices(ms(1)).start();
        intervals
            .set(&mdp, choice, &[[0.0, 0.75], [0.25, 1.0]])
            .unwrap();
        let discount = Discount::new(0.5).unwrap();
        let chance = |s| (s == ms(1)).then(|| "chance".to_string());
        let text = write_interval_drn(&mdp, &intervals, discount, DrnForm::Reachability, chance);
        let expected = "\
// hypersynth interval MDP, reachability form: 200 * Pmax=? [F \"goal\"] (robust) is the value
// discount 0.5: each move also goes to the fail (state 5) with probability 0.5
@type: MDP
@value_type: double-interval
@parameters

@reward_models

@nr_states
6
@nr_choices
7
@model
state 0 init
\taction go
\t\t1 : [0.5,0.5]
\t\t5 : [0.5,0.5]
\taction stop
\t\t3 : [1,1]
// chance
state 1
\taction adversary
\t\t0 : [0,0.75]
\t\t2 : [0.25,1]
state 2 absorbing
\taction collect
\t\t4 : [1,1]
state 3 absorbing
\taction collect
\t\t4 : [0.5,0.5]
\t\t5 : [0.5,0.5]
state 4 goal
\taction __NOLABEL__
\t\t4 : [1,1]
state 5 fail
\taction __NOLABEL__
\t\t5 : [1,1]
";
        assert_eq!(text, expected);
        // Reward form: the payoffs as rewards, the discount to the sink (4).
        let text = write_interval_drn(&mdp, &intervals, discount, DrnForm::Reward, chance);
        assert!(text.starts_with(
            "// hypersynth interval MDP: R{\"r\"}max=? [C] (robust) is the value (Storm 2.0's"
        ));
        assert!(text.contains("@value_type: double-interval\n@parameters\n\n@reward_models\nr\n"));
        assert!(text.contains(
            "state 0 init\n\taction go [0]\n\t\t1 : [0.5,0.5]\n\t\t4 : [0.5,0.5]\n\taction stop [0]\n"
        ));
        assert!(text.contains("state 3 absorbing\n\taction collect [100]\n\t\t4 : [1,1]\n"));
    }
}
