//! `settlement.csv`: a probe's displacement along a `cyclic` load at each cycle's minimum and
//! maximum is the probe's displacement in `probes.csv` at those times (the cantilever under a
//! 250 Hz tip load between 0.2 and 1 of 200 N, probes every 1e-4 s, a divisor of the half
//! period), and the extrema fall where the cycle puts them, to the nearest step.

mod common;

use common::{short_cantilever, test_dir};
use qdem_io::build::Simulation;
use qdem_io::runner::run;
use qdem_io::scene::Scene;
use std::collections::HashMap;
use std::path::Path;

/// A CSV file as columns by name.
fn columns(path: &Path) -> HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut cols: HashMap<String, Vec<f64>> = names.iter().map(|n| (n.clone(), vec![])).collect();
    for line in lines {
        for (name, value) in names.iter().zip(line.split(',')) {
            cols.get_mut(name).unwrap().push(value.parse().unwrap());
        }
    }
    cols
}

#[test]
fn settlement_per_cycle_is_the_probe_displacement_at_the_cycles_extrema() {
    let dir = test_dir("settlement-cycles");
    let path = short_cantilever(
        &dir,
        &[(
            "ramp = [[0.0, 0.0], [0.01, 1.0], [2.0, 1.0], [2.0, 0.0]]",
            "cyclic = { min = 0.2, max = 1.0, frequency = 250.0 }",
        )],
    );
    let mut sim = Simulation::build(Scene::load(&path).unwrap()).unwrap();
    let dt = sim.world.dt();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let cycles = columns(&out.join("settlement.csv"));
    let probes = columns(&out.join("probes.csv"));
    let period = 1.0 / 250.0;
    // 0.02 s: five whole cycles (the fifth's maximum at 0.018 s).
    assert_eq!(cycles["cycle"], vec![1.0, 2.0, 3.0, 4.0, 5.0]);
    let row_at = |t: f64| {
        let k = probes["t"].iter().position(|&p| (p - t).abs() < 0.5 * dt);
        k.unwrap_or_else(|| panic!("no probe row at t = {t}"))
    };
    let extrema = cycles["time_min"].iter().zip(&cycles["time_max"]);
    for (k, (&t_min, &t_max)) in extrema.enumerate() {
        assert!((t_min - k as f64 * period).abs() <= 0.5 * dt, "{t_min}");
        assert!(
            (t_max - (k as f64 + 0.5) * period).abs() <= 0.5 * dt,
            "{t_max}"
        );
        // The load is downward: the displacement along it is −uz.
        for (t, column) in [(t_min, "tip.at_min"), (t_max, "tip.at_max")] {
            let uz = probes["tip.uz"][row_at(t)];
            let along = cycles[column][k];
            assert!(
                (along + uz).abs() <= 1e-9 * uz.abs(),
                "{along} vs {uz} at {t}"
            );
        }
        eprintln!(
            "cycle {}: {:.4e} m at the minimum, {:.4e} m at the maximum",
            k + 1,
            cycles["tip.at_min"][k],
            cycles["tip.at_max"][k]
        );
    }
    assert!(out.join("settlement.svg").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
