//! Environment lighting: spheres (or tori) under an equirectangular HDR
//! environment, rendered progressively with multiple importance sampling of
//! the BRDF and of the environment (`shaders/env.wgsl`). Each [`EnvRenderer::render`] call adds one pass of
//! samples to a float accumulation buffer and shows the mean; any change of
//! models, settings, size or map restarts the accumulation. The map itself
//! (loading, the studio, its sampling CDFs) is CPU data in [`super::envmap`],
//! re-exported here.

use super::context::{Gpu, TARGET_FORMAT, Target};
use super::display::ToneMap;
use super::errors;
use super::fullscreen;
use super::pack::{TableBuffer, pack_all};
use super::shaders::ShaderLibrary;
use super::specialised::{Followed, ModelPipelines};
use anyhow::{Context, Result, bail};
use bv_core::ModelSpec;

pub use super::envmap::{EnvironmentMap, MAX_ENV_SIDE, STUDIO_HDR};

/// What stands under the environment, once per model (tile).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Object {
    /// A sphere (the lit sphere's geometry, `shaders/common/sphere.wgsl`).
    #[default]
    Sphere,
    /// A torus with its ring tilted towards the viewer, self-shadowing
    /// (`shaders/common/torus.wgsl`).
    Torus,
    /// A flat sample of infinite extent seen from an eye at
    /// [`EnvSettings::elevation`] above it (LECTURE.md N13: Fresnel at
    /// normal, mid and grazing angles; `plane_at` in env.wgsl). A smooth
    /// dielectric on it is a glass-coated dark floor: what it refracts is
    /// absorbed.
    Plane,
}

impl Object {
    /// Index the shader uses (`Frame.object` in env.wgsl).
    pub fn index(self) -> u32 {
        match self {
            Object::Sphere => 0,
            Object::Torus => 1,
            Object::Plane => 2,
        }
    }
}

/// Most interfaces a path through a transmitting object crosses or reflects
/// off inside it (`MAX_BOUNCES` in shaders/env.wgsl); the rest of a path
/// counts as dark. The view says so.
pub const MAX_BOUNCES: u32 = 16;

/// Settings of an environment-lit frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvSettings {
    /// Rotation of the environment about the vertical axis (radians).
    pub rotation: f64,
    /// Exposure in stops.
    pub exposure_ev: f64,
    /// Tone map after exposure.
    pub tone_map: ToneMap,
    /// Field of view of the background (degrees, vertical).
    pub background_fov_deg: f64,
    /// The surface turned about its normal (radians, from the tangent
    /// towards the bitangent).
    pub turn: f64,
    /// The plane object: the eye's elevation above the plane (radians;
    /// π/2 looks straight down).
    pub elevation: f64,
}

impl Default for EnvSettings {
    fn default() -> Self {
        Self {
            rotation: 0.0,
            exposure_ev: 0.0,
            tone_map: ToneMap::Aces,
            background_fov_deg: 60.0,
            turn: 0.0,
            elevation: 30f64.to_radians(),
        }
    }
}

#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FrameUniform {
    size: [f32; 2],
    tiles: u32,
    frame: u32,
    spp: u32,
    fov_tan: f32,
    object: u32,
    base: u32,
    x0: u32,
    x1: u32,
    y0: u32,
    y1: u32,
    turn: f32,
    cols: u32,
    band: u32,
    elevation: f32,
}

#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct EnvUniform {
    width: u32,
    height: u32,
    sampling: u32,
    marginal: u32,
    conditional: u32,
    rotation: f32,
    pad: [f32; 2],
}

#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShowUniform {
    size: [f32; 2],
    exposure: f32,
    tone: u32,
    y0: u32,
    pad: [u32; 3],
}

/// Rows `[y0, y0 + rows)` of the accumulation: rgb sum and sample count, four
/// f32 per pixel. A large image is split into bands so that each buffer fits
/// the device's storage binding limit (128 MiB on OpenGL, a 2900 × 2900
/// image).
struct Band {
    y0: u32,
    rows: u32,
    buffer: wgpu::Buffer,
}

/// Most GPU memory the accumulation of one image may take, however many
/// bands it is split into (an 8192 × 8192 image).
pub const MAX_ACCUMULATION_BYTES: u64 = 1 << 30;

struct EnvBuffers {
    /// Texels (rgb), marginal CDF, conditional CDFs, one after the other.
    data: wgpu::Buffer,
    marginal: u32,
    conditional: u32,
    size: (u32, u32),
    sampling: bool,
    generation: u64,
    /// The map's [`EnvironmentMap::unit`]: the accumulated samples are in
    /// this unit, and the display multiplies it back in with the exposure.
    unit: f32,
}

/// What the accumulated samples belong to; any difference restarts them.
#[derive(Debug, Clone, PartialEq)]
struct Key {
    models: Vec<ModelSpec>,
    rotation: f64,
    turn: f64,
    fov: f64,
    size: (u32, u32),
    env: u64,
    object: Object,
    elevation: f64,
}

/// The progressive environment renderer.
pub struct EnvRenderer {
    gpu: Gpu,
    frame_layout: wgpu::BindGroupLayout,
    map_layout: wgpu::BindGroupLayout,
    /// The accumulation pipelines, specialised per model.
    accumulate: ModelPipelines<wgpu::ComputePipeline>,
    show: wgpu::RenderPipeline,
    env: EnvBuffers,
    /// The accumulation, band by band (empty before the first pass).
    accum: Vec<Band>,
    /// The image size the bands cover.
    accum_size: Option<(u32, u32)>,
    /// Largest band in bytes, below the device's limit (tests force
    /// several bands on small images).
    max_band_bytes: Option<u64>,
    key: Option<Key>,
    frame: u32,
    samples: u64,
    target: Option<Target>,
    object: Object,
    tables: TableBuffer,
}

impl std::fmt::Debug for EnvRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EnvRenderer")
            .field("frame", &self.frame)
            .field("samples", &self.samples)
            .finish_non_exhaustive()
    }
}

const WORKGROUP: u32 = 8;

/// The bindings of env.wgsl (group 0: the frame; group 1: the map), all
/// visible to the compute stage: one layout for the generic and the
/// specialised pipelines (a specialised shader may leave some unused).
fn bind_group_layouts(device: &wgpu::Device) -> (wgpu::BindGroupLayout, wgpu::BindGroupLayout) {
    let buffer = |binding, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let read = wgpu::BufferBindingType::Storage { read_only: true };
    let frame = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("env frame"),
        entries: &[
            buffer(0, read),
            buffer(1, wgpu::BufferBindingType::Uniform),
            buffer(2, read),
            buffer(3, wgpu::BufferBindingType::Storage { read_only: false }),
            buffer(8, read),
        ],
    });
    let map = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("env map"),
        entries: &[buffer(0, wgpu::BufferBindingType::Uniform), buffer(1, read)],
    });
    (frame, map)
}

fn compute_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("env accumulate"),
        layout: Some(layout),
        module,
        entry_point: Some("accumulate"),
        compilation_options: Default::default(),
        cache: None,
    })
}

impl EnvRenderer {
    /// Adopts a changed catalogue (a user's model saved): only the
    /// pipelines whose code changed are built again (see
    /// [`super::specialised::ModelPipelines::follow_catalogue`]). The
    /// accumulation restarts when the new code draws: at once, or when the
    /// replacements arrive ([`Self::poll_pipelines`]), not for the stale
    /// pipelines drawing the old picture meanwhile.
    pub fn follow_catalogue(&mut self) -> Followed {
        let followed = self.accumulate.follow_catalogue();
        if followed.redraw {
            self.key = None;
        }
        followed
    }

    /// Takes the pipelines that finished compiling after a catalogue change
    /// (the accumulation restarts with them): `(arrived, waiting)`.
    pub fn poll_pipelines(&mut self) -> (bool, bool) {
        let (arrived, waiting) = self.accumulate.poll();
        if arrived {
            self.key = None;
        }
        (arrived, waiting)
    }

    /// Builds the pipelines and uploads `map`.
    pub fn new(gpu: Gpu, library: &mut ShaderLibrary, map: &EnvironmentMap) -> Result<Self> {
        let device = gpu.device.clone();
        errors::scoped(&device, "building the environment renderer", || {
            Self::build(gpu, library, map)
        })
    }

    fn build(gpu: Gpu, library: &mut ShaderLibrary, map: &EnvironmentMap) -> Result<Self> {
        // params, tiles, accumulation, environment map and MERL tables.
        let have = gpu.device.limits().max_storage_buffers_per_shader_stage;
        if have < 5 {
            bail!(
                "the environment view needs 5 storage buffers per shader stage; this device \
                 allows {have} (a downlevel or OpenGL device: try the Vulkan, Metal or DX12 backend)"
            );
        }
        let module = library.shader_module(&gpu.device, "env")?;
        let (frame_layout, map_layout) = bind_group_layouts(&gpu.device);
        let layout = gpu
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("env accumulate"),
                bind_group_layouts: &[Some(&frame_layout), Some(&map_layout)],
                immediate_size: 0,
            });
        let generic = compute_pipeline(&gpu.device, &layout, &module);
        let accumulate =
            ModelPipelines::new(&gpu.device, "env", layout, compute_pipeline, generic)?;
        let show_module = library.shader_module(&gpu.device, "env_display")?;
        let show = fullscreen::pipeline(
            &gpu.device,
            "env display",
            None,
            &show_module,
            TARGET_FORMAT,
        );
        let env = Self::upload(&gpu, map, 0)?;
        Ok(Self {
            gpu,
            frame_layout,
            map_layout,
            accumulate,
            show,
            env,
            accum: Vec::new(),
            accum_size: None,
            max_band_bytes: None,
            key: None,
            frame: 0,
            samples: 0,
            target: None,
            object: Object::Sphere,
            tables: TableBuffer::default(),
        })
    }

    fn upload(gpu: &Gpu, map: &EnvironmentMap, generation: u64) -> Result<EnvBuffers> {
        if map.width == 0
            || map.height == 0
            || map.texels.len() != (map.width * map.height) as usize
        {
            bail!(
                "environment map {}×{} has {} texels",
                map.width,
                map.height,
                map.texels.len()
            );
        }
        let (marginal, conditional, sampling) = map.cdfs();
        let mut data: Vec<f32> = map.texels.iter().flatten().copied().collect();
        let m = u32::try_from(data.len())?;
        data.extend_from_slice(&marginal);
        let c = u32::try_from(data.len())?;
        data.extend_from_slice(&conditional);
        let what = format!("an environment map of {}×{}", map.width, map.height);
        errors::check_buffer(
            &gpu.device,
            &what,
            4 * data.len() as u64,
            true,
            "use a smaller map",
        )?;
        let buffer = gpu.scoped(&format!("uploading {what}"), || {
            Ok(gpu.buffer(
                "env data",
                bytemuck::cast_slice(&data),
                wgpu::BufferUsages::STORAGE,
            ))
        })?;
        Ok(EnvBuffers {
            data: buffer,
            marginal: m,
            conditional: c,
            size: (map.width, map.height),
            sampling,
            generation,
            unit: map.unit,
        })
    }

    /// Replaces the environment (restarts the accumulation).
    pub fn set_environment(&mut self, map: &EnvironmentMap) -> Result<()> {
        self.env = Self::upload(&self.gpu, map, self.env.generation + 1)?;
        Ok(())
    }

    /// Chooses the object drawn under the environment (restarts the
    /// accumulation when it changes).
    pub fn set_object(&mut self, object: Object) {
        self.object = object;
    }

    /// The object drawn under the environment.
    pub fn object(&self) -> Object {
        self.object
    }

    /// Shows the samples accumulated so far again (after a change of exposure
    /// or tone map, which need no new samples) without adding any.
    pub fn display(
        &mut self,
        settings: &EnvSettings,
        width: u32,
        height: u32,
    ) -> Result<&wgpu::Texture> {
        // `show` refuses a size with nothing accumulated.
        self.show(settings, width, height)
    }

    /// Whether the next [`EnvRenderer::render`] with these arguments would
    /// restart the accumulation.
    pub fn would_restart(
        &self,
        models: &[ModelSpec],
        settings: &EnvSettings,
        width: u32,
        height: u32,
    ) -> bool {
        !self.key_matches(models, settings, width, height)
    }

    /// Samples per pixel accumulated so far (each counts one BRDF and one
    /// environment sample).
    pub fn samples_per_pixel(&self) -> u64 {
        self.samples
    }

    /// The device it renders on.
    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// Caps each band of the accumulation at `bytes` (at most the device's
    /// limit; `None`: the limit). The image is the same whatever the split:
    /// tests use it to check the bands on small images.
    pub fn set_max_band_bytes(&mut self, bytes: Option<u64>) {
        self.max_band_bytes = bytes;
        // The next pass restarts with the new split.
        self.key = None;
    }

    /// How many bands the accumulation is split into (0 before a pass).
    pub fn band_count(&self) -> usize {
        self.accum.len()
    }

    /// Adds one pass of `spp` samples per pixel (restarting first if anything
    /// changed) and returns the displayed mean in the renderer's texture.
    pub fn render(
        &mut self,
        models: &[ModelSpec],
        settings: &EnvSettings,
        width: u32,
        height: u32,
        spp: u32,
    ) -> Result<&wgpu::Texture> {
        self.accumulate_pass(models, settings, width, height, spp)?;
        self.show(settings, width, height)
    }

    /// Renders until `spp` samples per pixel are accumulated (in passes of at
    /// most 64) and reads the frame back (headless export).
    pub fn render_image(
        &mut self,
        models: &[ModelSpec],
        settings: &EnvSettings,
        width: u32,
        height: u32,
        spp: u32,
    ) -> Result<image::RgbaImage> {
        self.accumulate_to(models, settings, width, height, spp)?;
        let texture = self.show(settings, width, height)?.clone();
        self.gpu.read_rgba8(&texture)
    }

    /// Accumulates until `spp` samples per pixel and returns the mean
    /// radiance per pixel (row-major rgb), for tests and HDR export.
    pub fn render_radiance(
        &mut self,
        models: &[ModelSpec],
        settings: &EnvSettings,
        width: u32,
        height: u32,
        spp: u32,
    ) -> Result<Vec<[f32; 3]>> {
        self.accumulate_to(models, settings, width, height, spp)?;
        if self.accum.is_empty() {
            bail!("no accumulation buffer");
        }
        let mut out = Vec::with_capacity(width as usize * height as usize);
        for band in &self.accum {
            let size = band.buffer.size();
            let bytes = self.gpu.scoped("reading the environment back", || {
                self.gpu.read_buffer(&band.buffer, size)
            })?;
            let v: &[f32] = bytemuck::cast_slice(&bytes);
            out.extend(v.chunks_exact(4).map(|c| {
                let n = c[3].max(1.0);
                [c[0] / n, c[1] / n, c[2] / n]
            }));
        }
        Ok(out)
    }

    fn accumulate_to(
        &mut self,
        models: &[ModelSpec],
        settings: &EnvSettings,
        width: u32,
        height: u32,
        spp: u32,
    ) -> Result<()> {
        // A first zero-sample-free pass establishes the key (and restarts if needed).
        loop {
            let done = if self.key_matches(models, settings, width, height) {
                self.samples
            } else {
                0
            };
            if done >= u64::from(spp) {
                break;
            }
            let pass = (u64::from(spp) - done).min(64) as u32;
            self.accumulate_pass(models, settings, width, height, pass)?;
        }
        self.gpu.wait()
    }

    fn key(&self, models: &[ModelSpec], settings: &EnvSettings, width: u32, height: u32) -> Key {
        Key {
            models: models.to_vec(),
            rotation: settings.rotation,
            turn: settings.turn,
            fov: settings.background_fov_deg,
            size: (width, height),
            env: self.env.generation,
            object: self.object,
            // Only the plane depends on it: a sphere keeps its samples.
            elevation: if self.object == Object::Plane {
                settings.elevation
            } else {
                0.0
            },
        }
    }

    fn key_matches(
        &self,
        models: &[ModelSpec],
        settings: &EnvSettings,
        width: u32,
        height: u32,
    ) -> bool {
        self.key.as_ref() == Some(&self.key(models, settings, width, height))
    }

    fn accumulate_pass(
        &mut self,
        models: &[ModelSpec],
        settings: &EnvSettings,
        width: u32,
        height: u32,
        spp: u32,
    ) -> Result<()> {
        let device = self.gpu.device.clone();
        let result = errors::scoped(&device, "rendering the environment", || {
            self.accumulate_pass_unscoped(models, settings, width, height, spp)
        });
        if result.is_err() {
            // Whatever was accumulated is not to be trusted: the next pass
            // starts afresh.
            self.key = None;
            self.accum.clear();
            self.accum_size = None;
        }
        result
    }

    fn accumulate_pass_unscoped(
        &mut self,
        models: &[ModelSpec],
        settings: &EnvSettings,
        width: u32,
        height: u32,
        spp: u32,
    ) -> Result<()> {
        if models.is_empty() {
            bail!("the environment view needs at least one model");
        }
        let key = self.key(models, settings, width, height);
        let d = self.gpu.device.clone();
        if self.key.as_ref() != Some(&key) || self.accum.is_empty() {
            // Restart: fresh, zeroed accumulation bands.
            self.accum.clear();
            self.accum_size = None;
            self.key = None;
            let rows = band_rows(&d, width, height, self.max_band_bytes)?;
            let mut y0 = 0;
            while y0 < height {
                let n = rows.min(height - y0);
                self.accum.push(Band {
                    y0,
                    rows: n,
                    buffer: d.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("env accum"),
                        size: accumulation_bytes(width, n),
                        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                        mapped_at_creation: false,
                    }),
                });
                y0 += n;
            }
            self.accum_size = Some((width, height));
            self.key = Some(key);
            self.frame = 0;
            self.samples = 0;
        }
        let (params, refs, tables) = pack_all(models)?;
        self.accumulate.prepare(refs.iter().map(|r| r.model));
        if self.accum.is_empty() {
            bail!("no accumulation buffer");
        }
        let tbuf = self.tables.get(&self.gpu, &tables)?;
        let tiles: Vec<[u32; 2]> = refs.iter().map(|r| [r.model, r.offset]).collect();
        let grid = super::sphere::Grid::new(
            models.len(),
            glam::DVec2::new(f64::from(width), f64::from(height)),
        );
        let frame = FrameUniform {
            size: [width as f32, height as f32],
            tiles: u32::try_from(models.len())?,
            frame: self.frame,
            spp: spp.max(1),
            fov_tan: (0.5 * settings.background_fov_deg.to_radians()).tan() as f32,
            object: self.object.index(),
            // Sequences restart after 2^32 samples per pixel (never in practice).
            base: self.samples as u32,
            x0: 0,
            x1: width,
            y0: 0,
            y1: height,
            turn: settings.turn as f32,
            cols: u32::try_from(grid.cols)?,
            band: 0,
            elevation: settings.elevation as f32,
        };
        let env = EnvUniform {
            width: self.env.size.0,
            height: self.env.size.1,
            sampling: u32::from(self.env.sampling),
            marginal: self.env.marginal,
            conditional: self.env.conditional,
            rotation: settings.rotation as f32,
            pad: [0.0; 2],
        };
        let init = |label: &str, contents: &[u8], usage| self.gpu.buffer(label, contents, usage);
        let pbuf = init(
            "params",
            bytemuck::cast_slice(&params),
            wgpu::BufferUsages::STORAGE,
        );
        let mbuf = init(
            "models",
            bytemuck::cast_slice(&tiles),
            wgpu::BufferUsages::STORAGE,
        );
        let ebuf = init(
            "env info",
            bytemuck::bytes_of(&env),
            wgpu::BufferUsages::UNIFORM,
        );
        let g1 = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("env map"),
            layout: &self.map_layout,
            entries: &[entry(0, &ebuf), entry(1, &self.env.data)],
        });
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_bind_group(1, &g1, &[]);
            // One dispatch per band and tile, over the tile's columns and
            // the band's rows, with the tile's model's pipeline.
            for band in &self.accum {
                for (k, r) in refs.iter().enumerate() {
                    let [x0, x1, ty0, ty1] = grid.pixels(k, width, height);
                    // The rows of the tile in this band.
                    let (y0, y1) = (ty0.max(band.y0), ty1.min(band.y0 + band.rows));
                    if x1 <= x0 || y1 <= y0 {
                        continue;
                    }
                    let fbuf = init(
                        "frame",
                        bytemuck::bytes_of(&FrameUniform {
                            x0,
                            x1,
                            y0,
                            y1,
                            band: band.y0,
                            ..frame
                        }),
                        wgpu::BufferUsages::UNIFORM,
                    );
                    let g0 = d.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("env frame"),
                        layout: &self.frame_layout,
                        entries: &[
                            entry(0, &pbuf),
                            entry(1, &fbuf),
                            entry(2, &mbuf),
                            entry(3, &band.buffer),
                            entry(8, tbuf),
                        ],
                    });
                    let Some(p) = self.accumulate.get(r.model) else {
                        bail!("no pipeline could be built for model {}", r.model);
                    };
                    pass.set_pipeline(p);
                    pass.set_bind_group(0, &g0, &[]);
                    pass.dispatch_workgroups(
                        (x1 - x0).div_ceil(WORKGROUP),
                        (y1 - y0).div_ceil(WORKGROUP),
                        1,
                    );
                }
            }
        }
        self.gpu.queue.submit([enc.finish()]);
        self.frame = self.frame.wrapping_add(1);
        self.samples += u64::from(spp.max(1));
        Ok(())
    }

    fn show(&mut self, settings: &EnvSettings, width: u32, height: u32) -> Result<&wgpu::Texture> {
        let device = self.gpu.device.clone();
        errors::scoped(&device, "displaying the environment", || {
            self.show_unscoped(settings, width, height).map(|_| ())
        })?;
        self.target
            .as_ref()
            .map(|t| &t.texture)
            .context("no environment image")
    }

    fn show_unscoped(
        &mut self,
        settings: &EnvSettings,
        width: u32,
        height: u32,
    ) -> Result<&wgpu::Texture> {
        if self.accum.is_empty() || self.accum_size != Some((width, height)) {
            bail!("nothing rendered yet at {width}×{height}");
        }
        let d = &self.gpu.device;
        let layout = self.show.get_bind_group_layout(0);
        let binds: Vec<(&Band, wgpu::BindGroup)> = self
            .accum
            .iter()
            .map(|band| {
                let u = ShowUniform {
                    size: [width as f32, height as f32],
                    // In f64, then to f32: finite (the unit is at most 2⁸⁸,
                    // the exposure 2¹²); the display clamps what overflows.
                    exposure: (settings.exposure_ev.exp2() * f64::from(self.env.unit)) as f32,
                    tone: settings.tone_map.index(),
                    y0: band.y0,
                    pad: [0; 3],
                };
                let ubuf =
                    self.gpu
                        .buffer("show", bytemuck::bytes_of(&u), wgpu::BufferUsages::UNIFORM);
                let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("env display"),
                    layout: &layout,
                    entries: &[entry(0, &ubuf), entry(1, &band.buffer)],
                });
                (band, bind)
            })
            .collect();
        let target = Target::ensure(&mut self.target, &self.gpu, width, height)?;
        // Each band draws its rows only (the shader indexes its buffer from
        // the band's first row).
        let draws: Vec<fullscreen::Draw<'_>> = binds
            .iter()
            .map(|(band, bind)| fullscreen::Draw {
                pipeline: &self.show,
                bind_group: bind,
                scissor: Some([0, band.y0, width, band.rows]),
            })
            .collect();
        let mut enc = d.create_command_encoder(&Default::default());
        fullscreen::pass(&mut enc, "env display", &target.view, &draws);
        self.gpu.queue.submit([enc.finish()]);
        Ok(&target.texture)
    }
}

/// Rows per band of a `width`×`height` accumulation: as many as one storage
/// binding of the device holds (at most `cap` bytes), after checking the
/// image against the device's texture size and [`MAX_ACCUMULATION_BYTES`].
fn band_rows(device: &wgpu::Device, width: u32, height: u32, cap: Option<u64>) -> Result<u32> {
    if width == 0 || height == 0 {
        bail!("image size {width}×{height} is empty");
    }
    errors::check_texture(device, "an environment image", width, height)?;
    let total = accumulation_bytes(width, height);
    if total > MAX_ACCUMULATION_BYTES {
        bail!(
            "an environment image of {width}×{height} pixels needs {} MiB for its samples, \
             bv allows at most {} MiB; use a smaller --width/--height",
            total >> 20,
            MAX_ACCUMULATION_BYTES >> 20
        );
    }
    let l = device.limits();
    let limit = l
        .max_buffer_size
        .min(l.max_storage_buffer_binding_size)
        .min(cap.unwrap_or(u64::MAX));
    let row = accumulation_bytes(width, 1);
    if row > limit {
        bail!(
            "an environment image {width} pixels wide needs {row} bytes per row, this device \
             binds at most {limit} bytes; use a smaller --width"
        );
    }
    Ok(u32::try_from(limit / row)
        .unwrap_or(u32::MAX)
        .clamp(1, height))
}

/// Bytes of the accumulation buffer of a `width`×`height` image: four f32
/// (rgb sum and sample count) per pixel.
pub fn accumulation_bytes(width: u32, height: u32) -> u64 {
    16 * u64::from(width) * u64::from(height)
}

fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}
