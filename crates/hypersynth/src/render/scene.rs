//! Which product states a picture shows, and what the games stage says of them.

use super::controller::ControllerView;
use super::picture::{CellView, TracePoint};
use crate::arena::Owner;
use crate::arena::gridworld::{Cell, Collision, Gridworld, Layout};
use crate::automata::DfaState;
use crate::game::{HState, Hypergame, ProductState, Task, WinningRegions};

/// Why a picture cannot be drawn.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RenderError {
    #[error("the adversary's cell {0} is not a free cell of the map")]
    AdversaryCell(Cell),
    #[error(
        "{state} is not an enumerated state of the automaton of {task} (those are: {})",
        .enumerated.iter().map(u32::to_string).collect::<Vec<_>>().join(" ")
    )]
    AutomatonState {
        task: Task,
        state: DfaState,
        enumerated: Vec<DfaState>,
    },
}

/// The robot states of a partition picture: for each free cell of `layout` (by `x`, then `y`)
/// the robot's product state with the adversary on `adversary`, the robot to move and the
/// automata in `q1`, `q2`; `None` where the product does not enumerate it. The adversary's
/// own cell is left out when collisions are forbidden (the robot cannot be there).
pub fn partition_states(
    world: &Gridworld,
    layout: &Layout,
    game: &Hypergame,
    adversary: Cell,
    (q1, q2): (DfaState, DfaState),
) -> Result<Vec<(Cell, Option<HState>)>, RenderError> {
    if !layout.free_cells().contains(&adversary) {
        return Err(RenderError::AdversaryCell(adversary));
    }
    for (task, state, enumerated) in [
        (Task::Phi1, q1, game.q1_states()),
        (Task::Phi2, q2, game.q2_states()),
    ] {
        if !enumerated.contains(&state) {
            let enumerated = enumerated.to_vec();
            return Err(RenderError::AutomatonState {
                task,
                state,
                enumerated,
            });
        }
    }
    let forbidden = world.collision == Collision::Forbidden;
    Ok(layout
        .free_cells()
        .iter()
        .filter(|&&cell| !(forbidden && cell == adversary))
        .map(|&cell| {
            let h = layout
                .state(cell, adversary, Owner::Robot)
                .and_then(|arena| game.find(ProductState { arena, q1, q2 }));
            (cell, h)
        })
        .collect())
}

/// The cells of a partition picture: each state's win-label, and the controller's mark and
/// value when `controller` (computed for the states of `states`, in order) is given.
pub fn partition_cells(
    states: &[(Cell, Option<HState>)],
    regions: &WinningRegions,
    controller: Option<&ControllerView>,
) -> Vec<CellView> {
    let mut decisions = controller.map(|view| view.decisions.iter());
    states
        .iter()
        .map(|&(cell, h)| {
            let (mark, value) = match (h, decisions.as_mut()) {
                (Some(_), Some(decisions)) => decisions.next().copied().unwrap_or((None, None)),
                _ => (None, None),
            };
            CellView {
                cell,
                label: h.map(|h| regions.label(h)),
                mark,
                value,
            }
        })
        .collect()
}

/// The points of a run given as product states (with the action played in each).
pub fn trace_points(
    layout: &Layout,
    game: &Hypergame,
    regions: &WinningRegions,
    run: &[(HState, Option<String>)],
) -> Vec<TracePoint> {
    run.iter()
        .map(|(h, action)| {
            let (robot, adversary, turn) = layout.cells(game.state(*h).arena);
            TracePoint {
                robot,
                adversary,
                turn,
                label: regions.label(*h),
                action: action.clone(),
            }
        })
        .collect()
}
