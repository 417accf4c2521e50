//! Headless rendering of the GPU views to PNG (what a `bv render` will call):
//! `cargo run --release --example render_views -- OUT_DIR [SIZE] [SPP]`.
//! Writes `lit_sphere.png` and `environment.png` of three models side by side.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::gpu::{
    EnvRenderer, EnvSettings, EnvironmentMap, Gpu, LitSphereRenderer, LitSphereSettings,
    shaders::ShaderLibrary,
};
use bv_core::ModelSpec;
use std::path::PathBuf;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(args.next().unwrap_or_else(|| "out".to_string()));
    let size: u32 = args.next().map_or(Ok(256), |s| s.parse())?;
    let spp: u32 = args.next().map_or(Ok(256), |s| s.parse())?;
    std::fs::create_dir_all(&out)?;
    let models = [
        ModelSpec::from_json("lambert", &serde_json::json!({"albedo": [0.8, 0.45, 0.2]}))?,
        ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"kd": 0.0, "ks": 1.0, "distribution": "ggx", "alpha": 0.25,
                "fresnel": "conductor", "eta": [0.2, 0.92, 1.1], "k": [3.9, 2.45, 2.14]}),
        )?,
        ModelSpec::from_json(
            "ward",
            &serde_json::json!({"kd": 0.1, "ks": 0.4, "alpha_x": 0.05, "alpha_y": 0.3}),
        )?,
    ];
    let gpu = Gpu::headless()?;
    println!("adapter: {}", gpu.describe());
    let mut lib = ShaderLibrary::new()?;
    let mut lit = LitSphereRenderer::new(gpu.clone(), &mut lib)?;
    lit.render_image(&models, &LitSphereSettings::default(), 3 * size, size)?
        .save(out.join("lit_sphere.png"))?;
    let studio =
        EnvironmentMap::load(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/studio.hdr"))?;
    let mut env = EnvRenderer::new(gpu, &mut lib, &studio)?;
    env.render_image(&models, &EnvSettings::default(), 3 * size, size, spp)?
        .save(out.join("environment.png"))?;
    println!(
        "wrote {}/lit_sphere.png and environment.png ({spp} spp)",
        out.display()
    );
    Ok(())
}
