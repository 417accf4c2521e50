//! The GPU layout of a parameter declaration.
//!
//! Shaders read a model's parameters from one flat `array<f32>` storage buffer.
//! Where each parameter sits is derived here from the model's one declaration
//! ([`ParamDecl`] list), never written by hand: the application generates the
//! WGSL constants that the shaders use from [`gpu_layout`], and
//! [`pack_model`] writes values at exactly those offsets. A parameter added to a
//! declaration therefore moves every later offset in the packer and in the
//! shaders together.
//!
//! # Layout rules
//!
//! Offsets count `f32` slots from the start of the model's block.
//!
//! | kind | slots | content |
//! |---|---|---|
//! | `Float` | 1 | the value |
//! | `Color` | 3 | r, g, b |
//! | `Choice` | 1 | index of the option in the declared `options` (0, 1, …) |
//! | `Bool` | 1 | 0 or 1 |
//! | `List` | `1 + max_items · stride` | item count, then `max_items` items of the fields' own layout (`stride` slots each; unused items are 0) |
//! | `Path` | 0 | nothing: file-backed data (MERL tables) travels in its own buffer |
//! | `Components` | 2 | component count `n`, then the absolute offset of a table of `n` entries `(weight, model index, params offset)` |
//!
//! Parameters follow each other in declaration order with no padding (the
//! buffer is an array of scalars, so WGSL's vector alignment never applies).
//!
//! `Components` (the `mix` model) are flattened when packed: a mix of mixes is
//! linear, `Σ_j w_j Σ_k v_k f_k = Σ_{j,k} (w_j v_k) f_k`, so the table lists only
//! leaf models with the products of the weights along the path. A shader can
//! then evaluate a mix with one loop and no recursion (WGSL has none).
//!
//! Derived slots ([`pack_model_with`]): a renderer may store, right after a
//! model's block, quantities computed from its parameters by bv-core's own
//! functions (e.g. Blinn's normalisation constant, a quadrature), so that the
//! shader reads them instead of recomputing them per evaluation.
//!
//! All integers (counts, indices, offsets) are stored as `f32`, which
//! represents every integer up to 2²⁴ exactly; [`pack_model`] refuses buffers
//! that would grow beyond that.

use super::{MAX_NESTING, ModelSpec, ParamDecl, ParamKind, ParamValue, Params};
use crate::{BvError, Result, registry};

/// Largest slot index an `f32` holds exactly (2²⁴).
pub const MAX_SLOTS: usize = 1 << 24;

/// Slots of one entry of a flattened `Components` table: weight, model index,
/// parameter offset.
pub const COMPONENT_ENTRY_SLOTS: u32 = 3;

/// How one parameter is stored.
#[derive(Debug, Clone, PartialEq)]
pub enum GpuSlot {
    /// One slot.
    Float,
    /// Three slots, r g b.
    Color,
    /// One slot: the option index.
    Choice {
        /// The declared options, in index order.
        options: &'static [&'static str],
    },
    /// One slot: 0 or 1.
    Bool,
    /// Count, then `max_items` items of `item` layout.
    List {
        /// Most items.
        max_items: u32,
        /// Layout of one item (offsets relative to the item's start).
        item: GpuLayout,
    },
    /// No slot (file-backed data goes in a separate buffer).
    Path,
    /// Count and table offset of the flattened mix components.
    Components,
}

impl GpuSlot {
    /// Number of slots this parameter occupies in its model's block.
    pub fn slots(&self) -> u32 {
        match self {
            GpuSlot::Float | GpuSlot::Choice { .. } | GpuSlot::Bool => 1,
            GpuSlot::Color => 3,
            GpuSlot::List { max_items, item } => 1 + max_items * item.size,
            GpuSlot::Path => 0,
            GpuSlot::Components => 2,
        }
    }
}

/// Where one declared parameter lives.
#[derive(Debug, Clone, PartialEq)]
pub struct GpuParam {
    /// Parameter id from the declaration.
    pub id: &'static str,
    /// First slot, relative to the model's (or the list item's) block.
    pub offset: u32,
    /// What the slots hold.
    pub slot: GpuSlot,
}

/// The layout of a whole declaration.
#[derive(Debug, Clone, PartialEq)]
pub struct GpuLayout {
    /// One entry per declared parameter, in declaration order.
    pub params: Vec<GpuParam>,
    /// Total slots of the block (the stride of a list item).
    pub size: u32,
}

impl GpuLayout {
    /// The entry of parameter `id`.
    pub fn param(&self, id: &str) -> Option<&GpuParam> {
        self.params.iter().find(|p| p.id == id)
    }
}

/// The GPU layout of a parameter declaration (rules in the module docs).
pub fn gpu_layout(decls: &[ParamDecl]) -> GpuLayout {
    let mut params = Vec::with_capacity(decls.len());
    let mut offset = 0u32;
    for d in decls {
        let slot = match d.kind {
            ParamKind::Float(_) => GpuSlot::Float,
            ParamKind::Color(_) => GpuSlot::Color,
            ParamKind::Choice { options, .. } => GpuSlot::Choice { options },
            ParamKind::Bool { .. } => GpuSlot::Bool,
            ParamKind::List {
                fields, max_items, ..
            } => GpuSlot::List {
                // Declarations are static and small (Lafortune: a handful of
                // lobes); saturate rather than wrap if one were absurd.
                max_items: u32::try_from(max_items).unwrap_or(u32::MAX),
                item: gpu_layout(fields),
            },
            ParamKind::Path { .. } => GpuSlot::Path,
            ParamKind::Components { .. } => GpuSlot::Components,
        };
        let n = slot.slots();
        params.push(GpuParam {
            id: d.id,
            offset,
            slot,
        });
        offset = offset.saturating_add(n);
    }
    GpuLayout {
        params,
        size: offset,
    }
}

/// The index shaders use for model `id`: its position in the catalogue.
pub fn gpu_model_index(id: &str) -> Result<u32> {
    let info = registry::find(id)?;
    let i = registry::catalogue()
        .iter()
        .position(|m| m.id == info.id)
        .unwrap_or(0);
    Ok(i as u32)
}

/// A packed model: its catalogue index and the offset of its block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GpuModelRef {
    /// Catalogue index ([`gpu_model_index`]).
    pub model: u32,
    /// First slot of its parameter block in the buffer.
    pub offset: u32,
}

fn too_big() -> BvError {
    BvError::Invalid(format!(
        "packed parameters exceed {MAX_SLOTS} slots, the largest offset an f32 holds exactly"
    ))
}

fn to_slot(x: usize) -> Result<f32> {
    if x >= MAX_SLOTS {
        return Err(too_big());
    }
    Ok(x as f32)
}

/// Appends the packed parameters of `spec` to `buf` and returns where they are.
///
/// Values are stored as `f32` (rounded to nearest). Mixes are flattened into a
/// table of leaf models (module docs), each leaf's block appended after the table.
pub fn pack_model(spec: &ModelSpec, buf: &mut Vec<f32>) -> Result<GpuModelRef> {
    pack_model_with(spec, buf, &mut |_| Ok(Vec::new()))
}

/// Quantities a shader needs that are not parameters but functions of them,
/// computed once on the CPU (by bv-core's own code) rather than per evaluation:
/// called for every packed model (mix leaves included); what it returns is
/// stored right after the model's block, at offset `gpu_layout(..).size`.
pub type DerivedSlots<'a> = dyn FnMut(&ModelSpec) -> Result<Vec<f32>> + 'a;

/// [`pack_model`] with derived slots after each model's block.
pub fn pack_model_with(
    spec: &ModelSpec,
    buf: &mut Vec<f32>,
    derived: &mut DerivedSlots<'_>,
) -> Result<GpuModelRef> {
    pack_nested(spec, buf, 0, derived)
}

fn pack_nested(
    spec: &ModelSpec,
    buf: &mut Vec<f32>,
    depth: usize,
    derived: &mut DerivedSlots<'_>,
) -> Result<GpuModelRef> {
    let info = spec.model();
    let model = gpu_model_index(info.id)?;
    let layout = gpu_layout(info.params);
    let offset = buf.len();
    if offset + layout.size as usize >= MAX_SLOTS {
        return Err(too_big());
    }
    buf.resize(offset + layout.size as usize, 0.0);
    let mut deferred = Vec::new();
    write_block(&layout, spec.params(), buf, offset, &mut deferred)?;
    let extra = derived(spec)?;
    if buf.len() + extra.len() >= MAX_SLOTS {
        return Err(too_big());
    }
    buf.extend_from_slice(&extra);
    // Components: flatten into (weight, leaf) pairs, then write the table and
    // the leaves' blocks after this model's block.
    for (slot, components) in deferred {
        let mut leaves = Vec::new();
        flatten(components, 1.0, depth, &mut leaves)?;
        let table = buf.len();
        buf[slot] = to_slot(leaves.len())?;
        buf[slot + 1] = to_slot(table)?;
        buf.resize(table + leaves.len() * COMPONENT_ENTRY_SLOTS as usize, 0.0);
        for (j, (w, leaf)) in leaves.iter().enumerate() {
            let r = pack_nested(leaf, buf, depth + 1, derived)?;
            let e = table + j * COMPONENT_ENTRY_SLOTS as usize;
            buf[e] = *w as f32;
            buf[e + 1] = r.model as f32;
            buf[e + 2] = to_slot(r.offset as usize)?;
        }
    }
    Ok(GpuModelRef {
        model,
        offset: to_slot(offset)? as u32,
    })
}

/// Leaf models of a (possibly nested) component list with their accumulated
/// weights, zero weights dropped as `Mix` drops them.
fn flatten<'a>(
    components: &'a [super::Component],
    scale: f64,
    depth: usize,
    out: &mut Vec<(f64, &'a ModelSpec)>,
) -> Result<()> {
    if depth >= MAX_NESTING {
        return Err(BvError::BadValue {
            param: "components".to_string(),
            reason: format!("mixes nest deeper than {MAX_NESTING} levels"),
        });
    }
    for c in components {
        let w = scale * c.weight;
        if w == 0.0 {
            continue;
        }
        let nested = c
            .spec
            .model()
            .params
            .iter()
            .find(|d| matches!(d.kind, ParamKind::Components { .. }));
        match nested {
            Some(d) => flatten(c.spec.params().components(d.id)?, w, depth + 1, out)?,
            None => out.push((w, &c.spec)),
        }
        if out.len() * COMPONENT_ENTRY_SLOTS as usize >= MAX_SLOTS {
            return Err(too_big());
        }
    }
    Ok(())
}

type Deferred<'a> = Vec<(usize, &'a [super::Component])>;

fn write_block<'a>(
    layout: &GpuLayout,
    params: &'a Params,
    buf: &mut [f32],
    base: usize,
    deferred: &mut Deferred<'a>,
) -> Result<()> {
    for p in &layout.params {
        let at = base + p.offset as usize;
        let value = params.get(p.id)?;
        let mismatch = || BvError::BadValue {
            param: p.id.to_string(),
            reason: format!("value {} does not fit its declaration", value.to_json()),
        };
        match (&p.slot, value) {
            (GpuSlot::Float, ParamValue::Float(x)) => buf[at] = *x as f32,
            (GpuSlot::Color, ParamValue::Color(c)) => {
                for (k, x) in c.iter().enumerate() {
                    buf[at + k] = *x as f32;
                }
            }
            (GpuSlot::Color, ParamValue::Float(x)) => buf[at..at + 3].fill(*x as f32),
            (GpuSlot::Choice { options }, ParamValue::Text(s)) => {
                let i = options.iter().position(|o| o == s).ok_or_else(mismatch)?;
                buf[at] = i as f32;
            }
            (GpuSlot::Bool, ParamValue::Bool(b)) => buf[at] = f32::from(u8::from(*b)),
            (GpuSlot::List { max_items, item }, ParamValue::List(items)) => {
                if items.len() > *max_items as usize {
                    return Err(BvError::BadValue {
                        param: p.id.to_string(),
                        reason: format!("has {} items; at most {max_items}", items.len()),
                    });
                }
                buf[at] = items.len() as f32;
                for (i, it) in items.iter().enumerate() {
                    let start = at + 1 + i * item.size as usize;
                    write_block(item, it, buf, start, deferred)?;
                }
            }
            (GpuSlot::Path, ParamValue::Text(_)) => {}
            (GpuSlot::Components, ParamValue::Components(c)) => deferred.push((at, c)),
            _ => return Err(mismatch()),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{ColorSpec, FloatSpec};
    use serde_json::json;

    const FIELDS: &[ParamDecl] = &[
        ParamDecl {
            id: "n",
            label: "n",
            doc: "exponent",
            kind: ParamKind::Float(FloatSpec::linear(0.0, 100.0, 2.0)),
            applies: crate::Applies::Always,
        },
        ParamDecl {
            id: "c",
            label: "c",
            doc: "colour",
            kind: ParamKind::Color(ColorSpec::unit_range([0.25, 0.5, 0.75])),
            applies: crate::Applies::Always,
        },
    ];

    const DECLS: &[ParamDecl] = &[
        ParamDecl {
            id: "kd",
            label: "kd",
            doc: "colour",
            kind: ParamKind::Color(ColorSpec::unit_range([0.1, 0.2, 0.3])),
            applies: crate::Applies::Always,
        },
        ParamDecl {
            id: "mode",
            label: "mode",
            doc: "choice",
            kind: ParamKind::Choice {
                options: &["a", "b", "c"],
                default: "c",
            },
            applies: crate::Applies::Always,
        },
        ParamDecl {
            id: "flag",
            label: "flag",
            doc: "bool",
            kind: ParamKind::Bool { default: true },
            applies: crate::Applies::Always,
        },
        ParamDecl {
            id: "lobes",
            label: "lobes",
            doc: "list",
            kind: ParamKind::List {
                fields: FIELDS,
                min_items: 0,
                max_items: 3,
                default_items: 2,
            },
            applies: crate::Applies::Always,
        },
        ParamDecl {
            id: "file",
            label: "file",
            doc: "path",
            kind: ParamKind::Path {
                default: "",
                format: &crate::models::merl::MERL_FILES,
            },
            applies: crate::Applies::Always,
        },
        ParamDecl {
            id: "e",
            label: "e",
            doc: "float",
            kind: ParamKind::Float(FloatSpec::linear(0.0, 10.0, 7.5)),
            applies: crate::Applies::Always,
        },
    ];

    #[test]
    fn offsets_follow_the_rules() {
        // kd: 0..3, mode: 3, flag: 4, lobes: count 5, items 6.. (3 × 4 slots),
        // file: nothing, e: 18.
        let l = gpu_layout(DECLS);
        let at = |id: &str| l.param(id).unwrap().offset;
        assert_eq!(
            [at("kd"), at("mode"), at("flag"), at("lobes"), at("e")],
            [0, 3, 4, 5, 18]
        );
        assert_eq!(l.param("file").unwrap().slot.slots(), 0);
        assert_eq!(l.size, 19);
        let GpuSlot::List { item, max_items } = &l.param("lobes").unwrap().slot else {
            panic!("lobes is a list");
        };
        assert_eq!((*max_items, item.size), (3, 4));
        assert_eq!(item.param("c").unwrap().offset, 1);
    }

    #[test]
    fn packs_values_at_their_offsets() {
        let l = gpu_layout(DECLS);
        let p = Params::defaults(DECLS);
        let mut buf = vec![-1.0; l.size as usize];
        let mut deferred = Vec::new();
        write_block(&l, &p, &mut buf, 0, &mut deferred).unwrap();
        let want = [
            0.1f32, 0.2, 0.3, // kd
            2.0, // mode "c"
            1.0, // flag
            2.0, // two lobes
            2.0, 0.25, 0.5, 0.75, // lobe 0
            2.0, 0.25, 0.5, 0.75, // lobe 1
            -1.0, -1.0, -1.0, -1.0, // unused third item keeps what was there
            7.5,  // e
        ];
        assert_eq!(buf, want);
    }

    #[test]
    fn every_catalogue_model_packs_its_defaults() {
        for m in registry::catalogue().iter() {
            let spec = ModelSpec::new(m.id).unwrap();
            let mut buf = vec![0.0; 5];
            let r = pack_model(&spec, &mut buf).unwrap();
            assert_eq!(r.offset, 5, "{}", m.id);
            assert_eq!(r.model, gpu_model_index(m.id).unwrap());
            assert!(buf.len() >= 5 + gpu_layout(m.params).size as usize);
            assert!(buf.iter().all(|x| x.is_finite()));
        }
    }

    #[test]
    fn nested_mixes_flatten_with_weight_products() {
        let spec = ModelSpec::from_json(
            "mix",
            &json!({"components": [
                {"weight": 0.5, "model": "lambert", "params": {"albedo": 0.2}},
                {"weight": 2.0, "model": "mix", "params": {"components": [
                    {"weight": 0.25, "model": "lambert", "params": {"albedo": 0.4}},
                    {"weight": 0.0, "model": "lambert"},
                    {"weight": 3.0, "model": "oren-nayar", "params": {"sigma": 0.5}}
                ]}}
            ]}),
        )
        .unwrap();
        let mut buf = Vec::new();
        let r = pack_model(&spec, &mut buf).unwrap();
        assert_eq!(r.offset, 0);
        let comp = gpu_layout(crate::models::mix::PARAMS)
            .param("components")
            .unwrap()
            .offset as usize;
        let n = buf[comp] as usize;
        let table = buf[comp + 1] as usize;
        assert_eq!(n, 3, "zero weight dropped, nested mix flattened");
        let entry = |j: usize| {
            let e = table + 3 * j;
            (buf[e], buf[e + 1] as u32, buf[e + 2] as usize)
        };
        let lambert = gpu_model_index("lambert").unwrap();
        let on = gpu_model_index("oren-nayar").unwrap();
        let (w0, m0, o0) = entry(0);
        assert_eq!((w0, m0), (0.5, lambert));
        assert_eq!(buf[o0], 0.2f32);
        let (w1, m1, o1) = entry(1);
        assert_eq!((w1, m1), (0.5, lambert));
        assert_eq!(buf[o1], 0.4f32);
        let (w2, m2, o2) = entry(2);
        assert_eq!((w2, m2), (6.0, on));
        let sigma = gpu_layout(crate::models::oren_nayar::PARAMS)
            .param("sigma")
            .unwrap()
            .offset as usize;
        assert_eq!(buf[o2 + sigma], 0.5f32);
    }

    #[test]
    fn mismatched_values_are_refused() {
        let mut p = Params::defaults(DECLS);
        p.set_unvalidated("mode", ParamValue::Text("zzz".into()));
        let l = gpu_layout(DECLS);
        let mut buf = vec![0.0; l.size as usize];
        assert!(write_block(&l, &p, &mut buf, 0, &mut Vec::new()).is_err());
        p.set_unvalidated("mode", ParamValue::Float(1.0));
        assert!(write_block(&l, &p, &mut buf, 0, &mut Vec::new()).is_err());
    }
}
