//! Evaluators built from the state's specs (not saved). Each BRDF is rebuilt
//! only when its spec changed; its revision number then changes, which is the
//! key the views' caches use.

use super::state::AppState;
use bv_core::{Brdf, ModelSpec};
use std::collections::HashMap;
use std::sync::Arc;

/// One built BRDF.
#[derive(Clone)]
pub struct Built {
    /// The spec it was built from.
    pub spec: ModelSpec,
    /// The evaluator, or `None` if building failed.
    pub brdf: Option<Arc<dyn Brdf>>,
    /// Why building failed.
    pub error: Option<String>,
    /// Changes at every rebuild.
    pub revision: u64,
}

/// Built evaluators by BRDF id.
#[derive(Default)]
pub struct Runtime {
    built: HashMap<u64, Built>,
    next_revision: u64,
    builds: u64,
}

impl Runtime {
    /// Rebuilds what changed in `state` and forgets removed BRDFs.
    pub fn sync(&mut self, state: &AppState) {
        for e in &state.brdfs {
            if self.built.get(&e.id).is_some_and(|b| b.spec == e.spec) {
                continue;
            }
            self.next_revision += 1;
            self.builds += 1;
            let (brdf, error) = match e.spec.build() {
                Ok(b) => (Some(Arc::<dyn Brdf>::from(b)), None),
                Err(err) => (None, Some(err.to_string())),
            };
            self.built.insert(
                e.id,
                Built {
                    spec: e.spec.clone(),
                    brdf,
                    error,
                    revision: self.next_revision,
                },
            );
        }
        self.built.retain(|id, _| state.entry(*id).is_some());
    }

    /// The built BRDF of id `id`.
    pub fn get(&self, id: u64) -> Option<&Built> {
        self.built.get(&id)
    }

    /// How many builds ran since start (for tests of the caching).
    pub fn build_count(&self) -> u64 {
        self.builds
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::ParamValue;

    #[test]
    fn rebuilds_only_what_changed() {
        let mut s = AppState::default();
        let a = s.add(ModelSpec::new("lambert").unwrap());
        let b = s.add(ModelSpec::new("lambert").unwrap());
        let mut rt = Runtime::default();
        rt.sync(&s);
        assert_eq!(rt.build_count(), 2);
        let rev_a = rt.get(a).unwrap().revision;
        rt.sync(&s);
        assert_eq!(rt.build_count(), 2);
        s.entry_mut(b)
            .unwrap()
            .spec
            .set("albedo", ParamValue::Color([0.2; 3]))
            .unwrap();
        rt.sync(&s);
        assert_eq!(rt.build_count(), 3);
        assert_eq!(rt.get(a).unwrap().revision, rev_a);
        s.brdfs.retain(|e| e.id != a);
        rt.sync(&s);
        assert!(rt.get(a).is_none());
    }
}
