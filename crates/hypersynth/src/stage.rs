//! The pipeline's stages, how long each took, and a hook to watch them run.
//!
//! The library never prints: a caller that wants progress bars or a timing line passes an
//! [`Observer`] to the stages that take one, and is told when each stage starts and ends.
//! [`Timings`] is an observer that records the seconds per stage; `()` ignores everything.
//!
//! **Progress protocol.** A stage that knows how much work it has runs under [`metered`], which
//! hands it a [`Meter`]: the stage sets its total once ([`Meter::set_total`], in units of its
//! choice: bytes, states, sweeps) and then advances it from its loops ([`Meter::advance`],
//! [`Meter::set`]). A call costs an add and a compare; the meter tells the observer
//! ([`Observer::progress`]) only when the count crosses the next 1/256 of the total, so the
//! observer hears at most about 260 times per stage, always on the calling thread, with `done`
//! non-decreasing and at most `total`, and `total` fixed for the stage. Parallel work (rayon)
//! cannot share the `&mut` meter: [`Meter::parallel`] runs jobs on the pool, gives each a
//! [`Tally`] (an atomic counter they add to in batches) and reports the tally from the calling
//! thread while they run. Stages without a known total report nothing (a caller shows a
//! spinner).
//!
//! ```
//! use hypersynth::stage::{Stage, Timings, timed};
//!
//! let mut timings = Timings::default();
//! let sum = timed(&mut timings, Stage::Solve, || (1..=10).sum::<u32>());
//! assert_eq!(sum, 55);
//! assert!(timings.get(Stage::Solve) >= 0.0);
//! ```

use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use serde::Serialize;

use crate::limits::MemoryLimit;

/// A stage of the pipeline, in pipeline order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Reading the arena (and the formulas' syntax).
    Parse,
    /// Formulas to DFAs (or HOA files read).
    Translate,
    /// The hypergame product.
    Product,
    /// The three attractors and win-labels.
    Attractors,
    /// The adversary model.
    Adversary,
    /// The hypergame MDP.
    MdpBuild,
    /// The certified values.
    Solve,
    /// The opportunistic policy (tie-breaking included).
    Policy,
    /// The controller evaluated as a Markov chain.
    Evaluation,
    /// Simulated runs and the trace.
    Simulation,
}

impl Stage {
    /// Every stage, in pipeline order: `stage as usize` is the index of `stage` here.
    pub const ALL: [Stage; 10] = [
        Stage::Parse,
        Stage::Translate,
        Stage::Product,
        Stage::Attractors,
        Stage::Adversary,
        Stage::MdpBuild,
        Stage::Solve,
        Stage::Policy,
        Stage::Evaluation,
        Stage::Simulation,
    ];

    /// The stage's name in reports (the JSON key of [`Timings`]).
    pub fn name(self) -> &'static str {
        match self {
            Stage::Parse => "parse",
            Stage::Translate => "translate",
            Stage::Product => "product",
            Stage::Attractors => "attractors",
            Stage::Adversary => "adversary",
            Stage::MdpBuild => "mdp_build",
            Stage::Solve => "solve",
            Stage::Policy => "policy",
            Stage::Evaluation => "evaluation",
            Stage::Simulation => "simulation",
        }
    }
}

/// Told when stages start and finish, and of warnings about the input (all default to doing
/// nothing).
pub trait Observer {
    /// `stage` starts.
    fn started(&mut self, _stage: Stage) {}
    /// `done` of the `total` units of work of the running `stage` are done (see the module
    /// documentation for the protocol: coarse, `done` non-decreasing and at most `total`).
    fn progress(&mut self, _stage: Stage, _done: u64, _total: u64) {}
    /// `stage` finished after `seconds`.
    fn finished(&mut self, _stage: Stage, _seconds: f64) {}
    /// Something about the input deserves a warning (one line, no trailing period).
    fn warning(&mut self, _message: &str) {}
    /// Asked by `stage` before it allocates about `bytes` more (`what` says what, for a
    /// message): an error refuses, and the stage fails with it before allocating. The library
    /// has no ceiling of its own, so the default allows everything; a caller with one measures
    /// what is in use and asks its [`MemoryBudget`](crate::limits::MemoryBudget).
    fn reserve(
        &mut self,
        _stage: Stage,
        _bytes: u64,
        _what: &dyn Fn() -> String,
    ) -> Result<(), MemoryLimit> {
        Ok(())
    }
}

impl Observer for () {}

/// Runs `work` as `stage`, telling `observer`.
pub fn timed<T>(observer: &mut dyn Observer, stage: Stage, work: impl FnOnce() -> T) -> T {
    observer.started(stage);
    let start = Instant::now();
    let result = work();
    observer.finished(stage, start.elapsed().as_secs_f64());
    result
}

/// Runs `work` as `stage`, telling `observer`, with a [`Meter`] for `work` to report its
/// progress through.
pub fn metered<T>(
    observer: &mut dyn Observer,
    stage: Stage,
    work: impl FnOnce(&mut Meter<'_>) -> T,
) -> T {
    observer.started(stage);
    let start = Instant::now();
    let result = work(&mut Meter::new(&mut *observer, stage));
    observer.finished(stage, start.elapsed().as_secs_f64());
    result
}

/// How many reports a stage makes at most, beside its first (see the module documentation).
const REPORTS: u64 = 256;

/// A stage's progress counter, which tells its observer at coarse granularity (see the module
/// documentation).
pub struct Meter<'o> {
    observer: &'o mut dyn Observer,
    stage: Stage,
    total: u64,
    done: u64,
    /// The count at which the next report is due (`u64::MAX` before a total is set).
    next: u64,
}

impl<'o> Meter<'o> {
    /// A meter of `stage` reporting to `observer`, with no total yet.
    pub fn new(observer: &'o mut dyn Observer, stage: Stage) -> Meter<'o> {
        Meter {
            observer,
            stage,
            total: 0,
            done: 0,
            next: u64::MAX,
        }
    }

    /// A meter of `stage` that tells no one, for callers without an observer.
    pub fn unobserved(stage: Stage) -> Meter<'static> {
        // `()` has no size: leaking a box of it allocates nothing.
        Meter::new(Box::leak(Box::new(())), stage)
    }

    /// Sets the stage's total work and reports that none is done; call it once, before
    /// advancing (a second call is ignored, so the total stays fixed). Nothing is reported for
    /// a total of 0.
    pub fn set_total(&mut self, total: u64) {
        if self.next != u64::MAX || total == 0 {
            return;
        }
        self.total = total;
        self.report(0);
    }

    /// Asks the observer whether the stage may allocate about `bytes` more
    /// ([`Observer::reserve`]); `what` describes them (the stage and its sizes).
    pub fn reserve(&mut self, bytes: u64, what: impl Fn() -> String) -> Result<(), MemoryLimit> {
        self.observer.reserve(self.stage, bytes, &what)
    }

    /// `units` more are done.
    #[inline]
    pub fn advance(&mut self, units: u64) {
        self.set(self.done.saturating_add(units));
    }

    /// `done` units are done in all (a count below the last one is ignored).
    #[inline]
    pub fn set(&mut self, done: u64) {
        if done >= self.next {
            self.report(done);
        } else if done > self.done {
            self.done = done;
        }
    }

    #[cold]
    fn report(&mut self, done: u64) {
        let done = done.min(self.total).max(self.done);
        self.done = done;
        self.observer.progress(self.stage, done, self.total);
        let step = self.total.div_ceil(REPORTS).max(1);
        // The last report is always the total itself, so that a finished stage shows 100%.
        self.next = if done >= self.total {
            u64::MAX
        } else {
            (done + step).min(self.total)
        };
    }

    /// Runs `jobs` in parallel on the current rayon pool and returns their results in order;
    /// each job adds the units it completes to the [`Tally`] it is given, and the calling thread
    /// reports `done + tally` while they run.
    pub fn parallel<T, F>(&mut self, jobs: Vec<F>) -> Vec<T>
    where
        T: Send,
        F: FnOnce(&Tally) -> T + Send,
    {
        let base = self.done;
        let tally = Tally::default();
        let results: Vec<Mutex<Option<T>>> = jobs.iter().map(|_| Mutex::new(None)).collect();
        let pending = AtomicUsize::new(jobs.len());
        let caller = std::thread::current();
        rayon::in_place_scope(|scope| {
            for (job, slot) in jobs.into_iter().zip(&results) {
                let (tally, pending, caller) = (&tally, &pending, &caller);
                scope.spawn(move |_| {
                    // Counts the job as ended even if it panics (the scope then re-raises the
                    // panic), so that the loop below ends.
                    let _ended = Ended { pending, caller };
                    let result = job(tally);
                    *slot.lock().unwrap_or_else(|e| e.into_inner()) = Some(result);
                });
            }
            while pending.load(Ordering::Acquire) > 0 {
                self.set(base.saturating_add(tally.0.load(Ordering::Relaxed)));
                // On a pool thread (a pool of one, say), help with the jobs; elsewhere wait
                // for them, waking up to report.
                if !matches!(rayon::yield_now(), Some(rayon::Yield::Executed)) {
                    std::thread::park_timeout(Duration::from_millis(50));
                }
            }
        });
        self.set(base.saturating_add(tally.0.load(Ordering::Relaxed)));
        results
            .into_iter()
            .map(|slot| {
                slot.into_inner()
                    .unwrap_or_else(|e| e.into_inner())
                    .expect("every job ran")
            })
            .collect()
    }
}

/// Counts a job of [`Meter::parallel`] as ended when dropped, and wakes the caller after the
/// last one.
struct Ended<'a> {
    pending: &'a AtomicUsize,
    caller: &'a std::thread::Thread,
}

impl Drop for Ended<'_> {
    fn drop(&mut self) {
        if self.pending.fetch_sub(1, Ordering::AcqRel) == 1 {
            self.caller.unpark();
        }
    }
}

/// A counter that parallel jobs add their completed units to (see [`Meter::parallel`]); add in
/// batches of a few thousand units, not per item.
#[derive(Debug, Default)]
pub struct Tally(AtomicU64);

impl Tally {
    /// `units` more are done.
    pub fn add(&self, units: u64) {
        self.0.fetch_add(units, Ordering::Relaxed);
    }
}

/// Seconds spent in each stage (0 for stages that did not run).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    seconds: [f64; Stage::ALL.len()],
}

impl Timings {
    /// The seconds spent in `stage` (0 when it did not run).
    pub fn get(&self, stage: Stage) -> f64 {
        self.seconds[stage as usize]
    }

    /// The seconds spent in all stages together.
    pub fn total(&self) -> f64 {
        self.seconds.iter().sum()
    }
}

impl Observer for Timings {
    fn finished(&mut self, stage: Stage, seconds: f64) {
        self.seconds[stage as usize] += seconds;
    }
}

impl Serialize for Timings {
    /// An object with one key per stage, in pipeline order, and `total`.
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(Some(Stage::ALL.len() + 1))?;
        for stage in Stage::ALL {
            map.serialize_entry(stage.name(), &self.get(stage))?;
        }
        map.serialize_entry("total", &self.total())?;
        map.end()
    }
}
