//! Limits the stages share: a wall-clock [`Deadline`], the `Clock` that checks one from a hot
//! loop, and a [`MemoryBudget`] with the [`MemoryLimit`] error of a stage that would exceed it;
//! [`Bytes`] shows sizes in messages.
//!
//! Counted limits (states, edges, BDD nodes, steps) stay with the stages that count them: they
//! are deterministic, so a run that succeeds once succeeds every time. A deadline is not: it is
//! what a user means by "at most this many seconds", and a run near it may end either way.
//!
//! ```
//! use std::time::Duration;
//! use hypersynth::limits::{Bytes, Deadline, MemoryBudget};
//!
//! assert!(!Deadline::after(Duration::from_secs(3600)).passed());
//! assert!(Deadline::after(Duration::ZERO).passed());
//! let budget = MemoryBudget::new(500 << 20);
//! assert!(budget.check(100 << 20, 300 << 20, || "a test".to_string()).is_ok());
//! let refused = budget.check(300 << 20, 300 << 20, || "a test".to_string()).unwrap_err();
//! assert_eq!(
//!     refused.to_string(),
//!     "a test needs about 300 MiB more, with 300 MiB already in use: more than the memory \
//!      limit of 500 MiB"
//! );
//! assert_eq!(Bytes(1536).to_string(), "1.5 KiB");
//! ```

use std::fmt;
use std::time::{Duration, Instant};

/// A point in wall-clock time after which work stops, or none; it remembers the time it was
/// set for, so that a message can name the limit the user gave rather than what was left of it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Deadline(Option<(Instant, Duration)>);

impl Deadline {
    /// No deadline: work never stops for time.
    pub const NONE: Deadline = Deadline(None);

    /// `duration` from now (no deadline if that is beyond what an [`Instant`] can hold).
    pub fn after(duration: Duration) -> Deadline {
        Deadline(
            Instant::now()
                .checked_add(duration)
                .map(|instant| (instant, duration)),
        )
    }

    /// The instant, if there is a deadline.
    pub fn instant(self) -> Option<Instant> {
        self.0.map(|(instant, _)| instant)
    }

    /// The time the deadline was set for (the `duration` of [`after`](Deadline::after)), if
    /// there is one.
    pub fn limit(self) -> Option<Duration> {
        self.0.map(|(_, limit)| limit)
    }

    /// Whether the deadline has passed (never, without one).
    pub fn passed(self) -> bool {
        self.instant()
            .is_some_and(|deadline| Instant::now() >= deadline)
    }

    /// The time left (zero once passed), `None` without a deadline.
    pub fn remaining(self) -> Option<Duration> {
        self.instant()
            .map(|deadline| deadline.saturating_duration_since(Instant::now()))
    }

    /// The earlier of the two deadlines.
    pub fn min(self, other: Deadline) -> Deadline {
        match (self.0, other.0) {
            (Some(a), Some(b)) => Deadline(Some(if b.0 < a.0 { b } else { a })),
            (a, b) => Deadline(a.or(b)),
        }
    }
}

/// How many units of work a [`Clock`] lets pass between two readings of the time: reading it
/// costs about as much as a few dozen BDD steps, and a step well under a microsecond, so the
/// deadline is noticed within a millisecond or so and the reading costs under 1%.
const UNITS_PER_READING: u64 = 1 << 12;

/// Checks a [`Deadline`] from a loop that counts its work: [`Clock::tick`] is a subtraction
/// and a compare, and reads the time once per [`UNITS_PER_READING`] units.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Clock {
    deadline: Deadline,
    countdown: u64,
    passed: bool,
}

impl Clock {
    pub(crate) fn new(deadline: Deadline) -> Clock {
        Clock {
            deadline,
            countdown: UNITS_PER_READING,
            passed: false,
        }
    }

    /// Counts `units` of work; whether the deadline has passed (once it has, always).
    #[inline]
    pub(crate) fn tick(&mut self, units: u64) -> bool {
        if self.deadline.0.is_none() {
            return false;
        }
        match self.countdown.checked_sub(units) {
            Some(left) if left > 0 => {
                self.countdown = left;
                self.passed
            }
            _ => self.read(),
        }
    }

    /// Reads the time now, whatever the count.
    #[cold]
    pub(crate) fn read(&mut self) -> bool {
        self.countdown = UNITS_PER_READING;
        self.passed = self.passed || self.deadline.passed();
        self.passed
    }

    pub(crate) fn deadline(&self) -> Deadline {
        self.deadline
    }
}

/// Why counted or timed work stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stop {
    /// The count of work units.
    Count,
    /// The bytes allowed.
    Bytes,
    /// The deadline.
    Time,
}

/// Counted work with a ceiling, and a deadline read every so often ([`Clock`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Work {
    done: u64,
    max: u64,
    clock: Clock,
}

impl Work {
    /// At most `max` units, until `deadline`.
    pub(crate) fn new(max: u64, deadline: Deadline) -> Work {
        Work {
            done: 0,
            max,
            clock: Clock::new(deadline),
        }
    }

    /// No limit.
    pub(crate) fn unlimited() -> Work {
        Work::new(u64::MAX, Deadline::NONE)
    }

    /// Counts `units` more; an error once past the count or the deadline.
    #[inline]
    pub(crate) fn charge(&mut self, units: u64) -> Result<(), Stop> {
        self.done = self.done.saturating_add(units);
        if self.done > self.max {
            return Err(Stop::Count);
        }
        if self.clock.tick(units) {
            return Err(Stop::Time);
        }
        Ok(())
    }

    /// The deadline.
    pub(crate) fn deadline(&self) -> Deadline {
        self.clock.deadline()
    }
}

/// A number of bytes, shown in binary units with three significant digits (`512 B`, `1.5 KiB`,
/// `4.00 GiB`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Bytes(pub u64);

impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const UNITS: [&str; 7] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
        if self.0 < 1024 {
            return write!(f, "{} B", self.0);
        }
        let mut value = self.0 as f64;
        let mut unit = 0;
        while value >= 1024.0 && unit + 1 < UNITS.len() {
            value /= 1024.0;
            unit += 1;
        }
        let text = if value >= 100.0 {
            format!("{value:.0}")
        } else if value >= 10.0 {
            format!("{value:.1}")
        } else {
            format!("{value:.2}")
        };
        // `1.50` reads as `1.5`, `2.00` as `2`: trailing zeros say nothing.
        let text = if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.')
        } else {
            &text
        };
        write!(f, "{text} {}", UNITS[unit])
    }
}

/// A ceiling on the memory of a whole run, in bytes. Stages that grow ask it before they
/// allocate ([`MemoryBudget::check`], usually through [`crate::stage::Meter::reserve`]), with
/// what is in use already (the caller measures that: the library cannot see the process) and
/// what they are about to add, and refuse with a [`MemoryLimit`] rather than allocate past it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryBudget {
    limit: u64,
}

impl MemoryBudget {
    /// No ceiling.
    pub const UNLIMITED: MemoryBudget = MemoryBudget { limit: u64::MAX };

    /// At most `bytes` in all.
    pub fn new(bytes: u64) -> MemoryBudget {
        MemoryBudget { limit: bytes }
    }

    /// The ceiling in bytes.
    pub fn bytes(self) -> u64 {
        self.limit
    }

    /// Whether `needed` more bytes fit beside `in_use`; `what` (called only to refuse) says
    /// what needs them, for the message.
    pub fn check(
        self,
        in_use: u64,
        needed: u64,
        what: impl FnOnce() -> String,
    ) -> Result<(), MemoryLimit> {
        if in_use.saturating_add(needed) <= self.limit {
            Ok(())
        } else {
            Err(MemoryLimit {
                what: what(),
                needed,
                in_use,
                limit: self.limit,
                note: None,
            })
        }
    }
}

/// A stage would have needed more memory than the [`MemoryBudget`] allows, and stopped before
/// allocating it.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "{what} needs about {} more, with {} already in use: more than the memory limit of {}{}",
    Bytes(*.needed),
    Bytes(*.in_use),
    Bytes(*.limit),
    .note.as_ref().map(|note| format!(" ({note})")).unwrap_or_default()
)]
pub struct MemoryLimit {
    /// What needed the memory (a stage and its sizes).
    pub what: String,
    /// The bytes it would have added.
    pub needed: u64,
    /// The bytes in use when it asked.
    pub in_use: u64,
    /// The ceiling.
    pub limit: u64,
    /// What the caller adds at the end of the message, in parentheses (how its users raise
    /// the ceiling, say); none from the library.
    pub note: Option<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_read_in_binary_units() {
        let shown = |n: u64| Bytes(n).to_string();
        assert_eq!(shown(0), "0 B");
        assert_eq!(shown(1023), "1023 B");
        assert_eq!(shown(1024), "1 KiB");
        assert_eq!(shown(500 << 20), "500 MiB");
        assert_eq!(shown(3 << 29), "1.5 GiB");
        assert_eq!(shown((10 << 30) + (1 << 29)), "10.5 GiB");
        assert_eq!(shown(u64::MAX), "16 EiB");
    }

    #[test]
    fn a_clock_notices_its_deadline_only_when_it_reads_the_time() {
        let mut clock = Clock::new(Deadline::after(Duration::ZERO));
        // The first readings come after UNITS_PER_READING units.
        assert!(!clock.tick(1));
        assert!(clock.tick(UNITS_PER_READING));
        assert!(clock.tick(1), "once passed, always passed");
        let mut never = Clock::new(Deadline::NONE);
        assert!(!never.tick(u64::MAX));
        assert!(!never.read());
    }

    #[test]
    fn the_earlier_deadline_wins() {
        let soon = Deadline::after(Duration::from_secs(1));
        let later = Deadline::after(Duration::from_secs(100));
        assert_eq!(soon.min(later), soon);
        assert_eq!(later.min(soon).limit(), Some(Duration::from_secs(1)));
        assert_eq!(Deadline::NONE.min(later), later);
        assert_eq!(soon.min(Deadline::NONE), soon);
        assert!(Deadline::NONE.remaining().is_none());
        assert!(soon.remaining().unwrap() <= Duration::from_secs(1));
    }

    #[test]
    fn a_budget_allows_exactly_up_to_its_ceiling() {
        let budget = MemoryBudget::new(1000);
        assert!(budget.check(400, 600, String::new).is_ok());
        let error = budget.check(400, 601, || "x".into()).unwrap_err();
        assert_eq!((error.needed, error.in_use, error.limit), (601, 400, 1000));
        assert!(
            MemoryBudget::UNLIMITED
                .check(u64::MAX, 1, String::new)
                .is_ok()
        );
    }
}
