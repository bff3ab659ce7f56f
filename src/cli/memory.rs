//! `--max-memory SIZE`: the memory ceiling of a whole run. The stages that grow (translation,
//! reading a map into an arena, product and attractors, MDP build, solver) ask before they
//! allocate, through the progress observer ([`Observer::reserve`]), and refuse with an error
//! naming the stage and the sizes rather than allocate past it.
//!
//! What is in use is measured, not estimated: the resident set of the process
//! (`VmRSS` of `/proc/self/status`; 0 where it cannot be read, so only what the stages are about to add is
//! compared with the ceiling). The default is half the physical memory (`/proc/meminfo`), or
//! [`FALLBACK_DEFAULT`] where that cannot be read.
//!
//! [`Observer::reserve`]: hypersynth::stage::Observer::reserve

use std::sync::OnceLock;

use hypersynth::limits::{Bytes, MemoryBudget, MemoryLimit};

/// The memory option, shared by the main form and `translate`.
#[derive(clap::Args, Debug)]
#[group(id = "memory")]
pub struct Args {
    /// The most memory the run may use (its resident set): a number of bytes, or with a unit
    /// K, M, G or T (powers of 1024; `500M`, `2G`, `1.5G`) [default: half the physical
    /// memory]. Stages refuse, with the sizes they needed, before allocating past it.
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    max_memory: Option<u64>,
}

impl Args {
    /// Makes this run's ceiling the one given, or the default: call once, before any stage.
    pub fn install(&self) {
        let budget = match self.max_memory {
            Some(bytes) => MemoryBudget::new(bytes),
            None => default_budget(),
        };
        // A second call (there is none) would keep the first ceiling.
        let _ = BUDGET.set(budget);
    }
}

/// The ceiling when neither `--max-memory` nor the physical memory is known.
pub const FALLBACK_DEFAULT: u64 = 4 << 30;

static BUDGET: OnceLock<MemoryBudget> = OnceLock::new();

/// This run's ceiling ([`Args::install`]; the default if nothing was installed).
pub fn budget() -> MemoryBudget {
    *BUDGET.get_or_init(default_budget)
}

/// Half the physical memory: the rest stays for the system and whatever else runs.
fn default_budget() -> MemoryBudget {
    MemoryBudget::new(physical_memory().map_or(FALLBACK_DEFAULT, |total| total / 2))
}

/// `MemTotal` of `/proc/meminfo`, in bytes.
fn physical_memory() -> Option<u64> {
    kilobytes(&std::fs::read_to_string("/proc/meminfo").ok()?, "MemTotal:")
}

/// The process's resident set in bytes (`VmRSS` of `/proc/self/status`), 0 if unknown.
pub fn resident() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|text| kilobytes(&text, "VmRSS:"))
        .unwrap_or(0)
}

/// The value of the `/proc` line starting with `key`, given in kB, in bytes.
fn kilobytes(text: &str, key: &str) -> Option<u64> {
    let line = text.lines().find(|line| line.starts_with(key))?;
    let kilobytes: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kilobytes.checked_mul(1024)
}

/// Whether `bytes` more fit in this run's ceiling beside what is resident now; a refusal ends
/// with how to raise the ceiling.
pub fn reserve(bytes: u64, what: impl FnOnce() -> String) -> Result<(), MemoryLimit> {
    budget()
        .check(resident(), bytes, what)
        .map_err(|error| MemoryLimit {
            note: Some("raise it with --max-memory".to_string()),
            ..error
        })
}

/// What is left of the ceiling beside what is resident now.
pub fn available() -> u64 {
    budget().bytes().saturating_sub(resident())
}

/// The note that ends the translation's memory error: its limit is what the ceiling leaves.
pub fn raise_note() -> String {
    format!(
        "what --max-memory ({}) leaves beside what is in use: raise it with --max-memory",
        Bytes(budget().bytes())
    )
}

/// `SIZE`: a number of bytes, optionally fractional with a unit K, M, G or T (powers of 1024,
/// optionally followed by `B` or `iB`, any case).
fn parse_size(text: &str) -> Result<u64, String> {
    let trimmed = text.trim();
    let split = trimmed
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(trimmed.len());
    let (number, unit) = trimmed.split_at(split);
    let unit = unit.trim();
    let invalid = || {
        format!("`{text}` is not a size: give bytes, or a number with K, M, G or T (as in 500M)")
    };
    let value: f64 = number.parse().map_err(|_| invalid())?;
    let upper = unit.to_ascii_uppercase();
    let base = upper
        .strip_suffix("IB")
        .or_else(|| upper.strip_suffix('B'))
        .unwrap_or(&upper);
    let scale: u64 = match base {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        "T" => 1 << 40,
        _ => return Err(invalid()),
    };
    let bytes = value * scale as f64;
    if !bytes.is_finite() || bytes < 1.0 || bytes >= u64::MAX as f64 {
        return Err(format!("`{text}` is not a size of at least one byte"));
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_in_powers_of_1024() {
        assert_eq!(parse_size("500M"), Ok(500 << 20));
        assert_eq!(parse_size("2G"), Ok(2 << 30));
        assert_eq!(parse_size("1.5g"), Ok(3 << 29));
        assert_eq!(parse_size("64KiB"), Ok(64 << 10));
        assert_eq!(parse_size("64kb"), Ok(64 << 10));
        assert_eq!(parse_size("4096"), Ok(4096));
        assert_eq!(parse_size(" 1 T "), Ok(1 << 40));
        assert!(parse_size("0").is_err());
        assert!(parse_size("12Q").is_err());
        assert!(parse_size("M").is_err());
        assert!(parse_size("-5M").is_err());
        assert!(parse_size("1e9").is_err());
    }
}
