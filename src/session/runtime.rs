//! Evaluators built from the state's specs (not saved). Each BRDF is rebuilt
//! only when its spec changed; its revision number then changes, which is the
//! key the derived results' caches use (`crate::derive`).
//!
//! A revision names what was built, not when: it is a hash of the spec and
//! the catalogue's revision (a reloaded user file is another model under the
//! same id). So a result derived for one build is found by any later build
//! of the same spec, in this runtime (a slider dragged back) or another one
//! (the window's, while `bv render` or a screenshot draws the same scene).
//! A spec another runtime of the process holds is not even built again: the
//! runtimes share the evaluator. Headless paths (figures, decks, meshes,
//! SVG) use the process's one [`shared`] runtime.

use super::state::AppState;
use bv_core::{Brdf, ModelSpec};
use std::collections::HashMap;
use std::sync::{Arc, LazyLock, Mutex, MutexGuard, Weak};

/// One built BRDF.
#[derive(Clone)]
pub struct Built {
    /// The spec it was built from.
    pub spec: ModelSpec,
    /// The evaluator, or `None` if building failed.
    pub brdf: Option<Arc<dyn Brdf>>,
    /// Why building failed.
    pub error: Option<String>,
    /// Names the build: equal for builds of the same spec under the same
    /// catalogue, different otherwise (the key of derived results). The top
    /// bit is clear (`session::frame` sets it for a turned surface).
    pub revision: u64,
}

/// The revision of a build of `key`: a 63-bit hash (FNV-1a, stable across
/// runs and platforms) of the spec's JSON and the catalogue revision.
fn revision_of(key: &BuildKey) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in key.0.bytes().chain(key.1.to_le_bytes()) {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    (h & !(1 << 63)).max(1)
}

/// What a build is shared by: the spec (as JSON) and the catalogue revision
/// (a reloaded user file is another model under the same id).
type BuildKey = (String, u64);

/// Evaluators some runtime of the process holds, by what they were built
/// from. Weak: an evaluator no runtime holds is freed (a MERL table is
/// tens of megabytes).
static BUILDS: LazyLock<Mutex<Builds>> = LazyLock::new(Mutex::default);

/// What a runtime of the process holds, by what it was built from: the
/// evaluator (weak) and its revision.
type Builds = HashMap<BuildKey, (Weak<dyn Brdf>, u64)>;

/// The evaluator of `spec` and its revision: one a runtime of the process
/// holds, or a new build.
fn build(spec: &ModelSpec) -> (Result<Arc<dyn Brdf>, String>, bool, u64) {
    let key = (spec.to_json().to_string(), bv_core::registry::revision());
    let mut builds = BUILDS.lock().unwrap_or_else(|e| e.into_inner());
    builds.retain(|_, (w, _)| w.strong_count() > 0);
    if let Some((w, rev)) = builds.get(&key)
        && let Some(b) = w.upgrade()
    {
        return (Ok(b), false, *rev);
    }
    // Built outside the lock would let two runtimes build the same spec at
    // once; a build takes milliseconds (a MERL table is read by the loader
    // beforehand), so the lock is held.
    let revision = revision_of(&key);
    match spec.build() {
        Ok(b) => {
            let b = Arc::<dyn Brdf>::from(b);
            builds.insert(key, (Arc::downgrade(&b), revision));
            (Ok(b), true, revision)
        }
        Err(e) => (Err(e.to_string()), true, revision),
    }
}

/// Built evaluators by BRDF id.
#[derive(Default)]
pub struct Runtime {
    built: HashMap<u64, Built>,
    builds: u64,
}

impl Runtime {
    /// Rebuilds what changed in `state` and forgets removed BRDFs.
    pub fn sync(&mut self, state: &AppState) {
        for e in &state.brdfs {
            if self.built.get(&e.id).is_some_and(|b| b.spec == e.spec) {
                continue;
            }
            let (brdf, built, revision) = build(&e.spec);
            self.builds += u64::from(built);
            let (brdf, error) = match brdf {
                Ok(b) => (Some(b), None),
                Err(err) => (None, Some(err)),
            };
            self.built.insert(
                e.id,
                Built {
                    spec: e.spec.clone(),
                    brdf,
                    error,
                    revision,
                },
            );
        }
        self.built.retain(|id, _| state.entry(*id).is_some());
    }

    /// The built BRDF of id `id`.
    pub fn get(&self, id: u64) -> Option<&Built> {
        self.built.get(&id)
    }

    /// How many builds this runtime ran (evaluators shared with another
    /// runtime not counted), for tests of the caching.
    pub fn build_count(&self) -> u64 {
        self.builds
    }
}

/// The process's runtime for headless work: figures, decks, SVG and meshes
/// drawn by `bv render`, the screenshot dialog and scripts. One runtime and
/// one derived-result cache per process: `bv render --view all` builds each
/// BRDF once and computes each derived result once.
pub fn shared() -> MutexGuard<'static, Runtime> {
    static SHARED: LazyLock<Mutex<Runtime>> = LazyLock::new(Mutex::default);
    // A panic while it was held leaves a consistent map.
    SHARED.lock().unwrap_or_else(|e| e.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::ParamValue;

    #[test]
    fn rebuilds_only_what_changed() {
        let mut s = AppState::default();
        // Parameters no other test uses: tests run in parallel in one
        // process, and a spec another test holds is shared, not built.
        let lambert =
            |a: f64| ModelSpec::from_json("lambert", &serde_json::json!({ "albedo": a })).unwrap();
        let a = s.add(lambert(0.3141));
        let b = s.add(lambert(0.2718));
        let mut rt = Runtime::default();
        rt.sync(&s);
        assert_eq!(rt.build_count(), 2);
        let rev_a = rt.get(a).unwrap().revision;
        rt.sync(&s);
        assert_eq!(rt.build_count(), 2);
        s.entry_mut(b)
            .unwrap()
            .spec
            .set("albedo", ParamValue::Color([0.2113; 3]))
            .unwrap();
        rt.sync(&s);
        assert_eq!(rt.build_count(), 3);
        assert_eq!(rt.get(a).unwrap().revision, rev_a);
        s.brdfs.retain(|e| e.id != a);
        rt.sync(&s);
        assert!(rt.get(a).is_none());
    }

    #[test]
    fn runtimes_share_what_they_both_hold() {
        let mut s = AppState::default();
        let spec =
            ModelSpec::from_json("ward", &serde_json::json!({"alpha_x": 0.1234567})).unwrap();
        let a = s.add(spec.clone());
        let mut one = Runtime::default();
        one.sync(&s);
        let mut two = Runtime::default();
        two.sync(&s);
        let (x, y) = (one.get(a).unwrap(), two.get(a).unwrap());
        assert_eq!(x.revision, y.revision);
        assert!(Arc::ptr_eq(
            x.brdf.as_ref().unwrap(),
            y.brdf.as_ref().unwrap()
        ));
        assert_eq!(two.build_count(), 0);
        // Freed with the last runtime holding it: a later runtime builds
        // anew, under the same revision (its derived results still apply).
        let rev = x.revision;
        drop((one, two));
        let mut three = Runtime::default();
        three.sync(&s);
        assert_eq!(three.build_count(), 1);
        assert_eq!(three.get(a).unwrap().revision, rev);
        // Another spec, another revision.
        let b = s
            .add(ModelSpec::from_json("ward", &serde_json::json!({"alpha_x": 0.1234568})).unwrap());
        three.sync(&s);
        assert_ne!(three.get(b).unwrap().revision, rev);
    }
}
