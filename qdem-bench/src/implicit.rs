//! Cost of the implicit path (paper 001 Eqs. 22–27 with faer's sparse Cholesky) against the
//! number of unknowns: assembly of M + γ∆t C + β∆t² K, symbolic analysis, numeric
//! factorisation, one forward/backward solve, and one implicit Newmark step that reuses the
//! factorisation (force evaluation + solve + update), on a structured block clamped on one face.

use crate::throughput::{block_mesh, body_on, on_threads, Ordering};
use qdem_core::{CoreError, Dofs, Model, Newmark, Stepper};
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

/// Measures the implicit path on a block of about `tets` tetrahedra on `threads` threads: the
/// stepper's first factorisation (at `initialize`, its assembly, symbolic and numeric times
/// in [`qdem_core::FactorStats`]), then a few steps on it (the last one's triangular solve).
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
        let stats = stepper.factor_stats().expect("factorised at initialize");
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
