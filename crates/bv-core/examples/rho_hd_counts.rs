//! The work of a 90-angle ρhd curve by quadrature for every analytic model of
//! the catalogue (its defaults, as criterion's `rho_hd_curve/*/quadrature/90`
//! builds them): integrand evaluations per angle (deterministic, the robust
//! number), the largest stated error and the best of three wall times on one
//! thread (indicative only; criterion's `rho_hd_curve` is the measurement).
//!
//! Run: `cargo run --release -p bv-core --example rho_hd_counts -- [-v] [ID…]`
//! (`-v`: the evaluations at every angle too).
//! Prints one line per model.

use bv_core::analysis::albedo::{self, AlbedoMethod, AlbedoOptions};
use bv_core::params::ParamKind;
use bv_core::{ModelSpec, catalogue};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    // `-v`: the evaluations of every angle too.
    let verbose = args.iter().any(|a| a == "-v");
    let only: Vec<String> = args.into_iter().filter(|a| a != "-v").collect();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let opts = AlbedoOptions {
        method: AlbedoMethod::Quadrature,
        ..AlbedoOptions::default()
    };
    let mut specs: Vec<(String, ModelSpec)> = Vec::new();
    for m in catalogue().iter() {
        if m.params
            .iter()
            .any(|d| matches!(d.kind, ParamKind::Path { .. }))
        {
            continue;
        }
        specs.push((m.id.to_string(), ModelSpec::new(m.id)?));
    }
    specs.push((
        "cook-torrance-ggx".to_string(),
        ModelSpec::from_json("cook-torrance", &serde_json::json!({"distribution": "ggx"}))?,
    ));
    for (name, spec) in specs {
        if !only.is_empty() && !only.contains(&name) {
            continue;
        }
        let b = spec.build()?;
        let mut best = f64::INFINITY;
        let mut curve = None;
        for _ in 0..3 {
            let t = Instant::now();
            let c = pool.install(|| albedo::rho_hd_curve(b.as_ref(), 0.0, 90, &opts));
            best = best.min(t.elapsed().as_secs_f64());
            curve = Some(c);
        }
        let Some(c) = curve else { continue };
        let evals: usize = c.rho.iter().map(|e| e.samples).sum();
        let worst = c
            .rho
            .iter()
            .map(|e| e.std_error.max_element())
            .fold(0.0, f64::max);
        let unconverged = c
            .rho
            .iter()
            .filter(|e| !matches!(e.method, albedo::Method::Quadrature { converged: true }))
            .count();
        if verbose {
            let per: Vec<String> = c.rho.iter().map(|e| e.samples.to_string()).collect();
            println!("{name}: {}", per.join(" "));
        }
        println!(
            "{name:24} {:>8} evals/angle {:>8.1} ms  max stated error {worst:.1e}  unconverged {unconverged}",
            evals / c.rho.len().max(1),
            best * 1e3
        );
    }
    Ok(())
}
