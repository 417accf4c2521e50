//! `bv._native`: bv from Python (issue 30). The compiled half of the `bv`
//! package; `python/bv/__init__.py` wraps it with numpy conversions,
//! docstrings and figure objects.
//!
//! Every entry calls what the command line calls: models are built by
//! [`ModelSpec::from_json`] (the parsing and messages of `bv eval` and
//! scene files), `eval` goes through [`bv_core::batch::eval`] (the f32 SIMD
//! kernels `bv bench` measures) or the f64 reference [`Brdf::try_eval`]
//! (what `bv eval` answers), `albedo` through the albedo view's estimator
//! ([`bv::derive::albedo::rho_hd_at`], as `bv slice --curve albedo`), and
//! `check` through [`bv::cli::check::report`] (as `bv check --json`). Errors
//! come back as `ValueError` with the command line's message; nothing a
//! caller passes panics.

use bv::session::state::{AppState, Theme};
use bv_core::batch::{Dirs, Out};
use bv_core::{Brdf, ModelSpec, Rgb};
use glam::{DVec2, DVec3};
use numpy::ndarray::{Array2, ArrayView2};
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Pairs per batch-kernel call: big enough to amortise the dispatch, small
/// enough for the structure-of-arrays buffers to stay in L1/L2.
const CHUNK: usize = 4096;

/// Two `(N, 3)` float64 arrays handed to Python (albedo's values and errors).
type ArrayPair<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// A `ValueError` carrying the command line's message for `e`.
fn value_error(e: &anyhow::Error) -> PyErr {
    PyValueError::new_err(bv::cli::output::message(e))
}

/// A `ValueError` from any displayable error (the core's `BvError`).
fn bv_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// The model catalogue as `bv models --json` prints it (a JSON string; the
/// Python side parses it).
#[pyfunction]
fn models_json() -> PyResult<String> {
    serde_json::to_string(&bv::cli::models::catalogue_json()).map_err(bv_error)
}

/// One model with its parameters, built once.
#[pyclass(module = "bv._native", name = "Model", frozen)]
struct Model {
    spec: ModelSpec,
    brdf: Box<dyn Brdf>,
}

/// Directions of an `(N, 3)` or `(1, 3)` array, checked as the command line
/// checks them ([`bv_core::frame::checked_direction`]: finite, unit length
/// within 1e-3, then normalised). `None` when the row is refused.
fn direction(a: &ArrayView2<'_, f64>, i: usize) -> Option<DVec3> {
    let r = if a.nrows() == 1 { 0 } else { i };
    let v = DVec3::new(a[[r, 0]], a[[r, 1]], a[[r, 2]]);
    let len = v.length();
    ((len - 1.0).abs() <= 1e-3 && v.is_finite()).then(|| v / len)
}

/// The rows of `a` (1 row broadcasts) that are not directions: the first
/// one's message, as `bv eval` gives it, naming the row.
fn check_rows(name: &str, a: &ArrayView2<'_, f64>, n: usize) -> Result<(), String> {
    let bad = AtomicUsize::new(usize::MAX);
    let rows = if a.nrows() == 1 { 1 } else { n };
    (0..rows).into_par_iter().for_each(|i| {
        if direction(a, i).is_none() {
            bad.fetch_min(i, Ordering::Relaxed);
        }
    });
    let i = bad.load(Ordering::Relaxed);
    if i == usize::MAX {
        return Ok(());
    }
    let row = [a[[i, 0]], a[[i, 1]], a[[i, 2]]];
    let label = format!("{name}[{i}]");
    match bv_core::frame::checked_direction(&label, row) {
        Err(e) => Err(e.to_string()),
        Ok(_) => Err(format!("{label}: {row:?} is not a direction")),
    }
}

/// The number of pairs of two `(N, 3)` / `(1, 3)` arrays, or why they do
/// not broadcast.
fn pair_count(a: &ArrayView2<'_, f64>, b: &ArrayView2<'_, f64>) -> Result<usize, String> {
    for (name, x) in [("wi", a), ("wo", b)] {
        if x.ncols() != 3 {
            return Err(format!(
                "{name} must have shape (N, 3) or (3,), found {:?}",
                x.shape()
            ));
        }
    }
    match (a.nrows(), b.nrows()) {
        (n, m) if n == m => Ok(n),
        (1, m) => Ok(m),
        (n, 1) => Ok(n),
        (n, m) => Err(format!(
            "wi has {n} rows and wo {m}: they must match, or one be a single direction"
        )),
    }
}

#[pymethods]
impl Model {
    /// Builds `model` (a catalogue id or a `.brdf` path) with `params_json`
    /// (a JSON object, as `bv eval`'s `"params"`).
    #[new]
    fn new(model: &str, params_json: &str) -> PyResult<Self> {
        bv::session::user_models::install();
        let mut params: serde_json::Value = serde_json::from_str(params_json)
            .map_err(|e| PyValueError::new_err(format!("invalid parameters: {e}")))?;
        let mut model = model.trim();
        // A data file (`gold.binary`) stands for the catalogue model that
        // reads its format, with the path as its file parameter, as a file
        // dropped on the window does (`session::loader::file_model_for`).
        let path = std::path::Path::new(model);
        if let Some((info, param, format)) = bv::session::loader::file_model_for(path) {
            let ext = path
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase())
                .unwrap_or_default();
            if format.extensions().contains(&ext.as_str()) {
                if let serde_json::Value::Object(map) = &mut params {
                    map.entry(param)
                        .or_insert_with(|| serde_json::Value::String(model.to_string()));
                }
                model = info.id;
            }
        }
        let spec = ModelSpec::from_json(model, &params).map_err(bv_error)?;
        let brdf = spec.build().map_err(bv_error)?;
        Ok(Self { spec, brdf })
    }

    /// The model id.
    #[getter]
    fn id(&self) -> &str {
        self.spec.id()
    }

    /// Every parameter's value (defaults filled in) as a JSON string.
    fn params_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.spec.params().to_json()).map_err(bv_error)
    }

    /// Whether the model scatters below the surface.
    #[getter]
    fn transmits(&self) -> bool {
        self.brdf.transmits()
    }

    /// Whether `eval` in f32 runs a SIMD kernel (else the f64 code, lane
    /// by lane), and the instruction set.
    fn dispatch(&self) -> (bool, &'static str) {
        let kernel = self.brdf.batch_kernel().is_some();
        (
            kernel,
            if kernel {
                bv_core::batch::isa().name()
            } else {
                "scalar"
            },
        )
    }

    /// f(wi, wo) for `(N, 3)` float64 arrays (a `(1, 3)` one broadcasts):
    /// an `(N, 3)` float32 array through the batch kernels (`f64 = False`)
    /// or float64 through the f64 reference, on all cores without the GIL.
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wi: PyReadonlyArray2<'py, f64>,
        wo: PyReadonlyArray2<'py, f64>,
        f64_path: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (a, b) = (wi.as_array(), wo.as_array());
        let n = pair_count(&a, &b).map_err(PyValueError::new_err)?;
        let brdf = self.brdf.as_ref();
        if f64_path {
            let out = py
                .detach(|| eval_f64(brdf, &a, &b, n))
                .map_err(PyValueError::new_err)?;
            Ok(out.into_pyarray(py).into_any())
        } else {
            let out = py
                .detach(|| eval_f32(brdf, &a, &b, n))
                .map_err(PyValueError::new_err)?;
            Ok(out.into_pyarray(py).into_any())
        }
    }

    /// The density of `sample` at `wo` for light from `wi` (per steradian),
    /// an `(N,)` float64 array.
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        wi: PyReadonlyArray2<'py, f64>,
        wo: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (a, b) = (wi.as_array(), wo.as_array());
        let n = pair_count(&a, &b).map_err(PyValueError::new_err)?;
        let brdf = self.brdf.as_ref();
        let out = py
            .detach(|| -> Result<Vec<f64>, String> {
                check_rows("wi", &a, n)?;
                check_rows("wo", &b, n)?;
                Ok((0..n)
                    .into_par_iter()
                    .map(|i| match (direction(&a, i), direction(&b, i)) {
                        (Some(wi), Some(wo)) => brdf.pdf(wi, wo),
                        _ => f64::NAN,
                    })
                    .collect())
            })
            .map_err(PyValueError::new_err)?;
        Ok(out.into_pyarray(py).into_any())
    }

    /// Importance samples: `wo` `(N, 3)`, `weight` `(N, 3)` (f |cos θo| /
    /// pdf) and `pdf` `(N,)`, for `wi` `(N, 3)` or `(1, 3)` and uniform
    /// points `u` `(N, 2)` in [0, 1)². Where the model draws nothing, `wo`
    /// is NaN and weight and pdf are 0.
    #[allow(clippy::type_complexity)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wi: PyReadonlyArray2<'py, f64>,
        u: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyAny>,
    )> {
        let (a, uu) = (wi.as_array(), u.as_array());
        if a.ncols() != 3 {
            return Err(PyValueError::new_err(format!(
                "wi must have shape (N, 3) or (3,), found {:?}",
                a.shape()
            )));
        }
        if uu.ncols() != 2 {
            return Err(PyValueError::new_err(format!(
                "u must have shape (N, 2), found {:?}",
                uu.shape()
            )));
        }
        let n = uu.nrows();
        if a.nrows() != 1 && a.nrows() != n {
            return Err(PyValueError::new_err(format!(
                "wi has {} rows and u {n}: they must match, or wi be a single direction",
                a.nrows()
            )));
        }
        let brdf = self.brdf.as_ref();
        let (wo, weight, pdf) = py
            .detach(|| -> Result<_, String> {
                check_rows("wi", &a, n)?;
                if let Some(i) = (0..n).find(|&i| {
                    !(0.0..1.0).contains(&uu[[i, 0]]) || !(0.0..1.0).contains(&uu[[i, 1]])
                }) {
                    return Err(format!(
                        "u[{i}] = [{}, {}]: expected two numbers in [0, 1)",
                        uu[[i, 0]],
                        uu[[i, 1]]
                    ));
                }
                let rows: Vec<([f64; 3], [f64; 3], f64)> = (0..n)
                    .into_par_iter()
                    .map(|i| {
                        let Some(w) = direction(&a, i) else {
                            return ([f64::NAN; 3], [0.0; 3], 0.0);
                        };
                        let u = DVec2::new(uu[[i, 0]], uu[[i, 1]]);
                        match bv_core::sample_weighted(brdf, w, u) {
                            Some(s) => (s.wo.to_array(), s.weight.to_array(), s.pdf),
                            None => ([f64::NAN; 3], [0.0; 3], 0.0),
                        }
                    })
                    .collect();
                let mut wo = Array2::<f64>::zeros((n, 3));
                let mut weight = Array2::<f64>::zeros((n, 3));
                let mut pdf = Vec::with_capacity(n);
                for (i, (o, w, p)) in rows.into_iter().enumerate() {
                    for c in 0..3 {
                        wo[[i, c]] = o[c];
                        weight[[i, c]] = w[c];
                    }
                    pdf.push(p);
                }
                Ok((wo, weight, pdf))
            })
            .map_err(PyValueError::new_err)?;
        Ok((
            wo.into_pyarray(py),
            weight.into_pyarray(py),
            pdf.into_pyarray(py).into_any(),
        ))
    }

    /// ρhd at each θi in degrees (0..90, to 180 for a model that transmits)
    /// and azimuth `phi_i_deg`: `(values, errors)`, each `(N, 3)`, with the
    /// estimators of `bv slice --curve albedo` (quadrature with its error
    /// estimate for analytic models, Monte Carlo with one standard error for
    /// measured ones).
    fn albedo<'py>(
        &self,
        py: Python<'py>,
        theta_i_deg: PyReadonlyArray1<'py, f64>,
        phi_i_deg: f64,
    ) -> PyResult<ArrayPair<'py>> {
        let t = theta_i_deg.as_array();
        let max = if self.brdf.transmits() { 180.0 } else { 90.0 };
        if let Some(bad) = t
            .iter()
            .find(|x| !(x.is_finite() && (0.0..=max).contains(*x)))
        {
            return Err(PyValueError::new_err(format!(
                "theta_i {}: out of range 0..={max}°",
                bv_core::error::fmt_num(*bad)
            )));
        }
        if !phi_i_deg.is_finite() {
            return Err(PyValueError::new_err(format!(
                "phi_i {}: not a finite angle",
                bv_core::error::fmt_num(phi_i_deg)
            )));
        }
        let brdf = self.brdf.as_ref();
        let est: Vec<_> = py.detach(|| {
            let phi = phi_i_deg.to_radians();
            t.iter()
                .copied()
                .collect::<Vec<_>>()
                .par_iter()
                .enumerate()
                .map(|(k, &x)| bv::derive::albedo::rho_hd_at(brdf, x.to_radians(), phi, k as u64))
                .collect()
        });
        let n = est.len();
        let mut v = Array2::<f64>::zeros((n, 3));
        let mut e = Array2::<f64>::zeros((n, 3));
        for (i, x) in est.iter().enumerate() {
            for c in 0..3 {
                v[[i, c]] = x.value[c];
                e[[i, c]] = x.std_error[c];
            }
        }
        Ok((v.into_pyarray(py), e.into_pyarray(py)))
    }

    /// The property report as `bv check --json` prints it (a JSON string);
    /// `albedo` is `auto`, `quadrature` or `monte-carlo`.
    fn check_json(&self, py: Python<'_>, albedo: &str) -> PyResult<String> {
        use bv::cli::check::AlbedoChoice;
        let choice = match albedo {
            "auto" => AlbedoChoice::Auto,
            "quadrature" => AlbedoChoice::Quadrature,
            "monte-carlo" => AlbedoChoice::MonteCarlo,
            other => {
                return Err(PyValueError::new_err(format!(
                    "albedo={other:?}: expected \"auto\", \"quadrature\" or \"monte-carlo\""
                )));
            }
        };
        let spec = &self.spec;
        let v = py
            .detach(|| {
                let report = bv::cli::check::report(spec, choice)?;
                bv::cli::check::report_json(&report, spec)
            })
            .map_err(|e| value_error(&e))?;
        serde_json::to_string(&v).map_err(bv_error)
    }
}

/// f through the f64 reference for every pair (what `bv eval` answers).
fn eval_f64(
    brdf: &dyn Brdf,
    a: &ArrayView2<'_, f64>,
    b: &ArrayView2<'_, f64>,
    n: usize,
) -> Result<Array2<f64>, String> {
    check_rows("wi", a, n)?;
    check_rows("wo", b, n)?;
    let mut out = Array2::<f64>::zeros((n, 3));
    let slice = out
        .as_slice_mut()
        .ok_or_else(|| "internal: output not contiguous".to_string())?;
    let failed: Result<(), String> =
        slice
            .par_chunks_mut(3 * CHUNK)
            .enumerate()
            .try_for_each(|(c, o)| {
                for (j, px) in o.chunks_mut(3).enumerate() {
                    let i = c * CHUNK + j;
                    let (Some(wi), Some(wo)) = (direction(a, i), direction(b, i)) else {
                        return Err(format!("pair {i}: not a direction"));
                    };
                    let f: Rgb = brdf.try_eval(wi, wo).map_err(|e| e.to_string())?;
                    px.copy_from_slice(&f.to_array());
                }
                Ok(())
            });
    failed.map(|()| out)
}

/// f through the f32 batch kernels, CHUNK pairs at a time on all cores.
fn eval_f32(
    brdf: &dyn Brdf,
    a: &ArrayView2<'_, f64>,
    b: &ArrayView2<'_, f64>,
    n: usize,
) -> Result<Array2<f32>, String> {
    check_rows("wi", a, n)?;
    check_rows("wo", b, n)?;
    let mut out = Array2::<f32>::zeros((n, 3));
    let slice = out
        .as_slice_mut()
        .ok_or_else(|| "internal: output not contiguous".to_string())?;
    slice
        .par_chunks_mut(3 * CHUNK)
        .enumerate()
        .for_each(|(c, o)| {
            let m = o.len() / 3;
            // Structure of arrays for the kernel: wi x, y, z, wo x, y, z,
            // then r, g, b.
            let mut buf = vec![0f32; 9 * m];
            let (dirs, rgb) = buf.split_at_mut(6 * m);
            for j in 0..m {
                let i = c * CHUNK + j;
                // Rows were checked above; a refused one cannot reach here.
                let wi = direction(a, i).unwrap_or(DVec3::Z);
                let wo = direction(b, i).unwrap_or(DVec3::Z);
                for k in 0..3 {
                    dirs[k * m + j] = wi[k] as f32;
                    dirs[(3 + k) * m + j] = wo[k] as f32;
                }
            }
            let d: Vec<&[f32]> = dirs.chunks(m).collect();
            let dirs = Dirs {
                wi: [d[0], d[1], d[2]],
                wo: [d[3], d[4], d[5]],
            };
            let (r, gb) = rgb.split_at_mut(m);
            let (g, bl) = gb.split_at_mut(m);
            let mut out = Out { rgb: [r, g, bl] };
            bv_core::batch::eval(brdf, &dirs, &mut out);
            let [r, g, bl] = out.rgb;
            for j in 0..m {
                o[3 * j] = r[j];
                o[3 * j + 1] = g[j];
                o[3 * j + 2] = bl[j];
            }
        });
    Ok(out)
}

/// `bv render`'s options `args` (`--view`, `--width`, `--theta-i`, …)
/// parsed and checked by its own parser.
fn render_args(args: Vec<String>) -> PyResult<bv::cli::render::RenderArgs> {
    use clap::Parser as _;
    let argv = ["bv", "render"]
        .into_iter()
        .map(String::from)
        .chain(args)
        // Required by the parser; nothing is written.
        .chain(["--out".to_string(), "figure.png".to_string()]);
    let cli = bv::cli::Cli::try_parse_from(argv)
        .map_err(|e| PyValueError::new_err(e.render().to_string().trim().to_string()))?;
    match cli.command {
        Some(bv::cli::Command::Render(a)) => Ok(a),
        _ => Err(PyValueError::new_err("internal: not a render command")),
    }
}

/// An RGBA image as an `(H, W, 4)` uint8 array.
fn image_array(py: Python<'_>, img: image::RgbaImage) -> PyResult<Bound<'_, numpy::PyArray3<u8>>> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    let arr = numpy::ndarray::Array3::from_shape_vec((h, w, 4), img.into_raw())
        .map_err(|e| PyValueError::new_err(format!("internal: image of {w}×{h}: {e}")))?;
    Ok(arr.into_pyarray(py))
}

/// One view of `model` as an `(H, W, 4)` uint8 RGBA array, drawn as `bv
/// render --view …` draws it: `args` are `bv render`'s options (`--view`,
/// `--width`, `--theta-i`, …; parsed and checked by its own parser).
#[pyfunction]
fn render<'py>(
    py: Python<'py>,
    model: &Model,
    args: Vec<String>,
) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
    let a = render_args(args)?;
    let spec = model.spec.clone();
    let img = py
        .detach(|| bv::cli::render::view_image(&a, Some(spec)))
        .map_err(|e| value_error(&e))?;
    image_array(py, img)
}

/// One view of a whole scene (all its BRDFs, its light and display options,
/// `args` on top) as an `(H, W, 4)` uint8 RGBA array, drawn as `bv render
/// --scene FILE --view …` draws the scene's file.
#[pyfunction]
fn render_scene<'py>(
    py: Python<'py>,
    scene: &Scene,
    args: Vec<String>,
) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
    let a = render_args(args)?;
    let state = scene.state.clone();
    let img = py
        .detach(|| bv::cli::render::scene_image(&a, state))
        .map_err(|e| value_error(&e))?;
    image_array(py, img)
}

/// A scene: BRDFs (model, parameters, colour, visibility), light, camera,
/// display options; read and written as scene files (`bv --scene FILE`,
/// `bv render --scene FILE`, `bv scene check FILE`).
#[pyclass(module = "bv._native", name = "Scene", frozen)]
struct Scene {
    state: AppState,
    warnings: Vec<String>,
}

#[pymethods]
impl Scene {
    /// The scene of `models` (none: the first-run scene's) with the light
    /// at (`theta_i`, `phi_i`) degrees and the display options, checked as
    /// `bv scene new` checks them.
    #[new]
    #[pyo3(signature = (models, theta_i=None, phi_i=None, log=false, cosine=false, light=false))]
    fn new(
        models: Vec<PyRef<'_, Model>>,
        theta_i: Option<f64>,
        phi_i: Option<f64>,
        log: bool,
        cosine: bool,
        light: bool,
    ) -> PyResult<Self> {
        let specs = models.iter().map(|m| m.spec.clone()).collect();
        let opts = bv::cli::scene::NewScene {
            model: Vec::new(),
            params: Vec::new(),
            theta_i,
            phi_i,
            light,
            log,
            cosine,
        };
        let state = bv::cli::scene::state_with(specs, &opts).map_err(|e| value_error(&e))?;
        Ok(Self {
            state,
            warnings: Vec::new(),
        })
    }

    /// Reads a scene file as `bv scene check` reads it (the same message
    /// on failure).
    #[staticmethod]
    fn load(path: std::path::PathBuf) -> PyResult<Self> {
        bv::session::user_models::install();
        let loaded = bv::cli::scene::load(&path).map_err(|e| value_error(&e))?;
        Ok(Self {
            state: loaded.state,
            warnings: loaded.warnings,
        })
    }

    /// Writes the scene file atomically, as the viewer's Save does (paths
    /// relative to its folder where they lie inside it).
    fn save(&self, path: std::path::PathBuf) -> PyResult<()> {
        bv::session::scene_file::save(&path, &self.state)
            .map_err(|e| value_error(&anyhow::Error::new(e)))
    }

    /// The scene file's text (paths as given).
    fn to_toml(&self) -> PyResult<String> {
        bv::session::scene_file::to_toml(&self.state).map_err(bv_error)
    }

    /// The remarks loading made (unknown keys, a missing `format` line).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// The BRDFs as a JSON list of `{id, params, name, visible, color}`.
    fn brdfs_json(&self) -> PyResult<String> {
        let list: Vec<serde_json::Value> = self
            .state
            .brdfs
            .iter()
            .map(|b| {
                serde_json::json!({
                    "id": b.spec.id(),
                    "params": b.spec.params().to_json(),
                    "name": b.name,
                    "visible": b.visible,
                    "color": b.color,
                })
            })
            .collect();
        serde_json::to_string(&list).map_err(bv_error)
    }

    /// The BRDFs as models, in order.
    fn models(&self) -> PyResult<Vec<Model>> {
        self.state
            .brdfs
            .iter()
            .map(|b| {
                let brdf = b.spec.build().map_err(bv_error)?;
                Ok(Model {
                    spec: b.spec.clone(),
                    brdf,
                })
            })
            .collect()
    }

    /// The light's polar angle, degrees.
    #[getter]
    fn theta_i(&self) -> f64 {
        self.state.incident.theta_deg
    }

    /// The light's azimuth, degrees.
    #[getter]
    fn phi_i(&self) -> f64 {
        self.state.incident.phi_deg
    }

    /// Whether plots use a logarithmic scale.
    #[getter]
    fn log(&self) -> bool {
        self.state.display.log
    }

    /// Whether plots show f · cos θo.
    #[getter]
    fn cosine(&self) -> bool {
        self.state.display.cosine
    }

    /// `"light"` or `"dark"`.
    #[getter]
    fn theme(&self) -> &'static str {
        match self.state.theme {
            Theme::Light => "light",
            Theme::Dark => "dark",
        }
    }

    /// Whether two scenes hold the same state (what a scene file records).
    fn same_as(&self, other: &Scene) -> bool {
        self.state == other.state
    }
}

/// Fits the parameters `free` of `model` (its values are the first start
/// and the fixed ones; `None`: `bv_core::fit::default_free`) to `target`
/// with `bv_core::fit::fit`, as `bv fit` does, the GIL released. Returns
/// the fitted model and the result as JSON (what `bv fit --json` prints,
/// less the timing).
#[pyfunction]
#[pyo3(signature = (model, target, free, metric, starts))]
fn fit(
    py: Python<'_>,
    model: &Model,
    target: &Model,
    free: Option<Vec<String>>,
    metric: &str,
    starts: usize,
) -> PyResult<(Model, String)> {
    use bv_core::fit::{FitOptions, Metric};
    let metric = match metric {
        "ngan" => Metric::Ngan,
        "e2" => Metric::E2,
        other => {
            return Err(PyValueError::new_err(format!(
                "metric={other:?}: expected \"ngan\" (Ngan et al. 2005) or \"e2\" (Löw et al. 2012)"
            )));
        }
    };
    if !(1..=64).contains(&starts) {
        return Err(PyValueError::new_err(format!(
            "starts={starts}: expected 1 to 64"
        )));
    }
    let free: Vec<String> = match free {
        Some(list) => list,
        None => bv_core::fit::default_free(&model.spec)
            .into_iter()
            .map(str::to_string)
            .collect(),
    };
    if free.is_empty() {
        return Err(PyValueError::new_err(format!(
            "model `{}` has no float or colour parameter to fit",
            model.spec.id()
        )));
    }
    let opts = FitOptions {
        metric,
        starts,
        ..FitOptions::default()
    };
    let spec = &model.spec;
    let target_brdf = target.brdf.as_ref();
    let result = py
        .detach(|| {
            let refs: Vec<&str> = free.iter().map(String::as_str).collect();
            bv_core::fit::fit(
                spec,
                &refs,
                target_brdf,
                &opts,
                &std::sync::atomic::AtomicBool::new(false),
                &mut |_| {},
            )
        })
        .map_err(bv_error)?;
    let brdf = result.spec.build().map_err(bv_error)?;
    let v = bv::cli::fit::report_json(&result, &target.spec);
    let json = serde_json::to_string(&v).map_err(bv_error)?;
    Ok((
        Model {
            spec: result.spec,
            brdf,
        },
        json,
    ))
}

/// The compiled half of the `bv` package (see `bv/__init__.py`).
#[pymodule]
#[pyo3(name = "_native")]
fn bv_native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(models_json, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(render_scene, m)?)?;
    m.add_class::<Model>()?;
    m.add_class::<Scene>()?;
    Ok(())
}
