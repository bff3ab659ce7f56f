//! The dynamics of the Gymnasium environment (`Dynamics`): a play of the solved hypergame MDP
//! stepped one robot move at a time, the adversary's moves drawn from its model (or from a
//! Python callable) until the robot's turn or absorption. `hypersynth.gym` wraps it in a
//! `gymnasium.Env`; nothing here needs Gymnasium.
//!
//! The rules are the MDP's (`opportunistic::build`): the robot's enabled actions at a decision
//! node are its choices (arena moves and `stop`); an arena move is one robot move (discounted),
//! `stop` and the adversary's moves are instant; an absorbing MDP state pays its payoff. So a
//! step's reward is `g · payoff` when the robot's move (and the adversary's answer) ends in an
//! absorbing state, the payoff at once on `stop`, 0 otherwise: with gamma = g, the expected
//! return of a policy is the MDP's value of it.
//!
//! Randomness, as the library's simulations draw it: ChaCha8 seeded with the seed, one
//! `opportunistic::simulate::draw` per adversary move (from the model's distribution, or from
//! the callable's answer).

use std::sync::Arc;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyMapping, PyTuple};
use rand_chacha::ChaCha8Rng;
use rand_core::SeedableRng;

use hypersynth::arena::gridworld::Layout;
use hypersynth::arena::{ActionId, Owner, StateId};
use hypersynth::game::HState;
use hypersynth::mdp::{ChoiceId, MdpState};
use hypersynth::opportunistic::observations::run_line;
use hypersynth::opportunistic::simulate::draw;
use hypersynth::opportunistic::view::GameView;

use crate::errors::{OptionsError, exception};
use crate::solution::Solution;

/// Where an episode is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// The robot is to move at a decision node.
    Robot,
    /// The play is absorbed before the robot's first move: only `stop` is enabled, and it
    /// collects the absorbing state's payoff.
    Absorbed,
    /// The step bound was reached before the robot's turn: the next step truncates.
    Bounded,
    /// The episode ended (`outcome` says how).
    Ended,
}

/// The positive-probability edges of the adversary's model at every chance node: for product
/// state `h`, `edges[starts[h]..starts[h + 1]]` are the indices of its edges the MDP's chance
/// choice lists, in its order.
struct ChanceEdges {
    starts: Vec<u32>,
    edges: Vec<u32>,
}

/// The play of a solved problem, one robot move per `step` (see the module documentation):
/// `reset`, then `step(action)` with the index of an action in `actions` (the arena's, then
/// `stop`) until `terminated` or `truncated`. `hypersynth.gym.HypergameEnv` wraps it in a
/// Gymnasium environment.
///
/// >>> dynamics = hs.Dynamics(solution)
/// >>> dynamics.reset(seed=1)
/// >>> dynamics.state
/// '((0,2),(4,2),0)|0|0'
/// >>> reward, terminated, truncated = dynamics.step(dynamics.actions.index("stop"))
/// >>> reward, terminated, dynamics.outcome
/// (200.0, True, 'stop')
#[pyclass(module = "hypersynth")]
pub(crate) struct Dynamics {
    solution: Py<Solution>,
    adversary: Option<Py<PyAny>>,
    chance: Arc<ChanceEdges>,
    layout: Option<Arc<Layout>>,
    max_steps: u32,
    rng: ChaCha8Rng,
    /// The current MDP state (a decision node, an absorbing state, or a sink after `stop`).
    node: MdpState,
    /// The current product state.
    h: HState,
    phase: Phase,
    outcome: Option<&'static str>,
    /// Moves of either player, and robot moves, so far.
    steps: u32,
    moves: u32,
    /// The arena states entered since the previous observation.
    passed: Vec<StateId>,
    /// The episode's moves (arena state, action), for `run`.
    run: Vec<(StateId, ActionId)>,
}

impl Dynamics {
    fn with<T>(&self, py: Python<'_>, f: impl FnOnce(&Solution) -> T) -> T {
        f(self.solution.bind(py).get())
    }

    /// The choice of decision node `node` that plays `action` (an index of `actions`).
    fn choice(&self, solution: &Solution, action: usize) -> Option<ChoiceId> {
        let opportunistic = solution.opportunistic();
        let (hmdp, mdp) = (&opportunistic.mdp, opportunistic.mdp.mdp());
        let stop = solution.solved().problem.arena.actions().len();
        mdp.choices(self.node)
            .find(|&c| match hmdp.arena_action(c) {
                Some(a) => a as usize == action,
                None => action == stop,
            })
    }

    /// Enters product state `t` (its MDP state) and lets the adversary move until the robot's
    /// turn or absorption; the payoff collected (undiscounted) when absorbed.
    fn settle(&mut self, py: Python<'_>, t: HState) -> PyResult<Option<f64>> {
        let solution = self.solution.clone_ref(py);
        let solution = solution.bind(py).get();
        let opportunistic = solution.opportunistic();
        let (hmdp, mdp) = (&opportunistic.mdp, opportunistic.mdp.mdp());
        let product = &solution.solved().product;
        let mut h = t;
        loop {
            self.h = h;
            self.node = hmdp.node(h);
            self.passed.push(product.arena_state(h));
            if mdp.is_absorbing(self.node) {
                return Ok(Some(mdp.payoff(self.node).unwrap_or(0.0)));
            }
            if product.owner(h) == Owner::Robot {
                return Ok(None);
            }
            if self.steps >= self.max_steps {
                return Ok(None);
            }
            let (edge, next) = self.adversary_move(py, solution, h)?;
            let state = product.arena_state(h);
            self.run.push((state, edge));
            self.steps += 1;
            h = next;
        }
    }

    /// The adversary's move at chance node `h`: drawn from the model, or from the callable's
    /// answer.
    fn adversary_move(
        &mut self,
        py: Python<'_>,
        solution: &Solution,
        h: HState,
    ) -> PyResult<(ActionId, HState)> {
        let product = &solution.solved().product;
        let edges: Vec<(ActionId, HState)> = product.edges(h).collect();
        let Some(adversary) = &self.adversary else {
            let opportunistic = solution.opportunistic();
            let mdp = opportunistic.mdp.mdp();
            let choice = mdp.choices(opportunistic.mdp.node(h)).start();
            let range =
                self.chance.starts[h.index()] as usize..self.chance.starts[h.index() + 1] as usize;
            let positive = &self.chance.edges[range];
            let index = draw(&mut self.rng, mdp.probabilities(choice))
                .expect("the model gives some move positive probability");
            return Ok(edges[positive[index] as usize]);
        };
        let arena = product.arena();
        let names: Vec<&str> = edges.iter().map(|&(a, _)| arena.action_name(a)).collect();
        let state = arena.name(product.arena_state(h));
        let answer = adversary
            .bind(py)
            .call1((state, PyTuple::new(py, &names)?))?;
        let bad = |what: String| {
            exception::<OptionsError>(
                format!(
                    "adversary: at `{state}` it answered {what}; give one of {} or a mapping of them to weights",
                    names.join(", ")
                ),
                None,
                None,
            )
        };
        let mut weights = vec![0.0; names.len()];
        if let Ok(name) = answer.extract::<String>() {
            let index = names
                .iter()
                .position(|n| *n == name)
                .ok_or_else(|| bad(format!("`{name}`")))?;
            // A certain move is drawn too, so that the stream advances once per move.
            weights[index] = 1.0;
            let index = draw(&mut self.rng, &weights).expect("one weight is 1");
            return Ok(edges[index]);
        }
        let mapping = answer
            .cast::<PyMapping>()
            .map_err(|_| bad(answer.repr().map_or_else(|_| "?".into(), |r| r.to_string())))?;
        for item in mapping.items()?.iter() {
            let (name, weight): (String, f64) = item.extract()?;
            let index = names
                .iter()
                .position(|n| *n == name)
                .ok_or_else(|| bad(format!("a weight for `{name}`")))?;
            if !hypersynth::opportunistic::adversary::is_weight(weight) {
                return Err(bad(format!("the weight {weight} for `{name}`")));
            }
            weights[index] = weight;
        }
        let total: f64 = weights.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return Err(bad("weights that are all 0".to_string()));
        }
        for w in &mut weights {
            *w /= total;
        }
        let index = draw(&mut self.rng, &weights).expect("some weight is positive");
        Ok(edges[index])
    }

    fn end(&mut self, outcome: &'static str) {
        self.phase = Phase::Ended;
        self.outcome = Some(outcome);
    }
}

#[pymethods]
impl Dynamics {
    /// The play of `solution` (see the class); `adversary`, when given, replaces the model:
    /// called as `adversary(state, actions)` with the arena state's name and its enabled
    /// actions' names at each adversary move, it answers an action's name or a mapping of
    /// names to weights (drawn from with the seeded stream). `max_steps` bounds the moves of
    /// either player in an episode (it is then truncated). The stream starts seeded with the
    /// solve's seed.
    ///
    /// >>> hs.Dynamics(solution, adversary=lambda state, actions: actions[0]).max_steps
    /// 1000
    #[new]
    #[pyo3(signature = (solution, adversary = None, max_steps = 1000))]
    fn new(
        py: Python<'_>,
        solution: Bound<'_, Solution>,
        adversary: Option<Py<PyAny>>,
        max_steps: u32,
    ) -> PyResult<Dynamics> {
        if let Some(adversary) = &adversary
            && !adversary.bind(py).is_callable()
        {
            return Err(exception::<OptionsError>(
                "adversary: give a callable adversary(state, actions)",
                None,
                None,
            ));
        }
        let this = solution.get();
        this.explicit_only("Dynamics")?;
        let solved = this.solved();
        let opportunistic = this.opportunistic();
        // The model's positive edges at each chance node, in the MDP's order.
        let game = solved.game();
        let mut chance = ChanceEdges {
            starts: Vec::with_capacity(game.num_states() + 1),
            edges: Vec::new(),
        };
        let mut distribution = Vec::new();
        for h in game.states() {
            chance.starts.push(chance.edges.len() as u32);
            opportunistic
                .adversary
                .distribution(&game, h, &mut distribution);
            let positive = distribution.iter().enumerate().filter(|&(_, &p)| p > 0.0);
            chance.edges.extend(positive.map(|(e, _)| e as u32));
        }
        chance.starts.push(chance.edges.len() as u32);
        let layout = match &solved.problem.map {
            Some(map) => {
                Some(Arc::new(map.layout().map_err(|e| {
                    exception::<OptionsError>(e.to_string(), None, None)
                })?))
            }
            None => None,
        };
        let initial = solved.product.initial();
        Ok(Dynamics {
            adversary,
            chance: Arc::new(chance),
            layout,
            max_steps,
            rng: ChaCha8Rng::seed_from_u64(opportunistic.options.seed),
            node: opportunistic.mdp.node(initial),
            h: initial,
            phase: Phase::Ended,
            outcome: None,
            steps: 0,
            moves: 0,
            passed: Vec::new(),
            run: Vec::new(),
            solution: solution.unbind(),
        })
    }

    /// Starts an episode in h0, the adversary moving first if it owns h0; `seed` seeds the
    /// random stream (otherwise it goes on).
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> dynamics.moves, dynamics.passed
    /// (0, ['((0,2),(4,2),0)'])
    #[pyo3(signature = (seed = None))]
    fn reset(&mut self, py: Python<'_>, seed: Option<u64>) -> PyResult<()> {
        if let Some(seed) = seed {
            self.rng = ChaCha8Rng::seed_from_u64(seed);
        }
        self.steps = 0;
        self.moves = 0;
        self.outcome = None;
        self.passed.clear();
        self.run.clear();
        let initial = self.with(py, |s| s.solved().product.initial());
        self.phase = match self.settle(py, initial)? {
            Some(_) => Phase::Absorbed,
            None if self.is_robot_turn(py) && self.steps < self.max_steps => Phase::Robot,
            None => Phase::Bounded,
        };
        Ok(())
    }

    /// Plays the robot's action `action` (an index of `actions`), then the adversary's moves;
    /// returns `(reward, terminated, truncated)`. A masked action (not enabled here, see
    /// `action_mask`) ends the episode with reward 0 (`outcome` `"masked action"`), as giving
    /// up does.
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> dynamics.step(dynamics.actions.index("S"))
    /// (0.0, True, False)
    /// >>> dynamics.outcome
    /// 'masked action'
    fn step(&mut self, py: Python<'_>, action: usize) -> PyResult<(f64, bool, bool)> {
        if self.phase == Phase::Ended {
            return Err(exception::<OptionsError>(
                "the episode has ended: reset() starts another",
                None,
                None,
            ));
        }
        self.passed.clear();
        if self.phase == Phase::Bounded {
            self.end("step bound");
            return Ok((0.0, false, true));
        }
        let stop = self.with(py, |s| s.solved().problem.arena.actions().len());
        if self.phase == Phase::Absorbed {
            if action != stop {
                self.end("masked action");
                return Ok((0.0, true, false));
            }
            let payoff = self.with(py, |s| {
                s.opportunistic().mdp.mdp().payoff(self.node).unwrap_or(0.0)
            });
            self.end("absorbed");
            return Ok((payoff, true, false));
        }
        let Some(choice) = self.with(py, |s| self.choice(s, action)) else {
            self.end("masked action");
            return Ok((0.0, true, false));
        };
        let (target, g) = self.with(py, |s| {
            let mdp = s.opportunistic().mdp.mdp();
            let target = mdp.targets(choice)[0];
            (target, s.opportunistic().options.solve.discount.get())
        });
        if action == stop {
            let payoff = self.with(py, |s| s.opportunistic().mdp.mdp().payoff(target));
            self.node = target;
            self.end("stop");
            return Ok((payoff.unwrap_or(0.0), true, false));
        }
        let state = self.with(py, |s| s.solved().product.arena_state(self.h));
        self.run.push((state, action as ActionId));
        self.moves += 1;
        self.steps += 1;
        let next = self.with(py, |s| s.opportunistic().mdp.product_state(target));
        let next = next.expect("an arena move leads to a product state");
        match self.settle(py, next)? {
            Some(payoff) => {
                self.end("absorbed");
                Ok((g * payoff, true, false))
            }
            None if self.is_robot_turn(py) && self.steps < self.max_steps => {
                Ok((0.0, false, false))
            }
            None => {
                self.end("step bound");
                Ok((0.0, false, true))
            }
        }
    }

    /// The actions' names: the arena's, then `stop` (the indices `step` takes).
    ///
    /// >>> hs.Dynamics(solution).actions
    /// ['N', 'S', 'E', 'W', 'NE', 'NW', 'SE', 'SW', 'STAY', 'stop']
    #[getter]
    fn actions(&self, py: Python<'_>) -> Vec<String> {
        self.with(py, |s| {
            let mut actions = s.solved().problem.arena.actions().to_vec();
            actions.push(hypersynth::opportunistic::build::STOP.to_string());
            actions
        })
    }

    /// Per action, whether it is enabled now (1) or masked (0), as an `int8` NumPy array (all
    /// 0 once the episode ended).
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> [a for a, m in zip(dynamics.actions, dynamics.action_mask) if m]
    /// ['N', 'E', 'NE', 'stop']
    #[getter]
    fn action_mask<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i8>> {
        let mask = self.with(py, |s| {
            let stop = s.solved().problem.arena.actions().len();
            let mut mask = vec![0i8; stop + 1];
            match self.phase {
                Phase::Ended | Phase::Bounded => {}
                Phase::Absorbed => mask[stop] = 1,
                Phase::Robot => {
                    let opportunistic = s.opportunistic();
                    for c in opportunistic.mdp.mdp().choices(self.node) {
                        match opportunistic.mdp.arena_action(c) {
                            Some(a) => mask[a as usize] = 1,
                            None => mask[stop] = 1,
                        }
                    }
                }
            }
            mask
        });
        PyArray1::from_vec(py, mask)
    }

    /// The product state's name (`ARENA_STATE|Q1|Q2`).
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> dynamics.state
    /// '((0,2),(4,2),0)|0|0'
    #[getter]
    fn state(&self, py: Python<'_>) -> String {
        self.with(py, |s| s.solved().product.name(self.h))
    }

    /// The index of the product state in the solution's arrays.
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> dynamics.state_index == solution.state_index("h0")
    /// True
    #[getter]
    fn state_index(&self) -> usize {
        self.h.index()
    }

    /// The arena state's index (`Arena.names` order).
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> problem.arena.names[dynamics.arena_state]
    /// '((0,2),(4,2),0)'
    #[getter]
    fn arena_state(&self, py: Python<'_>) -> usize {
        self.with(py, |s| s.solved().product.arena_state(self.h).index())
    }

    /// The automata's states (one per automaton of the product: the sub-tasks', then the
    /// believed task's when it has its own).
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> dynamics.automata
    /// [0, 0]
    #[getter]
    fn automata(&self, py: Python<'_>) -> Vec<u32> {
        self.with(py, |s| {
            let product = &s.solved().product;
            (0..product.num_automata())
                .map(|i| product.automaton_state(self.h, i))
                .collect()
        })
    }

    /// The number of states of each automaton (the bounds of `automata`).
    ///
    /// >>> hs.Dynamics(solution).automata_sizes
    /// [3, 3]
    #[getter]
    fn automata_sizes(&self, py: Python<'_>) -> Vec<u32> {
        self.with(py, |s| {
            s.solved()
                .problem
                .tasks
                .automata()
                .iter()
                .map(|(_, dfa)| dfa.num_states() as u32)
                .collect()
        })
    }

    /// The number of arena states (the bound of `arena_state`).
    ///
    /// >>> hs.Dynamics(solution).num_arena_states
    /// 800
    #[getter]
    fn num_arena_states(&self, py: Python<'_>) -> usize {
        self.with(py, |s| s.solved().problem.arena.num_states())
    }

    /// On a map, the robot's and the adversary's cells `(rx, ry, ax, ay)`; None otherwise.
    ///
    /// >>> hs.Dynamics(solution).cells is None
    /// True
    #[getter]
    fn cells(&self, py: Python<'_>) -> Option<(u32, u32, u32, u32)> {
        let layout = self.layout.as_ref()?;
        let state = self.with(py, |s| s.solved().product.arena_state(self.h));
        let (robot, adversary, _) = layout.cells(state);
        Some((robot.x, robot.y, adversary.x, adversary.y))
    }

    /// On a map, its width and height; None otherwise.
    ///
    /// >>> hs.Dynamics(solution).grid is None
    /// True
    #[getter]
    fn grid(&self, py: Python<'_>) -> Option<(u32, u32)> {
        self.with(py, |s| {
            let map = s.solved().problem.map.as_ref()?;
            Some((map.width, map.height))
        })
    }

    /// The arena states entered since the previous observation (since h0 after `reset`), the
    /// current one last: what a controller must be told (`Controller.as_policy` reads them).
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> _ = dynamics.step(dynamics.actions.index("N"))
    /// >>> dynamics.passed
    /// ['((0,3),(4,2),1)', '((0,3),(3,2),0)']
    #[getter]
    fn passed(&self, py: Python<'_>) -> Vec<String> {
        self.with(py, |s| {
            let arena = &s.solved().problem.arena;
            self.passed
                .iter()
                .map(|&state| arena.name(state).to_string())
                .collect()
        })
    }

    /// The robot's moves in this episode (`stop` is not one).
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> dynamics.moves
    /// 0
    #[getter]
    fn moves(&self) -> u32 {
        self.moves
    }

    /// The moves of either player in this episode (bounded by `max_steps`).
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> _ = dynamics.step(dynamics.actions.index("N"))
    /// >>> dynamics.steps
    /// 2
    #[getter]
    fn steps(&self) -> u32 {
        self.steps
    }

    /// The discount per robot move of the solution (the gamma under which the expected return
    /// is the MDP's value).
    ///
    /// >>> hs.Dynamics(solution).discount
    /// 0.99
    #[getter]
    fn discount(&self, py: Python<'_>) -> f64 {
        self.with(py, |s| s.opportunistic().options.solve.discount.get())
    }

    /// The most moves of either player in an episode.
    ///
    /// >>> hs.Dynamics(solution, max_steps=50).max_steps
    /// 50
    #[getter]
    fn max_steps(&self) -> u32 {
        self.max_steps
    }

    /// How the episode ended: `"stop"` (the robot settled), `"absorbed"` (an absorbing state
    /// was reached: a commitment, a stuck player), `"masked action"`, `"step bound"`; None
    /// while it goes on.
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> dynamics.outcome is None
    /// True
    #[getter]
    fn outcome(&self) -> Option<&'static str> {
        self.outcome
    }

    /// The episode so far as one run of the observations format (arena states and actions of
    /// both players, `stop` left out), which `Problem.solve(observations=...)` learns from.
    ///
    /// >>> dynamics = hs.Dynamics(solution)
    /// >>> dynamics.reset(seed=1)
    /// >>> _ = dynamics.step(dynamics.actions.index("N"))
    /// >>> dynamics.run
    /// '"((0,2),(4,2),0)" N "((0,3),(4,2),1)" W "((0,3),(3,2),0)"'
    #[getter]
    fn run(&self, py: Python<'_>) -> String {
        self.with(py, |s| {
            let product = &s.solved().product;
            run_line(product.arena(), &self.run, product.arena_state(self.h))
        })
    }

    /// Its solution, episode and bound.
    ///
    /// >>> hs.Dynamics(solution)
    /// <hypersynth.Dynamics at '((0,2),(4,2),0)|0|0', 0 robot moves, max_steps 1000>
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "<hypersynth.Dynamics at {:?}, {} robot moves, max_steps {}>",
            self.state(py),
            self.moves,
            self.max_steps
        )
        .replace('"', "'")
    }
}

impl Dynamics {
    fn is_robot_turn(&self, py: Python<'_>) -> bool {
        self.with(py, |s| s.solved().product.owner(self.h) == Owner::Robot)
    }
}
