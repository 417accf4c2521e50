//! `bv tabulate`: samples any model into a MERL-layout `.binary` table
//!, so that users can build tables and tests can build
//! realistic full-size files.

use super::output::{print, warn};
use super::params::ModelArgs;
use anyhow::{Context as _, Result};
use bv_core::measured::merl::{self, MerlDims};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `bv tabulate`.
#[derive(Debug, Clone, clap::Args)]
pub struct TabulateArgs {
    /// The model and its parameters (`-m`/`--model`, `--preset`,
    /// `-p`/`--param`, as every sub-command takes them).
    #[command(flatten)]
    pub model: ModelArgs,
    /// Output file (see --help for what happens to an existing one).
    #[arg(long, value_name = "FILE.binary", long_help = super::output::OUT_HELP)]
    pub out: PathBuf,
    /// Cells along θh, θd, φd: each 1 to 4096, at most 16777216 cells (a
    /// 384 MiB file).
    #[arg(long, default_value = "90,90,180", value_name = "NθH,NθD,NΦD")]
    pub dims: String,
}

/// Runs `bv tabulate`.
pub fn run(args: &TabulateArgs) -> Result<()> {
    let dims = MerlDims::parse(&args.dims).context("--dims")?;
    let spec = args.model.spec()?;
    let brdf = spec.build()?;
    if !brdf.claims().isotropic {
        warn(&format!(
            "`{}` is anisotropic; the MERL layout has no φh axis, so the table holds its φh = 0 slice",
            spec.id()
        ));
    }
    if !brdf.deltas(glam::DVec3::Z).is_empty() {
        warn(&format!(
            "`{}` has delta lobes, which a table cannot hold (they tabulate as 0)",
            spec.id()
        ));
    }
    let work = super::budget::Work {
        serial: 0,
        parallel: dims.cells() as u64,
        threads: rayon::current_num_threads(),
    };
    super::budget::start(brdf.as_ref(), "bv tabulate", work, super::budget::LONG)?;
    let start = Instant::now();
    let table = merl::tabulate(brdf.as_ref(), dims)?;
    super::budget::finish(brdf.as_ref(), "tabulate")?;
    let tab_s = start.elapsed().as_secs_f64();
    for w in table.warnings().messages() {
        warn(&w);
    }
    table.write(&args.out)?;
    print(&format!(
        "wrote {}: {} {}, dims {} ({} bytes), tabulated in {:.2} s\n",
        args.out.display(),
        spec.id(),
        spec.params().to_json(),
        dims,
        dims.file_len(),
        tab_s
    ))
}
