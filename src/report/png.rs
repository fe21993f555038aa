//! PNG plots: the SVG plots rendered to pixels, for documents, chat and
//! issue trackers that do not show SVG.
//!
//! The plots are written once, as SVG ([`super::svg`], `sweep::plot`), and
//! rasterised here with `resvg`, a pure-Rust SVG renderer, so the two
//! formats cannot drift apart and the SVG stays byte-for-byte deterministic.
//! (A plotting crate was considered instead of the hand-written SVG: most of
//! the SVG code is the layout of this project's own panels — chatter state
//! bands, thresholds, edge marks — which a general plotting crate does not
//! draw either, and its output would no longer be byte-identical from run to
//! run.)
//!
//! Text is drawn with the built-in stroke font (`src/report/glyphs.rs`): each
//! `<text>` element becomes a stroked path before rendering, so a PNG has
//! its labels on a machine without any fonts, and its look does not depend
//! on which fonts a machine has. The SVG keeps its text as text.

use std::fmt::Write;

use resvg::tiny_skia::{Color, Pixmap, Transform};
use resvg::usvg;

use super::glyphs::{self, Pen};
use super::svg::escape;
use thiserror::Error;

/// Pixels per SVG unit: twice the SVG's size, sharp on high-density screens.
pub const SCALE: f32 = 2.0;

/// Why an SVG could not become a PNG.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum PngError {
    /// The document is not SVG that resvg can read.
    #[error("the plot is not valid SVG: {0}")]
    Svg(#[from] usvg::Error),
    /// The picture would be empty or wider or taller than 16 384 px.
    #[error("the plot is {width}×{height} px, too large to render")]
    TooLarge {
        /// px
        width: u32,
        /// px
        height: u32,
    },
    /// The PNG encoder failed: its message.
    #[error("cannot encode the PNG: {0}")]
    Encode(String),
}

/// A rendered plot.
#[derive(Debug, Clone)]
pub struct Png {
    /// The PNG file's bytes.
    pub bytes: Vec<u8>,
    /// px, the SVG's width times [`SCALE`].
    pub width: u32,
    /// px, the SVG's height times [`SCALE`].
    pub height: u32,
}

/// The largest side rendered: a plot is a few thousand pixels; anything
/// larger is a malformed size, not a plot.
const MAX_SIDE: u32 = 16_384;

/// Render an SVG document to a PNG on a white background, at [`SCALE`].
pub fn render(svg: &str) -> Result<Png, PngError> {
    let tree = usvg::Tree::from_str(&outline_text(svg), &usvg::Options::default())?;
    let size = tree.size();
    let width = (size.width() * SCALE).ceil() as u32;
    let height = (size.height() * SCALE).ceil() as u32;
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(PngError::TooLarge { width, height });
    }
    let mut pixmap = Pixmap::new(width, height).ok_or(PngError::TooLarge { width, height })?;
    pixmap.fill(Color::WHITE);
    resvg::render(
        &tree,
        Transform::from_scale(SCALE, SCALE),
        &mut pixmap.as_mut(),
    );
    let bytes = pixmap
        .encode_png()
        .map_err(|e| PngError::Encode(e.to_string()))?;
    Ok(Png {
        bytes,
        width,
        height,
    })
}

/// How text is drawn where it stands: what an element sets or inherits.
#[derive(Debug, Clone)]
struct TextStyle {
    size: f64,
    bold: bool,
    anchor: Anchor,
    fill: String,
}

/// Where a text's x is: its start, middle or end.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Anchor {
    Start,
    Middle,
    End,
}

impl Default for TextStyle {
    /// SVG's initial values: 16 px ("medium"), normal weight, black.
    fn default() -> Self {
        TextStyle {
            size: 16.0,
            bold: false,
            anchor: Anchor::Start,
            fill: "#000000".to_owned(),
        }
    }
}

impl TextStyle {
    /// This style with what an element's attributes set.
    fn with(&self, attributes: &[(&str, String)]) -> TextStyle {
        let mut style = self.clone();
        for (name, value) in attributes {
            match *name {
                "font-size" => {
                    let number = value.trim().trim_end_matches("px");
                    if let Ok(size) = number.parse::<f64>()
                        && size.is_finite()
                        && size >= 0.0
                    {
                        style.size = size;
                    }
                }
                "font-weight" => {
                    style.bold = match value.trim() {
                        "bold" | "bolder" => true,
                        "normal" | "lighter" => false,
                        number => number.parse::<u32>().is_ok_and(|w| w >= 600),
                    }
                }
                "text-anchor" => {
                    style.anchor = match value.trim() {
                        "middle" => Anchor::Middle,
                        "end" => Anchor::End,
                        _ => Anchor::Start,
                    }
                }
                "fill" => style.fill = value.clone(),
                _ => {}
            }
        }
        style
    }

    /// The stroke width: a regular weight at 8 % of the size, bold at 13 %.
    fn stroke_width(&self) -> f64 {
        self.size * if self.bold { 0.13 } else { 0.08 }
    }
}

/// `svg` with every `<text>` element replaced by its strokes in the
/// built-in font, as a stroked `<path>` in the text's colour (its
/// `transform` and opacity kept). Styles are inherited from enclosing
/// elements as SVG inherits them: size, weight, anchor and fill. Whitespace
/// is collapsed as SVG does by default. Everything else is copied.
fn outline_text(svg: &str) -> String {
    let mut out = String::with_capacity(svg.len() + svg.len() / 2);
    let mut styles = vec![TextStyle::default()];
    let mut rest = svg;
    while let Some(open) = rest.find('<') {
        out.push_str(&rest[..open]);
        rest = &rest[open..];
        let Some(close) = tag_end(rest) else {
            break;
        };
        let tag = &rest[..=close];
        if tag_name(tag) == "text"
            && !tag.ends_with("/>")
            && let Some(end) = rest.find("</text>")
        {
            let inner = &rest[close + 1..end];
            let style = styles.last().cloned().unwrap_or_default();
            write_text(&style, &tag_attributes(tag), inner, &mut out);
            rest = &rest[end + "</text>".len()..];
            continue;
        }
        follow(&mut styles, tag);
        out.push_str(tag);
        rest = &rest[close + 1..];
    }
    out.push_str(rest);
    out
}

/// The index of the `>` closing the tag `s` starts with, past quoted
/// attribute values and comments.
fn tag_end(s: &str) -> Option<usize> {
    if s.starts_with("<!--") {
        return s.find("-->").map(|i| i + 2);
    }
    let mut quote = None;
    for (i, c) in s.char_indices() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '>') => return Some(i),
            _ => {}
        }
    }
    None
}

/// The style stack after `tag`: a start tag pushes its element's style,
/// an end tag pops it; comments, declarations and empty elements leave it.
fn follow(styles: &mut Vec<TextStyle>, tag: &str) {
    if tag.starts_with("</") {
        if styles.len() > 1 {
            styles.pop();
        }
    } else if !tag.starts_with("<!") && !tag.starts_with("<?") && !tag.ends_with("/>") {
        let parent = styles.last().cloned().unwrap_or_default();
        styles.push(parent.with(&tag_attributes(tag)));
    }
}

/// The attributes of a start tag (`<name …>`), values unescaped.
fn tag_attributes(tag: &str) -> Vec<(&str, String)> {
    let start = 1 + tag_name(tag).len();
    attributes(tag.get(start..tag.len() - 1).unwrap_or(""))
}

/// The element name of a tag (`"g"` for `<g fill="red">`, `</g>`).
fn tag_name(tag: &str) -> &str {
    let name = tag.trim_start_matches('<').trim_start_matches('/');
    let len = name
        .find(|c: char| c.is_whitespace() || c == '>' || c == '/')
        .unwrap_or(name.len());
    &name[..len]
}

/// The `name="value"` pairs of a start tag's attribute text, values
/// unescaped.
fn attributes(text: &str) -> Vec<(&str, String)> {
    let mut pairs = Vec::new();
    let mut rest = text;
    while let Some(eq) = rest.find('=') {
        let name = rest[..eq].trim();
        let after = rest[eq + 1..].trim_start();
        let Some(quote) = after.chars().next().filter(|c| *c == '"' || *c == '\'') else {
            break;
        };
        let Some(len) = after[1..].find(quote) else {
            break;
        };
        pairs.push((name, unescape(&after[1..1 + len])));
        rest = &after[len + 2..];
    }
    pairs
}

/// Character data with XML's entities and character references resolved.
fn unescape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(amp) = rest.find('&') {
        out.push_str(&rest[..amp]);
        rest = &rest[amp..];
        let Some(semi) = rest.find(';').filter(|&i| i <= 10) else {
            out.push('&');
            rest = &rest[1..];
            continue;
        };
        let entity = &rest[1..semi];
        let c = match entity {
            "amp" => Some('&'),
            "lt" => Some('<'),
            "gt" => Some('>'),
            "quot" => Some('"'),
            "apos" => Some('\''),
            _ => entity
                .strip_prefix("#x")
                .map(|hex| u32::from_str_radix(hex, 16))
                .or_else(|| entity.strip_prefix('#').map(str::parse))
                .and_then(Result::ok)
                .and_then(char::from_u32),
        };
        match c {
            Some(c) => {
                out.push(c);
                rest = &rest[semi + 1..];
            }
            None => {
                out.push('&');
                rest = &rest[1..];
            }
        }
    }
    out.push_str(rest);
    out
}

/// One `<text>` element, drawn: `attributes` are the text's own, `inner`
/// its content (character data and `<tspan>` children).
fn write_text(inherited: &TextStyle, attributes: &[(&str, String)], inner: &str, out: &mut String) {
    let style = inherited.with(attributes);
    // The runs of characters with their style, whitespace collapsed over
    // the whole text as SVG does: runs of spaces become one, none at the ends.
    let mut runs: Vec<(TextStyle, String)> = Vec::new();
    let mut space = true;
    let mut push = |style: &TextStyle, text: &str, runs: &mut Vec<(TextStyle, String)>| {
        let mut kept = String::new();
        for c in text.chars() {
            let c = if matches!(c, '\n' | '\t' | '\r') {
                ' '
            } else {
                c
            };
            if c == ' ' && space {
                continue;
            }
            space = c == ' ';
            kept.push(c);
        }
        if !kept.is_empty() {
            runs.push((style.clone(), kept));
        }
    };
    let mut rest = inner;
    let mut span_styles = vec![style.clone()];
    while !rest.is_empty() {
        let next = rest.find('<').unwrap_or(rest.len());
        let current = span_styles.last().unwrap_or(&style);
        push(current, &unescape(&rest[..next]), &mut runs);
        rest = &rest[next..];
        let Some(close) = tag_end(rest) else {
            break;
        };
        follow(&mut span_styles, &rest[..=close]);
        rest = &rest[close + 1..];
    }
    if let Some((_, last)) = runs.last_mut()
        && last.ends_with(' ')
    {
        last.pop();
    }
    let width: f64 = runs.iter().map(|(s, t)| glyphs::advance(t) * s.size).sum();
    let number = |name: &str| {
        attributes
            .iter()
            .find(|(n, _)| *n == name)
            .and_then(|(_, v)| v.split([' ', ',']).next()?.parse::<f64>().ok())
            .filter(|v| v.is_finite())
            .unwrap_or(0.0)
    };
    let mut x = number("x")
        - match style.anchor {
            Anchor::Start => 0.0,
            Anchor::Middle => width / 2.0,
            Anchor::End => width,
        };
    let y = number("y");
    let kept: String = attributes
        .iter()
        .filter(|(n, _)| matches!(*n, "transform" | "opacity"))
        .map(|(n, v)| format!(r#" {n}="{}""#, escape(v)))
        .collect();
    for (run, text) in runs {
        let mut d = String::new();
        let pen = Pen {
            x,
            y,
            size: run.size,
        };
        x = glyphs::strokes(&text, pen, &mut d);
        if d.is_empty() || run.fill.trim() == "none" {
            continue;
        }
        let _ = write!(
            out,
            r#"<path{kept} d="{d}" fill="none" stroke="{}" stroke-width="{}" stroke-linecap="round" stroke-linejoin="round"/>"#,
            escape(&run.fill),
            run.stroke_width(),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: &str = r##"<svg xmlns="http://www.w3.org/2000/svg" width="40" height="30" viewBox="0 0 40 30"><rect x="10" y="5" width="20" height="10" fill="#ff0000"/></svg>"##;

    #[test]
    fn a_plot_becomes_a_png_of_twice_its_size_with_its_pixels_where_drawn() {
        let png = render(SQUARE).unwrap();
        assert_eq!(&png.bytes[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!((png.width, png.height), (80, 60));
        let pixmap = Pixmap::decode_png(&png.bytes).unwrap();
        let at = |x: u32, y: u32| pixmap.pixel(x, y).unwrap();
        // Inside the rectangle (scaled ×2): red; outside: the white page.
        let inside = at(40, 20);
        assert_eq!((inside.red(), inside.green(), inside.blue()), (255, 0, 0));
        let outside = at(5, 5);
        assert_eq!(
            (outside.red(), outside.green(), outside.blue()),
            (255, 255, 255)
        );
    }

    #[test]
    fn not_svg_is_an_error_not_a_panic() {
        assert!(matches!(render("<svg"), Err(PngError::Svg(_))));
        assert!(matches!(render("hello"), Err(PngError::Svg(_))));
    }

    #[test]
    fn an_absurd_size_is_refused() {
        let huge = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100000" height="10"></svg>"#;
        assert!(matches!(render(huge), Err(PngError::TooLarge { .. })));
    }

    /// The dark pixels' bounding box (x0, y0, x1, y1), px.
    fn ink(png: &Png) -> Option<(u32, u32, u32, u32)> {
        let pixmap = Pixmap::decode_png(&png.bytes).unwrap();
        let mut bbox: Option<(u32, u32, u32, u32)> = None;
        for y in 0..png.height {
            for x in 0..png.width {
                if pixmap.pixel(x, y).unwrap().red() < 128 {
                    let b = bbox.get_or_insert((x, y, x, y));
                    *b = (b.0.min(x), b.1.min(y), b.2.max(x), b.3.max(y));
                }
            }
        }
        bbox
    }

    fn page(body: &str) -> String {
        format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="60" viewBox="0 0 200 60" font-size="12">{body}</svg>"#
        )
    }

    #[test]
    fn text_is_drawn_without_any_font_where_it_is_anchored() {
        // "HH" at size 20: 2 × 0.722 em = 28.9 units wide, capitals 14.4 high.
        let start = render(&page(r#"<text x="100" y="40" font-size="20">HH</text>"#)).unwrap();
        let (x0, y0, x1, y1) = ink(&start).expect("the text has ink");
        // ×2 pixels: the first stem at 100 + 2 (0.1 em), the last at
        // 100 + 2 × 14.44 − 2, the baseline at 40, the cap line at 25.6.
        let near = |px: u32, units: f64| (f64::from(px) / 2.0 - units).abs() < 1.5;
        assert!(near(x0, 102.0) && near(x1, 126.9), "{x0}..{x1}");
        assert!(near(y0, 25.64) && near(y1, 40.0), "{y0}..{y1}");
        let end = render(&page(
            r#"<text x="100" y="40" font-size="20" text-anchor="end">HH</text>"#,
        ))
        .unwrap();
        let (e0, _, e1, _) = ink(&end).unwrap();
        assert!(
            near(e0, 102.0 - 28.88) && near(e1, 126.9 - 28.88),
            "{e0}..{e1}"
        );
        let middle = render(&page(
            r#"<text x="100" y="40" font-size="20" text-anchor="middle">HH</text>"#,
        ))
        .unwrap();
        let (m0, _, _, _) = ink(&middle).unwrap();
        assert!(near(m0, 102.0 - 14.44), "{m0}");
    }

    #[test]
    fn text_inherits_size_weight_and_colour_from_its_group() {
        let plain = render(&page(r#"<text x="10" y="40">IIII</text>"#)).unwrap();
        let group = render(&page(
            r##"<g font-size="24" font-weight="bold" fill="#ff0000"><text x="10" y="40">IIII</text></g>"##,
        ))
        .unwrap();
        let (_, p0, _, p1) = ink(&plain).unwrap();
        // The page's 12: an I is 0.718 em high, plus the round caps.
        assert!(
            ((p1 - p0) as f64 / 2.0 - 0.718 * 12.0).abs() < 1.5,
            "{p0}..{p1}"
        );
        // Red text has no dark red channel; its green channel is dark.
        assert!(ink(&group).is_none());
        let pixmap = Pixmap::decode_png(&group.bytes).unwrap();
        let red = (0..group.height)
            .flat_map(|y| (0..group.width).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let p = pixmap.pixel(x, y).unwrap();
                p.red() > 200 && p.green() < 60
            })
            .count();
        let dark = |png: &Png| {
            let pixmap = Pixmap::decode_png(&png.bytes).unwrap();
            (0..png.height)
                .flat_map(|y| (0..png.width).map(move |x| (x, y)))
                .filter(|&(x, y)| pixmap.pixel(x, y).unwrap().green() < 60)
                .count()
        };
        // Twice the size and bold: far more ink than the plain text.
        assert!(red > 3 * dark(&plain), "{red} against {}", dark(&plain));
    }

    #[test]
    fn spans_entities_and_whitespace_are_read_as_svg_reads_them() {
        let svg = page(
            r#"<text x="0" y="30" transform="translate(5,0)">  <tspan font-weight="bold">a&amp;b</tspan>   c&#x3bc;
</text><rect x="1" y="1" width="2" height="2"/>"#,
        );
        let out = outline_text(&svg);
        assert!(!out.contains("<text"), "{out}");
        assert!(out.contains(r#"<rect x="1" y="1" width="2" height="2"/>"#));
        // The bold span and the rest: two paths, both moved by the transform.
        assert_eq!(out.matches("<path").count(), 2, "{out}");
        assert_eq!(out.matches(r#"transform="translate(5,0)""#).count(), 2);
        assert!(out.contains(r#"stroke-width="1.56""#), "{out}");
        assert!(out.contains(r#"stroke-width="0.96""#), "{out}");
        // The second run starts after "a&b " (one space, not three).
        let width = (0.556 + 0.667 + 0.556 + 0.278) * 12.0;
        let second = out.rsplit("<path").next().unwrap();
        let c_start: f64 = second
            .split(" d=\"M")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        // 'c' is an arc starting at 40° around (280, 261), rx 190.
        let expected = width + (280.0 + 190.0 * 40f64.to_radians().cos()) * 12.0 / 1000.0;
        assert!(
            (c_start - expected).abs() < 0.01,
            "{c_start} against {expected}"
        );
    }

    #[test]
    fn comments_and_invisible_or_empty_text_are_left_alone() {
        let text = r#"<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"><!-- a <text> in a comment --><text x="1" y="2" fill="none">x</text><text x="1" y="2"/></svg>"#;
        let out = outline_text(text);
        assert!(out.contains("<!-- a <text> in a comment -->"));
        // Invisible text draws nothing; an empty element is left as it is.
        assert!(!out.contains("<path"), "{out}");
        assert!(render(text).is_ok());
    }
}
