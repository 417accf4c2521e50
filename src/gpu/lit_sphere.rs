//! Offscreen renderer of the lit sphere view: every given model on its own
//! orthographic sphere, side by side, lit by one directional light. Built once (device, pipeline), it re-renders on every
//! call, so a GUI view can call [`LitSphereRenderer::render`] each frame and
//! show the texture, and `bv render` can call [`LitSphereRenderer::render_image`] once.

use super::context::{Gpu, TARGET_FORMAT, Target};
use super::display::ToneMap;
use super::errors;
use super::fullscreen;
use super::pack::{TableBuffer, pack_all};
use super::shaders::ShaderLibrary;
use super::specialised::{Followed, ModelPipelines};
use super::sphere::Grid;
use anyhow::{Result, bail};
use bv_core::ModelSpec;
use glam::DVec3;

/// What is behind the spheres (display values, i.e. already sRGB-encoded, 0..1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Background {
    /// One flat colour.
    Flat([f32; 3]),
    /// A checkerboard of two colours with squares of `size` pixels.
    Checker {
        /// First colour.
        a: [f32; 3],
        /// Second colour.
        b: [f32; 3],
        /// Square size in pixels.
        size: f32,
    },
}

impl Default for Background {
    fn default() -> Self {
        Background::Flat([0.0; 3])
    }
}

/// Everything about a lit-sphere frame except the models and the size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LitSphereSettings {
    /// Direction towards the light in view space (x right, y up, z towards the
    /// viewer); normalised before use.
    pub light: DVec3,
    /// Irradiance E of the light at normal incidence.
    pub irradiance: f64,
    /// Exposure in stops: radiance is scaled by `2^ev`.
    pub exposure_ev: f64,
    /// Tone map after exposure.
    pub tone_map: ToneMap,
    /// Background.
    pub background: Background,
    /// The surface turned about its normal (radians, from the tangent
    /// towards the bitangent).
    pub turn: f64,
}

impl Default for LitSphereSettings {
    fn default() -> Self {
        Self {
            light: DVec3::new(-0.4, 0.5, 0.77),
            irradiance: 1.0,
            exposure_ev: 0.0,
            tone_map: ToneMap::None,
            background: Background::default(),
            turn: 0.0,
        }
    }
}

/// The uniform block of lit_sphere.wgsl (`View`).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ViewUniform {
    size: [f32; 2],
    tiles: u32,
    tone: u32,
    light: [f32; 4],
    exposure: f32,
    background: u32,
    checker: f32,
    turn: f32,
    cols: u32,
    pad: [u32; 3],
    color: [f32; 4],
    color2: [f32; 4],
}

/// The lit-sphere renderer: persistent pipelines, re-renders on demand.
///
/// Each sphere is drawn by a pipeline specialised for its model (built on
/// first use and kept; see [`ShaderLibrary::specialised_wgsl`] for why), the
/// generic pipeline standing in while one cannot be built.
pub struct LitSphereRenderer {
    gpu: Gpu,
    bind_layout: wgpu::BindGroupLayout,
    pipelines: ModelPipelines<wgpu::RenderPipeline>,
    target: Option<Target>,
    tables: TableBuffer,
}

impl std::fmt::Debug for LitSphereRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LitSphereRenderer")
            .field("pipelines", &self.pipelines)
            .finish_non_exhaustive()
    }
}

/// The bindings of lit_sphere.wgsl, all visible to the fragment stage: a
/// layout shared by the generic and the specialised pipelines (a specialised
/// shader may leave some unused).
fn bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let storage = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("lit sphere"),
        entries: &[
            storage(0),
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            storage(2),
            storage(8),
        ],
    })
}

fn pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
) -> wgpu::RenderPipeline {
    fullscreen::pipeline(device, "lit sphere", Some(layout), module, TARGET_FORMAT)
}

impl LitSphereRenderer {
    /// Builds the generic pipeline on `gpu` (specialised ones follow on use).
    pub fn new(gpu: Gpu, library: &mut ShaderLibrary) -> Result<Self> {
        let device = gpu.device.clone();
        errors::scoped(&device, "building the lit sphere renderer", || {
            Self::build(gpu, library)
        })
    }

    fn build(gpu: Gpu, library: &mut ShaderLibrary) -> Result<Self> {
        let module = library.shader_module(&gpu.device, "lit_sphere")?;
        let bind_layout = bind_group_layout(&gpu.device);
        let layout = gpu
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("lit sphere"),
                bind_group_layouts: &[Some(&bind_layout)],
                immediate_size: 0,
            });
        let generic = pipeline(&gpu.device, &layout, &module);
        let pipelines = ModelPipelines::new(&gpu.device, "lit_sphere", layout, pipeline, generic)?;
        Ok(Self {
            gpu,
            bind_layout,
            pipelines,
            target: None,
            tables: TableBuffer::default(),
        })
    }

    /// Adopts a changed catalogue (a user's model saved): only the pipelines
    /// whose code changed are built again (see
    /// [`super::specialised::ModelPipelines::follow_catalogue`]).
    pub fn follow_catalogue(&mut self) -> Followed {
        self.pipelines.follow_catalogue()
    }

    /// Takes the pipelines that finished compiling after a catalogue change:
    /// `(arrived, waiting)`, whether a sphere must be drawn again, and
    /// whether others are still compiling.
    pub fn poll_pipelines(&mut self) -> (bool, bool) {
        self.pipelines.poll()
    }

    /// How many pipelines were compiled after the renderer was built (for
    /// tests: what a changed catalogue cost).
    pub fn pipelines_compiled(&self) -> u64 {
        self.pipelines.compiled()
    }

    /// How many specialised pipelines exist (for tests).
    pub fn specialised_count(&self) -> usize {
        self.pipelines.specialised_count()
    }

    /// The device it renders on.
    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// Renders `models` side by side into the renderer's own `width`×`height`
    /// texture (kept between calls of the same size) and returns it; the work
    /// is submitted, not waited for.
    pub fn render(
        &mut self,
        models: &[ModelSpec],
        settings: &LitSphereSettings,
        width: u32,
        height: u32,
    ) -> Result<&wgpu::Texture> {
        let device = self.gpu.device.clone();
        errors::scoped(&device, "rendering the lit sphere", || {
            self.render_unscoped(models, settings, width, height)
                .map(|_| ())
        })?;
        match &self.target {
            Some(t) => Ok(&t.texture),
            None => bail!("no lit sphere image"),
        }
    }

    fn render_unscoped(
        &mut self,
        models: &[ModelSpec],
        settings: &LitSphereSettings,
        width: u32,
        height: u32,
    ) -> Result<&wgpu::Texture> {
        if models.is_empty() {
            bail!("the lit sphere needs at least one model");
        }
        let (params, refs, tables) = pack_all(models)?;
        let tiles: Vec<[u32; 2]> = refs.iter().map(|r| [r.model, r.offset]).collect();
        let light = settings.light.try_normalize().unwrap_or(DVec3::Z);
        let (background, checker, color, color2) = match settings.background {
            Background::Flat(c) => (0, 1.0, c, c),
            Background::Checker { a, b, size } => (1, size.max(1.0), a, b),
        };
        let grid = Grid::new(
            models.len(),
            glam::DVec2::new(f64::from(width), f64::from(height)),
        );
        let uniform = ViewUniform {
            size: [width as f32, height as f32],
            tiles: u32::try_from(models.len())?,
            tone: settings.tone_map.index(),
            light: [
                light.x as f32,
                light.y as f32,
                light.z as f32,
                settings.irradiance as f32,
            ],
            exposure: settings.exposure_ev.exp2() as f32,
            background,
            checker,
            turn: settings.turn as f32,
            cols: u32::try_from(grid.cols)?,
            pad: [0; 3],
            color: [color[0], color[1], color[2], 1.0],
            color2: [color2[0], color2[1], color2[2], 1.0],
        };
        let init = |label: &str, contents: &[u8], usage| self.gpu.buffer(label, contents, usage);
        let pbuf = init(
            "params",
            bytemuck::cast_slice(&params),
            wgpu::BufferUsages::STORAGE,
        );
        let ubuf = init(
            "view",
            bytemuck::bytes_of(&uniform),
            wgpu::BufferUsages::UNIFORM,
        );
        let mbuf = init(
            "models",
            bytemuck::cast_slice(&tiles),
            wgpu::BufferUsages::STORAGE,
        );
        self.pipelines.prepare(refs.iter().map(|r| r.model));
        let d = &self.gpu.device;
        let tbuf = self.tables.get(&self.gpu, &tables)?;
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lit sphere"),
            layout: &self.bind_layout,
            entries: &[
                entry(0, &pbuf),
                entry(1, &ubuf),
                entry(2, &mbuf),
                entry(8, tbuf),
            ],
        });
        let target = Target::ensure(&mut self.target, &self.gpu, width, height)?;
        // One draw per sphere, each clipped to its tile, with its model's
        // pipeline.
        let mut draws = Vec::with_capacity(refs.len());
        for (k, r) in refs.iter().enumerate() {
            let [x0, x1, y0, y1] = grid.pixels(k, width, height);
            if x1 <= x0 || y1 <= y0 {
                continue;
            }
            let Some(p) = self.pipelines.get(r.model) else {
                bail!("no pipeline could be built for model {}", r.model);
            };
            draws.push(fullscreen::Draw {
                pipeline: p,
                bind_group: &bind,
                scissor: Some([x0, y0, x1 - x0, y1 - y0]),
            });
        }
        let mut enc = d.create_command_encoder(&Default::default());
        fullscreen::pass(&mut enc, "lit sphere", &target.view, &draws);
        self.gpu.queue.submit([enc.finish()]);
        Ok(&target.texture)
    }

    /// Renders and reads the frame back (headless export).
    pub fn render_image(
        &mut self,
        models: &[ModelSpec],
        settings: &LitSphereSettings,
        width: u32,
        height: u32,
    ) -> Result<image::RgbaImage> {
        self.render(models, settings, width, height)?;
        let gpu = self.gpu.clone();
        let texture = &self.target.as_ref().map(|t| t.texture.clone());
        match texture {
            Some(t) => gpu.read_rgba8(t),
            None => bail!("no frame was rendered"),
        }
    }
}

fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}

/// The CPU reference of one frame: the same geometry, bv-core's f64 `eval`,
/// the same display transform (for tests and for checking a port by eye).
pub fn reference_image(
    models: &[ModelSpec],
    settings: &LitSphereSettings,
    width: u32,
    height: u32,
) -> Result<image::RgbaImage> {
    use super::display::{display, to_u8};
    use super::sphere::sphere_at;
    use glam::DVec2;
    // The turned surface through bv-core's change of frame (directions
    // rotated into the model's frame), not the shader's turned tangents, so
    // that the comparison checks one against the other.
    let brdfs = models
        .iter()
        .map(|m| {
            let b: std::sync::Arc<dyn bv_core::Brdf> = m.build()?.into();
            Ok(if settings.turn == 0.0 {
                b
            } else {
                std::sync::Arc::new(bv_core::rotated::Rotated::new(b, settings.turn))
            })
        })
        .collect::<bv_core::Result<Vec<_>>>()?;
    let light = settings.light.try_normalize().unwrap_or(DVec3::Z);
    let exposure = settings.exposure_ev.exp2();
    let size = DVec2::new(f64::from(width), f64::from(height));
    let mut img = image::RgbaImage::new(width, height);
    for (x, y, px) in img.enumerate_pixels_mut() {
        let p = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
        let c = match sphere_at(p, size, models.len()) {
            None => {
                let (c, c2, n, bg) = match settings.background {
                    Background::Flat(c) => (c, c, 1.0, 0),
                    Background::Checker { a, b, size } => (a, b, f64::from(size.max(1.0)), 1),
                };
                let odd = ((p.x / n).floor() as i64 + (p.y / n).floor() as i64) & 1 == 1;
                let c = if bg == 1 && odd { c2 } else { c };
                DVec3::new(c[0].into(), c[1].into(), c[2].into())
            }
            Some(s) => {
                let wi = s.to_local(light);
                let wo = s.to_local(DVec3::Z);
                let radiance = if wi.z > 0.0 {
                    brdfs[s.tile].eval(wi, wo) * wi.z * settings.irradiance
                } else {
                    DVec3::ZERO
                };
                display(radiance, exposure, settings.tone_map)
            }
        };
        *px = image::Rgba([to_u8(c.x), to_u8(c.y), to_u8(c.z), 255]);
    }
    Ok(img)
}
