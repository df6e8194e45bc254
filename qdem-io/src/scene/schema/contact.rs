//! `[contact]` and `[[wall]]`: how bodies touch each other and the walls.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// `[contact].law`: the contact law between spheres of different bodies and against walls.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ContactLawName {
    /// Linear Voigt spring (`normal_stiffness`, `tangential_stiffness`) with a Coulomb slider.
    #[default]
    #[serde(rename = "linear")]
    Linear,
    /// Hertz–Mindlin from the bodies' `young` and `poisson`, with a Mohr–Coulomb limit.
    #[serde(rename = "hertz-mindlin")]
    HertzMindlin,
}

scene_table! {
    /// `[contact]`: how bodies with contact spheres touch each other and the walls.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Contact in "[contact]" {
        #[serde(default)]
        law: ContactLawName => "\"linear\" or \"hertz-mindlin\"", optional = "\"linear\"",
            "The law; default linear.";
        #[serde(default)]
        normal_stiffness: Option<f64> => "number", optional,
            "Normal spring constant k_n (N/m), required by the linear law.";
        #[serde(default)]
        tangential_stiffness: Option<f64> => "number", optional,
            "Tangential spring constant k_t (N/m), required by the linear law.";
        #[serde(default)]
        friction: f64 => "number", optional = "0.0",
            "Coulomb friction coefficient between bodies (and walls that give none); default 0.";
        #[serde(default)]
        rolling_friction: f64 => "number", optional = "0.0",
            "Coefficient of rolling friction μ_r between bodies and against walls: a rolling \
             spring torque k_t R*² θ_r capped at μ_r R* F_n (LIGGGHTS `epsd2`, docs/contact.md); \
             default 0, none.";
        #[serde(default)]
        damping_ratio: f64 => "number", optional = "0.0",
            "Damping ratio ζ of the contact dashpots, in [0, 1); default 0 (paper 000: the \
             viscosity is in the bulk).";
        #[serde(default)]
        restitution: Option<f64> => "number", optional,
            "Coefficient of restitution e of a head-on impact, in (0, 1], instead of \
             `damping_ratio` (refused beside a non-zero one): ζ = −ln e / √(ln² e + π²).";
        #[serde(default)]
        local_damping: f64 => "number", optional = "0.0",
            "PFC's local non-viscous damping fraction, in [0, 1) (paper 003: 0.7 for quasi-static \
             packing); default 0.";
        #[serde(default)]
        skin: Option<f64> => "number", optional,
            "Skin distance of the neighbour lists (m); default a quarter of the smallest contact \
             radius.";
        #[serde(default = "default_overlap_tolerance")]
        overlap_tolerance: f64 => "number", optional = "0.05",
            "Largest overlap allowed at the start, as a fraction of the reduced radius; default \
             0.05.";
    }
}

impl Contact {
    /// The damping ratio ζ of the contact dashpots: `damping_ratio`, or the one that gives
    /// `restitution` e, ζ = −ln e / √(ln² e + π²). For the linear law this is exact: a head-on
    /// impact rebounds with e = exp(−ζπ/√(1 − ζ²)); for Hertz–Mindlin it is LIGGGHTS's
    /// β = −ζ, which gives e as well (Tsuji's damping, γ ∝ √δ: e does not depend on the
    /// impact speed).
    pub fn damping(&self) -> f64 {
        match self.restitution {
            Some(e) => {
                let log = e.ln();
                -log / (log * log + std::f64::consts::PI.powi(2)).sqrt()
            }
            None => self.damping_ratio,
        }
    }
}

fn default_overlap_tolerance() -> f64 {
    0.05
}

/// `[[wall]] start`: where a wall of a scene that starts from a checkpoint (`[run]
/// start_from`) begins.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum WallStart {
    /// Where the same wall (by its order) stood in the checkpoint, a servo wall with the
    /// velocity its servo had set: a stage goes on where the last one left its walls.
    #[default]
    #[serde(rename = "checkpoint")]
    Checkpoint,
    /// Where this scene places it (`point`, or the mesh as it is): a stage moves the wall.
    #[serde(rename = "scene")]
    Scene,
}

scene_table! {
    /// `[[wall]]`: a rigid plane (`point`, `normal`) or triangulated surface (`mesh`).
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Wall in "[[wall]]" {
        #[serde(default)]
        point: Option<[f64; 3]> => "[x, y, z]", optional,
            "A point of the plane (m).";
        #[serde(default)]
        normal: Option<[f64; 3]> => "[x, y, z]", optional,
            "The plane's normal, pointing to the side where bodies are (any length).";
        #[serde(default)]
        mesh: Option<PathBuf> => "path", optional,
            "A tetrahedral gmsh mesh whose boundary surface is the wall, relative to the scene \
             file.";
        #[serde(default)]
        friction: Option<f64> => "number", optional,
            "Friction coefficient against bodies; default `[contact] friction`.";
        #[serde(default)]
        velocity: [f64; 3] => "[x, y, z]", optional = "[0.0, 0.0, 0.0]",
            "Constant velocity of the wall (m/s); default zero.";
        #[serde(default)]
        servo: Option<WallServo> => "inline table", optional,
            "Stress control of a plane wall: `{ stress, area, gain, max_velocity, ramp }`; after each \
             force evaluation its speed towards the bodies is clamp(G (σ_target − σ), ±v_max), σ \
             the spheres' normal force on it over `area`. Not with `velocity` or a mesh.";
        #[serde(default)]
        start: WallStart => "\"checkpoint\" or \"scene\"", optional = "\"checkpoint\"",
            "With `[run] start_from`: where the wall begins. \"checkpoint\" (default): where the \
             checkpoint's wall of the same order stood at its end (a plane through its point \
             there, a mesh at its displacement there; a servo wall with its speed there), then \
             moving with `velocity` or its servo. \"scene\": at `point` (or the mesh as it is), \
             moving the wall for this stage.";
    }
}

scene_table! {
    /// `[[wall]] servo`: a plane wall whose speed along its normal is set after each force
    /// evaluation to clamp(G (σ_target − σ), ±v_max), σ the compressive stress the spheres put on
    /// it (their normal force over `area`), positive towards the bodies. σ_target may follow a
    /// load path in time, `ramp` (a factor on `stress`, as a `[[load]]`'s ramp).
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct WallServo in "[[wall]] servo" {
        stress: f64 => "number", required,
            "Target compressive normal stress σ_target (Pa), times `ramp`.";
        #[serde(default)]
        ramp: Option<Vec<[f64; 2]>> => "[[t, factor], …]", optional,
            "Time factor on `stress`, a load path: `[t, factor]` points, linear between, held \
             outside, two points at one time a step (as a `[[load]]`'s ramp; t from this run's \
             start); default a constant 1.";
        area: f64 => "number", required,
            "The area A the wall's normal force is divided by (m², > 0).";
        #[serde(default)]
        gain: Option<f64> => "number", optional,
            "Gain G (m/(s·Pa), > 0); default 0.5 A / Σ (k_n Δt + c_n) over the wall's touching \
             contacts, renewed each step (PFC's servo with the normal dashpots c_n).";
        max_velocity: f64 => "number", required,
            "Largest speed v_max (m/s, > 0): the servo's clamp and the wall's speed bound for the \
             neighbour lists.";
    }
}

impl WallServo {
    /// The contact model's servo. The scene's validation has already refused ramps the core
    /// would refuse.
    pub fn servo(&self) -> Result<qdem_contact::Servo, qdem_core::error::CoreError> {
        let points = self.ramp.clone().unwrap_or_default();
        let factor = super::fix_load::Ramp { points }.time_function()?;
        Ok(qdem_contact::Servo {
            stress: self.stress,
            factor,
            area: self.area,
            gain: self.gain,
            max_velocity: self.max_velocity,
        })
    }
}
