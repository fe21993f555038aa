//! A single-stroke sans-serif font, built in, for the text of the PNG plots.
//!
//! The PNG plots are the SVG plots rasterised; their text was drawn from
//! the system's fonts, so a machine without fonts (a container, a CI
//! runner) got plots without labels, and reading fonts took a font stack
//! larger than the rest of the renderer. Plot labels are short, mostly
//! ASCII, and need to be legible, not beautiful: each glyph here is a few
//! strokes (lines and elliptical arcs) drawn with round caps, like a
//! plotter's lettering.
//!
//! Coordinates are in thousandths of the font size, y up from the baseline:
//! capitals are 718 high, the x-height is 523 and descenders reach −207.
//! Advance widths follow the proportions of the common sans-serif fonts the
//! SVG asks for, so that text laid out for the SVG (right-aligned labels,
//! legends) fits the same space in the PNG.
//!
//! A glyph's strokes are written in a small path language:
//! `M x y` starts a stroke, `L x y` draws a line, and `A cx cy rx ry a0 a1`
//! draws the arc of the ellipse centred at (cx, cy) with radii rx, ry from
//! angle a0 to angle a1 (degrees, counter-clockwise from +x; a1 < a0 runs
//! clockwise), joined by a line to the stroke's current point if it has one.

use std::fmt::Write;

/// A glyph: its advance width and its strokes.
struct Glyph {
    advance: f64,
    strokes: &'static str,
}

/// The advance and strokes of `c`; a character the font lacks is a box.
fn glyph(c: char) -> Glyph {
    let (advance, strokes) = match c {
        ' ' | '\u{a0}' => (278, ""),
        '\u{2009}' | '\u{202f}' => (167, ""),
        '0' => (556, "A 278 351 188 351 0 360"),
        '1' => (556, "M 160 560 L 300 703 L 300 0"),
        '2' => (556, "A 278 510 180 193 160 -40 L 90 0 L 470 0"),
        '3' => (556, "A 278 534 165 169 150 -90 A 278 182 188 183 90 -150"),
        '4' => (556, "M 390 0 L 390 703 L 70 215 L 490 215"),
        '5' => (
            556,
            "M 440 703 L 140 703 L 118 400 A 280 225 190 225 128 -150",
        ),
        '6' => (
            556,
            "M 455 570 A 300 360 200 343 35 180 L 100 225 A 285 225 183 225 180 540",
        ),
        '7' => (556, "M 90 703 L 466 703 L 200 0"),
        '8' => (
            556,
            "A 278 535 160 168 0 360 M 463 190 A 278 190 185 190 0 360",
        ),
        '9' => (
            556,
            "A 270 478 183 225 0 360 M 453 478 L 455 343 A 255 343 200 343 0 -145",
        ),
        'A' => (667, "M 40 0 L 333 718 L 627 0 M 150 260 L 517 260"),
        'B' => (
            667,
            "M 100 372 L 420 372 A 420 186 170 186 90 -90 L 100 0 L 100 718 L 390 718 \
             A 390 545 150 173 90 -90 L 100 372",
        ),
        'C' => (722, "A 400 359 300 359 45 315"),
        'D' => (
            722,
            "M 100 0 L 100 718 L 330 718 A 330 359 300 359 90 -90 L 100 0",
        ),
        'E' => (
            667,
            "M 560 718 L 100 718 L 100 0 L 570 0 M 100 370 L 520 370",
        ),
        'F' => (611, "M 540 718 L 100 718 L 100 0 M 100 370 L 500 370"),
        'G' => (778, "A 420 359 320 359 45 345 L 729 330 L 450 330"),
        'H' => (
            722,
            "M 100 0 L 100 718 M 622 0 L 622 718 M 100 370 L 622 370",
        ),
        'I' => (278, "M 139 0 L 139 718"),
        'J' => (500, "M 400 718 L 400 200 A 240 200 160 200 0 -180"),
        'K' => (
            667,
            "M 100 0 L 100 718 M 600 718 L 100 260 M 280 420 L 620 0",
        ),
        'L' => (556, "M 100 718 L 100 0 L 520 0"),
        'M' => (833, "M 90 0 L 90 718 L 416 0 L 743 718 L 743 0"),
        'N' => (722, "M 100 0 L 100 718 L 622 0 L 622 718"),
        'O' => (778, "A 389 359 300 359 0 360"),
        'P' => (
            667,
            "M 100 0 L 100 718 L 400 718 A 400 530 180 188 90 -90 L 100 342",
        ),
        'Q' => (778, "A 389 359 300 359 0 360 M 450 200 L 700 -40"),
        'R' => (
            722,
            "M 100 0 L 100 718 L 420 718 A 420 535 180 183 90 -90 L 100 352 \
             M 400 352 L 640 0",
        ),
        'S' => (667, "A 333 535 220 183 20 270 A 333 176 240 176 90 -160"),
        'T' => (611, "M 40 718 L 571 718 M 305 718 L 305 0"),
        'U' => (
            722,
            "M 100 718 L 100 260 A 361 260 261 260 180 360 L 622 718",
        ),
        'V' => (667, "M 40 718 L 333 0 L 627 718"),
        'W' => (944, "M 40 718 L 250 0 L 472 718 L 694 0 L 904 718"),
        'X' => (667, "M 60 718 L 607 0 M 607 718 L 60 0"),
        'Y' => (667, "M 40 718 L 333 360 L 627 718 M 333 360 L 333 0"),
        'Z' => (611, "M 70 718 L 541 718 L 70 0 L 551 0"),
        'a' => (556, "A 255 261 175 261 0 360 M 440 523 L 440 0"),
        'b' => (556, "M 100 718 L 100 0 M 485 261 A 300 261 185 261 0 360"),
        'c' => (500, "A 280 261 190 261 40 320"),
        'd' => (556, "M 456 718 L 456 0 M 441 261 A 256 261 185 261 0 360"),
        'e' => (556, "M 95 261 L 465 261 A 280 261 185 261 0 320"),
        'f' => (
            278,
            "M 290 700 A 220 620 70 90 80 180 L 150 0 M 40 523 L 270 523",
        ),
        'g' => (
            556,
            "A 256 261 185 261 0 360 M 456 523 L 456 -20 A 271 -20 185 187 0 -160",
        ),
        'h' => (
            556,
            "M 100 718 L 100 0 M 100 330 A 280 330 180 193 180 0 L 460 0",
        ),
        'i' => (222, "M 111 0 L 111 523 M 111 680 L 111 700"),
        'j' => (
            222,
            "M 130 523 L 130 -100 A 40 -100 90 100 0 -120 M 130 680 L 130 700",
        ),
        'k' => (
            500,
            "M 100 718 L 100 0 M 430 523 L 100 200 M 220 310 L 450 0",
        ),
        'l' => (222, "M 111 718 L 111 0"),
        'm' => (
            833,
            "M 90 0 L 90 523 M 90 380 A 240 380 150 143 180 0 L 390 0 \
             M 390 380 A 560 380 150 143 180 0 L 710 0",
        ),
        'n' => (
            556,
            "M 100 0 L 100 523 M 100 340 A 280 340 180 183 180 0 L 460 0",
        ),
        'o' => (556, "A 278 261 185 261 0 360"),
        'p' => (
            556,
            "M 100 523 L 100 -207 M 485 261 A 300 261 185 261 0 360",
        ),
        'q' => (
            556,
            "M 456 523 L 456 -207 M 441 261 A 256 261 185 261 0 360",
        ),
        'r' => (333, "M 100 0 L 100 523 M 100 330 A 260 330 160 193 180 70"),
        's' => (500, "A 250 392 160 131 20 270 A 250 130 170 131 90 -160"),
        't' => (
            278,
            "M 140 680 L 140 80 A 220 80 80 80 180 300 M 40 523 L 260 523",
        ),
        'u' => (
            556,
            "M 100 523 L 100 180 A 280 180 180 180 180 360 M 460 523 L 460 0",
        ),
        'v' => (500, "M 50 523 L 250 0 L 450 523"),
        'w' => (722, "M 30 523 L 190 0 L 361 523 L 532 0 L 692 523"),
        'x' => (500, "M 70 523 L 430 0 M 430 523 L 70 0"),
        'y' => (
            500,
            "M 50 523 L 250 0 M 450 523 L 205 -130 L 160 -190 L 90 -207",
        ),
        'z' => (500, "M 70 523 L 430 523 L 70 0 L 440 0"),
        '!' => (278, "M 139 718 L 139 180 M 139 20 L 139 0"),
        '"' => (355, "M 110 718 L 110 500 M 245 718 L 245 500"),
        '#' => (
            556,
            "M 210 690 L 170 0 M 390 690 L 350 0 M 70 460 L 500 460 M 50 240 L 480 240",
        ),
        '$' => (
            556,
            "A 278 535 180 165 20 270 A 278 185 195 185 90 -160 M 278 790 L 278 -90",
        ),
        '%' => (
            889,
            "A 200 540 110 160 0 360 M 800 170 A 690 170 110 160 0 360 M 700 718 L 190 0",
        ),
        '&' => (
            667,
            "M 620 0 L 210 460 A 300 580 95 120 220 -30 L 150 250 \
             A 280 180 165 180 150 300 L 580 300",
        ),
        '\'' => (191, "M 95 718 L 95 500"),
        '(' => (333, "A 360 280 200 460 120 240"),
        ')' => (333, "A -27 280 200 460 60 -60"),
        '*' => (
            389,
            "M 195 718 L 195 440 M 75 650 L 315 510 M 315 650 L 75 510",
        ),
        '+' => (584, "M 292 80 L 292 520 M 72 300 L 512 300"),
        ',' => (278, "M 150 40 L 150 0 L 100 -120"),
        '-' => (333, "M 60 280 L 273 280"),
        '.' => (278, "M 139 20 L 139 0"),
        '/' => (278, "M 0 -20 L 278 730"),
        ':' => (278, "M 139 20 L 139 0 M 139 523 L 139 503"),
        ';' => (278, "M 139 523 L 139 503 M 150 40 L 150 0 L 100 -120"),
        '<' => (584, "M 512 520 L 72 300 L 512 80"),
        '=' => (584, "M 72 400 L 512 400 M 72 200 L 512 200"),
        '>' => (584, "M 72 520 L 512 300 L 72 80"),
        '?' => (
            556,
            "A 278 540 170 170 160 -60 L 278 300 L 278 180 M 278 20 L 278 0",
        ),
        '@' => (
            1015,
            "A 480 280 130 160 0 360 M 620 440 L 620 160 L 720 120 A 507 300 400 420 -20 300",
        ),
        '[' => (278, "M 230 718 L 100 718 L 100 -150 L 230 -150"),
        '\\' => (278, "M 0 730 L 278 -20"),
        ']' => (278, "M 48 718 L 178 718 L 178 -150 L 48 -150"),
        '^' => (469, "M 60 400 L 235 718 L 410 400"),
        '_' => (556, "M 0 -150 L 556 -150"),
        '`' => (333, "M 100 730 L 220 600"),
        '{' => (
            334,
            "M 260 718 L 200 700 L 180 640 L 180 380 L 100 290 L 180 200 L 180 -60 \
             L 200 -120 L 260 -140",
        ),
        '|' => (260, "M 130 730 L 130 -207"),
        '}' => (
            334,
            "M 74 718 L 134 700 L 154 640 L 154 380 L 234 290 L 154 200 L 154 -60 \
             L 134 -120 L 74 -140",
        ),
        '~' => (
            584,
            "M 70 280 L 140 330 L 220 330 L 360 260 L 440 260 L 512 310",
        ),
        'µ' | 'μ' => (
            556,
            "M 100 523 L 100 -207 M 100 180 A 280 180 180 180 180 360 M 460 523 L 460 0",
        ),
        'Ω' => (
            768,
            "M 70 0 L 250 0 L 250 90 A 384 400 290 318 245 -65 L 518 90 L 518 0 L 698 0",
        ),
        'Δ' => (667, "M 40 0 L 333 718 L 627 0 L 40 0"),
        'τ' => (
            500,
            "M 60 523 L 440 523 M 250 523 L 250 80 A 330 80 80 80 180 300",
        ),
        'π' => (
            556,
            "M 50 523 L 500 523 M 170 523 L 150 0 M 390 523 L 400 0",
        ),
        '°' => (400, "A 200 610 90 100 0 360"),
        '×' => (584, "M 110 120 L 474 480 M 474 120 L 110 480"),
        '·' | '⋅' => (278, "M 139 300 L 139 280"),
        '−' => (584, "M 72 300 L 512 300"),
        '–' => (556, "M 0 280 L 556 280"),
        '—' => (1000, "M 0 280 L 1000 280"),
        '²' => (333, "A 166 640 80 75 160 -40 L 70 440 L 260 440"),
        '³' => (333, "A 166 660 75 58 150 -90 A 166 545 85 60 90 -150"),
        '±' => (
            584,
            "M 292 160 L 292 560 M 72 360 L 512 360 M 72 30 L 512 30",
        ),
        '≤' => (584, "M 512 560 L 72 360 L 512 160 M 72 40 L 512 40"),
        '≥' => (584, "M 72 560 L 512 360 L 72 160 M 72 40 L 512 40"),
        '≈' => (
            584,
            "M 70 380 L 140 430 L 220 430 L 360 360 L 440 360 L 512 410 \
             M 70 180 L 140 230 L 220 230 L 360 160 L 440 160 L 512 210",
        ),
        '…' => (1000, "M 167 20 L 167 0 M 500 20 L 500 0 M 833 20 L 833 0"),
        '→' => (1000, "M 80 300 L 920 300 M 760 420 L 920 300 L 760 180"),
        '√' => (549, "M 40 300 L 140 330 L 260 0 L 520 800"),
        _ => (556, "M 80 0 L 80 718 L 476 718 L 476 0 L 80 0"),
    };
    Glyph {
        advance: f64::from(advance),
        strokes,
    }
}

/// The width of `text` at font size 1.
pub fn advance(text: &str) -> f64 {
    text.chars().map(|c| glyph(c).advance).sum::<f64>() / 1000.0
}

/// Where a piece of text is drawn: its pen position and size, user units.
#[derive(Debug, Clone, Copy)]
pub struct Pen {
    /// The left end of the baseline.
    pub x: f64,
    /// The baseline.
    pub y: f64,
    /// The font size: the em, in user units.
    pub size: f64,
}

/// Append SVG path data for `text`'s strokes at `pen` to `d` (SVG's y
/// down), returning the pen's x after the text.
pub fn strokes(text: &str, pen: Pen, d: &mut String) -> f64 {
    let scale = pen.size / 1000.0;
    let mut x = pen.x;
    for c in text.chars() {
        let g = glyph(c);
        let at = |gx: f64, gy: f64| (x + gx * scale, pen.y - gy * scale);
        draw(g.strokes, at, d);
        x += g.advance * scale;
    }
    x
}

/// The path data of one glyph's strokes, mapped through `at`.
fn draw(strokes: &str, at: impl Fn(f64, f64) -> (f64, f64), d: &mut String) {
    let mut words = strokes.split_ascii_whitespace();
    let mut current = false;
    let number = |words: &mut std::str::SplitAsciiWhitespace<'_>| -> f64 {
        words
            .next()
            .and_then(|w| w.parse().ok())
            .expect("a glyph's strokes are numbers after their command")
    };
    let point = |d: &mut String, command: char, (x, y): (f64, f64)| {
        let _ = write!(d, "{command}{} {}", round(x), round(y));
    };
    while let Some(command) = words.next() {
        match command {
            "M" => {
                let (x, y) = (number(&mut words), number(&mut words));
                point(d, 'M', at(x, y));
                current = true;
            }
            "L" => {
                let (x, y) = (number(&mut words), number(&mut words));
                point(d, if current { 'L' } else { 'M' }, at(x, y));
                current = true;
            }
            "A" => {
                let [cx, cy, rx, ry, a0, a1] = std::array::from_fn(|_| number(&mut words));
                // Steps of at most 12°: smooth at the sizes plots use.
                let steps = ((a1 - a0).abs() / 12.0).ceil().max(1.0) as usize;
                for k in 0..=steps {
                    let angle = (a0 + (a1 - a0) * k as f64 / steps as f64).to_radians();
                    let command = if k == 0 && !current { 'M' } else { 'L' };
                    point(d, command, at(cx + rx * angle.cos(), cy + ry * angle.sin()));
                }
                current = true;
            }
            other => unreachable!("a glyph's strokes have no command {other:?}"),
        }
    }
}

/// Two decimals: a hundredth of a user unit is below a pixel's tenth.
fn round(v: f64) -> f64 {
    (v * 100.0).round() / 100.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every point of the path data `d`.
    fn points(d: &str) -> Vec<(f64, f64)> {
        d.split(['M', 'L'])
            .filter(|p| !p.is_empty())
            .map(|p| {
                let mut v = p.split(' ').map(|n| n.parse::<f64>().unwrap());
                (v.next().unwrap(), v.next().unwrap())
            })
            .collect()
    }

    #[test]
    fn every_printable_ascii_character_is_drawn_inside_its_own_box() {
        // The symbols, and a character the font lacks (its box).
        let more = "µΩΔτπ°×·−–—²³±≤≥≈…→√\u{4e2d}";
        for c in (33u8..127).map(char::from).chain(more.chars()) {
            let g = glyph(c);
            assert!(!g.strokes.is_empty(), "{c:?} has no strokes");
            let mut d = String::new();
            let end = strokes(
                &c.to_string(),
                Pen {
                    x: 0.0,
                    y: 0.0,
                    size: 1000.0,
                },
                &mut d,
            );
            assert_eq!(end, g.advance, "{c:?}");
            let pts = points(&d);
            assert!(pts.len() >= 2, "{c:?}: {d}");
            for (x, y) in pts {
                // Glyphs may overhang their box by a stroke's width, no more.
                assert!((-60.0..=g.advance + 60.0).contains(&x), "{c:?}: x {x}");
                // y is down in SVG: from above the capitals to the descender.
                assert!((-800.0..=260.0).contains(&y), "{c:?}: y {y}");
            }
        }
    }

    #[test]
    fn the_box_stands_for_a_character_the_font_lacks_and_space_draws_nothing() {
        assert_eq!(glyph('\u{4e2d}').strokes, glyph('\u{fffd}').strokes);
        assert!(glyph('\u{4e2d}').strokes.starts_with("M 80 0"));
        let mut d = String::new();
        let end = strokes(
            "  ",
            Pen {
                x: 10.0,
                y: 5.0,
                size: 12.0,
            },
            &mut d,
        );
        assert!(d.is_empty());
        assert!((end - (10.0 + 2.0 * 0.278 * 12.0)).abs() < 1e-12);
    }

    #[test]
    fn text_scales_with_its_size_and_sits_on_its_baseline() {
        let mut d = String::new();
        strokes(
            "l",
            Pen {
                x: 100.0,
                y: 50.0,
                size: 10.0,
            },
            &mut d,
        );
        // The 'l' is one line from the ascender down to the baseline.
        assert_eq!(points(&d), vec![(101.11, 42.82), (101.11, 50.0)]);
        assert!((advance("Hello") - (0.722 + 0.556 + 0.222 + 0.222 + 0.556)).abs() < 1e-12);
    }
}
