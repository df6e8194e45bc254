//! `settlement.csv`: a probe's displacement along a `cyclic` load at each cycle's minimum and
//! maximum is the probe's displacement in `probes.csv` at those times (the cantilever under a
//! 250 Hz tip load between 0.2 and 1 of 200 N, probes every 1e-4 s, a divisor of the half
//! period), and the extrema fall where the cycle puts them, to the nearest step. The run's end:
//! a run of whole cycles (to 0.02 s) and one that stops within a cycle (0.021 s) both end on a
//! row for the sixth cycle's minimum (0.02 s), the permanent settlement after the fifth, with
//! no maximum; every row names the loaded body.

mod common;

use common::{short_cantilever, test_dir};
use qdem_io::build::Simulation;
use qdem_io::runner::run;
use qdem_io::scene::Scene;
use std::collections::HashMap;
use std::path::Path;

/// A CSV file as columns by name: numbers, but for the text column `body`, returned apart.
fn columns(path: &Path) -> (HashMap<String, Vec<f64>>, Vec<String>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut cols: HashMap<String, Vec<f64>> = names.iter().map(|n| (n.clone(), vec![])).collect();
    let mut bodies = Vec::new();
    for line in lines {
        for (name, value) in names.iter().zip(line.split(',')) {
            match name.as_str() {
                "body" => bodies.push(value.to_string()),
                _ => cols.get_mut(name).unwrap().push(value.parse().unwrap()),
            }
        }
    }
    (cols, bodies)
}

/// Runs the cyclic cantilever to `t_end` and checks `settlement.csv` against `probes.csv`.
fn cycles_match_probes(tag: &str, t_end: f64) {
    let dir = test_dir(tag);
    let t_end_line = format!("t_end = {t_end}");
    let path = short_cantilever(
        &dir,
        &[
            (
                "ramp = [[0.0, 0.0], [0.01, 1.0], [2.0, 1.0], [2.0, 0.0]]",
                "cyclic = { min = 0.2, max = 1.0, frequency = 250.0 }",
            ),
            ("t_end = 0.02", t_end_line.as_str()),
        ],
    );
    let mut sim = Simulation::build(Scene::load(&path).unwrap()).unwrap();
    let dt = sim.world.dt();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let (cycles, bodies) = columns(&out.join("settlement.csv"));
    let (probes, _) = columns(&out.join("probes.csv"));
    let period = 1.0 / 250.0;
    // Five whole cycles (the fifth's maximum at 0.018 s), then the sixth's minimum at 0.02 s.
    assert_eq!(cycles["cycle"], vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    assert_eq!(bodies, vec!["beam"; 6]);
    let row_at = |t: f64| {
        let k = probes["time"]
            .iter()
            .position(|&p| (p - t).abs() < 0.5 * dt);
        k.unwrap_or_else(|| panic!("no probe row at t = {t}"))
    };
    let extrema = cycles["time_min"].iter().zip(&cycles["time_max"]);
    for (k, (&t_min, &t_max)) in extrema.enumerate() {
        assert!((t_min - k as f64 * period).abs() <= 0.5 * dt, "{t_min}");
        let mut at = vec![(t_min, "tip.at_min")];
        if k < 5 {
            assert!(
                (t_max - (k as f64 + 0.5) * period).abs() <= 0.5 * dt,
                "{t_max}"
            );
            at.push((t_max, "tip.at_max"));
        } else {
            // The last cycle's maximum (0.022 s) lies beyond the run.
            assert!(t_max.is_nan() && cycles["tip.at_max"][k].is_nan());
        }
        // The load is downward: the displacement along it is −uz.
        for (t, column) in at {
            let uz = probes["tip.uz"][row_at(t)];
            let along = cycles[column][k];
            assert!(
                (along + uz).abs() <= 1e-9 * uz.abs(),
                "{along} vs {uz} at {t}"
            );
        }
        eprintln!(
            "{tag} cycle {}: {:.4e} m at the minimum, {:.4e} m at the maximum",
            k + 1,
            cycles["tip.at_min"][k],
            cycles["tip.at_max"][k]
        );
    }
    assert!(out.join("settlement.svg").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn settlement_per_cycle_is_the_probe_displacement_at_the_cycles_extrema() {
    cycles_match_probes("settlement-cycles", 0.02);
}

#[test]
fn a_run_that_stops_within_a_cycle_ends_on_that_cycles_minimum() {
    cycles_match_probes("settlement-within", 0.021);
}
