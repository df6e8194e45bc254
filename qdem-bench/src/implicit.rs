//! Cost of the implicit path (paper 001 Eqs. 22–27 with faer's sparse Cholesky) against the
//! number of unknowns: assembly of M + γ∆t C + β∆t² K, symbolic analysis, numeric
//! factorisation, one forward/backward solve, and one implicit Newmark step that reuses the
//! factorisation (force evaluation + solve + update), on a structured block clamped on one face.
//! [`run_and_print`] is `qdem bench --implicit`: those costs as a table or as one JSON document.

use crate::throughput::{block_mesh, body_on, cpu_model, on_threads, Ordering};
use qdem_core::{error::CoreError, solvers::Newmark, step::Dofs, step::Model, step::Stepper};
use serde_json::json;
use std::time::Instant;

/// One measurement of the implicit path.
#[derive(Clone, Debug)]
pub struct ImplicitResult {
    /// Tetrahedra.
    pub tets: usize,
    /// Unknowns after eliminating the clamped face.
    pub dofs: usize,
    /// Non-zeros of the lower triangle of the system matrix.
    pub nonzeros: usize,
    /// Stored values of the Cholesky factor.
    pub factor_nonzeros: usize,
    /// Assembly seconds (the first factorisation's).
    pub assembly_seconds: f64,
    /// Symbolic analysis seconds.
    pub symbolic_seconds: f64,
    /// Numeric factorisation seconds.
    pub numeric_seconds: f64,
    /// Seconds of one forward and backward triangular solve (the last step's).
    pub solve_seconds: f64,
    /// Seconds of one implicit Newmark step with the factorisation reused.
    pub step_seconds: f64,
}

/// The block sizes `qdem bench --implicit` measures by default, in tetrahedra.
pub const DEFAULT_TETS: [usize; 3] = [16_000, 180_000, 550_000];

/// Measures the implicit path on a block of about `tets` tetrahedra on `threads` threads: the
/// stepper's first factorisation (at `initialize`, its assembly, symbolic and numeric times
/// in [`qdem_core::step::FactorStats`]), then a few steps on it (the last one's triangular solve).
pub fn measure_implicit(tets: usize, threads: usize) -> Result<ImplicitResult, CoreError> {
    on_threads(threads, || {
        let mesh = block_mesh(tets, Ordering::Structured);
        let clamp = mesh.group("xmin").expect("structured groups").nodes.clone();
        let (body, mut state) = body_on(mesh, false);
        for n in clamp {
            state.fix(n as usize, Dofs::ALL);
        }
        let dt = 1e-4;
        let tets = body.tets().len();
        let mut models: Vec<Box<dyn Model>> = vec![Box::new(body)];
        let mut stepper = Newmark::average_acceleration(dt);
        stepper.initialize(&mut state, &mut models)?;
        let steps = 5;
        let start = Instant::now();
        for _ in 0..steps {
            stepper.step(&mut state, &mut models)?;
        }
        let step_seconds = start.elapsed().as_secs_f64() / steps as f64;
        let stats = stepper.report().factor.expect("factorised at initialize");
        Ok(ImplicitResult {
            tets,
            dofs: stats.dofs,
            nonzeros: stats.nonzeros,
            factor_nonzeros: stats.factor_nonzeros,
            assembly_seconds: stats.assembly_seconds,
            symbolic_seconds: stats.symbolic_seconds,
            numeric_seconds: stats.numeric_seconds,
            solve_seconds: stats.solve_seconds,
            step_seconds,
        })
    })
}

/// `qdem bench --implicit`: the implicit path's costs against the number of unknowns, by
/// default on blocks of about 10⁴, 10⁵ and 3 × 10⁵ unknowns.
pub fn run_and_print(
    tets: Option<Vec<usize>>,
    threads: usize,
    as_json: bool,
) -> Result<(), CoreError> {
    let sizes = tets.unwrap_or_else(|| DEFAULT_TETS.to_vec());
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
        let r = measure_implicit(size, threads)?;
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
