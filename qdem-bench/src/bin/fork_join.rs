//! `fork_join [--particles N] [--reps R]`: what a parallel region costs on this machine, the
//! measurement behind the Verlet sweeps' task size (`qdem_core::solvers::verlet_sweeps`).
//!
//! A pass over N particles (x += h v, the shape of a drift) is timed on one thread, as a rayon
//! `join` of two halves on a pool of two threads, and as the same halves on a persistent team
//! of two threads (the caller and one helper that spins for a while after each job, then
//! parks), each after a serial gap of 0, 20, 100 and 400 µs (the rest of a step, during which
//! an idle worker may fall asleep); and an empty `join` alone. Prints one JSON object: the
//! median time per region in µs of each, for each gap.

use serde_json::json;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

type V = [f64; 3];

const GAPS_US: [f64; 4] = [0.0, 20.0, 100.0, 400.0];

fn kick(x: &mut [V], v: &[V], h: f64) {
    for (x, v) in x.iter_mut().zip(v) {
        for k in 0..3 {
            x[k] += h * v[k];
        }
    }
}

/// Keeps this thread busy for `us` µs (the serial rest of a step).
fn busy(us: f64) {
    let start = Instant::now();
    while start.elapsed().as_secs_f64() * 1e6 < us {
        std::hint::spin_loop();
    }
}

/// The median over `reps` of the time `region` takes after a gap of `gap` µs, in µs.
fn median_after_gap(reps: usize, gap: f64, mut region: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..reps)
        .map(|_| {
            busy(gap);
            let start = Instant::now();
            region();
            start.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[reps / 2]
}

/// A team of the calling thread and one helper that owns the second half of the particles:
/// a job is an epoch the helper waits for, spinning for `spin` after its last job, then parked.
struct Team {
    epoch: Arc<AtomicU64>,
    done: Arc<AtomicU64>,
    helper: Option<std::thread::JoinHandle<()>>,
}

impl Team {
    fn new(mut x: Vec<V>, v: Vec<V>, spin: Duration) -> Team {
        let (epoch, done) = (Arc::new(AtomicU64::new(0)), Arc::new(AtomicU64::new(0)));
        let (e, d) = (epoch.clone(), done.clone());
        let helper = std::thread::spawn(move || {
            let mut seen = 0;
            loop {
                let idle = Instant::now();
                let next = loop {
                    let now = e.load(Ordering::Acquire);
                    if now != seen {
                        break now;
                    }
                    if idle.elapsed() < spin {
                        std::hint::spin_loop();
                    } else {
                        std::thread::park_timeout(Duration::from_millis(1));
                    }
                };
                if next == u64::MAX {
                    return;
                }
                kick(&mut x, &v, 1e-9);
                seen = next;
                d.store(next, Ordering::Release);
            }
        });
        Team {
            epoch,
            done,
            helper: Some(helper),
        }
    }

    /// One region: the helper's half and the caller's `own` half, then the wait for both.
    fn region(&self, own: impl FnOnce()) {
        let next = self.epoch.load(Ordering::Relaxed) + 1;
        self.epoch.store(next, Ordering::Release);
        if let Some(h) = &self.helper {
            h.thread().unpark();
        }
        own();
        while self.done.load(Ordering::Acquire) != next {
            std::hint::spin_loop();
        }
    }
}

impl Drop for Team {
    fn drop(&mut self) {
        self.epoch.store(u64::MAX, Ordering::Release);
        if let Some(h) = self.helper.take() {
            h.thread().unpark();
            h.join().expect("the helper ends");
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let option = |name: &str, default: usize| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .map_or(default, |s| s.parse().expect("a whole number"))
    };
    let (n, reps) = (option("--particles", 10_000), option("--reps", 2000));
    let half = n / 2;
    let (mut x, v) = (vec![[0.0; 3]; n], vec![[1.0; 3]; n]);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a pool of two threads");
    let mut rows = Vec::new();
    for gap in GAPS_US {
        let serial = median_after_gap(reps, gap, || kick(&mut x, &v, 1e-9));
        let (join, empty) = pool.install(|| {
            let join = median_after_gap(reps, gap, || {
                let (a, b) = x.split_at_mut(half);
                rayon::join(|| kick(a, &v[..half], 1e-9), || kick(b, &v[half..], 1e-9));
            });
            let empty = median_after_gap(reps, gap, || {
                rayon::join(|| (), || ());
            });
            (join, empty)
        });
        let mut team_us = Vec::new();
        for spin_us in [50, 1000] {
            let spin = Duration::from_micros(spin_us);
            let team = Team::new(x[half..].to_vec(), v[half..].to_vec(), spin);
            let own = &mut x[..half];
            let t = median_after_gap(reps, gap, || team.region(|| kick(own, &v[..half], 1e-9)));
            team_us.push(json!({"spin_us": spin_us, "region_us": t}));
        }
        rows.push(json!({
            "gap_us": gap,
            "serial_us": serial,
            "rayon_join_halves_us": join,
            "rayon_empty_join_us": empty,
            "team": team_us,
        }));
    }
    let out = json!({
        "particles": n,
        "reps": reps,
        "cpu": qdem_bench::throughput::cpu_model(),
        "regions": rows,
    });
    println!("{out}");
}
