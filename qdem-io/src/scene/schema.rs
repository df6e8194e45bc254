//! The data types of a scene: what a scene file deserializes into.
//!
//! Most tables deserialize straight into their public type. `[[fix]]` and `[[load]]` go through
//! private raw forms first, because their `group`/`box` pair becomes a single [`Selection`] and
//! their `dofs`/`ramp` are checked and normalised; that happens during
//! validation ([`super::Scene::parse`]).

use std::fmt;
use std::path::PathBuf;

use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize, Serializer};

/// The error message for a `dt` that is neither `"auto"` nor a number.
pub(crate) const DT_MESSAGE: &str = "dt must be \"auto\" or a number of seconds";

/// `[run]`: how long and how to integrate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Run {
    /// Simulated end time, s. Required, > 0.
    pub t_end: f64,
    /// Time step: `"auto"` (default) or a fixed number of seconds.
    #[serde(default)]
    pub dt: TimeStep,
    /// Time integrator; default [`Integrator::Verlet`].
    #[serde(default)]
    pub integrator: Integrator,
    /// Gravitational acceleration, m/s²; default zero.
    #[serde(default)]
    pub gravity: [f64; 3],
    /// Simulated time between two rows of `probes.csv`, s (> 0). Optional: `None` leaves the
    /// choice to the run loop.
    #[serde(default)]
    pub probe_every: Option<f64>,
    /// Fraction of the stable time-step bound used when `dt = "auto"`, in (0, 1]; default
    /// [`Run::DEFAULT_DT_SAFETY`].
    #[serde(default = "default_dt_safety")]
    pub dt_safety: f64,
    /// Newmark β (paper 001 Eq. 13), for `integrator = "newmark"` only (refused with another
    /// integrator); default ¼ (average acceleration, implicit). β = 0 with γ = ½ is explicit
    /// central difference.
    #[serde(default = "default_beta")]
    pub beta: f64,
    /// Newmark γ (paper 001 Eq. 14), for `integrator = "newmark"` only (refused with another
    /// integrator); default ½.
    #[serde(default = "default_gamma")]
    pub gamma: f64,
    /// Start from the state in this checkpoint (written by another scene with the same bodies,
    /// e.g. a deposition run), relative to the scene file: positions, velocities and reference
    /// positions are taken from it, time restarts at 0, the tangential contact springs carry
    /// over between the same spheres and walls.
    #[serde(default)]
    pub start_from: Option<PathBuf>,
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

/// `[[material]]`: a linear elastic (optionally Kelvin–Voigt viscous) isotropic material.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Unique name that `[[body]] material` refers to.
    pub name: String,
    /// Mass density, kg/m³ (> 0).
    pub density: f64,
    /// Young's modulus, Pa (> 0).
    pub young: f64,
    /// Poisson's ratio ν, in (−1, 0.5).
    pub poisson: f64,
    /// Shear viscosity μ_D, Pa·s (≥ 0); default 0.
    #[serde(default)]
    pub shear_viscosity: f64,
    /// Bulk viscosity λ_D + 2/3 μ_D, Pa·s (≥ 0); default 0.
    #[serde(default)]
    pub bulk_viscosity: f64,
    /// How its bodies' tetrahedra compute the volumetric stress; default `"standard"`.
    #[serde(default)]
    pub formulation: Formulation,
}

/// `[[material]] formulation`: the standard QDEM tetrahedron, or the average nodal pressure
/// one (Bonet & Burton 1998) that does not lock as ν → 0.5 ([`qdem_core::Formulation`]).
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
    pub fn core(self) -> qdem_core::Formulation {
        match self {
            Formulation::Standard => qdem_core::Formulation::Standard,
            Formulation::AveragedPressure => qdem_core::Formulation::AveragedPressure,
        }
    }
}

/// `[[body]]`: a continuum body meshed with tetrahedra.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// Unique name that fixes, loads and probes refer to.
    pub name: String,
    /// The gmsh mesh file as written in the scene, relative to the scene file's directory
    /// (see [`super::Scene::mesh_path`]).
    pub mesh: PathBuf,
    /// Name of a `[[material]]`.
    pub material: String,
    /// Reorder nodes for memory locality after import; default `true`.
    #[serde(default = "default_true")]
    pub reorder: bool,
    /// Merge the mesh's coincident nodes (nodes at one place, within 1e-9 of the mesh's size,
    /// that its tetrahedra do not share, as separately meshed volumes leave them) so that the
    /// tetrahedra on either side connect; default `false`: they are reported in a warning and
    /// the body stays in pieces there.
    #[serde(default)]
    pub merge_nodes: bool,
    /// Radius (m) of the contact spheres put at the body's surface vertices (paper 000 §4);
    /// `None` (the default): the body touches nothing.
    #[serde(default)]
    pub contact_radius: Option<f64>,
    /// Integrate the body as a rigid body (6 degrees of freedom, mass and inertia from its
    /// tetrahedra) instead of a deformable one; default `false`.
    #[serde(default)]
    pub rigid: bool,
    /// Translation applied to the mesh after the rotation (m); default zero.
    #[serde(default)]
    pub translate: [f64; 3],
    /// Rotation of the mesh about its nodes' centroid, in degrees about x, then y, then z
    /// (fixed axes); default zero.
    #[serde(default)]
    pub rotate_deg: [f64; 3],
    /// Initial velocity of every particle of the body (m/s); default zero.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Initial angular velocity of the body about its centre of mass (rad/s, world axes): a
    /// rigid body's ω; a deformable body's particles get v + ω × (x − x_c) in addition to
    /// `velocity`. Default zero.
    #[serde(default)]
    pub angular_velocity: [f64; 3],
    /// Name of the `[granular]` sample to lay the body on: after `translate` it is lowered
    /// along −z until its contact spheres touch the stones beneath (`rest_on.rs`); default
    /// none (the body stays where `translate` puts it).
    #[serde(default)]
    pub rest_on: Option<String>,
    /// A `poses.csv` written by an earlier run (relative to the scene file): a rigid body is
    /// placed where that run left its body of the same name (`pose_from.rs`); default none.
    #[serde(default)]
    pub pose_from: Option<PathBuf>,
    /// With `pose_from`: take the pose of this body of the poses file instead of the body of
    /// the same name (the sleepers of a three-sleeper box placed from the one sleeper of a
    /// periodic cell); default the body's own name.
    #[serde(default)]
    pub pose_body: Option<String>,
    /// With `pose_from`: added to the pose's centre of mass (m), e.g. one period along a
    /// periodic axis; default zero.
    #[serde(default)]
    pub pose_shift: [f64; 3],
}

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

/// `[contact]`: how bodies with contact spheres touch each other and the walls.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Contact {
    /// The law; default linear.
    #[serde(default)]
    pub law: ContactLawName,
    /// Normal spring constant k_n (N/m), required by the linear law.
    #[serde(default)]
    pub normal_stiffness: Option<f64>,
    /// Tangential spring constant k_t (N/m), required by the linear law.
    #[serde(default)]
    pub tangential_stiffness: Option<f64>,
    /// Coulomb friction coefficient between bodies (and walls that give none); default 0.
    #[serde(default)]
    pub friction: f64,
    /// Damping ratio ζ of the contact dashpots, in [0, 1); default 0 (paper 000: the
    /// viscosity is in the bulk).
    #[serde(default)]
    pub damping_ratio: f64,
    /// Coefficient of restitution e of a head-on impact, in (0, 1], instead of
    /// `damping_ratio`: ζ = −ln e / √(ln² e + π²) ([`Contact::damping`]).
    #[serde(default)]
    pub restitution: Option<f64>,
    /// PFC's local non-viscous damping fraction, in [0, 1) (paper 003: 0.7 for quasi-static
    /// packing); default 0.
    #[serde(default)]
    pub local_damping: f64,
    /// Skin distance of the neighbour lists (m); default a quarter of the smallest contact
    /// radius.
    #[serde(default)]
    pub skin: Option<f64>,
    /// Largest overlap allowed at the start, as a fraction of the reduced radius; default 0.05.
    #[serde(default = "default_overlap_tolerance")]
    pub overlap_tolerance: f64,
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

/// `[[wall]]`: a rigid plane (`point`, `normal`) or triangulated surface (`mesh`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    /// A point of the plane (m).
    #[serde(default)]
    pub point: Option<[f64; 3]>,
    /// The plane's normal, pointing to the side where bodies are (any length).
    #[serde(default)]
    pub normal: Option<[f64; 3]>,
    /// A tetrahedral gmsh mesh whose boundary surface is the wall, relative to the scene file.
    #[serde(default)]
    pub mesh: Option<PathBuf>,
    /// Friction coefficient against bodies; default `[contact] friction`.
    #[serde(default)]
    pub friction: Option<f64>,
    /// Constant velocity of the wall (m/s); default zero.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// A servo that moves the plane along its normal to hold a compressive stress.
    #[serde(default)]
    pub servo: Option<WallServo>,
}

/// `[[wall]] servo`: a plane wall whose speed along its normal is set after each force
/// evaluation to clamp(G (σ_target − σ), ±v_max), σ the compressive stress the spheres put on
/// it (their normal force over `area`), positive towards the bodies.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallServo {
    /// Target compressive stress σ_target (Pa).
    pub stress: f64,
    /// The area A the wall's normal force is divided by (m²).
    pub area: f64,
    /// Gain G (m/(s·Pa)); default 0.5 A / (Σ k_n Δt) at each evaluation (PFC's servo).
    #[serde(default)]
    pub gain: Option<f64>,
    /// Largest speed v_max (m/s).
    pub max_velocity: f64,
}

impl WallServo {
    /// The contact model's servo.
    pub fn servo(&self) -> qdem_contact::Servo {
        qdem_contact::Servo {
            stress: self.stress,
            area: self.area,
            gain: self.gain,
            max_velocity: self.max_velocity,
        }
    }
}

fn default_true() -> bool {
    true
}

/// Which particles of a body a fix or load applies to.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Selection {
    /// `group = "name"`: the nodes of a gmsh physical group.
    Group(String),
    /// `box = [[xmin, ymin, zmin], [xmax, ymax, zmax]]`: every particle inside the closed box.
    Box([[f64; 3]; 2]),
}

/// `[[fix]]`: prescribed zero displacement of some degrees of freedom.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fix {
    /// Name of the `[[body]]`.
    pub body: String,
    /// The particles that are fixed.
    pub selection: Selection,
    /// Fixed directions as an `[x, y, z]` mask, from `dofs = "xyz"` (default all three).
    pub dofs: [bool; 3],
    /// Also hold the rotation of the (rigid) body: `rotation = true`, e.g. a sleeper guided
    /// vertically by `dofs = "xy"`. Default false.
    pub rotation: bool,
}

/// `[[load]]`: a total force shared equally by the selected particles, or a pressure or
/// traction on the boundary faces they cover, lumped to the nodes by area; scaled by a ramp,
/// a cycle or a series.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Load {
    /// Name of the `[[body]]`.
    pub body: String,
    /// The particles that carry the load.
    pub selection: Selection,
    /// Total force, N, divided equally among the selected particles; zero for a load with
    /// `area`.
    pub total_force: [f64; 3],
    /// `pressure` or `traction` instead of `total_force`: a distributed load on the body's
    /// boundary triangles whose three nodes are all selected.
    pub area: Option<AreaLoad>,
    /// Time factor applied to `total_force`.
    pub ramp: Ramp,
    /// A sinusoidal time factor instead of `ramp`.
    pub cyclic: Option<CyclicLoad>,
    /// A time series read from a CSV file instead of `ramp`.
    pub series: Option<Series>,
}

/// A `[[load]]`'s distributed load on a face (Pa), lumped to the nodes of the face's
/// triangles by area (each node a third of each triangle's, `qdem_core::loads::surface_load`),
/// on the reference geometry (a dead load).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AreaLoad {
    /// `pressure = p`: p along the inward normal (positive pushes into the body).
    Pressure(f64),
    /// `traction = [tx, ty, tz]`: a force per unit area in a fixed direction.
    Traction([f64; 3]),
}

/// `series = { file, column }` of a `[[load]]`: the time factor on `total_force` is the named
/// column of a CSV file whose first column is time (s), linearly interpolated between rows and
/// held before the first and after the last. With `total_force = [0, 0, -1]` a column in
/// newtons is a downward force; with `[0, 0, -A]` a column in pascals is a pressure on the
/// area A (m²).
///
/// ```toml
/// [[load]]
/// body = "sleeper"
/// box = [[0.49, -0.2, 0.15], [0.64, 0.2, 0.2]]
/// total_force = [0.0, 0.0, -1.0]
/// series = { file = "train.csv", column = "Rp1" }
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Series {
    /// The CSV file, relative to the scene file; a header row names the columns.
    pub file: PathBuf,
    /// The column to read.
    pub column: String,
}

/// `cyclic = { min, max, frequency, phase_deg, start }` of a `[[load]]`: the factor on
/// `total_force` runs between `min` and `max` at `frequency`, each cycle beginning at the
/// minimum; `phase_deg` puts the load ahead (positive) of a zero-phase load that begins its
/// first cycle at `start`. Before its first cycle the factor is `min`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CyclicLoad {
    /// Factor at the minimum.
    pub min: f64,
    /// Factor at the maximum.
    pub max: f64,
    /// Hz.
    pub frequency: f64,
    /// Phase lead in degrees; default 0.
    #[serde(default)]
    pub phase_deg: f64,
    /// s; default 0.
    #[serde(default)]
    pub start: f64,
}

impl CyclicLoad {
    /// The core's cycle.
    pub fn cycle(&self) -> qdem_core::Cyclic {
        qdem_core::Cyclic {
            min: self.min,
            max: self.max,
            frequency: self.frequency,
            phase: self.phase_deg.to_radians(),
            start: self.start,
        }
    }
}

/// A piecewise-linear time factor given by `(t, factor)` points.
///
/// Between points the factor is interpolated linearly; before the first point the first factor
/// holds, after the last point the last factor holds. Two points with the same time make a jump:
/// the first value is reached from the left, the second holds from that time on. No points
/// means a constant factor 1 (the default when `ramp` is absent).
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
#[serde(transparent)]
pub struct Ramp {
    /// The `[t, factor]` points, times non-decreasing, at most two per time.
    pub points: Vec<[f64; 2]>,
}

impl Ramp {
    /// A constant factor 1.
    pub fn constant() -> Ramp {
        Ramp::default()
    }

    /// The ramp as the core's time function (a constant 1 when it has no points). The scene's
    /// validation has already refused ramps the core would refuse.
    ///
    /// ```
    /// use qdem_io::scene::Ramp;
    /// let ramp = Ramp { points: vec![[0.0, 0.0], [1.0, 1.0], [2.0, 1.0], [2.0, 0.0]] };
    /// let f = ramp.time_function().unwrap();
    /// assert_eq!(f.value(0.5), 0.5);
    /// assert_eq!(f.value(2.0), 0.0);
    /// assert_eq!(Ramp::constant().time_function().unwrap().value(3.0), 1.0);
    /// ```
    pub fn time_function(&self) -> Result<qdem_core::TimeFunction, qdem_core::CoreError> {
        if self.points.is_empty() {
            return Ok(qdem_core::TimeFunction::constant(1.0));
        }
        qdem_core::TimeFunction::new(self.points.iter().map(|p| (p[0], p[1])).collect())
    }
}

/// `[[probe]]`: what `probes.csv` follows. On a `[[body]]` (or `[ballast]`, `[bonded]`): the
/// particle nearest `point`, its displacement, velocity and acceleration. On the `[granular]`
/// sample (`body` names it): one stone, the one whose centre of mass is nearest `point` or
/// the `stone`-th, followed at its centre of mass; or the stones whose centre of mass lies in
/// `box` at each sample time, their mean velocity, kinetic energy and count.
///
/// ```toml
/// [[probe]]
/// name = "ball"
/// body = "grains"     # the [granular] name
/// stone = 1           # or point = [x, y, z], or box = [[x0, y0, z0], [x1, y1, z1]]
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Probe {
    /// Unique name (the CSV column prefix).
    pub name: String,
    /// Name of the `[[body]]`, `[ballast]`, `[bonded]` body or `[granular]` sample.
    pub body: String,
    /// The particle of the body nearest to this point (in the reference configuration), or
    /// the stone whose centre of mass is nearest to it, is sampled.
    #[serde(default)]
    pub point: Option<[f64; 3]>,
    /// `[granular]` only: the stone sampled, counted from 1 in the sample's order (the `stone`
    /// of `stones.csv`, `NAME stone K` in messages).
    #[serde(default)]
    pub stone: Option<usize>,
    /// `[granular]` only: a box (lower and upper corner, m): the stones whose centre of mass
    /// lies inside are averaged (columns `vx, vy, vz, ke, count`).
    #[serde(default, rename = "box")]
    pub region: Option<[[f64; 3]; 2]>,
}

/// `[[section]]`: a plane x[axis] = `at` across which the average magnitude of the contact
/// forces of touching sphere pairs is written to `sections.csv` at every probe time (the
/// force through a cell face of a box test, paper 003 §5; in a periodic cell the plane
/// repeats every period).
///
/// ```toml
/// [[section]]
/// name = "left"
/// axis = "y"
/// at = 0.7
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Section {
    /// Unique name (the CSV column).
    pub name: String,
    /// The axis the plane is normal to: "x", "y" or "z".
    pub axis: String,
    /// The plane's coordinate along `axis` (m).
    pub at: f64,
    /// The area of the section (m², a box test's cross-section): `sections.csv` then also has
    /// `NAME.stress`, the normal stress through the plane (Pa, tension positive).
    #[serde(default)]
    pub area: Option<f64>,
}

/// `[output]`: where and how often to write results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Output {
    /// Output directory as written (default `"out"`); the command line's `--out` overrides it.
    #[serde(default = "default_out_dir")]
    pub dir: PathBuf,
    /// Simulated time between VTU snapshots, s; 0 (the default) writes none.
    #[serde(default)]
    pub vtu_every: f64,
    /// Simulated time between checkpoints (`checkpoint.qdc` in the output directory, which
    /// `qdem run --resume` continues from), s; 0 (the default) writes one only when the run
    /// is interrupted (Ctrl-C, SIGTERM) or becomes unstable.
    #[serde(default)]
    pub checkpoint_every: f64,
    /// Whether to write `node_reactions.csv`: every `probe_every`, the force each `[[fix]]` of
    /// a deformable body carries at each of its particles, with the particle's gmsh node id and
    /// reference position; default false.
    #[serde(default)]
    pub node_reactions: bool,
}

impl Output {
    /// Whether VTU snapshots are requested.
    pub fn writes_vtu(&self) -> bool {
        self.vtu_every > 0.0
    }
}

impl Default for Output {
    fn default() -> Output {
        Output {
            dir: default_out_dir(),
            vtu_every: 0.0,
            checkpoint_every: 0.0,
            node_reactions: false,
        }
    }
}

fn default_out_dir() -> PathBuf {
    PathBuf::from("out")
}

/// `[[fix]]` as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawFix {
    pub body: String,
    #[serde(default)]
    pub group: Option<String>,
    #[serde(default, rename = "box")]
    pub bbox: Option<[[f64; 3]; 2]>,
    #[serde(default = "default_dofs")]
    pub dofs: String,
    #[serde(default)]
    pub rotation: bool,
}

fn default_dofs() -> String {
    "xyz".to_owned()
}

/// `[[load]]` as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawLoad {
    pub body: String,
    #[serde(default)]
    pub group: Option<String>,
    #[serde(default, rename = "box")]
    pub bbox: Option<[[f64; 3]; 2]>,
    #[serde(default)]
    pub total_force: Option<[f64; 3]>,
    #[serde(default)]
    pub pressure: Option<f64>,
    #[serde(default)]
    pub traction: Option<[f64; 3]>,
    #[serde(default)]
    pub ramp: Option<Vec<[f64; 2]>>,
    #[serde(default)]
    pub cyclic: Option<CyclicLoad>,
    #[serde(default)]
    pub series: Option<Series>,
}

/// The whole file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawScene {
    pub run: Run,
    #[serde(default, rename = "material")]
    pub materials: Vec<Material>,
    #[serde(default, rename = "body")]
    pub bodies: Vec<Body>,
    #[serde(default, rename = "fix")]
    pub fixes: Vec<RawFix>,
    #[serde(default, rename = "load")]
    pub loads: Vec<RawLoad>,
    #[serde(default, rename = "probe")]
    pub probes: Vec<Probe>,
    #[serde(default, rename = "section")]
    pub sections: Vec<Section>,
    #[serde(default, rename = "measure")]
    pub measures: Vec<super::measure::Measure>,
    #[serde(default)]
    pub contact: Option<Contact>,
    #[serde(default, rename = "wall")]
    pub walls: Vec<Wall>,
    #[serde(default)]
    pub bonded: Option<Bonded>,
    #[serde(default)]
    pub periodic: Option<Periodic>,
    #[serde(default)]
    pub granular: Option<Granular>,
    #[serde(default)]
    pub ballast: Option<Ballast>,
    #[serde(default)]
    pub output: Output,
}

/// `[ballast]`: deformable ballast stones (paper 000 §4): copies of gmsh stone meshes, each a
/// QDEM body with contact spheres at its surface vertices, scaled to a grading curve, turned at
/// random and laid on a loose lattice in `region` to be deposited under gravity. Together the
/// stones are one body called `name` (for probes, fixes, loads and output); in contact each
/// stone is its own body.
///
/// ```toml
/// [ballast]
/// name = "ballast"
/// material = "granite"
/// meshes = ["stones/coarse/stone_00.msh", "stones/coarse/stone_01.msh"]
/// contact_radius = 0.012
/// count = 300
/// region = [[-2.3, 0.0, 0.0], [2.3, 0.6, 1.0]]
/// exclude = [[-1.1, 0.15, 0.25], [1.1, 0.45, 1.0]]   # optional: keep clear (a sleeper)
/// grading = [[0.04, 0.0], [0.05, 0.5], [0.063, 1.0]]  # optional (sieve size m, passing)
/// seed = 1
/// velocity = [0.0, 0.0, -2.0]                           # optional (m/s)
/// rigid = false                                         # optional: rigid stones
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ballast {
    /// Name of the ballast body (stones are `NAME stone K` in messages).
    pub name: String,
    /// A `[[material]]`.
    pub material: String,
    /// Stone shapes: tetrahedral gmsh meshes, relative to the scene file.
    pub meshes: Vec<PathBuf>,
    /// Radius of the contact spheres at the stones' surface vertices, m (after scaling).
    pub contact_radius: f64,
    /// Number of stones.
    pub count: usize,
    /// The box filled with stones, bottom layer first (m).
    pub region: [[f64; 3]; 2],
    /// A box no stone may reach into (m).
    #[serde(default)]
    pub exclude: Option<[[f64; 3]; 2]>,
    /// Grading curve, (sieve size m, fraction passing) points; a stone's sieve size is the
    /// middle extent of its bounding box. Without one the meshes keep their size.
    #[serde(default)]
    pub grading: Option<Vec<[f64; 2]>>,
    /// Seed of the shapes, sizes, turns and lattice jitter; default 1.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Initial velocity of every stone (m/s), e.g. downward to shorten the fall; default 0.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Initial angular velocity of every stone about its own centre of mass (rad/s, world
    /// axes): its particles get v + ω × (x − x_c); default 0.
    #[serde(default)]
    pub angular_velocity: [f64; 3],
    /// Integrate each stone as a rigid body of its contact spheres (6 degrees of freedom, mass
    /// and inertia from its tetrahedra) instead of one deformable body; default `false`. A
    /// scene that `start_from`s a checkpoint may choose the other kind.
    #[serde(default)]
    pub rigid: bool,
}

/// `[periodic]`: periodic boundaries (paper 003 §4) along `axes`, over `length` (one period
/// per listed axis, from `origin`) or over the `box`.
///
/// ```toml
/// [periodic]
/// axes = "y"
/// length = [0.7]            # or box = [[0, 0, 0], [0.3, 0.7, 0.45]]
/// origin = [0.0, 0.0, 0.0]  # optional
///
/// [periodic.time_delay]     # optional: paper 003 §5
/// body = "sleeper"          # the body whose cyclic [[load]] gives the phase
/// lag_deg = 90.0            # or sleeper_spacing and speed (m, m/s)
/// shared_faces = false      # true: one scale for both sides of a pair (qdem's variant)
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Periodic {
    /// The periodic axes, e.g. `"y"` or `"xy"`.
    pub axes: String,
    /// One period per listed axis (m), in the order of `axes`.
    #[serde(default)]
    pub length: Option<Vec<f64>>,
    /// The lower corner of the cell (m); default the origin.
    #[serde(default)]
    pub origin: Option<[f64; 3]>,
    /// The cell as a box (lower and upper corner, m): origin and periods at once.
    #[serde(default, rename = "box")]
    pub bbox: Option<[[f64; 3]; 2]>,
    /// A time-delayed boundary.
    #[serde(default)]
    pub time_delay: Option<TimeDelay>,
}

/// `[periodic.time_delay]`: ghost forces scaled by the load phase of the neighbour cells
/// (paper 003 Eqs. 2–7).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeDelay {
    /// The body (a sleeper) whose `cyclic` [[load]] sets the phase Φ.
    pub body: String,
    /// The delayed axis; default the only periodic axis.
    #[serde(default)]
    pub axis: Option<String>,
    /// Phase lag δ of the neighbour cells (degrees); default 90 (paper 003 Eqs. 4–5).
    #[serde(default)]
    pub lag_deg: Option<f64>,
    /// With `speed`: the lag δ = 360° f s / v of sleepers `sleeper_spacing` apart (m).
    #[serde(default)]
    pub sleeper_spacing: Option<f64>,
    /// With `sleeper_spacing`: the speed of the travelling load (m/s).
    #[serde(default)]
    pub speed: Option<f64>,
    /// Shared faces (qdem's variant, not paper 003's Eqs. 6–7): both spheres of a pair
    /// through the boundary scaled alike, by the mean of the two faces' predicted forces, so
    /// the pair's action equals its reaction; default false.
    #[serde(default)]
    pub shared_faces: bool,
}

/// `[granular]`: a sample of rigid stones, each a clump of spheres (paper 003 §3), read from a
/// `sample` file (the `stones.csv` a run writes; `crop` keeps its stones lying wholly inside a
/// box) and/or generated loosely in `region` to be deposited under gravity.
///
/// ```toml
/// [granular]
/// name = "ballast"
/// material = "granite"
/// region = [[0, 0, 0.05], [0.3, 0.7, 1.2]]
/// count = 400
/// grading = [[0.0224, 0.0], [0.04, 0.5], [0.0625, 1.0]]  # (size m, fraction passing)
/// grading_basis = "mass"               # optional: fractions of mass; default "number"
/// spheres_per_stone = [3, 5]
/// shape = "angular"                    # optional: a stone with corners; default "elongated"
/// seed = 1
/// velocity = [0.0, 0.0, -1.0]          # optional, m/s: every stone
/// angular_velocity = [0.0, 20.0, 0.0]  # optional, rad/s: every stone about its centre
/// # region_velocity, region_angular_velocity: the generated stones' instead (a pour onto a
/// # sample at rest)
/// # or: sample = "stones.csv", crop = [[0, 0.7, 0], [0.3, 1.4, 0.45]]
/// # a periodic cell's sample repeated along y:
/// # sample = "stones.csv", copies = [[0, -0.7, 0], [0, 0, 0], [0, 0.7, 0]]
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Granular {
    /// Name (stones are called `NAME stone K` in messages).
    pub name: String,
    /// A `[[material]]` (density and contact elasticity).
    pub material: String,
    /// A stones file (CSV `stone,x,y,z,radius`), relative to the scene file.
    #[serde(default)]
    pub sample: Option<PathBuf>,
    /// The sample's stones placed once per translation (m), before `crop`: a sample deposited
    /// in a periodic cell, repeated by whole periods, fills a box several cells long with the
    /// cell's packing; default one copy where the file puts it.
    #[serde(default = "default_copies")]
    pub copies: Vec<[f64; 3]>,
    /// Keep only the sample's stones whose spheres all lie inside this box (m), up to
    /// `CROP_TOLERANCE` of a radius (a stone resting on a wall of the box stays).
    #[serde(default)]
    pub crop: Option<[[f64; 3]; 2]>,
    /// Generation: the box filled with stones on a loose lattice (m).
    #[serde(default)]
    pub region: Option<[[f64; 3]; 2]>,
    /// Generation: number of stones, at least 1.
    #[serde(default)]
    pub count: Option<usize>,
    /// Generation: the grading curve, (sieve size m, fraction passing) points.
    #[serde(default)]
    pub grading: Option<Vec<[f64; 2]>>,
    /// Generation: whether `grading`'s fractions passing count stones (`"number"`, the
    /// default) or mass (`"mass"`, as sieve analyses and ballast standards give them).
    #[serde(default)]
    pub grading_basis: GradingBasisName,
    /// Generation: smallest and largest number of spheres per stone; default [3, 5].
    #[serde(default = "default_spheres_per_stone")]
    pub spheres_per_stone: [usize; 2],
    /// Generation: the stones' shape, `"elongated"` (default: a row of spheres along the long
    /// axis) or `"angular"` (a core sphere with corner spheres, like crushed ballast).
    #[serde(default)]
    pub shape: ClumpShapeName,
    /// Generation: seed; default 1.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Initial velocity of every stone (m/s); default zero.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Initial angular velocity of every stone about its centre of mass (rad/s, world axes);
    /// default zero.
    #[serde(default)]
    pub angular_velocity: [f64; 3],
    /// Initial velocity of the generated (`region`) stones instead of `velocity` (m/s): grains
    /// poured onto a sample at rest; default `velocity`.
    #[serde(default)]
    pub region_velocity: Option<[f64; 3]>,
    /// Initial angular velocity of the generated stones instead of `angular_velocity`
    /// (rad/s); default `angular_velocity`.
    #[serde(default)]
    pub region_angular_velocity: Option<[f64; 3]>,
}

impl Granular {
    /// The initial velocity and angular velocity of a stone, generated or from the sample.
    pub fn motion(&self, generated: bool) -> ([f64; 3], [f64; 3]) {
        match generated {
            true => (
                self.region_velocity.unwrap_or(self.velocity),
                self.region_angular_velocity
                    .unwrap_or(self.angular_velocity),
            ),
            false => (self.velocity, self.angular_velocity),
        }
    }
}

fn default_copies() -> Vec<[f64; 3]> {
    vec![[0.0; 3]]
}

fn default_spheres_per_stone() -> [usize; 2] {
    [3, 5]
}

fn default_seed() -> u64 {
    1
}

/// `[granular] grading_basis`: what the grading's fractions passing count
/// (`qdem_contact::clump_sample::GradingBasis`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GradingBasisName {
    /// The fraction of stones finer than a size: the curve is sampled by number.
    #[default]
    Number,
    /// The fraction of mass finer than a size.
    Mass,
}

/// `[granular] shape`: how a generated stone's spheres are arranged
/// (`qdem_contact::clump_shape::ClumpShape`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ClumpShapeName {
    /// A row of spheres along the long axis: an elongated, flaky stone.
    #[default]
    Elongated,
    /// A core sphere with corner spheres out towards an ellipsoid: a stone with corners.
    Angular,
}

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

/// `[bonded]`: a 2D beam-bonded particle body (paper 001) filling a rectangle of the x–y
/// plane, with its supports and a uniform load on its top row. A scene with `[bonded]` has no
/// `[[body]]` and is integrated with `integrator = "newmark"`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bonded {
    /// Body name (for probes and messages).
    pub name: String,
    /// A `[[material]]`: density, young, poisson of the continuum represented.
    pub material: String,
    /// Lower-left corner (m); default the origin.
    #[serde(default)]
    pub origin: [f64; 2],
    /// Width and height (m).
    pub size: [f64; 2],
    /// Out-of-plane thickness (m); default 1.
    #[serde(default = "one")]
    pub thickness: f64,
    /// Particle spacing (m).
    pub element_size: f64,
    /// `"regular"` (default) or `"random"`.
    #[serde(default)]
    pub packing: PackingName,
    /// Largest random offset in spacings for `packing = "random"`, in [0, 0.25); default 0.1.
    #[serde(default = "default_jitter")]
    pub jitter: f64,
    /// Seed of the random packing.
    #[serde(default)]
    pub packing_seed: u64,
    /// Mean bond strength (Pa).
    pub strength_mean: f64,
    /// Standard deviation of the bond strength (Pa); default 0.
    #[serde(default)]
    pub strength_std: f64,
    /// Seed of the strengths.
    #[serde(default)]
    pub strength_seed: u64,
    /// Bond damping ratio ξ_b (Eq. 8), in [0, 1); default 0.
    #[serde(default)]
    pub damping_ratio: f64,
    /// Step as a multiple of the paper's ∆t_crit (Eq. 28): 0.2 for the paper's explicit runs,
    /// η for implicit ones. Optional; replaces `[run] dt`.
    #[serde(default)]
    pub critical_fraction: Option<f64>,
    /// Retake steps that overshoot a bond's strength or a contact's opening (Eqs. 29–30);
    /// default true.
    #[serde(default = "yes")]
    pub adaptive: bool,
    /// Implicit runs: how a step is solved after bonds broke or contacts changed (issue 26);
    /// default `"refactorize"`.
    #[serde(default)]
    pub event_solve: EventSolveName,
    /// Relative overshoot ε tolerated before a retake; default 0.05.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Unbonded contacts: tangential over normal stiffness; default 0.2.
    #[serde(default = "default_shear_ratio")]
    pub contact_shear_ratio: f64,
    /// Unbonded contacts: Coulomb friction; default 0.5.
    #[serde(default = "default_bbm_friction")]
    pub friction: f64,
    /// Unbonded contacts: damping ratio ξ_u (Eq. 6), in [0, 1); default 0.
    #[serde(default)]
    pub contact_damping_ratio: f64,
    /// `"simple"` (default), `"pinned"` or `"none"`.
    #[serde(default)]
    pub supports: Supports,
    /// Uniform downward line load on the top row (N/m); default 0.
    #[serde(default)]
    pub top_load: f64,
    /// Time over which `top_load` rises linearly from zero (s); default 0: applied at once.
    #[serde(default)]
    pub load_ramp: f64,
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

/// Top-level keys that are arrays of tables (`[[name]]`), for messages.
pub(crate) const ARRAY_TABLES: &[&str] = &[
    "material", "body", "fix", "load", "probe", "section", "wall",
];
