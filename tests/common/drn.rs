//! A reader of the DRN files `--export-mdp` writes, in either form and with plain or interval
//! probabilities, and the value Storm would give them, by naive value iteration: the maximal
//! total reward (reward form) or `r_max` times the maximal probability of reaching `goal`
//! (reachability form), the adversary taking, at every action with intervals, the worst
//! distribution within them. It shares no code with the library.

/// A DRN model: per state its labels and actions; `r_max` from the reachability form's first
/// comment line.
pub struct Drn {
    pub scale: Option<f64>,
    pub states: Vec<State>,
}

pub struct State {
    pub labels: Vec<String>,
    pub actions: Vec<Action>,
}

pub struct Action {
    pub reward: f64,
    /// Per successor, its probability interval (`[p, p]` for a plain probability).
    pub transitions: Vec<(usize, [f64; 2])>,
}

impl Drn {
    /// Reads `text`, panicking on anything the writer never writes.
    pub fn parse(text: &str) -> Drn {
        let scale = text.lines().next().and_then(|line| {
            let (_, rest) = line.split_once("reachability form: ")?;
            Some(rest.split(' ').next()?.parse().unwrap())
        });
        let mut states: Vec<State> = Vec::new();
        let model = text.split_once("@model\n").expect("a @model section").1;
        for line in model.lines().filter(|l| !l.starts_with("//")) {
            if let Some(rest) = line.strip_prefix("state ") {
                let mut words = rest.split(' ');
                let id: usize = words.next().unwrap().parse().unwrap();
                assert_eq!(id, states.len());
                states.push(State {
                    labels: words.map(str::to_owned).collect(),
                    actions: Vec::new(),
                });
            } else if let Some(rest) = line.strip_prefix("\taction ") {
                let reward = rest
                    .split_once(" [")
                    .map_or(0.0, |(_, r)| r.strip_suffix(']').unwrap().parse().unwrap());
                states.last_mut().unwrap().actions.push(Action {
                    reward,
                    transitions: Vec::new(),
                });
            } else {
                let (target, p) = line.trim_start().split_once(" : ").unwrap();
                let bounds = match p.strip_prefix('[') {
                    Some(p) => {
                        let (l, u) = p.strip_suffix(']').unwrap().split_once(',').unwrap();
                        [l.parse().unwrap(), u.parse().unwrap()]
                    }
                    None => [p.parse().unwrap(); 2],
                };
                let action = states.last_mut().unwrap().actions.last_mut().unwrap();
                action.transitions.push((target.parse().unwrap(), bounds));
            }
        }
        Drn { scale, states }
    }

    /// The value of the state labelled `init` as Storm defines it for this form (see the
    /// module documentation), by value iteration from 0 until nothing moves by 1e-13.
    pub fn initial_value(&self) -> f64 {
        let is = |s: &State, label: &str| s.labels.iter().any(|l| l == label);
        let mut values = vec![0.0; self.states.len()];
        for _ in 0..1_000_000 {
            let mut change = 0.0f64;
            for i in 0..self.states.len() {
                let state = &self.states[i];
                let next = if is(state, "goal") {
                    1.0
                } else {
                    state
                        .actions
                        .iter()
                        .map(|a| a.reward + worst(&a.transitions, &values))
                        .fold(0.0, f64::max)
                };
                change = change.max((next - values[i]).abs());
                values[i] = next;
            }
            if change < 1e-13 {
                break;
            }
        }
        let init = self.states.iter().position(|s| is(s, "init")).unwrap();
        values[init] * self.scale.unwrap_or(1.0)
    }
}

/// The least expectation of `values` over the distributions within the intervals: every
/// successor at its lower bound, the rest of the mass to the successors of least value first.
fn worst(transitions: &[(usize, [f64; 2])], values: &[f64]) -> f64 {
    let mut order: Vec<&(usize, [f64; 2])> = transitions.iter().collect();
    order.sort_by(|a, b| values[a.0].total_cmp(&values[b.0]));
    let mut left = 1.0 - transitions.iter().map(|t| t.1[0]).sum::<f64>();
    let mut sum = 0.0;
    for &&(target, [lower, upper]) in &order {
        let more = (upper - lower).min(left.max(0.0));
        left -= more;
        sum += (lower + more) * values[target];
    }
    sum
}
