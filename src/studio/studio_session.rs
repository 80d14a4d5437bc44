//! [`Studio`]: a labelling session on a folder of meshes.

use super::{Palette, PatchOptions, StudioError, crease_patches};
use crate::graph::{ShapeGraph, ShapeNode, load_collection};
use crate::labels::{read_part_names, read_shape_labels, vertices_to_faces};
use crate::mesh::{TriMesh, write_atomic};
use crate::propagate::{
    CollectionParts, MapStepReport, PropagateCollectionOptions, Propagation, fuse_propagation,
    map_route_on, propagate_labels, propagate_loaded,
};
use crate::render::{RgbImage, ViewFrame, canonical_frame, draw_mesh, encode_png};
use crate::spectral::HeatSmoother;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Component, Path, PathBuf};

/// Edits kept for undo: enough for a long session, bounded so memory is (each edit holds two
/// copies of one shape's labels).
const HISTORY: usize = 500;

/// Options of [`Studio::open`].
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct StudioOptions {
    /// Per-shape pipeline, graph and solver of the propagation, and the per-shape cache
    /// (default: those of `coseg propagate`; cache in the system's temporary folder).
    pub propagate: PropagateCollectionOptions,
    /// The patches clicks label (default [`PatchOptions::default`]).
    pub patches: PatchOptions,
    /// Where the session's files are read from and saved to (default `None`:
    /// `FOLDER/labels`).
    pub labels_dir: Option<PathBuf>,
}

/// One shape as the grid shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShapeInfo {
    /// Index (the folder's file order).
    pub index: usize,
    /// File stem.
    pub name: String,
    /// Vertex count.
    pub vertices: usize,
    /// Face count.
    pub faces: usize,
    /// Whether the shape carries an annotation (a source of the propagation).
    pub source: bool,
    /// Area-weighted mean confidence of its labels from the last propagation (`None` before
    /// the first; sources 1).
    pub confidence: Option<f64>,
    /// Share of vertices labelled (`≥ 0`).
    pub labelled: f64,
    /// Increases whenever its labels change (for caching pictures).
    pub version: u64,
}

/// What an edit did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct EditSummary {
    /// The shape edited.
    pub shape: usize,
    /// Vertices whose label changed (`0`: nothing to do, nothing recorded for undo).
    pub changed: usize,
}

/// Progress of [`Studio::propagate`], passed to its callback.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct PropagateProgress {
    /// Steps done.
    pub done: usize,
    /// Steps in all (one per changed shape for an incremental update, 1 for a full run).
    pub total: usize,
}

/// What [`Studio::propagate`] did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PropagateReport {
    /// Whether it ran from scratch (first run, or a part no previous run knew) rather than as
    /// incremental updates.
    pub full: bool,
    /// Shapes whose annotation had changed since the last run.
    pub changed_shapes: usize,
    /// Part transports computed by the updates (0 for a full run).
    pub transports: usize,
    /// Shapes whose labels differ from before.
    pub relabelled: usize,
    /// Warnings for the user.
    pub warnings: Vec<String>,
}

/// One undoable edit: a shape's annotation and shown labels before and after.
#[derive(Debug, Clone)]
struct Edit {
    shape: usize,
    before: Option<Vec<i32>>,
    before_labels: Vec<i32>,
    after: Option<Vec<i32>>,
    after_labels: Vec<i32>,
}

/// The propagation state [`Propagation::update`] continues from.
struct Solved {
    graph: ShapeGraph,
    smoothers: Vec<HeatSmoother>,
    propagation: Propagation,
    /// The parts route's co-segmentations ([`crate::propagate::PropagatedShapes::parts`]), reused by each
    /// fusion after an update.
    parts: Option<CollectionParts>,
    /// Per shape, what the map route did in the last run ([`map_route_on`]): after an
    /// update, a map is fitted again only where it was taken.
    map_route: Vec<Option<MapStepReport>>,
}

/// `summary.json` of a saved session.
#[derive(Debug, Serialize, Deserialize)]
struct SessionFile {
    tool: String,
    version: String,
    /// Shapes carrying an annotation (what `coseg eval` leaves out of its means).
    sources: Vec<String>,
    parts: Palette,
    confidence: BTreeMap<String, f64>,
}

/// A labelling session: the meshes of a folder, their labels (annotations on the sources,
/// propagated labels elsewhere), the palette, the edit history and the propagation state.
///
/// Every operation either succeeds or returns an error and changes nothing. Shapes are named by
/// their index in the folder's file order ([`Studio::shapes`]).
///
/// ```no_run
/// use coseg::studio::{Studio, StudioOptions};
/// let mut s = Studio::open("chairs".as_ref(), &StudioOptions::default()).unwrap();
/// let seat = s.add_part("seat").unwrap();
/// s.label_patch(0, 3, seat).unwrap();
/// s.propagate(|_| {}).unwrap();
/// s.save().unwrap();
/// ```
pub struct Studio {
    folder: PathBuf,
    labels_dir: PathBuf,
    options: PropagateCollectionOptions,
    names: Vec<String>,
    meshes: Vec<TriMesh>,
    frames: Vec<ViewFrame>,
    patches: Vec<Vec<u32>>,
    /// The per-shape data until the first propagation builds the graph from it.
    nodes: Option<Vec<ShapeNode>>,
    solved: Option<Solved>,
    annotations: Vec<Option<Vec<i32>>>,
    labels: Vec<Vec<i32>>,
    confidence: Vec<Option<f64>>,
    versions: Vec<u64>,
    dirty: BTreeSet<usize>,
    palette: Palette,
    undo: Vec<Edit>,
    redo: Vec<Edit>,
    warnings: Vec<String>,
}

impl Studio {
    /// Opens `folder` (meshes directly in it, through the per-shape cache) and resumes the
    /// session saved in the labels folder: with a `summary.json` there, the shapes it lists as
    /// sources are annotated and the others show their saved labels; without one, every label
    /// file there (`<stem>.labels.txt`, else `<stem>.seg`) is an annotation. Part names come
    /// from the summary, else `parts.json`. Patches ([`crease_patches`]) are cut for every
    /// shape. Unreadable meshes are skipped with a warning ([`Studio::warnings`]).
    pub fn open(folder: &Path, options: &StudioOptions) -> Result<Studio, StudioError> {
        let folder = folder.canonicalize().map_err(|e| StudioError::File {
            path: folder.display().to_string(),
            message: e.to_string(),
        })?;
        let labels_dir = options
            .labels_dir
            .clone()
            .unwrap_or_else(|| folder.join("labels"));
        let labels_dir = std::path::absolute(&labels_dir).unwrap_or(labels_dir);
        let cache = options
            .propagate
            .cache_dir
            .clone()
            .unwrap_or_else(|| std::env::temp_dir().join("coseg-cache"));
        let loaded = load_collection(&folder, &options.propagate.pipeline, &cache, |_, _, _| {})?;
        let mut warnings = loaded.warnings.clone();
        warnings.extend(loaded.skipped.iter().map(|s| s.error.clone()));
        if loaded.meshes.is_empty() {
            return Err(StudioError::BadRequest(format!(
                "{}: no usable mesh (.obj, .off, .ply)",
                folder.display()
            )));
        }
        let names: Vec<String> = loaded.nodes.iter().map(|n| n.name.clone()).collect();
        let (patches, frames): (Vec<Vec<u32>>, Vec<ViewFrame>) = loaded
            .meshes
            .par_iter()
            .map(|m| Ok((crease_patches(m, &options.patches)?, canonical_frame(m))))
            .collect::<Result<Vec<_>, StudioError>>()?
            .into_iter()
            .unzip();
        let n = names.len();
        // The propagation reads the same cache the collection was loaded through: the map
        // route re-reads each shape's spectrum from it instead of recomputing it in memory on
        // every propagation.
        let mut propagate_options = options.propagate.clone();
        propagate_options.cache_dir = Some(cache);
        let mut studio = Studio {
            folder,
            labels_dir,
            options: propagate_options,
            names,
            frames,
            patches,
            nodes: Some(loaded.nodes),
            solved: None,
            annotations: vec![None; n],
            labels: loaded
                .meshes
                .iter()
                .map(|m| vec![-1; m.vertex_count()])
                .collect(),
            meshes: loaded.meshes,
            confidence: vec![None; n],
            versions: vec![0; n],
            dirty: BTreeSet::new(),
            palette: Palette::default(),
            undo: Vec::new(),
            redo: Vec::new(),
            warnings: Vec::new(),
        };
        studio.resume(&mut warnings)?;
        studio.warnings = warnings;
        Ok(studio)
    }

    fn resume(&mut self, warnings: &mut Vec<String>) -> Result<(), StudioError> {
        let summary_path = self.labels_dir.join("summary.json");
        let session: Option<SessionFile> = match std::fs::read_to_string(&summary_path) {
            Ok(text) => match serde_json::from_str(&text) {
                Ok(s) => Some(s),
                Err(e) => {
                    warnings.push(format!(
                        "{}: not a studio session ({e}); label files read as annotations",
                        summary_path.display()
                    ));
                    None
                }
            },
            Err(_) => None,
        };
        for i in 0..self.names.len() {
            let name = &self.names[i];
            let file = [format!("{name}.labels.txt"), format!("{name}.seg")]
                .into_iter()
                .map(|f| self.labels_dir.join(f))
                .find(|p| p.is_file());
            let Some(path) = file else { continue };
            let labels = read_shape_labels(&path, &self.meshes[i], name)?.vertex_labels;
            let source = match &session {
                Some(s) => s.sources.contains(name),
                None => labels.iter().any(|&l| l >= 0),
            };
            for &l in &labels {
                self.palette.ensure(l, None);
            }
            if source {
                self.annotations[i] = Some(labels.clone());
                self.dirty.insert(i);
                self.confidence[i] = Some(1.0);
            }
            self.labels[i] = labels;
        }
        match session {
            Some(s) => {
                for p in s.parts.parts() {
                    self.palette.ensure(p.label, Some(&p.name));
                    self.palette.recolor(p.label, p.color)?;
                }
                for (i, name) in self.names.iter().enumerate() {
                    if let Some(&c) = s.confidence.get(name) {
                        self.confidence[i] = Some(c);
                    }
                }
            }
            None => {
                let names = self.labels_dir.join("parts.json");
                if names.is_file() {
                    for (l, name) in read_part_names(&names)? {
                        self.palette.ensure(l, Some(&name));
                    }
                }
            }
        }
        Ok(())
    }

    /// The canonical folder of meshes.
    pub fn folder(&self) -> &Path {
        &self.folder
    }

    /// The folder the session is saved to.
    pub fn labels_dir(&self) -> &Path {
        &self.labels_dir
    }

    /// Warnings of opening (skipped meshes, cache problems) and of the last propagation.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Number of shapes.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether the session has no shape (never: [`Studio::open`] refuses an empty folder).
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Every shape, in the folder's file order.
    pub fn shapes(&self) -> Vec<ShapeInfo> {
        (0..self.len())
            .map(|i| ShapeInfo {
                index: i,
                name: self.names[i].clone(),
                vertices: self.meshes[i].vertex_count(),
                faces: self.meshes[i].face_count(),
                source: self.annotations[i].is_some(),
                confidence: self.confidence[i],
                labelled: self.labels[i].iter().filter(|&&l| l >= 0).count() as f64
                    / self.labels[i].len().max(1) as f64,
                version: self.versions[i],
            })
            .collect()
    }

    /// Shape indices as the grid shows them: least confident first (shapes never propagated
    /// count as 0), sources last, ties in file order.
    pub fn grid_order(&self) -> Vec<usize> {
        let key = |i: usize| {
            let source = self.annotations[i].is_some();
            (source, self.confidence[i].unwrap_or(0.0))
        };
        let mut order: Vec<usize> = (0..self.len()).collect();
        order.sort_by(|&a, &b| {
            let (sa, ca) = key(a);
            let (sb, cb) = key(b);
            sa.cmp(&sb).then(ca.total_cmp(&cb)).then(a.cmp(&b))
        });
        order
    }

    fn check_shape(&self, i: usize) -> Result<(), StudioError> {
        if i >= self.len() {
            return Err(StudioError::BadRequest(format!(
                "no shape {i} (the folder has {})",
                self.len()
            )));
        }
        Ok(())
    }

    /// The mesh of shape `i`.
    pub fn mesh(&self, i: usize) -> Result<&TriMesh, StudioError> {
        self.check_shape(i)?;
        Ok(&self.meshes[i])
    }

    /// The labels shape `i` shows (per vertex, `-1` = none): its annotation on a source, its
    /// propagated labels elsewhere.
    pub fn labels(&self, i: usize) -> Result<&[i32], StudioError> {
        self.check_shape(i)?;
        Ok(&self.labels[i])
    }

    /// The patch of every vertex of shape `i` ([`crease_patches`]).
    pub fn patches(&self, i: usize) -> Result<&[u32], StudioError> {
        self.check_shape(i)?;
        Ok(&self.patches[i])
    }

    /// Positions of shape `i` in its canonical view frame ([`canonical_frame`]: x right, y up,
    /// z toward the viewer), centred and scaled into the unit ball; length `#V`.
    pub fn view_positions(&self, i: usize) -> Result<Vec<[f32; 3]>, StudioError> {
        self.check_shape(i)?;
        let view: Vec<[f64; 3]> = self.meshes[i]
            .positions()
            .iter()
            .map(|&p| self.frames[i].project(p))
            .collect();
        let r = view
            .iter()
            .map(|p| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt())
            .fold(0.0f64, f64::max);
        let s = if r > 0.0 { 1.0 / r } else { 1.0 };
        Ok(view.iter().map(|p| p.map(|x| (x * s) as f32)).collect())
    }

    /// The palette.
    pub fn palette(&self) -> &Palette {
        &self.palette
    }

    /// Adds a part named `name` ([`Palette::add`]); returns its label.
    pub fn add_part(&mut self, name: &str) -> Result<i32, StudioError> {
        self.palette.add(name)
    }

    /// Renames part `label`.
    pub fn rename_part(&mut self, label: i32, name: &str) -> Result<(), StudioError> {
        self.palette.rename(label, name)
    }

    /// Recolours part `label` (pictures of the shapes that show it change).
    pub fn recolor_part(&mut self, label: i32, color: [u8; 3]) -> Result<(), StudioError> {
        self.palette.recolor(label, color)?;
        for i in 0..self.len() {
            if self.labels[i].contains(&label) {
                self.versions[i] += 1;
            }
        }
        Ok(())
    }

    fn check_label(&self, label: i32) -> Result<(), StudioError> {
        if label < -1 || (label >= 0 && self.palette.get(label).is_none()) {
            return Err(StudioError::BadRequest(format!(
                "label {label} is not a part of the palette (or -1 to erase)"
            )));
        }
        Ok(())
    }

    /// Gives every vertex of patch `patch` of shape `i` the part `label` (`-1` erases).
    /// The shape becomes a source: its annotation is what it showed, with the patch changed.
    pub fn label_patch(
        &mut self,
        i: usize,
        patch: u32,
        label: i32,
    ) -> Result<EditSummary, StudioError> {
        self.check_shape(i)?;
        self.check_label(label)?;
        let vertices: Vec<u32> = (0..self.patches[i].len() as u32)
            .filter(|&v| self.patches[i][v as usize] == patch)
            .collect();
        if vertices.is_empty() {
            return Err(StudioError::BadRequest(format!(
                "shape {}: no patch {patch}",
                self.names[i]
            )));
        }
        Ok(self.apply(i, &vertices, label))
    }

    /// Gives the listed vertices of shape `i` the part `label` (`-1` erases): the brush.
    pub fn brush(
        &mut self,
        i: usize,
        vertices: &[u32],
        label: i32,
    ) -> Result<EditSummary, StudioError> {
        self.check_shape(i)?;
        self.check_label(label)?;
        let d = self.meshes[i].vertex_count();
        if let Some(&v) = vertices.iter().find(|&&v| v as usize >= d) {
            return Err(StudioError::BadRequest(format!(
                "shape {}: no vertex {v} (it has {d})",
                self.names[i]
            )));
        }
        Ok(self.apply(i, vertices, label))
    }

    fn apply(&mut self, i: usize, vertices: &[u32], label: i32) -> EditSummary {
        let mut annotation = self.labels[i].clone();
        let mut changed = 0;
        for &v in vertices {
            if annotation[v as usize] != label {
                annotation[v as usize] = label;
                changed += 1;
            }
        }
        if changed == 0 && self.annotations[i].is_some() {
            return EditSummary { shape: i, changed };
        }
        let after = annotation
            .iter()
            .any(|&l| l >= 0)
            .then(|| annotation.clone());
        let edit = Edit {
            shape: i,
            before: self.annotations[i].clone(),
            before_labels: self.labels[i].clone(),
            after,
            after_labels: annotation,
        };
        self.redo.clear();
        self.set(&edit, false);
        self.undo.push(edit);
        if self.undo.len() > HISTORY {
            self.undo.remove(0);
        }
        EditSummary { shape: i, changed }
    }

    fn set(&mut self, edit: &Edit, back: bool) {
        let i = edit.shape;
        let (annotation, labels) = if back {
            (&edit.before, &edit.before_labels)
        } else {
            (&edit.after, &edit.after_labels)
        };
        self.annotations[i] = annotation.clone();
        self.labels[i] = labels.clone();
        if annotation.is_some() {
            self.confidence[i] = Some(1.0);
        }
        self.versions[i] += 1;
        self.dirty.insert(i);
    }

    /// Undoes the last edit; returns the shape it changed (`None`: nothing to undo).
    pub fn undo(&mut self) -> Option<usize> {
        self.replay(true)
    }

    /// Redoes the last undone edit; returns the shape it changed (`None`: nothing to redo).
    pub fn redo(&mut self) -> Option<usize> {
        self.replay(false)
    }

    /// Moves the last edit of the undo stack (`back`) or of the redo stack onto the other one,
    /// setting the shape to the state before it or after it; returns the shape.
    fn replay(&mut self, back: bool) -> Option<usize> {
        let edit = if back {
            self.undo.pop()
        } else {
            self.redo.pop()
        }?;
        self.set(&edit, back);
        let i = edit.shape;
        if back {
            self.redo.push(edit);
        } else {
            self.undo.push(edit);
        }
        Some(i)
    }

    /// Edits that can be undone and redone.
    pub fn history(&self) -> (usize, usize) {
        (self.undo.len(), self.redo.len())
    }

    /// Shapes whose annotation changed since the last propagation.
    pub fn pending(&self) -> usize {
        self.dirty.len()
    }

    /// Carries the annotations to every other shape. The first run (and a run after a part no
    /// earlier run knew was used) solves from scratch ([`propagate_loaded`], which also builds
    /// the shape graph and heat smoothers, once); later runs call
    /// [`Propagation::update`] once per shape whose annotation changed, so only the
    /// transports a change touches are recomputed. `progress` is called after each step.
    /// Shapes that are not sources take the propagated labels.
    pub fn propagate(
        &mut self,
        mut progress: impl FnMut(PropagateProgress),
    ) -> Result<PropagateReport, StudioError> {
        if self.annotations.iter().all(Option::is_none) {
            return Err(StudioError::BadRequest(
                "nothing to propagate: label a part on at least one shape first".into(),
            ));
        }
        let changed: Vec<usize> = self.dirty.iter().copied().collect();
        let parts: BTreeSet<i32> = self
            .annotations
            .iter()
            .flatten()
            .flat_map(|a| a.iter().copied().filter(|&l| l >= 0))
            .collect();
        let mut report = PropagateReport {
            full: false,
            changed_shapes: changed.len(),
            transports: 0,
            relabelled: 0,
            warnings: Vec::new(),
        };
        let incremental = self.solved.as_ref().is_some_and(|s| {
            parts
                .iter()
                .all(|l| s.propagation.parts.binary_search(l).is_ok())
        });
        if incremental {
            let s = self.solved.as_mut().expect("checked");
            let smoothers = (!s.smoothers.is_empty()).then_some(s.smoothers.as_slice());
            for (k, &i) in changed.iter().enumerate() {
                let stats = s.propagation.update(
                    &s.graph,
                    smoothers,
                    i,
                    self.annotations[i].clone(),
                    &self.options.propagate,
                )?;
                report.transports += stats.transports;
                progress(PropagateProgress {
                    done: k + 1,
                    total: changed.len(),
                });
            }
            report.warnings = self.fuse_routes(false)?;
        } else {
            report.full = true;
            match self.solved.as_mut() {
                Some(s) => {
                    let smoothers = (!s.smoothers.is_empty()).then_some(s.smoothers.as_slice());
                    // The rigid route's registrations do not depend on the parts: keep them.
                    let rigid = std::mem::take(&mut s.propagation.rigid);
                    s.propagation = propagate_labels(
                        &s.graph,
                        smoothers,
                        &self.annotations,
                        &self.options.propagate,
                    )?;
                    s.propagation.rigid = rigid;
                    report.warnings = self.fuse_routes(true)?;
                }
                None => {
                    let nodes = self.nodes.clone().expect("nodes kept until the first run");
                    let out =
                        propagate_loaded(nodes, &self.meshes, &self.annotations, &self.options)?;
                    report.warnings = out.warnings;
                    self.nodes = None;
                    self.solved = Some(Solved {
                        graph: out.graph,
                        smoothers: out.smoothers,
                        propagation: out.propagation,
                        parts: out.parts,
                        map_route: out.map_route,
                    });
                }
            }
            progress(PropagateProgress { done: 1, total: 1 });
        }
        let p = &self.solved.as_ref().expect("solved above").propagation;
        for i in 0..self.len() {
            if self.annotations[i].is_some() {
                self.confidence[i] = Some(1.0);
                continue;
            }
            self.confidence[i] = Some(p.shape_confidence[i]);
            if self.labels[i] != p.labels[i] {
                self.labels[i] = p.labels[i].clone();
                self.versions[i] += 1;
                report.relabelled += 1;
            }
        }
        self.dirty.clear();
        self.warnings.extend(report.warnings.iter().cloned());
        Ok(report)
    }

    /// Fuses the band-affinity labels of the last update or solve with the other routes, as
    /// [`propagate_loaded`] does after its solve ([`fuse_propagation`], then the map route
    /// when `routes.map` is on), so that a session's labels after an update are those
    /// `coseg propagate` gives (the update itself moves the band affinity alone). The map
    /// route runs on every shape after a `full` solve, and after an update only where the
    /// last run took it ([`map_route_on`]: a ZoomOut map per shape costs more than the rest
    /// of an update). Returns the routes' warnings.
    fn fuse_routes(&mut self, full: bool) -> Result<Vec<String>, StudioError> {
        let Some(s) = self.solved.as_mut() else {
            return Ok(Vec::new());
        };
        let fusion = fuse_propagation(
            &s.graph,
            &self.meshes,
            &self.annotations,
            &mut s.propagation,
            s.parts.as_mut(),
            (!s.smoothers.is_empty()).then_some(s.smoothers.as_slice()),
            &self.options.propagate,
            &self.options.routes,
        )?;
        let mut warnings = fusion.warnings.clone();
        if self.options.routes.map {
            let targets: Vec<bool> = (0..self.meshes.len())
                .map(|i| full || matches!(s.map_route.get(i), Some(Some(r)) if r.applied))
                .collect();
            let (reports, w) = map_route_on(
                &self.meshes,
                &s.graph,
                &self.annotations,
                &mut s.propagation,
                &fusion,
                &self.options.pipeline,
                self.options.cache_dir.as_deref(),
                &targets,
            );
            // A shape not mapped again keeps what it had: a map not taken stays not taken.
            s.map_route.resize(targets.len(), None);
            for (i, r) in reports.into_iter().enumerate().filter(|&(i, _)| targets[i]) {
                s.map_route[i] = r;
            }
            warnings.extend(w);
        }
        Ok(warnings)
    }

    /// Writes the session into the labels folder (created if missing), each file atomically:
    /// `<stem>.labels.txt` and `<stem>.seg` for every shape, `parts.json` and `summary.json`.
    /// Returns the files written.
    pub fn save(&self) -> Result<Vec<PathBuf>, StudioError> {
        self.write_to(&self.labels_dir)
    }

    /// Writes the files [`Studio::save`] writes into `relative`, a folder inside the session's
    /// folder (created if missing): the labelled collection for `coseg eval RESULT --truth
    /// GT` and for mesh networks (per-face `.seg`, per-vertex `.labels.txt`). A path that
    /// leaves the folder is refused ([`Studio::resolve_inside`]).
    pub fn export(&self, relative: &str) -> Result<Vec<PathBuf>, StudioError> {
        let dir = self.resolve_inside(relative)?;
        if dir == self.folder {
            return Err(StudioError::BadRequest(
                "export into a subfolder, not the folder of meshes itself".into(),
            ));
        }
        self.write_to(&dir)
    }

    /// `relative` (a relative path of plain names, `/`-separated) inside the session's folder,
    /// or [`StudioError::OutsideFolder`]: absolute paths, `..`, and paths whose existing part
    /// leads out of the folder through a link are refused.
    pub fn resolve_inside(&self, relative: &str) -> Result<PathBuf, StudioError> {
        let outside = || StudioError::OutsideFolder {
            path: relative.to_string(),
            folder: self.folder.display().to_string(),
        };
        let rel = Path::new(relative);
        if relative.is_empty()
            || relative.contains('\\')
            || rel
                .components()
                .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
        {
            return Err(outside());
        }
        let full = self.folder.join(rel);
        // The deepest existing ancestor must resolve inside the folder (no link leads out).
        let mut probe = full.as_path();
        loop {
            if let Ok(real) = probe.canonicalize() {
                if !real.starts_with(&self.folder) {
                    return Err(outside());
                }
                break;
            }
            probe = probe.parent().ok_or_else(outside)?;
        }
        Ok(full)
    }

    fn write_to(&self, dir: &Path) -> Result<Vec<PathBuf>, StudioError> {
        let file_err = |path: &Path, e: &dyn std::fmt::Display| StudioError::File {
            path: path.display().to_string(),
            message: e.to_string(),
        };
        std::fs::create_dir_all(dir).map_err(|e| file_err(dir, &e))?;
        let mut written = Vec::new();
        for i in 0..self.len() {
            let faces = vertices_to_faces(&self.meshes[i], &self.labels[i])?;
            written.push(crate::labels::write_vertex_labels(
                dir,
                &self.names[i],
                &self.labels[i],
            )?);
            written.push(crate::labels::write_face_labels(
                dir,
                &self.names[i],
                &faces,
            )?);
        }
        let names: BTreeMap<String, &str> = self
            .palette
            .parts()
            .iter()
            .map(|p| (p.label.to_string(), p.name.as_str()))
            .collect();
        let session = SessionFile {
            tool: "coseg studio".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            sources: (0..self.len())
                .filter(|&i| self.annotations[i].is_some())
                .map(|i| self.names[i].clone())
                .collect(),
            parts: self.palette.clone(),
            confidence: (0..self.len())
                .filter_map(|i| self.confidence[i].map(|c| (self.names[i].clone(), c)))
                .collect(),
        };
        for (file, value) in [
            ("parts.json", serde_json::to_string_pretty(&names)),
            ("summary.json", serde_json::to_string_pretty(&session)),
        ] {
            let path = dir.join(file);
            let text = value.map_err(|e| file_err(&path, &e))?;
            write_atomic(&path, |w| {
                use std::io::Write;
                writeln!(w, "{text}")
            })
            .map_err(|e| file_err(&path, &e))?;
            written.push(path);
        }
        Ok(written)
    }

    /// A `size × size` PNG picture of shape `i` in its canonical view, coloured by its labels
    /// with the palette's colours.
    pub fn thumbnail(&self, i: usize, size: u32) -> Result<Vec<u8>, StudioError> {
        self.check_shape(i)?;
        if !(16..=2048).contains(&size) {
            return Err(StudioError::BadRequest(format!(
                "picture size {size} outside 16..=2048"
            )));
        }
        let mut img = RgbImage::filled(size, size, [255, 255, 255]);
        let colors = self.palette.colors(&self.labels[i]);
        draw_mesh(
            &mut img,
            [0, 0, size, size],
            &self.meshes[i],
            &colors,
            &self.frames[i],
        );
        Ok(encode_png(&img))
    }
}
