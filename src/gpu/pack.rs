//! Packing model parameters for the shaders: bv-core's generic packer plus the
//! derived slots some ports read after their block (computed here with
//! bv-core's own functions, so that the core stays the one source of the math).

use anyhow::Result;
use bv_core::ModelSpec;
use bv_core::microfacet::blinn_normalisation;
use bv_core::params::{GpuModelRef, pack_model_with};

/// Models without a WGSL port, and why: packing one (alone or inside a mix)
/// is refused with a message a view can show, rather than drawn black.
pub const NOT_PORTED: &[(&str, &str)] =
    &[("merl", "its measured table is not uploaded to the GPU yet")];

/// Refuses a model of [`NOT_PORTED`].
pub fn check_ported(spec: &ModelSpec) -> bv_core::Result<()> {
    match NOT_PORTED.iter().find(|(id, _)| *id == spec.model) {
        Some((id, why)) => Err(bv_core::BvError::Invalid(format!(
            "`{id}` cannot be drawn on the GPU: {why}"
        ))),
        None => Ok(()),
    }
}

/// Derived slots of one model (see `shaders/models/*.wgsl` for their use).
///
/// - `cook-torrance`: Blinn's normalisation constant for `alpha_x` and for
///   `alpha2` (0 unless the distribution is `blinn`; it costs a quadrature).
pub fn derived_slots(spec: &ModelSpec) -> bv_core::Result<Vec<f32>> {
    check_ported(spec)?;
    Ok(match spec.model.as_str() {
        "cook-torrance" => {
            if spec.params.text("distribution")? == "blinn" {
                vec![
                    blinn_normalisation(spec.params.float("alpha_x")?) as f32,
                    blinn_normalisation(spec.params.float("alpha2")?) as f32,
                ]
            } else {
                vec![0.0, 0.0]
            }
        }
        _ => Vec::new(),
    })
}

/// Appends `spec` (with its derived slots) to `buf`.
pub fn pack(spec: &ModelSpec, buf: &mut Vec<f32>) -> Result<GpuModelRef> {
    Ok(pack_model_with(spec, buf, &mut derived_slots)?)
}

/// The whole parameter buffer of a list of models, and where each one is.
pub fn pack_all(specs: &[ModelSpec]) -> Result<(Vec<f32>, Vec<GpuModelRef>)> {
    let mut buf = Vec::new();
    let refs = specs
        .iter()
        .map(|s| pack(s, &mut buf))
        .collect::<Result<Vec<_>>>()?;
    if buf.is_empty() {
        // wgpu refuses zero-sized bindings.
        buf.push(0.0);
    }
    Ok((buf, refs))
}
