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
//! Text needs a font. The system's fonts are searched once per process; the
//! plots ask for Helvetica or Arial, and when neither is installed the first
//! of Liberation Sans, DejaVu Sans or any sans-serif font stands in. With no
//! font at all the PNG is drawn without its text and [`Png::missing_fonts`]
//! says so, so the caller can warn (on Debian: `apt-get install
//! fonts-dejavu-core`).

use std::sync::{Arc, OnceLock};

use resvg::tiny_skia::{Color, Pixmap, Transform};
use resvg::usvg::{self, fontdb};
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
    /// No font was found, so the text was left out.
    pub missing_fonts: bool,
}

/// The largest side rendered: a plot is a few thousand pixels; anything
/// larger is a malformed size, not a plot.
const MAX_SIDE: u32 = 16_384;

/// The system fonts, loaded once, with a sans-serif family that exists.
fn fonts() -> Arc<fontdb::Database> {
    static FONTS: OnceLock<Arc<fontdb::Database>> = OnceLock::new();
    FONTS
        .get_or_init(|| {
            let mut db = fontdb::Database::new();
            db.load_system_fonts();
            let has = |name: &str| {
                db.faces()
                    .any(|f| f.families.iter().any(|(n, _)| n.eq_ignore_ascii_case(name)))
            };
            let preferred = ["Helvetica", "Arial", "Liberation Sans", "DejaVu Sans"]
                .into_iter()
                .find(|name| has(name))
                .map(str::to_owned)
                .or_else(|| {
                    db.faces()
                        .find(|f| !f.monospaced)
                        .and_then(|f| f.families.first().map(|(n, _)| n.clone()))
                });
            if let Some(family) = preferred {
                db.set_sans_serif_family(family);
            }
            Arc::new(db)
        })
        .clone()
}

/// Whether any font was found: without one a PNG has no text.
pub fn fonts_available() -> bool {
    !fonts().is_empty()
}

/// Render an SVG document to a PNG on a white background, at [`SCALE`].
pub fn render(svg: &str) -> Result<Png, PngError> {
    let fontdb = fonts();
    let missing_fonts = fontdb.is_empty();
    let options = usvg::Options {
        fontdb,
        ..usvg::Options::default()
    };
    let tree = usvg::Tree::from_str(svg, &options)?;
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
        missing_fonts,
    })
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
}
