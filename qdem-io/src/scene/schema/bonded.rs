//! `[bonded]`: a 2D beam-bonded particle body.

use serde::{Deserialize, Serialize};

/// `[bonded] packing`: how the rectangle is filled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PackingName {
    /// A triangular lattice.
    #[default]
    Regular,
    /// The lattice with random offsets of up to `jitter` spacings.
    Random,
}

/// `[bonded] event_solve`: how an implicit step is solved after events changed the tangent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EventSolveName {
    /// Refactorise the matrix at every change.
    #[default]
    Refactorize,
    /// Conjugate gradients preconditioned by the kept factor, refactorising past a bound.
    Preconditioned,
}

/// `[bonded] supports`: how the beam is held.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Supports {
    /// Simply supported: the end line of particles at each end held vertically, the left one
    /// nearest mid-height held horizontally.
    #[default]
    Simple,
    /// As `simple`, with the right end's mid-height particle held horizontally too (a pin on
    /// the centroid at each end: identical to `simple` before cracking, an arch after).
    Pinned,
    /// Nothing held.
    None,
}

scene_table! {
    /// `[bonded]`: a 2D beam-bonded particle body (paper 001) filling a rectangle of the x–y
    /// plane, with its supports and a uniform load on its top row. A scene with `[bonded]` has no
    /// `[[body]]` and is integrated with `integrator = "newmark"`.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Bonded in "[bonded]" {
        name: String => "string", required,
            "Body name (for probes and messages).";
        material: String => "string", required,
            "A `[[material]]`: density, young, poisson of the continuum represented.";
        #[serde(default)]
        origin: [f64; 2] => "[a, b]", optional = "[0.0, 0.0]",
            "Lower-left corner (m); default the origin.";
        size: [f64; 2] => "[a, b]", required,
            "Width and height (m).";
        #[serde(default = "one")]
        thickness: f64 => "number", optional = "1.0",
            "Out-of-plane thickness (m); default 1.";
        element_size: f64 => "number", required,
            "Particle spacing (m).";
        #[serde(default)]
        packing: PackingName => "\"regular\" or \"random\"", optional = "\"regular\"",
            "`\"regular\"` (default) or `\"random\"`.";
        #[serde(default = "default_jitter")]
        jitter: f64 => "number", optional = "0.1",
            "Largest random offset in spacings for `packing = \"random\"`, in [0, 0.25); default \
             0.1.";
        #[serde(default)]
        packing_seed: u64 => "integer", optional = "0",
            "Seed of the random packing; default 0.";
        strength_mean: f64 => "number", required,
            "Mean bond strength (Pa).";
        #[serde(default)]
        strength_std: f64 => "number", optional = "0.0",
            "Standard deviation of the bond strength (Pa); default 0.";
        #[serde(default)]
        strength_seed: u64 => "integer", optional = "0",
            "Seed of the strengths; default 0.";
        #[serde(default)]
        damping_ratio: f64 => "number", optional = "0.0",
            "Bond damping ratio ξ_b (Eq. 8), in [0, 1); default 0.";
        #[serde(default)]
        critical_fraction: Option<f64> => "number", optional,
            "Step as a multiple of the paper's ∆t_crit (Eq. 28): 0.2 for the paper's explicit \
             runs, η for implicit ones. Optional; replaces `[run] dt`.";
        #[serde(default = "yes")]
        adaptive: bool => "bool", optional = "true",
            "Retake steps that overshoot a bond's strength or a contact's opening (Eqs. 29–30); \
             default true.";
        #[serde(default)]
        event_solve: EventSolveName =>
            "\"refactorize\" or \"preconditioned\"", optional = "\"refactorize\"",
            "Implicit runs: how a step is solved after bonds broke or contacts changed (issue 26); \
             default `\"refactorize\"`.";
        #[serde(default = "default_tolerance")]
        tolerance: f64 => "number", optional = "0.05",
            "Relative overshoot ε tolerated before a retake; default 0.05.";
        #[serde(default = "default_shear_ratio")]
        contact_shear_ratio: f64 => "number", optional = "0.2",
            "Unbonded contacts: tangential over normal stiffness; default 0.2.";
        #[serde(default = "default_bbm_friction")]
        friction: f64 => "number", optional = "0.5",
            "Unbonded contacts: Coulomb friction; default 0.5.";
        #[serde(default)]
        contact_damping_ratio: f64 => "number", optional = "0.0",
            "Unbonded contacts: damping ratio ξ_u (Eq. 6), in [0, 1); default 0.";
        #[serde(default)]
        supports: Supports => "\"simple\", \"pinned\" or \"none\"", optional = "\"simple\"",
            "`\"simple\"` (default), `\"pinned\"` or `\"none\"`.";
        #[serde(default)]
        top_load: f64 => "number", optional = "0.0",
            "Uniform downward line load on the top row (N/m); default 0.";
        #[serde(default)]
        load_ramp: f64 => "number", optional = "0.0",
            "Time over which `top_load` rises linearly from zero (s); default 0: applied at once.";
    }
}

fn one() -> f64 {
    1.0
}

fn yes() -> bool {
    true
}

fn default_jitter() -> f64 {
    0.1
}

fn default_tolerance() -> f64 {
    0.05
}

fn default_shear_ratio() -> f64 {
    0.2
}

fn default_bbm_friction() -> f64 {
    0.5
}
