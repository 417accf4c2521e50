//! `bv render`: figures without a window. Any view of the registry
//! drawn offscreen by the viewer's own code (wgpu; lavapipe on a server) to
//! PNG, the 2D plots to SVG, the lobe to OBJ/PLY; `--view all` writes one file
//! per view into a folder, with a progress bar on stderr.

use super::params::spec_from_cli;
use crate::export::files::{self, Kind};
use crate::export::{self, Frame, Offscreen};
use crate::session::deck;
use crate::session::lighting::MAX_TARGET_SPP;
use crate::session::scene_file as scene;
use crate::session::state::{AppState, Incident, Theme};
use crate::session::views::ALIASES;
use crate::views::{REGISTRY, ViewEntry};
use anyhow::{Context as _, Result, bail};
use bv_core::error::quote;
use eframe::egui::Vec2;
use std::io::{IsTerminal, Write as _};
use std::path::{Path, PathBuf};

/// Options of `bv render`.
#[derive(Debug, Clone, clap::Args)]
#[command(
    long_about = "Draw a view to a file without opening a window: the viewer's own \
    drawing code, rendered offscreen with wgpu (on a machine without a GPU, Mesa's lavapipe: \
    apt install mesa-vulkan-drivers libvulkan1).\n\n\
    The output's extension picks the format: .png (any view), .svg (2D plots: polar, \
    cartesian, albedo, fresnel, snell, terms), .obj or .ply (the lobe's mesh, for Blender). With --view all, \
    --out is a folder and gets one <view>.png per view (and <view>.svg for the 2D plots with \
    --svg).\n\n\
    Example (every figure of a lecture, one shell loop):\n  \
    for m in lambert phong ward cook-torrance; do\n    \
    bv render --model $m --view all --theta-i 45 --out figs/$m --svg\n  \
    done\n\n\
    With --deck FILE, --out is a folder and gets one numbered PNG per scene of the \
    lecture deck (01-diffuse.png, …), 1920×1080 unless --width/--height say otherwise: \
    the whole window in presentation mode, title band and view strip included, as \
    `bv --deck FILE` shows it in a window of that size."
)]
pub struct RenderArgs {
    /// Scene file to draw (TOML: BRDFs, light, camera, display options).
    #[arg(long, value_name = "FILE", conflicts_with = "deck")]
    pub scene: Option<PathBuf>,

    /// A lecture deck: write every scene as a numbered PNG into the folder
    /// --out, drawn as presentation mode shows it.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["model", "params", "view", "scale", "svg", "transparent"])]
    pub deck: Option<PathBuf>,

    /// Draw this model (replaces the scene's BRDFs; default: the scene's, or
    /// the first model of the catalogue).
    #[arg(short, long, value_name = "ID")]
    pub model: Option<String>,

    /// Draw this material preset (its model and parameters, named after it;
    /// replaces the scene's BRDFs), e.g. `--preset Gold`; `--param` values
    /// apply on top.
    #[arg(long, value_name = "NAME", conflicts_with = "model")]
    pub preset: Option<String>,

    /// A parameter of --model, repeatable: `--param alpha=0.3`, a colour as
    /// `--param kd=0.2,0.5,0.8`.
    #[arg(short, long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,

    /// The view: lobe3d (or lobe), polar, cartesian, albedo, fresnel, any other
    /// view of this build (the error for an unknown one lists them), `all`, or
    /// `window` (the whole viewer window, panels included).
    #[arg(long, value_name = "VIEW", required_unless_present = "deck")]
    pub view: Option<String>,

    /// Polar angle of the light, degrees: 0..89.5 above the surface, 90.5..180
    /// below it (light inside a transmitting model's medium; the horizon band
    /// is refused).
    #[arg(long = "theta-i", value_name = "DEG", allow_negative_numbers = true)]
    pub theta_i: Option<f64>,

    /// Azimuth of the light, degrees.
    #[arg(long = "phi-i", value_name = "DEG", allow_negative_numbers = true)]
    pub phi_i: Option<f64>,

    /// Image width in pixels (default 1600; 1920 with --deck).
    #[arg(long)]
    pub width: Option<u32>,

    /// Image height in pixels (default 1200; 1080 with --deck).
    #[arg(long)]
    pub height: Option<u32>,

    /// Pixels per point: the size of text and lines (default: width / 800,
    /// between 1 and 4, so a 1600-pixel figure reads like the 800-point view
    /// on a 2× screen).
    #[arg(long, value_name = "S")]
    pub scale: Option<f32>,

    /// Samples per pixel of the environment view, honoured exactly, in every
    /// environment scene of a --deck too (default: the scene's target; on a
    /// software renderer such as lavapipe at most 2²⁷ samples in all, between
    /// 32 and 256 per pixel: 64 at 1600×1200 and 1920×1080, where
    /// --spp 256 gives a cleaner image in four times the time).
    #[arg(long, value_name = "N")]
    pub spp: Option<u32>,

    /// Transparent background (PNG and SVG).
    #[arg(long)]
    pub transparent: bool,

    /// Light theme (dark text on white: slides, print).
    #[arg(long, conflicts_with = "dark")]
    pub light: bool,

    /// Dark theme.
    #[arg(long)]
    pub dark: bool,

    /// Logarithmic scale.
    #[arg(long)]
    pub log: bool,

    /// Show f · cos θo.
    #[arg(long)]
    pub cosine: bool,

    /// With --view all: also write SVG for the 2D plots.
    #[arg(long)]
    pub svg: bool,

    /// Write a caption under each view's figure: every drawn BRDF with its
    /// model and parameters, and the light's direction.
    #[arg(long)]
    pub caption: bool,

    /// Output file (or folder with --view all).
    #[arg(short, long, value_name = "PATH")]
    pub out: PathBuf,
}

/// The list of view names for messages.
pub fn view_names() -> String {
    let mut names: Vec<String> = REGISTRY
        .iter()
        .map(|e| {
            let aliases: Vec<&str> = ALIASES
                .iter()
                .filter(|(_, id)| *id == e.id)
                .map(|(a, _)| *a)
                .collect();
            if aliases.is_empty() {
                e.id.to_string()
            } else {
                format!("{} (or {})", e.id, aliases.join(", "))
            }
        })
        .collect();
    names.push("all".into());
    names.push("window".into());
    names.join(", ")
}

/// The views `name` stands for.
pub fn views_for(name: &str) -> Result<Vec<&'static ViewEntry>> {
    if name.trim().eq_ignore_ascii_case("all") {
        return Ok(REGISTRY.iter().collect());
    }
    match crate::views::find_view(name) {
        Some(e) => Ok(vec![e]),
        None => bail!(
            "--view {name}: no such view in this build; available: {}",
            view_names()
        ),
    }
}

/// The state to draw: the scene (or defaults), with the command line's
/// changes on top.
pub fn state_for(a: &RenderArgs) -> Result<AppState> {
    let state = match &a.scene {
        Some(p) => {
            let loaded = scene::load(p).map_err(|e| match e {
                // It names the file already.
                scene::SceneError::File(e) => anyhow::anyhow!("--scene {e}"),
                e => anyhow::Error::new(e).context(format!("--scene {}", p.display())),
            })?;
            for w in &loaded.warnings {
                super::output::eprint(&format!("bv render: {}: {w}\n", p.display()));
            }
            loaded.state
        }
        None if a.model.is_none() && a.preset.is_none() => AppState::first_run(),
        None => AppState::default(),
    };
    apply_args(a, state)
}

/// `state` with the command line's changes on top (model or preset, light,
/// theme, samples, display options), sanitised: what `bv render --scene
/// FILE …` draws once the file is read. The Python module's
/// `bv.render(scene, …)` gives it a scene held in memory.
pub fn apply_args(a: &RenderArgs, mut state: AppState) -> Result<AppState> {
    if let Some(p) = &a.preset {
        let spec = super::params::preset_spec_from_cli(p, &a.params)?;
        let name = super::params::find_preset(p)?.name.clone();
        state.brdfs.clear();
        state.solo = None;
        state.add_named(spec, Some(name));
    } else if let Some(m) = &a.model {
        let spec = spec_from_cli(m, &a.params)?;
        state.brdfs.clear();
        state.solo = None;
        state.add(spec);
    } else if !a.params.is_empty() {
        bail!("--param needs --model or --preset");
    }
    let mut inc = state.incident;
    if let Some(t) = a.theta_i {
        if !(t.is_finite() && (0.0..=Incident::MAX_THETA_DEG).contains(&t)) {
            bail!(
                "--theta-i {t}: out of range 0..={}°",
                Incident::MAX_THETA_DEG
            );
        }
        if Incident::in_horizon_gap(t) {
            bail!("--theta-i {t}: {}", Incident::horizon_reason(t));
        }
        inc.theta_deg = t;
    }
    if let Some(p) = a.phi_i {
        if !p.is_finite() {
            bail!("--phi-i {p}: not a finite angle");
        }
        inc.phi_deg = p;
    }
    state.incident = inc.clamped();
    apply_looks(a, &mut state)?;
    state.display.caption |= a.caption;
    state.maximised = None;
    Ok(state.sanitised())
}

/// The options that change how a state is drawn, not what: `--light` or
/// `--dark`, `--log`, `--cosine`, and `--spp N` (the environment view's
/// target and its figures' exact count; a figure on a software renderer
/// otherwise keeps to a sample budget,
/// [`crate::views::environment::figure_spp`]). A single view and every
/// scene of a deck take them alike.
fn apply_looks(a: &RenderArgs, state: &mut AppState) -> Result<()> {
    if a.light {
        state.theme = Theme::Light;
    }
    if a.dark {
        state.theme = Theme::Dark;
    }
    state.display.log |= a.log;
    state.display.cosine |= a.cosine;
    if let Some(n) = a.spp {
        if !(1..=MAX_TARGET_SPP).contains(&n) {
            bail!("--spp {n}: expected 1..={MAX_TARGET_SPP} samples per pixel");
        }
        state.lighting.env.target_spp = n;
        state.lighting.env.figure_spp = Some(n);
    }
    Ok(())
}

fn kind_of(path: &Path) -> Result<Kind> {
    match Kind::of(path) {
        Some(k) => Ok(k),
        None => bail!(
            "--out {}: the extension picks the format: .png, .svg (2D plots), .obj or .ply (lobe mesh)",
            path.display()
        ),
    }
}

/// A progress bar on stderr (a line per step when stderr is not a terminal).
struct Progress {
    total: usize,
    tty: bool,
}

impl Progress {
    fn step(&self, done: usize, what: &str) {
        let mut err = std::io::stderr().lock();
        if self.tty {
            let width = 24;
            let filled = width * done / self.total.max(1);
            let _ = write!(
                err,
                "\r\x1b[2Kbv render [{}{}] {done}/{} {what}",
                "#".repeat(filled),
                ".".repeat(width - filled),
                self.total
            );
            if done == self.total {
                let _ = writeln!(err);
            }
        } else {
            let _ = writeln!(err, "bv render: [{done}/{}] {what}", self.total);
        }
        let _ = err.flush();
    }
}

/// The image size `a` asks for, checked.
fn size_of(a: &RenderArgs) -> Result<[u32; 2]> {
    let default_size = if a.deck.is_some() {
        [1920, 1080]
    } else {
        [1600, 1200]
    };
    let width = a.width.unwrap_or(default_size[0]);
    let height = a.height.unwrap_or(default_size[1]);
    if width == 0 || height == 0 {
        bail!("--width {width} --height {height}: an image needs at least one pixel each way");
    }
    let max = export::offscreen::MAX_SIDE;
    if width > max || height > max {
        bail!("--width {width} --height {height}: at most {max} pixels on a side");
    }
    Ok([width, height])
}

/// The pixels per point `a` asks for (default: width / 800 within 1..4).
fn scale_of(a: &RenderArgs, width: u32) -> Result<f32> {
    let scale = a
        .scale
        .unwrap_or_else(|| (width as f32 / 800.0).clamp(1.0, 4.0));
    if !(scale.is_finite() && (0.25..=8.0).contains(&scale)) {
        bail!("--scale {scale}: expected 0.25..=8");
    }
    Ok(scale)
}

/// One view (`--view`, not `all` or `window`) of the state `a` describes as
/// an RGBA image, with `spec` (when given) as its only BRDF: what `bv
/// render --view V --out F.png` writes, for the Python module's
/// `bv.render`.
pub fn view_image(a: &RenderArgs, spec: Option<bv_core::ModelSpec>) -> Result<image::RgbaImage> {
    let e = one_view(a)?;
    let mut state = state_for(a)?;
    if let Some(spec) = spec {
        state.brdfs.clear();
        state.solo = None;
        state.add(spec);
        state = state.sanitised();
    }
    draw_view(a, e, &state)
}

/// One view (`--view`) of the scene `scene` (all its BRDFs, its light and
/// display options) with `a`'s changes on top ([`apply_args`]) as an RGBA
/// image: what `bv render --scene FILE --view V --out F.png` writes for
/// that scene's file, for the Python module's `bv.render(scene, …)`.
pub fn scene_image(a: &RenderArgs, scene: AppState) -> Result<image::RgbaImage> {
    let e = one_view(a)?;
    let state = apply_args(a, scene)?;
    draw_view(a, e, &state)
}

/// The single view `a.view` names (not `all` or `window`), with the size
/// and scale checked.
fn one_view(a: &RenderArgs) -> Result<&'static ViewEntry> {
    let [width, _] = size_of(a)?;
    let view = a.view.as_deref().unwrap_or_default();
    if view.trim().eq_ignore_ascii_case("all") || view.trim().eq_ignore_ascii_case("window") {
        bail!("view {view:?}: one view of this build (lobe3d, polar, cartesian, albedo, …)");
    }
    let e = views_for(view)?[0];
    scale_of(a, width)?;
    Ok(e)
}

/// Draws the view `e` of `state` offscreen at `a`'s size and scale.
fn draw_view(a: &RenderArgs, e: &ViewEntry, state: &AppState) -> Result<image::RgbaImage> {
    let [width, height] = size_of(a)?;
    let scale = scale_of(a, width)?;
    let frame = Frame {
        size: Vec2::new(width as f32 / scale, height as f32 / scale),
        pixels_per_point: scale,
        dark: export::is_dark(state),
        transparent: a.transparent,
    };
    let mut off = open_device(frame)?;
    export::render_view(&mut off, state, e, frame)
        .with_context(|| format!("drawing the {} view", e.id))
}

/// Runs `bv render`.
pub fn run(a: &RenderArgs, shell: &super::Shell) -> Result<()> {
    let [width, height] = size_of(a)?;
    if let Some(deck) = &a.deck {
        return render_deck(a, deck, [width, height], shell.slide);
    }
    let view = a.view.as_deref().unwrap_or_default();
    let window = view.trim().eq_ignore_ascii_case("window");
    let views = if window { Vec::new() } else { views_for(view)? };
    let all = !window && (views.len() > 1 || view.trim().eq_ignore_ascii_case("all"));
    let scale = scale_of(a, width)?;
    let state = state_for(a)?;
    let frame = Frame {
        size: Vec2::new(width as f32 / scale, height as f32 / scale),
        pixels_per_point: scale,
        dark: export::is_dark(&state),
        transparent: a.transparent,
    };

    if window {
        if kind_of(&a.out)? != Kind::Png {
            bail!("--view window: only PNG (--out FILE.png)");
        }
        let mut off = open_device(frame)?;
        return files::write_window_png(&mut off, &state, frame, (shell.window)(&state), &a.out);
    }
    if !all {
        let e = views[0];
        let kind = kind_of(&a.out)?;
        return match kind {
            Kind::Png => {
                let mut off = open_device(frame)?;
                files::write_view_png(&mut off, &state, e, frame, &a.out)
            }
            Kind::Svg => files::write_view_svg(&state, e, svg_size(frame), a.transparent, &a.out),
            Kind::Obj | Kind::Ply => {
                if e.id != crate::session::views::LOBE.id {
                    bail!(
                        "--out {}: meshes come from the lobe view (--view lobe3d)",
                        a.out.display()
                    );
                }
                files::write_mesh(&state, kind == Kind::Ply, &a.out).map(|_| ())
            }
        };
    }

    // --view all: a folder of PNGs (and SVGs).
    if matches!(Kind::of(&a.out), Some(Kind::Png | Kind::Svg)) {
        bail!(
            "--view all writes one file per view: --out must be a folder, not {}",
            a.out.display()
        );
    }
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("cannot create the folder {}", a.out.display()))?;
    let svg_views: Vec<&ViewEntry> = if a.svg {
        let vector = files::svg_views();
        views
            .iter()
            .copied()
            .filter(|e| vector.iter().any(|v| v.id == e.id))
            .collect()
    } else {
        Vec::new()
    };
    let progress = Progress {
        total: views.len() + svg_views.len(),
        tty: std::io::stderr().is_terminal(),
    };
    let mut off = open_device(frame)?;
    let mut done = 0;
    progress.step(done, "starting");
    for e in &views {
        let path = a.out.join(format!("{}.png", e.id));
        files::write_view_png(&mut off, &state, e, frame, &path)?;
        done += 1;
        progress.step(done, &path.display().to_string());
    }
    for e in &svg_views {
        let path = a.out.join(format!("{}.svg", e.id));
        files::write_view_svg(&state, e, svg_size(frame), a.transparent, &path)?;
        done += 1;
        progress.step(done, &path.display().to_string());
    }
    Ok(())
}

/// `bv render --deck`: every slide of the deck as `NN-title.png` in the
/// folder `--out`, drawn as presentation mode draws a window of `pixels`
/// (the same scale, bands and strip: see `session::presentation`).
fn render_deck(
    a: &RenderArgs,
    path: &Path,
    [width, height]: [u32; 2],
    make: export::MakeSlide,
) -> Result<()> {
    let loaded = deck::load(path, scene::Builds::Required).map_err(|e| match e {
        // It names the file already.
        deck::DeckError::File(e) => anyhow::anyhow!("--deck {e}"),
        e => anyhow::Error::new(e).context(format!("--deck {}", path.display())),
    })?;
    for w in &loaded.warnings {
        super::output::eprint(&format!("bv render: {}: {w}\n", path.display()));
    }
    let mut d = loaded.deck;
    for s in &mut d.slides {
        apply_looks(a, &mut s.state)?;
    }
    if Kind::of(&a.out).is_some() {
        bail!(
            "--deck writes one PNG per scene: --out must be a folder, not {}",
            a.out.display()
        );
    }
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("cannot create the folder {}", a.out.display()))?;
    let scale = crate::session::presentation::scale_for([width as f32, height as f32]);
    let size = Vec2::new(width as f32 / scale, height as f32 / scale);
    let progress = Progress {
        total: d.slides.len(),
        tty: std::io::stderr().is_terminal(),
    };
    let mut off: Option<Offscreen> = None;
    progress.step(0, "starting");
    for (i, s) in d.slides.iter().enumerate() {
        let frame = Frame {
            size,
            pixels_per_point: scale,
            dark: export::is_dark(&s.state),
            transparent: false,
        };
        let off = match &mut off {
            Some(o) => o,
            None => off.insert(open_device(frame)?),
        };
        let digits = d.slides.len().to_string().len().max(2);
        let file = a
            .out
            .join(format!("{:0digits$}-{}.png", i + 1, deck::slug(&s.title)));
        let title = quote(&s.title);
        files::write_window_png(off, &s.state, frame, make(&d, i), &file)
            .with_context(|| format!("drawing scene {} (\"{title}\")", i + 1))?;
        progress.step(i + 1, &file.display().to_string());
    }
    Ok(())
}

/// Opens the headless device and checks that it can draw images of
/// `frame`'s size (its largest texture side), naming the options to change.
fn open_device(frame: Frame) -> Result<Offscreen> {
    let off = Offscreen::headless()?;
    let [w, h] = frame.pixels();
    let max = off.max_side();
    if w > max || h > max {
        bail!(
            "an image of {w}×{h} pixels: this device ({}) draws at most {max} pixels on a side; \
             use a smaller --width/--height (or --scale)",
            off.describe()
        );
    }
    Ok(off)
}

/// The size of a view's SVG in points: the frame less its margins (what
/// the PNG of the same frame draws the view in).
fn svg_size(frame: Frame) -> [f32; 2] {
    [
        frame.size.x - 2.0 * export::FIGURE_MARGIN,
        frame.size.y - 2.0 * export::FIGURE_MARGIN,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_views_list_the_available_ones() {
        let e = match views_for("lit-spheer") {
            Ok(_) => panic!("accepted"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains("lit-spheer") && e.contains("polar") && e.contains("all"),
            "{e}"
        );
        assert_eq!(views_for("lobe3d").unwrap()[0].id, "lobe");
        assert_eq!(views_for("all").unwrap().len(), REGISTRY.len());
    }

    #[test]
    fn extensions_pick_the_format() {
        assert_eq!(kind_of(Path::new("a.PNG")).unwrap(), Kind::Png);
        assert_eq!(kind_of(Path::new("a.ply")).unwrap(), Kind::Ply);
        assert!(kind_of(Path::new("a.jpg")).is_err());
    }
}
