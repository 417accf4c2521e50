//! `bv bench`: batch evaluation speed of one model on fixed-seed random
//! direction pairs . Prints `<number> M evals/s`.
//!
//! The pairs are drawn once, uniformly on the upper hemisphere, from
//! [`bv_core::sampling::rng`] with a fixed seed, so every run evaluates the same
//! pairs; they are held as structure-of-arrays f32 lanes
//! ([`bv_core::batch::PairBuf`]). They are split into chunks that a rayon pool
//! of `--threads` workers hands to [`bv_core::batch::eval`]: the model's SIMD
//! kernel where it has one, its scalar `eval` otherwise. One untimed pass warms
//! up (threads started, output pages touched, caches filled) and counts the
//! results that are not finite; then passes are timed until at least
//! [`MIN_TIMED`] has elapsed, so that small `--pairs` still give a stable
//! rate. The timed passes only evaluate: the count (a scan of every result,
//! about a sixth of a Cook-Torrance pass on AVX2) would be the same in each,
//! since the pairs and the model do not change, and the timings of other
//! libraries this is compared with (Mitsuba's `bsdf.eval`) hold no such scan. `--json` also says which path ran: whether the
//! model has a kernel, the instruction set dispatched and its f32 lanes.

use super::output::print;
use super::params::ModelArgs;
use anyhow::Context;
use bv_core::batch::{self, Out, PairBuf};
use bv_core::{Brdf, sampling};
use glam::DVec3;
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Seed of the benchmark pairs (fixed: every run evaluates the same pairs).
pub const SEED: u64 = 0x6276_6265_6e63_6801;

/// Pairs handed to one `eval_batch` call: large enough to amortise the call
/// and scheduling, small enough to balance the work across threads.
pub const CHUNK: usize = 4096;

/// Most pairs accepted per pass.
pub const MAX_PAIRS: usize = 50_000_000;

/// Most distinct pairs held in memory (24 bytes each as f32 lanes: 24 MiB). A larger
/// `--pairs` evaluates this pool over again, so memory stays bounded
/// whatever the count; a pool far larger than the caches already measures
/// the rate of out-of-cache evaluation.
pub const POOL: usize = 1 << 20;

/// Shortest total timed duration; passes repeat until it is reached.
pub const MIN_TIMED: Duration = Duration::from_millis(200);

/// Options of `bv bench`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchArgs {
    /// The model and its parameters.
    #[command(flatten)]
    pub model: ModelArgs,

    /// Direction pairs per pass (an integer, or e.g. 1e6), 1 to 50000000;
    /// at most 1048576 distinct pairs are held, larger counts reuse them.
    #[arg(long, value_name = "N", default_value = "1e6", value_parser = parse_count)]
    pub pairs: usize,

    /// Worker threads [default: all cores].
    #[arg(long, value_name = "T", value_parser = clap::value_parser!(u16).range(1..=1024))]
    pub threads: Option<u16>,

    /// Print JSON instead of one line of text.
    #[arg(long)]
    pub json: bool,
}

/// Parses a pair count: `1000`, `1e6` or `2.5e5` (a whole number from 1 to
/// [`MAX_PAIRS`]).
pub fn parse_count(s: &str) -> Result<usize, String> {
    let n = parse_whole(s)?;
    if n < 1.0 || n > MAX_PAIRS as f64 {
        return Err(format!("{} is outside 1..={MAX_PAIRS}", s.trim()));
    }
    Ok(n as usize)
}

/// A whole number typed as `1000`, `1_000`, `1e6` or `2.5e5` (any size; the
/// caller checks the range).
pub fn parse_whole(s: &str) -> Result<f64, String> {
    let s = s.trim().replace('_', "");
    let n = match s.parse::<u64>() {
        Ok(n) => n as f64,
        Err(_) => s
            .parse::<f64>()
            .map_err(|_| format!("`{s}` is not a number"))?,
    };
    if !(n.is_finite() && n.fract() == 0.0) {
        return Err(format!("`{s}` is not a whole number"));
    }
    Ok(n)
}

/// What one benchmark measured.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchResult {
    /// Pairs per pass.
    pub pairs: usize,
    /// Worker threads.
    pub threads: usize,
    /// Timed passes over all pairs.
    pub passes: usize,
    /// Timed duration.
    pub seconds: f64,
    /// The fastest single pass, in seconds (what "best of N" timings of other
    /// libraries report; less disturbed by other work on a shared machine).
    pub best_pass_seconds: f64,
    /// Results of one pass that were NaN or infinite (a model bug when
    /// non-zero), counted in the untimed warm-up pass.
    pub non_finite: usize,
    /// The path the evaluations took.
    pub dispatch: batch::Dispatch,
}

impl BenchResult {
    /// Evaluations per second.
    pub fn rate(&self) -> f64 {
        (self.pairs * self.passes) as f64 / self.seconds.max(1e-9)
    }

    /// Evaluations per second of the fastest pass.
    pub fn best_rate(&self) -> f64 {
        self.pairs as f64 / self.best_pass_seconds.max(1e-9)
    }
}

/// The benchmark's direction pairs: `n` pairs, both directions uniform on the
/// upper hemisphere, from the fixed [`SEED`].
pub fn random_pairs(n: usize) -> Vec<(DVec3, DVec3)> {
    let mut rng = sampling::rng(SEED);
    (0..n)
        .map(|_| {
            let wi = sampling::uniform_hemisphere(sampling::uniform2(&mut rng));
            let wo = sampling::uniform_hemisphere(sampling::uniform2(&mut rng));
            (wi, wo)
        })
        .collect()
}

/// Times batch evaluation of `brdf` on `count` pairs taken in turn from
/// `pairs` (over again when `count` is larger) with `threads` workers. Each
/// worker writes into its own [`CHUNK`]-sized buffer, so memory does not
/// grow with `count`.
pub fn measure(
    brdf: &dyn Brdf,
    pairs: &PairBuf,
    count: usize,
    threads: usize,
    min_timed: Duration,
) -> anyhow::Result<BenchResult> {
    anyhow::ensure!(!pairs.is_empty(), "no direction pairs to evaluate");
    let dispatch = std::sync::OnceLock::new();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("could not start the worker threads")?;
    // Chunk k covers evaluations k·CHUNK.. of the pass, pool entries from
    // (k·CHUNK) mod pool length on, wrapping around at the pool's end.
    let chunks = count.div_ceil(CHUNK);
    // One pass over every pair; with `check`, the count of results that are
    // not finite (0 without).
    let pass = |check: bool| -> usize {
        pool.install(|| {
            (0..chunks)
                .into_par_iter()
                .map_init(
                    || [vec![0f32; CHUNK], vec![0f32; CHUNK], vec![0f32; CHUNK]],
                    |[r, g, b], k| {
                        let first = k * CHUNK;
                        let len = CHUNK.min(count - first);
                        let mut done = 0;
                        while done < len {
                            let start = (first + done) % pairs.len();
                            let end = (start + len - done).min(pairs.len());
                            let n = end - start;
                            let span = done..done + n;
                            let mut out = Out {
                                rgb: [&mut r[span.clone()], &mut g[span.clone()], &mut b[span]],
                            };
                            let d = batch::eval(brdf, &pairs.dirs(start..end), &mut out);
                            dispatch.get_or_init(|| d);
                            done += n;
                        }
                        let o = [&r[..len], &g[..len], &b[..len]];
                        std::hint::black_box(o);
                        if check {
                            batch::count_non_finite(o, len)
                        } else {
                            0
                        }
                    },
                )
                .sum()
        })
    };
    let non_finite = pass(true);
    let start = Instant::now();
    let mut passes = 0;
    let mut best = f64::INFINITY;
    loop {
        let t = Instant::now();
        pass(false);
        best = best.min(t.elapsed().as_secs_f64());
        passes += 1;
        if start.elapsed() >= min_timed {
            break;
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let dispatch = *dispatch
        .get()
        .context("no batch was evaluated (an empty pass)")?;
    Ok(BenchResult {
        pairs: count,
        threads,
        passes,
        seconds,
        best_pass_seconds: best,
        non_finite,
        dispatch,
    })
}

/// Runs `bv bench`.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    let spec = args.model.spec()?;
    let brdf = spec
        .build()
        .with_context(|| format!("building model `{}`", spec.id()))?;
    let threads = match args.threads {
        Some(t) => usize::from(t),
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let pairs = PairBuf::from_pairs(&random_pairs(args.pairs.min(POOL)));
    // A warm-up pass and at least one timed one.
    let work = super::budget::Work {
        serial: 0,
        parallel: 2 * args.pairs as u64,
        threads,
    };
    super::budget::start(brdf.as_ref(), "bv bench", work, super::budget::LONG)?;
    let r = measure(brdf.as_ref(), &pairs, args.pairs, threads, MIN_TIMED)?;
    super::budget::finish(brdf.as_ref(), "bench")?;
    if r.non_finite > 0 {
        super::output::eprint(&format!(
            "bv bench: warning: {} of {} results were not finite (a bug in model `{}`)\n",
            r.non_finite,
            r.pairs,
            spec.id()
        ));
    }
    let rate = r.rate();
    let text = if args.json {
        let v = serde_json::json!({
            "model": spec.id(),
            "params": spec.params().to_json(),
            "pairs": r.pairs,
            "threads": r.threads,
            "passes": r.passes,
            "seconds": r.seconds,
            "evals_per_second": rate,
            "m_evals_per_second": rate / 1e6,
            "best_pass_seconds": r.best_pass_seconds,
            "best_m_evals_per_second": r.best_rate() / 1e6,
            "non_finite": r.non_finite,
            "kernel": r.dispatch.kernel,
            "isa": r.dispatch.isa,
            "lanes": r.dispatch.lanes,
            "precision": if r.dispatch.kernel { "f32" } else { "f64" },
        });
        format!("{v}\n")
    } else {
        let s = |n: usize| if n == 1 { "" } else { "s" };
        format!(
            "{:.*} M evals/s (model {}, {} pair{}, {} thread{}, {} pass{} in {:.3} s; best pass {:.*} M/s)\n",
            // Slow models (below 1 M evals/s) keep three significant digits.
            if rate >= 1e6 { 2 } else { 4 },
            rate / 1e6,
            spec.id(),
            r.pairs,
            s(r.pairs),
            r.threads,
            s(r.threads),
            r.passes,
            if r.passes == 1 { "" } else { "es" },
            r.seconds,
            if rate >= 1e6 { 2 } else { 4 },
            r.best_rate() / 1e6
        )
    };
    print(&text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::Rgb;

    #[test]
    fn counts_in_both_notations() {
        assert_eq!(parse_count("1000"), Ok(1000));
        assert_eq!(parse_count("1e6"), Ok(1_000_000));
        assert_eq!(parse_count("2.5e3"), Ok(2500));
        assert_eq!(parse_count("1_000"), Ok(1000));
        for bad in ["0", "-5", "1.5", "abc", "1e300", "inf", "NaN", ""] {
            assert!(parse_count(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn pairs_are_fixed_and_on_the_upper_hemisphere() {
        let a = random_pairs(100);
        assert_eq!(a, random_pairs(100));
        for (wi, wo) in a {
            for w in [wi, wo] {
                assert!((w.length() - 1.0).abs() < 1e-12 && w.z >= 0.0);
            }
        }
    }

    #[test]
    fn measure_evaluates_every_pair() {
        let brdf = bv_core::ModelSpec::new("lambert").unwrap().build().unwrap();
        let pairs = PairBuf::from_pairs(&random_pairs(10_000));
        let r = measure(brdf.as_ref(), &pairs, pairs.len(), 2, Duration::ZERO).unwrap();
        assert_eq!(
            (r.pairs, r.threads, r.passes, r.non_finite),
            (10_000, 2, 1, 0)
        );
        assert!(r.rate() > 0.0 && r.rate().is_finite());
        // The best pass is part of the timed duration, and never slower
        // than the mean.
        assert!(r.best_pass_seconds > 0.0 && r.best_pass_seconds <= r.seconds);
        assert!(r.best_rate() >= r.rate());
        // Lambert has a kernel; the ISA is whatever this CPU offers.
        assert!(r.dispatch.kernel && r.dispatch.lanes >= 1);
        assert_eq!(r.dispatch.isa, batch::isa().name());
    }

    /// A model that is NaN everywhere, so that every evaluation is counted.
    #[derive(Debug)]
    struct Nan;
    impl Brdf for Nan {
        fn id(&self) -> &'static str {
            "nan"
        }
        fn eval(&self, _: DVec3, _: DVec3) -> Rgb {
            Rgb::NAN
        }
        fn claims(&self) -> bv_core::Claims {
            bv_core::ModelSpec::new("lambert")
                .unwrap()
                .build()
                .unwrap()
                .claims()
        }
    }

    #[test]
    fn a_count_above_the_pool_reuses_it_and_evaluates_every_pair() {
        // Chunks wrap around a pool that is not a multiple of CHUNK, and
        // the last chunk is short.
        let pairs = PairBuf::from_pairs(&random_pairs(2 * CHUNK + 3));
        let count = 7 * CHUNK + 5;
        let r = measure(&Nan, &pairs, count, 3, Duration::ZERO).unwrap();
        assert_eq!((r.pairs, r.non_finite), (count, count));
        // No kernel: the scalar fallback.
        assert!(!r.dispatch.kernel);
        assert_eq!((r.dispatch.isa, r.dispatch.lanes), ("scalar", 1));
    }
}
