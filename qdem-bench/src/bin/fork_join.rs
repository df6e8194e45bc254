//! `fork_join [--particles N] [--reps R]`: what a parallel region costs on this machine, the
//! measurement behind the Verlet sweeps' task size (`qdem_core::solvers::verlet_sweeps`).
//!
//! A pass over N particles (x += h v, the shape of a drift) is timed on one thread, as a rayon
//! `join` of two halves on a pool of two threads, and as the same halves in one phase of the
//! steps' persistent team of two threads (`qdem_core::step::team`: the caller and one worker
//! that spins for a while after each phase, then parks), each after a serial gap of 0, 20,
//! 100 and 400 µs (the rest of a step, during which an idle worker may fall asleep); and an
//! empty `join` and an empty phase alone. The team runs with its worker spinning 50 µs, its
//! default 100 µs and 1 ms, each between steps (the worker parks after the spin) and inside a
//! held step (`Team::hold`: the worker yields after the spin and parks only after its
//! patience, as between the phases of one step). Prints one JSON object: the median time per
//! region in µs of each, for each gap.

use qdem_core::step::team::{Team, Waits};
use serde_json::json;
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
        for spin_us in [50, 100, 1000] {
            let waits = Waits {
                spin: Duration::from_micros(spin_us),
                ..Waits::default()
            };
            let team = Team::with_waits(2, waits);
            let mut halves = || {
                let (a, b) = x.split_at_mut(half);
                let parts = vec![(a, &v[..half]), (b, &v[half..])];
                team.run(parts, |(x, v)| kick(x, v, 1e-9));
            };
            let between_steps = median_after_gap(reps, gap, &mut halves);
            let in_step = team.hold(|| median_after_gap(reps, gap, &mut halves));
            let empty = median_after_gap(reps, gap, || {
                team.run(vec![(), ()], |()| ());
            });
            let held_empty = team.hold(|| {
                median_after_gap(reps, gap, || {
                    team.run(vec![(), ()], |()| ());
                })
            });
            team_us.push(json!({
                "spin_us": spin_us,
                "region_us": between_steps,
                "held_region_us": in_step,
                "empty_phase_us": empty,
                "held_empty_phase_us": held_empty,
            }));
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
