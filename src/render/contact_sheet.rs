//! [`render_sheet`], [`render_shape`] and [`write_pictures`]: labelled pictures of shapes.

use super::region_colors;
use super::{
    RenderError, RgbImage, ViewFrame, canonical_frame, draw_mesh, draw_text, text_width, write_png,
};
use crate::mesh::TriMesh;
use std::path::{Path, PathBuf};

/// One shape to draw: a name, its mesh and one label per vertex (`-1` = none, grey).
#[derive(Debug, Clone, Copy)]
pub struct RenderShape<'a> {
    /// Shown under the shape; the file stem of `<name>.png`.
    pub name: &'a str,
    /// The mesh.
    pub mesh: &'a TriMesh,
    /// Label (region or part id) per vertex, length #V.
    pub labels: &'a [i32],
    /// Optional confidence in [0, 1], shown after the name as a percentage.
    pub confidence: Option<f64>,
    /// The view to draw it from (`None`: the shape's own [`canonical_frame`]); a collection's
    /// pictures share one view, [`super::collection_views`].
    pub view: Option<ViewFrame>,
}

impl RenderShape<'_> {
    /// The view the shape is drawn from: [`RenderShape::view`], else its canonical view.
    pub fn frame(&self) -> ViewFrame {
        self.view.unwrap_or_else(|| canonical_frame(self.mesh))
    }
}

/// Every label of `shapes` (the unlabelled `-1` too), ascending, once each: the legend's
/// entries, and the viewer's.
pub(crate) fn labels_present(shapes: &[RenderShape<'_>]) -> Vec<i32> {
    let mut labels: Vec<i32> = shapes
        .iter()
        .flat_map(|s| s.labels.iter().copied())
        .collect();
    labels.sort_unstable();
    labels.dedup();
    labels
}

/// Layout of the pictures.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RenderOptions {
    /// Width and height of each shape's square cell, pixels (≥ 16).
    pub cell_size: u32,
    /// Cells per row of the contact sheet (`None`: `ceil(sqrt(n))`).
    pub columns: Option<usize>,
    /// Background colour.
    pub background: [u8; 3],
    /// Text colour.
    pub text: [u8; 3],
    /// Font scale (font pixels are `scale × scale` pixels; glyphs are `7 · scale` tall).
    pub font_scale: u32,
    /// Draw a legend (one colour swatch per label shown) under the sheet.
    pub legend: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            cell_size: 240,
            columns: None,
            background: [255, 255, 255],
            text: [20, 20, 20],
            font_scale: 2,
            legend: true,
        }
    }
}

impl RenderOptions {
    fn validate(&self) -> Result<(), RenderError> {
        if self.cell_size < 16 || self.cell_size > 8192 {
            return Err(RenderError::Options(format!(
                "cell_size {} outside 16..=8192",
                self.cell_size
            )));
        }
        if self.font_scale == 0 || self.font_scale > 16 {
            return Err(RenderError::Options("font_scale outside 1..=16".into()));
        }
        if self.columns == Some(0) {
            return Err(RenderError::Options("columns must be positive".into()));
        }
        Ok(())
    }

    fn caption_height(&self) -> u32 {
        9 * self.font_scale + 4
    }
}

fn check(shape: &RenderShape<'_>) -> Result<(), RenderError> {
    if shape.labels.len() != shape.mesh.vertex_count() {
        return Err(RenderError::Length {
            name: shape.name.to_string(),
            labels: shape.labels.len(),
            vertices: shape.mesh.vertex_count(),
        });
    }
    Ok(())
}

fn caption(shape: &RenderShape<'_>) -> String {
    match shape.confidence {
        Some(c) => format!("{} {:.0}%", shape.name, 100.0 * c),
        None => shape.name.to_string(),
    }
}

/// Cuts `text` so that it fits `width` pixels at `scale`, ending in `..` when cut.
fn fit(text: &str, width: u32, scale: u32) -> String {
    if text_width(text, scale) <= width {
        return text.to_string();
    }
    let mut out: String = text.chars().collect();
    while !out.is_empty() && text_width(&format!("{out}.."), scale) > width {
        out.pop();
    }
    format!("{out}..")
}

fn draw_cell(img: &mut RgbImage, x: u32, y: u32, shape: &RenderShape<'_>, opts: &RenderOptions) {
    let s = opts.cell_size;
    let frame = shape.frame();
    let colors = region_colors(shape.labels);
    draw_mesh(img, [x, y, s, s], shape.mesh, &colors, &frame);
    let text = fit(&caption(shape), s - 4, opts.font_scale);
    let tx = x as i64 + (s as i64 - text_width(&text, opts.font_scale) as i64) / 2;
    let ty = (y + s + 2) as i64;
    draw_text(img, &text, tx, ty, opts.font_scale, opts.text);
}

/// Draws the legend rows (swatch + id or name) from `y`; returns the height used. With
/// `dry_run` only measures.
fn legend(
    img: &mut RgbImage,
    y: u32,
    width: u32,
    labels: &[i32],
    part_names: Option<&[String]>,
    opts: &RenderOptions,
    dry_run: bool,
) -> u32 {
    let fs = opts.font_scale;
    let line = 9 * fs + 6;
    let swatch = 7 * fs;
    let (mut x, mut row) = (8u32, 0u32);
    let colors = region_colors(labels);
    for (&l, &c) in labels.iter().zip(&colors) {
        let name = match (l, part_names.and_then(|n| n.get(l as usize))) {
            (l, _) if l < 0 => "none".to_string(),
            (l, Some(n)) => format!("{l} {n}"),
            (l, None) => format!("{l}"),
        };
        let w = swatch + 4 + text_width(&name, fs) + 16;
        if x > 8 && x + w > width {
            x = 8;
            row += 1;
        }
        if !dry_run {
            let top = (y + 4 + row * line) as i64;
            img.fill_rect(x as i64, top, swatch as i64, swatch as i64, c);
            draw_text(img, &name, (x + swatch + 4) as i64, top, fs, opts.text);
        }
        x += w;
    }
    if labels.is_empty() {
        0
    } else {
        (row + 1) * line + 8
    }
}

/// A contact sheet: every shape in its own square cell (canonical view, coloured by label
/// with [`region_colors`]), its name and confidence underneath, cells in the given order,
/// left to right then top to bottom; under them, when `opts.legend`, one swatch per label
/// that occurs, named `id name` from `part_names[id]` when given.
///
/// Size: `columns · cell_size` wide; `rows · (cell_size + caption)` plus the legend tall.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::render::{RenderOptions, RenderShape, render_sheet};
/// let mesh = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let shape = RenderShape { name: "tri", mesh: &mesh, labels: &[0, 1, 1], confidence: None, view: None };
/// let sheet = render_sheet(&[shape, shape], None, &RenderOptions::default()).unwrap();
/// assert_eq!(sheet.width, 2 * RenderOptions::default().cell_size);
/// ```
pub fn render_sheet(
    shapes: &[RenderShape<'_>],
    part_names: Option<&[String]>,
    opts: &RenderOptions,
) -> Result<RgbImage, RenderError> {
    opts.validate()?;
    if shapes.is_empty() {
        return Err(RenderError::Empty);
    }
    for s in shapes {
        check(s)?;
    }
    let n = shapes.len();
    let cols = opts
        .columns
        .unwrap_or_else(|| (n as f64).sqrt().ceil() as usize)
        .min(n);
    let rows = n.div_ceil(cols);
    let cell_h = opts.cell_size + opts.caption_height();
    let width = cols as u32 * opts.cell_size;
    let labels = labels_present(shapes);
    let mut img = RgbImage::filled(1, 1, opts.background);
    let legend_h = if opts.legend {
        legend(&mut img, 0, width, &labels, part_names, opts, true)
    } else {
        0
    };
    let height = rows as u32 * cell_h + legend_h;
    let mut img = RgbImage::filled(width, height, opts.background);
    for (i, s) in shapes.iter().enumerate() {
        let (c, r) = ((i % cols) as u32, (i / cols) as u32);
        draw_cell(&mut img, c * opts.cell_size, r * cell_h, s, opts);
    }
    if opts.legend {
        legend(
            &mut img,
            rows as u32 * cell_h,
            width,
            &labels,
            part_names,
            opts,
            false,
        );
    }
    Ok(img)
}

/// One shape alone: a one-cell [`render_sheet`] without legend.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::render::{RenderOptions, RenderShape, render_shape};
/// let mesh = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let shape = RenderShape { name: "tri", mesh: &mesh, labels: &[0, 1, 1], confidence: Some(0.9), view: None };
/// let img = render_shape(&shape, &RenderOptions::default()).unwrap();
/// assert_eq!(img.width, 240);
/// ```
pub fn render_shape(
    shape: &RenderShape<'_>,
    opts: &RenderOptions,
) -> Result<RgbImage, RenderError> {
    let one = RenderOptions {
        columns: Some(1),
        legend: false,
        ..opts.clone()
    };
    render_sheet(std::slice::from_ref(shape), None, &one)
}

/// Writes `dir/preview.png` ([`render_sheet`] of all shapes) and `dir/<name>.png`
/// ([`render_shape`]) for each shape, atomically; returns the paths written, the sheet first.
/// `dir` is created if missing. Names must be usable as file stems.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::render::{RenderOptions, RenderShape, write_pictures};
/// let mesh = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let dir = std::env::temp_dir().join(format!("coseg-doc-pictures-{}", std::process::id()));
/// let shape = RenderShape { name: "tri", mesh: &mesh, labels: &[0, 1, 1], confidence: None, view: None };
/// let paths = write_pictures(&dir, &[shape], None, &RenderOptions::default()).unwrap();
/// assert_eq!(paths, vec![dir.join("preview.png"), dir.join("tri.png")]);
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_pictures(
    dir: &Path,
    shapes: &[RenderShape<'_>],
    part_names: Option<&[String]>,
    opts: &RenderOptions,
) -> Result<Vec<PathBuf>, RenderError> {
    for s in shapes {
        if s.name.is_empty()
            || s.name.contains(['/', '\\'])
            || s.name == "."
            || s.name == ".."
            || s.name == "preview"
        {
            return Err(RenderError::BadName(s.name.to_string()));
        }
    }
    let sheet = render_sheet(shapes, part_names, opts)?;
    std::fs::create_dir_all(dir).map_err(|source| {
        RenderError::Io(crate::FileError {
            path: dir.display().to_string(),
            source,
        })
    })?;
    let mut paths = vec![dir.join("preview.png")];
    write_png(&paths[0], &sheet)?;
    for s in shapes {
        let path = dir.join(format!("{}.png", s.name));
        write_png(&path, &render_shape(s, opts)?)?;
        paths.push(path);
    }
    Ok(paths)
}
