//! The fit as a background job (`derive::fit`): it converges to a known
//! model, reports progress, stops when cancelled, and restarts when the key
//! changes.

// Test code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::derive::Waker;
use bv::derive::fit::{FitJob, FitKey};
use bv_core::ModelSpec;
use bv_core::fit::{FitOptions, Metric};
use std::time::Duration;

fn spec(model: &str, params: &[(&str, &str)]) -> ModelSpec {
    let mut s = ModelSpec::new(model).unwrap();
    for (k, v) in params {
        s.set_str(k, v).unwrap();
    }
    s
}

fn float(s: &ModelSpec, name: &str) -> f64 {
    s.params().float(name).unwrap()
}

/// Ward α = 0.08 (ks, kd fixed at the truth): the job recovers α to 1 %.
#[test]
fn the_job_recovers_a_known_model() {
    let truth = spec("ward", &[("alpha", "0.08"), ("ks", "0.3"), ("kd", "0.4")]);
    let start = spec("ward", &[("alpha", "0.3"), ("ks", "0.3"), ("kd", "0.4")]);
    let job = FitJob::default();
    let key = FitKey {
        target: truth.clone(),
        model: start,
        free: vec!["alpha".into()],
        metric: Metric::Ngan,
    };
    job.request(key.clone(), FitOptions::default(), &Waker::none());
    assert!(job.wait_idle(Duration::from_secs(300)));
    let st = job.status();
    assert_eq!(st.key.as_ref(), Some(&key));
    let r = st.result.expect("a result").expect("no error");
    assert!(!r.cancelled);
    let a = float(&r.spec, "alpha_x");
    assert!((a / 0.08 - 1.0).abs() < 0.01, "alpha {a}");
    assert!(
        r.error < 1e-3 * r.initial_error.max(1e-9) || r.error < 1e-6,
        "{}",
        r.error
    );
    // The same key again: no new fit (the finished one is kept).
    job.request(key, FitOptions::default(), &Waker::none());
    assert!(!job.status().running);
}

fn slow_key(alpha: &str) -> FitKey {
    FitKey {
        target: spec(
            "cook-torrance",
            &[("distribution", "ggx"), ("alpha", alpha)],
        ),
        model: spec("cook-torrance", &[("distribution", "ggx")]),
        free: vec!["kd".into(), "ks".into(), "alpha".into()],
        metric: Metric::Ngan,
    }
}

fn slow_opts() -> FitOptions {
    FitOptions {
        starts: 64,
        max_iterations: 400,
        ..FitOptions::default()
    }
}

/// Waits until the running fit has reported `n` iterations.
fn wait_progress(job: &FitJob, n: usize) {
    let t0 = std::time::Instant::now();
    while job
        .status()
        .progress
        .is_none_or(|p| p.start == 0 && p.iteration < n)
    {
        assert!(t0.elapsed() < Duration::from_secs(120), "no progress");
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn cancel_stops_the_fit_and_leaves_no_result() {
    let job = FitJob::default();
    job.request(slow_key("0.05"), slow_opts(), &Waker::none());
    wait_progress(&job, 1);
    let p = job.status().progress.unwrap();
    assert!(p.error.is_finite() && p.starts == 64);
    job.cancel();
    // 64 starts of up to 400 iterations would take minutes; a cancelled fit
    // stops within one step.
    assert!(
        job.wait_idle(Duration::from_secs(60)),
        "the fit did not stop"
    );
    let st = job.status();
    assert!(st.key.is_none() && st.result.is_none() && !st.running);
}

#[test]
fn a_new_key_cancels_the_running_fit_and_starts_its_own() {
    let job = FitJob::default();
    job.request(slow_key("0.05"), slow_opts(), &Waker::none());
    wait_progress(&job, 1);
    assert_eq!(job.live(), 1);
    // Another key: the first fit is cancelled, the second runs.
    let quick = FitKey {
        target: spec("lambert", &[("albedo", "0.25")]),
        model: spec("lambert", &[("albedo", "0.5")]),
        free: vec!["albedo".into()],
        metric: Metric::E2,
    };
    job.request(quick.clone(), FitOptions::default(), &Waker::none());
    assert!(
        job.wait_idle(Duration::from_secs(120)),
        "the first fit did not stop"
    );
    let st = job.status();
    assert_eq!(st.key, Some(quick));
    let r = st.result.unwrap().unwrap();
    let c = r.spec.params().color("albedo").unwrap();
    for x in c.to_array() {
        assert!((x / 0.25 - 1.0).abs() < 1e-3, "albedo {c:?}");
    }
}
