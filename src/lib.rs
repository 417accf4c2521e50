//! The `bv` application: the viewer window (`app`, `views`) and the command line
//! (`cli`), both thin layers over `bv-core`.

pub mod app;
pub mod cli;
pub mod export;
pub mod gpu;
pub mod views;
