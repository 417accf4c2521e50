//! `bv simulate`: the virtual gonioreflectometer (issue 29) on the command
//! line. It generates a random microsurface (bv-core's `microsurface`), then
//! measures masking G1 against Smith, the NDF against D, and the BRDF and ρhd
//! (single and multiple bounces) for one incident direction, each with its
//! standard error; `--json` for scripts, a table otherwise. Progress goes to
//! stderr.
//!
//! Bad input (α ≤ 0, a size that is not a power of two or too large, zero or
//! absurd ray counts, an unknown Fresnel parameter) exits with status 2.

use super::output::{json_f64, print};
use anyhow::Context;
use bv_core::microsurface::measure::{self, GonioJob, GonioOptions};
use bv_core::microsurface::{SimFresnel, SlopeDistribution, Surface, SurfaceOptions};
use serde_json::{Value, json};
use std::io::{IsTerminal, Write};
use std::process::ExitCode;
use std::sync::Arc;

/// The surface's slope distribution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DistributionChoice {
    /// Gaussian random surface (Beckmann slopes).
    Beckmann,
    /// GGX slopes (a Gaussian surface with a varying roughness scale).
    Ggx,
}

/// The Fresnel factor at each bounce.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FresnelChoice {
    /// F = 1 (the furnace test: every ray keeps its energy).
    None,
    /// A conductor of index η + ik (`-p eta=… -p k=…`).
    Conductor,
}

/// Options of `bv simulate`.
#[derive(Debug, Clone, clap::Args)]
pub struct SimulateArgs {
    /// Slope distribution of the generated surface.
    #[arg(long, value_enum, default_value = "beckmann")]
    pub distribution: DistributionChoice,
    /// Roughness α (along x; also along y unless --alpha-y is given).
    #[arg(long)]
    pub alpha: f64,
    /// Roughness along y (anisotropic surface).
    #[arg(long)]
    pub alpha_y: Option<f64>,
    /// Incident polar angle θi in degrees, [0, 90).
    #[arg(long, default_value_t = 0.0)]
    pub theta_i: f64,
    /// Incident azimuth φi in degrees.
    #[arg(long, default_value_t = 0.0)]
    pub phi_i: f64,
    /// Fresnel factor per bounce.
    #[arg(long, value_enum, default_value = "none")]
    pub fresnel: FresnelChoice,
    /// Fresnel parameters: `-p eta=0.2 -p k=3.9` (conductor).
    #[arg(short, long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// Grid side of the surface (a power of two, 16..=4096).
    #[arg(long, default_value_t = 1024)]
    pub size: usize,
    /// Rays for the BRDF (G1 uses a tenth per angle, at least 10⁴).
    #[arg(long, default_value_t = 1_000_000)]
    pub rays: u64,
    /// Random seed (surface and rays).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Bounce cap (rays still bouncing are dropped and counted).
    #[arg(long, default_value_t = 64)]
    pub max_bounces: u32,
    /// Correlation length of the heights, in cells (≥ 1; default 4 for
    /// Beckmann, 2 for GGX).
    #[arg(long)]
    pub correlation_cells: Option<f64>,
    /// GGX only: correlation length of the local roughness scale, in cells
    /// (≥ the correlation length; more patches per surface with a shorter
    /// one, a purer GGX slope with a longer one; default 8).
    #[arg(long)]
    pub scale_cells: Option<f64>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// G1 is measured at these θ (degrees).
const G1_THETAS: [f64; 10] = [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 85.0];

fn fresnel(args: &SimulateArgs) -> anyhow::Result<SimFresnel> {
    let (mut eta, mut k) = (None, None);
    for p in &args.params {
        let (name, value) = p
            .split_once('=')
            .with_context(|| format!("--param {p}: expected NAME=VALUE"))?;
        let v: f64 = value
            .trim()
            .parse()
            .with_context(|| format!("--param {p}: `{value}` is not a number"))?;
        match name.trim() {
            "eta" => eta = Some(v),
            "k" => k = Some(v),
            other => {
                anyhow::bail!("--param {p}: unknown parameter `{other}` (simulate takes eta and k)")
            }
        }
    }
    match args.fresnel {
        FresnelChoice::None => {
            if eta.is_some() || k.is_some() {
                anyhow::bail!("--param eta/k need --fresnel conductor");
            }
            Ok(SimFresnel::None)
        }
        FresnelChoice::Conductor => {
            let eta = eta.context("--fresnel conductor needs -p eta=…")?;
            let k = k.unwrap_or(0.0);
            if !(eta.is_finite()
                && (0.01..=10.0).contains(&eta)
                && k.is_finite()
                && (0.0..=20.0).contains(&k))
            {
                anyhow::bail!(
                    "conductor index η = {eta}, k = {k}: need η in [0.01, 10], k in [0, 20]"
                );
            }
            Ok(SimFresnel::Conductor { eta, k })
        }
    }
}

/// Checks everything a user typed; the error exits with status 2.
fn options(args: &SimulateArgs) -> anyhow::Result<(SurfaceOptions, GonioOptions)> {
    let ay = args.alpha_y.unwrap_or(args.alpha);
    for (n, a) in [("--alpha", args.alpha), ("--alpha-y", ay)] {
        if !(a.is_finite() && a > 0.0) {
            anyhow::bail!("{n} {a}: roughness must be a positive number");
        }
    }
    let dist = match args.distribution {
        DistributionChoice::Beckmann => SlopeDistribution::Beckmann,
        DistributionChoice::Ggx => SlopeDistribution::Ggx,
    };
    let mut sopts = SurfaceOptions::new(dist, args.alpha, ay, args.size, args.seed);
    if let Some(l) = args.correlation_cells {
        sopts.correlation_cells = l;
    }
    if let Some(l) = args.scale_cells {
        sopts.scale_cells = l;
    }
    sopts.validate().context("surface")?;
    if args.rays == 0 || args.rays > 1_000_000_000 {
        anyhow::bail!("--rays {}: must be in [1, 10⁹]", args.rays);
    }
    if !(args.theta_i.is_finite() && (0.0..90.0).contains(&args.theta_i)) {
        anyhow::bail!("--theta-i {}: must be in [0, 90) degrees", args.theta_i);
    }
    if !args.phi_i.is_finite() {
        anyhow::bail!("--phi-i {}: must be finite", args.phi_i);
    }
    if args.max_bounces == 0 || args.max_bounces > 10_000 {
        anyhow::bail!("--max-bounces {}: must be in [1, 10000]", args.max_bounces);
    }
    let mut g = GonioOptions::new(args.theta_i.to_radians(), args.rays as usize, args.seed);
    g.phi_i = args.phi_i.to_radians();
    g.fresnel = fresnel(args)?;
    g.max_bounces = args.max_bounces;
    Ok((sopts, g))
}

/// Runs `bv simulate`.
pub fn run(args: &SimulateArgs) -> anyhow::Result<ExitCode> {
    let (sopts, gopts) = match options(args) {
        Ok(o) => o,
        Err(e) => {
            super::output::eprint(&format!("bv simulate: {}\n", super::output::message(&e)));
            return Ok(ExitCode::from(2));
        }
    };
    let start = std::time::Instant::now();
    let tty = std::io::stderr().is_terminal();
    let progress = |msg: &str| {
        if !tty {
            return;
        }
        let mut err = std::io::stderr().lock();
        // Progress is a courtesy: a closed stderr must not stop the run.
        let _ = write!(err, "\r{msg:<70}");
        let _ = err.flush();
    };
    progress(&format!("generating a {0}×{0} surface…", sopts.size));
    let surface = Arc::new(Surface::generate(&sopts).context("generating the surface")?);
    let t_surface = start.elapsed().as_secs_f64();

    progress("NDF…");
    let ndf = measure::ndf_histogram(&surface, 24, 16);
    let slopes = measure::slope_stats(&surface);

    let mut job = GonioJob::new(Arc::clone(&surface), gopts).context("gonioreflectometer")?;
    let t0 = std::time::Instant::now();
    let gonio = loop {
        if let Some(g) = job.step(32) {
            break g;
        }
        let (done, all) = job.progress();
        progress(&format!(
            "BRDF: {done}/{all} batches of {} rays",
            measure::BATCH
        ));
    };
    let t_gonio = t0.elapsed().as_secs_f64();

    progress("masking G1…");
    let g1_rays = (args.rays as usize / 10).max(10_000);
    let thetas: Vec<f64> = G1_THETAS.iter().map(|d| d.to_radians()).collect();
    let g1 = measure::measure_g1(&surface, &thetas, gopts.phi_i, g1_rays, args.seed)
        .context("measuring G1")?;
    let mut err = std::io::stderr().lock();
    let _ = writeln!(
        err,
        "{}{:<70}",
        if tty { "\r" } else { "" },
        format!(
            "done: surface {t_surface:.2} s, {} rays in {t_gonio:.2} s ({:.2} M rays/s, {} threads)",
            gonio.rays,
            gonio.rays as f64 / t_gonio / 1e6,
            rayon::current_num_threads()
        )
    );
    drop(err);

    let mf = surface.microfacet();
    let bins = gopts.n_theta * gopts.n_phi;
    let analytic: Vec<f64> = (0..bins).map(|b| gonio.analytic_single(&mf, b)).collect();
    let analytic_rho: f64 = (0..bins)
        .map(|b| analytic[b] * gopts.bin_cos_integral(b))
        .sum();
    if args.json {
        let brdf: Vec<Value> = (0..bins)
            .map(|b| {
                let (hi, lo, p0, p1) = gopts.bin_bounds(b);
                json!({
                    "theta_deg": [hi.acos().to_degrees(), lo.acos().to_degrees()],
                    "phi_deg": [p0.to_degrees(), p1.to_degrees()],
                    "single": json_f64(gonio.single[b]),
                    "single_sigma": json_f64(gonio.single_sigma[b]),
                    "multiple": json_f64(gonio.multiple[b]),
                    "multiple_sigma": json_f64(gonio.multiple_sigma[b]),
                    "single_sigma_surface": json_f64(gonio.single_sigma_surface[b]),
                    "multiple_sigma_surface": json_f64(gonio.multiple_sigma_surface[b]),
                    "cook_torrance": json_f64(analytic[b]),
                })
            })
            .collect();
        let v = json!({
            "distribution": format!("{:?}", sopts.distribution).to_lowercase(),
            "alpha": [sopts.alpha_x, sopts.alpha_y],
            "size": sopts.size,
            "seed": sopts.seed,
            "theta_i_deg": args.theta_i,
            "phi_i_deg": args.phi_i,
            "rays": gonio.rays,
            "dropped": gonio.dropped,
            "lost": gonio.lost,
            "g1": g1.iter().map(|p| json!({
                "theta_deg": p.theta.to_degrees(),
                "measured": json_f64(p.measured),
                "sigma": json_f64(p.sigma),
                "smith": json_f64(p.smith),
                "identity": json_f64(p.identity),
                "rays": p.rays,
            })).collect::<Vec<_>>(),
            "ndf_rel_error": json_f64(ndf.rel_error()),
            "slope_variance": {
                "measured": [json_f64(slopes.var_x), json_f64(slopes.var_y)],
                "beckmann": [sopts.alpha_x.powi(2) / 2.0, sopts.alpha_y.powi(2) / 2.0],
            },
            "rho": {
                "single": json_f64(gonio.rho_single),
                "single_sigma": json_f64(gonio.rho_single_sigma),
                "multiple": json_f64(gonio.rho_multiple),
                "multiple_sigma": json_f64(gonio.rho_multiple_sigma),
                "single_sigma_surface": json_f64(gonio.rho_single_sigma_surface),
                "multiple_sigma_surface": json_f64(gonio.rho_multiple_sigma_surface),
                "total": json_f64(gonio.rho()),
                "sigma": json_f64(gonio.rho_sigma),
                "cook_torrance_single": json_f64(analytic_rho),
            },
            "brdf_bins": "uniform in cos θo and φo (equal solid angle); values are the cos-weighted bin means of f in 1/sr; *_sigma: ray noise on this surface; *_sigma_surface: spread of 4×4 start tiles (ray noise and the surface's own fluctuation)",
            "brdf": brdf,
            "seconds": { "surface": t_surface, "brdf": t_gonio },
        });
        print(&format!("{}\n", serde_json::to_string_pretty(&v)?))?;
    } else {
        let mut s = String::new();
        s += &format!(
            "surface: {:?} αx = {} αy = {}, {}², seed {}\n",
            sopts.distribution, sopts.alpha_x, sopts.alpha_y, sopts.size, sopts.seed
        );
        s += &format!(
            "slope variance: x {:.5} y {:.5} (Beckmann α²/2: {:.5} {:.5}); NDF L1 error {:.4}\n\n",
            slopes.var_x,
            slopes.var_y,
            sopts.alpha_x.powi(2) / 2.0,
            sopts.alpha_y.powi(2) / 2.0,
            ndf.rel_error()
        );
        s += "masking G1(θ)   measured ± σ        Smith    surface identity\n";
        for p in &g1 {
            s += &format!(
                "  {:5.1}°        {:.4} ± {:.4}     {:.4}   {:.4}\n",
                p.theta.to_degrees(),
                p.measured,
                p.sigma,
                p.smith,
                p.identity
            );
        }
        s += &format!(
            "\nρhd(θi = {}°): single {:.4} ± {:.4} (Cook–Torrance, Smith correlated: {:.4}), multiple {:.4} ± {:.4}, total {:.4} ± {:.4}\n",
            args.theta_i,
            gonio.rho_single,
            gonio.rho_single_sigma,
            analytic_rho,
            gonio.rho_multiple,
            gonio.rho_multiple_sigma,
            gonio.rho(),
            gonio.rho_sigma
        );
        s += &format!(
            "rays {} (dropped at {} bounces: {}, lost: {}), {:.2} M rays/s\n",
            gonio.rays,
            gopts.max_bounces,
            gonio.dropped,
            gonio.lost,
            gonio.rays as f64 / t_gonio / 1e6
        );
        print(&s)?;
    }
    Ok(ExitCode::SUCCESS)
}
