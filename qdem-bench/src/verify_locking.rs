//! `qdem verify` rows of volumetric locking (issue 43): Lamé's thick-walled cylinder in plane
//! strain (a = 0.1 m, b = 0.2 m, 1 MPa inside, a quarter of 8 × 16 cells one cell thick,
//! u_z = 0) at ν = 0.3, 0.49 and 0.4999, the averaged-pressure tetrahedron (Bonet & Burton
//! 1998) against Lamé's bore displacement (tolerance 2%) with the standard kernel beside it
//! (informational: it locks, 26% short at ν = 0.4999). The case is
//! [`crate::locking_cases::ring_bore`]; the full study is the `locking_study` example
//! (docs/verification.md).

use crate::locking_cases::ring_bore;
use crate::verify::Row;
use qdem_core::continuum::Formulation;
use std::time::Instant;

/// The rows: per ν, the standard kernel (informational) and the averaged-pressure one (2%).
pub fn lame_rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for poisson in [0.3, 0.49, 0.4999] {
        for (formulation, tolerance) in [
            (Formulation::Standard, None),
            (Formulation::AveragedPressure, Some(0.02)),
        ] {
            let start = Instant::now();
            let (computed, exact) = ring_bore(poisson, formulation, (8, 16));
            rows.push(Row::relative(
                &format!(
                    "Lame cylinder, plane strain, nu = {poisson}, {}: bore u_r (m)",
                    formulation.name()
                ),
                exact,
                computed,
                tolerance,
                start.elapsed().as_secs_f64(),
            ));
        }
    }
    rows
}
