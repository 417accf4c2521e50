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
//! built again only when a specialisation fails.

use super::shaders::ShaderLibrary;
use anyhow::Result;
use std::collections::HashMap;

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
            .map(|&m| (m, self.stamp(m)))
            .collect();
        self.specialised
            .retain(|m, (stamp, _)| now.get(m) == Some(stamp));
        Ok(true)
    }

    /// Builds what drawing `models` (catalogue indices) needs: each one's
    /// specialised pipeline, and the generic one if a specialisation failed.
    pub fn prepare(&mut self, models: impl IntoIterator<Item = u32>) {
        let mut need_generic = false;
        for model in models {
            if !self.specialised.contains_key(&model) {
                let stamp = self.stamp(model);
                let built = self
                    .library
                    .specialised_module(&self.device, self.entry, Some(model))
                    .ok()
                    .map(|m| (self.build)(&self.device, &self.layout, &m));
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

    /// The pipeline that draws `model`: its specialised one, else the generic
    /// one (`None` if neither could be built, or [`Self::prepare`] was not
    /// asked for it).
    pub fn get(&self, model: u32) -> Option<&P> {
        match self.specialised.get(&model) {
            Some((_, Some(p))) => Some(p),
            _ => self.generic.as_ref(),
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
