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

/// The resident set now (VmRSS) in MiB.
pub fn current_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
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

/// A global allocator that counts the bytes live on the heap and their peak, so that a
/// benchmark can tell what its structures take from what the allocator and the kernel add.
/// Install it with `#[global_allocator] static A: memory::Counting = memory::Counting;`; it
/// counts from [`count_heap`] on (before, it costs one load per call: timings stay honest).
pub struct Counting;

static COUNTING: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Starts counting the heap (counts start at 0: call it before allocating what is measured).
pub fn count_heap() {
    COUNTING.store(true, std::sync::atomic::Ordering::Relaxed);
}

static LIVE: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
static PEAK: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

unsafe impl std::alloc::GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        let p = unsafe { std::alloc::System.alloc(layout) };
        if !p.is_null() {
            grow(layout.size());
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, layout: std::alloc::Layout) {
        unsafe { std::alloc::System.dealloc(p, layout) };
        shrink(layout.size());
    }
    unsafe fn realloc(&self, p: *mut u8, layout: std::alloc::Layout, size: usize) -> *mut u8 {
        let q = unsafe { std::alloc::System.realloc(p, layout, size) };
        if !q.is_null() {
            shrink(layout.size());
            grow(size);
        }
        q
    }
}

/// Counts a block freed (saturating: it may have been allocated before counting started).
fn shrink(size: usize) {
    use std::sync::atomic::Ordering::Relaxed;
    if COUNTING.load(Relaxed) {
        let _ = LIVE.fetch_update(Relaxed, Relaxed, |live| Some(live.saturating_sub(size)));
    }
}

fn grow(size: usize) {
    use std::sync::atomic::Ordering::Relaxed;
    if !COUNTING.load(Relaxed) {
        return;
    }
    let live = LIVE.fetch_add(size, Relaxed) + size;
    PEAK.fetch_max(live, Relaxed);
}

/// The bytes live on the heap now (with [`Counting`] installed; 0 otherwise).
pub fn heap_mib() -> f64 {
    LIVE.load(std::sync::atomic::Ordering::Relaxed) as f64 / 1048576.0
}

/// The peak of [`heap_mib`] since the start or the last [`reset_heap_peak`].
pub fn heap_peak_mib() -> f64 {
    PEAK.load(std::sync::atomic::Ordering::Relaxed) as f64 / 1048576.0
}

/// Starts a new heap peak from what is live now.
pub fn reset_heap_peak() {
    use std::sync::atomic::Ordering::Relaxed;
    PEAK.store(LIVE.load(Relaxed), Relaxed);
}
