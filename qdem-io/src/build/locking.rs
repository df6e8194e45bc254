//! The warning that a nearly incompressible material locks on linear tetrahedra (issue 43).
//!
//! A linear tetrahedron has one volumetric strain; as ν → 0.5 it must vanish in every element,
//! which a mesh of them cannot do in bending, so the body comes out far too stiff with no
//! other sign. The figures quoted are measured: a clamped 1.0 × 0.06 × 0.10 m bar of 4,376
//! tetrahedra under a 500 N tip load, static, against Timoshenko beam theory (the issue's
//! table), and the averaged-pressure formulation that does not lock
//! ([`qdem_core::continuum::averaged_pressure_tet`]). The explicit step is set by the bulk
//! (dilatational) wave whatever the formulation, which the warning of an explicit run states
//! as well; an implicit or static run has no such step, so an averaged-pressure body is not
//! warned of there at all.

use crate::scene::{Formulation, Material, Scene};

/// The Poisson's ratio from which a standard body is warned of.
pub const LOCKING_POISSON: f64 = 0.45;

/// (ν, tip deflection of the bar over beam theory) for the standard kernel; the
/// compressible reference is 0.89 at ν = 0.33 on the same mesh.
const MEASURED: [(f64, f64); 4] = [(0.45, 0.83), (0.49, 0.70), (0.499, 0.38), (0.4999, 0.10)];

/// One warning per deformable `[[body]]` whose material has ν ≥ [`LOCKING_POISSON`]: for the
/// standard formulation, the expected locking and the option that avoids it; in an explicit
/// run, for either, the bulk wave that sets the step.
pub fn warnings(scene: &Scene) -> Vec<String> {
    let materials = &scene.refs().body_materials;
    let explicit = !super::scheme(scene).is_implicit();
    scene
        .bodies
        .iter()
        .zip(materials)
        .filter(|(body, _)| !body.rigid)
        .filter_map(|(body, &m)| {
            let material = &scene.materials[m];
            (material.poisson >= LOCKING_POISSON)
                .then(|| warning(&body.name, material, explicit))
                .flatten()
        })
        .collect()
}

/// The warning for body `body` of `material` in an `explicit` run or not; none for an
/// averaged-pressure body outside an explicit run.
fn warning(body: &str, material: &Material, explicit: bool) -> Option<String> {
    let nu = material.poisson;
    let wave = bulk_wave_ratio(nu);
    let step = format!(
        "its explicit stable step is set by the bulk (dilatational) wave, \
         c_d = {:.4e} m/s, {wave:.1}x the shear wave speed: the step is {wave:.1}x shorter than \
         the shear (bending) response needs",
        bulk_wave_speed(material)
    );
    let step = match explicit {
        true => format!("; {step}"),
        false => String::new(),
    };
    match material.formulation {
        Formulation::AveragedPressure => explicit.then(|| {
            format!(
                "body `{body}`: material `{}` has poisson = {nu} and formulation = \
                 \"averaged-pressure\" (locking-free){step}",
                material.name
            )
        }),
        Formulation::Standard => {
            let (at, ratio) = measured_deflection(nu);
            Some(format!(
                "body `{body}`: material `{}` has poisson = {nu} >= {LOCKING_POISSON}: linear \
                 tetrahedra LOCK for nearly incompressible materials and the body will come out \
                 far too stiff in bending (a clamped bar of 4,376 tets at poisson = {at} \
                 deflected {ratio:.2}x beam theory, against 0.89x at poisson = 0.33 on the same \
                 mesh); add formulation = \"averaged-pressure\" to [[material]] `{}` (average \
                 nodal pressure tetrahedra, which bend as a compressible material does: 0.85x \
                 beam theory at poisson = 0.4999 against 0.82x for the standard at 0.33 on a \
                 3,600-tet bar){step}",
                material.name, material.name
            ))
        }
    }
}

/// The measured (ν, deflection over beam theory) of the standard kernel at the largest
/// tabulated ν not above `nu` (the first row below the table).
pub(crate) fn measured_deflection(nu: f64) -> (f64, f64) {
    MEASURED
        .iter()
        .rev()
        .find(|(at, _)| *at <= nu)
        .copied()
        .unwrap_or(MEASURED[0])
}

/// c_d / c_s = √((λ + 2μ)/μ) = √(2(1 − ν)/(1 − 2ν)).
fn bulk_wave_ratio(nu: f64) -> f64 {
    (2.0 * (1.0 - nu) / (1.0 - 2.0 * nu)).sqrt()
}

/// c_d = √((λ + 2μ)/ρ) (m/s).
fn bulk_wave_speed(m: &Material) -> f64 {
    let nu = m.poisson;
    let modulus = m.young * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    (modulus / m.density).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn material(poisson: f64, formulation: Formulation) -> Material {
        Material {
            name: "rubber".into(),
            density: 1100.0,
            young: 5e6,
            poisson,
            shear_viscosity: 0.0,
            bulk_viscosity: 0.0,
            formulation,
        }
    }

    #[test]
    fn a_nearly_incompressible_standard_material_is_told_its_locking_and_the_fix() {
        let w = warning("pad", &material(0.4999, Formulation::Standard), true).unwrap();
        assert!(w.contains("LOCK"), "{w}");
        assert!(w.contains("0.10x beam theory"), "{w}");
        assert!(w.contains("formulation = \"averaged-pressure\""), "{w}");
        // c_d/c_s = √(2 · 0.5001 / 0.0002) = 70.7.
        assert!(w.contains("70.7x the shear wave speed"), "{w}");
        let w = warning("pad", &material(0.46, Formulation::Standard), true).unwrap();
        assert!(w.contains("poisson = 0.45 deflected 0.83x"), "{w}");
    }

    /// An implicit or static run has no explicit step: the standard body is told its locking
    /// without the step, and an averaged-pressure body is not warned of at all.
    #[test]
    fn a_run_that_is_not_explicit_hears_nothing_of_the_explicit_step() {
        let w = warning("pad", &material(0.4999, Formulation::Standard), false).unwrap();
        assert!(w.contains("LOCK"), "{w}");
        assert!(!w.contains("explicit") && !w.contains("wave"), "{w}");
        assert!(w.ends_with("3,600-tet bar)"), "{w}");
        let averaged = material(0.4999, Formulation::AveragedPressure);
        assert_eq!(warning("pad", &averaged, false), None);
        assert!(warning("pad", &averaged, true).is_some());
    }

    #[test]
    fn the_bulk_wave_speed_is_that_of_the_constrained_modulus() {
        // ν = 0.25: λ = μ, c_d² = 3μ/ρ and c_s² = μ/ρ.
        assert!((bulk_wave_ratio(0.25) - 3f64.sqrt()).abs() < 1e-12);
        let m = material(0.25, Formulation::Standard);
        let mu = m.young / 2.5;
        assert!((bulk_wave_speed(&m) / (3.0 * mu / m.density).sqrt() - 1.0).abs() < 1e-12);
    }
}
