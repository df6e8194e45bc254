//! `[[fix]]` and `[[load]]`: the raw forms as written, and the validated fixes and loads
//! with their selection and time factor.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

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
    /// Fixed directions as a mask of the frame's three directions (x, y, z on the axes;
    /// r, θ, z in a cylindrical frame; e₁, e₂, e₃ of a basis), from `dofs` (default all three).
    pub dofs: [bool; 3],
    /// Also hold the rotation of the (rigid) body: `rotation = true`, e.g. a sleeper guided
    /// vertically by `dofs = "xy"`; its centre is then held in `dofs`. Default false: the
    /// body is held at the selected members (`qdem_core::step::rigid_constraints`).
    pub rotation: bool,
    /// The frame `dofs` names directions of: the axes unless `frame` is given.
    #[serde(skip_serializing_if = "FixFrame::is_axes")]
    pub frame: FixFrame,
}

/// The frame a `[[fix]]` holds its directions in.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum FixFrame {
    /// x, y, z (no `frame` key).
    #[default]
    Axes,
    /// `frame = [[e1], [e2], [e3]]`: one orthonormal basis for every node; `dofs` of "123".
    Basis([[f64; 3]; 3]),
    /// `frame = "cylindrical"` with `axis_origin` and `axis`: at each node its radial (r),
    /// tangential (θ, `t`) and axial (z) directions; `dofs` of "rtz".
    Cylindrical {
        /// A point of the axis (m).
        origin: [f64; 3],
        /// The axis's direction (a unit vector).
        axis: [f64; 3],
    },
}

impl FixFrame {
    /// Whether this is the axes' frame.
    pub fn is_axes(&self) -> bool {
        *self == FixFrame::Axes
    }

    /// The letters that name the frame's three directions in `dofs`.
    pub fn letters(&self) -> [char; 3] {
        match self {
            FixFrame::Axes => ['x', 'y', 'z'],
            FixFrame::Basis(_) => ['1', '2', '3'],
            FixFrame::Cylindrical { .. } => ['r', 't', 'z'],
        }
    }
}

/// `frame = …` as written: a name or a basis.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(
    untagged,
    expecting = "\"cylindrical\" or a basis [[x, y, z], [x, y, z], [x, y, z]] (e1, e2, e3)"
)]
pub(crate) enum RawFrame {
    /// `frame = "cylindrical"`.
    Name(FrameName),
    /// `frame = [[e1], [e2], [e3]]`.
    Basis([[f64; 3]; 3]),
}

/// The frames `frame` names.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub(crate) enum FrameName {
    /// r, θ, z about an axis.
    Cylindrical,
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

scene_table! {
    /// `[[fix]]` as written.
    #[derive(Debug, Clone, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub(crate) struct RawFix in "[[fix]]" {
        body: String => "string", required,
            "Name of the `[[body]]` (or `[ballast]`) whose particles are held.";
        #[serde(default)]
        group: Option<String> => "string", optional,
            "A gmsh physical group of the mesh: its nodes are held (or `box`).";
        #[serde(default)]
        bbox as "box": Option<[[f64; 3]; 2]> => "[[x, y, z], [x, y, z]]", optional,
            "Instead of `group`: the particles inside the closed box (lower and upper corner, m).";
        #[serde(default = "default_dofs")]
        dofs: String => "string", optional = "\"xyz\"",
            "The held directions, a subset of \"xyz\"; default \"xyz\". With `frame`, of the \
             frame's directions: \"rtz\" (radial, tangential, axial) in a cylindrical frame, \
             \"123\" of a basis (then required). `reactions.csv` gives the force the fix carries.";
        #[serde(default)]
        rotation: bool => "bool", optional = "false",
            "Also hold a rigid body's rotation, its centre then held in `dofs`; default false: \
             a fix on a rigid body's members holds the body at those points in `dofs`, free to \
             turn about them (held at one point it swings as a pendulum, along a line as a \
             hinge), and `reactions.csv` gives its reaction.";
        #[serde(default)]
        frame: Option<RawFrame> => "\"cylindrical\" or [[x, y, z], [x, y, z], [x, y, z]]", optional,
            "Hold `dofs` in a local frame of a deformable body: \"cylindrical\" (about `axis` \
             through `axis_origin`; at each node r, θ, z), or an orthonormal basis e₁, e₂, e₃ \
             (rows); e.g. a roller on a skewed face, the symmetry planes of a cylinder \
             (`dofs = \"t\"`). Its reactions are given in the frame. Not in a run over MPI ranks \
             (refused); a node on a cylindrical frame's axis is refused.";
        #[serde(default)]
        axis_origin: Option<[f64; 3]> => "[x, y, z]", optional,
            "With `frame = \"cylindrical\"`: a point of the axis, m; default the origin.";
        #[serde(default)]
        axis: Option<[f64; 3]> => "[x, y, z]", optional,
            "With `frame = \"cylindrical\"` (required there): the axis's direction (any length).";
    }
}

fn default_dofs() -> String {
    "xyz".to_owned()
}

scene_table! {
    /// `[[load]]` as written.
    #[derive(Debug, Clone, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub(crate) struct RawLoad in "[[load]]" {
        body: String => "string", required,
            "Name of the `[[body]]` loaded.";
        #[serde(default)]
        group: Option<String> => "string", optional,
            "A gmsh physical group: its nodes (for `total_force`) or the boundary triangles whose \
             three nodes it holds (for `pressure`, `traction`).";
        #[serde(default)]
        bbox as "box": Option<[[f64; 3]; 2]> => "[[x, y, z], [x, y, z]]", optional,
            "Instead of `group`: the particles inside the closed box, or the boundary triangles \
             inside it.";
        #[serde(default)]
        total_force: Option<[f64; 3]> => "[x, y, z]", optional,
            "Total force, N, shared equally by the selected particles; one of `total_force`, \
             `pressure`, `traction`.";
        #[serde(default)]
        pressure: Option<f64> => "number", optional,
            "Pressure, Pa, on the selected boundary faces along their inward normal (positive \
             pushes in), lumped to the nodes by area (a third of each triangle's to each of its \
             nodes).";
        #[serde(default)]
        traction: Option<[f64; 3]> => "[x, y, z]", optional,
            "Force per unit area, Pa, on the selected boundary faces in a fixed direction, lumped \
             like `pressure`.";
        #[serde(default)]
        ramp: Option<Vec<[f64; 2]>> => "[[t, factor], …]", optional,
            "Time factor: `[t, factor]` points, linear between, held outside; default a constant \
             1.";
        #[serde(default)]
        cyclic: Option<CyclicLoad> => "inline table", optional,
            "Time factor instead of `ramp`: `{ min, max, frequency, phase_deg, start }`, a \
             sinusoid between min and max.";
        #[serde(default)]
        series: Option<Series> => "inline table", optional,
            "Time factor instead of `ramp`: `{ file, column }`, a column of a CSV file (first \
             column the time).";
    }
}

scene_table! {
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
    pub struct Series in "[[load]] series" {
        file: PathBuf => "path", required,
            "The CSV file, relative to the scene file; a header row names the columns.";
        column: String => "string", required,
            "The column to read.";
    }
}

scene_table! {
    /// `cyclic = { min, max, frequency, phase_deg, start }` of a `[[load]]`: the factor on
    /// `total_force` runs between `min` and `max` at `frequency`, each cycle beginning at the
    /// minimum; `phase_deg` puts the load ahead (positive) of a zero-phase load that begins its
    /// first cycle at `start`. Before its first cycle the factor is `min`.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct CyclicLoad in "[[load]] cyclic" {
        min: f64 => "number", required,
            "Factor at the minimum.";
        max: f64 => "number", required,
            "Factor at the maximum.";
        frequency: f64 => "number", required,
            "Hz (> 0).";
        #[serde(default)]
        phase_deg: f64 => "number", optional = "0.0",
            "Phase lead in degrees; default 0.";
        #[serde(default)]
        start: f64 => "number", optional = "0.0",
            "Time the first cycle begins, s; default 0 (before it the factor is `min`).";
    }
}

impl CyclicLoad {
    /// The core's cycle.
    pub fn cycle(&self) -> qdem_core::loads::Cyclic {
        qdem_core::loads::Cyclic {
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
    pub fn time_function(
        &self,
    ) -> Result<qdem_core::loads::TimeFunction, qdem_core::error::CoreError> {
        if self.points.is_empty() {
            return Ok(qdem_core::loads::TimeFunction::constant(1.0));
        }
        qdem_core::loads::TimeFunction::new(self.points.iter().map(|p| (p[0], p[1])).collect())
    }
}
