//! A wgpu pipeline cache kept on disk between runs, where the backend has one
//! (Vulkan: `VkPipelineCache`). A driver that fills it skips compiling the
//! shaders of a pipeline it has seen, which is most of a cold start on
//! drivers without a cache of their own. One file per adapter, named by
//! [`wgpu::util::pipeline_cache_key`], under the user's cache folder
//! (`$BV_CACHE_DIR`, else `$XDG_CACHE_HOME/bv`, else `~/.cache/bv`).
//!
//! The data is the driver's and is never required: wgpu checks its header
//! (backend, adapter, driver version) and falls back to an empty cache when it
//! does not match, and a file that cannot be read or written only means
//! compiling as if there were none.

use std::path::PathBuf;

/// The device feature the cache needs (asked for wherever the adapter has it).
pub const FEATURE: wgpu::Features = wgpu::Features::PIPELINE_CACHE;

/// Environment variable naming the folder the cache is kept in.
pub const DIR_ENV: &str = "BV_CACHE_DIR";

/// Files larger than this are not read: a cache is kilobytes to a few
/// megabytes, and a huge file there is not one bv wrote.
const MAX_BYTES: u64 = 64 << 20;

/// A pipeline cache and the file it is kept in.
#[derive(Debug)]
pub struct DiskPipelineCache {
    cache: wgpu::PipelineCache,
    path: PathBuf,
    /// What the file held when it was read, so that an unchanged cache is
    /// not written again.
    loaded: Option<Vec<u8>>,
}

/// The folder caches are kept in, if the environment names one.
fn cache_dir() -> Option<PathBuf> {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var(DIR_ENV)
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("bv")))
        .or_else(|| var("HOME").map(|h| h.join(".cache").join("bv")))
}

impl DiskPipelineCache {
    /// The cache of the adapter `info` describes, loaded from its file when
    /// there is one; `None` where the device lacks [`FEATURE`] (every backend
    /// but Vulkan) or no cache folder is known.
    pub fn open(device: &wgpu::Device, info: &wgpu::AdapterInfo) -> Option<Self> {
        if !device.features().contains(FEATURE) {
            return None;
        }
        let key = wgpu::util::pipeline_cache_key(info)?;
        let path = cache_dir()?.join(format!("{key}.bin"));
        let data = std::fs::metadata(&path)
            .ok()
            .filter(|m| m.is_file() && m.len() <= MAX_BYTES)
            .and_then(|_| std::fs::read(&path).ok());
        // SAFETY: wgpu requires the data to come from `PipelineCache::get_data`
        // on a compatible adapter. The file is named by the adapter's key and
        // only ever written by `save` below; wgpu validates the header it puts
        // in front of the driver's data (backend, adapter, driver version,
        // length) and, with `fallback`, starts empty on any mismatch.
        let cache = unsafe {
            device.create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
                label: Some("bv pipelines"),
                data: data.as_deref(),
                fallback: true,
            })
        };
        Some(Self {
            cache,
            path,
            loaded: data,
        })
    }

    /// The cache, for `RenderPipelineDescriptor::cache`.
    pub fn cache(&self) -> &wgpu::PipelineCache {
        &self.cache
    }

    /// Writes the cache's data to its file (a temporary file renamed over
    /// it, so that a reader never sees half a cache). Failing is harmless:
    /// the next run compiles what it needs.
    pub fn save(&self) -> std::io::Result<()> {
        let Some(data) = self.cache.get_data() else {
            return Ok(());
        };
        if self.loaded.as_ref() == Some(&data) {
            return Ok(());
        }
        if let Some(dir) = self.path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        let temp = self
            .path
            .with_extension(format!("{}.tmp", std::process::id()));
        std::fs::write(&temp, &data)?;
        std::fs::rename(&temp, &self.path).inspect_err(|_| {
            let _ = std::fs::remove_file(&temp);
        })
    }

    /// The file the cache is kept in.
    pub fn path(&self) -> &std::path::Path {
        &self.path
    }
}
