//! Bad input through the `qdem` binary: every case must end with a non-zero exit status and one
//! clean message on stderr that starts with `error: `, names the offending file (and the line,
//! element id or key where there is one), says what to do, and is not a panic.
//!
//! The scenes and meshes live in `fixtures/bad/`; each scene refers to its mesh by a path
//! relative to the scene file.

mod common;
use common::{variant, workspace, TempDir};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const QDEM: &str = env!("CARGO_BIN_EXE_qdem");

/// A file of `fixtures/bad/`, as an absolute path.
fn bad(name: &str) -> PathBuf {
    workspace().join("fixtures/bad").join(name)
}

/// Runs `qdem ARGS` in `cwd` (the workspace root when `None`).
fn qdem_in<S: AsRef<OsStr>>(cwd: Option<&Path>, args: &[S]) -> Output {
    let root = workspace();
    Command::new(QDEM)
        .args(args)
        .current_dir(cwd.unwrap_or(&root))
        .env("CI", "1")
        .output()
        .expect("start the qdem binary")
}

fn qdem<S: AsRef<OsStr>>(args: &[S]) -> Output {
    qdem_in(None, args)
}

/// Phrases by which a message tells the user what to do.
const ADVICE: &[&str] = &[
    "fix:",
    "did you mean",
    "use ",
    "give ",
    "add ",
    "check ",
    "resolved relative to",
    // clap's usage errors: the usage line and where the help is.
    "Usage:",
    "try '--help'",
];

/// Asserts a clean failure: non-zero exit (1, not a panic's 101), stderr starting with
/// `error: ` that contains every string of `needles`, says what to do, and has no panic. Returns
/// stderr.
fn assert_clean_error(what: &str, out: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let context = format!("{what}\n--- stderr ---\n{stderr}\n--- stdout ---\n{stdout}");
    assert!(
        !out.status.success(),
        "{what}: expected a failure, got success\n{context}"
    );
    assert!(
        !stderr.contains("panicked"),
        "{what}: the program panicked\n{context}"
    );
    assert_eq!(
        out.status.code(),
        Some(1),
        "{what}: expected exit status 1\n{context}"
    );
    assert!(
        stderr.starts_with("error: "),
        "{what}: stderr does not start with `error: `\n{context}"
    );
    for needle in needles {
        assert!(
            stderr.contains(needle),
            "{what}: stderr does not contain {needle:?}\n{context}"
        );
    }
    assert!(
        ADVICE.iter().any(|a| stderr.contains(a)),
        "{what}: stderr does not say what to do (none of {ADVICE:?})\n{context}"
    );
    stderr
}

/// The 1-based line of `file` that contains `text` outside comments (exactly one line must).
fn line_of(file: &Path, text: &str) -> usize {
    let content = std::fs::read_to_string(file).expect("read the fixture");
    let lines: Vec<usize> = content
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim_start().starts_with('#') && l.contains(text))
        .map(|(i, _)| i + 1)
        .collect();
    assert_eq!(
        lines.len(),
        1,
        "{text:?} must appear on exactly one line of {}",
        file.display()
    );
    lines[0]
}

/// Runs `qdem check SCENE` and `qdem run SCENE --out DIR`; both must fail with the same
/// clean message containing `needles`, `check` must print nothing on stdout and `run` must not
/// create its output directory. Returns the message of `check`.
fn check_and_run(scene: &Path, needles: &[&str]) -> String {
    let check = qdem(&[OsStr::new("check"), scene.as_os_str()]);
    let message = assert_clean_error(&format!("qdem check {}", scene.display()), &check, needles);
    assert!(
        check.stdout.is_empty(),
        "qdem check {} printed on stdout although the scene is bad:\n{}",
        scene.display(),
        String::from_utf8_lossy(&check.stdout)
    );

    let tmp = TempDir::new("run");
    let out_dir = tmp.path().join("out");
    let run = qdem(&[
        OsStr::new("run"),
        scene.as_os_str(),
        OsStr::new("--out"),
        out_dir.as_os_str(),
    ]);
    let run_message = assert_clean_error(&format!("qdem run {}", scene.display()), &run, needles);
    assert!(
        run_message.ends_with(&message),
        "qdem run and qdem check report the same problem differently:\ncheck: {message}\nrun: {run_message}"
    );
    assert!(
        !out_dir.exists(),
        "qdem run created its output directory for a bad scene"
    );
    message
}

// ---------------------------------------------------------------------------------------------
// Meshes
// ---------------------------------------------------------------------------------------------

#[test]
fn truncated_mesh_names_file_and_line() {
    let scene = bad("truncated_mesh.toml");
    let mesh = scene.parent().unwrap().join("truncated_elements.msh");
    // The file ends in the middle of line 501 (500 complete lines, then a partial element).
    let text = std::fs::read_to_string(&mesh).unwrap();
    assert!(!text.ends_with('\n') && text.contains("$Elements") && !text.contains("$EndElements"));
    let last_line = text.lines().count();
    let at = format!("{}:{last_line}", mesh.display());
    check_and_run(&scene, &[&at, "truncated", "fix:"]);
}

#[test]
fn hexahedron_mesh_names_file_element_and_type() {
    let scene = bad("hexahedron_mesh.toml");
    let mesh = scene.parent().unwrap().join("../msh/bad_hexahedron.msh");
    let path = mesh.display().to_string();
    check_and_run(
        &scene,
        &[
            &path,
            "element 10",
            "Hexahedron",
            "type 5",
            "tetrahedra",
            "fix:",
        ],
    );
}

#[test]
fn missing_physical_group_lists_the_available_groups() {
    let scene = bad("missing_group.toml");
    let mesh = scene
        .parent()
        .unwrap()
        .join("../cantilever/cantilever_lc100.msh");
    let path = mesh.display().to_string();
    let scene_path = scene.display().to_string();
    let message = check_and_run(
        &scene,
        &[
            &scene_path,
            "[[fix]] #1",
            &path,
            "`clmap`",
            "did you mean `clamp`",
            "available",
            "fix:",
        ],
    );
    for group in ["`clamp`", "`tip`", "`beam`", "`tip_centre`"] {
        assert!(
            message.contains(group),
            "the available group {group} is not listed:\n{message}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Scene files
// ---------------------------------------------------------------------------------------------

#[test]
fn unknown_scene_key_has_line_and_suggestion() {
    let scene = bad("unknown_key.toml");
    let line = line_of(&scene, "t_ned");
    let at = format!("{}:{line}:", scene.display());
    check_and_run(
        &scene,
        &[&at, "unknown key `t_ned`", "[run]", "did you mean `t_end`"],
    );
}

#[test]
fn poisson_ratio_of_one_half_is_refused() {
    let scene = bad("poisson_half.toml");
    let line = line_of(&scene, "poisson = 0.5");
    let at = format!("{}:{line}:", scene.display());
    check_and_run(&scene, &[&at, "poisson = 0.5", "below 0.5", "use 0.49"]);
}

#[test]
fn negative_density_is_refused() {
    let scene = bad("negative_density.toml");
    let line = line_of(&scene, "density = -2350.0");
    let at = format!("{}:{line}:", scene.display());
    check_and_run(
        &scene,
        &[
            &at,
            "density = -2350",
            "must be positive",
            "give a value above 0",
        ],
    );
}

#[test]
fn time_step_above_the_stable_bound_gives_bound_and_auto() {
    let scene = bad("dt_too_large.toml");
    let path = scene.display().to_string();
    let message = check_and_run(&scene, &[&path, "dt = 1e-3", "stable bound", "\"auto\""]);
    // The bound is a number of seconds, a few microseconds on the lc100 mesh.
    let bound: f64 = message
        .split("stable bound ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|word| word.parse().ok())
        .unwrap_or_else(|| panic!("no number after `stable bound` in:\n{message}"));
    assert!(
        (1e-6..1e-5).contains(&bound),
        "stable bound {bound} s is not in [1e-6, 1e-5) s for the lc100 cantilever:\n{message}"
    );
}

#[test]
fn scene_file_that_does_not_exist() {
    let scene = bad("no_such_scene.toml");
    assert!(!scene.exists());
    let path = scene.display().to_string();
    for command in ["check", "run"] {
        let out = qdem(&[OsStr::new(command), scene.as_os_str()]);
        assert_clean_error(
            &format!("qdem {command} {path}"),
            &out,
            &[&path, "cannot read the scene file"],
        );
    }
}

#[test]
fn mesh_file_that_does_not_exist_names_the_resolved_path() {
    let scene = bad("missing_mesh.toml");
    let resolved = scene.parent().unwrap().join("no_such_mesh.msh");
    assert!(!resolved.exists());
    let line = line_of(&scene, "no_such_mesh.msh");
    let at = format!("{}:{line}:", scene.display());
    let resolved = resolved.display().to_string();
    check_and_run(&scene, &[&at, &resolved, "does not exist"]);

    // With a relative scene path the message still names a path that leads to the mesh's
    // location from the working directory.
    let dir = scene.parent().unwrap();
    let out = qdem_in(Some(dir), &["check", "missing_mesh.toml"]);
    let message = assert_clean_error(
        "qdem check missing_mesh.toml (relative)",
        &out,
        &["missing_mesh.toml"],
    );
    let named = message
        .split("mesh file ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .unwrap_or_else(|| panic!("no `mesh file PATH` in:\n{message}"));
    assert!(
        dir.join(named)
            .components()
            .eq(dir.join("no_such_mesh.msh").components()),
        "named path {named:?}, taken from the working directory {}, is not the mesh's path",
        dir.display()
    );
}

// ---------------------------------------------------------------------------------------------
// Command lines
// ---------------------------------------------------------------------------------------------

/// A valid scene, so that only the command line is wrong.
fn good_scene() -> PathBuf {
    workspace().join("fixtures/cantilever/cantilever_lc100.toml")
}

#[test]
fn no_command() {
    let out = qdem::<&str>(&[]);
    assert_clean_error(
        "qdem",
        &out,
        &[
            "no command given",
            "Usage: qdem <COMMAND>",
            "  run ",
            "  analyze ",
        ],
    );
}

#[test]
fn unknown_command() {
    let out = qdem(&["frobnicate"]);
    assert_clean_error(
        "qdem frobnicate",
        &out,
        &["unrecognized subcommand 'frobnicate'", "Usage: qdem"],
    );
}

#[test]
fn verify_and_bench_refuse_stray_arguments() {
    for command in ["verify", "bench"] {
        let out = qdem(&[command, "foo"]);
        let usage = format!("Usage: qdem {command}");
        assert_clean_error(
            &format!("qdem {command} foo"),
            &out,
            &["unexpected argument 'foo' found", &usage],
        );
    }
}

#[test]
fn run_and_check_without_a_scene() {
    for command in ["run", "check"] {
        let out = qdem(&[command]);
        let usage = format!("Usage: qdem {command}");
        assert_clean_error(
            &format!("qdem {command}"),
            &out,
            &[
                "the following required arguments were not provided",
                "<SCENE>",
                &usage,
            ],
        );
    }
    let out = qdem(&["check", "a.toml", "b.toml"]);
    assert_clean_error(
        "qdem check a.toml b.toml",
        &out,
        &["unexpected argument 'b.toml' found", "Usage: qdem check"],
    );
}

#[test]
fn a_bad_qdem_team_value() {
    // The persistent team of threads is opt-in through the environment: a value other than
    // 0 and 1 is refused before anything is written.
    let tmp = TempDir::new("team");
    let out_dir = tmp.path().join("out");
    let scene = good_scene();
    for command in ["run", "check"] {
        let out = Command::new(QDEM)
            .args([OsStr::new(command), scene.as_os_str()])
            .args(
                [OsStr::new("--out"), out_dir.as_os_str()]
                    .into_iter()
                    .take(match command {
                        "run" => 2,
                        _ => 0,
                    }),
            )
            .current_dir(workspace())
            .env("CI", "1")
            .env("QDEM_TEAM", "yes")
            .output()
            .expect("start the qdem binary");
        let what = format!("QDEM_TEAM=yes qdem {command} SCENE");
        assert_clean_error(&what, &out, &["QDEM_TEAM=\"yes\"", "give 1", "0"]);
        assert!(!out_dir.exists(), "{what} created its output directory");
    }
}

#[test]
fn zero_threads() {
    let tmp = TempDir::new("threads0");
    let out_dir = tmp.path().join("out");
    let scene = good_scene();
    let run = qdem(&[
        OsStr::new("run"),
        scene.as_os_str(),
        OsStr::new("--threads"),
        OsStr::new("0"),
        OsStr::new("--out"),
        out_dir.as_os_str(),
    ]);
    assert_clean_error(
        "qdem run SCENE --threads 0",
        &run,
        &["--threads", "'0'", "positive", "1 or more"],
    );
    assert!(
        !out_dir.exists(),
        "qdem run --threads 0 created its output directory"
    );
    let check = qdem(&[
        OsStr::new("check"),
        scene.as_os_str(),
        OsStr::new("--threads"),
        OsStr::new("0"),
    ]);
    assert_clean_error(
        "qdem check SCENE --threads 0",
        &check,
        &["--threads", "'0'", "positive"],
    );
    let word = qdem(&[
        OsStr::new("check"),
        scene.as_os_str(),
        OsStr::new("--threads"),
        OsStr::new("two"),
    ]);
    assert_clean_error(
        "qdem check SCENE --threads two",
        &word,
        &["--threads", "'two'", "positive"],
    );
}

#[test]
fn unknown_option() {
    let scene = good_scene();
    let out = qdem(&[
        OsStr::new("run"),
        scene.as_os_str(),
        OsStr::new("--frobnicate"),
    ]);
    assert_clean_error(
        "qdem run SCENE --frobnicate",
        &out,
        &[
            "unexpected argument '--frobnicate' found",
            "Usage: qdem run",
        ],
    );
    let out = qdem(&["verify", "--out", "x"]);
    assert_clean_error(
        "qdem verify --out x",
        &out,
        &[
            "the following required arguments were not provided",
            "--full",
            "Usage: qdem verify",
        ],
    );
}

#[test]
fn analyze_refuses_negative_and_non_numeric_values() {
    let scene = good_scene();
    for (flag, value) in [("--from", "-1"), ("--to", "soon"), ("--bandwidth", "inf")] {
        let out = qdem(&[
            OsStr::new("analyze"),
            scene.as_os_str(),
            OsStr::new(flag),
            OsStr::new(value),
        ]);
        let needle = format!("invalid value '{value}' for '{flag} ");
        assert_clean_error(
            &format!("qdem analyze SCENE {flag} {value}"),
            &out,
            &[&needle, "finite number >= 0"],
        );
    }
}

#[test]
fn bench_refuses_a_zero_in_a_list() {
    let out = qdem(&["bench", "--tets", "1000,0"]);
    assert_clean_error(
        "qdem bench --tets 1000,0",
        &out,
        &["invalid value '0' for '--tets <N,..>'", "positive"],
    );
}

#[test]
fn option_without_its_value() {
    let scene = good_scene();
    let out = qdem(&[OsStr::new("run"), scene.as_os_str(), OsStr::new("--out")]);
    assert_clean_error(
        "qdem run SCENE --out",
        &out,
        &["a value is required for '--out <DIR>'"],
    );
}

/// `--thread-list` once passed bench's check of allowed options and reached `unreachable!`; it
/// must be refused as an unknown argument.
#[test]
fn bench_thread_list_is_an_error_not_a_panic() {
    let out = qdem(&["bench", "--thread-list", "2"]);
    assert_clean_error(
        "qdem bench --thread-list 2",
        &out,
        &[
            "unexpected argument '--thread-list' found",
            "Usage: qdem bench",
        ],
    );
}

#[test]
fn zero_contact_stiffness_is_refused_on_its_line() {
    let scene = bad("contact_zero_stiffness.toml");
    let line = line_of(&scene, "normal_stiffness = 0.0");
    check_and_run(
        &scene,
        &[
            &format!("contact_zero_stiffness.toml:{line}:"),
            "must be positive",
        ],
    );
}

#[test]
fn contact_radius_larger_than_the_body_is_refused() {
    check_and_run(
        &bad("contact_radius_too_large.toml"),
        &[
            "body `block`",
            "contact_radius = 0.06",
            "at most 5.0000e-2 m",
        ],
    );
}

#[test]
fn hertz_mindlin_with_spring_constants_is_refused() {
    check_and_run(
        &bad("contact_hertz_with_stiffness.toml"),
        &["hertz-mindlin takes its stiffness", "young and poisson"],
    );
}

#[test]
fn rigid_body_with_newmark_is_refused() {
    check_and_run(
        &bad("rigid_newmark.toml"),
        &["rigid bodies are integrated by integrator = \"verlet\" only"],
    );
}

#[test]
fn interpenetrating_bodies_are_refused_before_the_run() {
    check_and_run(
        &bad("contact_overlap.toml"),
        &[
            "bodies `left` and `right` overlap by 5.000e-3 m",
            "move them apart",
            "in this scene: [[body]] `translate` or `contact_radius`; or a larger [contact] \
             `overlap_tolerance` (now 0.05)",
        ],
    );
}

// ---------------------------------------------------------------------------------------------
// Values that pass every range check but cannot run (issue 38)
// ---------------------------------------------------------------------------------------------

#[test]
fn a_time_step_that_underflows_to_zero_is_refused_with_its_cause() {
    let tmp = TempDir::new("zero-dt");
    for (edit, value) in [
        (("density = -2350.0", "density = 1e-295"), "density 1e-295"),
        (("young = 45e9", "young = 1e308"), "young 1e308"),
    ] {
        let mut edits = vec![edit];
        if edit.0 != "density = -2350.0" {
            edits.push(("density = -2350.0", "density = 2350.0"));
        }
        let scene = variant("bad/negative_density.toml", &edits, &tmp);
        check_and_run(
            &scene,
            &[
                "dt = 0e0 s",
                "zero, subnormal or not finite",
                value,
                "fix: check the materials' density and young",
            ],
        );
    }
}

#[test]
fn a_step_count_that_does_not_fit_or_a_step_that_does_not_advance_t_is_refused() {
    let tmp = TempDir::new("steps");
    let good = ("density = -2350.0", "density = 2350.0");
    let huge_end = variant(
        "bad/negative_density.toml",
        &[good, ("t_end = 0.01", "t_end = 1e300")],
        &tmp,
    );
    check_and_run(
        &huge_end,
        &["t_end = 1e300 s", "more than 2^53", "t + dt == t", "fix:"],
    );
    let tiny_step = variant(
        "bad/negative_density.toml",
        &[good, ("dt = \"auto\"", "dt = 1e-300")],
        &tmp,
    );
    check_and_run(
        &tiny_step,
        &[
            "dt = 1.0000e-300 s (as given in [run] dt)",
            "1.000e298 steps",
            "fix: give a shorter t_end or a larger dt (at least 1.110e-18 s)",
        ],
    );
}

#[test]
fn counts_of_ten_to_the_twelve_are_refused_with_the_memory_they_need() {
    let tmp = TempDir::new("counts");
    let cases = [
        (
            "contact/grains.toml",
            ("count = 2000", "count = 1000000000000"),
            "[granular] count = 1000000000000 stones",
            "fix: lower count",
        ),
        (
            "ballast/reduced_deposit.toml",
            ("count = 170", "count = 1000000000000"),
            "[ballast] count = 1000000000000 stones",
            "fix: lower count",
        ),
        (
            "bbm/small_beam.toml",
            ("element_size = 0.05", "element_size = 1e-9"),
            "element_size = 1e-9 m",
            "fix: give a smaller size or a larger element_size",
        ),
        (
            "bbm/small_beam.toml",
            ("size = [1.0, 0.2]", "size = [1e300, 0.2]"),
            "size = [1e300, 2e-1] m",
            "fix: give a smaller size or a larger element_size",
        ),
    ];
    for (fixture, edit, what, fix) in cases {
        let scene = variant(fixture, &[edit], &tmp);
        let message = check_and_run(
            &scene,
            &[what, "particles would need about", "of memory", fix],
        );
        // The memory is named with its unit and is far above any machine's.
        let need = message
            .split("would need about ")
            .nth(1)
            .expect("the memory needed");
        assert!(need.contains("TiB"), "{message}");
    }
}

#[test]
fn newmark_with_gamma_below_one_half_is_refused_naming_gamma() {
    let tmp = TempDir::new("gamma");
    let scene = variant(
        "bbm/small_beam.toml",
        &[("gamma = 0.5", "gamma = 0.3")],
        &tmp,
    );
    let line = line_of(&scene, "gamma = 0.3");
    let at = format!("{}:{line}:", scene.display());
    check_and_run(
        &scene,
        &[
            &at,
            "gamma = 0.3 is below 1/2",
            "negative",
            "fix: use gamma = 0.5",
        ],
    );
}

#[test]
fn bench_sizes_beyond_the_memory_are_refused_with_their_memory_before_any_work() {
    // 10^12 tetrahedra once panicked in the mesh generator ("too many nodes", exit 101).
    let out = qdem(&["bench", "--tets", "1000,1000000000000"]);
    let message = assert_clean_error(
        "qdem bench --tets 1000,1000000000000",
        &out,
        &[
            "--tets 1000000000000: a block of ",
            "nodes would need about",
            "TiB of memory, more than",
            "fix: give a smaller --tets",
        ],
    );
    assert!(out.stdout.is_empty(), "measured before refusing: {message}");
    let out = qdem(&["bench", "--implicit", "--tets", "50000000"]);
    assert_clean_error(
        "qdem bench --implicit --tets 50000000",
        &out,
        &["with its Cholesky factor (", "of memory, more than"],
    );
    // 2 x 10^8 tetrahedra under a 4 GiB address space once aborted allocating 14.4 GB
    // (exit 134): refused against the limit (or a lower one), whatever the machine's memory.
    let limited = Command::new("sh")
        .args([
            "-c",
            "ulimit -v 4194304 && exec \"$0\" bench --tets 200000000",
            QDEM,
        ])
        .env("CI", "1")
        .output()
        .expect("start sh");
    assert_clean_error(
        "qdem bench --tets 200000000 under ulimit -v 4194304",
        &limited,
        &["--tets 200000000: a block of ", "GiB of memory, more than"],
    );
}

#[test]
fn a_thread_count_far_beyond_the_cores_is_refused_at_once() {
    let scene = good_scene();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let most = (8 * cores).to_string();
    // 100000 threads once spent a minute starting in silence.
    let cases: [(&str, Vec<&OsStr>); 3] = [
        (
            "run",
            vec![
                OsStr::new("run"),
                scene.as_os_str(),
                OsStr::new("--threads"),
                OsStr::new("100000"),
            ],
        ),
        (
            "check",
            vec![
                OsStr::new("check"),
                scene.as_os_str(),
                OsStr::new("--threads"),
                OsStr::new("100000"),
            ],
        ),
        (
            "bench",
            vec![
                OsStr::new("bench"),
                OsStr::new("--threads"),
                OsStr::new("1,100000"),
            ],
        ),
    ];
    for (what, args) in cases {
        let out = qdem(&args);
        assert_clean_error(
            &format!("qdem {what} --threads 100000"),
            &out,
            &[
                "invalid value '100000' for '--threads",
                "threads is more than 8 per core of the",
                &format!("give at most {most}"),
            ],
        );
    }
}
// ---------------------------------------------------------------------------------------------
// Messages that name the real cause (issue 56)
// ---------------------------------------------------------------------------------------------

/// A negative count was taken by clap for an unknown flag, with the tip to write `-- -1`,
/// which would make it the scene's name; it must be refused as a count, naming the flag.
#[test]
fn a_negative_count_is_refused_as_a_count_not_a_flag() {
    let scene = good_scene();
    let scene = scene.to_str().expect("a UTF-8 path");
    let cases: [&[&str]; 6] = [
        &["run", scene, "--threads", "-1"],
        &["run", scene, "--stop-after", "-5"],
        &["run", scene, "--stop-after", "0"],
        &["check", scene, "--threads", "-2"],
        &["modes", scene, "--count", "-1"],
        &["bench", "--tets", "-3"],
    ];
    for args in cases {
        let (flag, value) = (args[args.len() - 2], args[args.len() - 1]);
        let what = format!("qdem {}", args.join(" "));
        let message = assert_clean_error(
            &what,
            &qdem(args),
            &[
                &format!("invalid value '{value}' for '{flag} <N"),
                "give a positive whole number",
            ],
        );
        assert!(!message.contains("tip"), "{what}:\n{message}");
    }
    let message = assert_clean_error(
        "qdem bench --threads 2,-1",
        &qdem(&["bench", "--threads", "2,-1"]),
        &[
            "invalid value '-1' for '--threads <N,..>'",
            "positive whole",
        ],
    );
    assert!(!message.contains("tip"), "{message}");
}

/// A file that starts like a checkpoint but holds random bytes after the magic was reported
/// as "format version 2142358983632637349"; a file that does not start with it is named too.
#[test]
fn a_start_checkpoint_that_is_not_one_is_named_as_such() {
    let tmp = TempDir::new("garbage-start");
    let garbage = tmp.path().join("garbage.qdc");
    // Bytes from a fixed linear congruential sequence (the probe's were random).
    let mut x: u64 = 0x2545_f491_4f6c_dd1d;
    let mut bytes = b"QDEMCKPT".to_vec();
    bytes.extend((0..400).map(|_| {
        x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        (x >> 33) as u8
    }));
    std::fs::write(&garbage, &bytes).expect("write the garbage file");
    let text = tmp.path().join("text.qdc");
    std::fs::write(&text, "t,tip.ux\n0,0\n").expect("write the text file");
    for (file, needles) in [
        (
            &garbage,
            &[
                "is not a qdem checkpoint: it starts with the bytes QDEMCKPT",
                "which no qdem writes",
                "fix: give a checkpoint.qdc that a qdem run wrote",
            ][..],
        ),
        (
            &text,
            &[
                "is not a qdem checkpoint (it does not start with the bytes QDEMCKPT",
                "fix: give the checkpoint.qdc that a qdem run wrote",
            ][..],
        ),
    ] {
        let start = format!("probe_every = 1e-3\nstart_from = \"{}\"", file.display());
        let scene = variant(
            "contact/incline.toml",
            &[("probe_every = 1e-3", &start)],
            &tmp,
        );
        let message = check_and_run(&scene, needles);
        assert!(!message.contains("has format version"), "{message}");
    }
}

/// A scene that nothing bounds the step of (a rigid block falling, no contact) with
/// `dt = "auto"` was told "dt = inf s is above the stable bound inf s ...; use dt = \"auto\"".
#[test]
fn an_automatic_step_that_nothing_bounds_is_explained() {
    let tmp = TempDir::new("no-bound");
    let scene = variant(
        "contact/incline.toml",
        &[
            ("contact_radius = 0.01\n", ""),
            (
                "[contact]\nlaw = \"linear\"\nnormal_stiffness = 1e7\ntangential_stiffness = 1e7\n\
                 friction = 0.3\ndamping_ratio = 0.05\n\n[[wall]]\npoint = [0.0, 0.0, 0.0]\n\
                 normal = [-0.422618262, 0.0, 0.906307787]\n",
                "",
            ),
        ],
        &tmp,
    );
    let message = check_and_run(
        &scene,
        &[
            "dt = \"auto\" cannot choose a step: no model of the scene bounds it",
            "fix: give [run] dt in seconds",
        ],
    );
    assert!(!message.contains("inf s"), "{message}");
    // With a dt the same scene runs.
    let given = variant(
        "contact/incline.toml",
        &[
            ("contact_radius = 0.01\n", ""),
            ("t_end = 0.4", "t_end = 0.01\ndt = 1e-3"),
            (
                "[contact]\nlaw = \"linear\"\nnormal_stiffness = 1e7\ntangential_stiffness = 1e7\n\
                 friction = 0.3\ndamping_ratio = 0.05\n\n[[wall]]\npoint = [0.0, 0.0, 0.0]\n\
                 normal = [-0.422618262, 0.0, 0.906307787]\n",
                "",
            ),
        ],
        &tmp,
    );
    let out = tmp.path().join("out");
    let done = qdem(&[
        OsStr::new("run"),
        given.as_os_str(),
        OsStr::new("--out"),
        out.as_os_str(),
    ]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
}

/// `[bonded] critical_fraction` sets the step of a bonded scene: a fraction whose step is
/// above the rigorous bound is refused naming it, not with advice to use `dt = "auto"`.
#[test]
fn a_critical_fraction_above_the_bound_is_refused_naming_it() {
    let tmp = TempDir::new("critical");
    let scene = variant(
        "bbm/small_beam.toml",
        &[("critical_fraction = 0.2", "critical_fraction = 5.0")],
        &tmp,
    );
    let message = check_and_run(
        &scene,
        &[
            "[bonded]: critical_fraction = 5 gives dt = 5 x the bonds' critical step",
            "above the rigorous stable bound",
            "fix: give critical_fraction <= ",
        ],
    );
    assert!(!message.contains("\"auto\""), "{message}");
    // The fraction named gives a step within the bound: the scene passes `qdem check`.
    let named: f64 = message
        .split("critical_fraction <= ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|word| word.parse().ok())
        .unwrap_or_else(|| panic!("no fraction in:\n{message}"));
    let fitted = variant(
        "bbm/small_beam.toml",
        &[(
            "critical_fraction = 0.2",
            &format!("critical_fraction = {named}"),
        )],
        &tmp,
    );
    let check = qdem(&[OsStr::new("check"), fitted.as_os_str()]);
    assert!(
        check.status.success(),
        "critical_fraction = {named}:\n{}",
        String::from_utf8_lossy(&check.stderr)
    );
}

/// The blocks of `collision.toml` thrown at ±400 m/s, twice the rubber's wave speed
/// (√(5e7 / 1100) = 213 m/s): the report once asked for a smaller step; the speed is the cause.
#[test]
fn bodies_thrown_faster_than_their_wave_speed_are_reported_for_the_speed_not_the_step() {
    let tmp = TempDir::new("fast-tunnel");
    let scene = variant(
        "contact/collision.toml",
        &[
            ("velocity = [4.0, 0.0, 0.0]", "velocity = [400.0, 0.0, 0.0]"),
            (
                "velocity = [-1.0, 0.0, 0.0]",
                "velocity = [-400.0, 0.0, 0.0]",
            ),
        ],
        &tmp,
    );
    let out = tmp.path().join("out");
    let run = qdem(&[
        OsStr::new("run"),
        scene.as_os_str(),
        OsStr::new("--out"),
        out.as_os_str(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    // The pass-through check, at the first rebuild of the contact lists, sees the sphere
    // between the other body's spheres before the overlap watch does.
    for part in [
        "a body passes through",
        "the load, not the step, is the cause",
        "velocity (4.000e2 m/s) gives body",
        "a strain of 1.876e0",
        "fix: check the body's velocity",
    ] {
        assert!(stderr.contains(part), "{part:?} in:\n{stderr}");
    }
    assert!(!stderr.contains("fix: a smaller step"), "{stderr}");
}
