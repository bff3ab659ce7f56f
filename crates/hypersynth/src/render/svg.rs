//! A minimal SVG writer: the few elements the pictures use, with attribute and text escaping.
//! Numbers are written with at most two decimals, so equal inputs give byte-identical files.

use std::fmt::Write as _;

/// An SVG document being written.
pub struct Svg {
    out: String,
}

/// `value` with at most two decimals and no trailing zeros.
fn number(value: f64) -> String {
    let text = format!("{value:.2}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" { "0" } else { text }.to_string()
}

/// `text` escaped for an attribute value or character data.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            // XML 1.0 forbids most control characters even escaped.
            c if c.is_control() => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// Text placement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anchor {
    /// The text begins at `x` (`text-anchor="start"`).
    Start,
    /// The text is centred on `x`.
    Middle,
    /// The text ends at `x`.
    End,
}

impl Svg {
    /// A document of `width` × `height` pixels with a white background and `title` (the
    /// accessible name, shown by browsers as the tooltip of the whole picture).
    pub fn new(width: f64, height: f64, title: &str) -> Svg {
        let mut out = String::new();
        let (w, h) = (number(width), number(height));
        let _ = writeln!(
            out,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
             viewBox=\"0 0 {w} {h}\" font-family=\"DejaVu Sans, Verdana, sans-serif\">"
        );
        let _ = writeln!(out, "<title>{}</title>", escape(title));
        let _ = writeln!(
            out,
            "<rect x=\"0\" y=\"0\" width=\"{w}\" height=\"{h}\" fill=\"#ffffff\"/>"
        );
        Svg { out }
    }

    /// A rectangle with its top-left corner at `(x, y)`; `style` is written as the element's raw
    /// attributes (e.g. `fill="#ffffff"`), unescaped.
    pub fn rect(&mut self, x: f64, y: f64, width: f64, height: f64, style: &str) {
        let _ = writeln!(
            self.out,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" {style}/>",
            number(x),
            number(y),
            number(width),
            number(height)
        );
    }

    /// A circle of centre `(cx, cy)` and radius `r`; `style` as for [`Svg::rect`].
    pub fn circle(&mut self, cx: f64, cy: f64, r: f64, style: &str) {
        let _ = writeln!(
            self.out,
            "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" {style}/>",
            number(cx),
            number(cy),
            number(r)
        );
    }

    /// A line segment from `from` to `to`; `style` as for [`Svg::rect`].
    pub fn line(&mut self, from: (f64, f64), to: (f64, f64), style: &str) {
        let _ = writeln!(
            self.out,
            "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" {style}/>",
            number(from.0),
            number(from.1),
            number(to.0),
            number(to.1)
        );
    }

    /// A polygon (`closed`) or polyline through `points`; `style` as for [`Svg::rect`].
    pub fn path(&mut self, points: &[(f64, f64)], closed: bool, style: &str) {
        let points: Vec<String> = points
            .iter()
            .map(|&(x, y)| format!("{},{}", number(x), number(y)))
            .collect();
        let element = if closed { "polygon" } else { "polyline" };
        let _ = writeln!(
            self.out,
            "<{element} points=\"{}\" {style}/>",
            points.join(" ")
        );
    }

    /// `text` (escaped) at `(x, y)`, the baseline's point that `anchor` names, in a font of `size`
    /// pixels; `style` as for [`Svg::rect`].
    pub fn text(&mut self, x: f64, y: f64, size: f64, anchor: Anchor, style: &str, text: &str) {
        let anchor = match anchor {
            Anchor::Start => "start",
            Anchor::Middle => "middle",
            Anchor::End => "end",
        };
        let _ = writeln!(
            self.out,
            "<text x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"{anchor}\" {style}>{}</text>",
            number(x),
            number(y),
            number(size),
            escape(text)
        );
    }

    /// Opens a group carrying a tooltip (`<title>`), closed by [`Svg::end_group`].
    pub fn group(&mut self, tooltip: &str) {
        let _ = writeln!(self.out, "<g><title>{}</title>", escape(tooltip));
    }

    /// Closes the group [`Svg::group`] opened last.
    pub fn end_group(&mut self) {
        self.out.push_str("</g>\n");
    }

    /// Closes the document and returns its text.
    pub fn finish(mut self) -> String {
        self.out.push_str("</svg>\n");
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short_and_text_is_escaped() {
        assert_eq!(number(3.0), "3");
        assert_eq!(number(2.5), "2.5");
        assert_eq!(number(1.0 / 3.0), "0.33");
        assert_eq!(number(-0.001), "0");
        assert_eq!(
            escape("a<b & \"c\">\u{7}"),
            "a&lt;b &amp; &quot;c&quot;&gt; "
        );
        let mut svg = Svg::new(10.0, 20.0, "t & u");
        svg.text(1.0, 2.0, 12.0, Anchor::Middle, "", "x<y");
        let text = svg.finish();
        assert!(text.contains("<title>t &amp; u</title>"));
        assert!(text.contains(">x&lt;y</text>"));
        assert!(text.ends_with("</svg>\n"));
    }
}
