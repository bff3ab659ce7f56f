//! The main form's pictures of a map: the map, the win-label partition with the controller's
//! moves, the values as a heat map, or a traced run; for the paper's form ([`draw`]) and the
//! general one ([`draw_general`]). Both describe their problem as a [`Scene`] (how a state
//! shows, the legend, the titles) and a [`SolvedScene`] (the controller), and one function
//! draws either.

use super::general::SubtaskSolution;
use super::opportunistic::OpportunisticSolution;
use super::{Subtask, SubtaskOptions};
use crate::arena::gridworld::{Cell, Gridworld, GridworldError};
use crate::automata::DfaState;
use crate::game::{HState, Hypergame, SubsetPayoffs, Task, TaskRegions, TaskSet, WinningRegions};
use crate::mdp::adversary::AdversaryModel;
use crate::mdp::evaluate::Plan;
use crate::mdp::subtasks::{Risk, SubtaskGame};
use crate::mdp::view::SolvedHypergame;
use crate::render::{self, Key, RenderError, Shading, SubtaskTags, Tag, Title, TitleChoice};
use crate::simulate::trace_plan;

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
        "--svg needs a map (a file starting with `{}`), not a text arena",
        crate::arena::map::HEADER
    )]
    NotAMap,
    /// The value and trace pictures need the MDP stage.
    #[error("--picture value and trace need the opportunistic stage: drop --games-only")]
    NeedsMdp,
    /// The map has no layout.
    #[error(transparent)]
    Gridworld(#[from] GridworldError),
    /// The requested slice does not exist.
    #[error(transparent)]
    Render(#[from] RenderError),
}

/// What a picture of the paper's form is of: the map, the names of the map and the formulas,
/// the solved game and, unless games only, its MDP solution.
pub struct PictureSubject<'a> {
    /// The map's name in titles (its file).
    pub map_name: &'a str,
    /// The map, if the arena is one.
    pub map: Option<&'a Gridworld>,
    /// `phi`, `phi1` and `phi2` as printed.
    pub formulas: [&'a str; 3],
    /// The hypergame and its regions.
    pub game: &'a Hypergame<'a>,
    /// Its winning regions.
    pub regions: &'a WinningRegions,
    /// The MDP stage's solution, when it ran.
    pub solution: Option<&'a OpportunisticSolution>,
    /// Step bound of a traced run.
    pub max_steps: u32,
}

/// What a picture of the general form (DESIGN.md 3.8) is of: the map, the sub-tasks and the
/// belief, the product with its regions and payoffs and, unless games only, the general MDP's
/// solution.
pub struct GeneralPictureSubject<'a> {
    /// The map's name in titles (its file).
    pub map_name: &'a str,
    /// The map, if the arena is one.
    pub map: Option<&'a Gridworld>,
    /// The sub-tasks, in product order.
    pub tasks: &'a [Subtask],
    /// psi as printed (or its file).
    pub believed: &'a str,
    /// The product of the sub-tasks' automata (and psi's).
    pub product: &'a Hypergame<'a>,
    /// `Win(T)` for every set, and `Win(psi)`.
    pub regions: &'a TaskRegions,
    /// `r(T)` for every set.
    pub payoffs: &'a SubsetPayoffs,
    /// The general MDP's game and solution, when the MDP stage ran.
    pub solution: Option<(&'a SubtaskGame<'a, 'a>, &'a SubtaskSolution)>,
    /// Step bound of a traced run.
    pub max_steps: u32,
}

/// What both forms' pictures need of the games stage.
struct Scene<'a> {
    world: &'a Gridworld,
    game: &'a Hypergame<'a>,
    /// The line naming the formulas.
    formulas: String,
    /// The product's automata as errors name them (`phi1`, `A`, `psi`).
    automata: Vec<String>,
    /// Their states as titles name them (`q1`, `q_A`).
    automaton_states: Vec<String>,
    /// What the partition shows (`Win-labels`).
    labels: &'a str,
    tag: &'a dyn Fn(HState) -> Tag,
    /// The legend of the tags of the states shown.
    key: &'a dyn Fn(&[HState]) -> Key,
    max_steps: u32,
}

/// What both forms' pictures need of the MDP stage.
struct SolvedScene<'a, P> {
    controller: P,
    value: &'a dyn Fn(HState) -> f64,
    adversary: &'a AdversaryModel,
    seed: u64,
    /// The settings in one line.
    settings: String,
    /// The largest payoff, the top of the value scale.
    max: f64,
}

/// The SVG of the picture `request` asks for, in the paper's form.
pub fn draw(subject: &PictureSubject, request: &PictureRequest) -> Result<String, PictureError> {
    let world = subject.map.ok_or(PictureError::NotAMap)?;
    let [phi, phi1, phi2] = subject.formulas;
    let regions = subject.regions;
    let tag = |h: HState| render::win_label_tag(regions.label(h));
    let key = |_: &[HState]| render::win_label_key();
    let (phi, phi1, phi2) = (
        render::typeset(phi),
        render::typeset(phi1),
        render::typeset(phi2),
    );
    let scene = Scene {
        world,
        game: subject.game,
        formulas: format!("φ = {phi},  ψ = φ₁ = {phi1},  φ₂ = {phi2}"),
        automata: vec![Task::Phi1.to_string(), Task::Phi2.to_string()],
        automaton_states: vec!["q1".to_string(), "q2".to_string()],
        labels: "Win-labels of the robot's states",
        tag: &tag,
        key: &key,
        max_steps: subject.max_steps,
    };
    let solved = SolvedHypergame::new(subject.game, regions);
    let Some(solution) = subject.solution else {
        return draw_scene::<crate::mdp::controller::Controller<SolvedHypergame>>(
            &scene, None, request,
        );
    };
    let value = |h: HState| solution.solution.value(solution.mdp.node(h)).lower;
    let solved_scene = SolvedScene {
        controller: solution.controller(&solved),
        value: &value,
        adversary: &solution.adversary,
        seed: solution.options.seed,
        settings: render::title::symbols(&solution.options.title()),
        max: solution.options.payoffs.get(Task::Phi),
    };
    draw_scene(&scene, Some(&solved_scene), request)
}

/// The SVG of the picture `request` asks for, in the general form: the partition colours each
/// robot state by its guarantee and writes its label in the cell ([`SubtaskTags`]); the values
/// go up to the payoff of all sub-tasks; the run is the general controller's.
pub fn draw_general(
    subject: &GeneralPictureSubject,
    request: &PictureRequest,
) -> Result<String, PictureError> {
    let world = subject.map.ok_or(PictureError::NotAMap)?;
    let names: Vec<String> = subject.tasks.iter().map(|t| t.name.clone()).collect();
    let tags = SubtaskTags::new(subject.regions, subject.payoffs, &names);
    let tag = |h: HState| tags.tag(h);
    let key = |shown: &[HState]| tags.key(shown.iter().copied());
    // The sub-tasks' automata, then psi's when it has one (named as the product names it).
    let mut automata = names.clone();
    if subject.product.num_automata() > names.len() {
        automata.push("psi".to_string());
    }
    let tasks: Vec<String> = subject
        .tasks
        .iter()
        .map(|t| format!("{}: {}", t.name, render::typeset(&t.task.name)))
        .collect();
    let scene = Scene {
        world,
        game: subject.product,
        formulas: format!(
            "Tasks {};  believed ψ = {}",
            tasks.join(", "),
            render::typeset(subject.believed)
        ),
        automaton_states: automata.iter().map(|name| format!("q_{name}")).collect(),
        automata,
        labels: "What the robot can force from each cell",
        tag: &tag,
        key: &key,
        max_steps: subject.max_steps,
    };
    let Some((game, solution)) = subject.solution else {
        return draw_scene::<crate::mdp::subtasks::SubtaskController>(&scene, None, request);
    };
    let value = |h: HState| solution.solution.value(solution.mdp.node(h)).lower;
    let solved_scene = SolvedScene {
        controller: solution.controller(game),
        value: &value,
        adversary: &solution.adversary,
        seed: solution.options.seed,
        settings: render::title::symbols(&general_settings(
            &solution.options,
            solution.risk,
            subject.payoffs,
            &names,
        )),
        max: subject.payoffs.all(),
    };
    draw_scene(&scene, Some(&solved_scene), request)
}

/// The general MDP's settings in one line, for a title.
fn general_settings(
    options: &SubtaskOptions,
    risk: Risk,
    payoffs: &SubsetPayoffs,
    names: &[String],
) -> String {
    let payoffs: Vec<String> = TaskSet::non_empty(payoffs.num_tasks())
        .map(|set| format!("{} = {}", set.display(names), payoffs.get(set)))
        .collect();
    let risk = match risk {
        Risk::Paper => "paper",
        Risk::Strict => "strict",
        Risk::Neutral => "neutral",
    };
    format!(
        "sigma_L {}, discount {}, risk {risk}, payoffs {}",
        options.sigma_l.title(),
        options.solve.discount.get(),
        payoffs.join(", ")
    )
}

/// Draws `request` for either form.
fn draw_scene<P: Plan>(
    scene: &Scene,
    solved: Option<&SolvedScene<P>>,
    request: &PictureRequest,
) -> Result<String, PictureError> {
    let (world, game) = (scene.world, scene.game);
    let layout = world.layout()?;
    let solved = match (request.picture, solved) {
        (Picture::Map, _) | (Picture::Partition, None) => None,
        (_, Some(solved)) => Some(solved),
        (_, None) => return Err(PictureError::NeedsMdp),
    };
    let formulas = scene.formulas.clone();
    Ok(match request.picture {
        Picture::Map => {
            let size = format!("Map, {} × {} cells", world.width, world.height);
            render::map(world, &Title::new(vec![size, formulas], &request.title))
        }
        Picture::Partition | Picture::Value => {
            let h0 = game.initial();
            let adversary = request.adversary_at.unwrap_or(world.adversary);
            let automata = match &request.automata {
                Some(automata) => automata.clone(),
                None => (0..game.num_automata())
                    .map(|i| game.automaton_state(h0, i))
                    .collect(),
            };
            let states = render::partition_states(
                world,
                &layout,
                game,
                adversary,
                &automata,
                &scene.automata,
            )?;
            let robot_states: Vec<HState> = states.iter().filter_map(|&(_, h)| h).collect();
            let view = solved.map(|solved| {
                render::controller_view(&solved.controller, solved.value, game, &robot_states, &[])
            });
            let cells = render::partition_cells(&states, scene.tag, view.as_ref(), h0);
            let shading = match (request.picture, solved) {
                (Picture::Value, Some(solved)) => Shading::Values { max: solved.max },
                _ => Shading::Labels,
            };
            let what = if shading == Shading::Labels {
                scene.labels
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
            let at: Vec<String> = scene
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
                title.push(solved.settings.clone());
            }
            let key = (scene.key)(&robot_states);
            let title = Title::new(title, &request.title);
            render::partition(world, &title, adversary, &cells, shading, &key)
        }
        Picture::Trace => {
            let solved = solved.ok_or(PictureError::NeedsMdp)?;
            let seed = solved.seed;
            let (_, _, steps) =
                trace_plan(&solved.controller, solved.adversary, seed, scene.max_steps);
            let view = render::controller_view(&solved.controller, solved.value, game, &[], &steps);
            let points = render::trace_points(&layout, game, scene.tag, &view.run);
            let title = vec![
                format!(
                    "A run of the opportunistic controller: {} steps (seed {seed})",
                    points.len()
                ),
                formulas,
                solved.settings.clone(),
            ];
            let title = Title::new(title, &request.title);
            render::trace(world, &title, &points)
        }
    })
}
