//! Models users write themselves: the `.brdf` file container of Disney's
//! BRDF Explorer ([`brdf_file`]).

pub mod brdf_file;
