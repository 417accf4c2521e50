//! Numbers as people read them, shared by the panel, the plots and the
//! reports.

/// Formats a value with about four significant digits (plots, readouts).
pub fn fmt_value(v: f64) -> String {
    if v == 0.0 {
        "0".to_string()
    } else if !(1e-3..1e4).contains(&v.abs()) {
        format!("{v:.3e}")
    } else {
        let digits = (3 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{v:.digits$}")
    }
}

/// An angle in degrees with at most three decimals and no trailing zeros
/// (89.999° must not read 90°; 45° reads `45`).
pub fn fmt_deg(x: f64) -> String {
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// A duration as a person reads it: `12.3 µs`, `4.5 ms`, `7.0 s`, `15 min`,
/// `2.1 h`.
pub fn fmt_duration(d: std::time::Duration) -> String {
    let s = d.as_secs_f64();
    if s >= 3600.0 {
        format!("{:.1} h", s / 3600.0)
    } else if s >= 60.0 {
        format!("{:.0} min", s / 60.0)
    } else if s >= 1.0 {
        format!("{s:.1} s")
    } else if s >= 1e-3 {
        format!("{:.1} ms", s * 1e3)
    } else {
        format!("{:.1} µs", s * 1e6)
    }
}
