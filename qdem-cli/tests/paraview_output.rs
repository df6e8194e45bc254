//! The ParaView outputs of issue 25, read back by meshio (`read_run_with_meshio.py`):
//! - a granular run (the small box test's bed: clumps falling into a periodic cell with walls)
//!   writes spheres, contact lines and walls beside the bodies at every `vtu_every`, one entry
//!   per sphere, contact and wall triangle; the contact lines' forces sum, per sphere, to the
//!   contact force the model applied, to round-off; the files are the same bytes on 1 and 2
//!   threads;
//! - a ballast deposit, a bonded beam and the cantilever write files meshio reads, with one
//!   entry per tetrahedron, bond and sphere;
//! - a run killed while it writes a VTU at every step leaves only whole VTU files;
//! - `scripts/render.py` draws a run where pvpython is installed (skipped elsewhere).

mod common;
use common::{run, workspace, TempDir};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

const QDEM: &str = env!("CARGO_BIN_EXE_qdem");

/// `fixtures/DIR/NAME` copied to `tmp` with the `(from, to)` edits and its relative mesh and
/// stone paths made absolute.
fn scene(tmp: &Path, dir: &str, name: &str, edits: &[(&str, &str)]) -> PathBuf {
    let fixtures = workspace().join("fixtures").join(dir);
    let text = std::fs::read_to_string(fixtures.join(name)).expect("read the fixture");
    // `"REL` becomes `"/…/fixtures/DIR/REL`.
    let at = |rel: &str| format!("\"{}/{rel}", fixtures.display());
    let text = text
        .replace("mesh = \"", &format!("mesh = {}", at("")))
        .replace("\"stones/", &at("stones/"));
    let text = edits.iter().fold(text, |text, (from, to)| {
        assert!(text.contains(from), "{name} has no `{from}`");
        text.replacen(from, to, 1)
    });
    let path = tmp.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// What `read_run_with_meshio.py` reads of `out`; fails (never skips) without meshio.
fn read_back(out: &Path) -> Value {
    let script = workspace().join("qdem-cli/tests/read_run_with_meshio.py");
    let output = Command::new("python3")
        .arg(script)
        .arg(out)
        .output()
        .expect("python3 is required");
    assert!(
        output.status.success(),
        "meshio could not read {} (pip install meshio):\n{}",
        out.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("one JSON object")
}

/// The files of `report` whose name starts with `vtu/KIND`.
fn files<'a>(report: &'a Value, kind: &str) -> Vec<(&'a String, &'a Value)> {
    let prefix = format!("vtu/{kind}");
    let all = report["files"].as_object().expect("files");
    all.iter().filter(|(n, _)| n.starts_with(&prefix)).collect()
}

/// The number of cells of `cell_type` in a file's report.
fn cells(file: &Value, cell_type: &str) -> u64 {
    file["cells"][cell_type].as_u64().unwrap_or(0)
}

/// Every array of a file has one entry per point (`point_data`) or cell (`cell_data`), and
/// its values are finite.
fn assert_consistent(name: &str, file: &Value) {
    let points = file["points"].as_u64().unwrap();
    let count: u64 = file["cells"]
        .as_object()
        .unwrap()
        .values()
        .map(|c| c.as_u64().unwrap())
        .sum();
    for (array, shape) in file["point_data"].as_object().unwrap() {
        assert_eq!(shape[0].as_u64().unwrap(), points, "{name}: {array}");
    }
    for (array, blocks) in file["cell_data"].as_object().unwrap() {
        let total: u64 = blocks
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b[0].as_u64().unwrap())
            .sum();
        assert_eq!(total, count, "{name}: {array}");
    }
    assert_eq!(file["finite"], true, "{name}: non-finite values");
}

/// The bed of the small box test, its stones starting lower and run for 0.2 s: 52 clumps of
/// one or two spheres falling in a periodic cell onto a floor between two walls.
fn granular_scene(tmp: &Path, vtu_every: &str) -> PathBuf {
    let output = format!("[output]\nvtu_every = {vtu_every}");
    let edits = [
        ("t_end = 0.8", "t_end = 0.2"),
        ("[0.3, 1.4, 1.6]", "[0.3, 1.4, 0.82]"),
        ("[output]", output.as_str()),
    ];
    scene(tmp, "boxtest", "small_deposit_cell_bed.toml", &edits)
}

#[test]
fn a_granular_run_writes_spheres_contacts_and_walls_whose_forces_sum_to_the_applied_ones() {
    let tmp = TempDir::new("paraview-granular");
    let scene = granular_scene(tmp.path(), "0.05");
    let mut vtus = Vec::new();
    for threads in [1, 2] {
        let out = tmp.path().join(format!("out{threads}"));
        run(&scene, &out, threads);
        let mut names: Vec<_> = std::fs::read_dir(out.join("vtu"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        names.sort();
        vtus.push(
            names
                .iter()
                .map(|p| std::fs::read(p).unwrap())
                .collect::<Vec<_>>(),
        );
    }
    assert!(
        vtus[0] == vtus[1],
        "the VTU files differ between 1 and 2 threads"
    );

    let out = tmp.path().join("out2");
    let report = read_back(&out);
    assert_eq!(report["times"], 5, "t = 0, 0.05, …, 0.2");
    let stones = std::fs::read_to_string(out.join("stones.csv")).unwrap();
    let spheres = stones.lines().count() as u64 - 1;
    for (name, file) in report["files"].as_object().unwrap() {
        assert_consistent(name, file);
    }
    for (name, file) in files(&report, "spheres") {
        assert_eq!(file["points"], spheres, "{name}: one point per sphere");
        assert_eq!(cells(file, "vertex"), spheres, "{name}");
        assert_eq!(file["part"], 1);
    }
    let contacts = files(&report, "contacts");
    assert_eq!(contacts.len(), 5);
    let lines: Vec<u64> = contacts.iter().map(|(_, f)| cells(f, "line")).collect();
    assert!(lines[4] >= 10, "stones touch by the end: {lines:?}");
    for (name, file) in &contacts {
        assert_eq!(
            file["points"].as_u64().unwrap(),
            2 * cells(file, "line"),
            "{name}"
        );
    }
    let walls = files(&report, "walls");
    assert_eq!(walls.len(), 1, "still walls are written once");
    assert_eq!(
        cells(walls[0].1, "triangle"),
        2 * 3,
        "three plane walls, two triangles each"
    );
    // The same contributions the model gathered, summed in another order (and by numpy):
    // a few ulps of the largest force.
    let sums = report["force_sums"].as_array().unwrap();
    assert_eq!(sums.len(), 5);
    for s in sums {
        let (error, largest) = (s["error"].as_f64().unwrap(), s["largest"].as_f64().unwrap());
        assert!(error <= 1e-12 * largest.max(1e-300), "{s}");
    }
    assert!(sums[4]["largest"].as_f64().unwrap() > 0.0);
}

#[test]
fn ballast_bonded_and_cantilever_runs_write_files_meshio_reads_entry_for_entry() {
    let tmp = TempDir::new("paraview-runs");
    let runs = [
        scene(
            tmp.path(),
            "ballast",
            "reduced_deposit.toml",
            &[
                ("t_end = 0.5", "t_end = 0.002"),
                ("vtu_every = 0.05", "vtu_every = 0.001"),
            ],
        ),
        scene(
            tmp.path(),
            "bbm",
            "small_beam.toml",
            &[("[output]", "[output]\nvtu_every = 1e-3")],
        ),
        scene(
            tmp.path(),
            "cantilever",
            "cantilever_lc100.toml",
            &[
                ("t_end = 3.0", "t_end = 0.02"),
                ("vtu_every = 0.05", "vtu_every = 0.01"),
            ],
        ),
    ];
    for scene in &runs {
        let out = tmp.path().join(scene.file_stem().unwrap());
        run(scene, &out, 2);
        let report = read_back(&out);
        let summary: Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(
            report["times"],
            3,
            "{}: t = 0 and two more",
            scene.display()
        );
        for (name, file) in report["files"].as_object().unwrap() {
            assert_consistent(name, file);
        }
        for (name, file) in files(&report, "state") {
            assert_eq!(
                cells(file, "tetra"),
                summary["tets"],
                "{name}: one cell per tet"
            );
            assert_eq!(file["part"], 0, "the bodies stay part 0");
        }
        let name = scene.file_stem().unwrap().to_str().unwrap();
        match name {
            "small_beam" => {
                for (file, bonds) in files(&report, "bonds") {
                    assert_eq!(cells(bonds, "line"), summary["bonded"]["bonds"], "{file}");
                    assert_eq!(bonds["points"], summary["particles"], "{file}");
                }
            }
            "reduced_deposit" => {
                assert_eq!(files(&report, "spheres").len(), 3);
                assert!(files(&report, "walls").len() == 1);
                for s in report["force_sums"].as_array().unwrap() {
                    let (e, f) = (s["error"].as_f64().unwrap(), s["largest"].as_f64().unwrap());
                    assert!(e <= 1e-12 * f.max(1e-300), "{s}");
                }
            }
            _ => assert_eq!(report["files"].as_object().unwrap().len(), 3, "tets only"),
        }
    }
}

#[test]
fn a_run_killed_while_writing_vtu_files_leaves_only_whole_ones() {
    let tmp = TempDir::new("paraview-kill");
    // A VTU time at every step: the run spends most of its time writing them.
    let scene = granular_scene(tmp.path(), "1e-9");
    let out = tmp.path().join("out");
    for (round, wait) in [40u64, 65, 90, 115, 140].into_iter().enumerate() {
        let mut child = Command::new(QDEM)
            .arg("run")
            .arg(&scene)
            .arg("--out")
            .arg(&out)
            .env("CI", "1")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(wait + 7 * round as u64));
        child.kill().unwrap();
        child.wait().unwrap();
        let Ok(entries) = std::fs::read_dir(out.join("vtu")) else {
            continue;
        };
        for entry in entries {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if name.starts_with('.') {
                continue; // the killed write's temporary, removed by the next run's start
            }
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(text.ends_with("</VTKFile>\n"), "{name} is cut short");
        }
    }
    assert!(
        out.join("vtu").is_dir(),
        "the runs got as far as writing VTU files"
    );
}

#[test]
fn render_py_draws_a_cantilever_and_a_crack_where_pvpython_is_installed() {
    let render = workspace().join("scripts/render.py");
    let tmp = TempDir::new("paraview-render");
    let cases = [
        (
            "cantilever",
            "cantilever",
            "cantilever_lc100.toml",
            "t_end = 3.0",
            "t_end = 0.01",
        ),
        (
            "bbm",
            "bbm",
            "small_beam.toml",
            "[output]",
            "[output]\nvtu_every = 1e-3",
        ),
    ];
    for (kind, dir, name, from, to) in cases {
        let scene = scene(tmp.path(), dir, name, &[(from, to)]);
        let out = tmp.path().join(kind);
        run(&scene, &out, 2);
        let png = tmp.path().join(format!("{kind}.png"));
        let done = Command::new("python3")
            .arg(&render)
            .args([kind, out.to_str().unwrap(), png.to_str().unwrap()])
            .stdout(Stdio::null())
            .output()
            .expect("python3 is required");
        let said = String::from_utf8_lossy(&done.stderr);
        if done.status.code() == Some(77) {
            eprintln!("skipped: {}", said.trim());
            return;
        }
        assert!(
            done.status.success(),
            "render.py {kind} failed: {}\n{said}",
            done.status
        );
        let bytes = std::fs::read(&png).unwrap();
        assert!(
            bytes.starts_with(b"\x89PNG") && bytes.len() > 5000,
            "{kind}.png"
        );
    }
}

/// A `pvpython` that dies of a segmentation fault as Debian's does when asked for
/// `--force-offscreen-rendering` without an X server: render.py says why and exits 77 (skip),
/// so the test command passes on such a machine.
#[test]
#[cfg(unix)]
fn render_py_skips_with_77_when_pvpython_cannot_render() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = TempDir::new("paraview-crash");
    let fake = tmp.path().join("pvpython");
    std::fs::write(&fake, "#!/bin/sh\nkill -SEGV $$\n").unwrap();
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    let path = format!(
        "{}:{}",
        tmp.path().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let done = Command::new("python3")
        .arg(workspace().join("scripts/render.py"))
        .args(["cantilever", "no-such-run", "never.png"])
        .env("PATH", path)
        .env_remove("DISPLAY")
        .env_remove("QDEM_RENDER_UNDER_PVPYTHON")
        .output()
        .expect("python3 is required");
    let said = String::from_utf8_lossy(&done.stderr);
    assert_eq!(done.status.code(), Some(77), "{said}");
    assert!(
        said.contains("cannot render here") && said.contains("SIGSEGV"),
        "{said}"
    );
}
