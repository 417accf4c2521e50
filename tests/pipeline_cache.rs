//! The pipeline cache kept on disk (`bv::gpu::pipeline_cache`): written where
//! the device has one, and never in the way: a corrupt file, or a folder that
//! cannot be written, still gives working pipelines.
//!
//! One test in its own binary: it sets `BV_CACHE_DIR`, which no other test
//! may see change.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::gpu::Headless;
use bv::gpu::lobe::LobeRenderer;
use bv::gpu::pipeline_cache::{DIR_ENV, DiskPipelineCache, FEATURE};

fn set_dir(dir: &std::path::Path) {
    // SAFETY: the only test of this binary; nothing else reads the
    // environment meanwhile.
    unsafe { std::env::set_var(DIR_ENV, dir) };
}

#[test]
fn the_cache_is_written_and_a_bad_one_is_harmless() {
    let h = match Headless::open() {
        Ok(h) => h,
        Err(e) if std::env::var(bv::gpu::context::SKIP_ENV).as_deref() == Ok("1") => {
            eprintln!("skipping: {e:#}");
            return;
        }
        Err(e) => panic!("GPU test needs an adapter: {e:#}"),
    };
    let errors = bv::gpu::errors::watch(&h.device);
    let info = h.adapter.get_info();
    let tmp = std::env::temp_dir().join(format!("bv-pipeline-cache-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    set_dir(&tmp);
    let make = || LobeRenderer::new(&h.device, Some(&h.adapter), wgpu::TextureFormat::Rgba8Unorm);

    if !h.device.features().contains(FEATURE) {
        // Not Vulkan: no cache, no file, pipelines all the same.
        assert!(DiskPipelineCache::open(&h.device, &info).is_none());
        make().unwrap();
        assert!(!tmp.exists(), "a cache folder without a cache");
        return;
    }
    let path = DiskPipelineCache::open(&h.device, &info)
        .expect("a device with the feature has a cache")
        .path()
        .to_path_buf();
    assert!(path.starts_with(&tmp), "{path:?} is not under {DIR_ENV}");

    // First run: the file appears, with the driver's data behind wgpu's header.
    make().unwrap();
    let first = std::fs::read(&path).expect("the cache file is written");
    assert!(!first.is_empty());

    // A corrupt file (another wgpu, a truncated write): wgpu falls back to an
    // empty cache, the pipelines are made, and a good cache replaces it.
    let garbage = b"not a pipeline cache".repeat(50);
    std::fs::write(&path, &garbage).unwrap();
    make().unwrap();
    let after = std::fs::read(&path).unwrap();
    assert_ne!(after, garbage, "the corrupt cache was kept");
    // Truncated to half a header.
    std::fs::write(&path, &first[..first.len() / 2]).unwrap();
    make().unwrap();

    // A cache folder that cannot be made (its parent is a file): no cache
    // written, nothing fails.
    let file = tmp.join("a-file");
    std::fs::write(&file, b"x").unwrap();
    set_dir(&file.join("cache"));
    make().unwrap();
    assert!(!file.join("cache").exists());

    // A directory where the cache file should be: not read, not replaced.
    set_dir(&tmp.join("dir-case"));
    std::fs::create_dir_all(tmp.join("dir-case").join(path.file_name().unwrap())).unwrap();
    make().unwrap();
    assert!(
        tmp.join("dir-case")
            .join(path.file_name().unwrap())
            .is_dir()
    );

    h.device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    assert_eq!(errors.count(), 0, "device errors");
    let _ = std::fs::remove_dir_all(&tmp);
}
