//! Pictures of results: a small CPU rasteriser (z-buffer, orthographic, no GPU, no display).
//!
//! A collection's shapes are drawn from one view ([`collection_views`]): a three-quarter view
//! from slightly above in the collection frame of [`crate::align::align_collection`], carried
//! to each shape by its rotation, so every shape is seen from the same side. A shape drawn
//! alone (or when the alignment fails) is drawn from its [canonical view](canonical_frame): its
//! principal axes, with a sign rule that depends only on the shape. Vertices are coloured by label with [`region_colors`] (the
//! colours of the coloured PLY files), so a part has one colour on every shape. Lighting is a
//! two-sided head light (ambient + Lambert) on interpolated vertex normals; each pixel takes
//! the colour of the nearest corner of its triangle, which keeps part boundaries crisp.
//!
//! - [`render_sheet`]: a contact sheet, one cell per shape with its name (and confidence)
//!   underneath and a legend of the labels shown;
//! - [`render_shape`]: one shape alone, same look;
//! - [`write_pictures`]: `DIR/preview.png` (the sheet) and `DIR/<name>.png` per shape;
//! - [`encode_png`] / [`write_png`]: deterministic PNG bytes (same image, same bytes).
//!
//! Everything is computed serially in `f64`: the same inputs give the same bytes.

mod canonical_view;
mod collection_view;
mod contact_sheet;
mod font;
mod png_io;
mod rasterise;
mod region_colors;

pub use canonical_view::{ViewFrame, canonical_frame};
pub use collection_view::{collection_views, collection_views_or_own};
pub(crate) use contact_sheet::labels_present;
pub use contact_sheet::{RenderOptions, RenderShape, render_shape, render_sheet, write_pictures};
pub use font::{draw_text, text_width};
pub use png_io::{encode_png, write_png};
pub use rasterise::draw_mesh;
pub use region_colors::region_colors;

use thiserror::Error;

/// Errors of the picture stage; each names the shape or file concerned.
#[derive(Debug, Error)]
pub enum RenderError {
    /// The labels do not match the mesh.
    #[error("{name}: {labels} labels for a mesh of {vertices} vertices")]
    Length {
        /// Shape name.
        name: String,
        /// Number of labels given.
        labels: usize,
        /// Vertex count.
        vertices: usize,
    },
    /// Nothing to draw.
    #[error("no shapes to render")]
    Empty,
    /// A shape name that cannot be a file name (`<name>.png`).
    #[error("invalid shape name {0:?}: must be non-empty without path separators")]
    BadName(String),
    /// Options that cannot produce an image.
    #[error("invalid render options: {0}")]
    Options(String),
    /// Writing a file failed.
    #[error(transparent)]
    Io(#[from] crate::FileError),
}

/// An 8-bit RGB image, rows top to bottom, `width * height * 3` bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major RGB bytes (length `3 * width * height`).
    pub pixels: Vec<u8>,
}

impl RgbImage {
    /// An image of `width × height` pixels filled with `color`.
    ///
    /// ```
    /// let img = coseg::render::RgbImage::filled(4, 2, [255, 0, 0]);
    /// assert_eq!(img.pixels.len(), 24);
    /// assert_eq!(img.get(3, 1), [255, 0, 0]);
    /// ```
    pub fn filled(width: u32, height: u32, color: [u8; 3]) -> Self {
        let n = width as usize * height as usize;
        let mut pixels = Vec::with_capacity(3 * n);
        for _ in 0..n {
            pixels.extend_from_slice(&color);
        }
        RgbImage {
            width,
            height,
            pixels,
        }
    }

    /// The colour at column `x`, row `y` (panics outside the image).
    pub fn get(&self, x: u32, y: u32) -> [u8; 3] {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        [self.pixels[i], self.pixels[i + 1], self.pixels[i + 2]]
    }

    /// Sets the colour at column `x`, row `y`; coordinates outside the image are ignored.
    pub fn set(&mut self, x: i64, y: i64, color: [u8; 3]) {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            return;
        }
        let i = 3 * (y as usize * self.width as usize + x as usize);
        self.pixels[i..i + 3].copy_from_slice(&color);
    }

    /// Fills the rectangle `[x, x + w) × [y, y + h)` (clipped to the image).
    pub fn fill_rect(&mut self, x: i64, y: i64, w: i64, h: i64, color: [u8; 3]) {
        for yy in y..y + h {
            for xx in x..x + w {
                self.set(xx, yy, color);
            }
        }
    }

    /// Copies `src` with its top-left corner at `(x, y)` (clipped to the image).
    pub fn blit(&mut self, src: &RgbImage, x: i64, y: i64) {
        for sy in 0..src.height {
            for sx in 0..src.width {
                self.set(x + sx as i64, y + sy as i64, src.get(sx, sy));
            }
        }
    }
}
