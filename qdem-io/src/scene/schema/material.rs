//! `[[material]]`: the elastic (and viscous) materials.

use serde::{Deserialize, Serialize};

scene_table! {
    /// `[[material]]`: a linear elastic (optionally Kelvin–Voigt viscous) isotropic material.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Material in "[[material]]" {
        name: String => "string", required,
            "Unique name that `[[body]] material` refers to.";
        density: f64 => "number", required,
            "Mass density, kg/m³ (> 0).";
        young: f64 => "number", required,
            "Young's modulus, Pa (> 0).";
        poisson: f64 => "number", required,
            "Poisson's ratio ν, in (−1, 0.5).";
        #[serde(default)]
        shear_viscosity: f64 => "number", optional = "0.0",
            "Shear viscosity μ_D, Pa·s (≥ 0); default 0.";
        #[serde(default)]
        bulk_viscosity: f64 => "number", optional = "0.0",
            "Bulk viscosity λ_D + 2/3 μ_D, Pa·s (≥ 0); default 0.";
        #[serde(default)]
        formulation: Formulation =>
            "\"standard\" or \"averaged-pressure\"", optional = "\"standard\"",
            "`\"standard\"` (default) or `\"averaged-pressure\"`: the average nodal pressure \
             tetrahedron (Bonet & Burton 1998) that does not lock as ν → 0.5.";
    }
}

/// `[[material]] formulation`: the standard QDEM tetrahedron, or the average nodal pressure
/// one (Bonet & Burton 1998) that does not lock as ν → 0.5 ([`qdem_core::continuum::Formulation`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Formulation {
    /// `"standard"`: each tetrahedron its own volumetric strain (paper 000 Eqs. 1–10).
    #[default]
    Standard,
    /// `"averaged-pressure"`: the volumetric strain averaged over each particle's tetrahedra.
    AveragedPressure,
}

impl Formulation {
    /// The core's formulation.
    pub fn core(self) -> qdem_core::continuum::Formulation {
        match self {
            Formulation::Standard => qdem_core::continuum::Formulation::Standard,
            Formulation::AveragedPressure => qdem_core::continuum::Formulation::AveragedPressure,
        }
    }
}
