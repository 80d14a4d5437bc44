//! [`encode_png`] and [`write_png`]: an [`RgbImage`] as PNG bytes.

use super::{RenderError, RgbImage};
use crate::mesh::write_atomic;
use std::io::Write;
use std::path::Path;

/// The PNG encoding of `img` (8-bit RGB, no metadata, fixed compression settings, so the same
/// image always gives the same bytes).
///
/// ```
/// let img = coseg::render::RgbImage::filled(3, 2, [10, 20, 30]);
/// let bytes = coseg::render::encode_png(&img);
/// assert_eq!(&bytes[1..4], b"PNG");
/// assert_eq!(bytes, coseg::render::encode_png(&img));
/// ```
pub fn encode_png(img: &RgbImage) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, img.width, img.height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Balanced);
        // Writing into a Vec cannot fail, and the header matches the pixel buffer.
        let mut writer = enc.write_header().expect("PNG header into memory");
        writer
            .write_image_data(&img.pixels)
            .expect("PNG data into memory");
    }
    out
}

/// Writes `img` as a PNG file at `path`, atomically (temporary file + rename).
pub fn write_png(path: &Path, img: &RgbImage) -> Result<(), RenderError> {
    let bytes = encode_png(img);
    write_atomic(path, |w| w.write_all(&bytes)).map_err(|source| {
        RenderError::Io(crate::FileError {
            path: path.display().to_string(),
            source,
        })
    })
}
