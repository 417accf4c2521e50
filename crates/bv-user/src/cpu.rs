//! The CPU evaluator of a file model (placeholder until the interpreter).

use crate::compile::Compiled;
use crate::error::{Result, UserError};
use bv_core::{Brdf, Claims, Rgb};
use glam::DVec3;

/// A file's program, ready to be given parameter values.
#[derive(Debug, Clone)]
pub struct FileProgram {
    file: String,
}

impl FileProgram {
    /// The program of a compiled file.
    pub fn new(c: &Compiled) -> Result<Self> {
        let _ = c;
        Ok(Self {
            file: String::new(),
        })
    }

    /// An evaluator for parameter values `p`.
    pub fn build(&self, id: &'static str, p: &bv_core::Params) -> Result<FileBrdf> {
        let _ = p;
        let _ = id;
        Err(UserError::Model {
            file: self.file.clone(),
            reason: "no CPU evaluator yet".into(),
        })
    }
}

/// A file model with its parameter values.
#[derive(Debug)]
pub struct FileBrdf {
    id: &'static str,
}

impl Brdf for FileBrdf {
    fn id(&self) -> &'static str {
        self.id
    }
    fn eval(&self, _wi: DVec3, _wo: DVec3) -> Rgb {
        Rgb::ZERO
    }
    fn claims(&self) -> Claims {
        Claims {
            reciprocal: false,
            energy_conserving: false,
            isotropic: false,
        }
    }
}
