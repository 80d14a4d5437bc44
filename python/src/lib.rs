//! `coseg._coseg`: the native half of the Python package. Thin over the `coseg` library: it
//! converts numpy arrays to library types, releases the GIL while the library computes, and
//! turns library errors into the package's exceptions (`coseg.errors`). The Python half
//! (`coseg/__init__.py`) coerces dtypes and documents the options.

mod options;

use coseg::cache::CacheOutcome;
use coseg::jobs::{
    CacheChoice, JobError, JobLabels, JobShape, PairJob, PropagateInput, PropagateJob,
    SegmentInput, run_pair, run_propagate, run_segment,
};
use coseg::labels::PartNames;
use coseg::mesh::{MeshFormat, TriMesh, read_mesh_with_report};
use coseg::output::SkippedInput;
use coseg::pipeline::compute_shape_data;
use coseg::shape_task;
use coseg::spectral::{SpectrumOptions, laplace_beltrami_spectrum};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use options::Opts;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use std::path::{Path, PathBuf};

/// The package exception for a library error: `FileError` (an `OSError`) when an I/O error is
/// anywhere in its source chain, `InputError` (a `ValueError`) otherwise; the message is the
/// library's.
fn lib_err(e: &(dyn std::error::Error + 'static)) -> PyErr {
    lib_err_in(e, None)
}

/// [`lib_err`] with the message prefixed by `context: `.
fn lib_err_in(e: &(dyn std::error::Error + 'static), context: Option<&str>) -> PyErr {
    let mut io = false;
    let mut cur: Option<&(dyn std::error::Error + 'static)> = Some(e);
    while let Some(c) = cur {
        io |= c.downcast_ref::<std::io::Error>().is_some();
        cur = c.source();
    }
    let message = match context {
        Some(c) => format!("{c}: {e}"),
        None => e.to_string(),
    };
    raise(if io { "FileError" } else { "InputError" }, message)
}

/// A `coseg.errors.<class>` exception with `message`.
fn raise(class: &str, message: String) -> PyErr {
    Python::attach(|py| {
        match py
            .import("coseg.errors")
            .and_then(|m| m.getattr(class))
            .and_then(|c| c.call1((message.clone(),)))
        {
            Ok(obj) => PyErr::from_value(obj),
            Err(e) => e,
        }
    })
}

fn input_err(message: impl Into<String>) -> PyErr {
    raise("InputError", message.into())
}

trait OrRaise<T> {
    fn or_raise(self) -> PyResult<T>;
}

impl<T, E: std::error::Error + 'static> OrRaise<T> for Result<T, E> {
    fn or_raise(self) -> PyResult<T> {
        self.map_err(|e| lib_err(&e))
    }
}

/// Copies `V` (`n × 3` float64) and `F` (`m × 3` int64) into a validated mesh. `what` names the
/// shape in errors.
fn mesh_from(
    v: &PyReadonlyArray2<'_, f64>,
    f: &PyReadonlyArray2<'_, i64>,
    what: &str,
) -> PyResult<TriMesh> {
    let (vs, fs) = (v.shape(), f.shape());
    if vs[1] != 3 {
        return Err(input_err(format!(
            "{what}: V must be n x 3, got {} x {}",
            vs[0], vs[1]
        )));
    }
    if fs[1] != 3 {
        return Err(input_err(format!(
            "{what}: F must be m x 3, got {} x {}",
            fs[0], fs[1]
        )));
    }
    let va = v.as_array();
    let positions: Vec<[f64; 3]> = va.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect();
    let fa = f.as_array();
    let mut faces = Vec::with_capacity(fs[0]);
    for (i, r) in fa.rows().into_iter().enumerate() {
        let mut tri = [0u32; 3];
        for (t, &x) in tri.iter_mut().zip(r.iter()) {
            *t = u32::try_from(x).map_err(|_| {
                input_err(format!(
                    "{what}: face {i} refers to vertex {x}, but the mesh has {} vertices",
                    vs[0]
                ))
            })?;
        }
        faces.push(tri);
    }
    TriMesh::new(positions, faces).map_err(|e| input_err(e.with_path(what).to_string()))
}

fn vf<'py>(
    py: Python<'py>,
    mesh: &TriMesh,
) -> (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>) {
    let d = mesh.vertex_count();
    let v: Vec<f64> = mesh.positions().iter().flatten().copied().collect();
    let f: Vec<i64> = mesh
        .faces()
        .iter()
        .flatten()
        .map(|&i| i64::from(i))
        .collect();
    let v = Array2::from_shape_vec((d, 3), v).expect("d x 3");
    let f = Array2::from_shape_vec((mesh.face_count(), 3), f).expect("m x 3");
    (v.into_pyarray(py), f.into_pyarray(py))
}

fn format_of(name: &str) -> PyResult<MeshFormat> {
    MeshFormat::from_path(Path::new(&format!("x.{name}"))).ok_or_else(|| {
        input_err(format!(
            "unknown mesh format {name:?} (expected obj, off or ply)"
        ))
    })
}

fn key_of(hex: &str) -> PyResult<coseg::cache::ShapeKey> {
    shape_task::parse_key(hex)
        .ok_or_else(|| input_err(format!("{hex:?} is not a 64-digit hex key")))
}

/// JSON text to a Python object (dicts, lists, numbers, strings).
fn json<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| input_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// The library's default of every option, by command and keyword
/// ([`coseg::jobs::defaults`]).
#[pyfunction]
fn defaults(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    json(py, &coseg::jobs::defaults())
}

/// Reads a mesh file (.obj, .off, .ply): `(V, F, warnings)`.
#[pyfunction]
fn read_mesh<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let (mesh, report) = py.detach(|| read_mesh_with_report(&path)).or_raise()?;
    let (v, f) = vf(py, &mesh);
    let warnings: Vec<String> = report
        .warnings
        .iter()
        .map(|w| format!("{}: {w}", path.display()))
        .collect();
    Ok((v, f, warnings).into_pyobject(py)?.into_any())
}

/// `(eigenvalues (k,), eigenvectors (n, k), vertex_areas (n,))` of the unit-area mesh.
#[pyfunction]
fn spectrum<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'py, f64>,
    f: PyReadonlyArray2<'py, i64>,
    k: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let mesh = mesh_from(&v, &f, "mesh")?;
    let s = py
        .detach(|| laplace_beltrami_spectrum(&mesh, &SpectrumOptions::with_eigenpairs(k)))
        .or_raise()?;
    let (d, k) = (s.vertex_count(), s.len());
    // Column-major d x k is row-major k x d, transposed.
    let vecs = Array2::from_shape_vec((k, d), s.eigenvectors)
        .expect("k x d")
        .reversed_axes();
    let out = (
        PyArray1::from_vec(py, s.eigenvalues),
        vecs.into_pyarray(py),
        PyArray1::from_vec(py, s.vertex_areas),
    );
    Ok(out.into_pyobject(py)?.into_any())
}

/// `(names, matrix (n, N))` of the descriptor table.
#[pyfunction]
#[pyo3(signature = (v, f, options=None))]
fn features<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'py, f64>,
    f: PyReadonlyArray2<'py, i64>,
    options: Option<Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut o = Opts::new(options);
    let pipe = o.pipeline()?;
    o.finish()?;
    let mesh = mesh_from(&v, &f, "mesh")?;
    let data = py.detach(|| compute_shape_data(&mesh, &pipe)).or_raise()?;
    let desc = data.descriptors;
    let (n, d) = (desc.feature_count(), desc.vertices);
    let names = desc.names();
    let m = Array2::from_shape_vec((n, d), desc.values)
        .expect("N x d")
        .reversed_axes();
    Ok((names, m.into_pyarray(py)).into_pyobject(py)?.into_any())
}

/// The band table, `(n, N)` uint8 labels in `0..bands`.
#[pyfunction]
#[pyo3(signature = (v, f, options=None))]
fn band_table<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'py, f64>,
    f: PyReadonlyArray2<'py, i64>,
    options: Option<Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyArray2<u8>>> {
    let mut o = Opts::new(options);
    let pipe = o.pipeline()?;
    o.finish()?;
    let mesh = mesh_from(&v, &f, "mesh")?;
    let data = py.detach(|| compute_shape_data(&mesh, &pipe)).or_raise()?;
    let t = data.bands;
    Ok(Array2::from_shape_vec((t.vertices, t.features), t.labels)
        .expect("d x N")
        .into_pyarray(py))
}

/// `(key_hex, vertices)` of mesh file bytes under the pipeline options.
#[pyfunction]
#[pyo3(signature = (mesh_bytes, format, options=None))]
fn shape_key<'py>(
    py: Python<'py>,
    mesh_bytes: &[u8],
    format: String,
    options: Option<Bound<'py, PyDict>>,
) -> PyResult<(String, usize)> {
    let mut o = Opts::new(options);
    let pipe = o.pipeline()?;
    o.finish()?;
    let format = format_of(&format)?;
    let (key, d) = py
        .detach(|| shape_task::shape_key_of_bytes(mesh_bytes, format, &pipe))
        .or_raise()?;
    Ok((key.to_hex(), d))
}

/// The per-shape task: `(key_hex, vertices, entry bytes, bands entry bytes)`.
#[pyfunction]
#[pyo3(signature = (mesh_bytes, format, options=None))]
fn shape_entry<'py>(
    py: Python<'py>,
    mesh_bytes: &[u8],
    format: String,
    options: Option<Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut o = Opts::new(options);
    let pipe = o.pipeline()?;
    o.finish()?;
    let format = format_of(&format)?;
    let e = py
        .detach(|| shape_task::compute_shape_entry(mesh_bytes, format, &pipe))
        .or_raise()?;
    let out = (
        e.key.to_hex(),
        e.vertices,
        PyBytes::new(py, &e.entry),
        PyBytes::new(py, &e.bands_entry),
    );
    Ok(out.into_pyobject(py)?.into_any())
}

/// Verifies and atomically writes both entries; returns their paths.
#[pyfunction]
fn store_entry(
    py: Python<'_>,
    cache_dir: PathBuf,
    key: String,
    vertices: usize,
    entry: &[u8],
    bands_entry: &[u8],
) -> PyResult<(PathBuf, PathBuf)> {
    let key = key_of(&key)?;
    let [a, b] = py
        .detach(|| shape_task::store_shape_entry(&cache_dir, &key, vertices, entry, bands_entry))
        .or_raise()?;
    Ok((a, b))
}

/// True when both entries of `key` in `cache_dir` verify.
#[pyfunction]
fn entry_is_valid(
    py: Python<'_>,
    cache_dir: PathBuf,
    key: String,
    vertices: usize,
) -> PyResult<bool> {
    let key = key_of(&key)?;
    Ok(py.detach(|| shape_task::entry_is_valid(&cache_dir, &key, vertices)))
}

/// A shape handed to `pair`/`segment`/`propagate`: its mesh, display name and the file it was
/// read from (its name when it came as arrays).
struct Shape {
    name: String,
    file: String,
    from_file: bool,
    mesh: TriMesh,
}

impl Shape {
    /// The shape as a job's input: its mesh, its name, and the file it was read from.
    fn into_job_shape(self) -> JobShape {
        JobShape::Mesh {
            file: self.from_file.then(|| PathBuf::from(&self.file)),
            name: self.name,
            mesh: self.mesh,
        }
    }
}

fn shapes_from(
    list: &Bound<'_, PyList>,
    names: Option<Vec<String>>,
    files: Option<Vec<Option<String>>>,
) -> PyResult<Vec<Shape>> {
    let mut out = Vec::with_capacity(list.len());
    for (i, item) in list.iter().enumerate() {
        let (v, f): (PyReadonlyArray2<f64>, PyReadonlyArray2<i64>) = item.extract()?;
        let name = names
            .as_ref()
            .and_then(|n| n.get(i).cloned())
            .unwrap_or_else(|| format!("shape{i:03}"));
        let file = files.as_ref().and_then(|f| f.get(i).cloned().flatten());
        let mesh = mesh_from(&v, &f, &format!("shape {i} ({name})"))?;
        out.push(Shape {
            from_file: file.is_some(),
            file: file.unwrap_or_else(|| name.clone()),
            name,
            mesh,
        });
    }
    Ok(out)
}

/// The shapes of a list as a job's input.
fn job_shapes(
    list: &Bound<'_, PyList>,
    names: Option<Vec<String>>,
    files: Option<Vec<Option<String>>>,
) -> PyResult<Vec<JobShape>> {
    Ok(shapes_from(list, names, files)?
        .into_iter()
        .map(Shape::into_job_shape)
        .collect())
}

/// The cache a job uses: `cache_dir` when given; otherwise a folder's, beside the output as the
/// CLI's (`CacheChoice::Auto`), and none for shapes given as a list.
fn cache_choice(cache_dir: Option<PathBuf>, folder: bool) -> CacheChoice {
    match (cache_dir, folder) {
        (Some(dir), _) => CacheChoice::Dir(dir),
        (None, true) => CacheChoice::Auto,
        (None, false) => CacheChoice::Off,
    }
}

/// One numpy array per shape.
fn arrays<'py, T: numpy::Element + Clone>(
    py: Python<'py>,
    per_shape: &[Vec<T>],
) -> Vec<Bound<'py, PyArray1<T>>> {
    per_shape
        .iter()
        .map(|a| PyArray1::from_slice(py, a))
        .collect()
}

/// What every collection job returns besides its own results: `summary` (summary.json's
/// content), `skipped`, `warnings`, `outcomes` (per shape, where its data came from) and
/// `written`.
fn set_run_report<'py>(
    d: &Bound<'py, PyDict>,
    summary: &impl serde::Serialize,
    skipped: &[SkippedInput],
    warnings: &[String],
    cache_outcomes: &[Option<CacheOutcome>],
    written: &[PathBuf],
) -> PyResult<()> {
    let py = d.py();
    d.set_item("summary", json(py, summary)?)?;
    d.set_item("skipped", json(py, &skipped)?)?;
    d.set_item("warnings", warnings.to_vec())?;
    let outcomes: Vec<&str> = cache_outcomes.iter().map(outcome_name).collect();
    d.set_item("outcomes", outcomes)?;
    d.set_item("written", written.to_vec())?;
    Ok(())
}

/// Pair stage: `{"labels_a", "labels_b", "summary", "written"}`.
#[pyfunction]
#[pyo3(signature = (shapes, names=None, options=None, files=None))]
fn pair<'py>(
    py: Python<'py>,
    shapes: Bound<'py, PyList>,
    names: Option<Vec<String>>,
    options: Option<Bound<'py, PyDict>>,
    files: Option<Vec<Option<String>>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut o = Opts::new(options);
    let pipe = o.pipeline()?;
    let cache: Option<PathBuf> = o.take("cache_dir")?;
    let out_dir: Option<PathBuf> = o.take("out")?;
    let pair_opts = o.pair()?;
    o.finish()?;
    let shapes = shapes_from(&shapes, names, files)?;
    if shapes.len() != 2 {
        return Err(input_err(format!(
            "pair needs 2 shapes, got {}",
            shapes.len()
        )));
    }
    let mut job = PairJob::default();
    job.pipeline = pipe;
    job.pair = pair_opts.options();
    job.cache = cache_choice(cache, false);
    job.output = out_dir;
    // Python returns arrays; pictures are `coseg.render`'s.
    job.pictures = false;
    let [a, b]: [Shape; 2] = shapes
        .try_into()
        .map_err(|_| input_err("pair needs 2 shapes"))?;
    let outcome = py
        .detach(|| run_pair([a.into_job_shape(), b.into_job_shape()], &job))
        .map_err(|e| match e {
            JobError::Output(e) => lib_err(&e),
            e => input_err(e.to_string()),
        })?;
    let [la, lb] = outcome.labels;
    let d = PyDict::new(py);
    d.set_item("labels_a", PyArray1::from_vec(py, la))?;
    d.set_item("labels_b", PyArray1::from_vec(py, lb))?;
    d.set_item("summary", json(py, &outcome.summary)?)?;
    d.set_item("written", outcome.written)?;
    d.set_item("warnings", outcome.warnings)?;
    Ok(d)
}

fn outcome_name(o: &Option<CacheOutcome>) -> &'static str {
    match o {
        Some(CacheOutcome::Hit) => "hit",
        Some(CacheOutcome::Miss) => "miss",
        Some(CacheOutcome::Recomputed { .. }) => "recomputed",
        None => "computed",
    }
}

/// Collection stage: `{"names", "labels", "summary", "skipped", "warnings", "outcomes",
/// "written"}`.
#[pyfunction]
#[pyo3(signature = (shapes, names=None, options=None, files=None))]
fn segment<'py>(
    py: Python<'py>,
    shapes: Bound<'py, PyAny>,
    names: Option<Vec<String>>,
    options: Option<Bound<'py, PyDict>>,
    files: Option<Vec<Option<String>>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut o = Opts::new(options);
    let mut job = o.segment()?;
    let cache: Option<PathBuf> = o.take("cache_dir")?;
    job.output = o.take("out")?;
    o.finish()?;
    // Python returns arrays; pictures are `coseg.render`'s.
    job.pictures = false;
    let list = shapes.cast::<PyList>().ok();
    job.cache = cache_choice(cache, list.is_none());
    let input = match list {
        Some(list) => SegmentInput::Shapes(job_shapes(list, names, files)?),
        None => SegmentInput::Folder(shapes.extract()?),
    };
    let outcome = py
        .detach(|| run_segment(input, &job))
        .map_err(|e| lib_err(&e))?;
    let d = PyDict::new(py);
    d.set_item("names", outcome.result.segmentation.names.clone())?;
    d.set_item("labels", arrays(py, &outcome.labels))?;
    set_run_report(
        &d,
        &outcome.summary,
        &outcome.skipped,
        &outcome.warnings,
        &outcome.cache_outcomes,
        &outcome.written,
    )?;
    Ok(d)
}

/// One annotation per shape as handed to `propagate`: `None`, per-vertex labels, or a label
/// file.
fn label_inputs(list: &Bound<'_, PyList>) -> PyResult<Vec<JobLabels>> {
    let mut out = Vec::with_capacity(list.len());
    for (i, item) in list.iter().enumerate() {
        out.push(if item.is_none() {
            JobLabels::None
        } else if let Ok(p) = item.extract::<PathBuf>() {
            JobLabels::File(p)
        } else {
            let a: numpy::PyReadonlyArray1<i64> = item.extract().map_err(|e| {
                input_err(format!(
                    "labels {i}: expected a 1-D int64 array, a label file or None ({e})"
                ))
            })?;
            JobLabels::Vertex(a.as_array().to_vec())
        });
    }
    Ok(out)
}

/// Label propagation: `{"names", "labels", "confidence", "parts", "shape_confidence",
/// "sources", "summary", "skipped", "warnings", "outcomes", "written"}`.
#[pyfunction]
#[pyo3(signature = (shapes, labels, names=None, options=None, files=None))]
fn propagate<'py>(
    py: Python<'py>,
    shapes: Bound<'py, PyAny>,
    labels: Bound<'py, PyList>,
    names: Option<Vec<String>>,
    options: Option<Bound<'py, PyDict>>,
    files: Option<Vec<Option<String>>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut o = Opts::new(options);
    let mut job = PropagateJob::default();
    let opts = &mut job.propagation;
    opts.pipeline = o.pipeline()?;
    let cache: Option<PathBuf> = o.take("cache_dir")?;
    job.output = o.take("out")?;
    opts.part_names = o.take("part_names")?;
    let names_map: Option<PartNames> = o.take("part_names_map")?;
    (opts.graph, opts.propagate) = o.propagate()?;
    opts.map_step = o.map_step()?;
    o.finish()?;
    // Python returns arrays; pictures are `coseg.render`'s.
    job.pictures = false;
    let list = shapes.cast::<PyList>().ok();
    job.cache = cache_choice(cache, list.is_none());
    let input = match list {
        Some(list) => PropagateInput::Shapes {
            shapes: job_shapes(list, names, files)?,
            labels: label_inputs(&labels)?,
            part_names: names_map.unwrap_or_default(),
        },
        None if names_map.is_some() => {
            return Err(input_err(
                "part names of a folder come from a file (part_names=PATH)",
            ));
        }
        None => PropagateInput::Folder {
            folder: shapes.extract()?,
            labels: labels.extract()?,
        },
    };
    let outcome = py
        .detach(|| run_propagate(input, &job))
        .map_err(|e| lib_err(&e))?;
    let (result, summary) = (&outcome.result, &outcome.summary);
    let p = &result.propagation;
    let n = result.graph.node_count();
    let d = PyDict::new(py);
    let names: Vec<String> = (0..n).map(|i| result.graph.node(i).name.clone()).collect();
    d.set_item("names", names)?;
    d.set_item("labels", arrays(py, &p.labels))?;
    d.set_item("confidence", arrays(py, &p.confidence))?;
    d.set_item("parts", p.parts.clone())?;
    d.set_item(
        "shape_confidence",
        PyArray1::from_slice(py, &p.shape_confidence),
    )?;
    d.set_item("sources", summary.sources.clone())?;
    let skipped: Vec<SkippedInput> = result.skipped.iter().map(SkippedInput::from).collect();
    set_run_report(
        &d,
        summary,
        &skipped,
        &result.warnings,
        &outcome.cache_outcomes,
        &outcome.written,
    )?;
    Ok(d)
}

#[pymodule]
fn _coseg(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(defaults, m)?)?;
    m.add_function(wrap_pyfunction!(read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(spectrum, m)?)?;
    m.add_function(wrap_pyfunction!(features, m)?)?;
    m.add_function(wrap_pyfunction!(band_table, m)?)?;
    m.add_function(wrap_pyfunction!(shape_key, m)?)?;
    m.add_function(wrap_pyfunction!(shape_entry, m)?)?;
    m.add_function(wrap_pyfunction!(store_entry, m)?)?;
    m.add_function(wrap_pyfunction!(entry_is_valid, m)?)?;
    m.add_function(wrap_pyfunction!(pair, m)?)?;
    m.add_function(wrap_pyfunction!(segment, m)?)?;
    m.add_function(wrap_pyfunction!(propagate, m)?)?;
    m.add("FORMAT_VERSION", coseg::cache::FORMAT_VERSION)?;
    Ok(())
}
