//! Arenas: read from a file or a text (an arena's or a map's), or built in code.

use std::sync::Arc;

use pyo3::prelude::*;

use hypersynth::arena::gridworld::Gridworld;
use hypersynth::arena::{self as lib_arena, Owner};
use hypersynth::pipeline::spec::ArenaSpec;
use hypersynth::render::title::TitleChoice;
use hypersynth::stage::{Meter, Stage};

use crate::errors::{ArenaError, Error, exception, in_field};

/// A two-player arena: robot and adversary states, labelled by propositions. Build one with
/// `Arena.from_file`, `Arena.from_string`, `Arena.from_map` or `ArenaBuilder`.
#[pyclass(frozen, module = "hypersynth")]
#[derive(Clone)]
pub(crate) struct Arena {
    pub(crate) name: String,
    pub(crate) arena: Arc<lib_arena::Arena>,
    pub(crate) map: Option<Arc<Gridworld>>,
}

impl Arena {
    /// The arena (or map) `spec` reads (as the command line reads them: a map's arena without
    /// display names, which serve only the arena writer).
    fn read(spec: ArenaSpec) -> PyResult<Arena> {
        let (arena, map) = spec
            .build(&mut Meter::unobserved(Stage::Parse))
            .map_err(|error| in_field(spec.name(), spec.text(), error.position, *error.kind))?;
        Ok(Arena {
            name: spec.name().to_string(),
            arena: Arc::new(arena),
            map: map.map(Arc::new),
        })
    }

    /// The arena or map of `text`, named `name`.
    fn of_text(name: &str, text: &str) -> PyResult<Arena> {
        Arena::read(ArenaSpec::Text {
            name: name.to_string(),
            text: text.to_string(),
        })
    }
}

#[pymethods]
impl Arena {
    /// Reads an arena file, or a map file (recognised by its header).
    #[staticmethod]
    fn from_file(path: std::path::PathBuf) -> PyResult<Arena> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|e| {
            exception::<Error>(format!("{name}: cannot read: {e}"), Some(&name), None)
        })?;
        Arena::of_text(&name, &text)
    }

    /// Reads an arena (or a map) from its text; `name` names it in messages and reports.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<string>"))]
    fn from_string(text: &str, name: &str) -> PyResult<Arena> {
        Arena::of_text(name, text)
    }

    /// Builds the arena of a map's text (the map format of docs/formats.md).
    #[staticmethod]
    #[pyo3(signature = (text, name = "<map>"))]
    fn from_map(text: &str, name: &str) -> PyResult<Arena> {
        Arena::read(ArenaSpec::Map {
            name: name.to_string(),
            text: text.to_string(),
        })
    }

    /// The name of the arena in messages and reports.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    fn __len__(&self) -> usize {
        self.arena.num_states()
    }

    /// The states' names, in arena order.
    #[getter]
    fn names(&self) -> Vec<&str> {
        self.arena.states().map(|s| self.arena.name(s)).collect()
    }

    /// Per state, `"robot"` or `"adversary"`.
    #[getter]
    fn owners(&self) -> Vec<&'static str> {
        self.arena
            .states()
            .map(|s| match self.arena.owner(s) {
                Owner::Robot => "robot",
                Owner::Adversary => "adversary",
            })
            .collect()
    }

    /// Per state, the set of propositions that hold there.
    #[getter]
    fn labels(&self) -> Vec<std::collections::BTreeSet<&str>> {
        let propositions = self.arena.propositions();
        self.arena
            .states()
            .map(|s| {
                self.arena
                    .label(s)
                    .iter()
                    .map(|p| propositions[p].as_str())
                    .collect()
            })
            .collect()
    }

    /// The initial state's name.
    #[getter]
    fn initial(&self) -> &str {
        self.arena.name(self.arena.initial())
    }

    /// The arena's propositions.
    #[getter]
    fn propositions(&self) -> Vec<String> {
        self.arena.propositions().to_vec()
    }

    /// The arena's actions.
    #[getter]
    fn actions(&self) -> Vec<String> {
        self.arena.actions().to_vec()
    }

    /// The transitions of state `name`: `(action, successor)` pairs.
    fn transitions(&self, name: &str) -> PyResult<Vec<(String, String)>> {
        let state = self.arena.find_state(name).ok_or_else(|| {
            exception::<ArenaError>(format!("no state is named `{name}`"), None, None)
        })?;
        Ok(self
            .arena
            .edges(state)
            .map(|(a, t)| {
                let action = self.arena.action_name(a).to_string();
                (action, self.arena.name(t).to_string())
            })
            .collect())
    }

    /// The arena in the arena format.
    fn to_text(&self) -> String {
        lib_arena::write(&self.arena)
    }

    /// The map as SVG (a map-based arena only; None otherwise).
    fn _repr_svg_(&self) -> Option<String> {
        let world = self.map.as_deref()?;
        let size = format!("Map, {} × {} cells", world.width, world.height);
        let title = hypersynth::render::title::Title::new(vec![size], &TitleChoice::Default);
        Some(hypersynth::render::picture::map(world, &title))
    }

    fn __repr__(&self) -> String {
        format!(
            "<hypersynth.Arena {:?}: {} states, {} transitions{}>",
            self.name,
            self.arena.num_states(),
            self.arena.num_transitions(),
            if self.map.is_some() { ", a map" } else { "" }
        )
    }
}

/// Builds an arena in code: `add_state`, `add_transition`, `set_initial`, then `build`.
#[pyclass(module = "hypersynth")]
pub(crate) struct ArenaBuilder {
    builder: Option<lib_arena::ArenaBuilder>,
}

impl ArenaBuilder {
    fn builder(&mut self) -> PyResult<&mut lib_arena::ArenaBuilder> {
        self.builder.as_mut().ok_or_else(|| {
            exception::<ArenaError>("this builder has already built its arena", None, None)
        })
    }

    fn state(&mut self, name: &str) -> PyResult<lib_arena::StateId> {
        self.builder()?.find_state(name).ok_or_else(|| {
            exception::<ArenaError>(format!("no state is named `{name}`"), None, None)
        })
    }
}

#[pymethods]
impl ArenaBuilder {
    #[new]
    fn new() -> Self {
        ArenaBuilder {
            builder: Some(lib_arena::ArenaBuilder::new()),
        }
    }

    /// Adds state `name` owned by `owner` (`"robot"` or `"adversary"`) where `labels` hold.
    #[pyo3(signature = (name, owner, labels = Vec::new()))]
    fn add_state(&mut self, name: &str, owner: &str, labels: Vec<String>) -> PyResult<()> {
        let owner = match owner {
            "robot" => Owner::Robot,
            "adversary" => Owner::Adversary,
            other => {
                return Err(exception::<ArenaError>(
                    format!("owner `{other}` is not `robot` or `adversary`"),
                    None,
                    None,
                ));
            }
        };
        let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
        self.builder()?
            .add_state(name, owner, labels, None)
            .map_err(|e| exception::<ArenaError>(e.to_string(), None, None))?;
        Ok(())
    }

    /// Adds the transition `source --action--> target` (states by name).
    fn add_transition(&mut self, source: &str, action: &str, target: &str) -> PyResult<()> {
        let (s, t) = (self.state(source)?, self.state(target)?);
        self.builder()?
            .add_transition(s, action, t)
            .map_err(|e| exception::<ArenaError>(e.to_string(), None, None))?;
        Ok(())
    }

    /// Makes state `name` the initial one (default: the first added).
    fn set_initial(&mut self, name: &str) -> PyResult<()> {
        let state = self.state(name)?;
        self.builder()?.set_initial(state);
        Ok(())
    }

    /// The arena built (the builder cannot be used after).
    #[pyo3(signature = (name = "<builder>"))]
    fn build(&mut self, name: &str) -> PyResult<Arena> {
        let builder = self.builder.take().ok_or_else(|| {
            exception::<ArenaError>("this builder has already built its arena", None, None)
        })?;
        let arena = builder
            .build()
            .map_err(|e| exception::<ArenaError>(e.to_string(), None, None))?;
        Ok(Arena {
            name: name.to_string(),
            arena: Arc::new(arena),
            map: None,
        })
    }
}
