//! Frames as pixels: the SVG of [`super::svg`] rasterized with resvg, written as PNG files or
//! as one animated GIF.
//!
//! Text needs a font, read at run time from `$POOLSIM_FONT` or, by default, from
//! [`DEFAULT_FONT`] (Debian's `fonts-dejavu-core`). A missing font is an error, not a picture
//! without names.

use resvg::tiny_skia::Pixmap;
use resvg::usvg;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use super::RasterError;
use super::{format_time, frame_name, frames, io_error, svg, Recording, RenderError};

/// Where the font is read from when `$POOLSIM_FONT` is not set.
pub const DEFAULT_FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

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

/// Writes every frame of `rec` into the folder `dir` as SVG and PNG; returns one line that says
/// what was written.
pub fn write_folder(rec: &Recording, dir: &Path, r: &Rasterizer) -> Result<String, RenderError> {
    let style = rec.style();
    std::fs::create_dir_all(dir).map_err(io_error(dir))?;
    let count = rec.shots.len();
    for (k, shot) in rec.shots.iter().enumerate() {
        let text = svg::frame(&rec.scene, shot, &style);
        let name = frame_name(k, count);
        let p = dir.join(format!("{name}.svg"));
        std::fs::write(&p, &text).map_err(io_error(&p))?;
        let p = dir.join(format!("{name}.png"));
        std::fs::write(&p, r.png(&text)?).map_err(io_error(&p))?;
    }
    Ok(format!(
        "{}: {} every {} as SVG and PNG ({} to {})",
        dir.display(),
        frames(count),
        format_time(rec.frame_time),
        frame_name(0, count),
        frame_name(count.saturating_sub(1), count)
    ))
}

/// Writes the frames of `rec` as one animated GIF at `path`; returns one line that says what was
/// written.
pub fn write_gif(rec: &Recording, path: &Path, r: &Rasterizer) -> Result<String, RenderError> {
    let style = rec.style();
    let mut file = Some(std::fs::File::create(path).map_err(io_error(path))?);
    let mut gif: Option<GifWriter<std::io::BufWriter<std::fs::File>>> = None;
    for shot in &rec.shots {
        let pixmap = r.pixmap(&svg::frame(&rec.scene, shot, &style))?;
        if let Some(file) = file.take() {
            gif = Some(GifWriter::new(
                std::io::BufWriter::new(file),
                pixmap.width(),
                pixmap.height(),
                rec.frame_time,
            )?);
        }
        if let Some(g) = &mut gif {
            g.add(&pixmap)?;
        }
    }
    if let Some(g) = gif {
        let mut w = g.finish()?;
        std::io::Write::flush(&mut w).map_err(io_error(path))?;
    }
    Ok(format!(
        "{}: {}, one every {} s (frame time {})",
        path.display(),
        frames(rec.shots.len()),
        format_time((rec.frame_time * 100.0).round().max(2.0) / 100.0),
        format_time(rec.frame_time)
    ))
}
