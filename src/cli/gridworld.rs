//! `hypersynth gridworld`: generates a two-player turn-based gridworld arena.

use std::fmt;
use std::path::PathBuf;
use std::process::ExitCode;
use std::str::FromStr;

use anyhow::Context;
use hypersynth::arena::gridworld::{
    ADVERSARY_MOVES, Cell, Collision, Gridworld, GridworldError, Move, ROBOT_MOVES,
};
use hypersynth::arena::{self, Owner};

#[derive(clap::Args, Clone, Debug)]
pub struct Args {
    /// Read the gridworld from a map file (`-` for standard input) instead of the options below.
    #[arg(long, value_name = "FILE", conflicts_with_all = [
        "size", "width", "height", "obstacles", "robot_start", "adversary_start", "labels",
        "robot_moves", "adversary_moves", "collision", "first",
    ])]
    map: Option<String>,
    /// The grid size, `WIDTHxHEIGHT` (or give --width and --height).
    #[arg(long, value_name = "WxH", value_parser = parse_size,
          required_unless_present_any = ["width", "height", "map"], conflicts_with_all = ["width", "height"])]
    size: Option<(u32, u32)>,
    /// The grid width (cells along x, eastward).
    #[arg(long, requires = "height")]
    width: Option<u32>,
    /// The grid height (cells along y, northward).
    #[arg(long, requires = "width")]
    height: Option<u32>,
    /// Obstacle cells `x,y` (repeatable, or several after one --obstacle); they carry `O`.
    #[arg(long = "obstacle", value_name = "X,Y", num_args = 1..)]
    obstacles: Vec<Cell>,
    /// The robot's initial cell. (`--robot` still works.)
    #[arg(
        long,
        alias = "robot",
        value_name = "X,Y",
        required_unless_present = "map"
    )]
    robot_start: Option<Cell>,
    /// The adversary's initial cell. (`--adversary` still works; on the main form,
    /// `--adversary` is a file of weights.)
    #[arg(
        long,
        alias = "adversary",
        value_name = "X,Y",
        required_unless_present = "map"
    )]
    adversary_start: Option<Cell>,
    /// Labelled cells `NAME=x,y` (repeatable, or several after one --label): states where the
    /// robot stands on the cell carry NAME.
    #[arg(long = "label", value_name = "NAME=X,Y", num_args = 1.., value_parser = parse_label)]
    labels: Vec<(String, Cell)>,
    /// The robot's moves, comma-separated, among N S E W NE NW SE SW STAY.
    #[arg(long, value_name = "MOVES", default_value_t = Moves(ROBOT_MOVES.to_vec()))]
    robot_moves: Moves,
    /// The adversary's moves, comma-separated, among N S E W NE NW SE SW STAY.
    #[arg(long, value_name = "MOVES", default_value_t = Moves(ADVERSARY_MOVES.to_vec()))]
    adversary_moves: Moves,
    /// A move into the other player's cell: `forbidden` (it does not exist), `allowed`, or
    /// `label:NAME` (allowed, and states where the players share a cell carry NAME).
    #[arg(long, value_name = "RULE", default_value_t = Collision::Forbidden)]
    collision: Collision,
    /// Who moves in the initial state.
    #[arg(long, value_enum, default_value_t = First::Robot)]
    first: First,
    /// Write the arena to FILE (atomically) instead of standard output.
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
}

/// Moves as they are given and shown (`--help`'s defaults): comma-separated, `N,S,E,W`.
#[derive(Clone, Debug)]
struct Moves(Vec<Move>);

impl fmt::Display for Moves {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.0.iter().map(|m| m.name()).collect();
        f.write_str(&names.join(","))
    }
}

impl FromStr for Moves {
    type Err = GridworldError;

    fn from_str(text: &str) -> Result<Moves, GridworldError> {
        text.split(',')
            .map(str::parse)
            .collect::<Result<_, _>>()
            .map(Moves)
    }
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum First {
    Robot,
    Adversary,
}

fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let side = |s: &str| s.parse::<u32>().ok();
    text.split_once('x')
        .and_then(|(w, h)| Some((side(w)?, side(h)?)))
        .ok_or_else(|| format!("`{text}` is not a size: expected WIDTHxHEIGHT, such as `5x5`"))
}

fn parse_label(text: &str) -> Result<(String, Cell), String> {
    let (name, cell) = text.split_once('=').ok_or_else(|| {
        format!("`{text}` is not a labelled cell: expected NAME=X,Y, such as `A=0,3`")
    })?;
    let cell = cell.parse::<Cell>().map_err(|e| e.to_string())?;
    Ok((name.to_string(), cell))
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let world = match &args.map {
        Some(file) => super::arena::load_map(file)?,
        None => from_options(args.clone())?,
    };
    let arena = world.build()?;
    let text = arena::write_with_comment(&arena, &world.describe());
    super::output::write_output(args.output.as_deref(), &text)?;
    Ok(ExitCode::SUCCESS)
}

/// The gridworld the options describe.
fn from_options(args: Args) -> anyhow::Result<Gridworld> {
    let (width, height) = args
        .size
        .or(args.width.zip(args.height))
        .context("the grid size is missing")?;
    let world = Gridworld {
        width,
        height,
        obstacles: args.obstacles,
        robot: args.robot_start.context("--robot-start is missing")?,
        adversary: args
            .adversary_start
            .context("--adversary-start is missing")?,
        labels: args.labels,
        robot_moves: args.robot_moves.0,
        adversary_moves: args.adversary_moves.0,
        collision: args.collision,
        first: match args.first {
            First::Robot => Owner::Robot,
            First::Adversary => Owner::Adversary,
        },
    };
    Ok(world)
}
