//! [`choose_features`]: which feature families a collection is co-segmented with, chosen by
//! the consistency each reaches on it (`coseg segment` without `--features`).
//!
//! Two kinds of collections want different features. Posed bodies (a cat sitting and
//! standing) are near-isometric: the intrinsic (spectral) family describes a point the same
//! way in every pose, while heights and normal directions change with the pose. Man-made
//! collections (chairs, goblets) are rigid but not isometric (a stool and an armchair have
//! different intrinsic geometry): heights and normal directions in one collection frame tell
//! a seat from a back, the spectra do not. Which kind a collection is shows in how well each
//! family's co-segmentation agrees with itself around the shape graph: the equal-area
//! co-segmentation into a dozen regions is computed with each candidate (the intrinsic family
//! alone; the intrinsic and the extrinsic families, the latter in the collection frame of
//! [`crate::align::align_collection`]), and the candidate whose regions are carried between
//! shapes most consistently is kept. Consistency is the confidence of [`super::start_score`]
//! (the area IoU of each region with its neighbours' regions carried onto it), taken per shape
//! ([`crate::graph::shape_confidences`]) so that the two candidates are compared shape by
//! shape.
//!
//! The rule is asymmetric: both families are kept unless the spectral family's advantage is
//! larger than the probe's own sampling error, i.e. unless a one-sided paired t-test over the
//! shapes ([`super::paired_advantage`]) rejects "the two candidates are alike" at the 5 %
//! level. Why not the higher mean: the probe scores twelve raw equal-area regions, not parts,
//! and on rigid-like collections the two candidates' means differ by a few hundredths either
//! way with some shapes favouring each, a difference the choice of shapes makes and unmakes;
//! the candidate with both families holds the spectral columns as well (a third of the
//! weight), and is what the parts of man-made collections need (docs/PARTS.md measures both).
//! A collection that does not align (posed bodies, shapes the alignment got wrong) gives the
//! extrinsic columns regions that carry over worse on most shapes, an advantage of the
//! spectral family larger than its spread across shapes, and the intrinsic family wins;
//! nothing depends on how the files are oriented beyond what the alignment recovers.
//!
//! The probe's consistency is not correspondence: on a collection of different bodies (a
//! stool and an armchair, generated humanoids of varied proportions) the spectral regions can
//! carry over consistently and still mix parts, and the paired test then drops the extrinsic
//! family that the parts need (docs/PARTS.md: every generated set where the spectral family
//! was chosen had worse parts). So the spectral family alone needs a second, independent
//! piece of evidence: that the collection is near-isometric, read from the shapes' spectra
//! ([`super::spectral_agreement`]: most shapes have a spectrally nearest shape that the map
//! step would call near-isometric). Without it both families are kept whatever the probe says;
//! with it the paired test decides as above. The rigid alignment's residual was measured as
//! the alternative prior and points the wrong way (posed TOSCA and FAUST bodies align with
//! smaller residuals than the generated rigid families, docs/PARTS.md).

use super::aligned_extrinsic_bands::{aligned_extrinsic_bands, concat_tables};
use super::paired_advantage::{PairedAdvantage, paired_advantage};
use super::spectral_agreement::{SpectralAgreement, spectral_agreement};
use super::start_score::start_score;
use crate::align::{AlignError, AlignOptions, CollectionAlignment, FrameCase, align_collection};
use crate::bands::BandWeighting;
use crate::features::{ExtrinsicOptions, FamilyWeights, FeatureFamilies};
use crate::graph::{
    CosegmentOptions, GraphError, GraphOptions, ShapeGraph, ShapeNode, cosegment, shape_confidences,
};
use crate::mesh::TriMesh;
use serde::Serialize;
use std::sync::Arc;

/// A collection alignment the caller makes (or has made) of the same meshes with
/// [`AlignOptions::default`]: called at most once, when the feature choice needs it, so that a
/// propagation aligns its collection once for the parts and the rigid route.
pub(crate) type SharedAlignment<'a> =
    &'a (dyn Fn() -> Arc<Result<CollectionAlignment, AlignError>> + Sync);

/// Options of [`choose_features`] (the default: `coseg segment` without `--features`).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ChooseFeaturesOptions {
    /// The collection alignment that gives the extrinsic family its frame (default
    /// [`AlignOptions::default`]).
    pub align: AlignOptions,
    /// The extrinsic family's columns (default: [`ExtrinsicOptions::default`]'s 100 height
    /// directions and two distances, with 16 normal
    /// columns); its `alignment` is ignored (the frame is the collection's).
    pub extrinsic: ExtrinsicOptions,
    /// How the extrinsic columns are cut into bands (default [`BandWeighting::Count`], as the
    /// per-shape pipeline's default; the band count is the nodes').
    pub weighting: BandWeighting,
    /// Equal-area regions of the probe co-segmentation each candidate is scored on (default
    /// 12, the leaves of the default parts).
    pub probe_regions: usize,
    /// The one-sided significance level at which the spectral family's per-shape advantage
    /// drops the extrinsic family (default 0.05: the p-value must be below it; 0 keeps both
    /// families whenever they could be computed).
    pub significance: f64,
    /// Whether the spectral family alone also needs the collection to be near-isometric by its
    /// spectra ([`super::spectral_agreement`]; default true). `false`: the paired test alone
    /// decides (the rule of commit ae717a7).
    pub require_near_isometric: bool,
}

/// Normal columns `|n · u|` of the chosen extrinsic family (a heuristic, hence private; the
/// default reaches callers through [`ChooseFeaturesOptions::default`]): 16 directions, the
/// count the aligned figures of docs/FEATURES.md and docs/PARTS.md were measured with (they
/// tell a seat from a back at the same height).
const DEFAULT_NORMALS: usize = 16;

/// Regions of the probe: the finest parts of the default mode (the equal-area leaves of parts
/// from geometry; a test keeps the two equal), so each candidate is scored on the regions the
/// parts are grouped from.
const DEFAULT_PROBE_REGIONS: usize = 12;

/// Significance level of the spectral family's advantage (module docs): the conventional 5 %.
/// It is a statement about the probe's noise, not a margin: the extrinsic family is dropped when
/// an advantage this consistent across shapes would arise by chance in fewer than one
/// collection in twenty where the two candidates are alike. Fixed before measuring, not fitted
/// to any collection (docs/PARTS.md lists the p-values measured, the closest FAUST's 0.027 and
/// a generated humanoid set's 0.060).
const DEFAULT_SIGNIFICANCE: f64 = 0.05;

impl Default for ChooseFeaturesOptions {
    fn default() -> Self {
        let extrinsic = ExtrinsicOptions {
            normal_directions: DEFAULT_NORMALS,
            ..ExtrinsicOptions::default()
        };
        Self {
            align: AlignOptions::default(),
            extrinsic,
            weighting: BandWeighting::Count,
            probe_regions: DEFAULT_PROBE_REGIONS,
            significance: DEFAULT_SIGNIFICANCE,
            require_near_isometric: true,
        }
    }
}

/// The feature families a collection was co-segmented with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FeatureSet {
    /// The intrinsic (spectral) family alone.
    Intrinsic,
    /// The intrinsic and the extrinsic families (heights, distances and normal columns in the
    /// collection frame), one equal share each for the spectral columns, the heights and
    /// distances, and the normal columns.
    IntrinsicExtrinsic,
}

impl FeatureSet {
    /// The name printed and recorded: `spectral` or `spectral,extrinsic`.
    pub fn name(self) -> &'static str {
        match self {
            FeatureSet::Intrinsic => "spectral",
            FeatureSet::IntrinsicExtrinsic => "spectral,extrinsic",
        }
    }
}

/// What [`choose_features`] decided, and why (`summary.json`'s `features`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeatureChoice {
    /// The families used.
    pub chosen: FeatureSet,
    /// The probe's mean region confidence with the intrinsic family alone.
    pub intrinsic_score: f64,
    /// The same with both families, the best of the up axes tried; `None` when the extrinsic
    /// family could not be computed (the warning says why).
    pub aligned_score: Option<f64>,
    /// The paired comparison over shapes of the spectral candidate against the best candidate
    /// with both families (each shape's mean region confidence in the probe,
    /// [`crate::graph::shape_confidences`]): the mean advantage of the spectral family, its
    /// standard error, `t` and the one-sided p-value; `None` without an extrinsic candidate.
    pub spectral_advantage: Option<PairedAdvantage>,
    /// The significance level the p-value was held against
    /// ([`ChooseFeaturesOptions::significance`]).
    pub significance: f64,
    /// How far the shapes' spectra agree ([`super::spectral_agreement`]): the spectral family
    /// alone is used only when they say near-isometric. `None` when it was not asked
    /// ([`ChooseFeaturesOptions::require_near_isometric`] false) or not needed (no extrinsic
    /// candidate).
    pub spectral_agreement: Option<SpectralAgreement>,
    /// The probe's score with both families for each up axis tried: the positive file axis
    /// when the files' frames agree; the synchronised frame's up as the alignment found it,
    /// then reversed, when the shapes were moved.
    pub aligned_scores: Vec<f64>,
    /// How the collection frame was found (`None`: the alignment failed).
    pub frame: Option<FrameCase>,
    /// The frame's up axis in file coordinates when the files were already aligned.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub up: Option<[f64; 3]>,
    /// One sentence for the user: the choice and the reason.
    pub reason: String,
}

/// The chosen nodes and what the collection stage needs of them.
#[derive(Debug, Clone)]
pub(crate) struct ChosenFeatures {
    /// The shape graph over the chosen columns, feature weights set.
    pub graph: ShapeGraph,
    /// The per-column weights (`None`: the intrinsic family alone).
    pub feature_weights: Option<Vec<f64>>,
    /// The up axis in file coordinates (already aligned files only).
    pub up: Option<[f64; 3]>,
    /// Columns a mirror image leaves unchanged (the spectral ones).
    pub mirror_columns: Vec<usize>,
    /// The report.
    pub choice: FeatureChoice,
}

/// A candidate with the extrinsic family: its probe score, graph, weights, up axis and each
/// shape's confidence in the probe.
type Candidate = (
    f64,
    ShapeGraph,
    Option<Vec<f64>>,
    Option<[f64; 3]>,
    Vec<f64>,
);

/// Chooses the feature families of a collection (module docs) and builds its shape graph.
///
/// Inputs: `nodes` (#shapes, the intrinsic family's band tables, as the default per-shape
/// pipeline gives them), `meshes` (graph order, one per node), `graph` (the shape graph's
/// options), `cosegment` (the co-segmentation's options; its region count is replaced by
/// [`ChooseFeaturesOptions::probe_regions`]), `options`.
///
/// Output: the chosen graph, weights and the [`FeatureChoice`]; `warnings` gets a line when
/// the alignment or the extrinsic columns fail (the intrinsic family is then used).
///
/// Cost: one collection alignment (≈ 0.1 s of CPU per shape), the extrinsic columns (a pass
/// over the vertices per column), and two raw equal-area co-segmentations.
///
/// Errors: those of [`ShapeGraph::build`] and [`cosegment`].
///
/// Known issues: the alignment is rigid and recovers the frame of strongly different shapes
/// (a stool and an armchair moved at random) only in part (docs/ALIGN.md); the shapes it
/// misplaces weaken the extrinsic candidate, which then loses to the intrinsic one rather
/// than mislead.
#[allow(clippy::too_many_arguments)]
pub(crate) fn choose_features(
    nodes: Vec<ShapeNode>,
    meshes: &[TriMesh],
    graph: &GraphOptions,
    cosegment_options: &CosegmentOptions,
    options: &ChooseFeaturesOptions,
    shared: Option<SharedAlignment<'_>>,
    warnings: &mut Vec<String>,
) -> Result<ChosenFeatures, GraphError> {
    let spectral = nodes.first().map_or(0, |n| n.bands.features);
    let mut probe = *cosegment_options;
    probe.regions = options.probe_regions;
    let mirror_columns: Vec<usize> = (0..spectral).collect();
    // Candidates with the extrinsic family. Files whose frames already agree: the positive file
    // axis nearest the alignment's up (files are written with a positive axis up, the
    // convention `--up` follows; the alignment's sign rule reads which side the mass leans to,
    // which chairs, for one, do not show). Shapes moved into a synchronised frame: its up axis
    // as the rule names it, and reversed, the probe deciding (nothing else tells the sign).
    let mut best: Option<Candidate> = None;
    let mut aligned_scores = Vec::new();
    let mut frame = None;
    let timer = crate::stage_timer::stage("parts: align collection");
    // The caller's alignment of these meshes under the default options, when it has one and
    // those are the options asked for: the same result without aligning twice.
    let aligned: Arc<Result<CollectionAlignment, AlignError>> =
        match shared.filter(|_| options.align == AlignOptions::default()) {
            Some(made) => made(),
            None => Arc::new(align_collection(meshes, &options.align)),
        };
    drop(timer);
    match aligned.as_ref() {
        Err(e) => warnings.push(format!(
            "the collection could not be aligned ({e}): the intrinsic family alone is used"
        )),
        Ok(alignment) => {
            frame = Some(alignment.case);
            let mut band_options = crate::bands::BandOptions::default();
            band_options.bands = nodes.first().map_or(band_options.bands, |n| n.bands.bands);
            band_options.weighting = options.weighting;
            let signs: &[bool] = match alignment.case {
                FrameCase::Synchronised => &[false, true],
                FrameCase::AlreadyAligned | FrameCase::Single => &[false],
            };
            for &reverse in signs {
                let (tables, up) = match aligned_extrinsic_bands(
                    meshes,
                    alignment,
                    &options.extrinsic,
                    &band_options,
                    reverse,
                ) {
                    Ok(t) => t,
                    Err(e) => {
                        warnings.push(format!("{e}: the intrinsic family alone is used"));
                        break;
                    }
                };
                let both: Vec<ShapeNode> = nodes
                    .iter()
                    .zip(&tables)
                    .map(|(n, t)| ShapeNode {
                        bands: concat_tables(&n.bands, t).into(),
                        ..n.clone()
                    })
                    .collect();
                let families = FeatureFamilies {
                    extrinsic: Some(options.extrinsic.clone()),
                    weights: FamilyWeights::default(),
                    ..FeatureFamilies::default()
                };
                let ext = tables.first().map_or(0, |t| t.features);
                let weights = families.feature_weights(spectral, [ext, 0, 0]);
                let _t = crate::stage_timer::stage(format!(
                    "parts: aligned candidate (reverse {reverse})"
                ));
                let mut g = ShapeGraph::build(both, graph)?;
                g.set_feature_weights(weights.clone())?;
                let seg = cosegment(&g, &probe)?;
                let score = start_score(&seg);
                aligned_scores.push(score);
                if best.as_ref().is_none_or(|b| score > b.0) {
                    let per_shape = shape_confidences(&g, &seg)?;
                    best = Some((score, g, weights, up, per_shape));
                }
            }
        }
    }
    let timer = crate::stage_timer::stage("parts: intrinsic candidate");
    let intrinsic = ShapeGraph::build(nodes, graph)?;
    let intrinsic_seg = cosegment(&intrinsic, &probe)?;
    let intrinsic_score = start_score(&intrinsic_seg);
    let intrinsic_shapes = shape_confidences(&intrinsic, &intrinsic_seg)?;
    drop(timer);
    let aligned_score = best.as_ref().map(|b| b.0);
    let advantage = best
        .as_ref()
        .map(|b| paired_advantage(&intrinsic_shapes, &b.4));
    let significance = options.significance;
    // The spectra are read only when they can change the choice: with an extrinsic candidate.
    let agreement = match &best {
        Some(_) if options.require_near_isometric => {
            let _t = crate::stage_timer::stage("parts: spectral agreement");
            Some(spectral_agreement(meshes))
        }
        _ => None,
    };
    let significant = advantage.is_some_and(|a| a.p_value < significance);
    let isometric = agreement.as_ref().is_none_or(|a| a.near_isometric);
    let spectra = agreement.as_ref().map_or(String::new(), |a| {
        format!(
            "{} of {} shapes have a near-isometric partner by their spectra (nearest eigenvalue discrepancy {})",
            a.with_partner,
            a.shapes,
            nearest_text(&a.nearest)
        )
    });
    let test = advantage.map_or(String::new(), |a| {
        format!(
            "; per shape the spectral family's advantage is {:+.3} ± {:.3} (standard error over {} shapes, one-sided paired t-test {}, level {significance})",
            a.mean,
            a.standard_error,
            a.shapes,
            p_text(a.p_value)
        )
    });
    let case = match frame {
        Some(FrameCase::AlreadyAligned) => "the files' frames agree",
        Some(FrameCase::Synchronised) => "aligned by registration",
        Some(FrameCase::Single) | None => "one shape",
    };
    let signs = if aligned_scores.len() > 1 {
        ", up axis as found / reversed"
    } else {
        ""
    };
    let scores = aligned_scores
        .iter()
        .map(|s| format!("{s:.3}"))
        .collect::<Vec<_>>()
        .join(" / ");
    Ok(match best {
        Some((_, g, weights, up, _)) if !significant || !isometric => {
            let reason = if isometric {
                let prior = if spectra.is_empty() {
                    String::new()
                } else {
                    format!(" ({spectra})")
                };
                format!(
                    "features spectral,extrinsic: the collection is rigid-like ({case}){prior}; its regions do not carry over significantly more consistently with the spectral family alone (mean confidence {intrinsic_score:.3}) than with the extrinsic family in the collection frame added ({scores}{signs}){test}"
                )
            } else {
                format!(
                    "features spectral,extrinsic: the collection is not near-isometric ({spectra}), so the spectral family's consistency is no evidence of correspondence ({case}; probe mean confidence {intrinsic_score:.3} spectral, {scores}{signs} with the extrinsic family{test})"
                )
            };
            ChosenFeatures {
            graph: g,
            feature_weights: weights,
            up,
            mirror_columns,
            choice: FeatureChoice {
                chosen: FeatureSet::IntrinsicExtrinsic,
                intrinsic_score,
                aligned_score,
                spectral_advantage: advantage,
                significance,
                spectral_agreement: agreement,
                aligned_scores,
                frame,
                up,
                reason,
            },
            }
        }
        _ => ChosenFeatures {
            graph: intrinsic,
            feature_weights: None,
            up: None,
            mirror_columns,
            choice: FeatureChoice {
                chosen: FeatureSet::Intrinsic,
                intrinsic_score,
                aligned_score,
                spectral_advantage: advantage,
                significance,
                reason: match aligned_score {
                    Some(_) if spectra.is_empty() => format!(
                        "features spectral: the collection is near-isometric or does not align rigidly ({case}); its regions carry over significantly more consistently with the spectral family alone (mean confidence {intrinsic_score:.3}) than with the extrinsic family added ({scores}{signs}){test}"
                    ),
                    Some(_) => format!(
                        "features spectral: the collection is near-isometric ({spectra}; {case}); its regions carry over significantly more consistently with the spectral family alone (mean confidence {intrinsic_score:.3}) than with the extrinsic family added ({scores}{signs}){test}"
                    ),
                    None => "features spectral: the extrinsic family could not be computed (see the warning)".to_string(),
                },
                spectral_agreement: agreement,
                aligned_scores,
                frame,
                up: None,
            },
        },
    })
}

/// The median of the shapes' nearest-partner discrepancies for the reason sentence (`none`
/// when no shape has one).
fn nearest_text(nearest: &[Option<f64>]) -> String {
    let d: Vec<f64> = nearest.iter().flatten().copied().collect();
    if d.is_empty() {
        return "none".to_string();
    }
    format!("median {:.3}", super::median(&d))
}

/// A p-value for the reason sentence: three decimals, or `p < 0.001` below what they show.
fn p_text(p: f64) -> String {
    if p < 0.001 {
        "p < 0.001".to_string()
    } else {
        format!("p = {p:.3}")
    }
}
