//! The per-shape pipeline: mesh → surface operators → spectrum → features → bands, computed
//! once per shape and kept in the per-shape cache ([`crate::cache`], which only stores and
//! verifies entries).
//!
//! The one loader is [`load_shape`]: a mesh file to its mesh and its per-shape data, through
//! the cache when a directory is given. `coseg pair` asks it for the full [`ShapeData`]
//! (spectrum, descriptors, bands), `coseg segment` (via [`crate::graph::load_collection`]) for
//! the compact [`ShapeBands`] (band table and vertex areas). Without a file:
//! [`compute_shape_data`] (no cache), [`load_or_compute`] and [`load_or_compute_bands`]
//! (a mesh in memory, through the cache).
//!
//! # What the cache keeps, and what a warm load recomputes
//! The full entry ([`StoredShape`]) keeps what is costly or impossible to recompute: the
//! spectrum (eigenvectors in `f32`), the columns of the sdf (ray casting, about 0.7 s per 10k
//! vertices) and user (read from a file that may since have changed or gone) families, and
//! the band table (deflated, 0.5 MB for 10k vertices; recomputing it would cost as much as
//! the descriptors). A warm load rebuilds the spectral descriptors (about 0.07 s for 10k
//! vertices and 300 features) and the extrinsic ones (milliseconds) from it, through the
//! same function as a cold run ([`shape_data_from_spectrum`] and
//! [`StoredShape::into_shape_data`] share it). Those stages are deterministic whatever the
//! thread count (fixed blocks, one task per feature; tested), and the eigenvectors are
//! rounded to `f32` in the cold run too, before any use, so a warm load gives the cold run's
//! bits.
//!
//! # The compact bands entry
//! The collection stage needs only each shape's band table and vertex areas, while the full
//! entry holds the spectrum too (8 MB for 10k vertices) and a full load rebuilds the
//! descriptors. [`load_or_compute_bands`] therefore keeps a second, deflated
//! file per shape ([`crate::cache::EntryKind::Bands`], about 0.5 MB for 10k vertices) next to
//! the full entry and rebuilds it from the full entry (or from scratch) whenever it is missing
//! or cannot be trusted.

mod load_shape;
mod shape_data;

pub use load_shape::{
    BandsResult, CacheResult, LoadedShape, ShapeContent, load_or_compute, load_or_compute_bands,
    load_shape, load_shape_from_mesh,
};
pub use shape_data::{
    FamilyFlags, PipelineError, ShapeBands, ShapeData, ShapePipelineOptions, StoredShape,
    compute_shape_data, decode_bands_entry, decode_shape_entry, encode_bands_entry,
    encode_shape_entry, shape_data_from_spectrum, shape_key, small_mesh_warning,
    unresolved_triangles_warning,
};
