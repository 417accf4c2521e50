//! What a command-line analysis may spend on a model, and what it does when
//! evaluations fail.
//!
//! A built-in model evaluates in a fraction of a microsecond; a user's
//! shader is interpreted and may take milliseconds per evaluation, or fail
//! (its step budget). Every command that evaluates a model many times
//! (`check`, `slice`, `tabulate`, `bench`) therefore:
//! 1. [`start`]s with the number of evaluations it needs: a model whose
//!    measured cost ([`Brdf::eval_cost`]) would take longer than the
//!    command's budget is refused at once, with the numbers; otherwise the
//!    model's clock is set ([`Brdf::limit_time`]), so that a model that is
//!    slower than its probe said still ends in bounded time;
//! 2. [`finish`]es by reading [`Brdf::health`]: a result computed with
//!    failed evaluations is an error (they read as 0), non-finite values a
//!    warning with their count.

use super::output::eprint;
use anyhow::{Result, bail};
use bv_core::Brdf;
use bv_core::text::fmt_duration;
use std::time::Duration;

/// Budget of `bv check`'s evaluations (the panel's badges use the same).
pub const CHECK: Duration = bv_core::analysis::CHECK_BUDGET;
/// Budget of `slice`, `tabulate` and `bench`.
pub const LONG: Duration = Duration::from_secs(60);

/// How many evaluations an analysis makes: `serial` on one thread,
/// `parallel` spread over `threads`.
#[derive(Debug, Clone, Copy)]
pub struct Work {
    /// Evaluations made one after another.
    pub serial: u64,
    /// Evaluations spread over the threads.
    pub parallel: u64,
    /// The threads the parallel part runs on.
    pub threads: usize,
}

/// Refuses `brdf` if `work` would take longer than `budget` at its
/// measured cost, and otherwise limits its time to the budget. `what` names
/// the command in the message.
pub fn start(brdf: &dyn Brdf, what: &str, work: Work, budget: Duration) -> Result<()> {
    let threads = work.threads.max(1);
    let evaluations = work.serial + work.parallel;
    if let Some(cost) = brdf.eval_cost() {
        let estimate =
            cost.as_secs_f64() * (work.serial as f64 + work.parallel as f64 / threads as f64);
        if estimate > budget.as_secs_f64() {
            bail!(
                "model `{}` is too slow for {what}: {} per evaluation, and {what} needs about \
                 {evaluations} evaluations (about {} on {threads} thread{}); its budget is {}",
                brdf.id(),
                fmt_duration(cost),
                fmt_duration(Duration::from_secs_f64(estimate.min(1e9))),
                if threads == 1 { "" } else { "s" },
                fmt_duration(budget)
            );
        }
    }
    brdf.limit_time(Some(budget));
    Ok(())
}

/// Ends an analysis of `brdf`: an error if evaluations failed, a warning
/// (on stderr, prefixed `bv {what}: `) if some were not finite.
pub fn finish(brdf: &dyn Brdf, what: &str) -> Result<()> {
    brdf.limit_time(None);
    let health = brdf.health();
    if let Some(e) = health.failure(brdf.id()) {
        return Err(e.into());
    }
    if health.non_finite > 0 {
        eprint(&format!(
            "bv {what}: warning: {} evaluation{} of model `{}` returned NaN or infinity, read as 0\n",
            health.non_finite,
            if health.non_finite == 1 { "" } else { "s" },
            brdf.id()
        ));
    }
    Ok(())
}
