//! `qdem bench`: prints the throughput measurements of [`qdem_bench::throughput`] as a table
//! or as one JSON document.

use qdem_bench::throughput::{cpu_model, measure, triad_bandwidth, BenchPlan};
use serde_json::json;

/// Runs the plan and prints a table or one JSON document.
pub fn run_and_print(plan: &BenchPlan, as_json: bool) {
    let mut results = Vec::new();
    let bandwidth: Vec<(usize, f64)> = plan
        .threads
        .iter()
        .map(|&t| (t, triad_bandwidth(t)))
        .collect();
    if !as_json {
        println!(
            "machine: {} ({} cores available)",
            cpu_model(),
            std::thread::available_parallelism().map_or(0, |n| n.get())
        );
        for (t, bw) in &bandwidth {
            println!("triad bandwidth, {t} threads: {:.2} GB/s", bw / 1e9);
        }
        println!(
            "{:>9} {:>9} {:>8} {:>7} {:>6} {:>14} {:>10} {:>10}",
            "tets",
            "particles",
            "material",
            "threads",
            "steps",
            "tet-steps/s",
            "B/tet-step",
            "% of triad"
        );
    }
    for &tets in &plan.tets {
        for viscous in [false, true] {
            for &threads in &plan.threads {
                let r = measure(tets, viscous, threads, plan.steps);
                let bw = bandwidth
                    .iter()
                    .find(|b| b.0 == threads)
                    .map_or(f64::NAN, |b| b.1);
                let fraction = r.tet_steps_per_second() * r.bytes_per_tet_step() / bw;
                if !as_json {
                    println!(
                        "{:>9} {:>9} {:>8} {:>7} {:>6} {:>14.4e} {:>10.0} {:>9.0}%",
                        r.tets,
                        r.particles,
                        if viscous { "visco" } else { "elastic" },
                        threads,
                        r.steps,
                        r.tet_steps_per_second(),
                        r.bytes_per_tet_step(),
                        100.0 * fraction
                    );
                }
                results.push(json!({
                    "tets": r.tets, "particles": r.particles,
                    "material": if viscous { "viscoelastic" } else { "elastic" },
                    "threads": r.threads, "steps": r.steps, "seconds": r.seconds,
                    "tet_steps_per_second": r.tet_steps_per_second(),
                    "particle_steps_per_second": (r.particles * r.steps) as f64 / r.seconds,
                    "bytes_per_tet_step": r.bytes_per_tet_step(),
                    "fraction_of_triad_bandwidth": fraction,
                }));
            }
        }
    }
    if as_json {
        let doc = json!({
            "machine": { "cpu": cpu_model(), "cores": std::thread::available_parallelism().map_or(0, |n| n.get()) },
            "triad_bandwidth_bytes_per_second": bandwidth.iter().map(|(t, b)| json!({"threads": t, "value": b})).collect::<Vec<_>>(),
            "results": results,
        });
        println!("{}", serde_json::to_string_pretty(&doc).expect("json"));
    }
}
