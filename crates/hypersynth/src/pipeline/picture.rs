//! The main form's pictures of a map: the map, the win-label partition with the controller's
//! moves, the values as a heat map, or a traced run, for either form ([`draw`]) and either
//! engine ([`draw_on`]): the product is read through [`Shown`] (how a state shows, the legend,
//! the titles: [`Figures`]) and the controller and its run through [`Controlled`].

use super::opportunistic::{MdpOptions, OpportunisticSolution};
use super::shown::{Controlled, ExplicitShown, Shown};
use super::tasks::{Believed, Tasks};
use crate::arena::gridworld::{Cell, Gridworld, GridworldError};
use crate::automata::DfaState;
use crate::game::{HState, TaskSet};
use crate::opportunistic::export::Explicit;
use crate::opportunistic::simulate::Trace;
use crate::opportunistic::view::SolvedHypergame;
use crate::render::{self, Key, RenderError, Shading, Tag, Tags, Title, TitleChoice};

/// Which picture to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Picture {
    /// The map alone.
    Map,
    /// The robot's states coloured by win-label, with the controller's moves when solved.
    Partition,
    /// The robot's states shaded by value.
    Value,
    /// One traced run of the controller.
    Trace,
}

/// A picture to draw, and which slice of the product the partition and value pictures show.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PictureRequest {
    /// Which picture.
    pub picture: Picture,
    /// The adversary's cell [default: its start].
    pub adversary_at: Option<Cell>,
    /// The automata's states, one per automaton of the product in its order (the paper's
    /// form: q1, q2; the general form: the sub-tasks', then psi's if it has one) [default:
    /// those of h0].
    pub automata: Option<Vec<DfaState>>,
    /// The title shown [default: the picture's description].
    pub title: TitleChoice,
}

/// Why a picture cannot be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PictureError {
    /// The arena is a text arena, not a map.
    #[error(
        "a picture needs a map (a file starting with `{}`), not a text arena",
        crate::arena::map::HEADER
    )]
    NotAMap,
    /// The value and trace pictures need the MDP stage.
    #[error("the value and trace pictures need the opportunistic stage, which was not run")]
    NeedsMdp,
    /// The map has no layout.
    #[error(transparent)]
    Gridworld(#[from] GridworldError),
    /// The requested slice does not exist.
    #[error(transparent)]
    Render(#[from] RenderError),
}

/// What a picture is of: the map, its name and the tasks, the solved game and, unless games
/// only, its MDP solution and the traced run.
pub struct PictureSubject<'a> {
    /// The map's name in titles (its file).
    pub map_name: &'a str,
    /// The map, if the arena is one.
    pub map: Option<&'a Gridworld>,
    /// The tasks, in product order, with their form.
    pub tasks: &'a Tasks,
    /// The product with its regions and payoffs.
    pub game: &'a SolvedHypergame<'a, 'a>,
    /// The MDP stage's solution, when it ran.
    pub solution: Option<&'a OpportunisticSolution>,
    /// The run to draw (the trace picture needs it).
    pub trace: Option<&'a Trace>,
}

/// The SVG of the picture `request` asks for, each robot state shown as [`Tags`] says (by its
/// win-label in the paper's terms). The values go up to the payoff of all sub-tasks.
pub fn draw(subject: &PictureSubject, request: &PictureRequest) -> Result<String, PictureError> {
    explicit(subject, |shown, solved| {
        draw_on(subject.map, subject.tasks, shown, solved, request)
    })
}

/// `f` of the explicit engine's product and controller (unless games only) in `subject`, as
/// the drawing and the page read either engine's.
pub(super) fn explicit<T>(
    subject: &PictureSubject,
    f: impl FnOnce(&dyn Shown, Option<&Controlled>) -> T,
) -> T {
    let game = subject.game;
    let shown = ExplicitShown(game);
    let Some(solution) = subject.solution else {
        return f(&shown, None);
    };
    let controller = solution.controller(game);
    let explicit = Explicit {
        controller: &controller,
        adversary: &solution.adversary,
    };
    let explain = |states: &[HState]| {
        Ok(states
            .iter()
            .map(|&h| controller.explain(h, &solution.evaluation))
            .collect())
    };
    let controlled = Controlled {
        controller: &explicit,
        explain: &explain,
        options: &solution.options,
        trace: subject.trace,
    };
    f(&shown, Some(&controlled))
}

/// How pictures and the explorer show the tasks and the robot's states, read from the
/// problem's presentation: the titles' line of formulas, the automata's names, and each state's
/// tag and the legend of the tags ([`Tags`]: by win-label where the presentation labels states
/// so, else by guarantee with the label written in the cell).
pub(super) struct Figures<'a> {
    /// The line naming the formulas.
    pub(super) formulas: String,
    /// The product's automata as errors name them (`phi1`, `A`, `psi`).
    pub(super) automata: Vec<String>,
    /// Their states as titles name them (`q1`, `q_A`).
    pub(super) automaton_states: Vec<String>,
    /// What the partition shows (`Win-labels`).
    pub(super) labels: &'static str,
    tags: Tags<'a>,
}

impl<'a> Figures<'a> {
    /// How `tasks` show on `shown`, their product.
    pub(super) fn new(tasks: &'a Tasks, shown: &'a dyn Shown) -> Figures<'a> {
        let presentation = tasks.presentation();
        let subtasks = tasks.subtasks();
        let formulas = match presentation.whole_task() {
            Some(phi) => format!(
                "φ = {},  ψ = φ₁ = {},  φ₂ = {}",
                render::typeset(phi),
                render::typeset(&subtasks[0].task.name),
                render::typeset(&subtasks[1].task.name)
            ),
            None => {
                let named: Vec<String> = subtasks
                    .iter()
                    .map(|t| format!("{}: {}", t.name, render::typeset(&t.task.name)))
                    .collect();
                format!(
                    "Tasks {};  believed ψ = {}",
                    named.join(", "),
                    render::typeset(tasks.believed().name())
                )
            }
        };
        let with_psi = matches!(tasks.believed(), Believed::Automaton(_));
        let win_labels = presentation.layout().win_labels;
        Figures {
            formulas,
            automata: presentation.automata(with_psi),
            automaton_states: presentation.automaton_states(with_psi),
            labels: match win_labels {
                true => "Win-labels of the robot's states",
                false => "What the robot can force from each cell",
            },
            tags: Tags::new(shown, shown.payoffs(), presentation.names(), win_labels),
        }
    }

    /// How robot state `h` shows: coloured by its win-label, or by its guarantee with its
    /// label written in the cell.
    pub(super) fn tag(&self, h: HState) -> Tag {
        self.tags.tag(h)
    }

    /// The legend of the tags of `shown` (the states a picture shows).
    pub(super) fn key(&self, shown: &[HState]) -> Key {
        self.tags.key(shown.iter().copied())
    }
}

/// The MDP stage's settings in one line, for a title: the paper's payoffs by name (`r1 = 200`),
/// or where guarantees are stated the risk rule and each set's payoff (`A,B = 300`).
pub(super) fn settings(tasks: &Tasks, options: &MdpOptions) -> String {
    let (sigma_l, discount) = (options.sigma_l.title(), options.solve.discount.get());
    let presentation = tasks.presentation();
    let payoffs = tasks.payoffs();
    let guarantees = presentation.layout().states_guarantees;
    let listed: Vec<String> = TaskSet::non_empty(payoffs.num_tasks())
        .map(|set| {
            let name = match guarantees {
                true => presentation.set_name(set),
                false => presentation.payoff_name(set),
            };
            format!("{name} = {}", payoffs.get(set))
        })
        .collect();
    let risk = match guarantees {
        true => format!(", risk {}", tasks.risk().name()),
        false => String::new(),
    };
    format!(
        "sigma_L {sigma_l}, discount {discount}{risk}, payoffs {}",
        listed.join(", ")
    )
}

/// Draws `request` of `tasks` on `map` (if the arena is one), their product `shown` and its
/// controller `solved` (unless games only), for either form and either engine.
pub(super) fn draw_on(
    map: Option<&Gridworld>,
    tasks: &Tasks,
    shown: &dyn Shown,
    solved: Option<&Controlled>,
    request: &PictureRequest,
) -> Result<String, PictureError> {
    let world = map.ok_or(PictureError::NotAMap)?;
    let figures = Figures::new(tasks, shown);
    let layout = world.layout()?;
    let solved = match (request.picture, solved) {
        (Picture::Map, _) | (Picture::Partition, None) => None,
        (_, Some(solved)) => Some(solved),
        (_, None) => return Err(PictureError::NeedsMdp),
    };
    let formulas = figures.formulas.clone();
    Ok(match request.picture {
        Picture::Map => {
            let size = format!("Map, {} × {} cells", world.width, world.height);
            render::map(world, &Title::new(vec![size, formulas], &request.title))
        }
        Picture::Partition | Picture::Value => {
            let h0 = shown.initial();
            let adversary = request.adversary_at.unwrap_or(world.adversary);
            let automata = match &request.automata {
                Some(automata) => automata.clone(),
                None => shown.tuple(shown.tuple_of(h0)),
            };
            let states = render::partition_states(
                world,
                &layout,
                shown,
                adversary,
                &automata,
                &figures.automata,
            )?;
            let robot_states: Vec<HState> = states.iter().filter_map(|&(_, h)| h).collect();
            let view =
                solved.map(|solved| render::controller_view(solved.controller, &robot_states, &[]));
            let cells = render::partition_cells(&states, |h| figures.tag(h), view.as_ref(), h0);
            let shading = match (request.picture, solved) {
                (Picture::Value, Some(_)) => Shading::Values {
                    max: tasks.payoffs().all(),
                },
                _ => Shading::Labels,
            };
            let what = if shading == Shading::Labels {
                figures.labels
            } else {
                "Values of the robot's states (lower bounds)"
            };
            let moves = if solved.is_some() {
                ", and the controller's moves"
            } else {
                ""
            };
            let which = if request.automata.is_none() {
                "as in h0: "
            } else {
                "at "
            };
            let at: Vec<String> = figures
                .automaton_states
                .iter()
                .zip(&automata)
                .map(|(name, q)| render::title::symbols(&format!("{name} = {q}")))
                .collect();
            let mut title = vec![
                format!("{what}{moves}"),
                format!(
                    "adversary at {adversary}, automata {which}{}",
                    at.join(", ")
                ),
                formulas,
            ];
            if let Some(solved) = solved {
                title.push(render::title::symbols(&settings(tasks, solved.options)));
            }
            let key = figures.key(&robot_states);
            let title = Title::new(title, &request.title);
            render::partition(world, &title, adversary, &cells, shading, &key)
        }
        Picture::Trace => {
            let solved = solved.ok_or(PictureError::NeedsMdp)?;
            let seed = solved.options.seed;
            let steps = solved.trace.map_or(&[][..], |trace| &trace.steps);
            let view = render::controller_view(solved.controller, &[], steps);
            let points = render::trace_points(&layout, shown, |h| figures.tag(h), &view.run);
            let title = vec![
                format!(
                    "A run of the opportunistic controller: {} steps (seed {seed})",
                    points.len()
                ),
                formulas,
                render::title::symbols(&settings(tasks, solved.options)),
            ];
            let title = Title::new(title, &request.title);
            render::trace(world, &title, &points)
        }
    })
}
