//! The library's table of the bundled font's metrics, which lays pictures out, checked against
//! the font file itself (`--png`, which rasterises with that font, is the command's
//! `tests/render_png.rs`).

use hypersynth::render::font;
use skrifa::instance::{LocationRef, Size};
use skrifa::{FontRef, MetadataProvider};

const FONT: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../assets/fonts/DejaVuSans.ttf"
);

#[test]
fn the_metrics_table_is_the_bundled_fonts() {
    let data = std::fs::read(FONT).unwrap();
    let face = FontRef::new(&data).unwrap();
    let metrics = face.glyph_metrics(Size::unscaled(), LocationRef::default());
    let charmap = face.charmap();
    let others = font::OTHERS.iter().map(|&(c, _)| c);
    for c in (' '..='~').chain(others) {
        let glyph = charmap
            .map(c)
            .unwrap_or_else(|| panic!("{c:?} not in the font"));
        let advance = metrics.advance_width(glyph).unwrap();
        assert_eq!(
            f64::from(advance) / font::UNITS_PER_EM,
            font::advance(c),
            "{c:?}"
        );
        if let Some(bounds) = metrics.bounds(glyph) {
            let (top, bottom) = (
                f64::from(bounds.y_max) / font::UNITS_PER_EM,
                f64::from(bounds.y_min) / font::UNITS_PER_EM,
            );
            assert!(top <= font::ASCENT && -bottom <= font::DESCENT, "{c:?}");
        }
    }
}
