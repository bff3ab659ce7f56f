//! `--svg FILE` on the main form: a picture of the map, the win-label partition with the
//! controller's moves, the values, or a simulated run (drawn by `hypersynth::pipeline::draw`);
//! `--html FILE`: the interactive explorer page (`hypersynth::pipeline::explorer`).

use std::path::PathBuf;

use hypersynth::arena::gridworld::Cell;
use hypersynth::pipeline::{self, PictureRequest};

/// The picture options of the main form.
#[derive(clap::Args, Debug)]
#[group(id = "render")]
pub struct Args {
    /// Also draw a picture as SVG into FILE (atomically); the ARENA must be a map.
    #[arg(long, value_name = "FILE")]
    pub svg: Option<PathBuf>,
    /// Which picture --svg draws: the map; the win-labels of the robot's states with the
    /// controller's moves (no moves with --games-only); their values as a heat map; or one
    /// simulated run (seeded by --seed).
    #[arg(long, value_enum, default_value_t = Picture::Partition, requires = "svg")]
    pub picture: Picture,
    /// The adversary's cell in the partition and value pictures [default: its start].
    #[arg(long, value_name = "X,Y", requires = "svg")]
    pub adversary_at: Option<Cell>,
    /// The automata's states in the partition and value pictures, one per automaton of the
    /// product: q1,q2 (the general form: the sub-tasks' in order, then psi's if it has its own
    /// automaton) [default: those of h0].
    #[arg(long, value_name = "Q1,Q2,...", value_parser = parse_states, requires = "svg")]
    pub automata: Option<AutomatonStates>,
    /// Also write an interactive explorer page into FILE (atomically; one self-contained HTML
    /// file): every slice, decision tables, the seeded run, playing the adversary. The ARENA
    /// must be a map.
    #[arg(long, value_name = "FILE")]
    pub html: Option<PathBuf>,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Picture {
    Map,
    Partition,
    Value,
    Trace,
}

/// The states of `--automata`, a list (a newtype, so that clap takes it as one value).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AutomatonStates(Vec<u32>);

fn parse_states(text: &str) -> Result<AutomatonStates, String> {
    text.split(',')
        .map(|s| s.trim().parse::<u32>().ok())
        .collect::<Option<Vec<u32>>>()
        .map(AutomatonStates)
        .ok_or_else(|| {
            format!("`{text}` is not a list of automaton states such as `0,1` (one per automaton)")
        })
}

impl Args {
    /// The picture `--svg` asks for, if any.
    pub fn request(&self) -> Option<PictureRequest> {
        self.svg.as_ref().map(|_| PictureRequest {
            picture: match self.picture {
                Picture::Map => pipeline::Picture::Map,
                Picture::Partition => pipeline::Picture::Partition,
                Picture::Value => pipeline::Picture::Value,
                Picture::Trace => pipeline::Picture::Trace,
            },
            adversary_at: self.adversary_at,
            automata: self.automata.as_ref().map(|states| states.0.clone()),
        })
    }
}
