//! The controller on the index space (docs/semantics.md §6.7, §13): the explicit engine's
//! decisions ([`Decision`]) read from a solved [`Model`] and its [`Policy`], the reactive
//! strategies from attractor ranks computed when a set is first played, and what the
//! controller's export reads ([`Exportable`]), what simulations play ([`Steps`], [`Board`]), and the
//! decision table of a state ([`Controller::explain`]).
//!
//! The rules are the explicit [`Controller`](crate::opportunistic::controller::Controller)'s:
//! give up where the value is 0, commit where the model absorbs a robot state (to the set it
//! settles for), else the policy's choice (a move, or `stop` to that set). A committed set's
//! reactive strategy plays the first edge (in edge order) into a state of lower rank in the
//! set's attractor, any edge into the region from a target. Its ranks take two bytes per product
//! state (four past rank 65 534), per set played, computed on first use.

use std::cell::{Cell, OnceCell, RefCell};
use std::collections::HashMap;

use bit_set::BitSet;

use super::attractor::Ranks;
use super::mdp::{Choice, Distribution, Kind, Model};
use super::moves::Moves;
use super::policy::{Policy, PolicyError, expected_moves_from};
use super::solve::Solution;
use crate::arena::{ActionId, Owner};
use crate::game::{HState, States, SubsetPayoffs, TaskSet, WinRegion, allows_robot_edge};
use crate::mdp::Interval;
use crate::mdp::absorption::first_exits;
use crate::opportunistic::controller::{ActionRow, Decision, Explanation, Outcome};
use crate::opportunistic::evaluate::{Step, Steps};
use crate::opportunistic::export::Exportable;
use crate::opportunistic::presentation::Presentation;
use crate::opportunistic::simulate::Board;

/// A choice's row of a decision table before its outcomes: its value, expected moves and where
/// it leads (a product state or a stop sink, numbered as [`Controller::exits`] reads it).
type Row = (f64, f64, u64);

/// The opportunistic controller of a solved implicit [`Model`].
pub struct Controller<'a, 'b, 'm, M> {
    model: &'a Model<'b, 'm, M>,
    solution: &'a Solution,
    policy: &'a Policy,
    /// Per set (by mask − 1), its attractor's ranks once a reactive move was asked for.
    ranks: Vec<OnceCell<Ranks>>,
    /// Asked for the bytes of a set's ranks before they are computed.
    budget: RefCell<Box<dyn FnMut(u64) -> bool + 'a>>,
    /// Whether `budget` refused some.
    refused: Cell<bool>,
}

impl<'a, 'b, 'm, M: Moves> Controller<'a, 'b, 'm, M> {
    /// The controller of `model` solved by `solution`, playing `policy` before it commits.
    pub fn new(
        model: &'a Model<'b, 'm, M>,
        solution: &'a Solution,
        policy: &'a Policy,
    ) -> Controller<'a, 'b, 'm, M> {
        let k = model.regions().num_tasks();
        Controller {
            model,
            solution,
            policy,
            ranks: (0..(1usize << k) - 1).map(|_| OnceCell::new()).collect(),
            budget: RefCell::new(Box::new(|_| true)),
            refused: Cell::new(false),
        }
    }

    /// The controller asking `budget(bytes)` before it computes a set's ranks (two or four
    /// bytes per product state); where `budget` says no, the set's reactive strategy has no
    /// move and [`Controller::refused`] tells.
    pub fn with_budget(self, budget: impl FnMut(u64) -> bool + 'a) -> Self {
        Controller {
            budget: RefCell::new(Box::new(budget)),
            ..self
        }
    }

    /// Whether the budget refused the ranks of some set.
    pub fn refused(&self) -> bool {
        self.refused.get()
    }

    /// The certified bounds on the value of `h`.
    pub fn value(&self, h: u32) -> Interval {
        self.solution.value(self.model, h)
    }

    /// The set `h` settles for (empty when it wins none).
    fn best(&self, h: u32) -> TaskSet {
        self.model
            .regions()
            .best(self.model.payoffs(), h)
            .unwrap_or_default()
    }

    /// The decision in robot state `h` before committing (the module documentation).
    pub fn decide(&self, h: u32) -> Decision {
        if self.value(h).upper == 0.0 {
            return Decision::GiveUp;
        }
        if self.model.commits(h) {
            return Decision::Commit(self.best(h));
        }
        let chosen = self.policy.choice(h).and_then(|c| self.model.choice(h, c));
        match chosen {
            Some(Choice::Move { action, target }) => Decision::Move {
                action,
                successor: HState::from_u32(target),
            },
            Some(Choice::Stop { .. }) => Decision::Stop(self.best(h)),
            None => Decision::GiveUp,
        }
    }

    /// The decision table of product state `h`, as the explicit controller's
    /// [`explain`](crate::opportunistic::controller::Controller::explain) gives it: per choice
    /// of a decision node its lower Q-value, the controller's expected robot moves when playing
    /// it (the policy's chain solved from the choices' targets as [`evaluate`](super::evaluate)
    /// solves it from h0, to within `epsilon` in at most `max_iterations` sweeps per component)
    /// and where it leads once the adversary has moved (the first robot state, absorbing state
    /// or stop sink reached through the chance nodes,
    /// [`first_exits`](crate::mdp::absorption::first_exits)).
    ///
    /// # Errors
    /// [`PolicyError`] when the expected moves are not certified.
    pub fn explain(
        &self,
        h: u32,
        epsilon: f64,
        max_iterations: u32,
    ) -> Result<Explanation, PolicyError> {
        let mut tables = self.explain_all(&[h], epsilon, max_iterations)?;
        Ok(tables.pop().expect("one table per state"))
    }

    /// The decision tables of `states`, in order ([`Controller::explain`]), the policy's chain
    /// solved once from all their choices' targets: what a page of many tables asks.
    ///
    /// # Errors
    /// [`PolicyError`] when the expected moves are not certified.
    pub fn explain_all(
        &self,
        states: &[u32],
        epsilon: f64,
        max_iterations: u32,
    ) -> Result<Vec<Explanation>, PolicyError> {
        let (model, space) = (self.model, self.model.space());
        // Per state: whether the robot moves there, and its choices as a decision node.
        let choices: Vec<(bool, Vec<Choice>)> = states
            .iter()
            .map(|&h| {
                let robot = space.owner(h) == Owner::Robot;
                let mut choices = Vec::new();
                if robot && model.kind(h) == Kind::Decision {
                    model.choices(h, |choice| choices.push(choice));
                }
                (robot, choices)
            })
            .collect();
        // The expected moves from each state, then from each of its moves' targets.
        let mut roots = Vec::new();
        for (&h, (_, choices)) in states.iter().zip(&choices) {
            roots.push(h);
            roots.extend(choices.iter().filter_map(|choice| match *choice {
                Choice::Move { target, .. } => Some(target),
                Choice::Stop { .. } => None,
            }));
        }
        let times = expected_moves_from(model, self.policy, &roots, epsilon, max_iterations)?;
        let mut times = times.into_iter();
        let g = self.policy.discount();
        let n = space.num_states() as u64;
        // Per state: its expected moves, and per choice its value, expected moves and start.
        let rows: Vec<(f64, Vec<Row>)> = states
            .iter()
            .zip(&choices)
            .map(|(&h, (_, choices))| {
                let expected_moves = times.next().expect("a time per state");
                let rows = choices
                    .iter()
                    .map(|&choice| match choice {
                        Choice::Move { target, .. } => {
                            let time = times.next().expect("a time per move");
                            (g * self.value(target).lower, 1.0 + time, u64::from(target))
                        }
                        Choice::Stop { payoff } => (payoff, 0.0, n + model.stop_sink(h) as u64),
                    })
                    .collect();
                (expected_moves, rows)
            })
            .collect();
        // Every choice's exits, ordered as the explicit engine numbers states in one pass.
        let mut exits: Vec<_> = rows
            .iter()
            .flat_map(|(_, rows)| rows.iter().map(|&(_, _, start)| self.exits(start)))
            .collect();
        self.in_product_order(&mut exits);
        let mut exits = exits.into_iter();
        let tables = states
            .iter()
            .zip(choices)
            .zip(rows)
            .map(|((&h, (robot, choices)), (expected_moves, rows))| {
                let actions = choices
                    .iter()
                    .zip(rows)
                    .map(|(&choice, (value, expected_moves, _))| ActionRow {
                        action: model.choice_name(choice),
                        value,
                        expected_moves,
                        outcomes: self.outcomes(exits.next().expect("exits per choice")),
                    })
                    .collect();
                let chosen = robot
                    .then(|| self.policy.mdp_choice(h))
                    .flatten()
                    .and_then(|c| choices.get(usize::from(c)))
                    .map(|&choice| model.choice_name(choice));
                Explanation {
                    state: space.name(h),
                    label: self.label(h),
                    robot,
                    value: self.value(h).lower,
                    expected_moves,
                    actions,
                    chosen,
                }
            })
            .collect();
        Ok(tables)
    }

    /// How decision tables label product state `h` ([`Presentation::state_label`]).
    pub fn label(&self, h: u32) -> String {
        let (regions, payoffs) = (self.model.regions(), self.model.payoffs());
        let presentation = self.model.presentation();
        presentation.state_label(regions, payoffs, HState::from_u32(h))
    }

    /// Where a choice leading to `start` (a product state, or stop sink `start − n` past the
    /// `n` product states, as the explicit MDP numbers its states) leads once the adversary
    /// has moved: the exits of [`first_exits`], by index.
    fn exits(&self, start: u64) -> Vec<(Option<u64>, f64)> {
        let model = self.model;
        let n = model.space().num_states() as u64;
        let is_chance = |s: u64| s < n && model.kind(s as u32) == Kind::Chance;
        let mut distribution = Distribution::default();
        first_exits([(start, 1.0)], is_chance, |s, out| {
            model.distribution(s as u32, &mut distribution);
            out.extend(distribution.iter().map(|(t, p)| (u64::from(t), p)));
        })
    }

    /// Orders each list of `exits` as the explicit engine lists them: by its numbers, which are
    /// the indices but with the reachable enumeration (then numbered breadth-first from h0,
    /// found by one search), the stop sinks after the product states and the mass that never
    /// leaves last.
    fn in_product_order(&self, exits: &mut [Vec<(Option<u64>, f64)>]) {
        let space = self.model.space();
        if space.enumeration() == States::Full {
            return;
        }
        let n = space.num_states() as u64;
        let mut numbers: HashMap<u32, u64> = exits
            .iter()
            .flatten()
            .filter_map(|&(s, _)| s.filter(|&s| s < n).map(|s| (s as u32, 0)))
            .collect();
        let mut next = 0;
        space.for_each_state(|h| {
            if let Some(number) = numbers.get_mut(&h) {
                *number = next;
            }
            next += 1;
        });
        for list in exits {
            list.sort_by_key(|&(s, _)| match s {
                Some(s) if s < n => numbers[&(s as u32)],
                Some(sink) => sink,
                None => u64::MAX,
            });
        }
    }

    /// The outcomes the explicit decision table shows for `exits`.
    fn outcomes(&self, exits: Vec<(Option<u64>, f64)>) -> Vec<Outcome> {
        let (model, space) = (self.model, self.model.space());
        let n = space.num_states() as u64;
        exits
            .into_iter()
            .map(|(s, probability)| match s {
                Some(s) if s < n => Outcome {
                    state: space.name(s as u32),
                    label: self.label(s as u32),
                    probability,
                    value: self.value(s as u32).lower,
                },
                Some(s) => {
                    let sink = &model.sinks()[(s - n) as usize];
                    Outcome::sink(sink.name.clone(), probability, sink.payoff)
                }
                None => Outcome::never_leaves(probability),
            })
            .collect()
    }

    /// The move of the reactive strategy of the non-empty `set` in robot state `h`, `None`
    /// outside `Win(set)`.
    pub fn reactive_move(&self, set: TaskSet, h: u32) -> Option<(ActionId, u32)> {
        let space = self.model.space();
        let cell = &self.ranks[set.0 as usize - 1];
        if cell.get().is_none() {
            let budget = |bytes| !self.refused.get() && (self.budget.borrow_mut())(bytes);
            match self
                .model
                .regions()
                .ranks(space, WinRegion::Set(set), budget)
            {
                Some(ranks) => drop(cell.set(ranks)),
                None => {
                    self.refused.set(true);
                    return None;
                }
            }
        }
        let ranks = cell.get().expect("computed above");
        let rank = ranks.get(h)?;
        let mut found = None;
        space.edges(h, |action, t| {
            if found.is_none() && allows_robot_edge(Some(rank), ranks.get(t)) {
                found = Some((action, t));
            }
        });
        found
    }
}

impl<M: Moves> Exportable for Controller<'_, '_, '_, M> {
    fn num_arena_states(&self) -> usize {
        self.model.space().moves().num_states()
    }
    fn arena_owner(&self, s: u32) -> Owner {
        self.model.space().moves().owner(s)
    }
    fn labels(&self) -> &[BitSet] {
        self.model.space().moves().labels()
    }
    fn propositions(&self) -> &[String] {
        self.model.space().moves().propositions()
    }
    fn action_name(&self, action: ActionId) -> &str {
        &self.model.space().moves().actions()[action as usize]
    }
    fn num_tuples(&self) -> u32 {
        self.model.space().num_tuples()
    }
    fn tuple(&self, tuple: u32) -> Vec<u32> {
        self.model.space().tuple_states(tuple)
    }
    fn presentation(&self) -> &Presentation {
        self.model.presentation()
    }
    fn payoffs(&self) -> &SubsetPayoffs {
        self.model.payoffs()
    }
    fn discount(&self) -> f64 {
        self.policy.discount()
    }
    fn num_states(&self) -> usize {
        self.model.space().num_states()
    }
    fn initial(&self) -> HState {
        HState::from_u32(self.model.space().initial())
    }
    fn value(&self, h: HState) -> Interval {
        Controller::value(self, h.as_u32())
    }
    fn is_robot(&self, h: HState) -> bool {
        self.model.space().owner(h.as_u32()) == Owner::Robot
    }
    fn position(&self, h: HState) -> (u32, u32) {
        let space = self.model.space();
        (space.arena_state(h.as_u32()), space.tuple(h.as_u32()))
    }
    fn successors(&self, h: HState, out: &mut Vec<HState>) {
        out.clear();
        self.model
            .space()
            .edges(h.as_u32(), |_, t| out.push(HState::from_u32(t)));
    }
    fn probabilities(&self, h: HState, out: &mut Vec<f64>) {
        let mut distribution = Distribution::default();
        self.model.distribution(h.as_u32(), &mut distribution);
        out.clear();
        out.extend_from_slice(distribution.edge_weights());
    }
    fn decide(&self, h: HState) -> Decision {
        Controller::decide(self, h.as_u32())
    }
    fn is_target(&self, set: TaskSet, h: HState) -> bool {
        self.model.space().is_target(set, h.as_u32())
    }
    fn reactive_move(&self, set: TaskSet, h: HState) -> Option<(ActionId, HState)> {
        Controller::reactive_move(self, set, h.as_u32()).map(|(a, t)| (a, HState::from_u32(t)))
    }
    fn is_enumerated(&self, h: HState) -> bool {
        self.model.space().enumerated(h.as_u32())
    }
}

impl<M: Moves> Board for Controller<'_, '_, '_, M> {
    fn initial(&self) -> HState {
        Exportable::initial(self)
    }
    fn is_robot(&self, h: HState) -> bool {
        Exportable::is_robot(self, h)
    }
    fn edges(&self, h: HState, out: &mut Vec<(ActionId, HState)>) {
        out.clear();
        self.model
            .space()
            .edges(h.as_u32(), |a, t| out.push((a, HState::from_u32(t))));
    }
    fn distribution(&self, h: HState, out: &mut Vec<f64>) {
        self.probabilities(h, out);
    }
}

impl<M: Moves> Steps for Controller<'_, '_, '_, M> {
    fn num_goals(&self) -> usize {
        1 << self.model.regions().num_tasks()
    }
    fn is_goal_target(&self, goal: usize, h: HState) -> bool {
        self.is_target(TaskSet(goal as u8), h)
    }
    fn goal_move(&self, goal: usize, h: HState) -> Option<(ActionId, HState)> {
        Exportable::reactive_move(self, TaskSet(goal as u8), h)
    }
    fn step(&self, h: HState) -> Step {
        let payoffs = self.model.payoffs();
        Step::of(Controller::decide(self, h.as_u32()), |set| payoffs.get(set))
    }
    fn stuck_payoff(&self) -> f64 {
        self.model.payoffs().all()
    }
    fn is_worthless(&self, h: HState) -> bool {
        Exportable::is_worthless(self, h)
    }
    fn discount(&self) -> f64 {
        self.policy.discount()
    }
}
