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
//! # The compact bands entry
//! The collection stage needs only each shape's band table and vertex areas (a few MB for 10k
//! vertices), while the full entry also holds the spectrum and the descriptors (about 40 MB).
//! [`load_or_compute_bands`] therefore keeps a second file per shape
//! ([`crate::cache::EntryKind::Bands`]) next to the full entry and rebuilds it from the full
//! entry (or from scratch) whenever it is missing or cannot be trusted.

mod load_shape;
mod shape_data;

pub use load_shape::{
    BandsResult, CacheResult, LoadedShape, ShapeContent, load_or_compute, load_or_compute_bands,
    load_shape,
};
pub use shape_data::{
    PipelineError, ShapeBands, ShapeData, ShapePipelineOptions, compute_shape_data,
    decode_bands_entry, decode_shape_entry, encode_bands_entry, encode_shape_entry,
    shape_data_from_spectrum, shape_key, small_mesh_warning,
};
