//! Summary figures of an arena, as `hypersynth arena` prints them.

use serde::Serialize;

use super::model::{Arena, Owner};

/// Summary figures of an arena: its size, names and defects.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Statistics {
    /// The number of states.
    pub states: usize,
    /// The number of states the robot owns.
    pub robot_states: usize,
    /// The number of states the adversary owns.
    pub adversary_states: usize,
    /// The number of transitions.
    pub transitions: usize,
    /// The action names, in id order.
    pub actions: Vec<String>,
    /// The proposition names, in id order.
    pub propositions: Vec<String>,
    /// The number of distinct labels (sets of propositions).
    pub distinct_labels: usize,
    /// The name of the initial state.
    pub initial: String,
    /// The robot states with no enabled action.
    pub stuck_robot_states: usize,
    /// The adversary states with no enabled action.
    pub stuck_adversary_states: usize,
    /// The states not reachable from the initial state.
    pub unreachable_states: usize,
}

impl Statistics {
    /// The figures of `arena`. Linear in its size.
    pub fn of(arena: &Arena) -> Statistics {
        let states = arena.num_states();
        let robot_states = (arena.states())
            .filter(|&s| arena.owner(s) == Owner::Robot)
            .count();
        let stuck_robot_states = arena
            .stuck_states()
            .filter(|&s| arena.owner(s) == Owner::Robot)
            .count();
        Statistics {
            states,
            robot_states,
            adversary_states: states - robot_states,
            transitions: arena.num_transitions(),
            actions: arena.actions().to_vec(),
            propositions: arena.propositions().to_vec(),
            distinct_labels: arena.labels().len(),
            initial: arena.name(arena.initial()).to_string(),
            stuck_robot_states,
            stuck_adversary_states: arena.stuck_states().count() - stuck_robot_states,
            unreachable_states: states - arena.reachable_states().count(),
        }
    }
}
