//! The watcher counts a file's quiet time from when its change arrived, not
//! from when the window next looked: a save is reloaded by the first poll
//! after it settled.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv_user::watch::{Reload, SETTLE, Watcher};
use std::time::{Duration, Instant};

fn lambert(kd: &str) -> String {
    format!(
        "analytic\n::begin parameters\nfloat kd 0 1 {kd}\n::end parameters\n\
         ::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{ return vec3(kd / 3.14159265); }}\n\
         ::end shader\n"
    )
}

#[test]
fn a_settled_save_is_reloaded_by_the_first_poll_after_it() {
    let dir = std::env::temp_dir().join(format!("bv-user-watch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("live.brdf");
    std::fs::write(&path, lambert("0.5")).unwrap();
    let mut w = Watcher::new().unwrap();
    w.watch(&path).unwrap();
    assert!(w.poll().is_empty(), "nothing changed yet");
    assert_eq!(w.settles_in(), None);

    std::fs::write(&path, lambert("0.25")).unwrap();
    // Nobody polls while the save settles (a window busy drawing).
    std::thread::sleep(SETTLE + Duration::from_millis(150));
    let reloads = w.poll();
    assert_eq!(
        reloads.len(),
        1,
        "one reload at the first poll: {reloads:?}"
    );
    assert!(matches!(&reloads[0], Reload::Loaded { .. }), "{reloads:?}");
    assert_eq!(w.settles_in(), None, "nothing waits any more");

    // A change just made waits at most SETTLE, counted from the change.
    std::fs::write(&path, lambert("0.75")).unwrap();
    let t0 = Instant::now();
    let mut waited = None;
    while t0.elapsed() < Duration::from_secs(5) {
        if !w.poll().is_empty() {
            break;
        }
        if let Some(d) = w.settles_in() {
            waited.get_or_insert(d);
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    let first = waited.expect("the change was seen settling");
    assert!(first <= SETTLE, "{first:?} > {SETTLE:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
