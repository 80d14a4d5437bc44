//! # coseg — stable region correspondences across shape collections
//!
//! coseg finds corresponding parts across a collection of 3D triangle meshes (co-segmentation)
//! and carries part labels from a few annotated shapes to the others. It implements
//! *Stable Region Correspondences Between Non-Isometric Shapes* (Ganapathi-Subramanian, Thibert,
//! Ovsjanikov, Guibas; SGP 2016) and extends it from pairs to collections.
//!
//! The pipeline, one module per stage, dependencies flowing one way:
//!
//! | stage | module | what it produces |
//! |---|---|---|
//! | meshes | [`mesh`] | validated triangle meshes, readers and writers (OBJ, OFF, PLY) |
//! | alignment | [`align`] | similarity transforms between shapes (pairwise registration), nearest-surface-point labels |
//! | spectrum | [`spectral`] | cotangent Laplacian, lumped mass, Laplace–Beltrami eigenpairs |
//! | features | [`features`] | per-vertex feature families: spectral (HKS, WKS, multiscale mean curvature), extrinsic heights, shape diameter, user columns |
//! | bands | [`bands`] | per-feature rank bands stored as a compact `u8` table |
//! | per-shape pipeline | [`pipeline`] | mesh → spectrum → features → bands once per shape, through [`cache`] (storage only); [`pipeline::load_shape`] is the one loader |
//! | correspondence maps | [`maps`] | functional maps, ZoomOut, one-to-one matches, map presets |
//! | affinity | [`affinity`] | the band-table affinity operator `W x`, `Wᵀ y` (never dense) |
//! | stable regions | [`stable`] | Algorithms 1–3 of the paper between two shapes |
//! | collections | [`graph`] | shape graph, cycle solver, consistent co-segmentation and its refinement |
//! | parts | [`parts`] | regions to parts: parts of their own size, part trees, mirror pairs, crease snapping; the whole collection stage of `coseg segment` ([`parts::segment_collection`]) |
//! | part labels | [`labels`] | annotation files (per vertex, `.seg` per face), vertex ↔ face conversion |
//! | propagation | [`propagate`] | part labels carried from annotated shapes to a collection |
//! | pictures | [`render`] | PNG pictures of results (CPU rasteriser, canonical view, the palette) |
//! | output | [`output`] | region files, coloured meshes, summaries, feature export, the viewer page |
//! | jobs | [`jobs`] | a command's whole run (inputs → options → result → files) as one call: what the CLI and Python translate to |
//! | studio | [`studio`] | a labelling session: crease patches, palette, edits with undo, incremental propagation, save (what `coseg studio` serves) |
//! | shape families | [`generate`] | synthetic collections with ground-truth parts |
//! | evaluation | [`evaluate`] | scores against ground truth: accuracy, per-part IoU, Rand index, purity and coverage; whole result folders ([`evaluate::evaluate_folder`]) |
//! | per-shape task | [`shape_task`] | the per-shape stage as bytes in, cache entry bytes out (for distributed engines) |
#![deny(missing_docs)]

pub mod affinity;
pub mod align;
pub mod bands;
pub mod cache;
pub mod evaluate;
pub mod features;
mod file_error;
pub mod generate;
pub mod graph;
pub mod jobs;
pub mod labels;
pub mod maps;
pub mod mesh;
mod option_range;
pub mod output;
pub mod parts;
pub mod pipeline;
pub mod propagate;
pub mod render;
pub mod shape_task;
pub mod spectral;
pub mod stable;
pub mod stage_timer;
pub mod studio;
mod vertex_sets;

pub use file_error::FileError;

/// The README's Rust example, compiled as a doc test so that it cannot rot.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
