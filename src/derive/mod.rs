//! Derived results: everything a view, a figure, the command line or a
//! script shows that is computed from a BRDF rather than read from it —
//! albedo curves, property reports, SH and factor projections and their
//! errors, sampling histograms and χ², reciprocity maps, slices and
//! tabulations, comparisons with measured data.
//!
//! Each is a job keyed by what it depends on (the BRDF's build revision,
//! which changes with the catalogue and the parameters, and the options),
//! run in steps on a thread on the desktop and between frames in a browser
//! page, cached in the process's one store ([`jobs::slots`]), cancellable,
//! with progress. The window's views, offscreen figures, `bv render` and
//! tests ask the same store, so a result is computed once per process.
//!
//! No egui and no wgpu here: a caller that shows results hands in a
//! [`jobs::Waker`] (the window's repaint request).

pub mod albedo;
pub mod compare;
pub mod factor;
pub mod fit;
pub mod gonio;
pub mod hemi;
pub mod interface;
pub mod jobs;
pub mod microsurface;
pub mod properties;
pub mod reciprocity;
pub mod sampling;
pub mod sh;
pub mod slice;
pub mod slices;

pub use jobs::{Done, Shown, Slots, Steps, Waker};
