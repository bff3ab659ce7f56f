//! The explorer page of a solved problem on a map ([`explorer`]): what the pictures show for
//! one slice, for every slice the page can afford, with the decision tables, the seeded run and
//! the tables the page's play mode answers from.
//!
//! Every number comes from the one solution of the run, either engine's ([`page_on`] reads it
//! through [`Shown`] and [`Controlled`]): tags and the legend as the pictures make them
//! ([`Figures`]), decisions and the reactive strategies' moves from the controller as its
//! export reads it ([`Exportable`]: what the exported controller holds, so that the page's
//! answers are `hypersynth execute`'s), decision tables and the traced run from the
//! controller, the headline from the report.
//!
//! **Size.** The page covers every slice (every automata tuple, every adversary cell) up to
//! [`ALL_SLICES`] robot states (a 24×24 map: 1.3 million), with the decisions, values and play
//! mode; beyond, the slices of h0's automata tuple (labels, decisions and values, no play), and
//! beyond [`ALL_SLICES`] robot states per tuple only h0's slice. Decision tables are embedded
//! for every covered robot state up to [`ALL_TABLES`] of them, else for h0's slice and the run.
//! The page says what it leaves out.

use std::collections::HashMap;

use super::opportunistic::trace_rows;
use super::picture::{Figures, PictureSubject, explicit, settings};
use super::shown::{Controlled, Shown};
use super::tasks::Tasks;
use crate::arena::Owner;
use crate::arena::gridworld::{Cell, Collision, Gridworld, GridworldError, Layout};
use crate::explorer::{self, Automaton, Choice, Grid, Move, Page, Run, RunStep, Slices, Start};
use crate::game::{HState, TaskSet};
use crate::implicit::PolicyError;
use crate::opportunistic::controller::Decision;
use crate::opportunistic::export::{Exportable, Table, automaton_table};
use crate::render::{self, RenderError};
use crate::report::{self, Report, number};

/// The most robot states whose slices the page covers with decisions, values and play.
pub const ALL_SLICES: usize = 2_000_000;

/// The most robot states whose decision tables the page embeds all.
pub const ALL_TABLES: usize = 50_000;

/// Why the page cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum ExplorerError {
    /// The arena is a text arena, not a map.
    #[error(
        "the explorer needs a map (a file starting with `{}`), not a text arena",
        crate::arena::map::HEADER
    )]
    NotAMap,
    /// The map has no layout.
    #[error(transparent)]
    Gridworld(#[from] GridworldError),
    /// A slice could not be listed (never for the slices of the problem's own product).
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The data could not be serialised.
    #[error("cannot serialise the explorer's data: {0}")]
    Json(#[from] serde_json::Error),
    /// A decision table's expected moves were not certified.
    #[error(transparent)]
    Table(#[from] PolicyError),
}

/// The explorer page (HTML) of `subject`, whose report is `report`.
pub fn explorer(subject: &PictureSubject, report: &Report) -> Result<String, ExplorerError> {
    Ok(explorer::html(&page(subject, report)?)?)
}

/// The explorer's data of `subject`.
pub fn page(subject: &PictureSubject, report: &Report) -> Result<Page, ExplorerError> {
    let about = About {
        map_name: subject.map_name,
        map: subject.map,
        tasks: subject.tasks,
        report,
    };
    explicit(subject, |shown, solved| page_on(&about, shown, solved))
}

/// What a page is of besides the product and the controller: the map, its name, the tasks
/// and the run's report.
pub(super) struct About<'a> {
    /// The map's name in the page's heading (its file).
    pub(super) map_name: &'a str,
    /// The map, if the arena is one.
    pub(super) map: Option<&'a Gridworld>,
    /// The tasks, in product order, with their form.
    pub(super) tasks: &'a Tasks,
    /// The report of the run.
    pub(super) report: &'a Report,
}

/// The explorer's data of the problem `about` describes, solved into `shown` and (unless games
/// only) the controller `solved`: either engine's.
pub(super) fn page_on(
    about: &About,
    shown: &dyn Shown,
    solved: Option<&Controlled>,
) -> Result<Page, ExplorerError> {
    let world = about.map.ok_or(ExplorerError::NotAMap)?;
    let layout = world.layout()?;
    let (tasks, report) = (about.tasks, about.report);
    let figures = Figures::new(tasks, shown);
    let cells = layout.free_cells();
    let f = cells.len();
    let cell_index = |cell: Cell| cells.binary_search(&cell).expect("a free cell");
    let h0 = shown.initial();
    let (robot0, adversary0, turn0) = layout.cells(shown.arena_state(h0));
    let start = Start {
        robot: cell_index(robot0),
        adversary: cell_index(adversary0),
        robot_first: turn0 == Owner::Robot,
        tuple: shown.tuple_of(h0) as usize,
    };
    let tuples: Vec<Vec<u32>> = (0..shown.num_tuples())
        .map(|slot| shown.tuple(slot))
        .collect();

    // Which slices the page covers.
    let mut notes = Vec::new();
    let per_tuple = f * f;
    let (covered_tuples, covered_adversaries, play) = if tuples.len() * per_tuple <= ALL_SLICES {
        (
            (0..tuples.len()).collect::<Vec<_>>(),
            (0..f).collect::<Vec<_>>(),
            true,
        )
    } else if per_tuple <= ALL_SLICES {
        notes.push(format!(
            "This problem has {} robot states: the page shows the slices of h0's automata \
             states only ({per_tuple} robot states), without the play mode.",
            tuples.len() * per_tuple
        ));
        (vec![start.tuple], (0..f).collect(), false)
    } else {
        notes.push(format!(
            "This problem has {} robot states: the page shows h0's slice only (the adversary \
             on its start, h0's automata states), without the play mode.",
            tuples.len() * per_tuple
        ));
        (vec![start.tuple], vec![start.adversary], false)
    };
    let play = play && solved.is_some();
    let controller = solved.map(|solved| solved.controller);

    // The robot states of every covered slice, in index order.
    let mut robot_states: Vec<Option<HState>> =
        Vec::with_capacity(covered_tuples.len() * covered_adversaries.len() * f);
    for &t in &covered_tuples {
        for &a in &covered_adversaries {
            robot_states.extend(slice_states(
                world, shown, &layout, &figures, cells[a], &tuples[t],
            )?);
        }
    }

    let mut tags = Dictionary::default();
    let tag_ids: Vec<Option<u64>> = robot_states
        .iter()
        .map(|h| h.map(|h| tags.index(figures.tag(h)) as u64))
        .collect();
    let tag_table = Table::encode(|| tag_ids.iter().copied());
    drop(tag_ids);
    let listed: Vec<HState> = robot_states.iter().flatten().copied().collect();
    let key = figures.key(&listed);
    drop(listed);

    let mut choices = Dictionary::default();
    let mut sets_committed_to: Vec<u8> = Vec::new();
    let (choice_table, value_table) = match controller {
        Some(controller) => {
            let decisions: Vec<Option<u64>> = robot_states
                .iter()
                .map(|h| {
                    h.map(|h| {
                        let choice = choice(controller, world, h);
                        if let Choice::Stop(set) | Choice::Commit(set) = choice
                            && !sets_committed_to.contains(&set)
                        {
                            sets_committed_to.push(set);
                        }
                        choices.index(choice) as u64
                    })
                })
                .collect();
            let values = Table::encode(|| {
                robot_states.iter().map(|h| {
                    h.map(|h| {
                        let value = controller.value(h).lower;
                        (value * 100.0).round().max(0.0) as u64
                    })
                })
            });
            (
                Some(Table::encode(|| decisions.iter().copied())),
                Some(values),
            )
        }
        _ => (None, None),
    };
    sets_committed_to.sort_unstable();

    // What the play mode answers from.
    let (reactive, adversary) = match controller {
        Some(controller) if play => {
            let reactive = sets_committed_to
                .iter()
                .map(|&set| {
                    let table = Table::encode(|| {
                        robot_states.iter().map(move |h| {
                            let h = (*h)?;
                            if controller.is_target(TaskSet(set), h) {
                                return None;
                            }
                            let (action, _) = controller.reactive_move(TaskSet(set), h)?;
                            Some(robot_move(world, controller.action_name(action)) as u64)
                        })
                    });
                    (set, table)
                })
                .collect();
            let (mut distribution, mut edges) = (Vec::new(), Vec::new());
            let mut support = Vec::with_capacity(robot_states.len());
            for &t in &covered_tuples {
                for &a in &covered_adversaries {
                    for r in 0..f {
                        let h = layout
                            .state(cells[r], cells[a], Owner::Adversary)
                            .filter(|_| !(world.collision == Collision::Forbidden && r == a))
                            .and_then(|s| shown.find_tuple(s, &tuples[t]))
                            .filter(|&h| {
                                shown.edges(h, &mut edges);
                                !edges.is_empty()
                            });
                        support.push(h.map(|h| {
                            controller.probabilities(h, &mut distribution);
                            let moves = edges
                                .iter()
                                .zip(&distribution)
                                .filter(|&(_, &p)| p > 0.0)
                                .fold(0u64, |bits, ((action, _), _)| {
                                    let m = adversary_move(world, shown.action_name(*action));
                                    bits | 1 << (m + 1)
                                });
                            moves | u64::from(controller.is_worthless(h))
                        }));
                    }
                }
            }
            (reactive, Some(Table::encode(|| support.iter().copied())))
        }
        _ => (Vec::new(), None),
    };

    // Decision tables.
    let index_of = |h: HState| -> Option<usize> {
        let (robot, adversary, _) = layout.cells(shown.arena_state(h));
        let t = covered_tuples
            .iter()
            .position(|&t| t == shown.tuple_of(h) as usize)?;
        let a = covered_adversaries
            .iter()
            .position(|&a| a == cell_index(adversary))?;
        Some((t * covered_adversaries.len() + a) * f + cell_index(robot))
    };
    let trace = solved.and_then(|solved| solved.trace);
    let tables = match solved {
        Some(solved) => {
            let explained: Vec<usize> = if robot_states.iter().flatten().count() <= ALL_TABLES {
                (0..robot_states.len())
                    .filter(|&i| robot_states[i].is_some())
                    .collect()
            } else {
                let h0_slice = index_of(h0).map(|i| i - i % f);
                let mut explained: Vec<usize> = h0_slice
                    .into_iter()
                    .flat_map(|first| first..first + f)
                    .filter(|&i| robot_states[i].is_some())
                    .collect();
                let run = trace.map_or(&[][..], |trace| &trace.steps);
                explained.extend(
                    run.iter()
                        .filter(|step| shown.is_robot(step.state))
                        .filter_map(|step| index_of(step.state)),
                );
                explained.sort_unstable();
                explained.dedup();
                notes.push(format!(
                    "Decision tables are embedded for {} of the {} robot states shown (h0's \
                     slice and the run's states); for another state, ask the command line \
                     (--explain=STATE).",
                    explained.len(),
                    robot_states.iter().flatten().count()
                ));
                explained
            };
            let explained: Vec<(usize, HState)> = explained
                .into_iter()
                .filter_map(|i| Some((i, robot_states[i]?)))
                .collect();
            let states: Vec<HState> = explained.iter().map(|&(_, h)| h).collect();
            let tables = (solved.explain)(&states)?;
            explained.into_iter().map(|(i, _)| i).zip(tables).collect()
        }
        None => Vec::new(),
    };

    let run = match (solved, trace) {
        (Some(solved), Some(trace)) => {
            let rows = trace_rows(
                trace,
                |h| shown.state_name(h),
                |h| shown.state_label(h),
                |a| shown.action_name(a).to_string(),
                |set| shown.set_name(set),
            );
            let steps = trace
                .steps
                .iter()
                .zip(rows)
                .map(|(step, row)| {
                    let (robot, adversary, turn) = layout.cells(shown.arena_state(step.state));
                    RunStep {
                        robot: cell_index(robot),
                        adversary: cell_index(adversary),
                        robot_turn: turn == Owner::Robot,
                        tuple: shown.tuple_of(step.state) as usize,
                        state: row.state,
                        label: row.label,
                        action: row.action,
                        committed: row.committed,
                    }
                })
                .collect();
            let outcome = shown.presentation().ending(trace.ending);
            Some(Run {
                seed: solved.options.seed,
                steps,
                outcome,
                payoff: trace.payoff,
            })
        }
        _ => None,
    };
    if solved.is_none() {
        notes.push(
            "The problem stopped after the games: the page shows the labels only (no \
             controller, values, run or play)."
                .to_string(),
        );
    }

    let letter = |r: usize, a: usize| {
        let state = layout
            .state(cells[r], cells[a], Owner::Robot)
            .expect("free cells");
        shown.arena_label(state)
    };
    let grid = Grid {
        width: world.width,
        height: world.height,
        cells: cells.iter().map(|c| (c.x, c.y)).collect(),
        labels: world
            .labels
            .iter()
            .map(|(name, cell)| (name.clone(), cell_index(*cell)))
            .collect(),
        collision: world.collision.to_string(),
        letters: (0..f)
            .map(|r| letter(r, if f > 1 { (r + 1) % f } else { r }))
            .collect(),
        shared: (0..f).map(|r| letter(r, r)).collect(),
        robot_moves: moves(&world.robot_moves),
        adversary_moves: moves(&world.adversary_moves),
    };
    let automata = tasks
        .automata()
        .iter()
        .enumerate()
        .map(|(i, (name, dfa))| Automaton {
            title: figures.automaton_states[i].clone(),
            states: shown.automaton_states(i),
            table: automaton_table(name, dfa, shown.labels(), shown.propositions()),
        })
        .collect();
    let mut lines = vec![figures.formulas.clone()];
    if let Some(solved) = solved {
        lines.push(settings(tasks, solved.options));
    }
    let payoffs = tasks.payoffs();
    let heat: Vec<String> = (0..=100)
        .map(|i| render::colour::heat_colour(f64::from(i) / 100.0))
        .collect();
    Ok(Page {
        format: explorer::FORMAT,
        title: about.map_name.to_string(),
        lines,
        summary: summary(report, shown),
        report: report.to_string(),
        notes,
        grid,
        automata,
        tuples,
        start,
        dark: tags
            .list
            .iter()
            .map(|tag| tag.colour.clone())
            .chain(heat.iter().cloned())
            .chain([render::colour::NOTHING_COLOUR.to_string()])
            .filter(|colour| render::colour::is_dark(colour))
            .collect(),
        tags: tags.list,
        key,
        heat,
        nothing: render::colour::NOTHING_COLOUR.to_string(),
        max: payoffs.all(),
        choices: choices.list,
        sets: (0..1usize << payoffs.num_tasks())
            .map(|mask| match mask {
                0 => String::new(),
                mask => shown.set_name(TaskSet(mask as u8)),
            })
            .collect(),
        slices: Slices {
            tuples: covered_tuples,
            adversaries: covered_adversaries,
            tags: tag_table,
            choices: choice_table,
            values: value_table,
            reactive,
            adversary,
        },
        tables,
        run,
    })
}

/// The robot states of the slice with the adversary on `adversary` and the automata in
/// `automata`, one per free cell in order (`None`: no such product state, or the adversary's
/// own cell when collisions are forbidden), as the partition picture lists them.
fn slice_states(
    world: &Gridworld,
    shown: &dyn Shown,
    layout: &Layout,
    figures: &Figures,
    adversary: Cell,
    automata: &[u32],
) -> Result<Vec<Option<HState>>, RenderError> {
    let listed =
        render::partition_states(world, layout, shown, adversary, automata, &figures.automata)?;
    let mut listed = listed.into_iter().peekable();
    Ok(layout
        .free_cells()
        .iter()
        .map(|&cell| match listed.peek() {
            Some(&(c, h)) if c == cell => {
                listed.next();
                h
            }
            _ => None,
        })
        .collect())
}

/// The controller's decision in robot state `h`, its move by index into the robot's moves.
fn choice(controller: &dyn Exportable, world: &Gridworld, h: HState) -> Choice {
    match controller.decide(h) {
        Decision::Move { action, .. } => {
            Choice::Move(robot_move(world, controller.action_name(action)))
        }
        Decision::Commit(set) => Choice::Commit(set.0),
        Decision::Stop(set) => Choice::Stop(set.0),
        Decision::GiveUp => Choice::GiveUp,
    }
}

/// The index of the robot's move named `name` (an action of the map's arena).
fn robot_move(world: &Gridworld, name: &str) -> usize {
    world
        .robot_moves
        .iter()
        .position(|m| m.name() == name)
        .expect("the robot's actions are its moves")
}

/// The index of the adversary's move named `name`.
fn adversary_move(world: &Gridworld, name: &str) -> usize {
    world
        .adversary_moves
        .iter()
        .position(|m| m.name() == name)
        .expect("the adversary's actions are its moves")
}

fn moves(moves: &[crate::arena::gridworld::Move]) -> Vec<Move> {
    moves
        .iter()
        .map(|m| {
            let (dx, dy) = m.offset();
            Move {
                name: m.name().to_string(),
                dx,
                dy,
            }
        })
        .collect()
}

/// The report's headline figures: the value of h0, what the controller collects, its first
/// decision, the MDP and the solver, the simulation if any; or, after the games only, h0.
fn summary(report: &Report, shown: &dyn Shown) -> Vec<(String, String)> {
    let h0 = shown.initial();
    let mut lines = vec![(
        "initial state".to_string(),
        format!("{}  {}", shown.state_name(h0), shown.state_label(h0)),
    )];
    let Some(s) = &report.synthesis else {
        return lines;
    };
    let d = &s.decision;
    lines.push((
        "value of h0".to_string(),
        format!(
            "{} (upper bound {})",
            number(d.value),
            number(d.value_upper)
        ),
    ));
    lines.push((
        "controller".to_string(),
        format!(
            "collects {} (upper bound {}), expected {} robot moves",
            number(d.policy_value),
            number(d.policy_value_upper),
            report::moves(d.expected_moves)
        ),
    ));
    let first = match (&d.action, &d.commits_to) {
        (Some(action), Some(set)) => format!("{action}, committing to {}", set.join(",")),
        (Some(action), None) => action.clone(),
        (None, Some(set)) => format!("commits to {}", set.join(",")),
        (None, None) if d.adversary_first => "the adversary moves first".to_string(),
        (None, None) => "none".to_string(),
    };
    lines.push(("first action".to_string(), first));
    let settings = &s.settings;
    lines.push((
        "adversary".to_string(),
        format!("sigma_L {} (seed {})", settings.sigma_l, settings.seed),
    ));
    lines.push((
        "solver".to_string(),
        format!(
            "discount {}, epsilon {:e}; {} iterations, gap {:.1e}",
            settings.discount, settings.epsilon, s.solver.iterations, s.solver.gap
        ),
    ));
    lines.push((
        "MDP".to_string(),
        format!(
            "{} states, {} choices, {} transitions",
            s.mdp.states, s.mdp.choices, s.mdp.transitions
        ),
    ));
    if let Some(sim) = &s.simulation {
        lines.push((
            "simulation".to_string(),
            format!(
                "{} runs: mean payoff {}, 95% CI [{}, {}]",
                sim.options.runs,
                number(sim.mean_payoff),
                number(sim.ci_low),
                number(sim.ci_high)
            ),
        ));
    }
    lines
}

/// Distinct values, each given the index of its first appearance.
struct Dictionary<T> {
    list: Vec<T>,
    index: HashMap<T, usize>,
}

impl<T> Default for Dictionary<T> {
    fn default() -> Self {
        Dictionary {
            list: Vec::new(),
            index: HashMap::new(),
        }
    }
}

impl<T: Clone + Eq + std::hash::Hash> Dictionary<T> {
    fn index(&mut self, value: T) -> usize {
        if let Some(&i) = self.index.get(&value) {
            return i;
        }
        self.list.push(value.clone());
        self.index.insert(value, self.list.len() - 1);
        self.list.len() - 1
    }
}
