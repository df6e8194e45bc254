//! The documented example scene parses to the expected values; defaults; file checks.

use std::path::{Path, PathBuf};

use qdem_io::scene::{Integrator, Ramp, Scene, SceneError, Selection, TimeStep};

const EXAMPLE: &str = r#"
[run]
t_end = 2.0                 # s
dt = "auto"                 # or a number of seconds (refused later if above the stable bound)
integrator = "verlet"
gravity = [0.0, 0.0, 0.0]
probe_every = 1e-4          # s between rows of probes.csv
dt_safety = 0.9             # optional, fraction of the stable bound used when dt = "auto", in (0, 1]

[[material]]
name = "concrete"
density = 2350.0            # kg/m^3
young = 45e9                # Pa
poisson = 0.167
shear_viscosity = 0.0       # Pa s (mu_D), optional, default 0
bulk_viscosity = 0.0        # Pa s (lambda_D + 2/3 mu_D), optional, default 0

[[body]]
name = "beam"
mesh = "cantilever.msh"     # relative to the scene file
material = "concrete"
reorder = true              # optional, default true: reorder nodes for locality

[[fix]]
body = "beam"
group = "clamp"             # gmsh physical group name, or instead:
# box = [[xmin, ymin, zmin], [xmax, ymax, zmax]]   # all particles inside the box
dofs = "xyz"                # any non-empty subset, e.g. "xy"

[[load]]
body = "beam"
group = "tip"               # or box = [[...], [...]]
total_force = [0.0, 0.0, -200.0]    # N, shared equally by the selected particles
ramp = [[0.0, 0.0], [1.0, 1.0]]     # (t, factor) piecewise linear; held after the last point;
                                    # a repeated t makes a jump: [[2.0, 1.0], [2.0, 0.0]]

[[probe]]
name = "tip"
body = "beam"
point = [2.4, 0.125, 0.11]  # the nearest particle is sampled

[output]
dir = "out"                 # --out overrides
vtu_every = 0.01            # s; absent or 0 = no VTU
"#;

const MINIMAL: &str = r#"
[run]
t_end = 1.0

[[material]]
name = "steel"
density = 7850
young = 210e9
poisson = 0.3

[[body]]
name = "block"
mesh = "block.msh"
material = "steel"
"#;

#[test]
fn example_parses_to_expected_values() {
    let path = Path::new("scenes/cantilever/scene.toml");
    let scene = Scene::parse(EXAMPLE, path).unwrap();

    assert_eq!(scene.path, path);
    let run = &scene.run;
    assert_eq!(run.t_end, 2.0);
    assert_eq!(run.dt, TimeStep::Auto);
    assert_eq!(run.integrator, Integrator::Verlet);
    assert_eq!(run.gravity, [0.0; 3]);
    assert_eq!(run.probe_every, Some(1e-4));
    assert_eq!(run.dt_safety, 0.9);

    assert_eq!(scene.materials.len(), 1);
    let m = scene.material("concrete").unwrap();
    assert_eq!(m.name, "concrete");
    assert_eq!(m.density, 2350.0);
    assert_eq!(m.young, 45e9);
    assert_eq!(m.poisson, 0.167);
    assert_eq!(m.shear_viscosity, 0.0);
    assert_eq!(m.bulk_viscosity, 0.0);
    assert!(scene.material("steel").is_none());

    assert_eq!(scene.bodies.len(), 1);
    let b = &scene.bodies[0];
    assert_eq!(b.name, "beam");
    assert_eq!(b.mesh, PathBuf::from("cantilever.msh"));
    assert_eq!(b.material, "concrete");
    assert!(b.reorder);
    assert_eq!(
        scene.mesh_path(b),
        PathBuf::from("scenes/cantilever/cantilever.msh")
    );
    assert_eq!(scene.body("beam"), Some(b));
    assert_eq!(scene.body_material(b), Some(m));

    assert_eq!(scene.fixes.len(), 1);
    let f = &scene.fixes[0];
    assert_eq!(f.body, "beam");
    assert_eq!(f.selection, Selection::Group("clamp".into()));
    assert_eq!(f.dofs, [true, true, true]);

    assert_eq!(scene.loads.len(), 1);
    let l = &scene.loads[0];
    assert_eq!(l.body, "beam");
    assert_eq!(l.selection, Selection::Group("tip".into()));
    assert_eq!(l.total_force, [0.0, 0.0, -200.0]);
    assert_eq!(l.ramp.points, vec![[0.0, 0.0], [1.0, 1.0]]);
    assert_eq!(l.ramp.time_function().unwrap().value(0.25), 0.25);
    assert_eq!(l.ramp.time_function().unwrap().value(5.0), 1.0);

    assert_eq!(scene.probes.len(), 1);
    let p = &scene.probes[0];
    assert_eq!(p.name, "tip");
    assert_eq!(p.body, "beam");
    assert_eq!(p.point, Some([2.4, 0.125, 0.11]));

    assert_eq!(scene.output.dir, PathBuf::from("out"));
    assert_eq!(scene.output.vtu_every, 0.01);
    assert!(scene.output.writes_vtu());

    // A parsed scene passes the in-code validation too.
    scene.validate().unwrap();
}

#[test]
fn defaults() {
    let scene = Scene::parse(MINIMAL, Path::new("scene.toml")).unwrap();
    assert_eq!(scene.run.dt, TimeStep::Auto);
    assert_eq!(scene.run.integrator, Integrator::Verlet);
    assert_eq!(scene.run.gravity, [0.0; 3]);
    assert_eq!(scene.run.probe_every, None);
    assert_eq!(scene.run.dt_safety, 0.9);
    let m = &scene.materials[0];
    assert_eq!(m.density, 7850.0); // integers are accepted for numbers
    assert_eq!((m.shear_viscosity, m.bulk_viscosity), (0.0, 0.0));
    assert!(scene.bodies[0].reorder);
    assert!(scene.fixes.is_empty() && scene.loads.is_empty() && scene.probes.is_empty());
    assert_eq!(scene.output.dir, PathBuf::from("out"));
    assert_eq!(scene.output.vtu_every, 0.0);
    assert!(!scene.output.writes_vtu());
    // No directory in the scene path: meshes are resolved against the current directory.
    assert_eq!(
        scene.mesh_path(&scene.bodies[0]),
        PathBuf::from("./block.msh")
    );
}

#[test]
fn fixed_dt_box_dofs_and_jump_ramp() {
    let text = MINIMAL.replace(
        "t_end = 1.0",
        "t_end = 1.0\ndt = 1e-6\ngravity = [0, 0, -9.81]",
    ) + r#"
[[fix]]
body = "block"
box = [[-1.0, -1.0, 0.0], [1.0, 1.0, 0.0]]
dofs = "zx"

[[fix]]
body = "block"
group = "side"

[[load]]
body = "block"
box = [[0, 0, 1], [1, 1, 1]]
total_force = [1, 2, 3]
ramp = [[0.0, 0.0], [1.0, 1.0], [2.0, 1.0], [2.0, 0.0]]

[[load]]
body = "block"
group = "top"
total_force = [0, 0, 1]
"#;
    let scene = Scene::parse(&text, Path::new("scene.toml")).unwrap();
    assert_eq!(scene.run.dt, TimeStep::Fixed(1e-6));
    assert_eq!(scene.run.gravity, [0.0, 0.0, -9.81]);
    assert_eq!(
        scene.fixes[0].selection,
        Selection::Box([[-1.0, -1.0, 0.0], [1.0, 1.0, 0.0]])
    );
    assert_eq!(scene.fixes[0].dofs, [true, false, true]);
    assert_eq!(scene.fixes[1].dofs, [true, true, true]); // default "xyz"
    let ramp = &scene.loads[0].ramp;
    assert_eq!(ramp.time_function().unwrap().value(1.5), 1.0);
    assert_eq!(ramp.time_function().unwrap().value(2.0), 0.0);
    assert_eq!(ramp.time_function().unwrap().value(3.0), 0.0);
    assert_eq!(scene.loads[1].ramp, Ramp::constant());
    assert_eq!(
        scene.loads[1].ramp.time_function().unwrap().value(10.0),
        1.0
    );
    scene.validate().unwrap();
}

#[test]
fn integer_dt_is_seconds() {
    let text = MINIMAL.replace("t_end = 1.0", "t_end = 1.0\ndt = 1");
    let scene = Scene::parse(&text, Path::new("scene.toml")).unwrap();
    assert_eq!(scene.run.dt, TimeStep::Fixed(1.0));
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("qdem-io-scene-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn load_checks_mesh_files() {
    let dir = temp_dir("load");
    let scene_path = dir.join("scene.toml");
    std::fs::write(&scene_path, MINIMAL).unwrap();

    // The mesh is missing: the error names the resolved path and the `mesh` line.
    let err = Scene::load(&scene_path).unwrap_err();
    assert!(matches!(err, SceneError::MissingFiles(_)), "{err}");
    let msg = err.to_string();
    let mesh = dir.join("block.msh");
    assert!(
        msg.starts_with(&format!("{}:13:8: ", scene_path.display())),
        "{msg}"
    );
    assert!(msg.contains(&mesh.display().to_string()), "{msg}");
    assert!(msg.contains("[[body]] \"block\""), "{msg}");
    assert!(msg.contains("does not exist"), "{msg}");

    // parse() does not look at files, validate_files() does.
    let scene = Scene::parse(MINIMAL, &scene_path).unwrap();
    assert!(scene.validate_files().is_err());

    std::fs::write(&mesh, "$MeshFormat\n").unwrap();
    let scene = Scene::load(&scene_path).unwrap();
    assert_eq!(scene.mesh_path(&scene.bodies[0]), mesh);
    scene.validate_files().unwrap();

    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn load_reports_unreadable_file() {
    let path = Path::new("/nonexistent/qdem/scene.toml");
    let err = Scene::load(path).unwrap_err();
    assert!(matches!(err, SceneError::Read { .. }));
    assert!(
        err.to_string()
            .starts_with("/nonexistent/qdem/scene.toml: "),
        "{err}"
    );
}

#[test]
fn scene_serializes_to_json() {
    let scene = Scene::parse(EXAMPLE, Path::new("scene.toml")).unwrap();
    let json = serde_json::to_value(&scene).unwrap();
    assert_eq!(json["run"]["dt"], "auto");
    assert_eq!(json["run"]["integrator"], "verlet");
    assert_eq!(json["fixes"][0]["selection"]["group"], "clamp");
    assert_eq!(json["materials"][0]["young"], 45e9);
}

#[test]
fn a_preconditioned_event_solve_in_an_explicit_run_is_warned_about() {
    let dir = std::env::temp_dir().join(format!("qdem-io-event-solve-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/bbm/small_beam.toml");
    let text = std::fs::read_to_string(fixture).unwrap();
    let warned = |text: &str| {
        let path = dir.join("beam.toml");
        std::fs::write(&path, text).unwrap();
        let sim = qdem_io::build::Simulation::build(Scene::load(&path).unwrap()).unwrap();
        sim.warnings
            .iter()
            .any(|w| w.contains("event_solve") && w.contains("no effect"))
    };
    let preconditioned = text.replace("[bonded]\n", "[bonded]\nevent_solve = \"preconditioned\"\n");
    assert!(warned(&preconditioned), "explicit Newmark (beta = 0)");
    assert!(
        !warned(&preconditioned.replace("beta = 0.0", "beta = 0.25")),
        "implicit"
    );
    assert!(!warned(&text), "the default");
    let _ = std::fs::remove_dir_all(&dir);
}
