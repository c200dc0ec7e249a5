//! PNG and GIF frames need the `pictures` feature. Without it a [`Rasterizer`] cannot be made:
//! its constructors fail with one clear error, and the writers that would use one are never
//! reached.

pub use super::RasterError;
use super::{Recording, RenderError};
use std::path::Path;

/// Turns SVG into pixels: not in this build (no value of this type exists).
pub enum Rasterizer {}

impl Rasterizer {
    /// Fails: this build draws no pixels.
    pub fn new() -> Result<Rasterizer, RasterError> {
        Err(RasterError(
            "PNG and GIF frames need poolsim built with the `pictures` feature".to_string(),
        ))
    }

    /// Fails, as [`Rasterizer::new`] does.
    pub fn with_font(_path: &Path) -> Result<Rasterizer, RasterError> {
        Rasterizer::new()
    }
}

/// Never called: no [`Rasterizer`] exists in this build.
pub fn write_folder(_: &Recording, _: &Path, r: &Rasterizer) -> Result<String, RenderError> {
    match *r {}
}

/// Never called: no [`Rasterizer`] exists in this build.
pub fn write_gif(_: &Recording, _: &Path, r: &Rasterizer) -> Result<String, RenderError> {
    match *r {}
}
