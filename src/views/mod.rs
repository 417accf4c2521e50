//! The viewer's views: the 3D polar lobe, the lit sphere, the polar plot of
//! the plane of incidence, the Cartesian plot, the environment-lit object,
//! the directional albedo, the Fresnel curves and the image slice in
//! half/difference angles. Each is a struct with its own `ui()`; they read
//! one [`Scene`] per frame and ask for changes by pushing [`Command`]s. A view
//! is added by writing its module and one line in [`REGISTRY`]; the window,
//! screenshots and `bv render` all go through the registry. A view with its
//! own wgpu pipeline also adds one field to [`GpuResources`]; one that renders
//! into a texture of its own finds egui's render state through its context
//! ([`install_context`]).

pub mod albedo;
pub mod camera;
pub mod cartesian;
pub mod chart;
pub mod colormap;
pub mod curves;
pub mod environment;
pub mod factor;
pub mod factor_overlay;
pub mod fonts;
pub mod fresnel;
pub mod gonio_overlay;
pub mod gpu_image;
pub mod hemi;
pub mod image_slice;
pub mod lit_sphere;
pub mod lobe3d;
pub mod lobe_gpu;
pub mod microsurface;
pub mod polar;
pub mod reciprocity;
pub mod sampling;
pub mod sh_overlay;
pub mod snell;
pub mod svg;
pub mod terms;
pub mod vgroove;

use crate::session::command::Command;
pub use crate::session::frame::{Scene, SceneBrdf};
use crate::session::views;
use eframe::egui::{self, Color32, Ui};
use std::any::Any;

/// A drawn BRDF's display colour as egui draws it.
pub trait BrdfColor {
    /// The colour of its curves, legend entries and meshes.
    fn color(&self) -> Color32;
}

impl BrdfColor for SceneBrdf {
    fn color(&self) -> Color32 {
        let [r, g, b] = self.rgb;
        Color32::from_rgb(r, g, b)
    }
}

/// A view of the scene.
pub trait View: Any {
    /// Widgets in the view's header bar (toggles).
    fn toolbar(&mut self, _ui: &mut Ui, _scene: &Scene<'_>, _out: &mut Vec<Command>) {}

    /// Draws the view into the whole of `ui`'s available rectangle.
    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>);

    /// For tests and drivers that need the concrete view.
    fn as_any(&self) -> &dyn Any;

    /// Whether the view is still working on what it showed in the last frame
    /// (building a renderer, sampling towards its target): screenshots and
    /// figures wait for it.
    fn busy(&self) -> bool {
        false
    }

    /// An error the view showed in its image (an environment map that did not
    /// load, a renderer that failed, a BRDF the GPU cannot draw): a figure must
    /// not carry an error message in its pixels.
    fn figure_error(&self) -> Option<String> {
        None
    }

    /// The view as an SVG document of `size` points (2D plots only; `None`
    /// for views that have no vector form). Same data, colours and labels as
    /// [`View::ui`] draws.
    fn svg(&mut self, _scene: &Scene<'_>, _size: [f32; 2], _dark: bool) -> Option<String> {
        None
    }

    /// Whether the view has something to show with the light below the
    /// surface when no drawn BRDF transmits (the Snell view draws either
    /// side of its interface). Default: no, and [`show`] puts
    /// [`light_below_note`] in its place.
    fn shows_light_below(&self) -> bool {
        false
    }
}

/// The interface whose optics the views mark (refracted ray, critical
/// angle, Snell's window): the selected BRDF if it transmits and reports an
/// index ([`bv_core::Brdf::interface_eta`]), else the first drawn one that
/// does; its label and `η`.
pub fn interface_model(scene: &Scene<'_>) -> Option<(String, f64)> {
    let with_eta = |b: &&SceneBrdf| b.brdf.transmits() && b.brdf.interface_eta().is_some();
    let b = scene
        .brdfs
        .iter()
        .filter(with_eta)
        .find(|b| b.selected)
        .or_else(|| scene.brdfs.iter().find(with_eta))?;
    Some((b.label.clone(), b.brdf.interface_eta()?))
}

/// Why a view shows nothing of the scene: the light is below the surface
/// (θi > 90°, issue 33) and every drawn BRDF reflects only (0 for light from
/// below by convention). `None` when the view can draw.
pub fn light_below_note(scene: &Scene<'_>) -> Option<String> {
    if !scene.incident.below()
        || scene.brdfs.is_empty()
        || scene.brdfs.iter().any(|b| b.brdf.transmits())
    {
        return None;
    }
    Some(format!(
        "Light below the surface (θi = {:.1}°): no drawn BRDF transmits, so nothing \
         scatters. Bring θi under 90° or add a model that transmits.",
        scene.incident.theta_deg
    ))
}

/// Draws `view`, or in its place the note of [`light_below_note`] where the
/// view has nothing to show (never a blank or a plot of zeros).
pub fn show(view: &mut dyn View, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
    if !view.shows_light_below()
        && let Some(note) = light_below_note(scene)
    {
        // Wrapped at the view's width, from the top: readable in the
        // smallest cell of the grid.
        ui.add_space(8.0);
        ui.add(egui::Label::new(egui::RichText::new(note).color(strong_text(ui))).wrap());
        return;
    }
    view.ui(ui, scene, out);
}

/// A registered view: its name (from the session's list of views) and its
/// constructor.
pub struct ViewEntry {
    /// Stable id (saved as the maximised view, used by shortcuts).
    pub id: &'static str,
    /// Title in the view's header.
    pub title: &'static str,
    /// Whether the window's overview grid shows it (see
    /// [`crate::session::views::ViewInfo::in_grid`]).
    pub in_grid: bool,
    /// Creates the view.
    pub make: fn() -> Box<dyn View>,
}

/// A view's constructor.
type MakeView = fn() -> Box<dyn View>;

/// Each view's constructor, by the view it draws (its id is spelled once,
/// in [`crate::session::views`]). Add a view here and in
/// [`crate::session::views::VIEWS`].
const CONSTRUCTORS: &[(views::ViewInfo, MakeView)] = &[
    (views::LOBE, || Box::new(lobe3d::Lobe3dView::new())),
    (views::LIT_SPHERE, || {
        Box::new(lit_sphere::LitSphereView::new())
    }),
    (views::POLAR, || Box::new(polar::PolarView::default())),
    (views::CARTESIAN, || {
        Box::new(cartesian::CartesianView::default())
    }),
    (views::ENVIRONMENT, || {
        Box::new(environment::EnvironmentView::new())
    }),
    (views::ALBEDO, || Box::new(albedo::AlbedoView::default())),
    (views::FRESNEL, || Box::new(fresnel::FresnelView::default())),
    (views::SLICE, || {
        Box::new(image_slice::ImageSliceView::default())
    }),
    (views::RECIPROCITY, || {
        Box::new(reciprocity::ReciprocityView::default())
    }),
    (views::SNELL, || Box::new(snell::SnellView::default())),
    (views::TERMS, || Box::new(terms::TermsView::default())),
    (views::SAMPLING, || {
        Box::new(sampling::SamplingView::default())
    }),
    (views::FACTOR, || Box::new(factor::FactorView::default())),
    (views::MICROSURFACE, || {
        Box::new(microsurface::MicrosurfaceView::default())
    }),
    (views::HEMI, || Box::new(hemi::HemiView::default())),
];

/// The constructor of the view `v`.
fn make(v: &views::ViewInfo) -> Option<fn() -> Box<dyn View>> {
    CONSTRUCTORS
        .iter()
        .find(|(c, _)| c == v)
        .map(|(_, make)| *make)
}

/// Every view, in the session's layout order (see
/// [`crate::session::views::VIEWS`]; a view without a constructor is
/// skipped, which a test forbids).
pub static REGISTRY: std::sync::LazyLock<Vec<ViewEntry>> = std::sync::LazyLock::new(|| {
    views::VIEWS
        .iter()
        .filter_map(|v| {
            Some(ViewEntry {
                id: v.id,
                title: v.title,
                in_grid: v.in_grid,
                make: make(v)?,
            })
        })
        .collect()
});

/// The registry entry with id `id`.
pub fn entry(id: &str) -> Option<&'static ViewEntry> {
    REGISTRY.iter().find(|v| v.id == id)
}

/// The registry entry with id or alias `name` (case-insensitive).
pub fn find_view(name: &str) -> Option<&'static ViewEntry> {
    views::find(name).and_then(|v| entry(v.id))
}

/// The GPU resources of every view with its own pipeline, made on a device
/// before they are put into a renderer's paint-callback resources
/// ([`GpuResources::install`]), so that their shaders compile while the
/// caller goes on (an offscreen renderer makes egui's renderer meanwhile).
pub struct GpuResources {
    lobe: Option<crate::gpu::lobe::LobeRenderer>,
}

impl GpuResources {
    /// Makes (and primes) the views' pipelines for passes of
    /// `target_format`.
    pub fn new(
        device: &eframe::wgpu::Device,
        queue: &eframe::wgpu::Queue,
        adapter: Option<&eframe::wgpu::Adapter>,
        target_format: eframe::wgpu::TextureFormat,
    ) -> Self {
        // wgpu's default answer to an error outside an error scope is a
        // panic; bv records it and shows it instead.
        crate::gpu::errors::watch(device);
        Self {
            lobe: lobe_gpu::renderer(device, queue, adapter, target_format),
        }
    }

    /// Puts them into a renderer's paint-callback resources.
    pub fn install(self, resources: &mut eframe::egui_wgpu::CallbackResources) {
        if let Some(lobe) = self.lobe {
            resources.insert(lobe);
        }
    }
}

/// Installs the GPU resources of every view with its own pipeline into a
/// renderer's paint-callback resources (eframe's window, a test harness):
/// [`GpuResources::new`] then [`GpuResources::install`]. `target_format` is
/// the format of the pass the views paint into.
pub fn install_gpu(
    resources: &mut eframe::egui_wgpu::CallbackResources,
    device: &eframe::wgpu::Device,
    queue: &eframe::wgpu::Queue,
    adapter: Option<&eframe::wgpu::Adapter>,
    target_format: eframe::wgpu::TextureFormat,
) {
    GpuResources::new(device, queue, adapter, target_format).install(resources);
}

/// The label of the value the views show.
pub fn value_label(cosine: bool) -> &'static str {
    if cosine { "f·cos θo" } else { "f" }
}

/// Convert an egui colour to sRGB 0..1 floats.
pub fn srgb_f32(c: Color32) -> [f32; 3] {
    [
        c.r() as f32 / 255.0,
        c.g() as f32 / 255.0,
        c.b() as f32 / 255.0,
    ]
}

/// A text colour that reads on the current background.
pub fn strong_text(ui: &Ui) -> Color32 {
    ui.visuals().strong_text_color()
}

/// The strong text colour of a theme, where no `Ui` is at hand (SVG).
pub fn strong_text_color(dark: bool) -> Color32 {
    if dark {
        Color32::from_gray(230)
    } else {
        Color32::from_gray(20)
    }
}

/// Marker colour of the light (ωi) in every view: a colour no BRDF of the
/// palette ([`crate::session::state::PALETTE`]) is drawn in, so that the
/// light is never mistaken for a curve (a test holds it apart from each).
/// Sun yellow on dark backgrounds; near-black on light ones, where yellow
/// does not read and orange is the second BRDF's colour.
pub fn light_color(dark: bool) -> Color32 {
    if dark {
        Color32::from_rgb(255, 235, 110)
    } else {
        Color32::from_rgb(35, 35, 35)
    }
}

/// Marker colour of the mirror direction in every view.
pub fn mirror_color(dark: bool) -> Color32 {
    if dark {
        Color32::from_rgb(200, 200, 200)
    } else {
        Color32::from_rgb(90, 90, 90)
    }
}

/// Whether a plot of `size` points has room for a legend of `entries` lines
/// (at most 40 % of its height, and a width a label fits in): in a small
/// grid cell a legend would cover the curves, and the panel's colour
/// swatches name them anyway. Maximised views and figures have room.
pub fn legend_fits(size: egui::Vec2, entries: usize) -> bool {
    entries as f32 * 18.0 + 12.0 <= 0.4 * size.y && size.x >= 280.0
}

/// `plot` with a legend in `corner` where [`legend_fits`].
pub fn with_legend(
    plot: egui_plot::Plot<'_>,
    size: egui::Vec2,
    entries: usize,
    corner: egui_plot::Corner,
) -> egui_plot::Plot<'_> {
    if legend_fits(size, entries) {
        plot.legend(egui_plot::Legend::default().position(corner))
    } else {
        plot
    }
}

/// How far (points) a plot's y-axis label may reach left of the rect the
/// plot is laid out in: egui_plot (0.38) draws the label rotated, starting a
/// quarter of a text row (its `AXIS_LABEL_GAP`) outside the plot, so a clip
/// rect at the view's edge cuts off the tops of its glyphs ("F
/// (reflectance)" read "⊢ (retlectance)"). Whoever clips a view leaves this
/// much room on its left (the grid's frames have it in their margin).
pub fn y_label_overhang(ui: &Ui) -> f32 {
    0.25 * ui.text_style_height(&egui::TextStyle::Body) + 1.0
}

/// Length (points) of the line sample in front of a [`side_legend`] label.
const LEGEND_SAMPLE: f32 = 26.0;

/// The width (points) a [`side_legend`] of `series` takes: the line sample
/// and the widest label at body size.
pub fn side_legend_width(ui: &Ui, series: &[chart::Series]) -> f32 {
    let font = egui::TextStyle::Body.resolve(ui.style());
    let widest = series
        .iter()
        .filter(|s| !s.label.is_empty())
        .map(|s| {
            ui.painter()
                .layout_no_wrap(s.label.clone(), font.clone(), Color32::WHITE)
                .size()
                .x
        })
        .fold(0.0, f32::max);
    LEGEND_SAMPLE + 3.0 * ui.spacing().item_spacing.x + widest
}

/// The room (points) a plot leaves beside it for a [`side_legend`] of
/// `legend` in a view `width` wide: none without entries, else the legend's
/// width (at most 0.4 of the view) and a gap.
pub fn side_legend_room(ui: &Ui, legend: &[chart::Series], width: f32) -> f32 {
    if legend.is_empty() {
        0.0
    } else {
        side_legend_width(ui, legend).min(0.4 * width) + ui.spacing().item_spacing.x
    }
}

/// Shows `plot` with `draw`, and `legend` in a column of `legend_w` points
/// to its right when it has entries (the polar and Cartesian views when
/// presenting).
pub fn show_with_side_legend<R>(
    ui: &mut Ui,
    plot: egui_plot::Plot<'_>,
    draw: impl FnOnce(&mut egui_plot::PlotUi<'_>) -> R,
    legend: &[chart::Series],
    scene: &Scene<'_>,
    legend_w: f32,
) -> egui_plot::PlotResponse<R> {
    if legend.is_empty() {
        return plot.show(ui, draw);
    }
    ui.horizontal_top(|ui| {
        let r = plot.show(ui, draw);
        ui.vertical(|ui| {
            ui.add_space(4.0);
            side_legend(ui, legend, scene, legend_w);
        });
        r
    })
    .inner
}

/// A legend drawn beside a plot rather than over it (presentation mode,
/// where the plots are short and egui_plot's legend either covered the
/// curves or was left out): per labelled series a sample of its line, in
/// its colour, width and dash, and its label in the text colour (legible
/// on the ground whatever the curve's colour).
/// `width` is the column's (from [`side_legend_width`], or less: a longer
/// label wraps).
pub fn side_legend(ui: &mut Ui, series: &[chart::Series], scene: &Scene<'_>, width: f32) {
    let text = strong_text(ui);
    ui.set_max_width(width);
    for s in series.iter().filter(|s| !s.label.is_empty()) {
        ui.horizontal_top(|ui| {
            let h = ui.text_style_height(&egui::TextStyle::Body);
            let (rect, _) =
                ui.allocate_exact_size(egui::vec2(LEGEND_SAMPLE, h), egui::Sense::hover());
            let y = rect.center().y;
            let ends = [egui::pos2(rect.left(), y), egui::pos2(rect.right(), y)];
            let stroke = egui::Stroke::new(scene.stroke(s.width), s.color);
            match s.dash {
                Some(d) => {
                    ui.painter()
                        .extend(egui::Shape::dashed_line(&ends, stroke, d, d * 0.8));
                }
                None => {
                    ui.painter().line_segment(ends, stroke);
                }
            }
            ui.add(egui::Label::new(egui::RichText::new(&s.label).color(text)).wrap());
        });
    }
}

/// `plot` without its hover readout and crosshair when presenting: the
/// presenter's pointer rests on the slide, and a crosshair with coordinates
/// where it happens to be would be read as part of the figure.
pub fn calm_hover<'a>(plot: egui_plot::Plot<'a>, scene: &Scene<'_>) -> egui_plot::Plot<'a> {
    if scene.presenting {
        plot.show_x(false).show_y(false).show_crosshair(false)
    } else {
        plot
    }
}

/// egui_plot's smallest grid spacing in points (`Plot::grid_spacing`'s
/// default minimum): its `GridInput::base_step_size` is this many points in
/// data units.
const PLOT_MIN_GRID_POINTS: f64 = 8.0;

/// Grid marks at `ticks` inside `bounds`, thinned to ones at least `gap`
/// points apart (the first and the last tick kept), each with a step size
/// spanning the whole axis. egui_plot fades a label whose step is closer
/// than its label spacing (60–80 points on x, 20–30 on y) and drops it below
/// that: presenting, that left the Fresnel plot's 15° ticks in a dim grey
/// and the term view's short plots with a lone "0" on their y axes. With
/// the whole span as step every kept label is drawn at full strength; the
/// thinning keeps them apart.
pub fn presented_marks(
    ticks: &[f64],
    bounds: (f64, f64),
    base_step: f64,
    gap: f64,
) -> Vec<egui_plot::GridMark> {
    let (lo, hi) = (bounds.0.min(bounds.1), bounds.0.max(bounds.1));
    if !(lo.is_finite() && hi.is_finite() && base_step.is_finite()) || base_step <= 0.0 {
        return Vec::new();
    }
    let gap_units = gap * base_step / PLOT_MIN_GRID_POINTS;
    let inside: Vec<f64> = ticks
        .iter()
        .copied()
        .filter(|t| t.is_finite() && (lo..=hi).contains(t))
        .collect();
    let mut kept: Vec<f64> = Vec::new();
    for &t in &inside {
        if kept.last().is_none_or(|&k| t - k >= gap_units) {
            kept.push(t);
        }
    }
    // The top tick too (what a short axis reads its scale by), in place of
    // a kept one too close to it.
    if let (Some(&last), Some(&top)) = (kept.last(), inside.last())
        && top != last
    {
        if top - last < gap_units && kept.len() > 1 {
            kept.pop();
        }
        if kept.last().is_none_or(|&k| top - k >= gap_units) {
            kept.push(top);
        }
    }
    let step = (hi - lo).max(1e-12) * 10.0;
    kept.into_iter()
        .map(|value| egui_plot::GridMark {
            value,
            step_size: step,
        })
        .collect()
}

/// `plot` with its axes marked at `chart`'s ticks, labelled as the chart
/// labels them and all at full strength (see [`presented_marks`]): the
/// axes of a presented plot.
pub fn presented_axes<'a>(plot: egui_plot::Plot<'a>, chart: &chart::Chart) -> egui_plot::Plot<'a> {
    fn label_of(ticks: &[(f64, String)], value: f64) -> String {
        ticks
            .iter()
            .find(|(t, _)| (t - value).abs() <= 1e-9 * t.abs().max(1.0))
            .map(|(_, l)| l.clone())
            .unwrap_or_default()
    }
    let (xs, ys) = (chart.x_ticks.clone(), chart.y_ticks.clone());
    let (xv, yv): (Vec<f64>, Vec<f64>) = (
        xs.iter().map(|t| t.0).collect(),
        ys.iter().map(|t| t.0).collect(),
    );
    plot.x_grid_spacer(move |input| presented_marks(&xv, input.bounds, input.base_step_size, 36.0))
        .y_grid_spacer(move |input| presented_marks(&yv, input.bounds, input.base_step_size, 24.0))
        .x_axis_formatter(move |mark, _| label_of(&xs, mark.value))
        .y_axis_formatter(move |mark, _| label_of(&ys, mark.value))
}

/// A faint colour for grids.
pub fn grid_color(dark: bool) -> Color32 {
    if dark {
        Color32::from_rgba_unmultiplied(150, 150, 150, 90)
    } else {
        Color32::from_rgba_unmultiplied(110, 110, 110, 90)
    }
}

/// Adds a toggle to a toolbar and returns whether it was clicked (labels are
/// what tests and screen readers find).
pub fn toolbar_toggle(ui: &mut Ui, on: bool, label: &str, hint: &str) -> bool {
    ui.selectable_label(on, label).on_hover_text(hint).clicked()
}

/// The label of the decade 10^k on a log axis: plain decimals near 1 (what
/// students read fastest), `1e-6` style beyond. (egui's default fonts have no
/// superscript minus.)
pub fn decade_label(k: i32) -> String {
    if (-3..=4).contains(&k) {
        let v = 10f64.powi(k);
        let digits = (-k).max(0) as usize;
        format!("{v:.digits$}")
    } else {
        format!("1e{k}")
    }
}

/// Gives the views of an egui context what they fetch from it (views that
/// find egui's render state through the context install it here), for
/// eframe's window and for offscreen figures alike.
pub fn install_context(ctx: &egui::Context, render_state: &eframe::egui_wgpu::RenderState) {
    fonts::install(ctx);
    gpu_image::install(ctx, render_state);
}

/// The background a figure view fills: the panel's colour, or nothing.
pub fn figure_fill(ui: &Ui, scene: &Scene<'_>) -> Color32 {
    if scene.transparent {
        Color32::TRANSPARENT
    } else {
        ui.visuals().panel_fill
    }
}

/// Shared by plots: the toggles for log and cosine.
pub fn display_toggles(ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
    let d = scene.state.display;
    if toolbar_toggle(ui, d.log, "log", "Logarithmic scale (L)") {
        out.push(Command::ToggleLog);
    }
    if toolbar_toggle(ui, d.cosine, "× cos θo", "Multiply by cos θo (C)") {
        out.push(Command::ToggleCosine);
    }
}

/// The waker of derived results shown in `ctx`'s window: a finished or
/// progressing job asks for a frame.
pub fn waker(ctx: &egui::Context) -> crate::derive::Waker {
    let ctx = ctx.clone();
    crate::derive::Waker::new(move |after| match after {
        None => ctx.request_repaint(),
        Some(d) => ctx.request_repaint_after(d),
    })
}

/// The id egui uses for a view's widgets.
pub fn view_id(id: &str) -> egui::Id {
    egui::Id::unique(("bv view", id))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The light's marker differs clearly from every BRDF colour, in both
    /// themes (largest channel difference at least 60 of 255).
    #[test]
    fn the_light_is_not_drawn_in_a_brdf_colour() {
        for dark in [true, false] {
            let l = light_color(dark);
            for c in crate::session::state::PALETTE {
                let d = (0..3)
                    .map(|k| (i32::from(l[k]) - i32::from(c[k])).abs())
                    .max()
                    .unwrap();
                assert!(d >= 60, "dark {dark}: light {l:?} vs palette {c:?}");
            }
        }
    }

    #[test]
    fn every_session_view_has_a_constructor() {
        let ids: Vec<_> = REGISTRY.iter().map(|v| v.id).collect();
        let want: Vec<_> = views::VIEWS.iter().map(|v| v.id).collect();
        assert_eq!(ids, want);
        assert!(entry("lobe").is_some());
        assert_eq!(find_view("LOBE3D").map(|e| e.id), Some("lobe"));
        assert!(find_view("nope").is_none());
    }

    #[test]
    fn decade_labels() {
        assert_eq!(decade_label(-3), "0.001");
        assert_eq!(decade_label(0), "1");
        assert_eq!(decade_label(2), "100");
        assert_eq!(decade_label(-6), "1e-6");
        assert_eq!(decade_label(-4), "1e-4");
    }
}
