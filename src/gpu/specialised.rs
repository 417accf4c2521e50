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
//! built again only when a specialisation fails. Their replacements are
//! composed and compiled on one compile thread while the dropped ones go on
//! drawing (the last working version, as a user file's reload promises), so
//! the window does not wait for the composer or a driver's compiler;
//! [`ModelPipelines::poll`] says when they arrive.

use super::errors;
use super::shaders::{ShaderLibrary, SharedLibrary, Snapshot};
use anyhow::Result;
use std::collections::HashMap;
use std::sync::OnceLock;
use std::sync::mpsc::{Receiver, SendError, Sender, TryRecvError, channel};

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

/// What adopting a changed catalogue did ([`ModelPipelines::follow_catalogue`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Followed {
    /// What is drawn changed from the next draw on: draw again now.
    pub redraw: bool,
    /// Replacements are compiling ([`ModelPipelines::poll`] says when they
    /// arrive; what they replace draws meanwhile, so nothing needs drawing
    /// again until then).
    pub compiling: bool,
}

impl Followed {
    /// Whether anything the pipelines draw changed or will change.
    pub fn changed(self) -> bool {
        self.redraw || self.compiling
    }
}

/// The pipelines of one entry shader: one per model drawn, and the generic
/// one for models whose specialisation failed.
pub struct ModelPipelines<P> {
    device: wgpu::Device,
    /// The catalogue the pipelines are compiled from.
    snapshot: Snapshot,
    entry: &'static str,
    layout: wgpu::PipelineLayout,
    build: Build<P>,
    generic: Option<P>,
    specialised: HashMap<u32, (Stamp, Option<P>)>,
    /// Replacements compiling on the compile thread, by model.
    building: HashMap<u32, (Stamp, Receiver<Option<P>>)>,
    /// Pipelines of an earlier catalogue, drawn until their replacements
    /// arrive.
    stale: HashMap<u32, P>,
    /// The models of the last [`Self::prepare`], in its order: those whose
    /// replacements start compiling when the catalogue is followed (others
    /// compile when drawn again).
    last_drawn: Vec<u32>,
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
            snapshot: Snapshot::now(),
            entry,
            layout,
            build,
            generic: Some(generic),
            specialised: HashMap::new(),
            building: HashMap::new(),
            stale: HashMap::new(),
            last_drawn: Vec::new(),
            compiled: 0,
        })
    }

    /// The stamp of catalogue model `model` in the followed catalogue (what
    /// a pipeline built now is compiled from).
    fn stamp(&self, model: u32) -> Stamp {
        match self.snapshot.catalogue.get(model as usize) {
            Some(m) if m.gpu.is_some() => Stamp::Model(std::ptr::from_ref(*m).addr()),
            _ => Stamp::Catalogue(self.snapshot.revision),
        }
    }

    /// The composed shaders of the followed catalogue (shared, composed on
    /// first use).
    fn library(&self) -> Result<SharedLibrary> {
        super::shaders::shared(&self.snapshot)
    }

    /// Adopts the current catalogue ([`bv_core::registry::revision`]): the
    /// pipelines whose code changed are dropped and the replacements of those
    /// last drawn start compiling at once on the compile thread, the shaders composed there
    /// too (the dropped ones draw until they arrive; [`Self::poll`]). A
    /// model that had no pipeline of its own (drawn through the generic
    /// dispatch) is drawn from the new code at its next draw. A replacement
    /// that fails to compose or compile arrives as a failed specialisation
    /// (the generic pipeline draws it, or the draw reports an error).
    pub fn follow_catalogue(&mut self) -> Followed
    where
        P: Send + 'static,
    {
        if self.snapshot.revision == bv_core::registry::revision() {
            return Followed::default();
        }
        self.snapshot = Snapshot::now();
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
        let mut followed = Followed::default();
        for (m, (stamp, built)) in std::mem::take(&mut self.specialised) {
            if now.get(&m) == Some(&stamp) {
                self.specialised.insert(m, (stamp, built));
            } else if let Some(p) = built {
                self.stale.insert(m, p);
            } else {
                followed.redraw = true;
            }
        }
        // What was drawn last, in the order drawn (one compile thread takes
        // them in turn).
        let waiting: Vec<u32> = self
            .last_drawn
            .iter()
            .filter(|m| self.stale.contains_key(m) && !self.building.contains_key(m))
            .copied()
            .collect();
        for m in waiting {
            self.start_replacement(m);
        }
        followed.compiling = !self.building.is_empty();
        followed
    }

    /// Starts compiling the replacement of stale model `model`'s pipeline.
    fn start_replacement(&mut self, model: u32)
    where
        P: Send + 'static,
    {
        let stamp = self.stamp(model);
        let rx = self.compile_elsewhere(model);
        self.building.insert(model, (stamp, rx));
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
        self.last_drawn.clear();
        for model in models {
            if !self.last_drawn.contains(&model) {
                self.last_drawn.push(model);
            }
            if !self.specialised.contains_key(&model) && !self.building.contains_key(&model) {
                if self.stale.contains_key(&model) {
                    self.start_replacement(model);
                    continue;
                }
                let stamp = self.stamp(model);
                let built = self.specialised_wgsl(model).ok().map(|source| {
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
                .library()
                .and_then(|lib| lock(&lib)?.shader_module(&self.device, self.entry))
                .ok()
                .map(|m| (self.build)(&self.device, &self.layout, &m));
            self.compiled += u64::from(self.generic.is_some());
        }
    }

    fn module(&self, source: String) -> wgpu::ShaderModule {
        module(&self.device, self.entry, source)
    }

    /// The entry shader specialised for `model`, from the followed catalogue.
    fn specialised_wgsl(&self, model: u32) -> Result<String> {
        lock(&self.library()?)?.specialised_wgsl(self.entry, Some(model))
    }

    /// Compiles the specialised pipeline of `model` on the compile thread
    /// (see [`run_elsewhere`]), the shaders composed there too: nothing of
    /// a replacement is done on the thread drawing the window.
    fn compile_elsewhere(&self, model: u32) -> Receiver<Option<P>>
    where
        P: Send + 'static,
    {
        let (tx, rx) = channel();
        let (device, layout, build, entry, snapshot) = (
            self.device.clone(),
            self.layout.clone(),
            self.build,
            self.entry,
            self.snapshot.clone(),
        );
        let work = move || {
            let source = super::shaders::shared(&snapshot)
                .and_then(|lib| lock(&lib)?.specialised_wgsl(entry, Some(model)));
            let built = source.and_then(|source| {
                errors::scoped(&device, "compiling a specialised pipeline", || {
                    let m = module(&device, entry, source);
                    Ok(build(&device, &layout, &m))
                })
            });
            // The receiver is gone only if the catalogue moved on.
            let _ = tx.send(built.ok());
        };
        run_elsewhere(Box::new(work));
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
/// The library behind a shared handle (a panic while it was held is an error,
/// not a second panic).
fn lock(lib: &SharedLibrary) -> Result<std::sync::MutexGuard<'_, ShaderLibrary>> {
    lib.lock()
        .map_err(|_| anyhow::anyhow!("the shader library was left broken by a panic"))
}

/// Work for the compile thread.
type Job = Box<dyn FnOnce() + Send>;

/// Runs `job` on the one compile thread, after the jobs asked for before it.
/// One thread, not one per pipeline: on two cores, several driver compiles
/// at once starve the software rasteriser drawing the window, and the views
/// are drawn (so their pipelines asked for) in the order they are seen, so
/// the first view gets its pipeline first. Where there is no thread (a
/// browser page, or one that could not be started) the job runs at once.
fn run_elsewhere(job: Job) {
    static QUEUE: OnceLock<Option<Sender<Job>>> = OnceLock::new();
    if cfg!(target_arch = "wasm32") {
        return job();
    }
    let queue = QUEUE.get_or_init(|| {
        let (tx, rx) = channel::<Job>();
        std::thread::Builder::new()
            .name("bv pipeline compile".into())
            .spawn(move || rx.into_iter().for_each(|job| job()))
            .ok()
            .map(|_| tx)
    });
    match queue {
        // A job that panicked ended the thread: the next ones run here.
        Some(tx) => {
            if let Err(SendError(job)) = tx.send(job) {
                job();
            }
        }
        None => job(),
    }
}

fn module(device: &wgpu::Device, entry: &str, source: String) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(entry),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}
