//! `[run]`: how long and how to integrate.

use std::fmt;
use std::path::PathBuf;

use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize, Serializer};

/// The error message for a `dt` that is neither `"auto"` nor a number.
pub(crate) const DT_MESSAGE: &str = "dt must be \"auto\" or a number of seconds";

scene_table! {
    /// `[run]`: how long and how to integrate.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Run in "[run]" {
        t_end: f64 => "number", required,
            "Simulated end time, s. Required, > 0.";
        #[serde(default)]
        dt: TimeStep => "number or \"auto\"", optional = "\"auto\"",
            "Time step: `\"auto\"` (default) or a fixed number of seconds (a normal number: a \
             subnormal one such as 1e-320 is refused).";
        #[serde(default)]
        integrator: Integrator => "\"verlet\", \"newmark\" or \"static\"", optional = "\"verlet\"",
            "Time integrator; default `\"verlet\"`; `\"static\"`: a linear static solve at every \
             `dt` of the load factor (default `probe_every`, else t_end / 100), once per distinct \
             load level, writing the final state's VTU.";
        #[serde(default)]
        gravity: [f64; 3] => "[x, y, z]", optional = "[0.0, 0.0, 0.0]",
            "Gravitational acceleration, m/s²; default zero.";
        #[serde(default)]
        probe_every: Option<f64> => "number", optional,
            "Simulated time between two rows of `probes.csv` (and the other CSV records), s (> 0); \
             default t_end / 1000.";
        #[serde(default = "default_dt_safety")]
        dt_safety: f64 => "number", optional = "0.9",
            "Fraction of the stable time-step bound used when `dt = \"auto\"`, in (0, 1]; default \
             0.9.";
        #[serde(default = "default_beta")]
        beta: f64 => "number", optional = "0.25",
            "Newmark β (paper 001 Eq. 13), for `integrator = \"newmark\"` only (refused with \
             another integrator, where it would do nothing); default ¼ (average acceleration, \
             implicit). β = 0 with γ = ½ is explicit central difference.";
        #[serde(default = "default_gamma")]
        gamma: f64 => "number", optional = "0.5",
            "Newmark γ (paper 001 Eq. 14), for `integrator = \"newmark\"` only (refused with \
             another integrator); default ½.";
        #[serde(default)]
        start_from: Option<PathBuf> => "path", optional,
            "Start from the state in this checkpoint (written by another scene with the same \
             bodies, e.g. a deposition run), relative to the scene file: positions, velocities and \
             reference positions are taken from it, time restarts at 0, and the tangential contact \
             springs are carried between the same spheres and walls (a spring whose sphere or wall \
             this scene lacks is dropped and counted); the walls begin where the checkpoint left \
             them (`[[wall]] start`), and the overlaps of what the stage places (its walls, and \
             bodies whose `rigid` changed) are checked at the checkpoint's positions; two bodies \
             both where the checkpoint left them overlap as its contacts did and are not.";
    }
}

fn default_beta() -> f64 {
    0.25
}

fn default_gamma() -> f64 {
    0.5
}

impl Run {
    /// The `dt_safety` used when the scene does not give one.
    pub const DEFAULT_DT_SAFETY: f64 = 0.9;
}

fn default_dt_safety() -> f64 {
    Run::DEFAULT_DT_SAFETY
}

/// `[run] dt`: the time step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum TimeStep {
    /// `dt = "auto"`: `dt_safety` times the stable bound computed from the models.
    #[default]
    Auto,
    /// `dt = <seconds>`: a fixed step (refused later if above the stable bound).
    Fixed(f64),
}

impl<'de> Deserialize<'de> for TimeStep {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct TimeStepVisitor;

        impl<'de> Visitor<'de> for TimeStepVisitor {
            type Value = TimeStep;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"auto\" or a number of seconds")
            }

            fn visit_str<E: de::Error>(self, v: &str) -> Result<TimeStep, E> {
                if v == "auto" {
                    Ok(TimeStep::Auto)
                } else {
                    Err(E::custom(DT_MESSAGE))
                }
            }

            fn visit_f64<E: de::Error>(self, v: f64) -> Result<TimeStep, E> {
                Ok(TimeStep::Fixed(v))
            }

            fn visit_i64<E: de::Error>(self, v: i64) -> Result<TimeStep, E> {
                Ok(TimeStep::Fixed(v as f64))
            }

            fn visit_u64<E: de::Error>(self, v: u64) -> Result<TimeStep, E> {
                Ok(TimeStep::Fixed(v as f64))
            }

            fn visit_bool<E: de::Error>(self, _: bool) -> Result<TimeStep, E> {
                Err(E::custom(DT_MESSAGE))
            }

            fn visit_map<A: de::MapAccess<'de>>(self, _: A) -> Result<TimeStep, A::Error> {
                Err(de::Error::custom(DT_MESSAGE))
            }

            fn visit_seq<A: de::SeqAccess<'de>>(self, _: A) -> Result<TimeStep, A::Error> {
                Err(de::Error::custom(DT_MESSAGE))
            }
        }

        deserializer.deserialize_any(TimeStepVisitor)
    }
}

impl Serialize for TimeStep {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            TimeStep::Auto => serializer.serialize_str("auto"),
            TimeStep::Fixed(dt) => serializer.serialize_f64(*dt),
        }
    }
}

/// `[run] integrator`: the time integration scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Integrator {
    /// Explicit velocity Verlet (central difference), as in the QDEM paper.
    #[default]
    #[serde(rename = "verlet")]
    Verlet,
    /// Newmark-β with `beta` and `gamma` (paper 001 Eqs. 13–16, 22–27): implicit for β > 0
    /// (needs a numeric `dt`), explicit central difference for β = 0.
    #[serde(rename = "newmark")]
    Newmark,
    /// Linear static solve K·u = f at every `dt` (default: `probe_every`, else t_end/100) of
    /// the load ramp up to `t_end`, solving once per distinct load level; velocities and
    /// accelerations are zero. The final state's VTU is written without `vtu_every`.
    #[serde(rename = "static")]
    Static,
}

impl Integrator {
    /// Every integrator, in the order the error messages list them.
    pub const ALL: &'static [Integrator] =
        &[Integrator::Verlet, Integrator::Newmark, Integrator::Static];

    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Verlet => "verlet",
            Integrator::Newmark => "newmark",
            Integrator::Static => "static",
        }
    }
}
