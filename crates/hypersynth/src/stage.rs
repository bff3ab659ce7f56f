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
//! thread while they run ([`Meter::join`]: two jobs of different kinds). Stages without a
//! known total report nothing (a caller shows a spinner).
//!
//! **Interruption.** Work run under [`interruptible`] stops early when its observer says so
//! ([`Observer::interrupted`], asked when a stage starts, at each progress report, so about 256
//! times per stage, and at its [`Meter::checkpoint`]s): the stage unwinds from the meter (parallel jobs from their next
//! [`Tally::add`]) and [`interruptible`] returns [`Interrupted`]. Everything the work built is
//! dropped on the way; what it borrowed is left as it was. Outside [`interruptible`] the
//! question is never asked, so no other caller can see a stage unwind.
//!
//! ```
//! use hypersynth::stage::{Stage, Timings, timed};
//!
//! let mut timings = Timings::default();
//! let sum = timed(&mut timings, Stage::Solve, || (1..=10).sum::<u32>());
//! assert_eq!(sum, 55);
//! assert!(timings.get(Stage::Solve) >= 0.0);
//! ```

use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
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
    /// The certified robust values (an adversary learnt from observations).
    RobustSolve,
    /// The opportunistic policy (tie-breaking included).
    Policy,
    /// The controller evaluated as a Markov chain.
    Evaluation,
    /// Simulated runs and the trace.
    Simulation,
}

impl Stage {
    /// Every stage, in pipeline order: `stage as usize` is the index of `stage` here.
    pub const ALL: [Stage; 11] = [
        Stage::Parse,
        Stage::Translate,
        Stage::Product,
        Stage::Attractors,
        Stage::Adversary,
        Stage::MdpBuild,
        Stage::Solve,
        Stage::RobustSolve,
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
            Stage::RobustSolve => "robust_solve",
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
    /// Whether the caller wants the work abandoned (a user pressed Ctrl-C, say). Asked on the
    /// calling thread when a stage starts and after each progress report, and only inside
    /// [`interruptible`], which then returns [`Interrupted`].
    fn interrupted(&mut self) -> bool {
        false
    }
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
    stop_if_interrupted(observer);
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
    stop_if_interrupted(observer);
    observer.started(stage);
    let start = Instant::now();
    let result = work(&mut Meter::new(&mut *observer, stage));
    observer.finished(stage, start.elapsed().as_secs_f64());
    result
}

/// Why work run by [`interruptible`] stopped before its end: its observer asked.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("interrupted")]
pub struct Interrupted;

thread_local! {
    /// How many calls of [`interruptible`] the current thread is inside.
    static INTERRUPTIBLE: Cell<u32> = const { Cell::new(0) };
    /// Whether the current thread is unwinding from an interruption (to its innermost
    /// [`interruptible`]).
    static INTERRUPTING: Cell<bool> = const { Cell::new(false) };
}

/// Runs `work`, which stops early with [`Interrupted`] when an observer it reports to answers
/// `true` to [`Observer::interrupted`] (see the module documentation). Any other panic of
/// `work` goes on unwinding. Costs nothing while `work` runs: the observer is asked only at the
/// progress reports it is told anyway.
pub fn interruptible<T>(work: impl FnOnce() -> T) -> Result<T, Interrupted> {
    struct Inside;
    impl Drop for Inside {
        fn drop(&mut self) {
            INTERRUPTIBLE.with(|depth| depth.set(depth.get() - 1));
        }
    }
    INTERRUPTIBLE.with(|depth| depth.set(depth.get() + 1));
    let _inside = Inside;
    // Unwind safety: everything `work` builds is dropped by the unwinding, and the caller
    // gets no value of it; what `work` borrows is only read by the stages.
    let result = catch_unwind(AssertUnwindSafe(work));
    INTERRUPTING.with(|interrupting| interrupting.set(false));
    match result {
        Ok(value) => Ok(value),
        Err(payload) if payload.is::<Interrupted>() => Err(Interrupted),
        Err(payload) => resume_unwind(payload),
    }
}

/// Unwinds to [`interruptible`] if the current thread is inside one and `observer` asks to
/// stop. (`resume_unwind` does not run the panic hook: nothing is printed.)
fn stop_if_interrupted(observer: &mut dyn Observer) {
    if INTERRUPTIBLE.with(Cell::get) > 0 && observer.interrupted() {
        INTERRUPTING.with(|interrupting| interrupting.set(true));
        resume_unwind(Box::new(Interrupted));
    }
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
    /// Calls of `set` between reports, for its checkpoints.
    calls: u32,
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
            calls: 0,
        }
    }

    /// A meter of `stage` that tells no one, for callers without an observer.
    pub fn unobserved(stage: Stage) -> Meter<'static> {
        // `()` has no size: leaking a box of it allocates nothing.
        Meter::new(Box::leak(Box::new(())), stage)
    }

    /// A point where interruptible work may stop (see the module documentation) although
    /// nothing is reported: between the long phases of a stage that precede its counted work.
    pub fn checkpoint(&mut self) {
        stop_if_interrupted(self.observer);
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
        } else {
            if done > self.done {
                self.done = done;
            }
            // Between reports, every 16th call is a checkpoint: a stage whose counted units
            // are slow (a sweep of a large component) still stops soon when interrupted.
            self.calls = self.calls.wrapping_add(1);
            if self.calls.is_multiple_of(16) {
                self.checkpoint();
            }
        }
    }

    #[cold]
    fn report(&mut self, done: u64) {
        let done = done.min(self.total).max(self.done);
        self.done = done;
        self.observer.progress(self.stage, done, self.total);
        stop_if_interrupted(self.observer);
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
            // If the caller is interrupted below, the jobs stop at their next `Tally::add`.
            let _stop = StopJobs(&tally);
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
                self.set(base.saturating_add(tally.done.load(Ordering::Relaxed)));
                // On a pool thread (a pool of one, say), help with the jobs; elsewhere wait
                // for them, waking up to report.
                if !matches!(rayon::yield_now(), Some(rayon::Yield::Executed)) {
                    std::thread::park_timeout(Duration::from_millis(50));
                }
            }
        });
        self.set(base.saturating_add(tally.done.load(Ordering::Relaxed)));
        results
            .into_iter()
            .map(|slot| {
                slot.into_inner()
                    .unwrap_or_else(|e| e.into_inner())
                    .expect("every job ran")
            })
            .collect()
    }

    /// [`Self::parallel`] for two jobs of different kinds: runs `a` and `b` side by side and
    /// returns both results.
    pub fn join<A, B>(
        &mut self,
        a: impl FnOnce(&Tally) -> A + Send,
        b: impl FnOnce(&Tally) -> B + Send,
    ) -> (A, B)
    where
        A: Send,
        B: Send,
    {
        let (mut first, mut second) = (None, None);
        {
            let (first, second) = (&mut first, &mut second);
            let jobs: Vec<Job<'_>> = vec![
                Box::new(move |tally: &Tally| *first = Some(a(tally))),
                Box::new(move |tally: &Tally| *second = Some(b(tally))),
            ];
            self.parallel(jobs);
        }
        (
            first.expect("every job ran"),
            second.expect("every job ran"),
        )
    }
}

/// A job of [`Meter::join`], its result written where it was told.
type Job<'a> = Box<dyn FnOnce(&Tally) + Send + 'a>;

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

/// Tells the jobs of [`Meter::parallel`] to stop when dropped by an interrupted caller (not by
/// one that panics: its panic must reach its caller as it is).
struct StopJobs<'a>(&'a Tally);

impl Drop for StopJobs<'_> {
    fn drop(&mut self) {
        if INTERRUPTING.with(Cell::get) {
            self.0.stop.store(true, Ordering::Relaxed);
        }
    }
}

/// A counter that parallel jobs add their completed units to (see [`Meter::parallel`]); add in
/// batches of a few thousand units, not per item.
#[derive(Debug, Default)]
pub struct Tally {
    done: AtomicU64,
    /// Set when the caller was interrupted: the jobs unwind at their next `add`.
    stop: AtomicBool,
}

impl Tally {
    /// `units` more are done. Unwinds (with [`Interrupted`]) when the stage was interrupted.
    pub fn add(&self, units: u64) {
        self.done.fetch_add(units, Ordering::Relaxed);
        if self.stop.load(Ordering::Relaxed) {
            resume_unwind(Box::new(Interrupted));
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Asks to stop at its `after`-th question, and counts the questions.
    struct StopAfter {
        after: usize,
        asked: usize,
    }

    impl Observer for StopAfter {
        fn interrupted(&mut self) -> bool {
            self.asked += 1;
            self.asked >= self.after
        }
    }

    /// A metered stage of `total` units, one per loop turn; returns the turns done (through
    /// `turns`, so that an interrupted run still tells how far it went).
    fn count(observer: &mut dyn Observer, total: u64, turns: &mut u64) {
        metered(observer, Stage::Solve, |meter| {
            meter.set_total(total);
            for _ in 0..total {
                *turns += 1;
                meter.advance(1);
            }
        });
    }

    #[test]
    fn an_interrupted_stage_stops_at_the_report_where_the_observer_asks() {
        // Asked once at the start, then after each of the reports at 0, 4, 8, ... of 1024:
        // the 4th question comes after the report at 8.
        let mut observer = StopAfter { after: 4, asked: 0 };
        let mut turns = 0;
        let result = interruptible(|| count(&mut observer, 1024, &mut turns));
        assert_eq!(result, Err(Interrupted));
        assert_eq!((observer.asked, turns), (4, 8));
        // Uninterrupted, the same work runs to its end.
        let mut observer = StopAfter {
            after: usize::MAX,
            asked: 0,
        };
        let mut turns = 0;
        assert_eq!(
            interruptible(|| count(&mut observer, 1024, &mut turns)),
            Ok(())
        );
        // Asked at the start, at the 257 reports (0, 4, ..., 1024), and at every 16th of the
        // 768 advances between reports (a checkpoint): 1 + 257 + 48.
        assert_eq!((observer.asked, turns), (1 + 257 + 48, 1024));
    }

    #[test]
    fn outside_interruptible_the_observer_is_never_asked() {
        let mut observer = StopAfter { after: 1, asked: 0 };
        let mut turns = 0;
        count(&mut observer, 1024, &mut turns);
        assert_eq!((observer.asked, turns), (0, 1024));
    }

    /// Runs 4 parallel jobs of `turns` turns each (a millisecond and 1000 units a turn),
    /// under an observer that stops at its third question (the first report inside the
    /// parallel work); returns the outcome and the units the jobs did.
    fn parallel_jobs(turns: u64) -> (Result<(), Interrupted>, u64) {
        let done = AtomicU64::new(0);
        let result = interruptible(|| {
            let mut observer = StopAfter { after: 3, asked: 0 };
            metered(&mut observer, Stage::Attractors, |meter| {
                meter.set_total(4 * turns * 1000);
                let jobs: Vec<_> = (0..4)
                    .map(|_| {
                        let done = &done;
                        move |tally: &Tally| {
                            for _ in 0..turns {
                                std::thread::sleep(Duration::from_millis(1));
                                done.fetch_add(1000, Ordering::Relaxed);
                                tally.add(1000);
                            }
                        }
                    })
                    .collect();
                meter.parallel(jobs);
            })
        });
        (result, done.load(Ordering::Relaxed))
    }

    #[test]
    fn join_returns_both_results_and_counts_both_tallies() {
        // Two jobs of different result types, on the global pool and on a pool of one thread
        // (where the caller runs them itself); the stage ends at the units both added.
        let run = || {
            let mut timings = Timings::default();
            metered(&mut timings, Stage::Policy, |meter| {
                meter.set_total(10);
                let (a, b) = meter.join(
                    |tally| {
                        tally.add(3);
                        vec![1u32, 2, 3]
                    },
                    |tally| {
                        tally.add(4);
                        "four"
                    },
                );
                (a, b, meter.done)
            })
        };
        assert_eq!(run(), (vec![1, 2, 3], "four", 7));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        assert_eq!(pool.install(run), (vec![1, 2, 3], "four", 7));
    }

    #[test]
    fn interrupting_a_parallel_stage_stops_its_jobs() {
        // The caller waits for the jobs on the global pool and reports as they go: 4 jobs of
        // 2 s each stop after a few dozen of their 8000 turns.
        let (result, done) = parallel_jobs(2000);
        assert_eq!(result, Err(Interrupted));
        assert!(done < 4 * 2000 * 1000 / 2, "{done} units");
        // On a one-thread pool the caller runs the jobs itself and reports between them: the
        // first job ends, the three others stop at their first turn.
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let (result, done) = pool.install(|| parallel_jobs(200));
        assert_eq!(result, Err(Interrupted));
        assert!(done < 4 * 200 * 1000 / 2, "{done} units");
    }

    #[test]
    fn other_panics_go_through_unchanged() {
        let caught = catch_unwind(|| interruptible(|| panic!("a bug"))).unwrap_err();
        assert_eq!(caught.downcast_ref::<&str>(), Some(&"a bug"));
        // A caller of parallel jobs that panics does not stop them as if interrupted, and its
        // own panic is what comes out.
        struct Panics;
        impl Observer for Panics {
            fn progress(&mut self, _: Stage, done: u64, _: u64) {
                if done > 0 {
                    panic!("observer bug");
                }
            }
        }
        let caught = catch_unwind(|| {
            interruptible(|| {
                metered(&mut Panics, Stage::Attractors, |meter| {
                    meter.set_total(2000);
                    let job = |tally: &Tally| {
                        std::thread::sleep(Duration::from_millis(100));
                        tally.add(1000);
                    };
                    meter.parallel(vec![job, job]);
                })
            })
        })
        .unwrap_err();
        assert_eq!(caught.downcast_ref::<&str>(), Some(&"observer bug"));
    }
}
