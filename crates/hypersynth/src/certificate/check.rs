//! The certificate's inequalities on the re-derived model, and the check of every one of them in
//! exact arithmetic (docs/semantics.md §9.4).

use std::fmt;

use super::exact::Sum;
use super::model::{Model, NONE, RobotRule};
use crate::arena::ActionId;
use crate::csr::Csr;
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

/// One inequality at node `u`, between its value `v(u)` and its successors'.
pub(crate) struct Inequality {
    shape: Shape,
    /// What the right-hand side is, for messages.
    pub(crate) what: What,
}

/// What an [`Inequality`]'s right-hand side is, spelled out only for a message.
pub(crate) enum What {
    /// A payoff or a fixed bound, described.
    Fixed(&'static str),
    /// `g · v(t)` of the certificate `value` (`x` or `y`), by `action` where it is the MDP's
    /// choice.
    Successor {
        value: char,
        t: u32,
        action: Option<ActionId>,
    },
    /// The expectation of `value` over a chance node's successors.
    Chance { value: char },
    /// The least expectation of `value` over a learnt region, widened (`outward`) or narrowed.
    Region { value: char, outward: bool },
}

impl What {
    /// The description, with state and action names from `model`.
    pub(crate) fn describe(&self, model: &Model) -> String {
        match *self {
            What::Fixed(text) => text.to_string(),
            What::Successor { value, t, action } => {
                let mut text = format!("g · {value}(`{}`)", model.name(t));
                if let Some(a) = action {
                    text += &format!(" (action `{}`)", model.arena().action_name(a));
                }
                text
            }
            What::Chance { value } => format!("Σ P · {value}(successors)"),
            What::Region { value, outward } => {
                let side = if outward { "widened" } else { "narrowed" };
                format!(
                    "the least Σ P · {value}(successors) over the learnt region ({side} by 2^-40)"
                )
            }
        }
    }
}

/// The two sides of an [`Inequality`].
enum Shape {
    /// `v(u) · Σ scale` against `Σ a · b` over `rhs` (the scale: a chance node's weights, else
    /// 1).
    Linear {
        scale: Vec<f64>,
        rhs: Vec<(f64, f64)>,
    },
    /// `v(u)` against the least `Σ p_i · value_i` over the distributions `p` with `lower_i ≤
    /// p_i ≤ upper_i`, one `(value, lower, upper)` per successor: a chance node where a learnt
    /// sigma_L rules (§9.4).
    Region(Vec<(f64, f64, f64)>),
}

impl Inequality {
    fn constant(value: f64, what: &'static str) -> Inequality {
        Inequality::linear(vec![1.0], vec![(value, 1.0)], What::Fixed(what))
    }

    fn linear(scale: Vec<f64>, rhs: Vec<(f64, f64)>, what: What) -> Inequality {
        Inequality {
            shape: Shape::Linear { scale, rhs },
            what,
        }
    }

    /// Whether `v(u) ≤` the right-hand side (`below`) or `≥` it (not `below`), exactly.
    pub(crate) fn holds(&self, value: f64, below: bool) -> bool {
        match &self.shape {
            Shape::Linear { scale, rhs } => {
                let left = Sum::of(scale.iter().map(|&w| (value, w)));
                let right = Sum::of(rhs.iter().copied());
                if below { left <= right } else { left >= right }
            }
            Shape::Region(rows) => region_holds(rows, value, below),
        }
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

    /// The right-hand side divided by the scale, rounded to nearest: what the value should be
    /// (infinite for a region that admits no distribution).
    pub(crate) fn approximate(&self) -> f64 {
        match &self.shape {
            Shape::Linear { scale, rhs } => {
                let scale: f64 = scale.iter().sum();
                rhs.iter().map(|&(a, b)| a * b).sum::<f64>() / scale
            }
            Shape::Region(rows) if !feasible(rows) => f64::INFINITY,
            Shape::Region(rows) => rows
                .iter()
                .map(|&(at, _, _)| {
                    rows.iter()
                        .fold(at, |f, &(v, l, u)| match v.total_cmp(&at) {
                            std::cmp::Ordering::Less => f - u * (at - v),
                            std::cmp::Ordering::Greater => f + l * (v - at),
                            std::cmp::Ordering::Equal => f,
                        })
                })
                .fold(0.0, f64::max),
        }
    }
}

/// Whether `value ≤` (`below`) or `≥` the least `Σ p_i · v_i` over the distributions within
/// `rows`' intervals, exactly. By linear programming duality that least sum is the greatest
/// of `f(λ) = λ + Σ l_i · (v_i − λ)⁺ − Σ u_i · (λ − v_i)⁺`, a concave function of `λ` whose
/// greatest value, for intervals that admit a distribution (`Σ l ≤ 1 ≤ Σ u`), is at one of
/// the `v_k`; and every `f(λ)` is at most the least sum, for any intervals containing one
/// distribution. So `value` is below it when `value ≤ f(v_k)` for some `k`, and above it when
/// the intervals admit a distribution and `value ≥ f(v_k)` for every `k`. Each comparison is
/// multiplied out into sums of products of two doubles, `value + Σ_{v_i < v_k} u_i · v_k +
/// Σ_{v_i > v_k} l_i · v_k` against `v_k + Σ_{v_i < v_k} u_i · v_i + Σ_{v_i > v_k} l_i · v_i`,
/// and compared exactly.
fn region_holds(rows: &[(f64, f64, f64)], value: f64, below: bool) -> bool {
    if !below && !feasible(rows) {
        return false;
    }
    let at = |&(vk, _, _): &(f64, f64, f64)| {
        let (mut left, mut right) = (Sum::of([(value, 1.0)]), Sum::of([(vk, 1.0)]));
        for &(v, l, u) in rows {
            let weight = if v < vk {
                u
            } else if v > vk {
                l
            } else {
                continue;
            };
            left.add(weight, vk);
            right.add(weight, v);
        }
        if below { left <= right } else { left >= right }
    };
    match below {
        true => rows.iter().any(at),
        false => rows.iter().all(at),
    }
}

/// Whether the intervals of `rows` admit a distribution: `Σ lower ≤ 1 ≤ Σ upper`, exactly.
fn feasible(rows: &[(f64, f64, f64)]) -> bool {
    let one = Sum::of([(1.0, 1.0)]);
    Sum::of(rows.iter().map(|&(_, l, _)| (l, 1.0))) <= one
        && Sum::of(rows.iter().map(|&(_, _, u)| (u, 1.0))) >= one
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
            let what = What::Successor {
                value: 'x',
                t,
                action: None,
            };
            Inequality::linear(vec![1.0], vec![(g, x(t))], what)
        }
        Step::Chance => chance(model, u, x, 'x', true),
    }
}

/// The inequality of chance node `u` over `value`: `v(u) · Σ w ≤ Σ w_a · v(T(u, a))`, or
/// where a learnt sigma_L rules, `v(u)` against the least `Σ P(a) · v(T(u, a))` over its
/// region, moved `outward` (the lower certificate's) or inward.
fn chance(
    model: &Model,
    u: u32,
    value: impl Fn(u32) -> f64,
    name: char,
    outward: bool,
) -> Inequality {
    if let Some(intervals) = model.intervals(u, outward) {
        let rows = (model.edges(u).iter().zip(intervals))
            .map(|(&(_, t), [lower, upper])| (value(t), lower, upper))
            .collect();
        return Inequality {
            shape: Shape::Region(rows),
            what: What::Region {
                value: name,
                outward,
            },
        };
    }
    let (mut scale, mut rhs) = (Vec::new(), Vec::new());
    for (&(_, t), &w) in model.edges(u).iter().zip(model.weights(u)) {
        if w > 0.0 {
            scale.push(w);
            rhs.push((w, value(t)));
        }
    }
    Inequality::linear(scale, rhs, What::Chance { value: name })
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
                let what = What::Successor {
                    value: 'y',
                    t,
                    action: Some(a),
                };
                Inequality::linear(vec![1.0], vec![(g, y(t))], what)
            }))
            .collect(),
        None if model.edges(u).is_empty() => {
            vec![Inequality::constant(
                model.all(),
                "what a stuck adversary pays",
            )]
        }
        None => vec![chance(model, u, y, 'y', false)],
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
/// state, `k + 1` next to a state of rank `k` (`NONE`: no rank); a chance node where a learnt
/// sigma_L rules only once every distribution of its region gives those successors positive
/// probability. The lower certificate holds only if every such state gets one; the least ranks
/// are the ones to look for, so the file need not give them.
pub(crate) fn ranks(model: &Model, steps: &[Option<Step>], order: &[u32], x: &[f64]) -> Vec<u32> {
    let reverse: Csr<u32, u32> = Csr::group_from(model.len(), || {
        order.iter().flat_map(|&u| {
            let successors = steps[u as usize].map(|step| chain_successors(model, step, u));
            successors.into_iter().flatten().map(move |t| (t, u))
        })
    });
    let mut ranks = vec![NONE; model.len()];
    let needs = |u: u32| {
        x[u as usize] > 0.0 && matches!(steps[u as usize], Some(Step::Move(_) | Step::Chance))
    };
    let pays = |t: u32| matches!(steps[t as usize], Some(Step::End(p, _)) if p > 0.0);
    // Whether every distribution at `p` gives positive probability to its successors that
    // pay or have a rank up to `below` (none with `None`): at a learnt chance node, one of
    // them with a positive lower end, or the others' upper ends adding up to less than 1
    // (the lower certificate's widened region); elsewhere the successor through which `p`
    // was found has positive probability.
    let forced = |p: u32, ranks: &[u32], below: Option<u32>| {
        let Some(intervals) = model.intervals(p, true) else {
            return true;
        };
        let counts = |t: u32| pays(t) || below.is_some_and(|r| ranks[t as usize] <= r);
        let mut outside = Sum::default();
        for (&(_, t), [lower, upper]) in model.edges(p).iter().zip(intervals) {
            match counts(t) {
                true if lower > 0.0 => return true,
                true => {}
                false => outside.add(upper, 1.0),
            }
        }
        outside < Sum::of([(1.0, 1.0)])
    };
    let mut layer: Vec<u32> = Vec::new();
    for &t in order {
        if pays(t) {
            for &p in reverse.row(t) {
                if needs(p) && ranks[p as usize] == NONE && forced(p, &ranks, None) {
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
            for &p in reverse.row(t) {
                if needs(p) && ranks[p as usize] == NONE && forced(p, &ranks, Some(rank - 1)) {
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
                inequality.what.describe(model),
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
                    inequality.what.describe(model),
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

#[cfg(test)]
mod tests {
    use rand_chacha::ChaCha8Rng;
    use rand_core::{RngCore, SeedableRng};

    use super::{Inequality, Shape, What, feasible, region_holds};

    /// The least `Σ p_i · v_i` over the distributions within the intervals by enumerating the
    /// region's vertices: at a vertex every coordinate but at most one sits at a bound, so try
    /// each free coordinate with every choice of bounds for the others (`None`: no
    /// distribution). Exact for the sixteenths used below.
    fn least_by_vertices(rows: &[(f64, f64, f64)]) -> Option<f64> {
        let n = rows.len();
        let mut least: Option<f64> = None;
        for free in 0..n {
            for bits in 0..1u32 << n {
                let mut p: Vec<f64> = (0..n)
                    .map(|i| {
                        if bits >> i & 1 == 1 {
                            rows[i].2
                        } else {
                            rows[i].1
                        }
                    })
                    .collect();
                p[free] = 0.0;
                p[free] = 1.0 - p.iter().sum::<f64>();
                if p[free] < rows[free].1 || p[free] > rows[free].2 {
                    continue;
                }
                let sum: f64 = (0..n).map(|i| p[i] * rows[i].0).sum();
                least = Some(least.map_or(sum, |l: f64| l.min(sum)));
            }
        }
        least
    }

    #[test]
    fn the_region_inequality_is_the_least_expectation_over_the_region() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut sixteenths = |most: u64| (rng.next_u64() % (most + 1)) as f64 / 16.0;
        let (mut feasible_cases, mut infeasible_cases) = (0, 0);
        for _ in 0..2000 {
            let n = 1 + (sixteenths(48) * 16.0) as usize % 4;
            let rows: Vec<(f64, f64, f64)> = (0..n)
                .map(|_| {
                    let value = sixteenths(16 * 300);
                    let (a, b) = (sixteenths(16), sixteenths(16));
                    (value, a.min(b), a.max(b))
                })
                .collect();
            let step = 1.0 / 16.0;
            match least_by_vertices(&rows) {
                Some(least) => {
                    feasible_cases += 1;
                    assert!(feasible(&rows), "{rows:?}");
                    assert!(region_holds(&rows, least, true), "{rows:?}: {least}");
                    assert!(region_holds(&rows, least, false), "{rows:?}: {least}");
                    assert!(!region_holds(&rows, least + step, true), "{rows:?}");
                    assert!(region_holds(&rows, least + step, false), "{rows:?}");
                    if least >= step {
                        assert!(region_holds(&rows, least - step, true), "{rows:?}");
                        assert!(!region_holds(&rows, least - step, false), "{rows:?}");
                    }
                    let inequality = Inequality {
                        shape: Shape::Region(rows.clone()),
                        what: What::Fixed(""),
                    };
                    assert_eq!(inequality.approximate(), least, "{rows:?}");
                    assert_eq!(inequality.tightest(true), least, "{rows:?}");
                    assert_eq!(inequality.tightest(false), least, "{rows:?}");
                }
                None => {
                    // No distribution: nothing is above the least sum (it is +∞).
                    infeasible_cases += 1;
                    assert!(!feasible(&rows), "{rows:?}");
                    assert!(!region_holds(&rows, f64::MAX, false), "{rows:?}");
                }
            }
        }
        assert!(feasible_cases > 200 && infeasible_cases > 200);
    }

    #[test]
    fn a_value_one_unit_in_the_last_place_too_high_is_refused() {
        // Two successors worth 1/3 (rounded) and 1, each [0.25, 1]: the adversary puts 0.75
        // on the first, so the least sum is 0.25 + 0.75 · third, exactly, which no double
        // equals; the greatest double below it passes, the next one up does not.
        let third = 1.0 / 3.0;
        let rows = [(third, 0.25, 1.0), (1.0, 0.25, 1.0)];
        let inequality = Inequality {
            shape: Shape::Region(rows.to_vec()),
            what: What::Fixed(""),
        };
        let x = inequality.tightest(true);
        assert!(region_holds(&rows, x, true));
        assert!(!region_holds(&rows, x.next_up(), true));
        assert!((x - (0.25 + 0.75 * third)).abs() < 1e-15);
    }
}
