//! `merl`: a measured BRDF from a MERL `.binary` table (SPEC §4; Matusik et al.
//! 2003, "A Data-Driven Reflectance Model").

use crate::measured::merl::{self as table, Interpolation, MerlTable};
use crate::params::{ParamDecl, ParamKind, Params};
use crate::registry::ModelInfo;
use crate::{Brdf, BvError, Claims, Result, Rgb};
use glam::DVec3;
use std::sync::Arc;

/// Parameter declaration.
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "path",
        label: "file",
        doc: "MERL .binary file (half/difference-angle table, 90×90×180 in the public set)",
        kind: ParamKind::Path { default: "" },
    },
    ParamDecl {
        id: "interpolation",
        label: "interpolation",
        doc: "Lookup between samples: trilinear in (θh index, θd, φd), or the nearest sample as the MERL reference code",
        kind: ParamKind::Choice {
            options: Interpolation::NAMES,
            default: "trilinear",
        },
    },
];

/// Catalogue entry.
pub const INFO: ModelInfo = ModelInfo {
    id: "merl",
    name: "MERL measured",
    summary: "Measured isotropic BRDF, tabulated in half/difference angles",
    citation: "Matusik, Pfister, Brand, McMillan 2003, A Data-Driven Reflectance Model; Rusinkiewicz 1998",
    params: PARAMS,
    build,
};

/// A measured BRDF: a shared table and how to look it up.
#[derive(Debug, Clone)]
pub struct Merl {
    table: Arc<MerlTable>,
    interpolation: Interpolation,
}

impl Merl {
    /// A model over an already loaded table (what `bv info` uses).
    pub fn from_table(table: Arc<MerlTable>, interpolation: Interpolation) -> Self {
        Self {
            table,
            interpolation,
        }
    }

    /// The table.
    pub fn table(&self) -> &Arc<MerlTable> {
        &self.table
    }

    /// The lookup mode.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    let path = p.text("path")?;
    if path.trim().is_empty() {
        return Err(BvError::BadValue {
            param: "path".into(),
            reason: "no file given: set it to a MERL .binary file".into(),
        });
    }
    let interpolation = Interpolation::from_name(p.text("interpolation")?)?;
    let table = table::read_cached(path)?;
    Ok(Box::new(Merl::from_table(table, interpolation)))
}

impl Brdf for Merl {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.table.lookup(wi, wo, self.interpolation)
    }

    fn claims(&self) -> Claims {
        Claims {
            // The φd fold makes every lookup reciprocal by construction.
            reciprocal: true,
            // Measured data makes no promise (and real files exceed ρhd = 1 at
            // grazing angles); the analysis reports what it finds.
            energy_conserving: false,
            // The table has no φh axis.
            isotropic: true,
        }
    }

    fn measured(&self) -> Option<(&Arc<MerlTable>, Interpolation)> {
        Some((&self.table, self.interpolation))
    }
}
