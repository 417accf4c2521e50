//! `bv tabulate`: samples any model into a MERL-layout `.binary` table, or
//! (`--format rgl`) writes it as an isotropic RGB RGL `.bsdf` material
//! (Dupuy & Jakob 2018; the writer is bv-core's `measured::rgl_write`), so
//! that users can build tables, share a model with Mitsuba 3's `measured`
//! plugin, and tests can build realistic files.

use super::output::{print, warn};
use super::params::ModelArgs;
use anyhow::{Context as _, Result};
use bv_core::measured::merl::{self, MerlDims};
use bv_core::measured::rgl_write::{self, RglWriteOptions};
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
    /// File format: `merl` (a `.binary` half/difference table) or `rgl` (an
    /// isotropic RGB `.bsdf` tensor file: 16 θi up to 85°, NDF and σ on 128
    /// nodes, VNDF 128², values 32²; `--dims` does not apply).
    #[arg(long, value_enum, default_value_t = TableFormat::Merl)]
    pub format: TableFormat,
    /// The `description` field of an RGL file (default: the model spec).
    #[arg(long)]
    pub description: Option<String>,
}

/// The file formats `bv tabulate` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TableFormat {
    /// A MERL `.binary` half/difference-angle table.
    Merl,
    /// An isotropic RGB RGL `.bsdf` tensor file.
    Rgl,
}

/// Runs `bv tabulate`.
pub fn run(args: &TabulateArgs) -> Result<()> {
    if args.format == TableFormat::Rgl {
        return run_rgl(args);
    }
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

/// `bv tabulate --format rgl`.
fn run_rgl(args: &TabulateArgs) -> Result<()> {
    let spec = args.model.spec()?;
    let brdf = spec.build()?;
    if !brdf.claims().isotropic {
        warn(&format!(
            "`{}` is anisotropic; the file is isotropic (φi = 0 slice, relative azimuths kept)",
            spec.id()
        ));
    }
    if !brdf.deltas(glam::DVec3::Z).is_empty() {
        warn(&format!(
            "`{}` has delta lobes, which a table cannot hold (they tabulate as 0)",
            spec.id()
        ));
    }
    let opts = RglWriteOptions {
        description: args
            .description
            .clone()
            .unwrap_or_else(|| format!("bv: {} {}", spec.id(), spec.params().to_json())),
        ..RglWriteOptions::default()
    };
    let work = super::budget::Work {
        serial: (opts.theta_i * (opts.vndf * opts.vndf + opts.values * opts.values)) as u64,
        parallel: 0,
        threads: 1,
    };
    super::budget::start(brdf.as_ref(), "bv tabulate", work, super::budget::LONG)?;
    let start = Instant::now();
    let bytes = rgl_write::tabulate_rgl(brdf.as_ref(), &opts)
        .with_context(|| format!("writing `{}` as an RGL file", spec.id()))?;
    super::budget::finish(brdf.as_ref(), "tabulate")?;
    let tab_s = start.elapsed().as_secs_f64();
    bv_core::fsio::write_atomic(&args.out, |w| w.write_all(&bytes))?;
    print(&format!(
        "wrote {}: {} {} as an RGL material ({} θi, VNDF {}², values {}², {} bytes), tabulated in {:.2} s\n",
        args.out.display(),
        spec.id(),
        spec.params().to_json(),
        opts.theta_i,
        opts.vndf,
        opts.values,
        bytes.len(),
        tab_s
    ))
}
