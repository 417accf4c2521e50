//! A simulated microsurface and a virtual gonioreflectometer (issue 29):
//! a periodic random heightfield whose slopes follow Beckmann's or GGX's
//! distribution ([`surface`]), rays traced against it with specular
//! reflection off its facets ([`trace`]), and the measurements with their
//! errors — NDF, masking G1, BRDF and ρhd split into single and multiple
//! bounces ([`measure`]) — to hold the analytic microfacet model against.

pub mod fft;
pub mod measure;
pub mod surface;
pub mod trace;

pub use measure::{G1Point, Gonio, GonioJob, GonioOptions, NdfHistogram, SlopeStats};
pub use surface::{SlopeDistribution, Surface, SurfaceOptions};
pub use trace::SimFresnel;
