//! The tetrahedron of a deformable body: `averaged-pressure` where ν ≥ 0.45, where the
//! standard one locks (the measured deflections of [`crate::build::locking`]), and the
//! standard one below, where it does not lock and costs less: the averaged-pressure
//! evaluation measured 2.35x the standard kernel's per tet-step elastic and 1.98x
//! viscoelastic (docs/verification.md, "Cost").

use super::{Advice, Topic};
use crate::build::locking::{measured_deflection, LOCKING_POISSON};
use crate::scene::{Formulation, Material};

/// Per tet-step cost of the averaged-pressure evaluation over the standard kernel's, elastic
/// and viscoelastic (docs/verification.md).
const COST: [f64; 2] = [2.35, 1.98];

/// The advice for the deformable body `body` of `material`.
pub(super) fn advise(body: &str, material: &Material) -> Advice {
    let nu = material.poisson;
    let viscous = material.shear_viscosity > 0.0 || material.bulk_viscosity > 0.0;
    let cost = COST[usize::from(viscous)];
    let now = match material.formulation {
        Formulation::Standard => "standard",
        Formulation::AveragedPressure => "averaged-pressure",
    };
    let locks = nu >= LOCKING_POISSON;
    let (at, ratio) = measured_deflection(nu);
    let (advised, reasoning) = match locks {
        true => (
            "averaged-pressure",
            format!(
                "poisson = {nu} >= {LOCKING_POISSON}: the standard tetrahedron locks (a clamped \
                 bar at poisson = {at} deflected {ratio:.2}x beam theory, 0.89x at 0.33); the \
                 averaged-pressure one does not, at {cost:.2}x the cost per tet-step"
            ),
        ),
        false => (
            "standard",
            format!(
                "poisson = {nu} < {LOCKING_POISSON}: the standard tetrahedron does not lock \
                 here and costs 1/{cost:.2} of the averaged-pressure one per tet-step"
            ),
        ),
    };
    let predicted_error = match (locks, material.formulation) {
        (true, Formulation::Standard) => 1.0 - ratio / 0.89,
        _ => 0.0,
    };
    Advice {
        subject: format!("body `{body}`"),
        topic: Topic::Formulation,
        now: now.to_string(),
        advised: advised.to_string(),
        reasoning,
        figures: vec![
            ("poisson".into(), nu),
            ("predicted_error".into(), predicted_error),
            ("cost_ratio".into(), cost),
        ],
    }
}
