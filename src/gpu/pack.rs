//! Packing model parameters for the shaders: bv-core's generic packer plus the
//! derived slots some ports read after their block (computed here with
//! bv-core's own functions, so that the core stays the one source of the math),
//! and the MERL tables that `merl` blocks point into.

use super::Gpu;
use anyhow::{Result, bail};
use bv_core::ModelSpec;
use bv_core::measured::merl::MerlTable;
use bv_core::microfacet::blinn_normalisation;
use bv_core::params::{GpuModelRef, pack_model_with};
use std::sync::Arc;

/// Table offsets are stored in units of this many floats, so that an offset
/// held in an `f32` slot stays exact up to 2²⁴ units (256 MiB of tables, more
/// than a storage binding may hold).
pub const TABLE_ALIGN: usize = 4;

/// The MERL tables a packed parameter buffer refers to, in upload order: the
/// contents of the `merl_data` storage buffer (`shaders/models/merl.wgsl`).
/// A table used by several models (or twice in a mix) is stored once.
#[derive(Debug, Clone, Default)]
pub struct MerlTables {
    tables: Vec<(Arc<MerlTable>, usize)>,
    len: usize,
}

impl MerlTables {
    /// The offset (in floats) of `table` in the buffer, appending it if new.
    pub fn offset_of(&mut self, table: &Arc<MerlTable>) -> usize {
        if let Some((_, o)) = self.tables.iter().find(|(t, _)| Arc::ptr_eq(t, table)) {
            return *o;
        }
        let offset = self.len.next_multiple_of(TABLE_ALIGN);
        self.len = offset + table.data().len();
        self.tables.push((table.clone(), offset));
        offset
    }

    /// Whether no table is referenced.
    pub fn is_empty(&self) -> bool {
        self.tables.is_empty()
    }

    /// Floats in the buffer (at least 1: wgpu refuses empty bindings).
    pub fn len(&self) -> usize {
        self.len.max(1)
    }

    /// Identifies the contents: the tables (by address) and their offsets.
    /// Two sets with the same key upload the same bytes.
    pub fn key(&self) -> Vec<(usize, usize)> {
        self.tables
            .iter()
            .map(|(t, o)| (Arc::as_ptr(t) as usize, *o))
            .collect()
    }

    /// Writes the buffer's contents into `out` (at least [`Self::len`] long,
    /// zero-filled by the caller): each table's data at its offset.
    pub fn write_into(&self, out: &mut [f32]) {
        for (t, o) in &self.tables {
            out[*o..*o + t.data().len()].copy_from_slice(t.data());
        }
    }

    /// The buffer's contents as one vector (tests; renderers use
    /// [`TableBuffer`], which writes straight into the mapped GPU buffer).
    pub fn to_vec(&self) -> Vec<f32> {
        let mut v = vec![0.0; self.len()];
        self.write_into(&mut v);
        v
    }
}

/// Derived slots of one model (see `shaders/models/*.wgsl` for their use).
///
/// - `cook-torrance`: Blinn's normalisation constant for `alpha_x` and for
///   `alpha2` (0 unless the distribution is `blinn`; it costs a quadrature).
/// - `merl`: `nθh, nθd, nφd` and the table's offset in `tables` in units of
///   [`TABLE_ALIGN`] floats (the table is added to `tables`; the model is built,
///   which reads the file through bv-core's cache).
pub fn derived_slots(spec: &ModelSpec, tables: &mut MerlTables) -> bv_core::Result<Vec<f32>> {
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
        "merl" => {
            let brdf = spec.build()?;
            let Some((table, _)) = brdf.measured() else {
                return Err(bv_core::BvError::Invalid(
                    "a merl model without a table".into(),
                ));
            };
            let d = table.dims();
            let offset = tables.offset_of(table) / TABLE_ALIGN;
            vec![
                d.theta_h as f32,
                d.theta_d as f32,
                d.phi_d as f32,
                offset as f32,
            ]
        }
        _ => Vec::new(),
    })
}

/// Appends `spec` (with its derived slots) to `buf`, adding the MERL tables it
/// uses to `tables`.
pub fn pack(spec: &ModelSpec, buf: &mut Vec<f32>, tables: &mut MerlTables) -> Result<GpuModelRef> {
    Ok(pack_model_with(spec, buf, &mut |s| {
        derived_slots(s, tables)
    })?)
}

/// The whole parameter buffer of a list of models, where each one is, and the
/// MERL tables they use.
pub fn pack_all(specs: &[ModelSpec]) -> Result<(Vec<f32>, Vec<GpuModelRef>, MerlTables)> {
    let mut buf = Vec::new();
    let mut tables = MerlTables::default();
    let refs = specs
        .iter()
        .map(|s| pack(s, &mut buf, &mut tables))
        .collect::<Result<Vec<_>>>()?;
    if buf.is_empty() {
        // wgpu refuses zero-sized bindings.
        buf.push(0.0);
    }
    if (tables.len() as u64) * 4 > u64::from(u32::MAX) {
        bail!("the MERL tables of these models do not fit one storage buffer");
    }
    Ok((buf, refs, tables))
}

/// The `merl_data` storage buffer of a renderer, uploaded again only when the
/// set of tables changes (a 90×90×180 table is 17.5 MB: re-uploading it on
/// every frame of a slider drag would cost more than drawing).
#[derive(Debug, Default)]
pub struct TableBuffer {
    key: Option<Vec<(usize, usize)>>,
    /// Keeps the tables alive while their addresses are the key.
    _held: Option<MerlTables>,
    buffer: Option<wgpu::Buffer>,
}

impl TableBuffer {
    /// The buffer holding `tables`, uploading it if it changed. Fails with a
    /// clear message when the tables exceed the device's storage binding limit.
    pub fn get(&mut self, gpu: &Gpu, tables: &MerlTables) -> Result<&wgpu::Buffer> {
        let key = tables.key();
        if self.key.as_ref() != Some(&key) || self.buffer.is_none() {
            let bytes = (tables.len() * 4) as u64;
            let limit = gpu.device.limits().max_storage_buffer_binding_size;
            if bytes > limit {
                bail!(
                    "the MERL tables drawn together need {:.1} MB, over this GPU's storage \
                     buffer limit of {:.1} MB: show fewer measured BRDFs at once",
                    bytes as f64 / 1e6,
                    limit as f64 / 1e6
                );
            }
            let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("merl tables"),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: true,
            });
            {
                // New buffers are zero-filled; each table is copied straight
                // from bv-core's vector into the mapping (no staging copy).
                let mut view = buffer
                    .slice(..)
                    .get_mapped_range_mut()
                    .map_err(|e| anyhow::anyhow!("mapping the MERL table buffer: {e:?}"))?;
                for (t, o) in &tables.tables {
                    let bytes: &[u8] = bytemuck::cast_slice(t.data());
                    view.slice(4 * o..4 * o + bytes.len())
                        .copy_from_slice(bytes);
                }
            }
            buffer.unmap();
            self.buffer = Some(buffer);
            self.key = Some(key);
            self._held = Some(tables.clone());
        }
        match &self.buffer {
            Some(b) => Ok(b),
            None => bail!("no MERL table buffer"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::measured::merl::MerlDims;

    fn table(n: usize, v: f32) -> Arc<MerlTable> {
        let dims = MerlDims::new(n as i64, 1, 1).unwrap();
        Arc::new(MerlTable::from_values(dims, vec![v; 3 * n]).unwrap())
    }

    #[test]
    fn tables_are_aligned_and_shared() {
        let mut t = MerlTables::default();
        let a = table(3, 1.0); // 9 floats
        let b = table(2, 2.0); // 6 floats
        assert_eq!(t.offset_of(&a), 0);
        assert_eq!(t.offset_of(&b), 12);
        assert_eq!(t.offset_of(&a), 0, "stored once");
        assert_eq!(t.len(), 18);
        let v = t.to_vec();
        assert_eq!(&v[..9], &[1.0; 9]);
        assert_eq!(&v[9..12], &[0.0; 3]);
        assert_eq!(&v[12..18], &[2.0; 6]);
        assert!(MerlTables::default().is_empty());
        assert_eq!(MerlTables::default().len(), 1);
    }
}
