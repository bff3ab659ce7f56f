//! The main form's pictures of a map: the map, the win-label partition with the controller's
//! moves, the values as a heat map, or a traced run.

use super::opportunistic::OpportunisticSolution;
use crate::arena::gridworld::{Cell, Gridworld, GridworldError};
use crate::automata::DfaState;
use crate::game::{Hypergame, Task, WinningRegions};
use crate::mdp::view::SolvedHypergame;
use crate::render::{self, RenderError, Shading};
use crate::simulate::trace;

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
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PictureRequest {
    /// Which picture.
    pub picture: Picture,
    /// The adversary's cell [default: its start].
    pub adversary_at: Option<Cell>,
    /// The automata's states (q1, q2) [default: those of h0].
    pub automata: Option<(DfaState, DfaState)>,
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

/// What a picture is of: the map, the names of the map and the formulas, the solved game and,
/// unless games only, its MDP solution.
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

/// The SVG of the picture `request` asks for.
pub fn draw(subject: &PictureSubject, request: &PictureRequest) -> Result<String, PictureError> {
    let world = subject.map.ok_or(PictureError::NotAMap)?;
    let [phi, phi1, phi2] = subject.formulas;
    let formulas = format!("phi = {phi};  psi = phi1 = {phi1};  phi2 = {phi2}");
    let game = subject.game;
    let layout = world.layout()?;
    let solution = match (request.picture, subject.solution) {
        (Picture::Map, _) | (Picture::Partition, None) => None,
        (_, Some(solution)) => Some(solution),
        (_, None) => return Err(PictureError::NeedsMdp),
    };
    let solved = SolvedHypergame::new(game, subject.regions);
    Ok(match request.picture {
        Picture::Map => render::map(world, &[format!("Map: {}", subject.map_name), formulas]),
        Picture::Partition | Picture::Value => {
            let h0 = game.state(game.initial());
            let adversary = request.adversary_at.unwrap_or(world.adversary);
            let automata = request.automata.unwrap_or((h0.q1, h0.q2));
            let states = render::partition_states(world, &layout, game, adversary, automata)?;
            let view = solution.map(|solution| {
                let robot_states: Vec<_> = states.iter().filter_map(|&(_, h)| h).collect();
                render::controller_view(&solution.controller(&solved), &robot_states, &[])
            });
            let cells = render::partition_cells(&states, subject.regions, view.as_ref());
            let shading = match (request.picture, solution) {
                (Picture::Value, Some(solution)) => Shading::Values {
                    max: solution.options.payoffs.get(Task::Phi),
                },
                _ => Shading::Labels,
            };
            let what = if shading == Shading::Labels {
                "Win-labels"
            } else {
                "Values"
            };
            let which = if request.automata.is_none() {
                " (as in h0)"
            } else {
                ""
            };
            let mut title = vec![
                format!(
                    "{what} of the robot's states, adversary at {adversary}, automata at q1 = {}, \
                     q2 = {}{which}",
                    automata.0, automata.1
                ),
                formulas,
            ];
            if let Some(solution) = solution {
                title.push(solution.options.title());
            }
            render::partition(world, &title, adversary, &cells, shading)
        }
        Picture::Trace => {
            let solution = solution.ok_or(PictureError::NeedsMdp)?;
            let controller = solution.controller(&solved);
            let seed = solution.options.seed;
            let (_, steps) = trace(&controller, &solution.adversary, seed, subject.max_steps);
            let view = render::controller_view(&controller, &[], &steps);
            let points = render::trace_points(&layout, game, subject.regions, &view.run);
            let title = vec![
                format!(
                    "A run of the opportunistic controller (seed {seed}, {} steps)",
                    points.len()
                ),
                formulas,
                solution.options.title(),
            ];
            render::trace(world, &title, &points)
        }
    })
}
