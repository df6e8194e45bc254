//! The registry of every scene key: its table, type and default, and meaning, in one place,
//! rendered as README.md's key reference ([`markdown_table`], between [`README_BEGIN`] and
//! [`README_END`]).
//!
//! The registry cannot fall behind the schema: a test asks serde itself which keys each table
//! accepts (the "expected one of" list of an unknown key, so the list is the parser's own)
//! and fails naming every key the parser accepts that the registry lacks, and every
//! registered key the parser refuses; another fails when README.md's table differs from
//! [`markdown_table`]. After adding a key to the schema: add its entry to [`SCENE_KEYS`]
//! (in the table's order), then regenerate README.md's table with
//! `QDEM_WRITE_KEYS=1 cargo test -p qdem-io --lib scene::keys`.

/// One scene key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneKey {
    /// The table, as written in a scene (`[run]`, `[[load]]`), or an inline table of one
    /// (`[[load]] cyclic`).
    pub table: &'static str,
    /// The key.
    pub key: &'static str,
    /// Its type, then `required` or `optional`.
    pub kind: &'static str,
    /// What it means, with its unit and default.
    pub meaning: &'static str,
}

const fn key(
    table: &'static str,
    key: &'static str,
    kind: &'static str,
    meaning: &'static str,
) -> SceneKey {
    SceneKey {
        table,
        key,
        kind,
        meaning,
    }
}

/// The line before README.md's key table.
pub const README_BEGIN: &str =
    "<!-- scene keys: generated from qdem-io/src/scene/keys.rs; QDEM_WRITE_KEYS=1 cargo test -p qdem-io --lib scene::keys -->";
/// The line after README.md's key table.
pub const README_END: &str = "<!-- end of scene keys -->";

/// Every key a scene file may hold, table by table.
pub const SCENE_KEYS: &[SceneKey] = &[
    key(
        "[run]",
        "t_end",
        "number, required",
        "Simulated end time, s. Required, > 0.",
    ),
    key(
        "[run]",
        "dt",
        "number or \"auto\", optional",
        "Time step: `\"auto\"` (default) or a fixed number of seconds (a normal number: a subnormal one such as 1e-320 is refused).",
    ),
    key(
        "[run]",
        "integrator",
        "\"verlet\", \"newmark\" or \"static\", optional",
        "Time integrator; default `\"verlet\"`; `\"static\"`: a linear static solve at every `dt` of the load factor (default `probe_every`, else t_end / 100), once per distinct load level, writing the final state's VTU.",
    ),
    key(
        "[run]",
        "gravity",
        "[x, y, z], optional",
        "Gravitational acceleration, m/s²; default zero.",
    ),
    key(
        "[run]",
        "probe_every",
        "number, optional",
        "Simulated time between two rows of `probes.csv` (and the other CSV records), s (> 0); default t_end / 1000.",
    ),
    key(
        "[run]",
        "dt_safety",
        "number, optional",
        "Fraction of the stable time-step bound used when `dt = \"auto\"`, in (0, 1]; default 0.9.",
    ),
    key(
        "[run]",
        "beta",
        "number, optional",
        "Newmark β (paper 001 Eq. 13), for `integrator = \"newmark\"` only (refused with another integrator, where it would do nothing); default ¼ (average acceleration, implicit). β = 0 with γ = ½ is explicit central difference.",
    ),
    key(
        "[run]",
        "gamma",
        "number, optional",
        "Newmark γ (paper 001 Eq. 14), for `integrator = \"newmark\"` only (refused with another integrator); default ½.",
    ),
    key(
        "[run]",
        "start_from",
        "path, optional",
        "Start from the state in this checkpoint (written by another scene with the same bodies, e.g. a deposition run), relative to the scene file: positions, velocities and reference positions are taken from it, time restarts at 0, and the tangential contact springs are carried between the same spheres and walls (a spring whose sphere or wall this scene lacks is dropped and counted).",
    ),
    key(
        "[[material]]",
        "name",
        "string, required",
        "Unique name that `[[body]] material` refers to.",
    ),
    key(
        "[[material]]",
        "density",
        "number, required",
        "Mass density, kg/m³ (> 0).",
    ),
    key(
        "[[material]]",
        "young",
        "number, required",
        "Young's modulus, Pa (> 0).",
    ),
    key(
        "[[material]]",
        "poisson",
        "number, required",
        "Poisson's ratio ν, in (−1, 0.5).",
    ),
    key(
        "[[material]]",
        "shear_viscosity",
        "number, optional",
        "Shear viscosity μ_D, Pa·s (≥ 0); default 0.",
    ),
    key(
        "[[material]]",
        "bulk_viscosity",
        "number, optional",
        "Bulk viscosity λ_D + 2/3 μ_D, Pa·s (≥ 0); default 0.",
    ),
    key(
        "[[material]]",
        "formulation",
        "string, optional",
        "`\"standard\"` (default) or `\"averaged-pressure\"`: the average nodal pressure tetrahedron (Bonet & Burton 1998) that does not lock as ν → 0.5; refused under MPI.",
    ),
    key(
        "[[body]]",
        "name",
        "string, required",
        "Unique name that fixes, loads and probes refer to.",
    ),
    key(
        "[[body]]",
        "mesh",
        "path, required",
        "The gmsh mesh file (MSH 2.2 or 4.1, linear tetrahedra), relative to the scene file.",
    ),
    key(
        "[[body]]",
        "material",
        "string, required",
        "Name of a `[[material]]`.",
    ),
    key(
        "[[body]]",
        "reorder",
        "bool, optional",
        "Reorder nodes for memory locality after import; default `true`.",
    ),
    key(
        "[[body]]",
        "merge_nodes",
        "bool, optional",
        "Merge the mesh's coincident nodes (nodes at one place, within 1e-9 of the mesh's size, that its tetrahedra do not share, as separately meshed volumes leave them) so that the tetrahedra on either side connect; default `false`: they are reported in a warning and the body stays in pieces there.",
    ),
    key(
        "[[body]]",
        "contact_radius",
        "number, optional",
        "Radius (m) of the contact spheres put at the body's surface vertices (paper 000 §4); `None` (the default): the body touches nothing.",
    ),
    key(
        "[[body]]",
        "rigid",
        "bool, optional",
        "Integrate the body as a rigid body (6 degrees of freedom, mass and inertia from its tetrahedra) instead of a deformable one; default `false`.",
    ),
    key(
        "[[body]]",
        "translate",
        "[x, y, z], optional",
        "Translation applied to the mesh after the rotation (m); default zero.",
    ),
    key(
        "[[body]]",
        "rotate_deg",
        "[x, y, z], optional",
        "Rotation of the mesh about its nodes' centroid, in degrees about x, then y, then z (fixed axes); default zero.",
    ),
    key(
        "[[body]]",
        "velocity",
        "[x, y, z], optional",
        "Initial velocity of every particle of the body (m/s); default zero.",
    ),
    key(
        "[[body]]",
        "angular_velocity",
        "[x, y, z], optional",
        "Initial angular velocity of the body about its centre of mass (rad/s, world axes): a rigid body's ω; a deformable body's particles get v + ω × (x − x_c) in addition to `velocity`. Default zero.",
    ),
    key(
        "[[body]]",
        "rest_on",
        "string, optional",
        "Name of the `[granular]` sample to lay the body on: after `translate` it is lowered along −z until its contact spheres touch the stones beneath (`rest_on.rs`); default none (the body stays where `translate` puts it).",
    ),
    key(
        "[[body]]",
        "pose_from",
        "path, optional",
        "A `poses.csv` written by an earlier run (relative to the scene file): a rigid body is placed where that run left its body of the same name (`pose_from.rs`); default none.",
    ),
    key(
        "[[body]]",
        "pose_body",
        "string, optional",
        "With `pose_from`: take the pose of this body of the poses file instead of the body of the same name (the sleepers of a three-sleeper box placed from the one sleeper of a periodic cell); default the body's own name.",
    ),
    key(
        "[[body]]",
        "pose_shift",
        "[x, y, z], optional",
        "With `pose_from`: added to the pose's centre of mass (m), e.g. one period along a periodic axis; default zero.",
    ),
    key(
        "[[fix]]",
        "body",
        "string, required",
        "Name of the `[[body]]` (or `[ballast]`) whose particles are held.",
    ),
    key(
        "[[fix]]",
        "group",
        "string, optional",
        "A gmsh physical group of the mesh: its nodes are held (or `box`).",
    ),
    key(
        "[[fix]]",
        "box",
        "[[x, y, z], [x, y, z]], optional",
        "Instead of `group`: the particles inside the closed box (lower and upper corner, m).",
    ),
    key(
        "[[fix]]",
        "dofs",
        "string, optional",
        "The held directions, a subset of \"xyz\"; default \"xyz\". `reactions.csv` gives the force the fix carries.",
    ),
    key(
        "[[fix]]",
        "rotation",
        "bool, optional",
        "Also hold a rigid body's rotation; default false.",
    ),
    key(
        "[[load]]",
        "body",
        "string, required",
        "Name of the `[[body]]` loaded.",
    ),
    key(
        "[[load]]",
        "group",
        "string, optional",
        "A gmsh physical group: its nodes (for `total_force`) or the boundary triangles whose three nodes it holds (for `pressure`, `traction`).",
    ),
    key(
        "[[load]]",
        "box",
        "[[x, y, z], [x, y, z]], optional",
        "Instead of `group`: the particles inside the closed box, or the boundary triangles inside it.",
    ),
    key(
        "[[load]]",
        "total_force",
        "[x, y, z], optional",
        "Total force, N, shared equally by the selected particles; one of `total_force`, `pressure`, `traction`.",
    ),
    key(
        "[[load]]",
        "pressure",
        "number, optional",
        "Pressure, Pa, on the selected boundary faces along their inward normal (positive pushes in), lumped to the nodes by area (a third of each triangle's to each of its nodes).",
    ),
    key(
        "[[load]]",
        "traction",
        "[x, y, z], optional",
        "Force per unit area, Pa, on the selected boundary faces in a fixed direction, lumped like `pressure`.",
    ),
    key(
        "[[load]]",
        "ramp",
        "[[t, factor], …], optional",
        "Time factor: `[t, factor]` points, linear between, held outside; default a constant 1.",
    ),
    key(
        "[[load]]",
        "cyclic",
        "inline table, optional",
        "Time factor instead of `ramp`: `{ min, max, frequency, phase_deg, start }`, a sinusoid between min and max.",
    ),
    key(
        "[[load]]",
        "series",
        "inline table, optional",
        "Time factor instead of `ramp`: `{ file, column }`, a column of a CSV file (first column the time).",
    ),
    key(
        "[[load]] cyclic",
        "min",
        "number, required",
        "Factor at the minimum.",
    ),
    key(
        "[[load]] cyclic",
        "max",
        "number, required",
        "Factor at the maximum.",
    ),
    key(
        "[[load]] cyclic",
        "frequency",
        "number, required",
        "Hz (> 0).",
    ),
    key(
        "[[load]] cyclic",
        "phase_deg",
        "number, optional",
        "Phase lead in degrees; default 0.",
    ),
    key(
        "[[load]] cyclic",
        "start",
        "number, optional",
        "Time the first cycle begins, s; default 0 (before it the factor is `min`).",
    ),
    key(
        "[[load]] series",
        "file",
        "path, required",
        "The CSV file, relative to the scene file; a header row names the columns.",
    ),
    key(
        "[[load]] series",
        "column",
        "string, required",
        "The column to read.",
    ),
    key(
        "[[probe]]",
        "name",
        "string, required",
        "Unique name (the CSV column prefix).",
    ),
    key(
        "[[probe]]",
        "body",
        "string, required",
        "Name of the `[[body]]`, `[ballast]`, `[bonded]` body or `[granular]` sample.",
    ),
    key(
        "[[probe]]",
        "point",
        "[x, y, z], optional",
        "The particle of the body nearest to this point (in the reference configuration), or the stone whose centre of mass is nearest to it, is sampled.",
    ),
    key(
        "[[probe]]",
        "stone",
        "integer, optional",
        "`[granular]` only: the stone sampled, counted from 1 in the sample's order (the `stone` of `stones.csv`, `NAME stone K` in messages).",
    ),
    key(
        "[[probe]]",
        "box",
        "[[x, y, z], [x, y, z]], optional",
        "`[granular]` only: a box (lower and upper corner, m): the stones whose centre of mass lies inside are averaged (columns `vx, vy, vz, ke, count`).",
    ),
    key(
        "[[section]]",
        "name",
        "string, required",
        "Unique name (the CSV column).",
    ),
    key(
        "[[section]]",
        "axis",
        "string, required",
        "The axis the plane is normal to: \"x\", \"y\" or \"z\".",
    ),
    key(
        "[[section]]",
        "at",
        "number, required",
        "The plane's coordinate along `axis` (m).",
    ),
    key(
        "[[section]]",
        "area",
        "number, optional",
        "The section's area, m²: `sections.csv` also gives `NAME.stress`, the normal stress through the plane (Pa, tension positive).",
    ),
    key(
        "[[measure]]",
        "name",
        "string, required",
        "Unique name: the files `measure_NAME.csv`, `measure_NAME.svg`, `measure_NAME_energy.svg`.",
    ),
    key(
        "[[measure]]",
        "box",
        "[[x, y, z], [x, y, z]], optional",
        "The region as a box (lower and upper corner, m); or `center` and `radius`. Needs `[granular]` and `[contact]`.",
    ),
    key(
        "[[measure]]",
        "center",
        "[x, y, z], optional",
        "Instead of `box`: the centre of a spherical region (m), with `radius`.",
    ),
    key(
        "[[measure]]",
        "radius",
        "number, optional",
        "With `center`: the spherical region's radius (m).",
    ),
    key(
        "[[measure]]",
        "every",
        "number, optional",
        "Simulated time between two rows of `measure_NAME.csv`, s; default `probe_every`.",
    ),
    key(
        "[contact]",
        "law",
        "\"linear\" or \"hertz-mindlin\", optional",
        "The law; default linear.",
    ),
    key(
        "[contact]",
        "normal_stiffness",
        "number, optional",
        "Normal spring constant k_n (N/m), required by the linear law.",
    ),
    key(
        "[contact]",
        "tangential_stiffness",
        "number, optional",
        "Tangential spring constant k_t (N/m), required by the linear law.",
    ),
    key(
        "[contact]",
        "friction",
        "number, optional",
        "Coulomb friction coefficient between bodies (and walls that give none); default 0.",
    ),
    key(
        "[contact]",
        "damping_ratio",
        "number, optional",
        "Damping ratio ζ of the contact dashpots, in [0, 1); default 0 (paper 000: the viscosity is in the bulk).",
    ),
    key(
        "[contact]",
        "restitution",
        "number, optional",
        "Coefficient of restitution e of a head-on impact, in (0, 1], instead of `damping_ratio` (refused beside a non-zero one): ζ = −ln e / √(ln² e + π²).",
    ),
    key(
        "[contact]",
        "local_damping",
        "number, optional",
        "PFC's local non-viscous damping fraction, in [0, 1) (paper 003: 0.7 for quasi-static packing); default 0.",
    ),
    key(
        "[contact]",
        "skin",
        "number, optional",
        "Skin distance of the neighbour lists (m); default a quarter of the smallest contact radius.",
    ),
    key(
        "[contact]",
        "overlap_tolerance",
        "number, optional",
        "Largest overlap allowed at the start, as a fraction of the reduced radius; default 0.05.",
    ),
    key(
        "[[wall]]",
        "point",
        "[x, y, z], optional",
        "A point of the plane (m).",
    ),
    key(
        "[[wall]]",
        "normal",
        "[x, y, z], optional",
        "The plane's normal, pointing to the side where bodies are (any length).",
    ),
    key(
        "[[wall]]",
        "mesh",
        "path, optional",
        "A tetrahedral gmsh mesh whose boundary surface is the wall, relative to the scene file.",
    ),
    key(
        "[[wall]]",
        "friction",
        "number, optional",
        "Friction coefficient against bodies; default `[contact] friction`.",
    ),
    key(
        "[[wall]]",
        "velocity",
        "[x, y, z], optional",
        "Constant velocity of the wall (m/s); default zero.",
    ),
    key(
        "[[wall]]",
        "servo",
        "inline table, optional",
        "Stress control of a plane wall: `{ stress, area, gain, max_velocity }`; after each force evaluation its speed towards the bodies is clamp(G (σ_target − σ), ±v_max), σ the spheres' normal force on it over `area`. Not with `velocity`, a mesh, or MPI ranks.",
    ),
    key(
        "[[wall]] servo",
        "stress",
        "number, required",
        "Target compressive normal stress σ_target (Pa).",
    ),
    key(
        "[[wall]] servo",
        "area",
        "number, required",
        "The area A the wall's normal force is divided by (m², > 0).",
    ),
    key(
        "[[wall]] servo",
        "gain",
        "number, optional",
        "Gain G (m/(s·Pa), > 0); default 0.5 A / Σ (k_n Δt + c_n) over the wall's touching contacts, renewed each step (PFC's servo with the normal dashpots c_n).",
    ),
    key(
        "[[wall]] servo",
        "max_velocity",
        "number, required",
        "Largest speed v_max (m/s, > 0): the servo's clamp and the wall's speed bound for the neighbour lists.",
    ),
    key(
        "[periodic]",
        "axes",
        "string, required",
        "The periodic axes, e.g. `\"y\"` or `\"xy\"`.",
    ),
    key(
        "[periodic]",
        "length",
        "[number, …], optional",
        "One period per listed axis (m), in the order of `axes`.",
    ),
    key(
        "[periodic]",
        "origin",
        "[x, y, z], optional",
        "The lower corner of the cell (m); default the origin.",
    ),
    key(
        "[periodic]",
        "box",
        "[[x, y, z], [x, y, z]], optional",
        "The cell as a box (lower and upper corner, m): origin and periods at once.",
    ),
    key(
        "[periodic]",
        "time_delay",
        "table, optional",
        "A time-delayed boundary.",
    ),
    key(
        "[periodic.time_delay]",
        "body",
        "string, required",
        "The body (a sleeper) whose `cyclic` [[load]] sets the phase Φ.",
    ),
    key(
        "[periodic.time_delay]",
        "axis",
        "string, optional",
        "The delayed axis; default the only periodic axis.",
    ),
    key(
        "[periodic.time_delay]",
        "lag_deg",
        "number, optional",
        "Phase lag δ of the neighbour cells (degrees); default 90 (paper 003 Eqs. 4–5).",
    ),
    key(
        "[periodic.time_delay]",
        "sleeper_spacing",
        "number, optional",
        "With `speed`: the lag δ = 360° f s / v of sleepers `sleeper_spacing` apart (m).",
    ),
    key(
        "[periodic.time_delay]",
        "speed",
        "number, optional",
        "With `sleeper_spacing`: the speed of the travelling load (m/s).",
    ),
    key(
        "[periodic.time_delay]",
        "shared_faces",
        "bool, optional",
        "Shared faces (qdem's variant, not paper 003's Eqs. 6–7): both spheres of a pair through the boundary scaled alike, by the mean of the two faces' predicted forces, so the pair's action equals its reaction; default false.",
    ),
    key(
        "[granular]",
        "name",
        "string, required",
        "Name (stones are called `NAME stone K` in messages).",
    ),
    key(
        "[granular]",
        "material",
        "string, required",
        "A `[[material]]` (density and contact elasticity).",
    ),
    key(
        "[granular]",
        "sample",
        "path, optional",
        "A stones file (CSV `stone,x,y,z,radius`), relative to the scene file.",
    ),
    key(
        "[granular]",
        "copies",
        "[[x, y, z], …], optional",
        "The sample's stones placed once per translation (m), before `crop`: a sample deposited in a periodic cell, repeated by whole periods, fills a box several cells long with the cell's packing; default one copy where the file puts it.",
    ),
    key(
        "[granular]",
        "crop",
        "[[x, y, z], [x, y, z]], optional",
        "Keep only the sample's stones whose spheres all lie inside this box (m), up to `CROP_TOLERANCE` of a radius (a stone resting on a wall of the box stays).",
    ),
    key(
        "[granular]",
        "region",
        "[[x, y, z], [x, y, z]], optional",
        "Generation: the box filled with stones on a loose lattice (m).",
    ),
    key(
        "[granular]",
        "count",
        "integer, optional",
        "Generation: number of stones, at least 1.",
    ),
    key(
        "[granular]",
        "grading",
        "[[size, passing], …], optional",
        "Generation: the grading curve, (sieve size m, fraction passing) points.",
    ),
    key(
        "[granular]",
        "grading_basis",
        "\"number\" or \"mass\", optional",
        "Generation: what `grading`'s fractions passing count: `\"number\"` (default) the fraction of stones finer than a size (the sample is coarser by mass than the curve), `\"mass\"` the fraction of mass, as sieve analyses and ballast standards give it (within a segment the mass is spread uniformly in size, a stone weighing ∝ d³).",
    ),
    key(
        "[granular]",
        "spheres_per_stone",
        "[integer, integer], optional",
        "Generation: smallest and largest number of spheres per stone; default [3, 5].",
    ),
    key(
        "[granular]",
        "shape",
        "\"elongated\" or \"angular\", optional",
        "Generation: the stones' shape: `\"elongated\"` (default) a row of spheres along a long axis, a flaky stone; `\"angular\"` a core sphere with the other spheres as corners out towards an ellipsoid, like crushed ballast. Both stay within 0.65 of the sieve size of the stone's origin; one sphere is a plain sphere of radius d/2.",
    ),
    key(
        "[granular]",
        "seed",
        "integer, optional",
        "Generation: seed; default 1.",
    ),
    key(
        "[granular]",
        "velocity",
        "[x, y, z], optional",
        "Initial velocity of every stone (m/s); default zero.",
    ),
    key(
        "[granular]",
        "angular_velocity",
        "[x, y, z], optional",
        "Initial angular velocity of every stone about its centre of mass (rad/s, world axes); default zero.",
    ),
    key(
        "[granular]",
        "region_velocity",
        "[x, y, z], optional",
        "Initial velocity of the generated (`region`) stones instead of `velocity` (m/s): grains poured onto a sample at rest; default `velocity`.",
    ),
    key(
        "[granular]",
        "region_angular_velocity",
        "[x, y, z], optional",
        "Initial angular velocity of the generated stones instead of `angular_velocity` (rad/s); default `angular_velocity`.",
    ),
    key(
        "[ballast]",
        "name",
        "string, required",
        "Name of the ballast body (stones are `NAME stone K` in messages).",
    ),
    key(
        "[ballast]",
        "material",
        "string, required",
        "A `[[material]]`.",
    ),
    key(
        "[ballast]",
        "meshes",
        "[path, …], required",
        "Stone shapes: tetrahedral gmsh meshes, relative to the scene file.",
    ),
    key(
        "[ballast]",
        "contact_radius",
        "number, required",
        "Radius of the contact spheres at the stones' surface vertices, m (after scaling).",
    ),
    key(
        "[ballast]",
        "count",
        "integer, required",
        "Number of stones.",
    ),
    key(
        "[ballast]",
        "region",
        "[[x, y, z], [x, y, z]], required",
        "The box filled with stones, bottom layer first (m).",
    ),
    key(
        "[ballast]",
        "exclude",
        "[[x, y, z], [x, y, z]], optional",
        "A box no stone may reach into (m).",
    ),
    key(
        "[ballast]",
        "grading",
        "[[size, passing], …], optional",
        "Grading curve, (sieve size m, fraction passing) points; a stone's sieve size is the middle extent of its bounding box. Without one the meshes keep their size.",
    ),
    key(
        "[ballast]",
        "seed",
        "integer, optional",
        "Seed of the shapes, sizes, turns and lattice jitter; default 1.",
    ),
    key(
        "[ballast]",
        "velocity",
        "[x, y, z], optional",
        "Initial velocity of every stone (m/s), e.g. downward to shorten the fall; default 0.",
    ),
    key(
        "[ballast]",
        "angular_velocity",
        "[x, y, z], optional",
        "Initial angular velocity of every stone about its own centre of mass (rad/s, world axes): its particles get v + ω × (x − x_c); default 0.",
    ),
    key(
        "[ballast]",
        "rigid",
        "bool, optional",
        "Each stone a rigid body of its contact spheres (mass, centre and inertia from its tetrahedra) instead of a deformable one; default `false`. A scene that `start_from`s a checkpoint may change it: stones become deformable at their pose, unstressed, or rigid at their centre of mass and best-fit rotation.",
    ),
    key(
        "[bonded]",
        "name",
        "string, required",
        "Body name (for probes and messages).",
    ),
    key(
        "[bonded]",
        "material",
        "string, required",
        "A `[[material]]`: density, young, poisson of the continuum represented.",
    ),
    key(
        "[bonded]",
        "origin",
        "[a, b], optional",
        "Lower-left corner (m); default the origin.",
    ),
    key(
        "[bonded]",
        "size",
        "[a, b], required",
        "Width and height (m).",
    ),
    key(
        "[bonded]",
        "thickness",
        "number, optional",
        "Out-of-plane thickness (m); default 1.",
    ),
    key(
        "[bonded]",
        "element_size",
        "number, required",
        "Particle spacing (m).",
    ),
    key(
        "[bonded]",
        "packing",
        "\"regular\" or \"random\", optional",
        "`\"regular\"` (default) or `\"random\"`.",
    ),
    key(
        "[bonded]",
        "jitter",
        "number, optional",
        "Largest random offset in spacings for `packing = \"random\"`, in [0, 0.25); default 0.1.",
    ),
    key(
        "[bonded]",
        "packing_seed",
        "integer, optional",
        "Seed of the random packing.",
    ),
    key(
        "[bonded]",
        "strength_mean",
        "number, required",
        "Mean bond strength (Pa).",
    ),
    key(
        "[bonded]",
        "strength_std",
        "number, optional",
        "Standard deviation of the bond strength (Pa); default 0.",
    ),
    key(
        "[bonded]",
        "strength_seed",
        "integer, optional",
        "Seed of the strengths.",
    ),
    key(
        "[bonded]",
        "damping_ratio",
        "number, optional",
        "Bond damping ratio ξ_b (Eq. 8), in [0, 1); default 0.",
    ),
    key(
        "[bonded]",
        "critical_fraction",
        "number, optional",
        "Step as a multiple of the paper's ∆t_crit (Eq. 28): 0.2 for the paper's explicit runs, η for implicit ones. Optional; replaces `[run] dt`.",
    ),
    key(
        "[bonded]",
        "adaptive",
        "bool, optional",
        "Retake steps that overshoot a bond's strength or a contact's opening (Eqs. 29–30); default true.",
    ),
    key(
        "[bonded]",
        "event_solve",
        "\"refactorize\" or \"preconditioned\", optional",
        "Implicit runs: how a step is solved after bonds broke or contacts changed (issue 26); default `\"refactorize\"`.",
    ),
    key(
        "[bonded]",
        "tolerance",
        "number, optional",
        "Relative overshoot ε tolerated before a retake; default 0.05.",
    ),
    key(
        "[bonded]",
        "contact_shear_ratio",
        "number, optional",
        "Unbonded contacts: tangential over normal stiffness; default 0.2.",
    ),
    key(
        "[bonded]",
        "friction",
        "number, optional",
        "Unbonded contacts: Coulomb friction; default 0.5.",
    ),
    key(
        "[bonded]",
        "contact_damping_ratio",
        "number, optional",
        "Unbonded contacts: damping ratio ξ_u (Eq. 6), in [0, 1); default 0.",
    ),
    key(
        "[bonded]",
        "supports",
        "\"simple\", \"pinned\" or \"none\", optional",
        "`\"simple\"` (default), `\"pinned\"` or `\"none\"`.",
    ),
    key(
        "[bonded]",
        "top_load",
        "number, optional",
        "Uniform downward line load on the top row (N/m); default 0.",
    ),
    key(
        "[bonded]",
        "load_ramp",
        "number, optional",
        "Time over which `top_load` rises linearly from zero (s); default 0: applied at once.",
    ),
    key(
        "[output]",
        "dir",
        "path, optional",
        "Output directory as written (default `\"out\"`); the command line's `--out` overrides it.",
    ),
    key(
        "[output]",
        "vtu_every",
        "number, optional",
        "Simulated time between VTU snapshots, s; 0 (the default) writes none, except a static run's final state.",
    ),
    key(
        "[output]",
        "checkpoint_every",
        "number, optional",
        "Simulated time between checkpoints (`checkpoint.qdc` in the output directory, which `qdem run --resume` continues from), s; 0 (the default) writes one only when the run is interrupted (Ctrl-C, SIGTERM) or becomes unstable.",
    ),
    key(
        "[output]",
        "node_reactions",
        "bool, optional",
        "Whether to write `node_reactions.csv`: every `probe_every`, the force each `[[fix]]` of a deformable body carries at each of its particles, with the particle's gmsh node id and reference position; default false.",
    ),
];

/// The registry as a Markdown table: `| table | key | type | meaning |`, one row per key.
///
/// ```
/// let table = qdem_io::scene::keys::markdown_table();
/// assert!(table.contains("| `[run]` | `t_end` | number, required |"));
/// ```
pub fn markdown_table() -> String {
    let mut out = String::from("| table | key | type | meaning |\n| --- | --- | --- | --- |\n");
    for k in SCENE_KEYS {
        out.push_str(&format!(
            "| `{}` | `{}` | {} | {} |\n",
            k.table,
            k.key,
            k.kind,
            k.meaning.replace('|', "\\|")
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::schema::RawScene;
    use std::collections::BTreeSet;
    use std::path::Path;

    /// A scene text that puts the unknown key `zz_unknown` into `table`.
    fn probe_text(table: &str) -> String {
        match table.split_once(' ') {
            Some((outer, inline)) => format!("{outer}\n{inline} = {{ zz_unknown = 1 }}\n"),
            None => format!("{table}\nzz_unknown = 1\n"),
        }
    }

    /// The keys serde accepts in the table where `text` puts `zz_unknown`: the list of its
    /// "unknown field" error.
    fn accepted(text: &str) -> BTreeSet<String> {
        let error = toml::from_str::<RawScene>(text)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        let list = error
            .split_once("unknown field `zz_unknown`, expected ")
            .unwrap_or_else(|| panic!("no unknown-field error for {text:?}: {error}"))
            .1;
        let list = list.lines().next().unwrap_or("");
        list.split('`')
            .skip(1)
            .step_by(2)
            .map(str::to_string)
            .collect()
    }

    const HOW: &str = "add the key to SCENE_KEYS in qdem-io/src/scene/keys.rs (or remove it), \
                       then regenerate README.md's table: QDEM_WRITE_KEYS=1 cargo test -p \
                       qdem-io --lib scene::keys";

    /// Every key the parser accepts is registered, and every registered key is accepted;
    /// every top-level table the parser accepts has registered keys.
    #[test]
    fn registry_matches_the_parser() {
        let tables: BTreeSet<&str> = SCENE_KEYS.iter().map(|k| k.table).collect();
        let mut missing = Vec::new();
        let mut stale = Vec::new();
        for table in &tables {
            let parser = accepted(&probe_text(table));
            let registry: BTreeSet<String> = SCENE_KEYS
                .iter()
                .filter(|k| k.table == *table)
                .map(|k| k.key.to_string())
                .collect();
            missing.extend(parser.difference(&registry).map(|k| format!("{table} {k}")));
            stale.extend(registry.difference(&parser).map(|k| format!("{table} {k}")));
        }
        for top in accepted("zz_unknown = 1\n") {
            let named = |t: &&str| {
                let name = t.trim_start_matches('[').split([']', '.', ' ']).next();
                name == Some(top.as_str())
            };
            if !tables.iter().any(named) {
                missing.push(format!("the table [{top}] (every key of it)"));
            }
        }
        assert!(
            missing.is_empty() && stale.is_empty(),
            "the scene key registry is out of date:\n  accepted by the parser but not \
             registered: {missing:?}\n  registered but refused by the parser: {stale:?}\n\
             fix: {HOW}"
        );
    }

    /// README.md's key table is the registry's rendering; with `QDEM_WRITE_KEYS=1` the test
    /// writes it there instead.
    #[test]
    fn readme_table_is_the_registry() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md");
        let readme = std::fs::read_to_string(&path).unwrap();
        let (before, rest) = readme
            .split_once(README_BEGIN)
            .unwrap_or_else(|| panic!("README.md has no line {README_BEGIN:?}; {HOW}"));
        let (current, after) = rest
            .split_once(README_END)
            .unwrap_or_else(|| panic!("README.md has no line {README_END:?}; {HOW}"));
        let table = format!("\n{}", markdown_table());
        if std::env::var_os("QDEM_WRITE_KEYS").is_some() {
            let text = format!("{before}{README_BEGIN}{table}{README_END}{after}");
            std::fs::write(&path, text).unwrap();
            return;
        }
        let rows = |t: &str| t.lines().map(str::to_string).collect::<BTreeSet<_>>();
        let (want, have) = (rows(&table), rows(current));
        let absent: Vec<_> = want.difference(&have).collect();
        let extra: Vec<_> = have.difference(&want).collect();
        assert!(
            current == table,
            "README.md's scene key table differs from the registry:\n  rows missing from \
             README.md: {absent:#?}\n  rows README.md has that the registry does not: \
             {extra:#?}\nfix: QDEM_WRITE_KEYS=1 cargo test -p qdem-io --lib scene::keys"
        );
    }
}
