//! The pipelines of one entry shader specialised per model, which follow a
//! changing catalogue in place.
//!
//! Why per model: a software rasteriser (lavapipe) runs every branch of the
//! generic model dispatch on every pixel under an execution mask, so a
//! pipeline compiled for one model ([`ShaderLibrary::specialised_wgsl`]) is
//! ten times faster to run. Why in place: when a user's file is saved, only
//! that model's code changed, and compiling one specialised pipeline takes a
//! tenth of a second where the generic one (every model's code) takes most of
//! a second on lavapipe and several seconds for the environment shader. So a
//! new catalogue drops only the pipelines whose code changed: those of the
//! changed models and those of models drawn through the generic dispatch (a
//! mix reads its components through it), and the generic pipeline, which is
//! built again only when a specialisation fails. Their replacements compile
//! on worker threads while the dropped ones go on drawing (the last working
//! version, as a user file's reload promises), so the window does not wait
//! for a driver's compiler; [`ModelPipelines::poll`] says when they arrive.

use super::errors;
use super::shaders::ShaderLibrary;
use anyhow::Result;
use std::collections::HashMap;
use std::sync::mpsc::{Receiver, TryRecvError};

/// Builds a pipeline of type `P` from a composed shader module.
pub type Build<P> = fn(&wgpu::Device, &wgpu::PipelineLayout, &wgpu::ShaderModule) -> P;

/// What a specialised pipeline was compiled from: the model's catalogue
/// entry's address (a registration leaks a new entry, so the address changes
/// exactly when the model does), or, for a model without a GPU port of its own (drawn
/// through the generic dispatch), the whole catalogue's revision.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stamp {
    Model(usize),
    Catalogue(u64),
}

/// The pipelines of one entry shader: one per model drawn, and the generic
/// one for models whose specialisation failed.
pub struct ModelPipelines<P> {
    device: wgpu::Device,
    library: ShaderLibrary,
    entry: &'static str,
    layout: wgpu::PipelineLayout,
    build: Build<P>,
    generic: Option<P>,
    specialised: HashMap<u32, (Stamp, Option<P>)>,
    /// Replacements compiling on worker threads, by model.
    building: HashMap<u32, (Stamp, Receiver<Option<P>>)>,
    /// Pipelines of an earlier catalogue, drawn until their replacements
    /// arrive.
    stale: HashMap<u32, P>,
    /// Pipelines compiled since [`Self::new`], the generic one included.
    compiled: u64,
}

impl<P> std::fmt::Debug for ModelPipelines<P> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ModelPipelines")
            .field("entry", &self.entry)
            .field("generic", &self.generic.is_some())
            .field("specialised", &self.specialised.len())
            .finish_non_exhaustive()
    }
}

impl<P> ModelPipelines<P> {
    /// The pipelines of entry shader `entry` (a name of
    /// [`super::shaders::ENTRIES`]) under `layout`, with the generic pipeline
    /// `generic` already built; specialised ones are built on first use.
    pub fn new(
        device: &wgpu::Device,
        entry: &'static str,
        layout: wgpu::PipelineLayout,
        build: Build<P>,
        generic: P,
    ) -> Result<Self> {
        Ok(Self {
            device: device.clone(),
            library: ShaderLibrary::new()?,
            entry,
            layout,
            build,
            generic: Some(generic),
            specialised: HashMap::new(),
            building: HashMap::new(),
            stale: HashMap::new(),
            compiled: 0,
        })
    }

    /// The stamp of catalogue model `model` in the library's catalogue (what
    /// a pipeline built now is compiled from).
    fn stamp(&self, model: u32) -> Stamp {
        match self.library.catalogue().get(model as usize) {
            Some(m) if m.gpu.is_some() => Stamp::Model(std::ptr::from_ref(*m).addr()),
            _ => Stamp::Catalogue(self.library.catalogue_revision()),
        }
    }

    /// Adopts the current catalogue ([`bv_core::registry::revision`]): the
    /// shaders are composed again and the pipelines whose code changed are
    /// dropped (built again on use). `Ok(false)` when the catalogue had not
    /// changed; an error (the new catalogue's shaders do not compose) leaves
    /// everything as it was.
    pub fn follow_catalogue(&mut self) -> Result<bool> {
        if self.library.catalogue_revision() == bv_core::registry::revision() {
            return Ok(false);
        }
        self.library = ShaderLibrary::new()?;
        self.generic = None;
        let now: HashMap<u32, Stamp> = self
            .specialised
            .keys()
            .chain(self.building.keys())
            .map(|&m| (m, self.stamp(m)))
            .collect();
        // A replacement still compiling for an older catalogue is dropped
        // (its worker's result goes nowhere).
        self.building
            .retain(|m, (stamp, _)| now.get(m) == Some(stamp));
        for (m, (stamp, built)) in std::mem::take(&mut self.specialised) {
            if now.get(&m) == Some(&stamp) {
                self.specialised.insert(m, (stamp, built));
            } else if let Some(p) = built {
                self.stale.insert(m, p);
            }
        }
        Ok(true)
    }

    /// Builds what drawing `models` (catalogue indices) needs: each one's
    /// specialised pipeline (on this thread the first time; on a worker, the
    /// stale one drawing meanwhile, when it replaces one of an earlier
    /// catalogue), and the generic one if a specialisation failed.
    pub fn prepare(&mut self, models: impl IntoIterator<Item = u32>)
    where
        P: Send + 'static,
    {
        let mut need_generic = false;
        for model in models {
            if !self.specialised.contains_key(&model) && !self.building.contains_key(&model) {
                let stamp = self.stamp(model);
                let source = self.library.specialised_wgsl(self.entry, Some(model));
                if self.stale.contains_key(&model)
                    && let Ok(source) = &source
                {
                    let rx = self.compile_elsewhere(source.clone());
                    self.building.insert(model, (stamp, rx));
                    continue;
                }
                let built = source.ok().map(|source| {
                    let m = self.module(source);
                    (self.build)(&self.device, &self.layout, &m)
                });
                self.compiled += u64::from(built.is_some());
                self.specialised.insert(model, (stamp, built));
            }
            need_generic |= matches!(self.specialised.get(&model), Some((_, None)));
        }
        if need_generic && self.generic.is_none() {
            self.generic = self
                .library
                .shader_module(&self.device, self.entry)
                .ok()
                .map(|m| (self.build)(&self.device, &self.layout, &m));
            self.compiled += u64::from(self.generic.is_some());
        }
    }

    fn module(&self, source: String) -> wgpu::ShaderModule {
        module(&self.device, self.entry, source)
    }

    /// Compiles a specialised pipeline of `source` on a worker thread (in a
    /// browser page, which has none, at once).
    fn compile_elsewhere(&self, source: String) -> Receiver<Option<P>>
    where
        P: Send + 'static,
    {
        let (tx, rx) = std::sync::mpsc::channel();
        let (device, layout, build, entry) = (
            self.device.clone(),
            self.layout.clone(),
            self.build,
            self.entry,
        );
        let work = move || {
            let built = errors::scoped(&device, "compiling a specialised pipeline", || {
                let m = module(&device, entry, source);
                Ok(build(&device, &layout, &m))
            });
            // The receiver is gone only if the catalogue moved on.
            let _ = tx.send(built.ok());
        };
        if cfg!(target_arch = "wasm32") {
            work();
        } else {
            // Without a thread the sender is dropped unsent, which
            // [`Self::poll`] takes as a failed build (the generic pipeline
            // draws).
            let _ = std::thread::Builder::new()
                .name("bv pipeline compile".into())
                .spawn(work);
        }
        rx
    }

    /// Takes the replacements that finished compiling: `(arrived, waiting)`,
    /// whether any arrived (what they draw must be drawn again) and whether
    /// others are still compiling (poll again in a later frame).
    pub fn poll(&mut self) -> (bool, bool) {
        let mut arrived = false;
        let mut done = Vec::new();
        for (&m, (_, rx)) in &self.building {
            match rx.try_recv() {
                Ok(built) => done.push((m, built)),
                Err(TryRecvError::Empty) => {}
                Err(TryRecvError::Disconnected) => done.push((m, None)),
            }
        }
        for (m, built) in done {
            if let Some((stamp, _)) = self.building.remove(&m) {
                self.compiled += u64::from(built.is_some());
                self.stale.remove(&m);
                self.specialised.insert(m, (stamp, built));
                arrived = true;
            }
        }
        (arrived, !self.building.is_empty())
    }

    /// The pipeline that draws `model`: its specialised one, else the generic
    /// one (`None` if neither could be built, or [`Self::prepare`] was not
    /// asked for it).
    pub fn get(&self, model: u32) -> Option<&P> {
        match self.specialised.get(&model) {
            Some((_, Some(p))) => Some(p),
            _ => self.stale.get(&model).or(self.generic.as_ref()),
        }
    }

    /// How many pipelines were compiled after [`Self::new`] (what a changed
    /// catalogue cost).
    pub fn compiled(&self) -> u64 {
        self.compiled
    }

    /// How many specialised pipelines exist.
    pub fn specialised_count(&self) -> usize {
        self.specialised
            .values()
            .filter(|(_, p)| p.is_some())
            .count()
    }
}

/// A wgpu shader module of a composed WGSL source.
fn module(device: &wgpu::Device, entry: &str, source: String) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(entry),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}
