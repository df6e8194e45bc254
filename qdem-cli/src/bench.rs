//! `qdem bench`: prints the throughput measurements of [`qdem_bench::throughput`] as a table
//! or as one JSON document.

use crate::command::CliError;
use qdem_bench::implicit::measure_implicit;
use qdem_bench::throughput::{
    cpu_model, measure, measure_ordered, triad_bandwidth, BenchPlan, Ordering,
};
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
    let locality = locality_rows(plan, as_json);
    if as_json {
        let doc = json!({
            "locality": locality,
            "machine": { "cpu": cpu_model(), "cores": std::thread::available_parallelism().map_or(0, |n| n.get()) },
            "triad_bandwidth_bytes_per_second": bandwidth.iter().map(|(t, b)| json!({"threads": t, "value": b})).collect::<Vec<_>>(),
            "results": results,
        });
        println!("{}", serde_json::to_string_pretty(&doc).expect("json"));
    }
}

/// Effect of node ordering: the largest planned block, elastic, on the most threads, in
/// generator order, shuffled, and shuffled then reordered (reverse Cuthill–McKee).
fn locality_rows(plan: &BenchPlan, as_json: bool) -> Vec<serde_json::Value> {
    let (Some(&tets), Some(&threads)) = (plan.tets.iter().max(), plan.threads.iter().max()) else {
        return Vec::new();
    };
    if !as_json {
        println!("node ordering, {tets} tets, elastic, {threads} threads:");
    }
    [Ordering::Structured, Ordering::Shuffled, Ordering::Reordered]
        .into_iter()
        .map(|ordering| {
            let r = measure_ordered(tets, ordering, false, threads, plan.steps);
            if !as_json {
                println!("{:>12?} {:>14.4e} tet-steps/s", ordering, r.tet_steps_per_second());
            }
            json!({"ordering": format!("{ordering:?}").to_lowercase(), "tets": r.tets, "threads": threads, "tet_steps_per_second": r.tet_steps_per_second()})
        })
        .collect()
}

/// `qdem bench --implicit`: the implicit path's costs against the number of unknowns, by
/// default on blocks of about 10⁴, 10⁵ and 3 × 10⁵ unknowns.
pub fn implicit_and_print(
    tets: Option<Vec<usize>>,
    threads: usize,
    as_json: bool,
) -> Result<(), CliError> {
    let sizes = tets.unwrap_or_else(|| vec![16_000, 180_000, 550_000]);
    if !as_json {
        println!("machine: {}, {threads} threads", cpu_model());
        println!(
            "{:>8} {:>8} {:>10} {:>12} {:>9} {:>9} {:>9} {:>9} {:>9} {:>10}",
            "tets",
            "unknowns",
            "nnz(A)",
            "nnz(L)",
            "assemble",
            "symbolic",
            "numeric",
            "solve",
            "step",
            "step/solve"
        );
    }
    let mut results = Vec::new();
    for size in sizes {
        let r = measure_implicit(size, threads).map_err(|e| CliError::Verify(e.to_string()))?;
        let ratio = r.step_seconds / r.solve_seconds;
        if !as_json {
            println!(
                "{:>8} {:>8} {:>10} {:>12} {:>9.3e} {:>9.3e} {:>9.3e} {:>9.3e} {:>9.3e} {:>10.2}",
                r.tets,
                r.dofs,
                r.nonzeros,
                r.factor_nonzeros,
                r.assembly_seconds,
                r.symbolic_seconds,
                r.numeric_seconds,
                r.solve_seconds,
                r.step_seconds,
                ratio
            );
        }
        results.push(json!({
            "tets": r.tets, "unknowns": r.dofs, "nonzeros": r.nonzeros, "factor_nonzeros": r.factor_nonzeros,
            "assembly_seconds": r.assembly_seconds, "symbolic_seconds": r.symbolic_seconds,
            "numeric_seconds": r.numeric_seconds, "solve_seconds": r.solve_seconds,
            "step_seconds": r.step_seconds, "step_over_solve": ratio,
        }));
    }
    if as_json {
        let doc = json!({"machine": {"cpu": cpu_model(), "threads": threads}, "implicit": results});
        println!("{}", serde_json::to_string_pretty(&doc).expect("json"));
    }
    Ok(())
}
