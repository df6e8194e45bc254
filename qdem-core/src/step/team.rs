//! A persistent team of threads for the parallel regions of a step: the calling thread and
//! one worker per extra thread, woken at most once per step.
//!
//! A rayon region costs a wake-up of the sleeping workers each time (10–20 µs on the 2-core
//! benchmark machine, qdem-bench's `fork_join`), and a DEM step has four (the drift, the
//! contacts' read of the centres, the pair kernel, the kick). A [`Team`] runs each of them as
//! a *phase*: the caller posts the phase (one epoch counter), runs part 0 itself and waits
//! until every worker has run its part. A worker waits for the next phase as a barrier does
//! on a quiet machine: it spins for a short while ([`Waits::spin`]); inside a step that holds
//! the team ([`Team::hold`]) it then yields its core until [`Waits::patience`] has passed;
//! only then does it park (`std::thread::park`), and a phase posted to a parked worker
//! unparks it: a *wake-up*. The gaps between the phases of a step are short serial work, so
//! a step costs at most one wake-up, at its first phase; between steps the workers spin
//! [`Waits::spin`] and park.
//!
//! Determinism is the callers': a phase's parts are a fixed function of the item count and
//! [`Team::size`], part `i` runs on thread `i` (0: the caller), and [`Team::run`] returns
//! the parts' results in part order, so sums gathered from them have a fixed order.
//!
//! The team is opt-in: a driver creates one and [`Team::install`]s it on the stepping
//! thread; the stages that can run as phases ask [`with_current`] and fall back to rayon
//! without one. It lives in `step/`, the bottom layer, because both the steppers' sweeps and
//! the models' stages use it. [`counts`] counts the parallel regions a thread started, rayon
//! regions included ([`note_rayon_region`]), and the team's wake-ups.
//!
//! ```
//! use qdem_core::step::team::{self, Team};
//!
//! let team = Team::new(2);
//! let sums = team.install(|| {
//!     team::with_current(|t| {
//!         let t = t.expect("installed");
//!         let parts: Vec<Vec<f64>> = vec![vec![1.0, 2.0], vec![3.0, 4.0]];
//!         t.run(parts, |p| p.iter().sum::<f64>())
//!     })
//! });
//! assert_eq!(sums, vec![3.0, 7.0]);
//! assert_eq!(team::counts().regions, 1);
//! ```

use std::any::Any;
use std::cell::{Cell, UnsafeCell};
use std::marker::PhantomData;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::ptr::NonNull;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long an idle worker waits before it gives its core away.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Waits {
    /// How long a worker spins for the next phase before yielding (in a held step) or parking.
    pub spin: Duration,
    /// How long, in all, a worker of a held step waits before it parks.
    pub patience: Duration,
}

impl Default for Waits {
    /// Spin 100 µs (longer than the serial gaps of a DEM step and than its rest between
    /// steps on 10⁴ spheres), be patient 2 ms inside a step (a rebuild of the lists).
    fn default() -> Waits {
        Waits {
            spin: Duration::from_micros(100),
            patience: Duration::from_millis(2),
        }
    }
}

/// The parallel regions a thread started and the wake-ups they cost, since the thread
/// began ([`counts`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RegionCounts {
    /// Parallel regions: team phases and rayon regions of the stages that count them.
    pub regions: u64,
    /// Team phases among them.
    pub phases: u64,
    /// Workers a phase found parked and unparked.
    pub wakeups: u64,
    /// Steps that held a team ([`Team::hold`]).
    pub holds: u64,
}

thread_local! {
    static COUNTS: Cell<RegionCounts> = const { Cell::new(RegionCounts {
        regions: 0, phases: 0, wakeups: 0, holds: 0,
    }) };
    static CURRENT: Cell<Option<NonNull<Team>>> = const { Cell::new(None) };
}

/// The parallel regions this thread has started, and their wake-ups.
pub fn counts() -> RegionCounts {
    COUNTS.with(Cell::get)
}

fn count(f: impl FnOnce(&mut RegionCounts)) {
    COUNTS.with(|c| {
        let mut v = c.get();
        f(&mut v);
        c.set(v);
    });
}

/// Counts a rayon region that a stage started in place of a team phase (each may wake the
/// pool's sleeping workers).
pub fn note_rayon_region() {
    count(|c| c.regions += 1);
}

/// Calls `f` with the team installed on this thread ([`Team::install`]), `None` without one
/// or while that team runs a phase (a phase's parts do not start phases of their own).
pub fn with_current<R>(f: impl FnOnce(Option<&Team>) -> R) -> R {
    let team = CURRENT.with(Cell::get);
    // SAFETY: the pointer was set by `Team::install`, which clears it before the team can
    // move or drop, and it is read on the thread that set it.
    let team = team.map(|t| unsafe { t.as_ref() });
    f(team.filter(|t| !t.busy.get()))
}

/// Runs `f` holding this thread's team, if any, for a step ([`Team::hold`]).
pub fn hold<R>(f: impl FnOnce() -> R) -> R {
    let team = CURRENT.with(Cell::get);
    match team {
        // SAFETY: as in `with_current`.
        Some(t) => unsafe { t.as_ref() }.hold(f),
        None => f(),
    }
}

/// Items of the given `costs` cut into at most `parts` contiguous shares of about equal cost
/// (ascending, covering every item, none empty): share k ends at the first item whose
/// running cost reaches k + 1 parts of the total. A function of the costs and `parts` alone.
///
/// ```
/// use qdem_core::step::team::shares;
///
/// assert_eq!(shares(&[4, 1, 1, 1, 1], 2), vec![0..1, 1..5]);
/// assert_eq!(shares(&[1, 1, 1], 5), vec![0..1, 1..2, 2..3]);
/// assert_eq!(shares(&[], 2), Vec::<std::ops::Range<usize>>::new());
/// ```
pub fn shares(costs: &[usize], parts: usize) -> Vec<std::ops::Range<usize>> {
    let parts = parts.clamp(1, costs.len().max(1));
    let total: usize = costs.iter().sum();
    let mut out = Vec::with_capacity(parts);
    let (mut start, mut running) = (0, 0);
    for (i, &c) in costs.iter().enumerate() {
        running += c;
        let k = out.len() + 1;
        let left = costs.len() - i - 1;
        let due = running * parts >= k * total;
        // Keep one item for each share still to come, and end the last at the end.
        if k < parts && (due || left == parts - k) {
            out.push(start..i + 1);
            start = i + 1;
        }
    }
    if start < costs.len() {
        out.push(start..costs.len());
    }
    out
}

/// A phase's work for part `i`, its lifetime erased while the phase runs.
type Job = *const (dyn Fn(usize) + Sync);

/// What the caller and the workers share.
struct Shared {
    /// Bumped by each phase (and by the end of the team, to `u64::MAX`).
    epoch: AtomicU64,
    /// Workers done with the current phase.
    done: AtomicUsize,
    /// Whether a step holds the team (workers yield rather than park).
    held: AtomicBool,
    /// The current phase's work; written only while every worker is idle.
    job: UnsafeCell<Option<Job>>,
    /// Per worker, whether it is parked or about to park.
    parked: Vec<AtomicBool>,
    /// The first panic of a worker's part in this phase.
    panic: Mutex<Option<Box<dyn Any + Send>>>,
    waits: Waits,
}

// SAFETY: `job` is written by the caller only before it bumps `epoch` (release) and while no
// worker runs a part (after `done` reached the count), and read by workers after they see the
// new epoch (acquire); the job it points to is `Sync`.
unsafe impl Sync for Shared {}
// SAFETY: as above; the pointer is only dereferenced during the phase that set it.
unsafe impl Send for Shared {}

/// A persistent team of the calling thread and `size − 1` workers ([module docs](self)).
pub struct Team {
    shared: Arc<Shared>,
    workers: Vec<JoinHandle<()>>,
    /// Whether this team is running a phase (on the caller's thread).
    busy: Cell<bool>,
    /// Nested holds on the caller's thread.
    holds: Cell<u32>,
    /// The team belongs to the thread that installs it.
    _not_sync: PhantomData<Cell<()>>,
}

impl Team {
    /// A team of `size` threads (the caller and `size − 1` workers; at least one) with the
    /// default [`Waits`].
    pub fn new(size: usize) -> Team {
        Team::with_waits(size, Waits::default())
    }

    /// A team of `size` threads whose workers wait as `waits` says.
    pub fn with_waits(size: usize, waits: Waits) -> Team {
        let workers = size.max(1) - 1;
        let shared = Arc::new(Shared {
            epoch: AtomicU64::new(0),
            done: AtomicUsize::new(0),
            held: AtomicBool::new(false),
            job: UnsafeCell::new(None),
            parked: (0..workers).map(|_| AtomicBool::new(false)).collect(),
            panic: Mutex::new(None),
            waits,
        });
        let workers = (0..workers)
            .map(|w| {
                let shared = shared.clone();
                std::thread::Builder::new()
                    .name(format!("qdem-team-{}", w + 1))
                    .spawn(move || work(&shared, w))
                    .expect("a team worker thread starts")
            })
            .collect();
        Team {
            shared,
            workers,
            busy: Cell::new(false),
            holds: Cell::new(0),
            _not_sync: PhantomData,
        }
    }

    /// The threads of the team, the caller included.
    pub fn size(&self) -> usize {
        self.workers.len() + 1
    }

    /// Runs `f` with this team as the current one of this thread ([`with_current`]).
    pub fn install<R>(&self, f: impl FnOnce() -> R) -> R {
        struct Restore(Option<NonNull<Team>>);
        impl Drop for Restore {
            fn drop(&mut self) {
                CURRENT.with(|c| c.set(self.0));
            }
        }
        let _restore = Restore(CURRENT.with(|c| c.replace(Some(NonNull::from(self)))));
        f()
    }

    /// Runs `f` (a step) with the team held: between its phases the workers spin, then
    /// yield, and park only after [`Waits::patience`].
    pub fn hold<R>(&self, f: impl FnOnce() -> R) -> R {
        struct Release<'a>(&'a Team);
        impl Drop for Release<'_> {
            fn drop(&mut self) {
                let holds = self.0.holds.get() - 1;
                self.0.holds.set(holds);
                if holds == 0 {
                    self.0.shared.held.store(false, Ordering::Relaxed);
                }
            }
        }
        if self.holds.get() == 0 {
            count(|c| c.holds += 1);
            self.shared.held.store(true, Ordering::Relaxed);
        }
        self.holds.set(self.holds.get() + 1);
        let _release = Release(self);
        f()
    }

    /// One phase: part `i` of `parts` (at most [`Team::size`]) runs `work` on thread `i`,
    /// the first on the caller; returns the results in part order. One part runs on the
    /// caller alone, without a phase.
    pub fn run<T: Send, R: Send>(&self, parts: Vec<T>, work: impl Fn(T) -> R + Sync) -> Vec<R> {
        assert!(
            parts.len() <= self.size(),
            "{} parts for a team of {}",
            parts.len(),
            self.size()
        );
        if parts.len() <= 1 || self.workers.is_empty() {
            return parts.into_iter().map(work).collect();
        }
        let count_parts = parts.len();
        let slots: Vec<Mutex<Option<T>>> = parts.into_iter().map(|p| Mutex::new(Some(p))).collect();
        let results: Vec<Mutex<Option<R>>> = (0..count_parts).map(|_| Mutex::new(None)).collect();
        let job = |i: usize| {
            let part = slots.get(i).and_then(|s| lock(s).take());
            if let Some(part) = part {
                *lock(&results[i]) = Some(work(part));
            }
        };
        self.phase(&job);
        results
            .into_iter()
            .map(|r| {
                r.into_inner()
                    .unwrap_or_else(|e| e.into_inner())
                    .expect("every part ran")
            })
            .collect()
    }

    /// Posts `job` to the workers, runs its part 0 and waits for every worker's part; then
    /// passes on the first panic of any part.
    fn phase(&self, job: &(dyn Fn(usize) + Sync)) {
        let shared = &*self.shared;
        // SAFETY: every worker is idle (the last phase waited for all of them), so none reads
        // `job`; the lifetime is erased only until this function has waited for every worker
        // below, which it does before it returns or unwinds.
        unsafe {
            let erased: Job = std::mem::transmute::<*const (dyn Fn(usize) + Sync + '_), Job>(job);
            *shared.job.get() = Some(erased);
        }
        shared.done.store(0, Ordering::Relaxed);
        shared.epoch.fetch_add(1, Ordering::SeqCst);
        let mut woken = 0;
        for (w, parked) in shared.parked.iter().enumerate() {
            if parked.swap(false, Ordering::SeqCst) {
                self.workers[w].thread().unpark();
                woken += 1;
            }
        }
        count(|c| {
            c.regions += 1;
            c.phases += 1;
            c.wakeups += woken;
        });
        self.busy.set(true);
        let own = catch_unwind(AssertUnwindSafe(|| job(0)));
        self.wait_for_workers();
        self.busy.set(false);
        // SAFETY: every worker is done with the job.
        unsafe { *shared.job.get() = None };
        if let Err(payload) = own {
            resume_unwind(payload);
        }
        if let Some(payload) = lock(&shared.panic).take() {
            resume_unwind(payload);
        }
    }

    /// Spins until every worker has run its part of the phase (yielding after a while, for a
    /// worker that lost its core).
    fn wait_for_workers(&self) {
        let start = Instant::now();
        let workers = self.workers.len();
        while self.shared.done.load(Ordering::Acquire) < workers {
            if start.elapsed() < self.shared.waits.spin {
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
        }
    }
}

impl Drop for Team {
    fn drop(&mut self) {
        self.shared.epoch.store(u64::MAX, Ordering::SeqCst);
        for w in self.workers.drain(..) {
            w.thread().unpark();
            // A worker's panic was passed on by its phase; the worker itself ends cleanly.
            let _ = w.join();
        }
    }
}

/// Locks `m`, whatever a panic left in it (the parts' panics are passed on separately).
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// A worker's life: wait for each phase, run its part `w + 1`, report it done.
fn work(shared: &Shared, w: usize) {
    let mut seen = 0;
    loop {
        seen = wait_for_phase(shared, w, seen);
        if seen == u64::MAX {
            return;
        }
        // SAFETY: the caller set the job before it bumped the epoch we acquired, and keeps
        // it alive until `done` counts this worker.
        let job = unsafe { *shared.job.get() }.expect("a phase has a job");
        // SAFETY: as above.
        let ran = catch_unwind(AssertUnwindSafe(|| unsafe { (*job)(w + 1) }));
        if let Err(payload) = ran {
            lock(&shared.panic).get_or_insert(payload);
        }
        shared.done.fetch_add(1, Ordering::Release);
    }
}

/// Waits until the epoch moves past `seen`: spins, then yields while a step holds the team,
/// then parks; returns the new epoch.
fn wait_for_phase(shared: &Shared, w: usize, seen: u64) -> u64 {
    let start = Instant::now();
    loop {
        let epoch = shared.epoch.load(Ordering::Acquire);
        if epoch != seen {
            return epoch;
        }
        let waited = start.elapsed();
        if waited < shared.waits.spin {
            std::hint::spin_loop();
            continue;
        }
        if shared.held.load(Ordering::Relaxed) && waited < shared.waits.patience {
            std::thread::yield_now();
            continue;
        }
        park(shared, w, seen);
    }
}

/// Parks worker `w` until a phase after `seen` unparks it (or one was posted meanwhile).
///
/// The flag is raised again before every check of the epoch: a caller still posting the
/// phase this worker has already run can clear it late (and leave a wake-up that ends the
/// first `park` at once), and a flag left down would hide the worker from the next phase.
fn park(shared: &Shared, w: usize, seen: u64) {
    loop {
        shared.parked[w].store(true, Ordering::SeqCst);
        if shared.epoch.load(Ordering::SeqCst) != seen {
            break;
        }
        std::thread::park();
    }
    shared.parked[w].store(false, Ordering::SeqCst);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_run_on_their_threads_and_come_back_in_order() {
        let team = Team::new(3);
        let before = counts();
        for round in 0..200u64 {
            let parts: Vec<u64> = (0..3).map(|i| round * 10 + i).collect();
            let out = team.run(parts, |p| (p, std::thread::current().id()));
            assert_eq!(
                out.iter().map(|o| o.0).collect::<Vec<_>>(),
                vec![round * 10, round * 10 + 1, round * 10 + 2]
            );
            assert_eq!(out[0].1, std::thread::current().id());
            assert_ne!(out[1].1, out[2].1);
        }
        let after = counts();
        assert_eq!(after.phases - before.phases, 200);
        assert_eq!(after.regions - before.regions, 200);
    }

    #[test]
    fn a_worker_that_parks_before_its_phase_is_fully_posted_is_still_woken_by_the_next() {
        // Workers that park as soon as they are idle, three teams of four on a machine of
        // fewer cores: a caller often loses its core while it posts a phase, and a worker it
        // already reached runs its part and parks for the next phase before the caller posts
        // this one to it. Every phase must still reach every worker; a lost wake-up leaves a
        // caller waiting for ever, caught by the deadline.
        let waits = Waits {
            spin: Duration::ZERO,
            patience: Duration::ZERO,
        };
        let (tx, rx) = std::sync::mpsc::channel();
        for _ in 0..3 {
            let tx = tx.clone();
            std::thread::spawn(move || {
                let team = Team::with_waits(4, waits);
                for round in 0..20_000u64 {
                    assert_eq!(team.run(vec![round; 4], |r| r + 1), vec![round + 1; 4]);
                }
                tx.send(()).expect("the test waits");
            });
        }
        for _ in 0..3 {
            let ended = rx.recv_timeout(Duration::from_secs(60));
            assert!(ended.is_ok(), "a phase never reached a parked worker");
        }
    }

    #[test]
    fn shares_are_contiguous_cover_every_item_and_balance_the_cost() {
        let costs: Vec<usize> = (0..37).map(|i| 1 + (i * 7) % 11).collect();
        let total: usize = costs.iter().sum();
        for parts in 1..6 {
            let cut = shares(&costs, parts);
            assert_eq!(cut.len(), parts);
            assert_eq!(cut[0].start, 0);
            assert_eq!(cut.last().map(|r| r.end), Some(costs.len()));
            for w in cut.windows(2) {
                assert_eq!(w[0].end, w[1].start);
            }
            // No share exceeds its fair part by more than one item's cost (11 at most).
            for r in &cut {
                let cost: usize = costs[r.clone()].iter().sum();
                assert!(cost <= total / parts + 11, "{parts}: {r:?} costs {cost}");
            }
        }
        // Zero costs still give non-empty shares.
        assert_eq!(shares(&[0, 0, 0, 0], 2), vec![0..1, 1..4]);
    }

    #[test]
    fn a_held_step_wakes_a_parked_worker_once() {
        // Workers that park at once outside a step and never inside one; a serial gap of
        // 2 ms before each phase, in which an unheld worker parks: ten phases of one held
        // step cost one wake-up at most (its first phase), ten phases outside a step wake
        // the worker again (each one that found it parked).
        let waits = Waits {
            spin: Duration::ZERO,
            patience: Duration::from_secs(3600),
        };
        let team = Team::with_waits(2, waits);
        let gap = || std::thread::sleep(Duration::from_millis(2));
        let phases = || {
            for _ in 0..10 {
                gap();
                assert_eq!(team.run(vec![1, 2], |x| x * 2), vec![2, 4]);
            }
        };
        let before = counts();
        team.hold(phases);
        let held = counts();
        assert_eq!(held.phases - before.phases, 10);
        assert!(held.wakeups - before.wakeups <= 1, "{held:?}");
        assert_eq!(held.holds - before.holds, 1);
        phases();
        let after = counts();
        assert!(after.wakeups - held.wakeups >= 2, "{after:?}");
    }

    #[test]
    fn a_panic_in_a_workers_part_reaches_the_caller_and_the_team_goes_on() {
        let team = Team::new(2);
        let caught = catch_unwind(AssertUnwindSafe(|| {
            team.run(vec![0, 1], |i| assert!(i == 0, "part {i} fails"));
        }));
        assert!(caught.is_err());
        assert_eq!(team.run(vec![3, 4], |x| x + 1), vec![4, 5]);
    }

    #[test]
    fn the_installed_team_is_current_on_its_thread_outside_its_phases() {
        let team = Team::new(2);
        assert!(with_current(|t| t.is_none()));
        team.install(|| {
            assert_eq!(with_current(|t| t.map(Team::size)), Some(2));
            let inner = team.run(vec![0, 1], |_| with_current(|t| t.is_some()));
            assert_eq!(inner, vec![false, false]);
        });
        assert!(with_current(|t| t.is_none()));
    }
}
