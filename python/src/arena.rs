//! Arenas: read from a file or a text (an arena's or a map's), or built in code.

use std::sync::Arc;

use pyo3::prelude::*;

use hypersynth::arena::gridworld::Gridworld;
use hypersynth::arena::{self as lib_arena, Owner};
use hypersynth::pipeline::spec::ArenaSpec;
use hypersynth::render::title::TitleChoice;
use hypersynth::stage::{Meter, Stage};

use crate::errors::{ArenaError, exception, file_error, in_field};

/// A two-player arena: robot and adversary states, labelled by propositions. Build one with
/// `Arena.from_file`, `Arena.from_string`, `Arena.from_map` or `ArenaBuilder`.
///
/// >>> arena = hs.Arena.from_file("specs/case-study/map.txt")
/// >>> len(arena), arena.is_map
/// (800, True)
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
    /// Reads an arena file, or a map file (recognised by its header). A file that cannot be
    /// read raises `FileError`, which is also the `OSError` of its cause
    /// (`FileNotFoundError`...).
    ///
    /// >>> arena = hs.Arena.from_file("specs/case-study/arena.txt")
    /// >>> len(arena), arena.initial
    /// (800, '((0,2),(4,2),0)')
    #[staticmethod]
    fn from_file(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Arena> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|e| file_error(py, &name, &e))?;
        Arena::of_text(&name, &text)
    }

    /// Reads an arena (or a map) from its text; `name` names it in messages and reports.
    ///
    /// >>> arena = hs.Arena.from_string("initial s\nstate s robot {}\nstate t adversary {}\n"
    /// ...                              "edge s go t\nedge t back s\n", name="two")
    /// >>> arena.names, arena.owners
    /// (['s', 't'], ['robot', 'adversary'])
    #[staticmethod]
    #[pyo3(signature = (text, name = "<string>"))]
    fn from_string(text: &str, name: &str) -> PyResult<Arena> {
        Arena::of_text(name, text)
    }

    /// Builds the arena of a map's text (the map format of docs/formats.md).
    ///
    /// >>> text = open("specs/case-study/map.txt").read()
    /// >>> arena = hs.Arena.from_map(text, name="case study")
    /// >>> len(arena), arena.is_map
    /// (800, True)
    #[staticmethod]
    #[pyo3(signature = (text, name = "<map>"))]
    fn from_map(text: &str, name: &str) -> PyResult<Arena> {
        Arena::read(ArenaSpec::Map {
            name: name.to_string(),
            text: text.to_string(),
        })
    }

    /// The name of the arena in messages and reports.
    ///
    /// >>> hs.Arena.from_file("specs/case-study/arena.txt").name
    /// 'specs/case-study/arena.txt'
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Whether the arena was built from a map (pictures need one).
    ///
    /// >>> hs.Arena.from_file("specs/case-study/arena.txt").is_map
    /// False
    #[getter]
    fn is_map(&self) -> bool {
        self.map.is_some()
    }

    /// The number of states.
    ///
    /// >>> len(hs.Arena.from_file("specs/case-study/arena.txt"))
    /// 800
    fn __len__(&self) -> usize {
        self.arena.num_states()
    }

    /// Pickles as its text (the map's, for a map) and name: the same arena is read back.
    ///
    /// >>> import pickle
    /// >>> arena = hs.Arena.from_file("specs/case-study/arena.txt")
    /// >>> pickle.loads(pickle.dumps(arena)).to_text() == arena.to_text()
    /// True
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String, String))> {
        let this = slf.get();
        let (constructor, text) = match &this.map {
            Some(map) => ("from_map", hypersynth::arena::map::write(map)),
            None => ("from_string", lib_arena::write(&this.arena)),
        };
        let constructor = slf.get_type().getattr(constructor)?;
        Ok((constructor, (text, this.name.clone())))
    }

    /// The states' names, in arena order.
    ///
    /// >>> hs.Arena.from_file("specs/case-study/arena.txt").names[:2]
    /// ['((0,0),(0,0),0)', '((0,0),(0,2),0)']
    #[getter]
    fn names(&self) -> Vec<&str> {
        self.arena.states().map(|s| self.arena.name(s)).collect()
    }

    /// Per state, `"robot"` or `"adversary"`.
    ///
    /// >>> sorted(set(hs.Arena.from_file("specs/case-study/arena.txt").owners))
    /// ['adversary', 'robot']
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
    ///
    /// >>> arena = hs.Arena.from_file("specs/case-study/arena.txt")
    /// >>> arena.labels[arena.names.index("((0,3),(4,2),0)")]
    /// {'A'}
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
    ///
    /// >>> hs.Arena.from_file("specs/case-study/arena.txt").initial
    /// '((0,2),(4,2),0)'
    #[getter]
    fn initial(&self) -> &str {
        self.arena.name(self.arena.initial())
    }

    /// The arena's propositions.
    ///
    /// >>> hs.Arena.from_file("specs/case-study/arena.txt").propositions
    /// ['A', 'B', 'O']
    #[getter]
    fn propositions(&self) -> Vec<String> {
        self.arena.propositions().to_vec()
    }

    /// The arena's actions.
    ///
    /// >>> hs.Arena.from_file("specs/case-study/arena.txt").actions
    /// ['N', 'S', 'E', 'W', 'NE', 'NW', 'SE', 'SW', 'STAY']
    #[getter]
    fn actions(&self) -> Vec<String> {
        self.arena.actions().to_vec()
    }

    /// The transitions of state `name`: `(action, successor)` pairs.
    ///
    /// >>> hs.Arena.from_file("specs/case-study/arena.txt").transitions("((0,2),(4,2),0)")[0]
    /// ('N', '((0,3),(4,2),1)')
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
    ///
    /// >>> arena = hs.Arena.from_string("initial s\nstate s robot {A}\nedge s stay s\n")
    /// >>> print(arena.to_text())
    /// # hypersynth arena v1
    /// propositions A
    /// actions stay
    /// initial s
    /// state s robot {A}
    /// edge s stay s
    fn to_text(&self) -> String {
        lib_arena::write(&self.arena)
    }

    /// The map as SVG (a map-based arena only; None otherwise): Jupyter shows the arena so.
    ///
    /// >>> hs.Arena.from_file("specs/case-study/map.txt")._repr_svg_()[:4]
    /// '<svg'
    fn _repr_svg_(&self) -> Option<String> {
        let world = self.map.as_deref()?;
        let size = format!("Map, {} × {} cells", world.width, world.height);
        let title = hypersynth::render::title::Title::new(vec![size], &TitleChoice::Default);
        Some(hypersynth::render::picture::map(world, &title))
    }

    /// Its name and sizes.
    ///
    /// >>> hs.Arena.from_file("specs/case-study/arena.txt")
    /// <hypersynth.Arena "specs/case-study/arena.txt": 800 states, ... transitions>
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
///
/// >>> builder = hs.ArenaBuilder()
/// >>> builder.add_state("r", "robot")
/// >>> builder.add_state("g", "adversary", ["A"])
/// >>> builder.add_transition("r", "go", "g")
/// >>> builder.add_transition("g", "back", "r")
/// >>> builder.set_initial("r")
/// >>> builder.build("pair")
/// <hypersynth.Arena "pair": 2 states, 2 transitions>
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
    /// An empty builder.
    ///
    /// >>> hs.ArenaBuilder().build()
    /// Traceback (most recent call last):
    /// hypersynth.ArenaError: the arena has no state
    #[new]
    fn new() -> Self {
        ArenaBuilder {
            builder: Some(lib_arena::ArenaBuilder::new()),
        }
    }

    /// Adds state `name` owned by `owner` (`"robot"` or `"adversary"`) where `labels` hold.
    ///
    /// >>> builder = hs.ArenaBuilder()
    /// >>> builder.add_state("g", "robot", ["A", "B"])
    /// >>> builder.set_initial("g")
    /// >>> [sorted(label) for label in builder.build().labels]
    /// [['A', 'B']]
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
    ///
    /// >>> builder = hs.ArenaBuilder()
    /// >>> builder.add_state("r", "robot")
    /// >>> builder.add_transition("r", "stay", "r")
    /// >>> builder.set_initial("r")
    /// >>> builder.build().transitions("r")
    /// [('stay', 'r')]
    fn add_transition(&mut self, source: &str, action: &str, target: &str) -> PyResult<()> {
        let (s, t) = (self.state(source)?, self.state(target)?);
        self.builder()?
            .add_transition(s, action, t)
            .map_err(|e| exception::<ArenaError>(e.to_string(), None, None))?;
        Ok(())
    }

    /// Makes state `name` the initial one (default: the first added).
    ///
    /// >>> builder = hs.ArenaBuilder()
    /// >>> builder.add_state("a", "robot")
    /// >>> builder.add_state("b", "robot")
    /// >>> builder.set_initial("b")
    /// >>> builder.build().initial
    /// 'b'
    fn set_initial(&mut self, name: &str) -> PyResult<()> {
        let state = self.state(name)?;
        self.builder()?.set_initial(state);
        Ok(())
    }

    /// The arena built, named `name` (the builder cannot be used after).
    ///
    /// >>> builder = hs.ArenaBuilder()
    /// >>> builder.add_state("r", "robot")
    /// >>> builder.set_initial("r")
    /// >>> builder.build("one").name
    /// 'one'
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
