//! The one font the pictures are laid out for, DejaVu Sans (the file and its licence are in
//! `assets/fonts/`, where the command's PNG output loads it from): the advance widths of the
//! characters the pictures write, so that every text's box is known before it is drawn. Each
//! `<text>` also carries its width as `textLength`, so a viewer that substitutes another font
//! still fits the text into that box.
//!
//! The figures are the font's own (units of 1/2048 em; the crate's `tests/render/font.rs` checks
//! them against the bundled file).

/// Font units per em.
pub const UNITS_PER_EM: f64 = 2048.0;

/// How far above the baseline a text's box reaches, in em: the tallest of the characters in
/// the tables below (`` ` ``: 1638/2048).
pub const ASCENT: f64 = 0.8;

/// How far below the baseline a text's box reaches, in em (`_`: 483/2048).
pub const DESCENT: f64 = 0.24;

/// The family name written in the SVG, with fallbacks of similar width.
pub const FAMILY: &str = "DejaVu Sans, Verdana, sans-serif";

/// Advance widths of the printable ASCII characters, from `' '` (32) to `'~'` (126).
pub const ASCII: [u16; 95] = [
    651, 821, 942, 1716, 1303, 1946, 1597, 563, 799, 799, 1024, 1716, 651, 739, 651, 690, 1303,
    1303, 1303, 1303, 1303, 1303, 1303, 1303, 1303, 1303, 690, 690, 1716, 1716, 1716, 1087, 2048,
    1401, 1405, 1430, 1577, 1294, 1178, 1587, 1540, 604, 604, 1343, 1141, 1767, 1532, 1612, 1235,
    1612, 1423, 1300, 1251, 1499, 1401, 2025, 1403, 1251, 1403, 799, 690, 799, 1716, 1024, 1024,
    1255, 1300, 1126, 1300, 1260, 721, 1300, 1298, 569, 569, 1186, 569, 1995, 1298, 1253, 1300,
    1300, 842, 1067, 803, 1298, 1212, 1675, 1212, 1212, 1075, 1303, 690, 1303, 1716,
];

/// Advance widths of the other characters the pictures write (Greek letters of formulas and
/// settings, subscript digits, logical connectives, typographic marks).
pub const OTHERS: [(char, u16); 34] = [
    ('×', 1716),
    ('¬', 1716),
    ('γ', 1212),
    ('σ', 1298),
    ('φ', 1351),
    ('ψ', 1351),
    ('–', 1024),
    ('—', 2048),
    ('…', 2048),
    ('₀', 821),
    ('₁', 821),
    ('₂', 821),
    ('₃', 821),
    ('₄', 821),
    ('₅', 821),
    ('₆', 821),
    ('₇', 821),
    ('₈', 821),
    ('₉', 821),
    ('→', 1716),
    ('↔', 1716),
    ('∧', 1499),
    ('∨', 1499),
    ('≤', 1716),
    ('≥', 1716),
    ('●', 1787),
    ('◆', 1575),
    ('·', 651),
    ('°', 1024),
    ('≠', 1716),
    ('∞', 1706),
    ('δ', 1253),
    ('ε', 1107),
    ('π', 1233),
];

/// The advance width of `c` in em; characters outside the tables count as a full em (wider
/// than any of the font's letters, so their boxes are never too small).
pub fn advance(c: char) -> f64 {
    let units = match c {
        ' '..='~' => ASCII[c as usize - 32],
        _ => OTHERS
            .iter()
            .find(|&&(other, _)| other == c)
            .map_or(2048, |&(_, units)| units),
    };
    f64::from(units) / UNITS_PER_EM
}

/// The width of `text` set at `size` pixels (no kerning: the sum of the advances).
pub fn width(text: &str, size: f64) -> f64 {
    text.chars().map(advance).sum::<f64>() * size
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_add_up_the_advances() {
        // "10": two digits of 1303 units.
        assert!((width("10", 20.48) - 26.06).abs() < 1e-9);
        assert_eq!(advance('i'), 569.0 / 2048.0);
        assert_eq!(advance('φ'), 1351.0 / 2048.0);
        assert_eq!(advance('\u{4E00}'), 1.0);
        let mut seen: Vec<char> = OTHERS.iter().map(|&(c, _)| c).collect();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), OTHERS.len(), "a character listed twice");
    }
}
