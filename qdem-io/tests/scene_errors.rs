//! Every error names the scene path (with line and column where known), the table and key,
//! and the suggestion or the fix.

use std::path::Path;

use qdem_io::scene::{ClumpShapeName, GradingBasisName, Scene, SceneError};

const PATH: &str = "scenes/scene.toml";

/// The example scene, without comments so that line numbers are easy to count.
const BASE: &str = r#"[run]
t_end = 2.0
dt = "auto"
integrator = "verlet"
gravity = [0.0, 0.0, 0.0]
probe_every = 1e-4
dt_safety = 0.9

[[material]]
name = "concrete"
density = 2350.0
young = 45e9
poisson = 0.167
shear_viscosity = 0.0
bulk_viscosity = 0.0

[[body]]
name = "beam"
mesh = "cantilever.msh"
material = "concrete"
reorder = true

[[fix]]
body = "beam"
group = "clamp"
dofs = "xyz"

[[load]]
body = "beam"
group = "tip"
total_force = [0.0, 0.0, -200.0]
ramp = [[0.0, 0.0], [1.0, 1.0]]

[[probe]]
name = "tip"
body = "beam"
point = [2.4, 0.125, 0.11]

[output]
dir = "out"
vtu_every = 0.01
"#;

/// BASE with `from` replaced (exactly one occurrence) by `to`.
fn with(from: &str, to: &str) -> String {
    assert_eq!(
        BASE.matches(from).count(),
        1,
        "`{from}` must occur once in BASE"
    );
    BASE.replacen(from, to, 1)
}

/// Parse `text`, expecting an error; returns it with its message.
fn error(text: &str) -> (SceneError, String) {
    let err = Scene::parse(text, Path::new(PATH)).expect_err("the scene should be refused");
    let msg = err.to_string();
    println!("{msg}");
    (err, msg)
}

/// Assert `msg` contains every part.
#[track_caller]
fn assert_has(msg: &str, parts: &[&str]) {
    for part in parts {
        assert!(msg.contains(part), "expected {part:?} in:\n{msg}");
    }
}

#[test]
fn base_is_valid() {
    Scene::parse(BASE, Path::new(PATH)).unwrap();
}

// ---- TOML syntax -------------------------------------------------------------------------

#[test]
fn syntax_error_is_located() {
    let (err, msg) = error(&with("t_end = 2.0", "t_end = 2.0.0"));
    assert!(matches!(err, SceneError::Syntax(_)));
    assert!(msg.starts_with("scenes/scene.toml:2:"), "{msg}");
    assert_has(&msg, &["invalid TOML"]);
}

#[test]
fn duplicate_key_is_a_syntax_error() {
    let (_, msg) = error(&with("t_end = 2.0", "t_end = 2.0\nt_end = 3.0"));
    assert!(msg.starts_with("scenes/scene.toml:3:"), "{msg}");
}

// ---- schema: unknown keys and tables ------------------------------------------------------

#[test]
fn unknown_key_in_run_suggests_the_right_one() {
    let (err, msg) = error(&with("t_end = 2.0", "t_ned = 2.0"));
    assert!(matches!(err, SceneError::Schema(_)));
    assert_eq!(
        msg,
        "scenes/scene.toml:2:1: unknown key `t_ned` in [run]; did you mean `t_end`?"
    );
}

#[test]
fn unknown_key_case_insensitive_match() {
    let (_, msg) = error(&with("dt_safety = 0.9", "DT_Safety = 0.9"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:7:1:",
            "`DT_Safety` in [run]",
            "did you mean `dt_safety`?",
        ],
    );
}

#[test]
fn unknown_key_without_suggestion_lists_valid_keys() {
    let (_, msg) = error(&with("t_end = 2.0", "t_end = 2.0\ncolor = 1"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:3:1:",
            "unknown key `color` in [run]",
            "valid keys:",
            "`t_end`",
            "`dt_safety`",
        ],
    );
    assert!(!msg.contains("did you mean"), "{msg}");
}

#[test]
fn unknown_key_in_array_table_names_the_element() {
    let (_, msg) = error(&with("density = 2350.0", "densty = 2350.0"));
    assert_eq!(
        msg,
        "scenes/scene.toml:11:1: unknown key `densty` in [[material]] \"concrete\"; did you mean `density`?"
    );
    let (_, msg) = error(&with("dofs = \"xyz\"", "dof = \"xyz\""));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:26:1:",
            "unknown key `dof` in [[fix]] #1",
            "did you mean `dofs`?",
        ],
    );
    let (_, msg) = error(&with("total_force =", "totalforce ="));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:31:1:",
            "[[load]] #1",
            "did you mean `total_force`?",
        ],
    );
    let (_, msg) = error(&with("point = ", "pointt = "));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:37:1:",
            "[[probe]] \"tip\"",
            "did you mean `point`?",
        ],
    );
    let (_, msg) = error(&with("reorder = true", "reoder = true"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:21:1:",
            "[[body]] \"beam\"",
            "did you mean `reorder`?",
        ],
    );
}

#[test]
fn unknown_key_in_output() {
    let (_, msg) = error(&with("vtu_every = 0.01", "vtu_evry = 0.01"));
    assert_eq!(
        msg,
        "scenes/scene.toml:41:1: unknown key `vtu_evry` in [output]; did you mean `vtu_every`?"
    );
}

#[test]
fn unknown_top_level_table_suggests_the_right_one() {
    let (err, msg) = error(&with("[output]", "[outptu]"));
    assert!(matches!(err, SceneError::Schema(_)));
    assert_eq!(
        msg,
        "scenes/scene.toml:39:2: unknown table `[outptu]`; did you mean `[output]`?"
    );
    let (_, msg) = error(&with("[[body]]", "[[bodies]]"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:17:3:",
            "unknown table `[[bodies]]`",
            "did you mean `[[body]]`?",
        ],
    );
    let (_, msg) = error(&with("[[material]]", "[[Material]]"));
    assert_has(
        &msg,
        &[
            "unknown table `[[Material]]`",
            "did you mean `[[material]]`?",
        ],
    );
}

#[test]
fn unknown_top_level_table_without_suggestion_lists_tables() {
    let (_, msg) = error(&format!("{BASE}\n[solver]\nk = 1\n"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:43:2:",
            "unknown table `[solver]`",
            "[run]",
            "[[material]]",
            "[output]",
        ],
    );
}

#[test]
fn unknown_top_level_key() {
    let (_, msg) = error(&format!("titel = \"x\"\n{BASE}"));
    assert_has(
        &msg,
        &["scenes/scene.toml:1:1:", "unknown top-level key `titel`"],
    );
}

#[test]
fn nested_unknown_table() {
    let (_, msg) = error(&format!("{BASE}\n[output.extra]\nk = 1\n"));
    assert_has(
        &msg,
        &["scenes/scene.toml:43:9:", "unknown key `extra` in [output]"],
    );
}

// ---- schema: values ---------------------------------------------------------------------

#[test]
fn unknown_integrator_lists_valid_ones() {
    let (err, msg) = error(&with("integrator = \"verlet\"", "integrator = \"rk4\""));
    assert!(matches!(err, SceneError::Schema(_)));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:4:14:",
            "`rk4`",
            "`integrator` in [run]",
            "valid values: `verlet`",
        ],
    );
    let (_, msg) = error(&with("integrator = \"verlet\"", "integrator = \"verlt\""));
    assert_has(&msg, &["did you mean `verlet`?"]);
}

#[test]
fn dt_must_be_auto_or_seconds() {
    for bad in ["\"automatic\"", "true", "[1.0]"] {
        let (err, msg) = error(&with("dt = \"auto\"", &format!("dt = {bad}")));
        assert!(matches!(err, SceneError::Schema(_)));
        assert_has(
            &msg,
            &[
                "scenes/scene.toml:3:6:",
                "[run]",
                "dt must be \"auto\" or a number of seconds",
            ],
        );
    }
}

#[test]
fn wrong_type_names_key_and_table() {
    let (_, msg) = error(&with("t_end = 2.0", "t_end = \"2 s\""));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:2:9:",
            "`t_end` in [run]",
            "expected a number",
        ],
    );
    let (_, msg) = error(&with("gravity = [0.0, 0.0, 0.0]", "gravity = [0.0, 0.0]"));
    assert_has(
        &msg,
        &["scenes/scene.toml:5:11:", "`gravity` in [run]", "length 2"],
    );
    let (_, msg) = error(&with("young = 45e9", "young = \"45 GPa\""));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:12:9:",
            "`young` in [[material]] \"concrete\"",
        ],
    );
    let (_, msg) = error(&with(
        "point = [2.4, 0.125, 0.11]",
        "point = [2.4, \"a\", 0.11]",
    ));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:37:15:",
            "`point[1]` in [[probe]] \"tip\"",
        ],
    );
}

#[test]
fn missing_key_names_table() {
    let (_, msg) = error(&with("t_end = 2.0\n", ""));
    assert_has(
        &msg,
        &["scenes/scene.toml:1:1:", "missing key `t_end` in [run]"],
    );
    let (_, msg) = error(&with("young = 45e9\n", ""));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:9:1:",
            "missing key `young` in [[material]] \"concrete\"",
        ],
    );
    let (_, msg) = error(&with("total_force = [0.0, 0.0, -200.0]\n", ""));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:28:1:",
            "missing key `total_force` in [[load]] #1",
        ],
    );
}

#[test]
fn missing_run_table() {
    let text = BASE.replacen("[run]\n", "", 1).replace("t_end = 2.0\ndt = \"auto\"\nintegrator = \"verlet\"\ngravity = [0.0, 0.0, 0.0]\nprobe_every = 1e-4\ndt_safety = 0.9\n", "");
    let (_, msg) = error(&text);
    assert_has(&msg, &["scenes/scene.toml", "missing table `[run]`"]);
}

// ---- semantics: numbers -------------------------------------------------------------------

#[test]
fn poisson_at_or_above_half_is_refused_with_advice() {
    let (err, msg) = error(&with("poisson = 0.167", "poisson = 0.5"));
    assert!(matches!(err, SceneError::Invalid(_)));
    assert_eq!(
        msg,
        "scenes/scene.toml:13:11: [[material]] \"concrete\": poisson = 0.5: ν must be below 0.5 \
         (incompressible materials are not supported by an explicit step; use 0.49 at most)"
    );
    let (_, msg) = error(&with("poisson = 0.167", "poisson = -1.0"));
    assert_has(&msg, &["scenes/scene.toml:13:11:", "ν must be above −1"]);
}

#[test]
fn material_constants_must_be_positive() {
    let (_, msg) = error(&with("density = 2350.0", "density = 0.0"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:11:11:",
            "[[material]] \"concrete\"",
            "density = 0",
            "must be positive",
        ],
    );
    let (_, msg) = error(&with("young = 45e9", "young = -1.0"));
    assert_has(
        &msg,
        &["scenes/scene.toml:12:9:", "young = -1", "must be positive"],
    );
    let (_, msg) = error(&with("shear_viscosity = 0.0", "shear_viscosity = -2.0"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:14:19:",
            "shear_viscosity = -2",
            "must not be negative",
        ],
    );
    let (_, msg) = error(&with("bulk_viscosity = 0.0", "bulk_viscosity = -2.0"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:15:18:",
            "bulk_viscosity = -2",
            "must not be negative",
        ],
    );
}

#[test]
fn run_values_are_checked() {
    let (_, msg) = error(&with("t_end = 2.0", "t_end = 0.0"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:2:9:",
            "[run]: t_end = 0",
            "must be positive",
        ],
    );
    let (_, msg) = error(&with("dt = \"auto\"", "dt = -1e-6"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:3:6:",
            "[run]: dt = -0.000001",
            "must be positive",
        ],
    );
    let (_, msg) = error(&with("dt = \"auto\"", "dt = 0"));
    assert_has(
        &msg,
        &["scenes/scene.toml:3:6:", "dt = 0", "must be positive"],
    );
    for bad in ["0.0", "1.5", "-0.1"] {
        let (_, msg) = error(&with("dt_safety = 0.9", &format!("dt_safety = {bad}")));
        assert_has(
            &msg,
            &[
                "scenes/scene.toml:7:13:",
                "[run]: dt_safety",
                "must be in (0, 1]",
            ],
        );
    }
    Scene::parse(&with("dt_safety = 0.9", "dt_safety = 1.0"), Path::new(PATH)).unwrap();
    let (_, msg) = error(&with("probe_every = 1e-4", "probe_every = 0"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:6:15:",
            "[run]: probe_every = 0",
            "must be positive",
        ],
    );
    let (_, msg) = error(&with("vtu_every = 0.01", "vtu_every = -0.01"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:41:13:",
            "[output]: vtu_every = -0.01",
            "must not be negative",
        ],
    );
    Scene::parse(&with("vtu_every = 0.01", "vtu_every = 0"), Path::new(PATH)).unwrap();
}

#[test]
fn numbers_must_be_finite() {
    let (_, msg) = error(&with(
        "gravity = [0.0, 0.0, 0.0]",
        "gravity = [0.0, nan, 0.0]",
    ));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:5:11:",
            "[run]: `gravity` must be a finite number, not NaN",
        ],
    );
    let (_, msg) = error(&with("young = 45e9", "young = inf"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:12:9:",
            "`young` must be a finite number, not inf",
        ],
    );
    let (_, msg) = error(&with(
        "point = [2.4, 0.125, 0.11]",
        "point = [2.4, -inf, 0.11]",
    ));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:37:9:",
            "[[probe]] \"tip\"",
            "`point` must be a finite number",
        ],
    );
    let (_, msg) = error(&with(
        "total_force = [0.0, 0.0, -200.0]",
        "total_force = [0.0, 0.0, nan]",
    ));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:31:15:",
            "[[load]] #1",
            "`total_force` must be a finite",
        ],
    );
    let (_, msg) = error(&with("dt = \"auto\"", "dt = inf"));
    assert_has(
        &msg,
        &["scenes/scene.toml:3:6:", "`dt` must be a finite number"],
    );
}

// ---- semantics: names and references -----------------------------------------------------

#[test]
fn duplicate_names() {
    let material = "[[material]]\nname = \"concrete\"\ndensity = 1.0\nyoung = 1.0\npoisson = 0.2\n";
    let (_, msg) = error(&format!("{BASE}\n{material}"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:44:8:",
            "[[material]] \"concrete\" (#2)",
            "duplicate material name \"concrete\"",
            "line 10",
            "rename",
        ],
    );
    let body = "[[body]]\nname = \"beam\"\nmesh = \"b.msh\"\nmaterial = \"concrete\"\n";
    let (_, msg) = error(&format!("{BASE}\n{body}"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:44:8:",
            "duplicate body name \"beam\"",
            "line 18",
        ],
    );
    let probe = "[[probe]]\nname = \"tip\"\nbody = \"beam\"\npoint = [0, 0, 0]\n";
    let (_, msg) = error(&format!("{BASE}\n{probe}"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:44:8:",
            "duplicate probe name \"tip\"",
            "line 35",
        ],
    );
}

#[test]
fn undefined_material_suggests_and_lists() {
    let (err, msg) = error(&with("material = \"concrete\"", "material = \"concret\""));
    assert!(matches!(err, SceneError::Invalid(_)));
    assert_eq!(
        msg,
        "scenes/scene.toml:20:12: [[body]] \"beam\": material \"concret\" is not defined; did you \
         mean \"concrete\"? (defined materials: \"concrete\")"
    );
    let (_, msg) = error(&with("material = \"concrete\"", "material = \"granite\""));
    assert_has(
        &msg,
        &[
            "material \"granite\" is not defined",
            "defined materials: \"concrete\"",
        ],
    );
    assert!(!msg.contains("did you mean"), "{msg}");
}

#[test]
fn unknown_body_in_fix_load_probe() {
    let text = BASE.replace("body = \"beam\"", "body = \"bean\"");
    let (err, msg) = error(&text);
    // All three are reported, one per line, in file order.
    assert_eq!(err.diagnostics().len(), 3, "{msg}");
    let lines: Vec<&str> = msg.lines().collect();
    assert_eq!(lines.len(), 3);
    assert_has(
        lines[0],
        &[
            "scenes/scene.toml:24:8:",
            "[[fix]] #1: body \"bean\" is not defined",
            "did you mean \"beam\"?",
            "defined bodies: \"beam\"",
        ],
    );
    assert_has(
        lines[1],
        &["scenes/scene.toml:29:8:", "[[load]] #1: body \"bean\""],
    );
    assert_has(
        lines[2],
        &[
            "scenes/scene.toml:36:8:",
            "[[probe]] \"tip\": body \"bean\"",
        ],
    );
}

#[test]
fn at_least_one_material_and_body() {
    let text = "[run]\nt_end = 1.0\n";
    let (err, msg) = error(text);
    assert_eq!(err.diagnostics().len(), 2, "{msg}");
    assert_has(
        &msg,
        &[
            "scenes/scene.toml: no [[material]] is defined",
            "scenes/scene.toml: no [[body]] is defined",
        ],
    );
}

// ---- semantics: fixes, loads, ramps, boxes -------------------------------------------------

#[test]
fn selection_needs_exactly_one_of_group_and_box() {
    let (_, msg) = error(&with(
        "group = \"clamp\"",
        "group = \"clamp\"\nbox = [[0, 0, 0], [1, 1, 1]]",
    ));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:26:7:",
            "[[fix]] #1: give either `group` or `box`, not both",
        ],
    );
    let (_, msg) = error(&with("group = \"tip\"\n", ""));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:28:1:",
            "[[load]] #1: no particles selected",
            "group = ",
            "box = [[xmin",
        ],
    );
}

#[test]
fn box_min_must_not_exceed_max() {
    let (_, msg) = error(&with("group = \"clamp\"", "box = [[0, 2, 0], [1, 1, 1]]"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:25:7:",
            "[[fix]] #1: box min y = 2 is above max y = 1",
        ],
    );
    // A flat box (min == max) is fine.
    Scene::parse(
        &with("group = \"clamp\"", "box = [[0, 0, 0], [0, 1, 1]]"),
        Path::new(PATH),
    )
    .unwrap();
}

#[test]
fn dofs_are_checked() {
    let (_, msg) = error(&with("dofs = \"xyz\"", "dofs = \"\""));
    assert_has(
        &msg,
        &["scenes/scene.toml:26:8:", "[[fix]] #1: dofs is empty"],
    );
    let (_, msg) = error(&with("dofs = \"xyz\"", "dofs = \"xw\""));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:26:8:",
            "`w` is not a direction",
            "x, y, z",
        ],
    );
    let (_, msg) = error(&with("dofs = \"xyz\"", "dofs = \"xx\""));
    assert_has(&msg, &["scenes/scene.toml:26:8:", "`x` appears twice"]);
    let (_, msg) = error(&with("dofs = \"xyz\"", "dofs = \"X\""));
    assert_has(&msg, &["`X` is not a direction"]);
}

/// A `[[fix]]`'s `frame`: a known name with its axis, an orthonormal basis, directions named in
/// the frame, the axis keys only with a cylindrical frame.
#[test]
fn fix_frames_are_checked() {
    let framed = |keys: &str| with("dofs = \"xyz\"", keys);
    let (_, msg) = error(&framed("frame = \"cylindrical\"\ndofs = \"t\""));
    assert_has(
        &msg,
        &["[[fix]] #1", "needs `axis`", "axis = [0.0, 0.0, 1.0]"],
    );
    let (_, msg) = error(&framed(
        "frame = \"cylindrical\"\naxis = [0.0, 0.0, 0.0]\ndofs = \"t\"",
    ));
    assert_has(&msg, &["[[fix]] #1", "non-zero axis"]);
    let (_, msg) = error(&framed("frame = \"spherical\"\ndofs = \"t\""));
    assert_has(&msg, &["frame", "\"cylindrical\" or a basis [[x, y, z]"]);
    let (_, msg) = error(&framed(
        "frame = [[1.0, 0.0, 0.0], [0.1, 1.0, 0.0], [0.0, 0.0, 1.0]]\ndofs = \"1\"",
    ));
    assert_has(&msg, &["[[fix]] #1", "not orthonormal", "right angles"]);
    // With a frame, `dofs` names its directions; the default "xyz" does not.
    let (_, msg) = error(&framed("frame = \"cylindrical\"\naxis = [0.0, 0.0, 1.0]"));
    assert_has(&msg, &["`x` is not a direction", "r, t, z", "with `frame`"]);
    let (_, msg) = error(&framed(
        "frame = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\ndofs = \"x\"",
    ));
    assert_has(&msg, &["`x` is not a direction", "1, 2, 3"]);
    let (_, msg) = error(&framed("axis = [0.0, 0.0, 1.0]"));
    assert_has(
        &msg,
        &["`axis` is the axis of a cylindrical frame", "drop `axis`"],
    );
    // A valid one parses, its axis normalised.
    let scene = Scene::parse(
        &framed("frame = \"cylindrical\"\naxis = [0.0, 0.0, 2.0]\ndofs = \"rt\""),
        Path::new(PATH),
    )
    .unwrap();
    assert_eq!(
        scene.fixes[0].frame,
        qdem_io::scene::FixFrame::Cylindrical {
            origin: [0.0; 3],
            axis: [0.0, 0.0, 1.0]
        }
    );
    assert_eq!(scene.fixes[0].dofs, [true, true, false]);
}

#[test]
fn ramps_are_checked() {
    let ramp = "ramp = [[0.0, 0.0], [1.0, 1.0]]";
    let (_, msg) = error(&with(ramp, "ramp = []"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:32:8:",
            "[[load]] #1: ramp has no points",
            "constant factor 1",
        ],
    );
    let (_, msg) = error(&with(ramp, "ramp = [[0.0, 0.0], [2.0, 1.0], [1.0, 1.0]]"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:32:",
            "ramp times must not decrease",
            "point 3 (t = 1)",
        ],
    );
    let (_, msg) = error(&with(
        ramp,
        "ramp = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [1.0, 2.0]]",
    ));
    assert_has(
        &msg,
        &["scenes/scene.toml:32:", "more than two points at t = 1"],
    );
    let (_, msg) = error(&with(ramp, "ramp = [[0.0, 0.0], [1.0, nan]]"));
    assert_has(
        &msg,
        &["scenes/scene.toml:32:8:", "`ramp` must be a finite number"],
    );
    // A jump (two points at one time) is fine.
    Scene::parse(
        &with(ramp, "ramp = [[0.0, 0.0], [2.0, 1.0], [2.0, 0.0]]"),
        Path::new(PATH),
    )
    .unwrap();
}

// ---- collecting -----------------------------------------------------------------------------

#[test]
fn semantic_errors_are_collected_in_file_order() {
    let text = with("poisson = 0.167", "poisson = 0.5")
        .replace("t_end = 2.0", "t_end = -2.0")
        .replace("dofs = \"xyz\"", "dofs = \"\"")
        .replace("material = \"concrete\"", "material = \"steel\"");
    let (err, msg) = error(&text);
    let lines: Vec<&str> = msg.lines().collect();
    assert_eq!(err.diagnostics().len(), 4, "{msg}");
    assert_eq!(lines.len(), 4);
    assert!(
        lines[0].starts_with("scenes/scene.toml:2:9: [run]: t_end"),
        "{msg}"
    );
    assert!(lines[1].starts_with("scenes/scene.toml:13:11:"), "{msg}");
    assert!(lines[2].starts_with("scenes/scene.toml:20:12:"), "{msg}");
    assert!(lines[3].starts_with("scenes/scene.toml:26:8:"), "{msg}");
    assert!(lines.iter().all(|l| l.starts_with(PATH)));
}

#[test]
fn in_code_validation_has_no_positions() {
    let mut scene = Scene::parse(BASE, Path::new(PATH)).unwrap();
    scene.materials[0].poisson = 0.5;
    scene.fixes[0].dofs = [false; 3];
    let err = scene.validate().unwrap_err();
    let msg = err.to_string();
    assert_eq!(err.diagnostics().len(), 2, "{msg}");
    assert_has(
        &msg,
        &[
            "scenes/scene.toml: [[material]] \"concrete\": poisson = 0.5",
            "scenes/scene.toml: [[fix]] #1: dofs is empty",
        ],
    );
}

#[test]
fn missing_mesh_names_resolved_path() {
    let scene = Scene::parse(BASE, Path::new("/nonexistent/dir/scene.toml")).unwrap();
    let err = scene.validate_files().unwrap_err();
    assert!(matches!(err, SceneError::MissingFiles(_)));
    assert_has(
        &err.to_string(),
        &["/nonexistent/dir/scene.toml: [[body]] \"beam\": mesh file /nonexistent/dir/cantilever.msh does not exist"],
    );
}

/// A `[bonded]` scene: valid as written, and refused with a message naming the key for a
/// bad value, a `[[body]]` beside it, a non-Newmark integrator or a `[[fix]]`.
#[test]
fn bonded_scenes_parse_and_bad_ones_are_refused_with_the_key() {
    let good = r#"
[run]
t_end = 0.01
integrator = "newmark"
beta = 0.25
dt = 1e-3

[[material]]
name = "concrete"
density = 2400.0
young = 30e9
poisson = 0.25

[bonded]
name = "beam"
material = "concrete"
size = [3.0, 0.5]
element_size = 0.05
strength_mean = 6e6
top_load = 230e3
load_ramp = 0.25
supports = "pinned"

[[probe]]
name = "mid"
body = "beam"
point = [1.5, 0.25, 0.0]
"#;
    let scene = qdem_io::scene::Scene::parse(good, std::path::Path::new("beam.toml")).unwrap();
    let b = scene.bonded.as_ref().unwrap();
    assert_eq!(b.supports, qdem_io::scene::Supports::Pinned);
    assert_eq!(b.tolerance, 0.05);
    assert!(b.adaptive);
    let cases = [
        (
            good.replace("element_size = 0.05", "element_size = -0.05"),
            "element_size",
        ),
        (
            good.replace("integrator = \"newmark\"", "integrator = \"verlet\""),
            "newmark",
        ),
        (
            good.replace(
                "material = \"concrete\"\nsize",
                "material = \"concret\"\nsize",
            ),
            "did you mean \"concrete\"",
        ),
        (
            good.replace("supports = \"pinned\"", "supports = \"clamped\""),
            "supports",
        ),
        (
            good.replace("load_ramp = 0.25", "load_rmp = 0.25"),
            "load_ramp",
        ),
        (
            format!("{good}\n[[fix]]\nbody = \"beam\"\nbox = [[0,0,0],[1,1,1]]\n"),
            "top_load",
        ),
    ];
    for (text, expected) in cases {
        let error = qdem_io::scene::Scene::parse(&text, std::path::Path::new("beam.toml"))
            .expect_err(expected)
            .to_string();
        assert!(error.contains(expected), "{expected:?} not in: {error}");
        assert!(error.contains("beam.toml"), "no file in: {error}");
    }
}

#[test]
fn periodic_and_time_delay_mistakes_are_named() {
    let periodic = format!("{BASE}\n[periodic]\naxes = \"yy\"\nlength = [0.7]\n");
    let (_, msg) = error(&periodic);
    assert_has(&msg, &[PATH, "[periodic]", "axes = \"yy\"", "at most once"]);
    let periodic = format!("{BASE}\n[periodic]\naxes = \"xy\"\nlength = [0.7]\n");
    let (_, msg) = error(&periodic);
    assert_has(
        &msg,
        &["[periodic]", "length has 1 entries", "one period per axis"],
    );
    let delayed = format!(
        "{BASE}\n[periodic]\naxes = \"y\"\nlength = [0.7]\n\n[periodic.time_delay]\nbody = \"beam\"\n"
    );
    let (_, msg) = error(&delayed);
    assert_has(
        &msg,
        &["[periodic.time_delay]", "carries no [[load]] with `cyclic`"],
    );
    let both = with(
        "ramp = [[0.0, 0.0], [1.0, 1.0]]",
        "ramp = [[0.0, 0.0], [1.0, 1.0]]\ncyclic = { min = 0.1, max = 1.0, frequency = 0.0 }",
    );
    let (_, msg) = error(&both);
    assert_has(
        &msg,
        &["[[load]] #1", "frequency", "either `ramp` or `cyclic`"],
    );
}

#[test]
fn granular_unknown_shape_and_grading_basis_list_the_valid_ones() {
    let generated = format!(
        "{BASE}\n[contact]\nnormal_stiffness = 1e6\ntangential_stiffness = 1e6\n\n[granular]\n\
         name = \"ballast\"\nmaterial = \"concrete\"\nregion = [[0, 0, 0], [0.3, 0.7, 1.0]]\n\
         count = 10\ngrading = [[0.05, 0.0], [0.1, 1.0]]\n"
    );
    for (key, bad, valid) in [
        ("shape", "blocky", "`elongated`, `angular`"),
        ("grading_basis", "volume", "`number`, `mass`"),
    ] {
        let (err, msg) = error(&format!("{generated}{key} = \"{bad}\"\n"));
        assert!(matches!(err, SceneError::Schema(_)));
        assert_has(
            &msg,
            &[
                &format!("`{bad}`"),
                &format!("`{key}` in [granular]"),
                &format!("valid values: {valid}"),
            ],
        );
    }
    // The valid values parse, and the defaults are today's.
    let fine = format!("{generated}shape = \"angular\"\ngrading_basis = \"mass\"\n");
    for (text, expected) in [
        (&fine, (ClumpShapeName::Angular, GradingBasisName::Mass)),
        (
            &generated,
            (ClumpShapeName::Elongated, GradingBasisName::Number),
        ),
    ] {
        let g = Scene::parse(text, Path::new(PATH))
            .unwrap()
            .granular
            .unwrap();
        assert_eq!((g.shape, g.grading_basis), expected);
    }
}

#[test]
fn granular_mistakes_are_named() {
    let granular = format!(
        "{BASE}\n[granular]\nname = \"ballast\"\nmaterial = \"granit\"\nregion = [[0, 0, 0], [0.3, 0.7, 1.0]]\n"
    );
    let (_, msg) = error(&granular);
    assert_has(
        &msg,
        &[
            "[granular] \"ballast\"",
            "material \"granit\" is not defined",
            "add a [contact] table",
            "needs all of `region`, `count` and `grading`",
        ],
    );
    let rest = with("reorder = true", "reorder = true\nrest_on = \"ballast\"");
    let (_, msg) = error(&rest);
    assert_has(
        &msg,
        &[
            "scene.toml:22:11: [[body]] \"beam\"",
            "rest_on = \"ballast\" needs a [granular] sample of that name",
            "rest_on needs the body's contact_radius",
        ],
    );
    let posed = with(
        "reorder = true",
        "reorder = true\nrest_on = \"ballast\"\npose_from = \"poses.csv\"",
    );
    let (_, msg) = error(&posed);
    assert_has(
        &msg,
        &[
            "pose_from places rigid bodies only",
            "pose_from and rest_on both place the body; keep one",
        ],
    );
    let options = with(
        "reorder = true",
        "reorder = true\npose_body = \"sleeper2\"\npose_shift = [0.0, 0.7, 0.0]",
    );
    let (_, msg) = error(&options);
    assert_has(
        &msg,
        &[
            "pose_body chooses a pose of a `pose_from` file; give pose_from or drop pose_body",
            "pose_shift chooses a pose",
        ],
    );
    let copies = format!(
        "{BASE}\n[granular]\nname = \"ballast\"\nmaterial = \"concrete\"\nregion = [[0, 0, 0], [0.3, 0.7, 1.0]]\ncount = 10\ngrading = [[0.05, 0.0], [0.1, 1.0]]\ncopies = [[0.0, 0.7, 0.0]]\n"
    );
    let (_, msg) = error(&copies);
    assert_has(
        &msg,
        &["copies repeats the stones of a `sample` file; give one or drop copies"],
    );
    let rotation = with("dofs = \"xyz\"", "dofs = \"xyz\"\nrotation = true");
    let (_, msg) = error(&rotation);
    assert_has(&msg, &["[[fix]] #1", "rotation = true", "is not rigid"]);
}

#[test]
fn a_section_needs_one_axis_a_finite_plane_and_contacts() {
    let bad = with(
        "[output]",
        "[[section]]\nname = \"face\"\naxis = \"xy\"\nat = nan\n\n[output]",
    );
    let (_, msg) = error(&bad);
    assert_has(
        &msg,
        &[
            "scene.toml:41:8: [[section]] \"face\": axis = \"xy\": name the one axis",
            "[[section]] \"face\": `at` must be a finite number, not NaN",
            "measures contact forces, but the scene has no [contact]",
        ],
    );
}

#[test]
fn initial_motion_keys_and_grain_probes_are_checked_by_name() {
    // A body's angular velocity: finite, three components.
    let (_, msg) = error(&with(
        "reorder = true",
        "reorder = true\nangular_velocity = [0.0, nan, 1.0]",
    ));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:22:",
            "[[body]] \"beam\": `angular_velocity` must be a finite number, not NaN",
        ],
    );
    let (_, msg) = error(&with(
        "reorder = true",
        "reorder = true\nangular_velocity = [0.0, 1.0]",
    ));
    assert_has(
        &msg,
        &["scenes/scene.toml:22:", "angular_velocity", "length"],
    );
    // [granular]: finite motion, the region_ forms only with a generation.
    let granular = format!(
        "{BASE}\n[contact]\nnormal_stiffness = 1e6\ntangential_stiffness = 1e6\n\n[granular]\n\
         name = \"grains\"\nmaterial = \"concrete\"\nsample = \"stones.csv\"\n\
         velocity = [inf, 0.0, 0.0]\nangular_velocity = [0.0, 0.0, nan]\n\
         region_velocity = [0.0, 0.0, -1.0]\n\n[[probe]]\nname = \"grain\"\nbody = \"grains\"\n\
         stone = 0\nbox = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]\n\n[[probe]]\nname = \"bad\"\n\
         body = \"beam\"\nstone = 2\n"
    );
    let (_, msg) = error(&granular);
    assert_has(
        &msg,
        &[
            "[granular] \"grains\": `velocity` must be a finite number, not inf",
            "[granular] \"grains\": `angular_velocity` must be a finite number, not NaN",
            "region_velocity sets the generated stones' motion, but nothing is generated",
            "[[probe]] \"grain\": a probe on the [granular] sample \"grains\" takes one of",
            "stone = 0: stones are counted from 1",
            "[[probe]] \"bad\": `stone` picks stones of the [granular] sample",
            "give `point`, the place on the body to sample",
        ],
    );
}

// ---- messages that name the real cause (issue 56) ----------------------------------------

#[test]
fn a_subnormal_dt_is_refused_as_such_naming_run_dt() {
    // 1e-320 s is positive, so the positivity check passed it, and the run then blamed the
    // materials' density and young for a step they did not set.
    let (_, msg) = error(&with("dt = \"auto\"", "dt = 1e-320"));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:3:6:",
            "[run]: dt = 1e-320 s is subnormal",
            "fix: give dt = \"auto\"",
        ],
    );
    assert!(!msg.contains("density"), "{msg}");
    // The smallest normal step is a step (a run of it is refused later for its step count).
    let smallest = format!("dt = {:e}", f64::MIN_POSITIVE);
    Scene::parse(&with("dt = \"auto\"", &smallest), Path::new(PATH)).unwrap();
}

#[test]
fn each_non_finite_run_key_is_named_as_itself() {
    // A Newmark scene, so that beta and gamma are read; each key in turn set to NaN and to
    // infinity must be named itself, on its own line (gamma was named `beta`).
    let newmark = with(
        "integrator = \"verlet\"",
        "integrator = \"newmark\"\nbeta = 0.25\ngamma = 0.5",
    )
    .replace("dt = \"auto\"", "dt = 1e-4");
    let keys = [
        ("t_end", "t_end = 2.0"),
        ("dt", "dt = 1e-4"),
        ("beta", "beta = 0.25"),
        ("gamma", "gamma = 0.5"),
        ("probe_every", "probe_every = 1e-4"),
        ("dt_safety", "dt_safety = 0.9"),
    ];
    for (key, line) in keys {
        let row = newmark
            .lines()
            .position(|l| l == line)
            .expect("the key's line")
            + 1;
        for bad in ["nan", "inf", "-inf"] {
            let text = newmark.replacen(line, &format!("{key} = {bad}"), 1);
            let (_, msg) = error(&text);
            let shown = if bad == "nan" { "NaN" } else { bad };
            assert_has(
                &msg,
                &[
                    &format!("scenes/scene.toml:{row}:"),
                    &format!("[run]: `{key}` must be a finite number, not {shown}"),
                ],
            );
            for (other, _) in keys.iter().filter(|(k, _)| *k != key) {
                assert!(
                    !msg.contains(&format!("`{other}`")),
                    "{key} = {bad}:\n{msg}"
                );
            }
        }
    }
    // A cyclic load's factors: each named by its own key.
    for key in ["min", "max", "phase_deg", "start"] {
        let mut cyclic = [
            ("min", "0.1"),
            ("max", "1.0"),
            ("phase_deg", "0.0"),
            ("start", "0.0"),
        ]
        .map(|(k, v)| (k, v.to_string()));
        cyclic.iter_mut().find(|(k, _)| *k == key).unwrap().1 = "nan".into();
        let fields: Vec<String> = cyclic.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        let text = with(
            "ramp = [[0.0, 0.0], [1.0, 1.0]]",
            &format!("cyclic = {{ {}, frequency = 10.0 }}", fields.join(", ")),
        );
        let (_, msg) = error(&text);
        assert_has(
            &msg,
            &[&format!(
                "[[load]] #1: `cyclic.{key}` must be a finite number, not NaN"
            )],
        );
    }
}

#[test]
fn newmark_parameters_with_another_integrator_are_refused() {
    // BASE steps with Verlet: a beta or gamma there does nothing.
    let (_, msg) = error(&with(
        "integrator = \"verlet\"",
        "integrator = \"verlet\"\nbeta = 0.25\ngamma = 0.6",
    ));
    assert_has(
        &msg,
        &[
            "scenes/scene.toml:5:8: [run]: beta is a parameter of integrator = \"newmark\" only",
            "scenes/scene.toml:6:9: [run]: gamma is a parameter of integrator = \"newmark\" only",
            "with integrator = \"verlet\" (the default) it does nothing",
            "fix: add integrator = \"newmark\" to [run]",
        ],
    );
    let (_, msg) = error(&with(
        "integrator = \"verlet\"",
        "integrator = \"static\"\ngamma = 0.5",
    ));
    assert_has(
        &msg,
        &[
            "[run]: gamma is a parameter",
            "integrator = \"static\" it does",
        ],
    );
    assert!(!msg.contains("beta"), "{msg}");
    // Given with Newmark they are read.
    let newmark = with(
        "integrator = \"verlet\"",
        "integrator = \"newmark\"\nbeta = 0.0\ngamma = 0.5",
    );
    Scene::parse(&newmark, Path::new(PATH)).unwrap();
}

#[test]
fn a_granular_generation_of_zero_stones_is_refused() {
    let granular = format!(
        "{BASE}\n[contact]\nnormal_stiffness = 1e6\ntangential_stiffness = 1e6\n\n[granular]\n\
         name = \"grains\"\nmaterial = \"concrete\"\nregion = [[0, 0, 0], [0.3, 0.7, 1.0]]\n\
         count = 0\ngrading = [[0.05, 0.0], [0.1, 1.0]]\n"
    );
    let (_, msg) = error(&granular);
    assert_has(
        &msg,
        &[
            "[granular] \"grains\": count = 0 generates no stone",
            "fix: give count >= 1",
        ],
    );
    let one = granular.replace("count = 0", "count = 1");
    Scene::parse(&one, Path::new(PATH)).unwrap();
}

#[test]
fn a_negative_rolling_friction_is_refused_at_its_key() {
    let scene = format!(
        "{BASE}\n[contact]\nnormal_stiffness = 1e6\ntangential_stiffness = 1e6\n\
         rolling_friction = -0.1\n\n[granular]\nname = \"ballast\"\nmaterial = \"concrete\"\n\
         region = [[0, 0, 0], [0.3, 0.7, 1.0]]\ncount = 10\ngrading = [[0.05, 0.0], [0.1, 1.0]]\n"
    );
    let line = BASE.lines().count() + 5;
    let (_, msg) = error(&scene);
    assert_has(
        &msg,
        &[
            &format!("scenes/scene.toml:{line}:20:"),
            "[contact]: rolling_friction = -0.1",
            "must not be negative",
        ],
    );
}
