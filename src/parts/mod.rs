//! Parts: what turns a collection's co-segmentation ([`crate::graph`]) into parts, and the
//! whole collection stage as `coseg segment` runs it (docs/METHOD.md §5, docs/PARTS.md).
//!
//! One entry point, [`segment_collection`], runs each mode of `coseg segment`:
//! equal-area regions (the default), parts of their own size (`--parts auto|N`,
//! [`PartsFrom::Adaptive`]) and parts from geometry (`--parts N --parts-from geometry`,
//! [`PartsFrom::Geometry`]). Its stages:
//!
//! - [`adaptive_cosegment`]: consistent tuples with each tuple's size found from the data
//!   (Algorithm 3 across the graph), the number of parts from the data and a tree of parts.
//! - [`mirror_pairs`]: which tuples are left/right copies of each other (each shape's own
//!   plane of mirror symmetry, [`mirror_plane`]); the part tree merges them first.
//! - [`split_disconnected_leaves`]: equal-area regions made of pieces of different parts,
//!   split into their kinds of pieces.
//! - [`geometric_part_tree`]: a part tree over equal-area regions that merges touching regions
//!   (and mirror pairs) of one thickness, read from each shape's [`PartCues`].
//! - [`snap_part_boundaries`]: the parts' boundaries moved onto creases.
//! - [`spectral_agreement`]: whether a collection is near-isometric by its spectra, which the
//!   feature choice asks before it drops the extrinsic family.
//! - [`PartsReport`]: what `summary.json` records of a parts run.
//! - [`part_tree`] and [`cut_part_tree`]: parts from geometry in two steps, the tree (the
//!   costly part) and its cut; [`segment_collection_cached`] keeps the tree in the cache, so
//!   that another number of parts only re-cuts.
//!
//! Errors are the collection stage's [`GraphError`](crate::graph::GraphError).

mod adaptive_cosegment;
mod aligned_extrinsic_bands;
mod choose_features;
mod choose_part_count;
mod geometric_part_tree;
mod mirror_pairs;
mod paired_advantage;
mod part_cues;
mod part_tree_cache;
mod parts_report;
mod segment_collection;
mod snap_part_boundaries;
mod spectral_agreement;
mod split_disconnected_leaves;
mod start_score;

// The median of a list (the mean of the middle two for an even length), for every stage that
// takes one over shapes or votes.
pub(crate) use adaptive_cosegment::median;
pub use adaptive_cosegment::{
    AdaptiveCosegmentation, AdaptiveOptions, AutoTuple, PartMerge, PartTree, Sizing, StopReason,
    adaptive_cosegment, adaptive_update,
};
pub use aligned_extrinsic_bands::aligned_extrinsic_bands;
pub(crate) use choose_features::SharedAlignment;
pub use choose_features::{ChooseFeaturesOptions, FeatureChoice, FeatureSet};
pub use choose_part_count::{PartCount, choose_part_count};
pub use geometric_part_tree::{
    geometric_part_tree, geometric_part_tree_linked, geometric_part_tree_with_cues,
};
pub use mirror_pairs::{Likeness, MirrorPair, MirrorPlane, mirror_pairs, mirror_plane};
pub use paired_advantage::{PairedAdvantage, paired_advantage};
pub use part_cues::{PartCues, PartCuesResult, load_or_compute_part_cues};
pub(crate) use part_tree_cache::segment_collection_cached_sharing;
pub use part_tree_cache::{part_tree_key, segment_collection_cached};
pub use parts_report::PartsReport;
pub use segment_collection::{
    FeatureSelection, PartTreeStage, PartsFrom, PartsRequest, SegmentCollectionOptions,
    SegmentTimes, SegmentedCollection, cut_part_tree, part_tree, segment_collection,
};
pub(crate) use segment_collection::{GEOMETRY_LEAVES, segment_collection_sharing};
pub use snap_part_boundaries::snap_part_boundaries;
pub use spectral_agreement::{SpectralAgreement, spectral_agreement};
pub use split_disconnected_leaves::{SplitLeaves, split_disconnected_leaves};
pub use start_score::start_score;
