//! The device the renderers share: opened headless here, or handed over by the
//! GUI's egui-wgpu render state.

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
}

impl Gpu {
    /// Opens the first adapter wgpu finds (on a machine without a GPU, Mesa's
    /// lavapipe: `apt-get install libvulkan1 mesa-vulkan-drivers`).
    pub fn headless() -> Result<Self> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| {
            anyhow!(
                "no GPU adapter found ({e}); on a machine without a GPU install Mesa's \
                 software Vulkan (apt-get install libvulkan1 mesa-vulkan-drivers)"
            )
        })?;
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("bv"),
            required_features: wgpu::Features::empty(),
            required_limits: wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .with_context(|| format!("opening a device on {}", info.name))?;
        Ok(Self {
            device,
            queue,
            info,
        })
    }

    /// Wraps a device opened elsewhere (the GUI's render state).
    pub fn from_parts(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> Self {
        Self {
            device,
            queue,
            info,
        }
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

    /// Copies a `MAP_READ` buffer's first `len` bytes back to the CPU.
    pub fn read_buffer(&self, buffer: &wgpu::Buffer, len: u64) -> Result<Vec<u8>> {
        let slice = buffer.slice(..len);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            // The receiver lives until recv() below returns.
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv()
            .context("the GPU dropped a buffer mapping")?
            .map_err(|e| anyhow!("mapping a readback buffer: {e}"))?;
        let bytes = slice
            .get_mapped_range()
            .map_err(|e| anyhow!("reading a mapped buffer: {e:?}"))?
            .to_vec();
        buffer.unmap();
        Ok(bytes)
    }
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
