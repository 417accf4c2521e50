//! Writes the procedural studio environment shipped as `assets/studio.hdr`
//! (256×128, Radiance RGBE), so that the environment view works on a fresh
//! machine: `cargo run --example make_studio [-- PATH [WIDTH HEIGHT]]`.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::gpu::EnvironmentMap;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .unwrap_or_else(|| "assets/studio.hdr".to_string());
    let width: u32 = args.next().map_or(Ok(256), |s| s.parse())?;
    let height: u32 = args.next().map_or(Ok(128), |s| s.parse())?;
    EnvironmentMap::studio(width, height).save_hdr(std::path::Path::new(&path))?;
    println!("wrote {path} ({width}×{height})");
    Ok(())
}
