//! The learning curve: the robust and the nominal value of h0 against the number of observed
//! runs they were learnt from (docs/semantics.md §10), on a logarithmic axis of runs.
//!
//! Layout, top to bottom: the title lines, the value axis's name, the plot (horizontal grid
//! lines at round values, labelled on the left; vertical ones at 1, 2, 5, 10, ... runs,
//! labelled below, a label left out where it would meet the previous one), the runs axis's
//! name, and the legend, one line per series. Every series is a line with a mark at each point
//! (lines may cross each other; no text lies in the plot), and colour is never the only cue:
//! the robust value is solid with circles, the nominal one dashed with squares, the reference
//! dotted. [`super::figure::overlaps`] checks the finished picture.

use super::colour::{BLUE, ORANGE};
use super::figure::{Anchor, Figure, Paint, Role, Shape};
use super::font;
use super::picture::{AXIS_SIZE, BLACK, GRID_LINE, LEGEND_ROW, LEGEND_SIZE, MARGIN, title_lines};
use super::title::Title;
use crate::opportunistic::observations::CurvePoint;

/// The plot's size, in pixels.
const PLOT_WIDTH: f64 = 520.0;
const PLOT_HEIGHT: f64 = 280.0;
/// Space between the plot's frame and its first and last points.
const INSET: f64 = 14.0;
/// The reference line's colour.
const REFERENCE: &str = "#000000";
/// The length of a legend line's sample.
const SAMPLE: f64 = 34.0;

/// One series: its colour, dash pattern and mark.
struct Series {
    colour: &'static str,
    dash: &'static str,
    square: bool,
}

const ROBUST: Series = Series {
    colour: BLUE,
    dash: "",
    square: false,
};
const NOMINAL: Series = Series {
    colour: ORANGE,
    dash: "stroke-dasharray=\"7 4\"",
    square: true,
};

/// The learning curve of `points` (in increasing order of runs): the robust and the nominal
/// value (their certified lower bounds); `reference`, if given, a horizontal line at a value with its
/// legend text (the value under the model of the options).
pub fn learning_curve(
    title: &Title,
    points: &[CurvePoint],
    reference: Option<(f64, &str)>,
) -> String {
    let mut figure = Figure::new(0.0, 0.0, &title.description);
    let (top, title_right) = title_lines(&mut figure, title);
    let values = points
        .iter()
        .flat_map(|p| [p.value, p.nominal_value])
        .chain(reference.map(|(v, _)| v))
        .filter(|v| v.is_finite());
    let axis = ValueAxis::new(values);
    // The value labels' width, so that the plot starts right of them.
    let labels: Vec<String> = axis.ticks().map(|v| axis.label(v)).collect();
    let label_width = labels
        .iter()
        .map(|l| font::width(l, AXIS_SIZE))
        .fold(0.0, f64::max);
    let left = MARGIN + label_width + 8.0;
    let plot_top = top + 2.0 * AXIS_SIZE;
    let bottom = plot_top + PLOT_HEIGHT;
    let right = left + PLOT_WIDTH;
    let max_runs = points.iter().map(|p| p.runs).max().unwrap_or(1).max(1);
    let runs_axis = RunsAxis::new(max_runs, left + INSET, right - INSET);
    let y_of =
        |v: f64| bottom - INSET - (v - axis.lo) / (axis.hi - axis.lo) * (PLOT_HEIGHT - 2.0 * INSET);
    let mut text_right = title_right;
    let mut text = |figure: &mut Figure, at, anchor, size, line: &str| {
        let (_, _, r, _) = figure.text(at, size, anchor, BLACK, "", line, false);
        text_right = text_right.max(r);
    };
    // The frame, the grid and the labels of both axes.
    let grid = Paint {
        fill: None,
        stroke: Some((GRID_LINE, 0.6)),
        extra: "stroke-dasharray=\"2 3\"",
    };
    for (v, label) in axis.ticks().zip(&labels) {
        let y = y_of(v);
        figure.shape(
            Shape::Polyline(vec![(left, y), (right, y)]),
            Role::Line,
            grid,
        );
        let at = (left - 6.0, y + 0.36 * AXIS_SIZE);
        text(&mut figure, at, Anchor::End, AXIS_SIZE, label);
    }
    let mut last_label_right = f64::NEG_INFINITY;
    for n in runs_axis.ticks() {
        let x = runs_axis.x(n);
        figure.shape(
            Shape::Polyline(vec![(x, plot_top), (x, bottom)]),
            Role::Line,
            grid,
        );
        figure.shape(
            Shape::Polyline(vec![(x, bottom), (x, bottom + 4.0)]),
            Role::Line,
            Paint::outline(BLACK, 1.0),
        );
        let label = n.to_string();
        let half = font::width(&label, AXIS_SIZE) / 2.0;
        if x - half > last_label_right + 6.0 {
            let at = (x, bottom + 6.0 + font::ASCENT * AXIS_SIZE);
            text(&mut figure, at, Anchor::Middle, AXIS_SIZE, &label);
            last_label_right = x + half;
        }
    }
    figure.shape(
        Shape::Rect {
            x: left,
            y: plot_top,
            width: PLOT_WIDTH,
            height: PLOT_HEIGHT,
        },
        Role::Line,
        Paint::outline(BLACK, 1.0),
    );
    let at = (left, plot_top - 0.8 * AXIS_SIZE);
    text(&mut figure, at, Anchor::Start, AXIS_SIZE, "value of h0");
    let axis_name = bottom + 10.0 + 2.0 * AXIS_SIZE;
    let at = ((left + right) / 2.0, axis_name);
    let name = "runs observed (the first ones of the file), logarithmic scale";
    text(&mut figure, at, Anchor::Middle, AXIS_SIZE, name);
    let at = |p: &CurvePoint, v: f64| (runs_axis.x(p.runs), y_of(v));
    for (series, value) in [
        (
            &NOMINAL,
            (|p: &CurvePoint| p.nominal_value) as fn(&CurvePoint) -> f64,
        ),
        (&ROBUST, |p: &CurvePoint| p.value),
    ] {
        let line: Vec<(f64, f64)> = points.iter().map(|p| at(p, value(p))).collect();
        draw_series(&mut figure, series, &line, &line);
    }
    // The reference over them, thin and dotted: the nominal value comes close to it.
    if let Some((v, _)) = reference {
        let y = y_of(v);
        figure.shape(
            Shape::Polyline(vec![(left, y), (right, y)]),
            Role::Line,
            reference_paint(),
        );
    }
    // The legend.
    let mut y = axis_name + 12.0;
    let mut entries = vec![
        (
            Some(&ROBUST),
            "robust value: guaranteed with probability at least 1 − δ".to_string(),
        ),
        (
            Some(&NOMINAL),
            "nominal value: the observed frequencies (uniform where unobserved)".to_string(),
        ),
    ];
    if let Some((_, what)) = reference {
        entries.push((None, what.to_string()));
    }
    for (series, what) in entries {
        let mid = y + LEGEND_ROW / 2.0;
        let sample = vec![(left, mid), (left + SAMPLE, mid)];
        match series {
            Some(series) => {
                draw_series(&mut figure, series, &sample, &[(left + SAMPLE / 2.0, mid)]);
            }
            None => figure.shape(Shape::Polyline(sample), Role::Line, reference_paint()),
        }
        let at = (left + SAMPLE + 8.0, mid + 0.36 * LEGEND_SIZE);
        text(&mut figure, at, Anchor::Start, LEGEND_SIZE, &what);
        y += LEGEND_ROW;
    }
    let width = text_right.max(right) + MARGIN;
    figure.resize(width.ceil(), (y + MARGIN).ceil());
    figure.to_svg()
}

fn reference_paint() -> Paint<'static> {
    Paint {
        fill: None,
        stroke: Some((REFERENCE, 1.2)),
        extra: "stroke-dasharray=\"2 2\"",
    }
}

/// A series: its line through `points`, then a mark at each of `marks`.
fn draw_series(figure: &mut Figure, series: &Series, points: &[(f64, f64)], marks: &[(f64, f64)]) {
    let line = Paint {
        fill: None,
        stroke: Some((series.colour, 2.0)),
        extra: series.dash,
    };
    figure.shape(Shape::Polyline(points.to_vec()), Role::Line, line);
    for &(x, y) in marks {
        let shape = if series.square {
            Shape::Rect {
                x: x - 3.5,
                y: y - 3.5,
                width: 7.0,
                height: 7.0,
            }
        } else {
            Shape::Circle {
                centre: (x, y),
                r: 4.0,
            }
        };
        figure.shape(
            shape,
            Role::Line,
            Paint::filled("#FFFFFF", series.colour, 2.0),
        );
    }
}

/// The value axis: round values from `lo` to `hi`, `step` apart.
struct ValueAxis {
    lo: f64,
    hi: f64,
    step: f64,
}

impl ValueAxis {
    /// The axis that holds `values` with about five steps between round values.
    fn new(values: impl Iterator<Item = f64>) -> ValueAxis {
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        let (lo, hi) = if lo > hi { (0.0, 1.0) } else { (lo, hi) };
        let spread = (hi - lo).max(1e-6 * hi.abs().max(1.0));
        let raw = spread / 5.0;
        let magnitude = 10f64.powf(raw.log10().floor());
        let step = [1.0, 2.0, 2.5, 5.0, 10.0]
            .into_iter()
            .map(|m| m * magnitude)
            .find(|&s| s >= raw)
            .unwrap_or(10.0 * magnitude);
        let lo_tick = (lo / step).floor() * step;
        let mut hi_tick = (hi / step).ceil() * step;
        if hi_tick <= lo_tick {
            hi_tick = lo_tick + step;
        }
        ValueAxis {
            lo: lo_tick,
            hi: hi_tick,
            step,
        }
    }

    /// The round values from `lo` to `hi`.
    fn ticks(&self) -> impl Iterator<Item = f64> + '_ {
        let count = ((self.hi - self.lo) / self.step).round() as usize;
        (0..=count).map(move |i| self.lo + i as f64 * self.step)
    }

    /// A round value as the axis writes it: with as many decimals as the step has.
    fn label(&self, v: f64) -> String {
        let decimals = (0..6)
            .find(|&d| {
                let scaled = self.step * 10f64.powi(d);
                (scaled - scaled.round()).abs() < 1e-6 * scaled.max(1.0)
            })
            .unwrap_or(6) as usize;
        let text = format!("{v:.decimals$}");
        match text.strip_prefix('-') {
            Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
            _ => text,
        }
    }
}

/// The runs axis: logarithmic from 1 to `max` between pixels `x0` and `x1`.
struct RunsAxis {
    max: u32,
    x0: f64,
    x1: f64,
}

impl RunsAxis {
    fn new(max: u32, x0: f64, x1: f64) -> RunsAxis {
        RunsAxis {
            max: max.max(2),
            x0,
            x1,
        }
    }

    fn x(&self, runs: u32) -> f64 {
        let t = f64::from(runs.max(1)).ln() / f64::from(self.max).ln();
        self.x0 + t * (self.x1 - self.x0)
    }

    /// 1, 2, 5, 10, 20, 50, ... up to the largest number of runs.
    fn ticks(&self) -> impl Iterator<Item = u32> + '_ {
        (0..10u32)
            .flat_map(|e| [1u32, 2, 5].map(move |m| m.saturating_mul(10u32.saturating_pow(e))))
            .take_while(|&n| n <= self.max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_value_axis_has_round_steps_around_the_values() {
        let axis = ValueAxis::new([271.3, 294.8].into_iter());
        assert_eq!((axis.lo, axis.hi, axis.step), (270.0, 295.0, 5.0));
        assert_eq!(axis.label(270.0), "270");
        let axis = ValueAxis::new([0.12, 0.5].into_iter());
        assert_eq!(axis.step, 0.1);
        assert_eq!(axis.label(0.1), "0.1");
        assert_eq!(ValueAxis::new([0.0, 12.0].into_iter()).label(2.5), "2.5");
        let flat = ValueAxis::new([300.0, 300.0].into_iter());
        assert!(flat.lo <= 300.0 && flat.hi > flat.lo);
        let empty = ValueAxis::new(std::iter::empty());
        assert_eq!((empty.lo, empty.hi), (0.0, 1.0));
    }

    #[test]
    fn the_runs_axis_is_logarithmic_with_one_two_five_ticks() {
        let axis = RunsAxis::new(100, 0.0, 200.0);
        assert_eq!(axis.x(1), 0.0);
        assert!((axis.x(10) - 100.0).abs() < 1e-9);
        assert_eq!(axis.x(100), 200.0);
        assert_eq!(axis.ticks().collect::<Vec<_>>(), [1, 2, 5, 10, 20, 50, 100]);
    }
}
