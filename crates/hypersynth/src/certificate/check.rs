//! The certificate's inequalities on the re-derived model, and the check of every one of them in
//! exact arithmetic (docs/semantics.md §9.4).

use std::fmt;

use super::exact::Sum;
use super::model::{Model, NONE, RobotRule};
use crate::opportunistic::export::{Choice, Scope};
use crate::opportunistic::load::CertificateEntries;

/// What the controller does at a node of its chain (the lower certificate's view).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Step {
    /// The chain ends paying this (commit or stop inside the set's region, give up: 0, a stuck
    /// adversary: `r(all)`); `why` says which.
    End(f64, &'static str),
    /// The robot moves along edge `edge` of the node.
    Move(usize),
    /// The adversary moves by its weights.
    Chance,
}

/// One inequality at node `u`: `v(u) · Σ scale` compared with `Σ a · b` over `rhs`.
pub(crate) struct Inequality {
    /// The multipliers of the node's own value (the weights of a chance node, else 1).
    pub(crate) scale: Vec<f64>,
    /// The right-hand side's products.
    pub(crate) rhs: Vec<(f64, f64)>,
    /// What the right-hand side is, for messages.
    pub(crate) what: String,
}

impl Inequality {
    fn constant(value: f64, what: impl Into<String>) -> Inequality {
        Inequality {
            scale: vec![1.0],
            rhs: vec![(value, 1.0)],
            what: what.into(),
        }
    }

    /// Whether `value · Σ scale ≤ Σ rhs` (`below`) or `≥` (not `below`), exactly.
    pub(crate) fn holds(&self, value: f64, below: bool) -> bool {
        let left = Sum::of(self.scale.iter().map(|&w| (value, w)));
        let right = Sum::of(self.rhs.iter().copied());
        if below { left <= right } else { left >= right }
    }

    /// The greatest double `q ≥ 0` with `q · Σ scale ≤ Σ rhs` (`below`), or the least with
    /// `q · Σ scale ≥ Σ rhs`: found from the approximation one unit in the last place at a
    /// time, each step an exact comparison, so the result is that double whatever the
    /// approximation's rounding (0 if no `q ≥ 0` satisfies a `below` inequality).
    pub(crate) fn tightest(&self, below: bool) -> f64 {
        let mut q = self.approximate().max(0.0);
        if !q.is_finite() {
            q = f64::MAX;
        }
        if below {
            if self.holds(q, true) {
                while q < f64::MAX && self.holds(q.next_up(), true) {
                    q = q.next_up();
                }
            } else {
                while q > 0.0 && !self.holds(q, true) {
                    q = q.next_down().max(0.0);
                }
            }
        } else if self.holds(q, false) {
            while q > 0.0 && self.holds(q.next_down().max(0.0), false) {
                q = q.next_down().max(0.0);
            }
        } else {
            while q < f64::MAX && !self.holds(q, false) {
                q = q.next_up();
            }
        }
        q
    }

    /// The right-hand side divided by the scale, rounded to nearest: what the value should be.
    pub(crate) fn approximate(&self) -> f64 {
        let scale: f64 = self.scale.iter().sum();
        self.rhs.iter().map(|&(a, b)| a * b).sum::<f64>() / scale
    }
}

/// The controller's chain on `model`: per node, its step (`None`: a robot node without a
/// decision).
pub(crate) fn steps(model: &Model) -> Vec<Option<Step>> {
    let checked = model.checked;
    let tuples = checked.file.tuples.len();
    let uncommitted = checked.modes.first().and_then(Option::as_ref);
    (0..model.len() as u32)
        .map(|u| {
            let (s, t) = model.nodes[u as usize];
            let row = checked.ranks.of(s) * tuples + t as usize;
            if !model.is_robot(u) {
                // Where the file marks an adversary state worth 0, its executor gives up.
                let gives_up = checked
                    .adversary
                    .get(row)
                    .is_some_and(|entry| entry & 1 == 1);
                return Some(match model.edges(u).is_empty() {
                    true => Step::End(model.all(), "what a stuck adversary pays"),
                    false if gives_up => Step::End(0.0, "0 (the file gives up at this state)"),
                    false => Step::Chance,
                });
            }
            let c = uncommitted?.get(row)? as usize;
            Some(match &checked.file.choices[c] {
                Choice::Move(_) => {
                    let action = checked.moves[c]?;
                    Step::Move(model.edges(u).iter().position(|&(a, _)| a == action)?)
                }
                Choice::Stop(set) | Choice::Commit(set) => match model.wins(*set, u) {
                    true => Step::End(model.payoff(*set), "the payoff of the set committed to"),
                    false => Step::End(0.0, "0 (committing outside the set's region)"),
                },
                Choice::GiveUp => Step::End(0.0, "0 (giving up)"),
            })
        })
        .collect()
}

/// The successors of positive probability of node `u` in the controller's chain.
pub(crate) fn chain_successors<'m>(
    model: &'m Model,
    step: Step,
    u: u32,
) -> impl Iterator<Item = u32> + 'm {
    let edges = model.edges(u);
    let weights = model.weights(u);
    (0..edges.len())
        .filter(move |&i| match step {
            Step::End(..) => false,
            Step::Move(edge) => i == edge,
            Step::Chance => weights[i] > 0.0,
        })
        .map(move |i| edges[i].1)
}

/// The lower certificate's inequality at `u` (`x(u) ≤ …`), with `x` the lower values.
pub(crate) fn lower_inequality(
    model: &Model,
    step: Step,
    u: u32,
    x: impl Fn(u32) -> f64,
    g: f64,
) -> Inequality {
    match step {
        Step::End(p, why) => Inequality::constant(p, why),
        Step::Move(edge) => {
            let (_, t) = model.edges(u)[edge];
            Inequality {
                scale: vec![1.0],
                rhs: vec![(g, x(t))],
                what: format!("g · x(`{}`)", model.name(t)),
            }
        }
        Step::Chance => chance(model, u, x, "x"),
    }
}

/// The inequality of chance node `u` over `value`: `v(u) · Σ w ≤ Σ w_a · v(T(u, a))`.
fn chance(model: &Model, u: u32, value: impl Fn(u32) -> f64, name: &str) -> Inequality {
    let (mut scale, mut rhs) = (Vec::new(), Vec::new());
    for (&(_, t), &w) in model.edges(u).iter().zip(model.weights(u)) {
        if w > 0.0 {
            scale.push(w);
            rhs.push((w, value(t)));
        }
    }
    Inequality {
        scale,
        rhs,
        what: format!("Σ P · {name}(successors)"),
    }
}

/// The upper certificate's inequalities at `u` (`y(u) ≥ …` each), with `y` the upper values;
/// `rule` is the MDP's at a robot node.
pub(crate) fn upper_inequalities(
    model: &Model,
    rule: Option<&RobotRule>,
    u: u32,
    y: impl Fn(u32) -> f64,
    g: f64,
) -> Vec<Inequality> {
    match rule {
        Some(RobotRule::Absorbing(p)) => vec![Inequality::constant(*p, "the absorbing payoff")],
        Some(RobotRule::Decide { stop, moves }) => stop
            .map(|p| Inequality::constant(p, "the payoff of stop"))
            .into_iter()
            .chain(moves.iter().map(|&i| {
                let (a, t) = model.edges(u)[i];
                Inequality {
                    scale: vec![1.0],
                    rhs: vec![(g, y(t))],
                    what: format!(
                        "g · y(`{}`) (action `{}`)",
                        model.name(t),
                        model.arena().action_name(a)
                    ),
                }
            }))
            .collect(),
        None if model.edges(u).is_empty() => {
            vec![Inequality::constant(
                model.all(),
                "what a stuck adversary pays",
            )]
        }
        None => vec![chance(model, u, y, "y")],
    }
}

/// The MDP's successors of `u` under every enabled choice and the adversary's moves of
/// positive probability.
pub(crate) fn upper_successors<'m>(
    model: &'m Model,
    rule: Option<&'m RobotRule>,
    u: u32,
) -> Box<dyn Iterator<Item = u32> + 'm> {
    let edges = model.edges(u);
    match rule {
        Some(RobotRule::Absorbing(_)) => Box::new(std::iter::empty()),
        Some(RobotRule::Decide { moves, .. }) => Box::new(moves.iter().map(move |&i| edges[i].1)),
        None => Box::new(
            edges
                .iter()
                .zip(model.weights(u))
                .filter(|&(_, &w)| w > 0.0)
                .map(|(&(_, t), _)| t),
        ),
    }
}

/// The states reachable by `successors` from the certificate's roots, in breadth-first order:
/// from h0 (node 0) for a file of scope `reachable`; for a file of scope `all`, from h0 and then
/// every robot node (each has a decision), so that the certificate covers every state that has
/// one.
pub(crate) fn reach(model: &Model, mut successors: impl FnMut(u32) -> Vec<u32>) -> Vec<u32> {
    let n = model.len();
    let roots: Vec<u32> = match model.checked.file.scope {
        Scope::Reachable => vec![0],
        Scope::All => std::iter::once(0)
            .chain((1..n as u32).filter(|&u| model.is_robot(u)))
            .collect(),
    };
    let mut seen = bit_set::BitSet::with_capacity(n);
    let mut order = Vec::with_capacity(roots.len());
    for root in roots {
        if seen.insert(root as usize) {
            order.push(root);
        }
    }
    let mut at = 0;
    while at < order.len() {
        for t in successors(order[at]) {
            if seen.insert(t as usize) {
                order.push(t);
            }
        }
        at += 1;
    }
    order
}

/// Whether state `u` of D_L (taking `step`) carries its own x in the file: a robot state that
/// moves, or a chance node with an adversary state among its successors of positive
/// probability. The others' x is derived: the payoff of an end, and at a chance node whose
/// successors are all robot states the greatest double its inequality allows.
pub(crate) fn lower_carries(model: &Model, step: Step, u: u32) -> bool {
    match step {
        Step::End(..) => false,
        Step::Move(_) => true,
        Step::Chance => chain_successors(model, step, u).any(|t| !model.is_robot(t)),
    }
}

/// Whether state `u` of D_U carries its own y in the file: a decision node, or a chance node
/// with an adversary state among its successors of positive probability. The others' y is
/// derived: the payoff of an absorbing or stuck state, and at a chance node whose successors
/// are all robot states the least double its inequality allows.
pub(crate) fn upper_carries(model: &Model, rule: Option<&RobotRule>, u: u32) -> bool {
    match rule {
        Some(RobotRule::Absorbing(_)) => false,
        Some(RobotRule::Decide { .. }) => true,
        None => upper_successors(model, rule, u).any(|t| !model.is_robot(t)),
    }
}

/// The values of one certificate over the model's nodes (0 outside `states`): `given` in
/// order for the states of `states` that `carry` one, `fixed` where it gives a value, then
/// `derive` for the others, from the values placed. The state and problem when `given` does
/// not have one value per state that carries one.
pub(crate) fn resolve(
    n: usize,
    states: &[u32],
    given: &[f64],
    carries: impl Fn(u32) -> bool,
    fixed: impl Fn(u32) -> Option<f64>,
    derive: impl Fn(u32, &[f64]) -> f64,
) -> Result<Vec<f64>, (u32, String)> {
    let mut values = vec![0.0; n];
    let mut next = given.iter();
    let mut derived = Vec::new();
    for &u in states {
        if carries(u) {
            let Some(&value) = next.next() else {
                let message = format!(
                    "the state carries a value and the certificate's {} values are used up",
                    given.len()
                );
                return Err((u, message));
            };
            values[u as usize] = value;
        } else if let Some(value) = fixed(u) {
            values[u as usize] = value;
        } else {
            derived.push(u);
        }
    }
    if next.len() > 0 {
        let carried = given.len() - next.len();
        let message = format!(
            "the certificate gives {} values, where {carried} states carry one",
            given.len()
        );
        return Err((states[0], message));
    }
    for u in derived {
        values[u as usize] = derive(u, &values);
    }
    Ok(values)
}

/// Ranks over the controller's chain on `order` (D_L) by a backward search from the states that
/// pay: a state of positive x that moves or is a chance node gets rank 0 next to a paying
/// state, `k + 1` next to a state of rank `k` (`NONE`: no rank). The lower certificate holds
/// only if every such state gets one; the least ranks are the ones to look for, so the file
/// need not give them.
pub(crate) fn ranks(model: &Model, steps: &[Option<Step>], order: &[u32], x: &[f64]) -> Vec<u32> {
    let mut reverse: Vec<Vec<u32>> = vec![Vec::new(); model.len()];
    for &u in order {
        if let Some(step) = steps[u as usize] {
            for t in chain_successors(model, step, u) {
                reverse[t as usize].push(u);
            }
        }
    }
    let mut ranks = vec![NONE; model.len()];
    let needs = |u: u32| {
        x[u as usize] > 0.0 && matches!(steps[u as usize], Some(Step::Move(_) | Step::Chance))
    };
    let mut layer: Vec<u32> = Vec::new();
    for &t in order {
        if matches!(steps[t as usize], Some(Step::End(p, _)) if p > 0.0) {
            for &p in &reverse[t as usize] {
                if needs(p) && ranks[p as usize] == NONE {
                    ranks[p as usize] = 0;
                    layer.push(p);
                }
            }
        }
    }
    let mut rank = 0;
    while !layer.is_empty() {
        rank += 1;
        let mut next = Vec::new();
        for &t in &layer {
            for &p in &reverse[t as usize] {
                if needs(p) && ranks[p as usize] == NONE {
                    ranks[p as usize] = rank;
                    next.push(p);
                }
            }
        }
        layer = next;
    }
    ranks
}

/// Where robot node `u` commits to a set `T` inside `Win(T)` (by `stop` or `commit`), that
/// the file's strategy for `T` wins from there surely (§5.4): at every robot node the play can
/// reach in that mode before `T` holds, the file's move lowers the rank in `Win(T)` (adversary
/// moves lower it by the attractor's definition), so `T` holds within `rank(u)` moves. The
/// node and the problem otherwise.
fn committed_play(model: &Model, u: u32) -> Result<(), (u32, String)> {
    let checked = model.checked;
    let tuples = checked.file.tuples.len();
    let row = |v: u32| {
        let (s, t) = model.nodes[v as usize];
        checked.ranks.of(s) * tuples + t as usize
    };
    let Some(c) = checked
        .modes
        .first()
        .and_then(Option::as_ref)
        .and_then(|m| m.get(row(u)))
    else {
        return Ok(());
    };
    let (Choice::Stop(set) | Choice::Commit(set)) = checked.file.choices[c as usize] else {
        return Ok(());
    };
    if !model.wins(set, u) || model.payoff(set) == 0.0 {
        return Ok(());
    }
    let mode = checked.modes.get(set as usize).and_then(Option::as_ref);
    let mut seen = bit_set::BitSet::new();
    let mut stack = vec![u];
    while let Some(v) = stack.pop() {
        if !seen.insert(v as usize) || model.is_target(set, v) {
            continue;
        }
        if !model.is_robot(v) {
            stack.extend(model.edges(v).iter().map(|&(_, t)| t));
            continue;
        }
        let own = model.rank(set, v);
        let step = mode
            .and_then(|m| m.get(row(v)))
            .and_then(|c| checked.moves[c as usize])
            .and_then(|a| model.edges(v).iter().find(|&&(b, _)| b == a));
        let Some(&(a, t)) = step else {
            let message = format!("committed to set {set}, the file has no move here");
            return Err((v, message));
        };
        if model.rank(set, t) >= own {
            let message = format!(
                "committed to set {set}, the file's move `{}` does not lower the rank {own} in \
                 the set's winning region",
                model.arena().action_name(a)
            );
            return Err((v, message));
        }
        stack.push(t);
    }
    Ok(())
}

/// Which certificate failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bound {
    /// The controller collects at least x(h0).
    Lower,
    /// No controller collects more than y(h0).
    Upper,
}

impl fmt::Display for Bound {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Bound::Lower => "lower",
            Bound::Upper => "upper",
        })
    }
}

/// The first state and inequality of a certificate that fail.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal {
    /// The certificate.
    pub bound: Bound,
    /// The product state, `ARENA_STATE|q_1|…`.
    pub state: String,
    /// The condition that fails, with the values involved.
    pub inequality: String,
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the {} certificate fails at state `{}`: {}",
            self.bound, self.state, self.inequality
        )
    }
}

/// What a certificate that checks says.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Certified {
    /// x(h0): the controller collects at least this.
    pub lower: f64,
    /// y(h0): no controller collects more.
    pub upper: f64,
    /// The states of D_L.
    pub lower_states: usize,
    /// The states of D_U.
    pub upper_states: usize,
}

/// Checks `certificate` on `model`: the lower certificate over D_L (its inequalities, then its
/// ranks, then the commitments), then the upper one over D_U, each state in breadth-first
/// order from the roots (`reach`).
pub(crate) fn check(model: &Model, certificate: &CertificateEntries) -> Result<Certified, Refusal> {
    let g = model.checked.file.discount;
    let refuse = |bound, u, inequality: String| Refusal {
        bound,
        state: model.name(u),
        inequality,
    };
    let steps = steps(model);
    let lower_states = reach(model, |u| match steps[u as usize] {
        Some(step) => chain_successors(model, step, u).collect(),
        None => Vec::new(),
    });
    if let Some(&u) = lower_states.iter().find(|&&u| steps[u as usize].is_none()) {
        let message = "the controller reaches this robot state and has no decision there";
        return Err(refuse(Bound::Lower, u, message.to_string()));
    }
    let step = |u: u32| steps[u as usize].expect("every state of D_L has a step");
    let x = resolve(
        model.len(),
        &lower_states,
        &certificate.lower,
        |u| lower_carries(model, step(u), u),
        |u| match step(u) {
            Step::End(p, _) => Some(p),
            _ => None,
        },
        |u, x| lower_inequality(model, step(u), u, |t| x[t as usize], g).tightest(true),
    )
    .map_err(|(u, message)| refuse(Bound::Lower, u, message))?;
    for &u in &lower_states {
        let xu = x[u as usize];
        let inequality = lower_inequality(model, step(u), u, |t| x[t as usize], g);
        if !inequality.holds(xu, true) {
            let message = format!(
                "x = {xu} exceeds {} = {}",
                inequality.what,
                inequality.approximate()
            );
            return Err(refuse(Bound::Lower, u, message));
        }
    }
    let ranks = ranks(model, &steps, &lower_states, &x);
    for &u in &lower_states {
        let needs = matches!(step(u), Step::Move(_) | Step::Chance) && x[u as usize] > 0.0;
        if needs && ranks[u as usize] == NONE {
            let message = format!(
                "x = {} > 0 and the state has no rank: no path of states of positive x leads \
                 from it to a payoff with positive probability",
                x[u as usize]
            );
            return Err(refuse(Bound::Lower, u, message));
        }
    }
    for &u in &lower_states {
        if let Err((v, message)) = committed_play(model, u) {
            return Err(refuse(Bound::Lower, v, message));
        }
    }
    let rules = model.robot_rules();
    let rule = |u: u32| rules[u as usize].as_ref();
    let upper_states = reach(model, |u| upper_successors(model, rule(u), u).collect());
    let y = resolve(
        model.len(),
        &upper_states,
        &certificate.upper,
        |u| upper_carries(model, rule(u), u),
        |u| match rule(u) {
            Some(RobotRule::Absorbing(p)) => Some(*p),
            None if model.edges(u).is_empty() => Some(model.all()),
            _ => None,
        },
        |u, y| {
            upper_inequalities(model, rule(u), u, |t| y[t as usize], g)
                .iter()
                .map(|inequality| inequality.tightest(false))
                .fold(0.0, f64::max)
        },
    )
    .map_err(|(u, message)| refuse(Bound::Upper, u, message))?;
    for &u in &upper_states {
        let yu = y[u as usize];
        for inequality in upper_inequalities(model, rule(u), u, |t| y[t as usize], g) {
            if !inequality.holds(yu, false) {
                let message = format!(
                    "y = {yu} is below {} = {}",
                    inequality.what,
                    inequality.approximate()
                );
                return Err(refuse(Bound::Upper, u, message));
            }
        }
    }
    Ok(Certified {
        lower: x[0],
        upper: y[0],
        lower_states: lower_states.len(),
        upper_states: upper_states.len(),
    })
}
