//! Volumetric locking study (issue 43): the standard QDEM tetrahedron and the
//! averaged-pressure one (Bonet & Burton 1998) against Lamé's thick-walled cylinder in plane
//! strain and a clamped bar against Timoshenko beam theory, over Poisson's ratios and mesh
//! refinements; one JSON object per line, the table of docs/verification.md.
//!
//! `cargo run --release -p qdem-bench --example locking_study`

use qdem_bench::locking_cases::{bar_tip, ring_bore};
use qdem_core::continuum::Formulation;

fn main() {
    for poisson in [0.3, 0.49, 0.4999] {
        for cells in [(4, 8), (6, 12), (8, 16), (12, 24)] {
            let (standard, exact) = ring_bore(poisson, Formulation::Standard, cells);
            let (averaged, _) = ring_bore(poisson, Formulation::AveragedPressure, cells);
            println!(
                "{{\"case\": \"lame\", \"poisson\": {poisson}, \"cells\": [{}, {}], \"tets\": {}, \"exact_m\": {exact:.6e}, \"standard_ratio\": {:.4}, \"averaged_ratio\": {:.4}}}",
                cells.0, cells.1, 6 * cells.0 * cells.1, standard / exact, averaged / exact
            );
        }
    }
    for poisson in [0.33, 0.45, 0.49, 0.499, 0.4999] {
        for cells in [[20, 2, 3], [40, 3, 5], [80, 5, 8], [120, 7, 12]] {
            let (standard, beam) = bar_tip(poisson, Formulation::Standard, cells);
            let (averaged, _) = bar_tip(poisson, Formulation::AveragedPressure, cells);
            println!(
                "{{\"case\": \"bar\", \"poisson\": {poisson}, \"cells\": {cells:?}, \"tets\": {}, \"timoshenko_m\": {beam:.6e}, \"standard_ratio\": {:.4}, \"averaged_ratio\": {:.4}}}",
                6 * cells[0] * cells[1] * cells[2], standard / beam, averaged / beam
            );
        }
    }
}
