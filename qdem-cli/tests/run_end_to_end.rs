//! `qdem run` end to end on a short variant of the lc100 cantilever scene: the files it writes
//! (probes.csv, summary.json, results.pvd and the VTUs), the physics of the probe, the VTU read
//! back by meshio, and bit-identical probes for 1 and 2 threads.

use std::collections::HashMap;
mod common;
use common::{run, workspace, TempDir};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Probe columns of the scene's single probe `tip`.
const HEADER: &str =
    "time,tip.ux,tip.uy,tip.uz,tip.vx,tip.vy,tip.vz,tip.ax,tip.ay,tip.az,tip.wx,tip.wy,tip.wz";
/// The probe point of the scene (a mesh node lies exactly there).
const TIP: [f64; 3] = [2.4, 0.125, 0.11];
const PARTICLES: u64 = 352;
const TETS: u64 = 915;
const T_END: f64 = 0.02;
const PROBE_EVERY: f64 = 1e-3;
const VTU_EVERY: f64 = 0.01;

/// Replaces the one line of `text` that equals `from` (after trimming) by `to`.
fn replace_line(text: &str, from: &str, to: &str) -> String {
    let hits = text.lines().filter(|l| l.trim() == from).count();
    assert_eq!(
        hits, 1,
        "the cantilever scene must have exactly one line `{from}`"
    );
    text.lines()
        .map(|l| if l.trim() == from { to } else { l })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

/// Writes the short cantilever scene (t_end = 0.02 s) into `dir`, with the mesh path made
/// absolute; returns the scene path.
fn write_short_scene(dir: &Path, t_end: f64) -> PathBuf {
    let fixtures = workspace().join("fixtures/cantilever");
    let text = std::fs::read_to_string(fixtures.join("cantilever_lc100.toml"))
        .expect("read fixtures/cantilever/cantilever_lc100.toml");
    let mesh = fixtures.join("cantilever_lc100.msh");
    let mesh = mesh.to_str().expect("a UTF-8 workspace path");
    let mesh_line = format!("mesh = {}", toml_string(mesh));
    let text = replace_line(&text, "t_end = 3.0", &format!("t_end = {t_end:?}"));
    let text = replace_line(
        &text,
        "probe_every = 1e-4",
        &format!("probe_every = {PROBE_EVERY:e}"),
    );
    let text = replace_line(
        &text,
        "vtu_every = 0.05",
        &format!("vtu_every = {VTU_EVERY:?}"),
    );
    let text = replace_line(&text, "mesh = \"cantilever_lc100.msh\"", &mesh_line);
    let scene = dir.join("cantilever_short.toml");
    std::fs::write(&scene, text).expect("write the scene");
    scene
}

/// A TOML basic string.
fn toml_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The rows of a probe CSV, each as numbers, after checking the header.
fn probe_rows(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).expect("read probes.csv");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(HEADER), "probes.csv header");
    assert!(
        text.ends_with('\n'),
        "probes.csv does not end with a newline"
    );
    lines
        .enumerate()
        .map(|(i, line)| {
            let mut row: Vec<f64> = line
                .split(',')
                .map(|v| {
                    v.parse().unwrap_or_else(|_| {
                        panic!("probes.csv row {}: `{v}` is not a number", i + 1)
                    })
                })
                .collect();
            assert_eq!(row.len(), 13, "probes.csv row {}: `{line}`", i + 1);
            // A node of a deformable body has no rotation of its own: its ω is NaN.
            assert!(
                row[..10].iter().all(|v| v.is_finite()) && row[10..].iter().all(|v| v.is_nan()),
                "probes.csv row {}: `{line}`",
                i + 1
            );
            row.truncate(10);
            row
        })
        .collect()
}

/// `(timestep, file)` of every `<DataSet>` of a PVD file.
fn pvd_entries(path: &Path) -> Vec<(f64, String)> {
    let text = std::fs::read_to_string(path).expect("read results.pvd");
    assert!(text.contains("<VTKFile type=\"Collection\""), "{text}");
    let attr = |tag: &str, name: &str| -> String {
        let key = format!("{name}=\"");
        let start = tag
            .find(&key)
            .unwrap_or_else(|| panic!("no {name} in `{tag}`"))
            + key.len();
        let end = tag[start..].find('"').expect("closing quote") + start;
        tag[start..end].to_string()
    };
    text.split("<DataSet")
        .skip(1)
        .map(|tag| {
            let tag = &tag[..tag.find("/>").expect("<DataSet .../>")];
            let time = attr(tag, "timestep");
            (
                time.parse().unwrap_or_else(|_| panic!("timestep `{time}`")),
                attr(tag, "file"),
            )
        })
        .collect()
}

/// Every file or directory under `dir` whose name starts with `.`.
fn hidden_files(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).expect("list the output directory") {
        let path = entry.expect("directory entry").path();
        if path
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with('.'))
        {
            found.push(path.clone());
        }
        if path.is_dir() {
            found.extend(hidden_files(&path));
        }
    }
    found
}

fn summary(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("summary.json")).expect("read summary.json");
    serde_json::from_str(&text).expect("summary.json is JSON")
}

#[test]
fn short_cantilever_run_writes_complete_outputs() {
    let tmp = TempDir::new("outputs");
    let scene = write_short_scene(tmp.path(), T_END);
    let out = tmp.path().join("out");
    run(&scene, &out, 2);

    // summary.json
    let s = summary(&out);
    let number = |key: &str| -> f64 {
        s.get(key)
            .and_then(serde_json::Value::as_f64)
            .unwrap_or_else(|| panic!("summary.json has no number `{key}`: {s:#}"))
    };
    let integer = |key: &str| -> u64 {
        s.get(key)
            .and_then(serde_json::Value::as_u64)
            .unwrap_or_else(|| panic!("summary.json has no whole number `{key}`: {s:#}"))
    };
    let (steps, dt, t_end) = (integer("steps"), number("dt"), number("t_end"));
    assert_eq!(t_end, T_END);
    assert!(dt > 0.0 && dt < 1e-5, "dt = {dt}");
    assert!(steps > 0, "steps = {steps}");
    assert!(
        (steps as f64 * dt - T_END).abs() < 0.5 * dt,
        "steps * dt = {} is not t_end = {T_END}",
        steps as f64 * dt
    );
    assert!(number("wall_seconds") > 0.0);
    assert_eq!(integer("particles"), PARTICLES);
    assert_eq!(integer("tets"), TETS);
    assert!(number("tet_steps_per_second") > 0.0);
    assert_eq!(integer("threads"), 2);

    // probes.csv: t = 0, 0.001, ..., 0.02, each to within half a step.
    let rows = probe_rows(&out.join("probes.csv"));
    assert_eq!(rows.len(), 21, "probes.csv data rows");
    for (k, row) in rows.iter().enumerate() {
        let expected = k as f64 * PROBE_EVERY;
        assert!(
            (row[0] - expected).abs() <= 0.5 * dt,
            "probes.csv row {}: t = {} is not {expected} to within half a step ({dt})",
            k + 1,
            row[0]
        );
    }
    assert!(
        rows.windows(2).all(|w| w[1][0] > w[0][0]),
        "probes.csv times do not increase"
    );
    assert_eq!(
        rows[0][1..7],
        [0.0; 6],
        "at t = 0 the tip must be undisplaced and at rest"
    );

    // Physics: at t = 0.02 s the ramp gives 200 N x 0.02 = 4 N downward. The quasi-static tip
    // deflection for 4 N on this mesh is about -1.27 um (-63.4 um at 200 N); the dynamic
    // response starting from rest stays below twice that.
    let last = rows.last().unwrap();
    let uz = last[3];
    assert!(
        -3e-6 < uz && uz < 0.0,
        "tip uz at t = {} is {uz} m, expected in (-3 um, 0)",
        last[0]
    );

    // results.pvd: t = 0, 0.01, 0.02, every file present.
    let entries = pvd_entries(&out.join("results.pvd"));
    assert_eq!(entries.len(), 3, "results.pvd entries: {entries:?}");
    for (k, (time, file)) in entries.iter().enumerate() {
        let expected = k as f64 * VTU_EVERY;
        assert!(
            (time - expected).abs() <= 0.5 * dt,
            "results.pvd entry {k}: t = {time}, expected {expected}"
        );
        let path = out.join(file);
        assert!(
            path.is_file(),
            "{} (from results.pvd) does not exist",
            path.display()
        );
        assert!(file.ends_with(".vtu"), "{file}");
    }
    assert_eq!(
        entries.last().unwrap().0,
        last[0],
        "the last VTU and the last probe row are not the same state"
    );
    assert_eq!(integer("probe_rows"), 21);
    assert_eq!(integer("vtu_files"), 3);

    // Atomic writes leave no temporary `.NAME.tmp-PID` file behind.
    let hidden = hidden_files(&out);
    assert!(
        hidden.is_empty(),
        "temporary files left in the output: {hidden:?}"
    );
}

/// Fails (never skips) when meshio is missing: CI installs it.
fn require_meshio() {
    let ok = Command::new("python3")
        .args(["-c", "import meshio"])
        .output()
        .is_ok_and(|o| o.status.success());
    assert!(ok, "meshio is required: pip install meshio");
}

#[test]
fn last_vtu_reads_back_with_meshio_and_matches_the_probe() {
    require_meshio();
    let tmp = TempDir::new("meshio");
    let scene = write_short_scene(tmp.path(), T_END);
    let out = tmp.path().join("out");
    run(&scene, &out, 2);

    let rows = probe_rows(&out.join("probes.csv"));
    let last_row = rows.last().expect("probe rows");
    let entries = pvd_entries(&out.join("results.pvd"));
    let (time, file) = entries.last().expect("a VTU");
    assert_eq!(
        *time, last_row[0],
        "the last VTU and the last probe row are not the same state"
    );
    let vtu = out.join(file);

    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/read_vtu_with_meshio.py");
    let output = Command::new("python3")
        .arg(&script)
        .arg(&vtu)
        .args(TIP.map(|x| x.to_string()))
        .output()
        .expect("run python3");
    assert!(
        output.status.success(),
        "meshio could not read {}:\n{}",
        vtu.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_slice(&output.stdout).expect("the script prints JSON");
    let shape =
        |table: &str, name: &str| -> Option<serde_json::Value> { report[table].get(name).cloned() };

    assert_eq!(report["points"], PARTICLES, "{report:#}");
    assert_eq!(report["tetra"], TETS, "{report:#}");
    assert_eq!(
        report["other_cell_types"],
        serde_json::json!([]),
        "{report:#}"
    );
    for name in ["displacement", "velocity"] {
        assert_eq!(
            shape("point_data", name),
            Some(serde_json::json!([PARTICLES, 3])),
            "point_data `{name}`: {report:#}"
        );
    }
    for name in ["von_mises", "volumetric_strain"] {
        assert_eq!(
            shape("cell_data", name),
            Some(serde_json::json!([[TETS]])),
            "cell_data `{name}`: {report:#}"
        );
    }
    assert_eq!(report["cell_data_finite"], true, "{report:#}");
    // The probe particle is the nearest particle; a mesh node lies exactly at the point.
    assert_eq!(report["nearest_distance"], 0.0, "{report:#}");

    let u: Vec<f64> = report["nearest_displacement"]
        .as_array()
        .expect("a displacement")
        .iter()
        .map(|v| v.as_f64().expect("a number"))
        .collect();
    let probe = &last_row[1..4];
    for (axis, (a, b)) in u.iter().zip(probe).enumerate() {
        assert!(
            (a - b).abs() <= 1e-12 * a.abs().max(b.abs()),
            "displacement {} of the VTU point nearest {TIP:?} is {a}, probes.csv has {b}",
            ["ux", "uy", "uz"][axis]
        );
    }
}

#[test]
fn one_and_two_threads_give_identical_probes() {
    let tmp = TempDir::new("threads");
    let scene = write_short_scene(tmp.path(), T_END);
    let mut csv: HashMap<usize, Vec<u8>> = HashMap::new();
    for threads in [1, 2] {
        let out = tmp.path().join(format!("out{threads}"));
        run(&scene, &out, threads);
        assert_eq!(summary(&out)["threads"], threads, "summary.json threads");
        csv.insert(
            threads,
            std::fs::read(out.join("probes.csv")).expect("read probes.csv"),
        );
    }
    let (one, two) = (&csv[&1], &csv[&2]);
    assert!(one.len() > HEADER.len() + 1, "probes.csv has no rows");
    if one != two {
        let (a, b) = (String::from_utf8_lossy(one), String::from_utf8_lossy(two));
        let first = a.lines().zip(b.lines()).position(|(x, y)| x != y).map_or(
            "the line counts differ".to_string(),
            |i| {
                format!(
                    "line {}:\n  1 thread:  {}\n  2 threads: {}",
                    i + 1,
                    a.lines().nth(i).unwrap(),
                    b.lines().nth(i).unwrap()
                )
            },
        );
        panic!(
            "probes.csv differs between --threads 1 and --threads 2; first difference at {first}"
        );
    }
}

#[test]
fn contact_scene_gives_identical_outputs_for_1_and_2_threads() {
    // Two deformable cubes colliding and a rigid cube on a triangulated floor.
    let tmp = TempDir::new("contact-threads");
    let scene = workspace().join("fixtures/contact/collision.toml");
    let mut outputs = Vec::new();
    for threads in [1, 2] {
        let out = tmp.path().join(format!("out{threads}"));
        run(&scene, &out, threads);
        let csv = std::fs::read(out.join("probes.csv")).expect("read probes.csv");
        let last = pvd_entries(&out.join("results.pvd"))
            .last()
            .expect("a snapshot")
            .1
            .clone();
        let vtu = std::fs::read(out.join(&last)).expect("read the last VTU");
        outputs.push((csv, vtu));
    }
    assert!(outputs[0].0.len() > 1000, "probes.csv has rows");
    assert!(outputs[0] == outputs[1], "1 and 2 threads differ");
}

#[test]
fn bonded_beam_cracks_and_writes_its_crack_pattern_identically_on_1_and_2_threads() {
    // A 1 m bonded beam loaded suddenly far above its cracking load.
    let tmp = TempDir::new("bonded");
    let scene = workspace().join("fixtures/bbm/small_beam.toml");
    let mut outputs = Vec::new();
    for threads in [1, 2] {
        let out = tmp.path().join(format!("out{threads}"));
        run(&scene, &out, threads);
        let csv = std::fs::read(out.join("probes.csv")).expect("read probes.csv");
        let svg = std::fs::read_to_string(out.join("crack.svg")).expect("read crack.svg");
        outputs.push((csv, svg, summary(&out)));
    }
    let bonded = &outputs[0].2["bonded"];
    let broken = bonded["broken_bonds"].as_u64().expect("broken_bonds");
    assert!(broken > 0 && broken < bonded["bonds"].as_u64().unwrap());
    assert!(bonded["first_break_time"].as_f64().expect("a first break") > 0.0);
    assert_eq!(outputs[0].1.matches("<line").count() as u64, broken);
    assert!(
        outputs[0].0 == outputs[1].0,
        "probes differ between 1 and 2 threads"
    );
    assert!(
        outputs[0].1 == outputs[1].1,
        "crack patterns differ between 1 and 2 threads"
    );
}
