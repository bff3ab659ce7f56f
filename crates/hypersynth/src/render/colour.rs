//! One colour per label and per set of tasks, the same in every picture.
//!
//! The rule: a cell's fill names the set of tasks the robot can force from there (the best one,
//! in the general form), and a set's colour depends only on which tasks it holds, by their
//! position: the first, second and third `--task` (the paper's form: `phi1` then `phi2`). So
//! `{A}` is yellow in the decoy and in three-tasks (A is the first task of both), and so is the
//! paper's `(W, L, L)`, "only phi1 can be forced". The paper's other labels are sets too:
//! `(W, W, W)` is `{phi1, phi2}`, `(L, W, L)` is `{phi2}`, `(L, L, L)` nothing; `(W, W, L)`
//! ("either, not both") is the one label that is no set, and has its own colour, which no set
//! takes.
//!
//! | set (by position) | colour | paper's label |
//! |---|---|---|
//! | nothing | vermillion `#D55E00` | `(L, L, L)` |
//! | {1} | yellow `#F0E442` | `(W, L, L)` |
//! | {2} | reddish purple `#CC79A7` | `(L, W, L)` |
//! | {1, 2} | bluish green `#009E73` | `(W, W, W)` |
//! | {3} | orange `#E69F00` | |
//! | {1, 3} | blue `#0072B2` | |
//! | {2, 3} | grey `#BBBBBB` | |
//! | {1, 2, 3} | olive `#999933` | |
//! | either 1 or 2, not both | sky blue `#56B4E9` | `(W, W, L)` |
//!
//! The first seven are the Okabe–Ito colours, distinguishable with the common colour-vision
//! deficiencies; olive is Paul Tol's. Colour is never the only cue: cells carry the label's
//! code. Sets over a fourth task and beyond are too many for fixed colours: with four tasks or
//! more, a picture colours sets by the rank of their payoff on the light part of the value scale
//! ([`rank_colour`]), and only the codes name them.

use crate::game::{TaskSet, WinLabel};

const BLUISH_GREEN: &str = "#009E73";
const SKY_BLUE: &str = "#56B4E9";
const YELLOW: &str = "#F0E442";
const REDDISH_PURPLE: &str = "#CC79A7";
const VERMILLION: &str = "#D55E00";
/// The robot's colour (Okabe–Ito blue), also the set {1, 3}.
pub const BLUE: &str = "#0072B2";
/// The adversary's colour (Okabe–Ito orange), also the set {3}.
pub const ORANGE: &str = "#E69F00";
const GREY: &str = "#BBBBBB";
const OLIVE: &str = "#999933";

/// The fill of a state that can force nothing: the paper's `(L, L, L)`.
pub const NOTHING_COLOUR: &str = VERMILLION;

/// The fill of the paper's `(W, W, L)`: either task, not both.
pub const EITHER_COLOUR: &str = SKY_BLUE;

/// The fill of obstacles.
pub const OBSTACLE_FILL: &str = "#4D4D4D";

/// The fill of goal cells (labelled cells) where the fill says nothing else (map, run).
pub const GOAL_FILL: &str = "#FFF6CC";

/// The colour of the set of tasks `set` (by position), when it holds only the first three.
pub fn set_colour(set: TaskSet) -> Option<&'static str> {
    const BY_MASK: [&str; 8] = [
        VERMILLION,
        YELLOW,
        REDDISH_PURPLE,
        BLUISH_GREEN,
        ORANGE,
        BLUE,
        GREY,
        OLIVE,
    ];
    BY_MASK.get(usize::from(set.0)).copied()
}

/// The fill of a robot cell with this win-label of the paper's form (black for the impossible
/// labels).
pub fn label_colour(label: WinLabel) -> &'static str {
    let set = |mask| set_colour(TaskSet(mask)).unwrap_or("#000000");
    match label.code() {
        "WWW" => set(0b11),
        "WWL" => EITHER_COLOUR,
        "WLL" => set(0b01),
        "LWL" => set(0b10),
        "LLL" => NOTHING_COLOUR,
        _ => "#000000",
    }
}

/// The fill of the general form's payoff class `index` (0: the largest payoff) among `count`
/// classes of positive payoff, for problems of four tasks or more: evenly spaced stops of the
/// light part of the value scale, the largest at its top.
pub fn rank_colour(index: usize, count: usize) -> String {
    if count <= 1 {
        return heat_colour(1.0);
    }
    let t = 1.0 - index as f64 / (count - 1) as f64;
    heat_colour(0.3 + 0.7 * t)
}

/// The value scale's stops (viridis' ends and three stops between), from 0 to 1.
pub const SCALE: [(f64, f64, f64); 5] = [
    (68.0, 1.0, 84.0),
    (59.0, 82.0, 139.0),
    (33.0, 145.0, 140.0),
    (94.0, 201.0, 98.0),
    (253.0, 231.0, 37.0),
];

/// The value scale at `t` in [0, 1], linear in sRGB between its stops (as an SVG gradient
/// through them draws it).
pub fn heat_colour(t: f64) -> String {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let position = t * (SCALE.len() - 1) as f64;
    let i = (position.floor() as usize).min(SCALE.len() - 2);
    let f = position - i as f64;
    let (a, b) = (SCALE[i], SCALE[i + 1]);
    let mix = |x: f64, y: f64| (x + (y - x) * f).round() as u8;
    format!(
        "#{:02X}{:02X}{:02X}",
        mix(a.0, b.0),
        mix(a.1, b.1),
        mix(a.2, b.2)
    )
}

/// Whether black shows worse than white on `colour` (`#RRGGBB`): its relative luminance (WCAG)
/// is below 0.179, where both contrast equally. Anything else (a gradient) counts as light.
pub fn is_dark(colour: &str) -> bool {
    let channel = |i: usize| {
        let value = colour
            .get(1 + 2 * i..3 + 2 * i)
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        value.map(|v| {
            let c = f64::from(v) / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        })
    };
    match (colour.len(), channel(0), channel(1), channel(2)) {
        (7, Some(r), Some(g), Some(b)) => 0.2126 * r + 0.7152 * g + 0.0722 * b < 0.179,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_set_of_three_tasks_and_the_either_label_have_distinct_colours() {
        let mut colours: Vec<&str> = (0..8).map(|m| set_colour(TaskSet(m)).unwrap()).collect();
        colours.push(EITHER_COLOUR);
        colours.sort_unstable();
        colours.dedup();
        assert_eq!(colours.len(), 9);
        assert_eq!(set_colour(TaskSet(8)), None);
    }

    #[test]
    fn the_papers_labels_take_the_colours_of_their_sets() {
        let label = |code: &str| {
            WinLabel::ALL
                .into_iter()
                .find(|l| l.code() == code)
                .unwrap()
        };
        assert_eq!(label_colour(label("WLL")), YELLOW);
        assert_eq!(label_colour(label("LWL")), REDDISH_PURPLE);
        assert_eq!(label_colour(label("WWW")), BLUISH_GREEN);
        assert_eq!(label_colour(label("LLL")), VERMILLION);
        assert_eq!(label_colour(label("WWL")), SKY_BLUE);
        assert_eq!(label_colour(label("LLW")), "#000000");
    }

    #[test]
    fn dark_fills_are_those_white_contrasts_better_with() {
        assert!(is_dark("#440154") && is_dark("#0072B2") && is_dark("#4D4D4D"));
        assert!(!is_dark("#F0E442") && !is_dark("#D55E00") && !is_dark("#FFFFFF"));
        assert!(!is_dark("url(#value-scale)"));
    }

    #[test]
    fn the_value_scale_runs_through_its_stops() {
        assert_eq!(heat_colour(0.0), "#440154");
        assert_eq!(heat_colour(1.0), "#FDE725");
        assert_eq!(heat_colour(0.5), "#21918C");
        // Halfway between the first two stops, rounded half away from zero.
        assert_eq!(heat_colour(0.125), "#402A70");
        assert_eq!(heat_colour(f64::NAN), "#440154");
        assert_eq!(rank_colour(0, 8), heat_colour(1.0));
        assert_eq!(rank_colour(7, 8), heat_colour(0.3));
    }
}
