//! `--svg FILE` and `--png FILE` on the main form: a picture of the map, the win-label partition
//! with the controller's moves, the values, or a simulated run (drawn by the library as SVG;
//! rasterised here with resvg and the bundled font, so a PNG is the same on every machine; the
//! learning curve's `--learning-curve-png` too);
//! `--html FILE`: the interactive explorer page (`hypersynth::pipeline::explorer`).

use std::path::PathBuf;

use anyhow::Context;
use hypersynth::arena::gridworld::Cell;
use hypersynth::pipeline::{self, PictureRequest};
use hypersynth::render::TitleChoice;
use resvg::{tiny_skia, usvg};

/// The font the pictures are laid out for (DejaVu Sans; licence in assets/fonts/).
pub const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The picture options of the main form.
#[derive(clap::Args, Debug)]
#[group(id = "render")]
#[command(group = clap::ArgGroup::new("picture-file").args(["svg", "png"]).multiple(true))]
#[command(group = clap::ArgGroup::new("png-file").args(["png", "learning_curve_png"]).multiple(true))]
#[command(group = clap::ArgGroup::new("titled").args(["svg", "png", "learning_curve", "learning_curve_png"]).multiple(true))]
pub struct Args {
    /// Also draw a picture as SVG into FILE (atomically); the ARENA must be a map.
    #[arg(long, value_name = "FILE")]
    pub svg: Option<PathBuf>,
    /// Also draw the picture as PNG into FILE (atomically), at --dpi, with the bundled font.
    #[arg(long, value_name = "FILE")]
    pub png: Option<PathBuf>,
    /// The PNGs' resolution in dots per inch, 72 to 1200 (an SVG pixel is 1/96 inch).
    #[arg(long, value_name = "DPI", default_value_t = 300, requires = "png-file",
          value_parser = clap::value_parser!(u32).range(72..=1200))]
    pub dpi: u32,
    /// Which picture to draw: the map; the win-labels of the robot's states with the
    /// controller's moves (no moves with --games-only); their values on a colour scale; or one
    /// simulated run (seeded by --seed).
    #[arg(long, value_enum, default_value_t = Picture::Partition, requires = "picture-file")]
    pub picture: Picture,
    /// The adversary's cell in the partition and value pictures [default: its start].
    #[arg(long, value_name = "X,Y", requires = "picture-file")]
    pub adversary_at: Option<Cell>,
    /// The automata's states in the partition and value pictures, one per automaton of the
    /// product: q1,q2 (the general form: the sub-tasks' in order, then psi's if it has its own
    /// automaton) [default: those of h0].
    #[arg(long, value_name = "Q1,Q2,...", value_parser = parse_states, requires = "picture-file")]
    pub automata: Option<AutomatonStates>,
    /// The title above the picture (and the learning curve) instead of its description (`\n`
    /// starts a new line).
    #[arg(
        long,
        value_name = "TEXT",
        requires = "titled",
        conflicts_with = "no_title"
    )]
    pub title: Option<String>,
    /// No title above the picture (and the learning curve); the SVG keeps its description as
    /// its accessible name.
    #[arg(long, requires = "titled")]
    pub no_title: bool,
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
    /// The option that asked for the picture, for messages: `--svg`, else `--png`.
    pub fn file_flag(&self) -> &'static str {
        if self.svg.is_some() { "--svg" } else { "--png" }
    }

    /// The `--picture` value, as typed.
    pub fn picture_name(&self) -> String {
        clap::ValueEnum::to_possible_value(&self.picture)
            .map(|value| value.get_name().to_string())
            .unwrap_or_default()
    }

    /// The title `--title` and `--no-title` ask for.
    pub fn title(&self) -> TitleChoice {
        match (&self.title, self.no_title) {
            (_, true) => TitleChoice::None,
            (Some(text), false) => TitleChoice::Text(text.replace("\\n", "\n")),
            (None, false) => TitleChoice::Default,
        }
    }

    /// The picture `--svg` or `--png` asks for, if any.
    pub fn request(&self) -> Option<PictureRequest> {
        if self.svg.is_none() && self.png.is_none() {
            return None;
        }
        let title = self.title();
        Some(PictureRequest {
            picture: match self.picture {
                Picture::Map => pipeline::Picture::Map,
                Picture::Partition => pipeline::Picture::Partition,
                Picture::Value => pipeline::Picture::Value,
                Picture::Trace => pipeline::Picture::Trace,
            },
            adversary_at: self.adversary_at,
            automata: self.automata.as_ref().map(|states| states.0.clone()),
            title,
        })
    }

    /// Writes the PNG `--png` asks for, rasterised from `svg` (atomically).
    pub fn write_png(&self, svg: Option<&str>) -> anyhow::Result<()> {
        self.write_png_to(self.png.as_ref(), svg)
    }

    /// Writes `svg` rasterised at `--dpi` into `path`, if both are given (atomically).
    pub fn write_png_to(&self, path: Option<&PathBuf>, svg: Option<&str>) -> anyhow::Result<()> {
        let (Some(path), Some(svg)) = (path, svg) else {
            return Ok(());
        };
        let png =
            rasterise(svg, self.dpi).with_context(|| format!("cannot draw {}", path.display()))?;
        super::io::write_atomically(path, &png)
            .with_context(|| format!("cannot write {}", path.display()))
    }
}

/// `svg` as a PNG at `dpi` dots per inch (the SVG's pixels taken as 1/96 inch, the PNG's
/// physical size recorded), text set in the bundled font only.
pub fn rasterise(svg: &str, dpi: u32) -> anyhow::Result<Vec<u8>> {
    let mut options = usvg::Options::default();
    let fonts = options.fontdb_mut();
    fonts.load_font_data(FONT.to_vec());
    fonts.set_sans_serif_family("DejaVu Sans");
    let tree = usvg::Tree::from_str(svg, &options).context("unreadable SVG")?;
    let scale = f64::from(dpi) / 96.0;
    let size = tree
        .size()
        .to_int_size()
        .scale_by(scale as f32)
        .context("picture too large")?;
    let mut pixmap =
        tiny_skia::Pixmap::new(size.width(), size.height()).context("picture too large")?;
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(scale as f32, scale as f32),
        &mut pixmap.as_mut(),
    );
    let rgba: Vec<u8> = pixmap
        .pixels()
        .iter()
        .flat_map(|p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue(), c.alpha()]
        })
        .collect();
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, size.width(), size.height());
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let per_metre = (f64::from(dpi) / 0.0254).round() as u32;
    encoder.set_pixel_dims(Some(png::PixelDimensions {
        xppu: per_metre,
        yppu: per_metre,
        unit: png::Unit::Meter,
    }));
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&rgba)?;
    writer.finish()?;
    Ok(out)
}
