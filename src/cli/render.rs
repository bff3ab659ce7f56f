//! `--svg FILE` on the main form: a picture of the map, the win-label partition with the
//! controller's moves, the values, or a simulated run. The ARENA must be a map (the picture
//! needs its grid); the games stage gives the colours, the MDP stage the moves.

use std::path::PathBuf;

use anyhow::{Context as _, bail};
use hypersynth::arena::Arena;
use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::game::{Hypergame, Task, WinningRegions};
use hypersynth::io::write_atomically;
use hypersynth::mdp::build::Payoffs;
use hypersynth::mdp::view::SolvedHypergame;
use hypersynth::render::{self, Shading};
use hypersynth::report::MdpConfig;

use super::opportunistic::{self, SigmaLKind};

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
    /// The automata's states in the partition and value pictures [default: those of h0].
    #[arg(long, value_name = "Q1,Q2", value_parser = parse_states, requires = "svg")]
    pub automata: Option<(u32, u32)>,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Picture {
    Map,
    Partition,
    Value,
    Trace,
}

fn parse_states(text: &str) -> Result<(u32, u32), String> {
    let state = |s: &str| s.trim().parse::<u32>().ok();
    text.split_once(',')
        .and_then(|(q1, q2)| Some((state(q1)?, state(q2)?)))
        .ok_or_else(|| format!("`{text}` is not a pair of automaton states such as `0,1`"))
}

/// What the pictures are of.
pub struct Subject<'a> {
    pub arena_file: &'a str,
    pub map: Option<&'a Gridworld>,
    pub game: &'a Hypergame<'a>,
    pub regions: &'a WinningRegions,
    /// `phi`, `phi1` and `phi2` as printed.
    pub formulas: [&'a str; 3],
}

/// Draws the picture `args` ask for, if any; `mdp` (the MDP stage's options and payoffs) is
/// `None` with `--games-only`.
pub fn run(
    args: &Args,
    subject: &Subject,
    mdp: Option<(&opportunistic::Args, Payoffs)>,
) -> anyhow::Result<()> {
    let Some(path) = &args.svg else {
        return Ok(());
    };
    let Some(world) = subject.map else {
        bail!(
            "{}: --svg needs a map (a file starting with `{}`), not a text arena",
            subject.arena_file,
            hypersynth::arena::map::HEADER
        );
    };
    let [phi, phi1, phi2] = subject.formulas;
    let formulas = format!("phi = {phi};  psi = phi1 = {phi1};  phi2 = {phi2}");
    let game = subject.game;
    let layout = world.layout()?;
    // The MDP stage's settings with the options they come from, when the picture needs them.
    let stage = match (args.picture, mdp) {
        (Picture::Map, _) | (Picture::Partition, None) => None,
        (_, Some((mdp, payoffs))) => Some((
            mdp_config(mdp, payoffs, args.picture == Picture::Trace, game.arena())?,
            mdp,
        )),
        (_, None) => {
            bail!("--picture value and trace need the opportunistic stage: drop --games-only")
        }
    };
    let solved = SolvedHypergame::new(game, subject.regions);
    let svg = match args.picture {
        Picture::Map => render::map(world, &[format!("Map: {}", subject.arena_file), formulas]),
        Picture::Partition | Picture::Value => {
            let h0 = game.state(game.initial());
            let adversary = args.adversary_at.unwrap_or(world.adversary);
            let automata = args.automata.unwrap_or((h0.q1, h0.q2));
            let states = render::partition_states(world, &layout, game, adversary, automata)?;
            let view = match &stage {
                Some((config, _)) => {
                    let robot_states: Vec<_> = states.iter().filter_map(|&(_, h)| h).collect();
                    Some(render::controller_view(&solved, config, &robot_states)?)
                }
                None => None,
            };
            let cells = render::partition_cells(&states, subject.regions, view.as_ref());
            let shading = match (args.picture, &stage) {
                (Picture::Value, Some((config, _))) => Shading::Values {
                    max: config.payoffs.get(hypersynth::game::Task::Phi),
                },
                _ => Shading::Labels,
            };
            let what = if shading == Shading::Labels {
                "Win-labels"
            } else {
                "Values"
            };
            let which = if args.automata.is_none() {
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
            if let Some((config, mdp)) = &stage {
                title.push(settings(config, mdp));
            }
            render::partition(world, &title, adversary, &cells, shading)
        }
        Picture::Trace => {
            let (config, mdp) = stage.context("a trace needs the opportunistic stage")?;
            let view = render::controller_view(&solved, &config, &[])?;
            let points = render::trace_points(&layout, game, subject.regions, &view.run);
            let title = vec![
                format!(
                    "A run of the opportunistic controller (seed {}, {} steps)",
                    config.seed,
                    points.len()
                ),
                formulas,
                settings(&config, mdp),
            ];
            render::trace(world, &title, &points)
        }
    };
    write_atomically(path, svg.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
}

/// The MDP settings in one line, for a title.
fn settings(config: &MdpConfig, mdp: &opportunistic::Args) -> String {
    let sigma_l = match (&mdp.adversary, mdp.sigma_l) {
        (Some(path), _) => format!("weights from {path}"),
        (None, SigmaLKind::Uniform) => "uniform".to_string(),
        (None, SigmaLKind::Random) => format!("random (seed {})", mdp.seed),
    };
    format!(
        "sigma_L {sigma_l}, discount {}, payoffs r1 = {}, r2 = {}, r = {}",
        config.solve.discount.get(),
        config.payoffs.get(Task::Phi1),
        config.payoffs.get(Task::Phi2),
        config.payoffs.get(Task::Phi)
    )
}

/// The MDP stage's settings from its options, for a picture: no simulation, a trace if asked.
fn mdp_config(
    args: &opportunistic::Args,
    payoffs: Payoffs,
    trace: bool,
    arena: &Arena,
) -> anyhow::Result<MdpConfig> {
    let mut config = opportunistic::config(args, payoffs, arena)?;
    config.simulate = None;
    config.trace = trace;
    Ok(config)
}
