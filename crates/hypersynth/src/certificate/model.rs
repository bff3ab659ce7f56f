//! The hypergame MDP of a controller file, re-derived from the file alone (docs/semantics.md
//! §9.4): the product states reachable from h0 under any move, the attractors `Win(T)` and
//! `Win(psi)`, the guarantees and levels, the adversary's weights, and the choices the MDP
//! enables (§6.3 in the paper's form, §8.5 in the general one).
//!
//! This is the checker's own reading of the semantics, written from the specification and not
//! from the MDP's build, which it must not trust: every rule below cites the section it follows.
//! Cost: linear in the product states reachable from h0 and their edges, once per set of
//! sub-tasks for the attractors; a dense index of one word per (arena state, tuple).

use bit_set::BitSet;

use crate::arena::{ActionId, Arena, Owner, StateId};
use crate::csr::Csr;
use crate::opportunistic::adversary::sigma_l_weights;
use crate::opportunistic::export::{ControllerFile, SigmaLRule};
use crate::opportunistic::load::Checked;
use crate::opportunistic::observations::{Counts, Region};
use crate::opportunistic::presentation::{Commitment, Presentation};
use crate::opportunistic::risk::Risk;

/// No node, no level.
pub(crate) const NONE: u32 = u32::MAX;

/// How far an estimated interval end of a learnt region is moved, outward for the lower
/// certificate and inward for the upper one (§9.4): 2^-40, far beyond the rounding error of
/// computing `p_hat ± e_s` in doubles (a few units in the last place of numbers at most 2 in
/// size, about 10^-15), so that the region checked contains the region of §10.2's real
/// numbers (outward) or lies within it (inward).
pub(crate) const REGION_MARGIN: f64 = 1.0 / (1u64 << 40) as f64;

/// What the MDP does at a robot state (§6.3, §8.5).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum RobotRule {
    /// Absorbing with this payoff.
    Absorbing(f64),
    /// A decision node: `stop` with its payoff when enabled, and the edges (indices into the
    /// node's edges) of the arena actions the risk rule allows.
    Decide {
        /// The payoff of `stop`, when it is enabled.
        stop: Option<f64>,
        /// The allowed arena actions, as indices of the node's edges.
        moves: Vec<usize>,
    },
}

/// The product of a controller file, with its regions and the adversary's weights.
pub(crate) struct Model<'c> {
    pub(crate) checked: &'c Checked,
    /// Per node: its arena state and tuple.
    pub(crate) nodes: Vec<(StateId, u32)>,
    /// Per (arena state, tuple) entry, its node (`NONE` if not reached).
    index: Vec<u32>,
    /// Per node, the range of its edges in `edges` and `weights`.
    starts: Vec<u32>,
    /// (action, successor node), in arena edge order per node.
    edges: Vec<(ActionId, u32)>,
    /// Per edge of an adversary node, the adversary model's weight (0: probability 0); 0 for
    /// a robot node's edges.
    weights: Vec<f64>,
    /// `Win(T)` per set (mask), `Win(psi)`.
    win: Vec<BitSet>,
    /// Per set (mask), each node's rank in `Win(T)` (`NONE` outside), and its targets.
    ranks: Vec<Vec<u32>>,
    targets: Vec<BitSet>,
    psi: BitSet,
    /// `r(T)` per mask.
    payoffs: Vec<f64>,
    /// The distinct payoffs with 0, ascending: a level is an index into it.
    levels: Vec<f64>,
    /// A learnt sigma_L's confidence region, and the adversary nodes where it rules.
    region: Option<Region>,
    learnt: BitSet,
}

/// Why a file's product cannot be built.
pub(crate) type ModelError = String;

impl<'c> Model<'c> {
    /// The product of `checked` reachable from h0 under any move, with its regions and
    /// weights.
    pub(crate) fn new(checked: &'c Checked) -> Result<Model<'c>, ModelError> {
        let file = &checked.file;
        let arena = &checked.arena;
        let tuples = file.tuples.len();
        let next = tuple_steps(checked);
        let initial: Vec<u32> = file.automata.iter().map(|a| a.initial).collect();
        let s0 = arena.initial();
        let letter0 = checked.letters[arena.label_id(s0) as usize];
        let t0: Vec<u32> = initial
            .iter()
            .zip(&file.automata)
            .map(|(&q, a)| a.step[q as usize][letter0])
            .collect();
        let t0 = *checked
            .tuples
            .get(&t0)
            .ok_or("the file's tuples lack the automata states of h0")?;
        let mut model = Model {
            checked,
            nodes: vec![(s0, t0 as u32)],
            index: vec![NONE; arena.num_states() * tuples],
            starts: vec![0],
            edges: Vec::new(),
            weights: Vec::new(),
            win: Vec::new(),
            ranks: Vec::new(),
            targets: Vec::new(),
            psi: BitSet::new(),
            payoffs: file.payoffs.clone(),
            levels: Vec::new(),
            region: match &file.sigma_l {
                SigmaLRule::Learnt { delta, counts } => {
                    let counts = Counts::from_entries(arena, counts);
                    let region = Region::new(&counts, *delta);
                    Some(region.map_err(|e| format!("the file's learnt sigma_L: {e}"))?)
                }
                _ => None,
            },
            learnt: BitSet::new(),
        };
        model.index[s0.index() * tuples + t0] = 0;
        let letters = file.labels.len();
        let mut u = 0;
        while u < model.nodes.len() {
            let (s, t) = model.nodes[u];
            for (a, s2) in arena.edges(s) {
                let letter = checked.letters[arena.label_id(s2) as usize];
                let t2 = next[t as usize * letters + letter];
                if t2 == NONE {
                    return Err(format!(
                        "the file's tuples lack the automata states reached by `{}` from `{}`",
                        arena.action_name(a),
                        model.name(u as u32)
                    ));
                }
                let entry = s2.index() * tuples + t2 as usize;
                if model.index[entry] == NONE {
                    model.index[entry] = model.nodes.len() as u32;
                    model.nodes.push((s2, t2));
                }
                model.edges.push((a, model.index[entry]));
            }
            model.starts.push(model.edges.len() as u32);
            u += 1;
        }
        model.regions();
        model.weigh()?;
        model.levels = std::iter::once(0.0)
            .chain(model.payoffs.iter().copied())
            .collect();
        model.levels.sort_by(f64::total_cmp);
        model.levels.dedup();
        Ok(model)
    }

    /// The number of nodes.
    pub(crate) fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Node `u`'s (arena state, tuple) entry, `s · |tuples| + t`.
    pub(crate) fn entry(&self, u: u32) -> usize {
        let (s, t) = self.nodes[u as usize];
        s.index() * self.checked.file.tuples.len() + t as usize
    }

    /// Node `u`'s name, `ARENA_STATE|q_1|…` (docs/semantics.md §8.3).
    pub(crate) fn name(&self, u: u32) -> String {
        let (s, t) = self.nodes[u as usize];
        let mut name = self.arena().name(s).to_string();
        for q in &self.checked.file.tuples[t as usize] {
            name.push('|');
            name.push_str(&q.to_string());
        }
        name
    }

    pub(crate) fn arena(&self) -> &Arena {
        &self.checked.arena
    }

    fn file(&self) -> &ControllerFile {
        &self.checked.file
    }

    /// Whether node `u` is the robot's.
    pub(crate) fn is_robot(&self, u: u32) -> bool {
        self.arena().owner(self.nodes[u as usize].0) == Owner::Robot
    }

    /// Node `u`'s edges: (action, successor node), in arena order.
    pub(crate) fn edges(&self, u: u32) -> &[(ActionId, u32)] {
        &self.edges[self.starts[u as usize] as usize..self.starts[u as usize + 1] as usize]
    }

    /// The adversary's weights on node `u`'s edges (all 0 at a robot node).
    pub(crate) fn weights(&self, u: u32) -> &[f64] {
        &self.weights[self.starts[u as usize] as usize..self.starts[u as usize + 1] as usize]
    }

    /// At an adversary node where a learnt sigma_L rules, its edges' probability intervals:
    /// the region's, each estimated end moved by [`REGION_MARGIN`] outward (`outward`, the
    /// lower certificate's region, which contains the true one) or inward (the upper
    /// certificate's, which the true one contains), then cut to `[0, 1]`; exact ends (`[0, 1]`
    /// unobserved, `[1, 1]` for a single action) as they are. `None` elsewhere.
    pub(crate) fn intervals(&self, u: u32, outward: bool) -> Option<Vec<[f64; 2]>> {
        let region = self
            .region
            .as_ref()
            .filter(|_| self.learnt.contains(u as usize))?;
        let s = self.nodes[u as usize].0;
        let shift = if outward {
            REGION_MARGIN
        } else {
            -REGION_MARGIN
        };
        let degree = self.edges(u).len();
        Some(
            (0..degree)
                .map(|e| match region.radius(s) {
                    Some(radius) => {
                        let p = region.estimate(s, e, degree);
                        [
                            ((p - radius) - shift).max(0.0),
                            ((p + radius) + shift).min(1.0),
                        ]
                    }
                    None => region.interval(s, e, degree),
                })
                .collect(),
        )
    }

    /// Whether node `u` is in `Win(T)`.
    pub(crate) fn wins(&self, set: u8, u: u32) -> bool {
        self.win[set as usize].contains(u as usize)
    }

    /// Node `u`'s rank in `Win(T)` (`NONE` outside).
    pub(crate) fn rank(&self, set: u8, u: u32) -> u32 {
        self.ranks[set as usize][u as usize]
    }

    /// Whether node `u` satisfies every sub-task of `T` (its automata are final).
    pub(crate) fn is_target(&self, set: u8, u: u32) -> bool {
        self.targets[set as usize].contains(u as usize)
    }

    /// `r(T)`.
    pub(crate) fn payoff(&self, set: u8) -> f64 {
        self.payoffs[set as usize]
    }

    /// `r(all)`, what a stuck adversary state pays.
    pub(crate) fn all(&self) -> f64 {
        self.payoffs[self.payoffs.len() - 1]
    }

    /// The guarantee `gr(u)`: the largest `r(T)` with `u ∈ Win(T)`, 0 if none (§8.4).
    pub(crate) fn guarantee(&self, u: u32) -> f64 {
        (1..self.payoffs.len())
            .filter(|&set| self.win[set].contains(u as usize))
            .map(|set| self.payoffs[set])
            .fold(0.0, f64::max)
    }

    /// The level of a robot node or a stuck adversary node (§8.5).
    fn level(&self, u: u32) -> u32 {
        let value = if self.is_robot(u) {
            self.guarantee(u)
        } else {
            self.all()
        };
        self.levels.partition_point(|&v| v < value) as u32
    }

    /// `Win(T)` for every set, `Win(psi)` (§5.1, §8.3): backward search with a counter per
    /// node of the successors still outside (1 for a robot node, its edges for an adversary
    /// node, so that a stuck adversary node joins every region at once).
    fn regions(&mut self) {
        let file = &self.checked.file;
        let n = self.nodes.len();
        let reverse: Csr<u32, u32> = Csr::group_from(n, || {
            (0..n as u32).flat_map(|u| self.edges(u).iter().map(move |&(_, t)| (t, u)))
        });
        // Per automaton, per state, whether it is final.
        let finals: Vec<Vec<bool>> = file
            .automata
            .iter()
            .map(|a| {
                let mut finals = vec![false; a.step.len()];
                for &q in &a.finals {
                    if let Some(slot) = finals.get_mut(q as usize) {
                        *slot = true;
                    }
                }
                finals
            })
            .collect();
        let is_final = |u: usize, i: usize| {
            let (_, t) = self.nodes[u];
            let q = file.tuples[t as usize][i] as usize;
            finals[i].get(q).copied().unwrap_or(false)
        };
        // Level by level (§5.1): the targets at rank 0; a state joins at rank k + 1 when some
        // (robot) or its last (adversary) successor joined at rank k; a stuck adversary state
        // outside the targets joins at rank 1.
        let attractor = |target: &dyn Fn(usize) -> bool| {
            let mut counters: Vec<usize> = (0..n as u32)
                .map(|u| match self.is_robot(u) {
                    true => 1,
                    false => self.edges(u).len(),
                })
                .collect();
            let mut ranks = vec![NONE; n];
            let mut layer: Vec<usize> = (0..n).filter(|&u| target(u)).collect();
            layer.iter().for_each(|&u| ranks[u] = 0);
            let mut rank = 0;
            // Rank 0 is always followed by rank 1, the stuck adversary states', even when
            // there are no targets.
            while rank == 0 || !layer.is_empty() {
                let mut next = Vec::new();
                if rank == 0 {
                    for u in 0..n {
                        if counters[u] == 0 && ranks[u] == NONE {
                            ranks[u] = 1;
                            next.push(u);
                        }
                    }
                }
                for &t in &layer {
                    for &p in reverse.row(t as u32) {
                        let p = p as usize;
                        if ranks[p] != NONE {
                            continue;
                        }
                        counters[p] -= 1;
                        if counters[p] == 0 {
                            ranks[p] = rank + 1;
                            next.push(p);
                        }
                    }
                }
                layer = next;
                rank += 1;
            }
            ranks
        };
        let k = file.tasks.len();
        let region = |ranks: &[u32]| -> BitSet { (0..n).filter(|&u| ranks[u] != NONE).collect() };
        let mut ranks = vec![vec![NONE; n]];
        for set in 1..1usize << k {
            ranks.push(attractor(&|u| {
                (0..k).filter(|i| set >> i & 1 == 1).all(|i| is_final(u, i))
            }));
        }
        let win: Vec<BitSet> = ranks.iter().map(|r| region(r)).collect();
        let psi = match (file.believed.set, file.believed.automaton) {
            (Some(set), _) => win[set as usize].clone(),
            _ => region(&attractor(&|u| is_final(u, k))),
        };
        let targets = (0..1usize << k)
            .map(|set| {
                (0..n)
                    .filter(|&u| {
                        set > 0 && (0..k).filter(|i| set >> i & 1 == 1).all(|i| is_final(u, i))
                    })
                    .collect()
            })
            .collect();
        (self.win, self.psi, self.targets, self.ranks) = (win, psi, targets, ranks);
    }

    /// The adversary's weight on every edge of every adversary node (§6.2): outside
    /// `Win(psi)`, 1 on each safe action (its successor outside `Win(psi)`) and 0 on the
    /// others, when there is a safe action; elsewhere sigma_L's weights, from the adversary
    /// model's one definition of them (a learnt sigma_L: 1 on every action, its support, and
    /// the node is marked as one where the region rules, §10.2).
    fn weigh(&mut self) -> Result<(), ModelError> {
        let arena = &self.checked.arena;
        let sigma_l = sigma_l_weights(arena, &self.checked.file.sigma_l.to_sigma_l())
            .map_err(|errors| format!("the file's sigma_L: {errors}"))?;
        let mut weights = vec![0.0; self.edges.len()];
        for u in 0..self.nodes.len() as u32 {
            if self.is_robot(u) {
                continue;
            }
            let start = self.starts[u as usize] as usize;
            let edges = self.edges(u);
            let safe = |t: u32| !self.psi.contains(t as usize);
            if !self.psi.contains(u as usize) && edges.iter().any(|&(_, t)| safe(t)) {
                for (i, &(_, t)) in edges.iter().enumerate() {
                    weights[start + i] = if safe(t) { 1.0 } else { 0.0 };
                }
                continue;
            }
            let row = sigma_l.row(self.nodes[u as usize].0);
            weights[start..start + edges.len()].copy_from_slice(row);
            if self.region.is_some() {
                self.learnt.insert(u as usize);
            }
        }
        self.weights = weights;
        Ok(())
    }

    /// Per node, the least level of the next robot node or stuck adversary node reached
    /// through adversary moves of positive probability (the node's own where it is one;
    /// `NONE`: none is reached), §8.5.
    fn least_next_levels(&self) -> Vec<u32> {
        self.waves(false, true)
    }

    /// Per node, the greatest level of a robot node or stuck adversary node reachable through
    /// any robot move and the adversary's moves of positive probability, §8.5.
    fn greatest_reachable_levels(&self) -> Vec<u32> {
        self.waves(true, false)
    }

    /// Levels spread backwards from the robot nodes and stuck adversary nodes, in increasing
    /// (`ascending`) or decreasing order of level, each node keeping the first it meets:
    /// through adversary moves of positive probability, and robot moves too with
    /// `robot_moves`.
    fn waves(&self, robot_moves: bool, ascending: bool) -> Vec<u32> {
        let n = self.nodes.len();
        let reverse: Csr<u32, u32> = Csr::group_from(n, || {
            (0..n as u32)
                .filter(|&u| robot_moves || !self.is_robot(u))
                .flat_map(|u| {
                    let robot = self.is_robot(u);
                    (self.edges(u).iter().zip(self.weights(u)))
                        .filter(move |&(_, &w)| robot || w > 0.0)
                        .map(move |(&(_, t), _)| (t, u))
                })
        });
        let mut sources: Vec<(u32, u32)> = (0..n as u32)
            .filter(|&u| self.is_robot(u) || self.edges(u).is_empty())
            .map(|u| (self.level(u), u))
            .collect();
        sources.sort_unstable_by_key(|&(level, u)| (if ascending { level } else { !level }, u));
        let mut found = vec![NONE; n];
        let mut queue = Vec::new();
        for (i, &(level, u)) in sources.iter().enumerate() {
            if found[u as usize] == NONE {
                found[u as usize] = level;
                queue.push(u);
            }
            if sources.get(i + 1).is_some_and(|&(next, _)| next == level) {
                continue;
            }
            while let Some(t) = queue.pop() {
                for &p in reverse.row(t) {
                    if found[p as usize] == NONE {
                        found[p as usize] = level;
                        queue.push(p);
                    }
                }
            }
        }
        found
    }

    /// What the MDP does at every robot node (`None` at adversary nodes).
    pub(crate) fn robot_rules(&self) -> Vec<Option<RobotRule>> {
        let file = self.file();
        let next = self.least_next_levels();
        let commitment = Presentation::of_form(file.form, file.tasks.clone()).commitment();
        let greatest = match commitment {
            Commitment::NothingBetter => Some(self.greatest_reachable_levels()),
            Commitment::Labels => None,
        };
        let all = (self.payoffs.len() - 1) as u8;
        (0..self.nodes.len() as u32)
            .map(|u| {
                if !self.is_robot(u) {
                    return None;
                }
                let guarantee = self.guarantee(u);
                let own = self.level(u);
                // §6.3: absorbing in Win(phi) and outside Win(psi) with a positive guarantee;
                // §8.5: absorbing where no greater level can be reached.
                let absorbing = match &greatest {
                    None => {
                        self.wins(all, u) || (!self.psi.contains(u as usize) && guarantee > 0.0)
                    }
                    Some(greatest) => greatest[u as usize] <= own,
                };
                if absorbing {
                    return Some(RobotRule::Absorbing(guarantee));
                }
                if self.edges(u).is_empty() && own == 0 {
                    return Some(RobotRule::Absorbing(0.0));
                }
                let moves = (0..self.edges(u).len())
                    .filter(|&i| {
                        let least = next[self.edges(u)[i].1 as usize];
                        least == NONE
                            || match file.risk {
                                Risk::Paper => own == 0 || least > 0,
                                Risk::Strict => least >= own,
                                Risk::Neutral => true,
                            }
                    })
                    .collect();
                let stop = (own > 0).then_some(guarantee);
                Some(RobotRule::Decide { stop, moves })
            })
            .collect()
    }
}

/// For every (tuple, letter), the tuple the automata move to (`NONE` if the file lacks it).
fn tuple_steps(checked: &Checked) -> Vec<u32> {
    let file = &checked.file;
    let letters = file.labels.len();
    let mut next = Vec::with_capacity(file.tuples.len() * letters);
    for tuple in &file.tuples {
        for letter in 0..letters {
            let stepped: Vec<u32> = tuple
                .iter()
                .zip(&file.automata)
                .map(|(&q, a)| a.step[q as usize][letter])
                .collect();
            next.push(checked.tuples.get(&stepped).map_or(NONE, |&t| t as u32));
        }
    }
    next
}
