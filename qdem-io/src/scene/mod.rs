//! Scene files: the TOML schema of a simulation, its parsing and its validation.
//!
//! A scene file describes one run: `[run]` (end time, time step, integrator, gravity, probe
//! interval), `[[material]]`s, `[[body]]`s (a gmsh mesh and a material each), `[[fix]]`es,
//! `[[load]]`s, `[[probe]]`s and `[output]`. See [`Scene`] for the format.
//!
//! # Pipeline
//!
//! [`Scene::parse`] runs three stages, each with its own kind of [`SceneError`]:
//!
//! 1. **TOML syntax** ([`SceneError::Syntax`]): the text is parsed into toml's spanned
//!    document, which also gives a map from key paths to byte spans (private `spans` module).
//! 2. **Schema** ([`SceneError::Schema`]): serde deserializes into the types of [`schema`]; every
//!    struct denies unknown fields. serde's first error is rewritten to name the table and the
//!    key and to propose the closest valid key ([`suggest`]): `unknown key `t_ned` in [run];
//!    did you mean `t_end`?`.
//! 3. **Semantics** ([`SceneError::Invalid`]): ranges, references between tables, ramps, boxes
//!    (private `validate` module, one file per table). All problems are collected and reported
//!    one per line, in file order, each located through the span map. The references between
//!    tables (a fix's body, a body's material, …) are resolved into [`Refs`] on the way, so
//!    the build indexes instead of looking names up.
//!
//! [`Scene::load`] reads the file first and, after parsing, checks that the mesh files exist
//! ([`SceneError::MissingFiles`]); [`Scene::parse`] touches no file so that it can be tested on
//! strings.
//!
//! Every message starts with `path:line:column: ` (or `path: ` when there is no position), so
//! editors and terminals can jump to it.
//!
//! # Why the span map instead of `toml::Spanned` fields
//!
//! Wrapping fields in `Spanned<T>` would leak positions into every consumer of [`Scene`]. The
//! document is parsed a second time into toml's spanned tree instead (cheap: scene files are
//! small), so the public types stay plain data that can also be built in code and checked with
//! [`Scene::validate`].

use std::path::{Path, PathBuf};

mod error;
pub mod keys;
mod refs;
pub mod schema;
mod spans;
pub mod suggest;
mod validate;

pub use error::{Diagnostic, SceneError};
pub use refs::{ProbeTarget, Refs};
pub use schema::{
    AreaLoad, Ballast, Body, Bonded, ClumpShapeName, Contact, ContactLawName, CyclicLoad,
    EventSolveName, Fix, FixFrame, Formulation, GradingBasisName, Granular, Integrator, Load,
    Material, Measure, MeasureRegion, Output, PackingName, Periodic, Probe, Ramp, Run, Section,
    Selection, Series, Supports, TimeDelay, TimeStep, Wall, WallServo, WallStart,
};

use schema::RawScene;
use spans::SpanIndex;

/// A parsed and validated scene file.
///
/// ```toml
/// [run]
/// t_end = 2.0                 # s
/// dt = "auto"                 # or a number of seconds
/// integrator = "verlet"
/// gravity = [0.0, 0.0, 0.0]
/// probe_every = 1e-4          # s between rows of probes.csv
/// dt_safety = 0.9             # optional, in (0, 1]
///
/// [[material]]
/// name = "concrete"
/// density = 2350.0            # kg/m^3
/// young = 45e9                # Pa
/// poisson = 0.167
/// shear_viscosity = 0.0       # Pa s, optional
/// bulk_viscosity = 0.0        # Pa s, optional
///
/// [[body]]
/// name = "beam"
/// mesh = "cantilever.msh"     # relative to the scene file
/// material = "concrete"
/// reorder = true              # optional
/// contact_radius = 0.012      # m, optional: spheres at the surface vertices
/// rigid = false               # optional: integrate as a rigid body
/// translate = [0.0, 0.0, 0.0] # m, optional, after the rotation
/// rotate_deg = [0.0, 0.0, 0.0]  # optional, about the centroid: x, then y, then z
/// velocity = [0.0, 0.0, 0.0]  # m/s, optional initial velocity
///
/// [[fix]]
/// body = "beam"
/// group = "clamp"             # or box = [[xmin, ymin, zmin], [xmax, ymax, zmax]]
/// dofs = "xyz"
/// rotation = false            # optional: also hold a rigid body's rotation
///
/// [[load]]
/// body = "beam"
/// group = "tip"
/// total_force = [0.0, 0.0, -200.0] # or pressure = 1e6 (Pa, on the selected boundary
///                                  # faces), or traction = [tx, ty, tz] (Pa)
/// ramp = [[0.0, 0.0], [1.0, 1.0]]  # or cyclic = { min = 0.075, max = 1.0, frequency = 3.0,
///                                  #                phase_deg = 0.0, start = 0.0 }
///
/// [[probe]]
/// name = "tip"
/// body = "beam"
/// point = [2.4, 0.125, 0.11]
///
/// [contact]                   # needed when a body has contact_radius
/// law = "linear"              # or "hertz-mindlin" (from each body's young and poisson)
/// normal_stiffness = 1.613e9  # N/m, linear law
/// tangential_stiffness = 0.672e9
/// friction = 0.577
/// damping_ratio = 0.0         # optional, in [0, 1)
/// local_damping = 0.0         # optional, in [0, 1) (PFC's 0.7 for packing)
///
/// [[wall]]
/// point = [0.0, 0.0, -0.5]    # a plane through point with normal towards the bodies,
/// normal = [0.0, 0.0, 1.0]    # or mesh = "obstacle.msh" (its boundary surface)
/// friction = 0.5              # optional, default [contact] friction
/// velocity = [0.0, 0.0, 0.0]  # m/s, optional
///
/// [periodic]                  # optional: see [`Periodic`] (and its time_delay)
/// axes = "y"
/// length = [0.7]
///
/// [granular]                  # optional: rigid clumps of spheres, see [`Granular`]
/// name = "ballast"
/// material = "granite"
/// sample = "stones.csv"
///
/// [output]
/// dir = "out"
/// vtu_every = 0.01
/// ```
///
/// Required: `[run] t_end`, at least one `[[material]]` and one `[[body]]`. Defaults: `dt =
/// "auto"`, `integrator = "verlet"`, `gravity = [0, 0, 0]`, no `probe_every`, `dt_safety =
/// 0.9`, viscosities 0, `reorder = true`, `dofs = "xyz"`, no ramp (factor 1), `[output] dir =
/// "out"`, `vtu_every = 0`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Scene {
    /// `[run]`.
    pub run: Run,
    /// `[[material]]`, in file order.
    pub materials: Vec<Material>,
    /// `[[body]]`, in file order.
    pub bodies: Vec<Body>,
    /// `[[fix]]`, in file order.
    pub fixes: Vec<Fix>,
    /// `[[load]]`, in file order.
    pub loads: Vec<Load>,
    /// `[contact]`, when bodies touch.
    pub contact: Option<Contact>,
    /// `[[wall]]`, in file order.
    pub walls: Vec<Wall>,
    /// `[[probe]]`, in file order.
    pub probes: Vec<Probe>,
    /// `[[section]]`, in file order.
    pub sections: Vec<Section>,
    /// `[[measure]]`, in file order.
    pub measures: Vec<Measure>,
    /// `[bonded]`: a 2D beam-bonded particle body instead of `[[body]]`s.
    pub bonded: Option<Bonded>,
    /// `[periodic]`: periodic axes and an optional time delay.
    pub periodic: Option<Periodic>,
    /// `[granular]`: a sample of rigid stones.
    pub granular: Option<Granular>,
    /// `[ballast]`: deformable stones.
    pub ballast: Option<Ballast>,
    /// `[output]` (defaults when absent).
    pub output: Output,
    /// The scene file; relative paths inside the scene are resolved against its directory.
    pub path: PathBuf,
    /// The references between the tables, resolved by validation ([`Scene::refs`]).
    #[serde(skip)]
    pub(crate) refs: Refs,
}

impl Scene {
    /// Read, parse and validate the scene file at `path`, and check that its mesh files exist.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let (scene, spans) = parse_with_spans(&text, path)?;
        let missing = validate::missing_files(&scene, Some(&text), Some(&spans));
        if missing.is_empty() {
            Ok(scene)
        } else {
            Err(SceneError::MissingFiles(missing))
        }
    }

    /// Parse and validate scene `text`; `path` is the file it came from (used in messages and
    /// to resolve relative paths). Touches no file: see [`Scene::validate_files`].
    pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
        parse_with_spans(text, path).map(|(scene, _)| scene)
    }

    /// Check the semantic rules on a scene built or modified in code (a parsed scene already
    /// passed them). Messages carry no line numbers.
    pub fn validate(&self) -> Result<(), SceneError> {
        validate::validate(validate::to_raw(self), &self.path, None, None).map(|_| ())
    }

    /// Check the semantic rules again, as [`Scene::validate`], and return the scene with its
    /// references resolved anew: for a scene whose names or references were changed in code
    /// after parsing, before it is built.
    pub fn validated(&self) -> Result<Scene, SceneError> {
        validate::validate(validate::to_raw(self), &self.path, None, None)
    }

    /// The references between the scene's tables (a body's material, a fix's body, …) as
    /// indices, resolved when the scene was validated.
    pub fn refs(&self) -> &Refs {
        &self.refs
    }

    /// Check that the files the scene refers to exist: every body's mesh, resolved with
    /// [`Scene::mesh_path`]. [`Scene::load`] does this itself.
    pub fn validate_files(&self) -> Result<(), SceneError> {
        let missing = validate::missing_files(self, None, None);
        if missing.is_empty() {
            Ok(())
        } else {
            Err(SceneError::MissingFiles(missing))
        }
    }

    /// The directory relative paths in the scene are resolved against: the scene file's
    /// directory (`.` when the path has none).
    pub fn base_dir(&self) -> &Path {
        match self.path.parent() {
            Some(dir) if !dir.as_os_str().is_empty() => dir,
            _ => Path::new("."),
        }
    }

    /// The mesh file of `body`, resolved relative to the scene file's directory (an absolute
    /// `mesh` is kept as is).
    pub fn mesh_path(&self, body: &Body) -> PathBuf {
        self.base_dir().join(&body.mesh)
    }

    /// The stones file of `[granular] sample`, resolved like [`Scene::mesh_path`].
    pub fn sample_path(&self) -> Option<PathBuf> {
        let sample = self.granular.as_ref()?.sample.as_ref()?;
        Some(self.base_dir().join(sample))
    }

    /// A file named in the scene (a stone mesh, a load series, a checkpoint to start from),
    /// resolved like [`Scene::mesh_path`].
    pub fn resolve(&self, file: &Path) -> PathBuf {
        self.base_dir().join(file)
    }

    /// The mesh file of a mesh wall, resolved like [`Scene::mesh_path`].
    pub fn wall_mesh_path(&self, mesh: &Path) -> PathBuf {
        self.base_dir().join(mesh)
    }

    /// The material called `name`.
    pub fn material(&self, name: &str) -> Option<&Material> {
        self.materials.iter().find(|m| m.name == name)
    }

    /// The body called `name`.
    pub fn body(&self, name: &str) -> Option<&Body> {
        self.bodies.iter().find(|b| b.name == name)
    }

    /// The material of `body` (always present in a validated scene).
    pub fn body_material(&self, body: &Body) -> Option<&Material> {
        self.material(&body.material)
    }
}

fn parse_with_spans(text: &str, path: &Path) -> Result<(Scene, SpanIndex), SceneError> {
    let document = toml::de::DeTable::parse(text).map_err(|e| {
        SceneError::Syntax(Diagnostic::at(
            path,
            Some(text),
            e.span().map(|s| s.start),
            format!("invalid TOML: {}", e.message().trim()),
        ))
    })?;
    let spans = SpanIndex::new(document.get_ref());
    let raw: RawScene = toml::from_str(text)
        .map_err(|e| SceneError::Schema(error::schema_diagnostic(&e, text, path, &spans)))?;
    let scene = validate::validate(raw, path, Some(text), Some(&spans))?;
    Ok((scene, spans))
}
