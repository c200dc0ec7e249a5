//! Frames as pixels: the SVG of [`super::svg`] rasterized with resvg, written as PNG files or
//! as one animated GIF.
//!
//! Text needs a font, read at run time from `$POOLSIM_FONT` or, by default, from
//! [`DEFAULT_FONT`] (Debian's `fonts-dejavu-core`). A missing font is an error, not a picture
//! without names.

use resvg::tiny_skia::Pixmap;
use resvg::usvg;
use std::fmt;
use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;

/// Where the font is read from when `$POOLSIM_FONT` is not set.
pub const DEFAULT_FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

/// Why a picture could not be made.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RasterError(pub String);

impl fmt::Display for RasterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for RasterError {}

/// The font file to read: `$POOLSIM_FONT` if set, else [`DEFAULT_FONT`].
pub fn font_path() -> PathBuf {
    std::env::var_os("POOLSIM_FONT")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(DEFAULT_FONT))
}

/// Turns SVG text into pixels, with one font for every label.
pub struct Rasterizer {
    options: usvg::Options<'static>,
}

impl Rasterizer {
    /// A rasterizer with the font of [`font_path`].
    pub fn new() -> Result<Rasterizer, RasterError> {
        Rasterizer::with_font(&font_path())
    }

    /// A rasterizer with the font in file `path` (a TrueType or OpenType file).
    pub fn with_font(path: &std::path::Path) -> Result<Rasterizer, RasterError> {
        let data = std::fs::read(path).map_err(|e| {
            RasterError(format!(
                "{}: cannot read the font for the labels of PNG and GIF frames: {e} (install \
                 Debian's fonts-dejavu-core, or set POOLSIM_FONT to a .ttf file)",
                path.display()
            ))
        })?;
        let mut db = usvg::fontdb::Database::new();
        db.load_font_data(data);
        let family = db
            .faces()
            .next()
            .and_then(|f| f.families.first().map(|(name, _)| name.clone()))
            .ok_or_else(|| {
                RasterError(format!(
                    "{}: not a font file that can be read (TrueType or OpenType)",
                    path.display()
                ))
            })?;
        db.set_sans_serif_family(family.clone());
        let options = usvg::Options {
            font_family: family,
            fontdb: Arc::new(db),
            ..usvg::Options::default()
        };
        Ok(Rasterizer { options })
    }

    /// The SVG document `svg` as pixels, at one pixel per SVG unit.
    pub fn pixmap(&self, svg: &str) -> Result<Pixmap, RasterError> {
        let tree = usvg::Tree::from_str(svg, &self.options)
            .map_err(|e| RasterError(format!("cannot read the frame's SVG: {e}")))?;
        let size = tree.size().to_int_size();
        let mut pixmap = Pixmap::new(size.width(), size.height()).ok_or_else(|| {
            RasterError(format!(
                "cannot make a {} x {} picture",
                size.width(),
                size.height()
            ))
        })?;
        pixmap.fill(resvg::tiny_skia::Color::WHITE);
        resvg::render(
            &tree,
            resvg::tiny_skia::Transform::default(),
            &mut pixmap.as_mut(),
        );
        Ok(pixmap)
    }

    /// The SVG document `svg` as a PNG file's bytes.
    pub fn png(&self, svg: &str) -> Result<Vec<u8>, RasterError> {
        self.pixmap(svg)?
            .encode_png()
            .map_err(|e| RasterError(format!("cannot encode a PNG: {e}")))
    }
}

/// Writes frames as one animated GIF that loops forever.
pub struct GifWriter<W: Write> {
    encoder: gif::Encoder<W>,
    width: u16,
    height: u16,
    delay: u16,
}

impl<W: Write> GifWriter<W> {
    /// A GIF of `width` × `height` pixels whose frames each show for `delay_seconds` (rounded to
    /// hundredths, at least 0.02 s, the shortest delay browsers honour).
    pub fn new(
        out: W,
        width: u32,
        height: u32,
        delay_seconds: f64,
    ) -> Result<GifWriter<W>, RasterError> {
        let too_big = || RasterError(format!("{width} x {height} is too large for a GIF"));
        let w = u16::try_from(width).map_err(|_| too_big())?;
        let h = u16::try_from(height).map_err(|_| too_big())?;
        let mut encoder = gif::Encoder::new(out, w, h, &[]).map_err(gif_error)?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(gif_error)?;
        let delay = (delay_seconds * 100.0).round().clamp(2.0, 65_535.0) as u16;
        Ok(GifWriter {
            encoder,
            width: w,
            height: h,
            delay,
        })
    }

    /// Adds a frame, which must have the GIF's size.
    pub fn add(&mut self, pixmap: &Pixmap) -> Result<(), RasterError> {
        if pixmap.width() != u32::from(self.width) || pixmap.height() != u32::from(self.height) {
            return Err(RasterError(format!(
                "a {} x {} frame in a {} x {} GIF",
                pixmap.width(),
                pixmap.height(),
                self.width,
                self.height
            )));
        }
        // The pixmap is opaque, so its premultiplied colours are the plain ones.
        let mut rgba = pixmap.data().to_vec();
        let mut frame = gif::Frame::from_rgba_speed(self.width, self.height, &mut rgba, 10);
        frame.delay = self.delay;
        self.encoder.write_frame(&frame).map_err(gif_error)
    }

    /// Ends the GIF and returns the writer.
    pub fn finish(self) -> Result<W, RasterError> {
        self.encoder.into_inner().map_err(gif_error)
    }
}

fn gif_error(e: gif::EncodingError) -> RasterError {
    RasterError(format!("cannot write the GIF: {e}"))
}
