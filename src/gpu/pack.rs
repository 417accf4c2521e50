//! Packing model parameters for the shaders: bv-core's generic packer plus
//! the derived slots each model's GPU port computes after its block (with
//! bv-core's own functions, so that the core stays the one source of the
//! math), and the data blobs (measured tables) those blocks point into.

use super::Gpu;
use anyhow::{Result, bail};
use bv_core::ModelSpec;
use bv_core::model::{GpuBlob, GpuTables, TABLE_ALIGN};
use bv_core::params::{GpuModelRef, pack_model_with};
use std::sync::Arc;

/// The blobs a packed parameter buffer refers to, in upload order: the
/// contents of the `merl_data` storage buffer (`shaders/models/merl.wgsl`).
/// A blob used by several models (or twice in a mix) is stored once.
#[derive(Debug, Clone, Default)]
pub struct Tables {
    tables: Vec<(Arc<dyn GpuBlob>, usize)>,
    len: usize,
}

impl GpuTables for Tables {
    fn offset_of(&mut self, blob: Arc<dyn GpuBlob>) -> usize {
        if let Some((_, o)) = self
            .tables
            .iter()
            .find(|(t, _)| std::ptr::addr_eq(Arc::as_ptr(t), Arc::as_ptr(&blob)))
        {
            return *o;
        }
        let offset = self.len.next_multiple_of(TABLE_ALIGN);
        self.len = offset + blob.gpu_data().len();
        self.tables.push((blob, offset));
        offset
    }
}

impl Tables {
    /// Whether no blob is referenced.
    pub fn is_empty(&self) -> bool {
        self.tables.is_empty()
    }

    /// Floats in the buffer (at least 1: wgpu refuses empty bindings).
    pub fn len(&self) -> usize {
        self.len.max(1)
    }

    /// Identifies the contents: the blobs (by address) and their offsets.
    /// Two sets with the same key upload the same bytes.
    pub fn key(&self) -> Vec<(usize, usize)> {
        self.tables
            .iter()
            .map(|(t, o)| (Arc::as_ptr(t) as *const () as usize, *o))
            .collect()
    }

    /// Writes the buffer's contents into `out` (at least [`Self::len`] long,
    /// zero-filled by the caller): each blob's data at its offset.
    pub fn write_into(&self, out: &mut [f32]) {
        for (t, o) in &self.tables {
            let d = t.gpu_data();
            out[*o..*o + d.len()].copy_from_slice(d);
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

/// The derived slots of one model, as its GPU port computes them (none for a
/// model without a port or without derived slots).
pub fn derived_slots(spec: &ModelSpec, tables: &mut Tables) -> bv_core::Result<Vec<f32>> {
    match spec.model().gpu.as_ref().and_then(|g| g.derive) {
        Some(derive) => derive(spec, tables),
        None => Ok(Vec::new()),
    }
}

/// Appends `spec` (with its derived slots) to `buf`, adding the blobs it
/// uses to `tables`.
pub fn pack(spec: &ModelSpec, buf: &mut Vec<f32>, tables: &mut Tables) -> Result<GpuModelRef> {
    Ok(pack_model_with(spec, buf, &mut |s| {
        derived_slots(s, tables)
    })?)
}

/// The whole parameter buffer of a list of models, where each one is, and the
/// blobs they use.
pub fn pack_all(specs: &[ModelSpec]) -> Result<(Vec<f32>, Vec<GpuModelRef>, Tables)> {
    let mut buf = Vec::new();
    let mut tables = Tables::default();
    let refs = specs
        .iter()
        .map(|s| pack(s, &mut buf, &mut tables))
        .collect::<Result<Vec<_>>>()?;
    if buf.is_empty() {
        // wgpu refuses zero-sized bindings.
        buf.push(0.0);
    }
    if (tables.len() as u64) * 4 > u64::from(u32::MAX) {
        bail!("the measured tables of these models do not fit one storage buffer");
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
    _held: Option<Tables>,
    buffer: Option<wgpu::Buffer>,
}

impl TableBuffer {
    /// The buffer holding `tables`, uploading it if it changed. Fails with a
    /// clear message when the tables exceed the device's storage binding limit.
    pub fn get(&mut self, gpu: &Gpu, tables: &Tables) -> Result<&wgpu::Buffer> {
        let key = tables.key();
        if self.key.as_ref() != Some(&key) || self.buffer.is_none() {
            let bytes = (tables.len() * 4) as u64;
            let limit = gpu.device.limits().max_storage_buffer_binding_size;
            if bytes > limit {
                bail!(
                    "the measured tables (MERL, RGL) drawn together need {:.1} MB, over this \
                     GPU's storage buffer limit of {:.1} MB: show fewer measured BRDFs at once",
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
                    let bytes: &[u8] = bytemuck::cast_slice(t.gpu_data());
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
    use bv_core::measured::merl::{MerlDims, MerlTable};

    fn table(n: usize, v: f32) -> Arc<MerlTable> {
        let dims = MerlDims::new(n as i64, 1, 1).unwrap();
        Arc::new(MerlTable::from_values(dims, vec![v; 3 * n]).unwrap())
    }

    #[test]
    fn tables_are_aligned_and_shared() {
        let mut t = Tables::default();
        let a = table(3, 1.0); // 9 floats
        let b = table(2, 2.0); // 6 floats
        assert_eq!(t.offset_of(a.clone()), 0);
        assert_eq!(t.offset_of(b), 12);
        assert_eq!(t.offset_of(a), 0, "stored once");
        assert_eq!(t.len(), 18);
        let v = t.to_vec();
        assert_eq!(&v[..9], &[1.0; 9]);
        assert_eq!(&v[9..12], &[0.0; 3]);
        assert_eq!(&v[12..18], &[2.0; 6]);
        assert!(Tables::default().is_empty());
        assert_eq!(Tables::default().len(), 1);
    }
}
