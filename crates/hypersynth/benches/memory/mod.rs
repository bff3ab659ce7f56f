//! Peak resident memory for the benchmarks (Linux: /proc/self/status and clear_refs; elsewhere
//! the peak is unknown and resetting does nothing). Each benchmark uses what it needs.
#![allow(dead_code)]

/// The peak resident set (VmHWM) in MiB since the start or the last [`reset_peak`].
pub fn peak_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// [`peak_mib`] as text with one decimal, `-` when unknown.
pub fn peak_text() -> String {
    peak_mib().map_or_else(|| "-".to_string(), |mib| format!("{mib:.1}"))
}

/// Resets the peak so that what follows reports its own.
pub fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}
