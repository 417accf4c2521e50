//! The device the renderers share: opened headless here ([`Headless`], the
//! one opener of bv, also under `bv render`'s egui renderer), or handed over
//! by the GUI's egui-wgpu render state; the limits bv asks of it; and the
//! offscreen colour [`Target`] the renderers draw into.

use super::errors::{self, ErrorLog};
use super::readback;
use anyhow::{Context, Result, anyhow};

/// Environment variable that lets GPU tests pass without an adapter (for
/// machines that cannot install lavapipe); CI installs it and must not skip.
pub const SKIP_ENV: &str = "BV_SKIP_GPU_TESTS";

/// A wgpu device and its queue.
#[derive(Debug, Clone)]
pub struct Gpu {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// What the adapter is (name, backend, device type), for reports.
    pub info: wgpu::AdapterInfo,
    /// The device's uncaptured errors (recorded, never a panic).
    pub errors: ErrorLog,
}

/// A device opened headless, with what an egui-wgpu renderer also needs
/// (the instance and the adapter).
#[derive(Debug)]
pub struct Headless {
    /// The wgpu instance the adapter came from.
    pub instance: wgpu::Instance,
    /// The adapter.
    pub adapter: wgpu::Adapter,
    /// The device, with [`limits`].
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
}

impl Headless {
    /// Opens the first adapter wgpu finds, preferring a real GPU (on a
    /// machine without one, Mesa's lavapipe: `apt-get install libvulkan1
    /// mesa-vulkan-drivers`); without any, the error is
    /// [`errors::no_gpu_message`].
    ///
    /// The native APIs (Vulkan, Metal, DX12) are asked first and OpenGL only
    /// when none of them has an adapter: starting wgpu's GL backend (EGL)
    /// took 10 of the 36 ms a headless start cost on a lavapipe machine,
    /// for an adapter that Vulkan's would have been preferred to anyway.
    /// `WGPU_BACKEND`, when set, is obeyed as it stands.
    pub fn open() -> Result<Self> {
        let request = |only: Option<wgpu::Backends>| {
            let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
            if let Some(only) = only {
                desc.backends &= only;
            }
            let instance = wgpu::Instance::new(desc);
            let adapter =
                pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                    power_preference: wgpu::PowerPreference::HighPerformance,
                    force_fallback_adapter: false,
                    compatible_surface: None,
                    ..Default::default()
                }));
            adapter.map(|a| (instance, a))
        };
        let found = if std::env::var_os("WGPU_BACKEND").is_some() {
            request(None)
        } else {
            request(Some(wgpu::Backends::PRIMARY)).or_else(|_| request(None))
        };
        let (instance, adapter) =
            found.map_err(|e| anyhow!(errors::no_gpu_message(&e.to_string())))?;
        Self::on(instance, adapter)
    }

    /// Opens a device with [`limits`] on `adapter`.
    fn on(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Self> {
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("bv"),
            // Where the adapter keeps pipeline caches, bv keeps one on disk.
            required_features: adapter.features() & super::pipeline_cache::FEATURE,
            required_limits: limits(&adapter),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .with_context(|| format!("opening a device on {}", info.name))?;
        Ok(Self {
            instance,
            adapter,
            device,
            queue,
        })
    }
}

impl Gpu {
    /// Opens a device headless ([`Headless::open`]).
    pub fn headless() -> Result<Self> {
        let h = Headless::open()?;
        let info = h.adapter.get_info();
        Ok(Self::from_parts(h.device, h.queue, info))
    }

    /// Wraps a device opened elsewhere (the GUI's render state); its
    /// uncaptured errors are recorded from now on instead of panicking.
    pub fn from_parts(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> Self {
        let errors = errors::watch(&device);
        Self {
            device,
            queue,
            info,
            errors,
        }
    }

    /// Runs `work` inside error scopes of this device (see
    /// [`errors::scoped`]): a validation or out-of-memory error becomes an
    /// `Err` naming `what`.
    pub fn scoped<T>(&self, what: &str, work: impl FnOnce() -> Result<T>) -> Result<T> {
        errors::scoped(&self.device, what, work)
    }

    /// One line naming the adapter: `llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Cpu)`.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }

    /// Blocks until all submitted work is done.
    pub fn wait(&self) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| anyhow!("waiting for the GPU: {e}"))
    }

    /// Copies the first `len` bytes of a `COPY_SRC` buffer back to the CPU
    /// ([`readback::read_buffer`]).
    pub fn read_buffer(&self, buffer: &wgpu::Buffer, len: u64) -> Result<Vec<u8>> {
        readback::read_buffer(&self.device, &self.queue, buffer, len)
    }
}

/// What a headless device asks for: the downlevel defaults (so that what
/// works here works on modest hardware), with the adapter's texture and
/// buffer sizes (a figure's size is what the user asks for, and every buffer
/// or texture sized from an image is checked against the device's limits,
/// so a larger figure on a larger GPU is drawn, not refused) and up to 8
/// storage buffers per shader stage. The environment pass binds 5
/// (parameters, tiles, accumulation, environment map, MERL tables); downlevel
/// promises only 4, while every Vulkan, Metal and DX12 device has at least 8,
/// which is also what egui-wgpu's window device requests (`Limits::default()`).
pub fn limits(adapter: &wgpu::Adapter) -> wgpu::Limits {
    let have = adapter.limits();
    let mut l = wgpu::Limits::downlevel_defaults().using_resolution(have.clone());
    l.max_buffer_size = have.max_buffer_size;
    l.max_storage_buffer_binding_size = have.max_storage_buffer_binding_size;
    l.max_storage_buffers_per_shader_stage = have
        .max_storage_buffers_per_shader_stage
        .min(8)
        .max(l.max_storage_buffers_per_shader_stage);
    l
}

/// Opens the headless device for a test. Without an adapter the test FAILS
/// with a clear message (CI installs lavapipe, so a silent skip would hide
/// breakage) unless `BV_SKIP_GPU_TESTS=1`, in which case `None` is returned
/// and the caller returns early.
pub fn gpu_for_test() -> Option<Gpu> {
    match Gpu::headless() {
        Ok(g) => Some(g),
        Err(e) if std::env::var(SKIP_ENV).as_deref() == Ok("1") => {
            eprintln!("skipping GPU test ({SKIP_ENV}=1): {e:#}");
            None
        }
        Err(e) => panic!(
            "GPU test needs an adapter: {e:#}\n(set {SKIP_ENV}=1 to skip GPU tests on a machine \
             without one)"
        ),
    }
}

impl Gpu {
    /// A buffer holding `contents` (the per-frame parameter, tile and uniform
    /// buffers of every renderer are made this way).
    pub fn buffer(&self, label: &str, contents: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
        buffer_init(&self.device, &self.queue, label, contents, usage)
    }

    /// Reads an `Rgba8Unorm` texture (with `COPY_SRC`) back as an image
    /// ([`readback::read_rgba8`]).
    pub fn read_rgba8(&self, texture: &wgpu::Texture) -> Result<image::RgbaImage> {
        readback::read_rgba8(&self.device, &self.queue, texture)
    }
}

/// An offscreen colour target that is re-created only when its size changes.
#[derive(Debug)]
pub struct Target {
    /// The texture (`Rgba8Unorm`, sRGB-encoded values; render attachment,
    /// texture binding and copy source, so that a GUI can show it directly).
    pub texture: wgpu::Texture,
    /// Its default view.
    pub view: wgpu::TextureView,
}

/// Format of every offscreen target (values are already sRGB-encoded by the shaders).
pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

impl Target {
    /// A target of the given size (at least 1×1, at most the device's limit).
    pub fn new(gpu: &Gpu, width: u32, height: u32) -> Result<Self> {
        errors::check_texture(&gpu.device, "an image", width, height)?;
        let texture = gpu.scoped("creating an image", || {
            Ok(gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("bv target"),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: TARGET_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                // A GUI that samples through an sRGB view (decoding to linear) may
                // create one of the same texture, where the device can (OpenGL
                // cannot reinterpret a texture's format).
                view_formats: if gpu.info.backend != wgpu::Backend::Gl {
                    &[wgpu::TextureFormat::Rgba8UnormSrgb]
                } else {
                    &[]
                },
            }))
        })?;
        let view = texture.create_view(&Default::default());
        Ok(Self { texture, view })
    }

    /// Keeps `slot`'s target if it has the size, else makes a new one.
    pub fn ensure<'a>(
        slot: &'a mut Option<Target>,
        gpu: &Gpu,
        width: u32,
        height: u32,
    ) -> Result<&'a Target> {
        let fits = slot
            .as_ref()
            .is_some_and(|t| t.texture.width() == width && t.texture.height() == height);
        if !fits {
            *slot = Some(Target::new(gpu, width, height)?);
        }
        slot.as_ref().context("target")
    }
}

/// A buffer of `device` holding `contents`. On the desktop it is mapped at
/// creation (wgpu's `create_buffer_init`). In a browser a buffer mapped at
/// creation throws once the page's GPU device is lost, and wgpu's web
/// backend turns that into a panic; a plain buffer written through the queue
/// only records an error there, so the page shows the loss instead.
pub fn buffer_init(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    contents: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    #[cfg(not(target_arch = "wasm32"))]
    {
        use wgpu::util::DeviceExt;
        let _ = queue;
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        })
    }
    #[cfg(target_arch = "wasm32")]
    {
        // Writes through the queue come in multiples of four bytes.
        let align = wgpu::COPY_BUFFER_ALIGNMENT as usize;
        let size = contents.len().max(1).div_ceil(align) * align;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size as u64,
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut padded = contents.to_vec();
        padded.resize(size, 0);
        queue.write_buffer(&buffer, 0, &padded);
        buffer
    }
}
