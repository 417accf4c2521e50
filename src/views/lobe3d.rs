//! The 3D polar lobe view: `r(wo) · wo` for every drawn BRDF, the primary one
//! opaque and coloured by value, the others translucent in their own colours;
//! with the frame's axes, the incident ray, the (dashed) mirror direction, delta
//! lobes as spikes, a faint unit hemisphere grid and a ground disc.
//!
//! Meshes come from `bv_core::lobe::build` and are cached per BRDF, keyed on
//! everything they depend on, so a frame rebuilds a mesh only when its
//! parameters, the light or the display options changed, and never more than
//! once. While a pointer button is held the meshes are built at 64 × 128, and
//! refined to 128 × 256 when it is released.

use super::BrdfColor as _;
use super::camera::{self, CameraMatrices};
use super::factor_overlay;
use super::lobe_gpu::LobeCallback;
use super::sh_overlay;
use super::{Scene, View, colormap, curves};
use crate::derive::factor::FactorDone;
use crate::derive::sh::ShDone;
use crate::gpu::lobe::{LineSeg, LobeCamera, LobeFrame, MeshDraw, MeshStyle};
use crate::session::command::Command;
use crate::session::state::{Camera, Display, Incident};
use bv_core::lobe::{self, LobeMesh, LobeOptions, RadiusScale};
use eframe::egui::{self, Align2, Color32, FontId, Pos2, Rect, Sense, Stroke, Ui, Vec2};
use glam::Vec3;
use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// Mesh resolution while something is being dragged (θ rings, φ segments).
pub const DRAG_RESOLUTION: (usize, usize) = (64, 128);
/// Mesh resolution at rest.
pub const IDLE_RESOLUTION: (usize, usize) = (128, 256);

/// Opacity of overlaid (non-primary) lobes.
const OVERLAY_ALPHA: f32 = 0.38;

/// Opacity of the primary lobe under the SH overlay: see-through, so that the
/// reconstruction's wireframe shows where it lies inside the lobe (a sharp
/// peak's reconstruction is mostly inside).
const UNDER_SH_ALPHA: f32 = 0.6;

/// Mesh key of the SH reconstruction (distinct from BRDF ids and the disc).
const SH_MESH_KEY: u64 = u64::MAX - 2;

/// Mesh key of the factorisation's reconstruction.
const FACTOR_MESH_KEY: u64 = u64::MAX - 3;

#[derive(Debug, Clone, Copy, PartialEq)]
struct MeshKey {
    brdf_revision: u64,
    incident: (f64, f64),
    cosine: bool,
    log: bool,
    resolution: (usize, usize),
}

struct CachedLobe {
    key: MeshKey,
    mesh: Arc<LobeMesh>,
    revision: u64,
}

/// The 3D lobe view.
pub struct Lobe3dView {
    key: u64,
    cache: HashMap<u64, CachedLobe>,
    next_revision: u64,
    disc: Arc<LobeMesh>,
    last_scale: f32,
    rebuilds: u64,
    last_frame: Option<Arc<LobeFrame>>,
    /// The SH overlay's latest result and its mesh revision.
    sh: Option<(ShDone, u64)>,
    /// The factorisation overlay's latest result and its mesh revision.
    factor: Option<(FactorDone, u64)>,
    /// Where the view was drawn in the last frame.
    pub view_rect: Option<Rect>,
}

impl Default for Lobe3dView {
    fn default() -> Self {
        Self::new()
    }
}

static NEXT_VIEW_KEY: AtomicU64 = AtomicU64::new(1);

impl Lobe3dView {
    /// A view with empty caches.
    pub fn new() -> Self {
        Self {
            key: NEXT_VIEW_KEY.fetch_add(1, Ordering::Relaxed),
            cache: HashMap::new(),
            next_revision: 1,
            disc: Arc::new(ground_disc(96)),
            last_scale: 1.0,
            rebuilds: 0,
            last_frame: None,
            sh: None,
            factor: None,
            view_rect: None,
        }
    }

    /// The SH overlay result the view draws (with the overlay on).
    pub fn sh_result(&self) -> Option<&ShDone> {
        self.sh.as_ref().map(|(d, _)| d)
    }

    /// Takes the SH overlay's latest result (`None` with the overlay off);
    /// a new result gets a new mesh revision.
    pub fn set_sh(&mut self, done: Option<ShDone>) {
        self.sh = done.map(|d| match &self.sh {
            Some((old, rev)) if Arc::ptr_eq(old, &d) => (d, *rev),
            _ => {
                let rev = self.next_revision;
                self.next_revision += 1;
                (d, rev)
            }
        });
    }

    /// The factorisation overlay result the view draws (with the overlay on).
    pub fn factor_result(&self) -> Option<&FactorDone> {
        self.factor.as_ref().map(|(d, _)| d)
    }

    /// Takes the factorisation overlay's latest result (`None` with the
    /// overlay off); a new result gets a new mesh revision.
    pub fn set_factor(&mut self, done: Option<FactorDone>) {
        self.factor = done.map(|d| match &self.factor {
            Some((old, rev)) if Arc::ptr_eq(old, &d) => (d, *rev),
            _ => {
                let rev = self.next_revision;
                self.next_revision += 1;
                (d, rev)
            }
        });
    }

    /// The cached lobe mesh of BRDF `id` (what the view last drew).
    pub fn mesh(&self, id: u64) -> Option<&Arc<LobeMesh>> {
        self.cache.get(&id).map(|c| &c.mesh)
    }

    /// How many meshes were built since the view was created.
    pub fn rebuild_count(&self) -> u64 {
        self.rebuilds
    }

    /// World units per radius unit in the last frame.
    pub fn world_scale(&self) -> f32 {
        self.last_scale
    }

    /// The last frame handed to the GPU.
    pub fn last_frame(&self) -> Option<&Arc<LobeFrame>> {
        self.last_frame.as_ref()
    }

    /// Brings the mesh cache up to date with the scene (at most one build per
    /// BRDF) and drops meshes of BRDFs no longer drawn.
    pub fn update_meshes(&mut self, scene: &Scene<'_>) {
        let d = scene.state.display;
        let resolution = if scene.interacting {
            DRAG_RESOLUTION
        } else {
            IDLE_RESOLUTION
        };
        let wi = scene.wi();
        for b in &scene.brdfs {
            let key = MeshKey {
                brdf_revision: b.revision,
                incident: (scene.incident.theta_deg, scene.incident.phi_deg),
                cosine: d.cosine,
                log: d.log,
                resolution,
            };
            if self.cache.get(&b.id).is_some_and(|c| c.key == key) {
                continue;
            }
            let opts = LobeOptions {
                n_theta: resolution.0,
                n_phi: resolution.1,
                cosine: d.cosine,
                scale: if d.log {
                    RadiusScale::Log
                } else {
                    RadiusScale::Linear
                },
            };
            let mesh = Arc::new(lobe::build(b.brdf.as_ref(), wi, &opts));
            let revision = self.next_revision;
            self.next_revision += 1;
            self.rebuilds += 1;
            self.cache.insert(
                b.id,
                CachedLobe {
                    key,
                    mesh,
                    revision,
                },
            );
        }
        self.cache
            .retain(|id, _| scene.brdfs.iter().any(|b| b.id == *id));
    }

    /// The scale that maps the scene's radii to world units.
    fn scale_for(&self, scene: &Scene<'_>) -> f32 {
        if !scene.state.display.auto_scale {
            return scene.state.camera.fixed_scale;
        }
        let r = scene
            .brdfs
            .iter()
            .filter_map(|b| self.cache.get(&b.id))
            .map(|c| c.mesh.max_radius)
            .fold(0.0, f64::max);
        if r > 1e-12 && r.is_finite() {
            (1.0 / r) as f32
        } else {
            1.0
        }
    }

    /// Builds the frame for a viewport of `size` points (updates the mesh cache
    /// first). This is all the GPU needs; `background` is sRGB 0..1.
    pub fn frame(
        &mut self,
        scene: &Scene<'_>,
        size: Vec2,
        background: [f32; 4],
        dark: bool,
    ) -> Arc<LobeFrame> {
        self.update_meshes(scene);
        let scale = self.scale_for(scene);
        self.last_scale = scale;
        let d = scene.state.display;
        let cam = CameraMatrices::framed(&scene.state.camera, size.x, size.y, whole_sphere(scene));
        let primary = scene.primary().map(|b| b.id);
        let sh = self
            .sh
            .as_ref()
            .filter(|_| d.sh_overlay)
            .and_then(|(done, rev)| Some((done.value.as_ref().ok()?, *rev)))
            .filter(|(r, _)| Some(r.brdf_id) == primary);
        let factor = self
            .factor
            .as_ref()
            .filter(|_| d.factor_overlay)
            .and_then(|(done, rev)| Some((done.value.as_ref().ok()?, *rev)))
            .filter(|(r, _)| Some(r.brdf_id) == primary);
        let overlaid = sh.is_some() || factor.is_some();
        let mut meshes = Vec::new();
        for b in &scene.brdfs {
            let Some(c) = self.cache.get(&b.id) else {
                continue;
            };
            let is_primary = Some(b.id) == primary;
            meshes.push(MeshDraw {
                key: b.id,
                revision: c.revision,
                mesh: c.mesh.clone(),
                style: MeshStyle {
                    by_value: is_primary && d.color_by_value,
                    color: super::srgb_f32(b.color()),
                    alpha: if d.wireframe {
                        1.0
                    } else if is_primary {
                        if overlaid { UNDER_SH_ALPHA } else { 1.0 }
                    } else {
                        OVERLAY_ALPHA
                    },
                    wireframe: d.wireframe,
                    value_max: c.mesh.max_value as f32,
                    log: d.log,
                    scale,
                    unlit: d.wireframe,
                },
            });
        }
        if let Some((r, rev)) = sh {
            meshes.push(MeshDraw {
                key: SH_MESH_KEY,
                revision: rev,
                mesh: r.mesh.clone(),
                style: MeshStyle {
                    by_value: false,
                    color: if dark {
                        [0.97, 0.97, 0.97]
                    } else {
                        [0.05, 0.05, 0.05]
                    },
                    alpha: 1.0,
                    wireframe: true,
                    value_max: 1.0,
                    log: d.log,
                    scale,
                    unlit: true,
                },
            });
        }
        if let Some((r, rev)) = factor {
            meshes.push(MeshDraw {
                key: FACTOR_MESH_KEY,
                revision: rev,
                mesh: r.mesh.clone(),
                style: MeshStyle {
                    by_value: false,
                    // Amber, apart from the SH wireframe's white / black.
                    color: if dark {
                        [1.0, 0.72, 0.2]
                    } else {
                        [0.75, 0.38, 0.0]
                    },
                    alpha: 1.0,
                    wireframe: true,
                    value_max: 1.0,
                    log: d.log,
                    scale,
                    unlit: true,
                },
            });
        }
        let ground = if dark {
            [0.55, 0.58, 0.62]
        } else {
            [0.45, 0.47, 0.5]
        };
        meshes.push(MeshDraw {
            key: u64::MAX - 1,
            revision: 0,
            mesh: self.disc.clone(),
            style: MeshStyle {
                by_value: false,
                color: ground,
                alpha: 0.10,
                wireframe: false,
                value_max: 1.0,
                log: false,
                scale: 1.0,
                unlit: true,
            },
        });
        let lower = scene.brdfs.iter().any(|b| b.brdf.transmits());
        let mut lines = guide_lines(scene.incident, dark, lower);
        // The refracted ray of the selected (or first) interface model:
        // Snell's law in vector form (bv_core::frame::refract), dashed in
        // the polar view's colour for ωt; none under total internal
        // reflection.
        let eta = super::interface_model(scene).map(|m| m.1);
        if let Some(t) = eta.and_then(|e| bv_core::frame::refract(scene.wi(), e)) {
            let refr = if dark {
                Color32::from_rgb(110, 190, 255)
            } else {
                Color32::from_rgb(20, 100, 200)
            };
            dashed(
                &mut lines,
                Vec3::ZERO,
                // Shorter than the mirror ray: the default camera frames
                // the upper hemisphere, and the lower one ends sooner on
                // the screen.
                t.as_vec3() * REFRACTED_LENGTH,
                0.06,
                0.045,
                rgba(refr, 0.95),
                2.0,
            );
        }
        for b in &scene.brdfs {
            if let Some(c) = self.cache.get(&b.id) {
                delta_spikes(&c.mesh, b.color(), &mut lines);
            }
        }
        let frame = Arc::new(LobeFrame {
            camera: LobeCamera {
                view_proj: cam.view_proj,
                eye: cam.eye,
            },
            background,
            meshes,
            lines,
            interacting: scene.interacting,
        });
        self.last_frame = Some(frame.clone());
        frame
    }
}

/// A flat disc of unit radius on the ground plane (a fan of `n` triangles).
fn ground_disc(n: usize) -> LobeMesh {
    let mut positions = vec![[0.0, 0.0, 0.0]];
    for k in 0..n {
        let a = std::f32::consts::TAU * k as f32 / n as f32;
        positions.push([a.cos(), a.sin(), 0.0]);
    }
    let mut indices = Vec::with_capacity(n * 3);
    for k in 0..n {
        indices.extend_from_slice(&[0, 1 + k as u32, 1 + ((k + 1) % n) as u32]);
    }
    LobeMesh {
        normals: vec![[0.0, 0.0, 1.0]; positions.len()],
        values: vec![[0.0; 3]; positions.len()],
        positions,
        indices,
        ..Default::default()
    }
}

fn rgba(c: Color32, alpha: f32) -> [f32; 4] {
    let [r, g, b] = super::srgb_f32(c);
    [r, g, b, alpha]
}

/// Points along a curve `f(t)`, `t ∈ [0, 1]`, as segments.
fn polyline(
    out: &mut Vec<LineSeg>,
    n: usize,
    color: [f32; 4],
    width: f32,
    f: impl Fn(f32) -> Vec3,
) {
    let mut prev = f(0.0);
    for k in 1..=n {
        let p = f(k as f32 / n as f32);
        out.push(LineSeg::new(prev, p, color, width));
        prev = p;
    }
}

/// A dashed segment.
fn dashed(
    out: &mut Vec<LineSeg>,
    a: Vec3,
    b: Vec3,
    dash: f32,
    gap: f32,
    color: [f32; 4],
    width: f32,
) {
    let len = (b - a).length();
    if len <= 0.0 {
        return;
    }
    let dir = (b - a) / len;
    let mut t = 0.0;
    while t < len {
        let e = (t + dash).min(len);
        out.push(LineSeg::new(a + dir * t, a + dir * e, color, width));
        t = e + gap;
    }
}

/// An arrow head at `tip` pointing along `dir` (unit).
fn arrow_head(
    out: &mut Vec<LineSeg>,
    tip: Vec3,
    dir: Vec3,
    size: f32,
    color: [f32; 4],
    width: f32,
) {
    let u = dir.any_orthonormal_vector();
    let v = dir.cross(u);
    let back = tip - dir * size;
    for side in [u, -u, v, -v] {
        out.push(LineSeg::new(tip, back + side * size * 0.45, color, width));
    }
}

/// Grid, ground rings, axes, incident ray and mirror direction; with
/// `lower`, the grid of the lower hemisphere too, fainter (a transmitting
/// model's lobe reaches below the surface, issue 33).
fn guide_lines(incident: Incident, dark: bool, lower: bool) -> Vec<LineSeg> {
    use std::f32::consts::{FRAC_PI_2, TAU};
    let mut out = Vec::new();
    let grid = rgba(super::grid_color(dark), if dark { 0.22 } else { 0.28 });
    let horizon = rgba(super::grid_color(dark), if dark { 0.5 } else { 0.6 });
    // Meridians every 30°, parallels at 30° and 60°, and the horizon.
    for k in 0..12 {
        let phi = TAU * k as f32 / 12.0;
        polyline(&mut out, 24, grid, 1.0, |t| {
            let th = t * FRAC_PI_2;
            Vec3::new(th.sin() * phi.cos(), th.sin() * phi.sin(), th.cos())
        });
    }
    if lower {
        let faint = rgba(super::grid_color(dark), if dark { 0.12 } else { 0.16 });
        for k in 0..12 {
            let phi = TAU * k as f32 / 12.0;
            polyline(&mut out, 24, faint, 1.0, |t| {
                let th = FRAC_PI_2 + t * FRAC_PI_2;
                Vec3::new(th.sin() * phi.cos(), th.sin() * phi.sin(), th.cos())
            });
        }
        for th_deg in [120.0f32, 150.0] {
            let th = th_deg.to_radians();
            polyline(&mut out, 96, faint, 1.0, |t| {
                let phi = t * TAU;
                Vec3::new(th.sin() * phi.cos(), th.sin() * phi.sin(), th.cos())
            });
        }
    }
    for th_deg in [30.0f32, 60.0] {
        let th = th_deg.to_radians();
        polyline(&mut out, 96, grid, 1.0, |t| {
            let phi = t * TAU;
            Vec3::new(th.sin() * phi.cos(), th.sin() * phi.sin(), th.cos())
        });
    }
    polyline(&mut out, 128, horizon, 1.5, |t| {
        let phi = t * TAU;
        Vec3::new(phi.cos(), phi.sin(), 0.0)
    });
    // Half-radius ring on the ground.
    polyline(&mut out, 96, grid, 1.0, |t| {
        let phi = t * TAU;
        Vec3::new(0.5 * phi.cos(), 0.5 * phi.sin(), 0.0)
    });

    // Frame axes: n (blue), t (red), b (green).
    let axis = 1.3;
    let (n_col, t_col, b_col) = axis_colors(dark);
    out.push(LineSeg::new(
        Vec3::ZERO,
        Vec3::Z * axis,
        rgba(n_col, 1.0),
        2.0,
    ));
    arrow_head(
        &mut out,
        Vec3::Z * axis,
        Vec3::Z,
        0.07,
        rgba(n_col, 1.0),
        2.0,
    );
    out.push(LineSeg::new(
        Vec3::ZERO,
        Vec3::X * axis,
        rgba(t_col, 1.0),
        2.0,
    ));
    arrow_head(
        &mut out,
        Vec3::X * axis,
        Vec3::X,
        0.07,
        rgba(t_col, 1.0),
        2.0,
    );
    out.push(LineSeg::new(
        Vec3::ZERO,
        Vec3::Y * axis,
        rgba(b_col, 1.0),
        2.0,
    ));
    arrow_head(
        &mut out,
        Vec3::Y * axis,
        Vec3::Y,
        0.07,
        rgba(b_col, 1.0),
        2.0,
    );

    // Incident ray: from the light towards the surface point.
    let wi = incident.direction().as_vec3();
    let light = rgba(super::light_color(dark), 1.0);
    out.push(LineSeg::new(wi * INCIDENT_LENGTH, wi * 0.02, light, 3.0));
    arrow_head(&mut out, wi * 0.02, -wi, 0.1, light, 3.0);
    // Mirror direction, dashed.
    let r = bv_core::frame::reflect(incident.direction()).as_vec3();
    dashed(
        &mut out,
        Vec3::ZERO,
        r * MIRROR_LENGTH,
        0.06,
        0.045,
        rgba(super::mirror_color(dark), 0.95),
        2.0,
    );
    out
}

/// Length of the drawn incident ray (unit hemisphere = 1).
const INCIDENT_LENGTH: f32 = 1.55;
/// Length of the drawn mirror direction.
const MIRROR_LENGTH: f32 = 1.4;
/// Length of the drawn refracted direction.
const REFRACTED_LENGTH: f32 = 1.15;

/// Axis colours (n, t, b).
fn axis_colors(dark: bool) -> (Color32, Color32, Color32) {
    if dark {
        (
            Color32::from_rgb(120, 160, 255),
            Color32::from_rgb(240, 100, 100),
            Color32::from_rgb(110, 210, 110),
        )
    } else {
        (
            Color32::from_rgb(40, 80, 220),
            Color32::from_rgb(200, 40, 40),
            Color32::from_rgb(30, 150, 30),
        )
    }
}

/// Delta lobes as spikes whose length is their weight (channel mean) in units
/// of the unit hemisphere.
fn delta_spikes(mesh: &LobeMesh, color: Color32, out: &mut Vec<LineSeg>) {
    for d in &mesh.deltas {
        let w = bv_core::mean_rgb(d.weight) as f32;
        if w.is_nan() || w <= 0.0 || w.is_infinite() {
            continue;
        }
        let dir = d.direction.as_vec3();
        let tip = dir * w;
        out.push(LineSeg::new(Vec3::ZERO, tip, rgba(color, 1.0), 4.0));
        arrow_head(out, tip, dir, 0.08, rgba(color, 1.0), 3.0);
    }
}

impl View for Lobe3dView {
    fn toolbar(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let d = scene.state.display;
        let set = |out: &mut Vec<Command>, f: &dyn Fn(&mut Display)| {
            let mut n = d;
            f(&mut n);
            out.push(Command::SetDisplay(n));
        };
        if super::toolbar_toggle(ui, d.cosine, "× cos θo", "Multiply by cos θo (C)") {
            out.push(Command::ToggleCosine);
        }
        if super::toolbar_toggle(ui, d.log, "log", "Logarithmic radius ln(1 + f) (L)") {
            out.push(Command::ToggleLog);
        }
        if super::toolbar_toggle(ui, d.wireframe, "wireframe", "Draw grid lines (W)") {
            out.push(Command::ToggleWireframe);
        }
        if super::toolbar_toggle(
            ui,
            d.color_by_value,
            "colour by value",
            "Colour the selected lobe by its value",
        ) {
            set(out, &|n| n.color_by_value = !n.color_by_value);
        }
        sh_overlay::control(ui, scene, out);
        sh_overlay::error_label(
            ui,
            scene,
            crate::derive::sh::request(&super::waker(ui.ctx()), scene).as_ref(),
        );
        factor_overlay::control(ui, scene, out);
        factor_overlay::error_label(
            ui,
            scene,
            crate::derive::factor::request(&super::waker(ui.ctx()), scene).as_ref(),
        );
        super::gonio_overlay::control(ui, scene, out);
        if super::toolbar_toggle(
            ui,
            d.auto_scale,
            "auto scale",
            "Fit the largest lobe to the unit hemisphere; off keeps the current scale while parameters change",
        ) {
            // Freeze the scale in use so that turning auto-scale off changes nothing on screen.
            let scale = self.last_scale;
            set(out, &|n| n.auto_scale = !n.auto_scale);
            out.push(Command::SetCamera(Camera {
                fixed_scale: scale,
                ..scene.state.camera
            }));
        }
        if ui
            .button("reset camera")
            .on_hover_text("Reset the camera (R, or double-click the view)")
            .clicked()
        {
            out.push(Command::ResetCamera);
        }
    }

    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let rect = ui.available_rect_before_wrap();
        if rect.width() < 8.0 || rect.height() < 8.0 {
            return;
        }
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        self.view_rect = Some(rect);
        let dark = ui.visuals().dark_mode;
        let mut bg = background(dark);
        if scene.transparent {
            bg = [0.0; 4];
        }
        self.set_sh(crate::derive::sh::request(&super::waker(ui.ctx()), scene));
        self.set_factor(crate::derive::factor::request(
            &super::waker(ui.ctx()),
            scene,
        ));
        let frame = self.frame(scene, rect.size(), bg, dark);
        // A lost device (a browser took it back) fails every buffer the
        // renderer would create: say so instead of drawing.
        if let Some(why) = super::gpu_image::device_lost(ui.ctx()) {
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                format!(
                    "The 3D lobe cannot draw: the GPU device was lost ({why});\nreload the page"
                ),
                egui::FontId::proportional(14.0),
                ui.visuals().weak_text_color(),
            );
        } else {
            ui.painter().add(
                LobeCallback {
                    view: self.key,
                    rect,
                    frame: frame.clone(),
                }
                .shape(),
            );
        }

        // The frame's camera, with the viewport in points that projecting
        // labels and pointer rays needs.
        let cam = CameraMatrices::framed(
            &scene.state.camera,
            rect.width(),
            rect.height(),
            whole_sphere(scene),
        );
        handle_input(ui, &response, rect, scene, &cam, out);
        self.overlays(ui, rect, scene, &cam, dark);
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// Background of the lobe view (sRGB 0..1): the GPU views' one
/// ([`super::gpu_image::view_background`]).
pub fn background(dark: bool) -> [f32; 4] {
    super::gpu_image::view_background(dark)
}

fn handle_input(
    ui: &Ui,
    response: &egui::Response,
    rect: Rect,
    scene: &Scene<'_>,
    cam: &CameraMatrices,
    out: &mut Vec<Command>,
) {
    let modifiers = ui.input(|i| i.modifiers);
    let light_drag = modifiers.shift || modifiers.ctrl || modifiers.command;
    if response.double_clicked() {
        out.push(Command::ResetCamera);
        return;
    }
    if (response.dragged() || response.clicked()) && light_drag {
        if let Some(p) = response.interact_pointer_pos() {
            let (o, d) = cam.ray(p.x - rect.min.x, p.y - rect.min.y);
            if let Some(hit) = camera::pick_hemisphere(o, d) {
                out.push(Command::SetIncident(Incident::from_direction(
                    hit.as_dvec3(),
                )));
            }
        }
    } else if response.dragged() {
        let delta = response.drag_delta();
        let c = scene.state.camera;
        out.push(Command::SetCamera(Camera {
            yaw_deg: c.yaw_deg - delta.x * 0.45,
            pitch_deg: c.pitch_deg + delta.y * 0.45,
            ..c
        }));
    }
    if response.hovered() {
        let (scroll, zoom) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
        let factor = (-scroll * 0.0025).exp() / zoom.max(1e-3);
        if (factor - 1.0).abs() > 1e-4 {
            let c = scene.state.camera;
            out.push(Command::SetCamera(Camera {
                distance: c.distance * factor,
                ..c
            }));
        }
    }
}

impl Lobe3dView {
    fn overlays(&self, ui: &Ui, rect: Rect, scene: &Scene<'_>, cam: &CameraMatrices, dark: bool) {
        let painter = ui.painter_at(rect);
        let text = super::strong_text(ui);
        let font = FontId::proportional(15.0);
        let at = |p: Vec3| cam.project(p).map(|s| rect.min + Vec2::new(s[0], s[1]));
        let (n_col, t_col, b_col) = axis_colors(dark);
        // The light's and the mirror direction's labels first: the axes'
        // labels then step aside where they would fall on one (seen along
        // ωr, ωi's label sat on n's).
        let mut taken: Vec<Rect> = Vec::new();
        let wi = scene.wi().as_vec3();
        if let Some(s) = at(wi * (INCIDENT_LENGTH + 0.04)) {
            let label = format!(
                "ωi ({:.0}°, {:.0}°)",
                scene.incident.theta_deg, scene.incident.phi_deg
            );
            let align = away_from(at(Vec3::ZERO), s);
            taken.push(outlined_text(
                &painter,
                s,
                align,
                &label,
                font.clone(),
                super::light_color(dark),
                dark,
            ));
        }
        let r = bv_core::frame::reflect(scene.wi()).as_vec3();
        if let Some(s) = at(r * (MIRROR_LENGTH + 0.04)) {
            let align = away_from(at(Vec3::ZERO), s);
            taken.push(outlined_text(
                &painter,
                s,
                align,
                "ωr",
                font.clone(),
                super::mirror_color(dark),
                dark,
            ));
        }
        for (p, label, c) in [
            (Vec3::Z * 1.42, "n", n_col),
            (Vec3::X * 1.42, "t", t_col),
            (Vec3::Y * 1.42, "b", b_col),
        ] {
            if let Some(s) = at(p) {
                let size = painter
                    .layout_no_wrap(label.to_string(), font.clone(), c)
                    .size();
                let (pos, align) = clear_of(s, size, &taken, painter.clip_rect().shrink(3.0));
                taken.push(outlined_text(
                    &painter,
                    pos,
                    align,
                    label,
                    font.clone(),
                    c,
                    dark,
                ));
            }
        }

        let d = scene.state.display;
        let small = FontId::proportional(12.5);
        self.gonio_overlay(ui, &painter, &at, scene, dark);
        // Colour bar of the primary lobe.
        if let Some(p) = scene.primary()
            && d.color_by_value
            && !d.wireframe
            && let Some(c) = self.cache.get(&p.id)
            // A pure delta model has no lobe to colour.
            && c.mesh.max_value > 0.0
        {
            let vmax = c.mesh.max_value;
            // Bottom right: below the horizon, where reflection lobes never go.
            let h = (rect.height() * 0.32).clamp(50.0, 200.0);
            let bar = Rect::from_min_size(
                Pos2::new(rect.max.x - 84.0, rect.max.y - 44.0 - h),
                Vec2::new(14.0, h),
            );
            let mut mesh = egui::Mesh::default();
            let steps = 32;
            for k in 0..=steps {
                let t = k as f32 / steps as f32;
                let y = bar.max.y - t * bar.height();
                let col = colormap::viridis(t);
                mesh.colored_vertex(Pos2::new(bar.min.x, y), col);
                mesh.colored_vertex(Pos2::new(bar.max.x, y), col);
                if k > 0 {
                    let i = (2 * k) as u32;
                    mesh.add_triangle(i - 2, i - 1, i);
                    mesh.add_triangle(i - 1, i + 1, i);
                }
            }
            painter.add(egui::Shape::mesh(mesh));
            painter.rect_stroke(
                bar,
                0.0,
                Stroke::new(1.0, text.gamma_multiply(0.6)),
                egui::StrokeKind::Outside,
            );
            for t in [0.0f64, 0.5, 1.0] {
                // The value at colour-map position t (log maps ln(1 + v)).
                let v = if d.log {
                    ((1.0 + vmax).ln() * t).exp() - 1.0
                } else {
                    vmax * t
                };
                let y = bar.max.y - t as f32 * bar.height();
                painter.line_segment(
                    [Pos2::new(bar.max.x, y), Pos2::new(bar.max.x + 4.0, y)],
                    Stroke::new(1.0, text),
                );
                painter.text(
                    Pos2::new(bar.max.x + 6.0, y),
                    Align2::LEFT_CENTER,
                    curves::fmt_value(v),
                    small.clone(),
                    text,
                );
            }
            painter.text(
                Pos2::new(bar.center().x, bar.min.y - 6.0),
                Align2::CENTER_BOTTOM,
                format!("{} (1/sr)", super::value_label(d.cosine)),
                small.clone(),
                text,
            );
        }

        // What the unit hemisphere stands for, and how to drive the view.
        let unit = 1.0 / self.last_scale.max(1e-30) as f64;
        let scale_text = if d.log {
            format!(
                "grid radius: ln(1 + {}) = {}",
                super::value_label(d.cosine),
                curves::fmt_value(unit)
            )
        } else {
            format!(
                "grid radius: {} = {} 1/sr",
                super::value_label(d.cosine),
                curves::fmt_value(unit)
            )
        };
        let weak = ui.visuals().weak_text_color();
        // Figures have no pointer: the scale line takes the hint's place.
        let lift = if scene.figure { -6.0 } else { -24.0 };
        painter.text(
            rect.left_bottom() + Vec2::new(8.0, lift),
            Align2::LEFT_BOTTOM,
            scale_text,
            small.clone(),
            text,
        );
        if !scene.figure {
            painter.text(
                rect.left_bottom() + Vec2::new(8.0, -6.0),
                Align2::LEFT_BOTTOM,
                "drag: orbit · scroll: zoom · shift+drag: move light · double-click: reset",
                small.clone(),
                weak,
            );
        }
        if scene.brdfs.is_empty() {
            super::gpu_image::centre_note(&painter, rect, super::gpu_image::NOTHING_DRAWN, weak);
        }
    }
}

/// Text with a thin outline in the background colour, readable over the lobe.
/// Whether the view frames the whole sphere: the light is below the
/// surface, or a drawn model transmits (its lobe lies below). Issue 33:
/// framed for the upper hemisphere, light from below ran off the view.
fn whole_sphere(scene: &Scene<'_>) -> bool {
    scene.incident.below() || scene.brdfs.iter().any(|b| b.brdf.transmits())
}

impl Lobe3dView {
    /// The gonioreflectometer's readings (`plots.gonio`) as dots with 2σ
    /// bars at their detector directions, on the lobes' radius scale: the
    /// same measurement the polar view draws, here against the whole lobe.
    fn gonio_overlay(
        &self,
        ui: &Ui,
        painter: &egui::Painter,
        at: &dyn Fn(Vec3) -> Option<Pos2>,
        scene: &Scene<'_>,
        dark: bool,
    ) {
        if !scene.state.plots.gonio {
            return;
        }
        let Some(overlay) = super::gonio_overlay::readings_3d(scene, &super::waker(ui.ctx()))
        else {
            return;
        };
        let sets = &overlay.sets;
        let scale = f64::from(self.last_scale);
        let radius = if scene.state.display.log {
            RadiusScale::Log
        } else {
            RadiusScale::Linear
        };
        let ink = super::strong_text_color(dark);
        let halo = if dark {
            Color32::from_black_alpha(200)
        } else {
            Color32::from_white_alpha(220)
        };
        let point = |dir: glam::DVec3, v: f64| at((dir * radius.apply(v) * scale).as_vec3());
        // The one-bounce model (F = 1) the surface's hollow dots follow,
        // dashed in the primary BRDF's colour.
        if let Some(curve) = &overlay.reference {
            let color = scene.primary().map_or(ink, |b| b.color());
            let pts: Vec<Pos2> = curve.iter().filter_map(|&(dir, v)| point(dir, v)).collect();
            for w in [4.0, 2.0] {
                let c = if w > 3.0 { halo } else { color };
                painter.extend(egui::Shape::dashed_line(&pts, Stroke::new(w, c), 8.0, 5.0));
            }
        }
        for set in sets {
            for &(dir, v, lo, hi) in &set.stops {
                if let (Some(a), Some(b)) = (point(dir, lo), point(dir, hi)) {
                    painter.line_segment([a, b], Stroke::new(3.5, halo));
                    painter.line_segment([a, b], Stroke::new(1.5, ink));
                }
                if let Some(c) = point(dir, v) {
                    if set.filled {
                        painter.circle(c, 3.5, ink, Stroke::new(1.5, halo));
                    } else {
                        painter.circle(c, 3.5, halo, Stroke::new(1.5, ink));
                    }
                }
            }
        }
        // One line per entry: in one line it ran wider than the view.
        let lines: Vec<String> = sets
            .iter()
            .map(|s| format!("{} {}, 2σ bars", if s.filled { "●" } else { "○" }, s.label))
            .chain(
                overlay
                    .reference
                    .as_ref()
                    .map(|_| "- - the model with F = 1".to_string()),
            )
            .collect();
        let rect = painter.clip_rect();
        // Top right: the light's label may be top left, the grid radius
        // is bottom left and the colour bar right of the middle.
        outlined_text(
            painter,
            rect.right_top() + Vec2::new(-8.0, 8.0),
            Align2::RIGHT_TOP,
            &lines.join("\n"),
            FontId::proportional(13.0),
            ink,
            dark,
        );
    }
}

/// The text is moved inside the painter's clip rectangle if it would stick out,
/// so a label is never cut in a narrow view.
fn outlined_text(
    painter: &egui::Painter,
    pos: Pos2,
    align: Align2,
    text: &str,
    font: FontId,
    color: Color32,
    dark: bool,
) -> Rect {
    let halo = if dark {
        Color32::from_rgba_unmultiplied(0, 0, 0, 160)
    } else {
        Color32::from_rgba_unmultiplied(255, 255, 255, 200)
    };
    let galley = painter.layout_no_wrap(text.to_string(), font.clone(), color);
    let r = inside(
        align.anchor_size(pos, galley.size()),
        painter.clip_rect().shrink(3.0),
    );
    for o in [
        Vec2::new(-1.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(0.0, -1.0),
        Vec2::new(0.0, 1.0),
    ] {
        painter.text(r.min + o, Align2::LEFT_TOP, text, font.clone(), halo);
    }
    painter.galley(r.min, galley, color);
    r
}

/// `r` moved the least that puts it inside `bounds` (a label near the
/// view's edge stays whole).
fn inside(r: Rect, bounds: Rect) -> Rect {
    let dx = (bounds.min.x - r.min.x).max(0.0) + (bounds.max.x - r.max.x).min(0.0);
    let dy = (bounds.min.y - r.min.y).max(0.0) + (bounds.max.y - r.max.y).min(0.0);
    r.translate(Vec2::new(dx, dy))
}

/// Where a label of `size` centred on `p` goes so that it covers none of
/// the labels already drawn (`taken`) once [`outlined_text`] has moved it
/// inside `bounds`: centred on `p` when that is clear, else the nearest
/// clear place beside it (right, left, below, above, a step further out
/// each round), else centred on `p` after all.
fn clear_of(p: Pos2, size: Vec2, taken: &[Rect], bounds: Rect) -> (Pos2, Align2) {
    let gap = 6.0;
    let clear = |at: Pos2, align: Align2| {
        let r = inside(align.anchor_size(at, size), bounds).expand(1.0);
        !taken.iter().any(|t| t.intersects(r))
    };
    if clear(p, Align2::CENTER_CENTER) {
        return (p, Align2::CENTER_CENTER);
    }
    for k in 0..6 {
        let k = k as f32;
        let (dx, dy) = (
            size.x * 0.5 + gap + k * size.x,
            size.y * 0.5 + gap + k * size.y,
        );
        for (at, align) in [
            (p + Vec2::new(dx, 0.0), Align2::LEFT_CENTER),
            (p - Vec2::new(dx, 0.0), Align2::RIGHT_CENTER),
            (p + Vec2::new(0.0, dy), Align2::CENTER_TOP),
            (p - Vec2::new(0.0, dy), Align2::CENTER_BOTTOM),
        ] {
            if clear(at, align) {
                return (at, align);
            }
        }
    }
    (p, Align2::CENTER_CENTER)
}

/// Anchors a label on the side of `p` away from `origin`, so it does not
/// cover the line it names.
fn away_from(origin: Option<Pos2>, p: Pos2) -> Align2 {
    match origin {
        Some(o) if p.x < o.x - 4.0 => Align2::RIGHT_CENTER,
        Some(o) if p.x > o.x + 4.0 => Align2::LEFT_CENTER,
        _ => Align2::CENTER_BOTTOM,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_labels_step_aside_from_drawn_labels() {
        let size = Vec2::new(10.0, 16.0);
        let p = Pos2::new(100.0, 100.0);
        // Clear: centred on its point.
        let view = Rect::from_min_size(Pos2::ZERO, Vec2::splat(1000.0));
        assert_eq!(clear_of(p, size, &[], view), (p, Align2::CENTER_CENTER));
        // On ωi's label: beside it, not covering it.
        let wi = Rect::from_center_size(p, Vec2::new(120.0, 18.0));
        let (at, align) = clear_of(p, size, &[wi], view);
        let r = align.anchor_size(at, size);
        assert!(!r.intersects(wi), "{r:?}");
        // Off the top, where the label is moved down inside the view onto
        // ωi's label (at the view's top edge): placed clear of it there.
        let top = Pos2::new(100.0, -30.0);
        let wi = Rect::from_min_size(Pos2::new(40.0, 0.0), Vec2::new(120.0, 18.0));
        let (at, align) = clear_of(top, size, &[wi], view);
        let r = inside(align.anchor_size(at, size), view);
        assert!(!r.intersects(wi), "{r:?}");
        // Boxed in on every side: centred (drawn where it belongs).
        let wall = Rect::from_center_size(p, Vec2::splat(400.0));
        assert_eq!(clear_of(p, size, &[wall], view), (p, Align2::CENTER_CENTER));
    }

    #[test]
    fn ground_disc_is_a_fan() {
        let d = ground_disc(8);
        assert_eq!(d.positions.len(), 9);
        assert_eq!(d.indices.len(), 24);
        assert!(d.indices.iter().all(|&i| (i as usize) < 9));
    }

    #[test]
    fn dashes_cover_the_segment_with_gaps() {
        let mut out = Vec::new();
        dashed(&mut out, Vec3::ZERO, Vec3::X, 0.1, 0.1, [1.0; 4], 1.0);
        assert_eq!(out.len(), 5);
        assert!((out[4].b[0] - 0.9).abs() < 1e-5);
    }
}
