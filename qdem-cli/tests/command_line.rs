//! The command line itself: `--help` lists the five commands and each command's flags,
//! `--version` prints the version, and `qdem bench` takes its comma-separated lists and prints
//! the JSON document whose keys `docs/BENCHMARKS.md` is made from.

use std::process::{Command, Output};

fn qdem(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_qdem"))
        .args(args)
        .env("CI", "1")
        .output()
        .expect("start the qdem binary")
}

/// Stdout of a command that must succeed with nothing on stderr.
fn success(args: &[&str]) -> String {
    let out = qdem(args);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "qdem {args:?} failed ({}):\n{stderr}\n{stdout}",
        out.status
    );
    assert!(
        stderr.is_empty(),
        "qdem {args:?} wrote on stderr:\n{stderr}"
    );
    stdout
}

#[test]
fn help_lists_the_five_commands() {
    for help in [&["--help"][..], &["-h"], &["help"]] {
        let stdout = success(help);
        for command in ["run", "check", "verify", "bench", "analyze"] {
            assert!(
                stdout
                    .lines()
                    .any(|l| l.trim_start().starts_with(&format!("{command} "))
                        && l.trim().len() > command.len() + 10),
                "qdem {help:?} does not list `{command}` with its description:\n{stdout}"
            );
        }
    }
}

#[test]
fn each_command_has_help_with_its_flags() {
    let flags: [(&str, &[&str]); 5] = [
        ("run", &["SCENE", "--out", "--threads", "--resume"]),
        ("check", &["SCENE", "--threads"]),
        ("verify", &["--json", "--full", "--out"]),
        (
            "bench",
            &["--json", "--tets", "--threads", "--steps", "--implicit"],
        ),
        (
            "analyze",
            &["SCENE", "--out", "--from", "--to", "--bandwidth", "--fmax"],
        ),
    ];
    for (command, flags) in flags {
        for help in [vec![command, "--help"], vec!["help", command]] {
            let stdout = success(&help);
            assert!(
                stdout.starts_with(|c: char| c.is_alphabetic()),
                "qdem {help:?} does not start with a description:\n{stdout}"
            );
            for flag in flags {
                assert!(
                    stdout.contains(flag),
                    "qdem {help:?} does not mention {flag}:\n{stdout}"
                );
            }
        }
    }
}

#[test]
fn version_prints_the_version() {
    let stdout = success(&["--version"]);
    assert_eq!(stdout.trim(), format!("qdem {}", env!("CARGO_PKG_VERSION")));
}

/// `--formulation averaged-pressure` measures the averaged-pressure tetrahedron (issue 62:
/// `qdem bench` measured the standard one only), whose step does the standard kernel's work
/// and its strain pass and averages: more floating-point operations and modelled bytes per
/// tet-step than the standard tetrahedron's on the same block.
#[test]
fn bench_measures_the_averaged_pressure_tetrahedron() {
    let rows = |formulation: &str| {
        let args = [
            "bench",
            "--json",
            "--tets",
            "750",
            "--threads",
            "1",
            "--steps",
            "3",
        ];
        let stdout = success(&[&args[..], &["--formulation", formulation]].concat());
        let doc: serde_json::Value = serde_json::from_str(&stdout).expect("JSON");
        doc["results"].as_array().expect("results").clone()
    };
    let (standard, averaged) = (rows("standard"), rows("averaged-pressure"));
    assert_eq!(averaged.len(), 2, "elastic and viscoelastic: {averaged:?}");
    for (s, a) in standard.iter().zip(&averaged) {
        assert_eq!(a["formulation"], "averaged-pressure", "{a}");
        assert_eq!(
            (s["material"].clone(), s["tets"].clone()),
            (a["material"].clone(), a["tets"].clone())
        );
        for key in ["flops_per_tet_step", "bytes_per_tet_step"] {
            let (s, a) = (s[key].as_f64().unwrap(), a[key].as_f64().unwrap());
            assert!(a > 1.2 * s, "{key}: averaged {a} against standard {s}");
        }
    }
}

#[test]
fn bench_times_stones_as_one_body_beside_a_cube_of_as_many_tetrahedra() {
    // 20 stones: the 16 fine stones of the ballast fixture, then the first 4 again, as one
    // body; their tetrahedra are the fixture table's `tets_fine` (stones.csv).
    let table = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../fixtures/ballast/stones/stones.csv"
    ))
    .expect("stones.csv");
    let fine: Vec<u64> = table
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .nth(1)
                .and_then(|t| t.parse().ok())
                .expect("tets_fine")
        })
        .collect();
    assert_eq!(fine.len(), 16);
    let want: u64 = (0..20).map(|k| fine[k % 16]).sum();
    let stdout = success(&[
        "bench",
        "--json",
        "--stones",
        "20",
        "--threads",
        "1",
        "--steps",
        "2",
    ]);
    let doc: serde_json::Value = serde_json::from_str(&stdout)
        .unwrap_or_else(|e| panic!("stdout is not JSON ({e}):\n{stdout}"));
    assert_eq!(doc["locality"].as_array().map(Vec::len), Some(0), "{doc:#}");
    let prefetch = std::env::var("QDEM_PREFETCH").as_deref() != Ok("0");
    assert_eq!(doc["prefetch"].as_bool(), Some(prefetch), "{doc:#}");
    let rows = doc["results"].as_array().expect("results");
    // (stones, cube) x (elastic, viscoelastic) x 1 thread count.
    assert_eq!(rows.len(), 4, "{doc:#}");
    let number = |row: &serde_json::Value, key: &str| row[key].as_f64().expect(key);
    for (stones, cube) in rows[..2].iter().zip(&rows[2..]) {
        assert_eq!(
            (&stones["body"], &cube["body"]),
            (&"stones".into(), &"cube".into())
        );
        assert_eq!(stones["material"], cube["material"]);
        assert_eq!(stones["tets"].as_u64(), Some(want), "{stones}");
        // The cube is the nearest of 6 n^3 tetrahedra: within half a cell layer of the total.
        let ratio = number(cube, "tets") / want as f64;
        assert!((0.85..1.15).contains(&ratio), "{cube}");
        // Small stones have far more particles per tetrahedron than the cube (0.4 against
        // 0.2 at this size), so the model gives them more bytes per tet-step.
        let per_tet = |row| number(row, "particles") / number(row, "tets");
        assert!(
            per_tet(stones) > 0.35 && per_tet(cube) < 0.25,
            "{stones}\n{cube}"
        );
        assert!(number(stones, "bytes_per_tet_step") > number(cube, "bytes_per_tet_step"));
        assert!(number(stones, "tet_steps_per_second") > 0.0);
    }
}

#[test]
fn bench_takes_comma_separated_lists() {
    let stdout = success(&[
        "bench",
        "--json",
        "--tets",
        "750,1500",
        "--threads",
        "1,2",
        "--steps",
        "3",
    ]);
    let doc: serde_json::Value = serde_json::from_str(&stdout)
        .unwrap_or_else(|e| panic!("stdout is not JSON ({e}):\n{stdout}"));
    for key in [
        "locality",
        "machine",
        "triad_bandwidth_bytes_per_second",
        "results",
    ] {
        assert!(doc.get(key).is_some(), "no `{key}` in {doc:#}");
    }
    let results = doc["results"].as_array().expect("results is an array");
    // 2 sizes x (elastic, viscoelastic) x 2 thread counts.
    assert_eq!(results.len(), 8, "{doc:#}");
    for row in results {
        assert_eq!(row["steps"], 3, "{row}");
        assert_eq!(row["formulation"], "standard", "{row}");
        for key in [
            "tets",
            "particles",
            "material",
            "threads",
            "seconds",
            "tet_steps_per_second",
            "particle_steps_per_second",
            "bytes_per_tet_step",
            "fraction_of_triad_bandwidth",
        ] {
            assert!(row.get(key).is_some(), "row without `{key}`: {row}");
        }
    }
    let threads: Vec<u64> = results
        .iter()
        .filter_map(|r| r["threads"].as_u64())
        .collect();
    assert!(threads.contains(&1) && threads.contains(&2), "{doc:#}");
    // Structured, shuffled, reordered (reverse Cuthill-McKee) and blocked.
    let orderings: Vec<&str> = doc["locality"]
        .as_array()
        .expect("locality is an array")
        .iter()
        .filter_map(|row| row["ordering"].as_str())
        .collect();
    assert_eq!(
        orderings,
        ["structured", "shuffled", "reordered", "blocked"],
        "{doc:#}"
    );
}

#[test]
fn check_names_each_bodys_kind_and_what_limits_the_step() {
    let fixtures = concat!(env!("CARGO_MANIFEST_DIR"), "/../fixtures/ballast/");
    let limit = |line: &str, out: &str| -> f64 {
        let at = out
            .find(line)
            .unwrap_or_else(|| panic!("no `{line}` in\n{out}"));
        let rest = &out[at + line.len()..];
        rest.split_whitespace().next().unwrap().parse().unwrap()
    };
    let deformable = success(&[
        "check",
        &format!("{fixtures}stiff_deposit.toml"),
        "--threads",
        "1",
    ]);
    let rigid = success(&[
        "check",
        &format!("{fixtures}stiff_deposit_rigid.toml"),
        "--threads",
        "1",
    ]);
    let sleeper = "step limit of body `sleeper`: deformable, its tetrahedra bound the step at ";
    let stones = "step limit of body `ballast`: deformable, its tetrahedra bound the step at ";
    let contacts = "step limit of the contacts: ";
    // The same sleeper either way; rigid stones have no bound of their own, and their
    // contacts act on whole stones instead of vertex particles, so they allow a longer step.
    assert_eq!(limit(sleeper, &deformable), limit(sleeper, &rigid));
    assert!(limit(stones, &deformable) > 0.0);
    assert!(rigid.contains("step limit of body `ballast`: 105 rigid stones, no bound of their own"));
    assert!(rigid.contains("rigid stones): 1993 particles"), "{rigid}");
    assert!(limit(contacts, &rigid) > 5.0 * limit(contacts, &deformable));
}

/// `qdem check` prints the modelling advice in its report, and `--advice json` the same
/// advice alone as a JSON array: the cantilever is held at its clamp (deformable), locks not
/// at ν = 0.167 (standard), and its release at 2 s excites its first mode fully, so Newmark
/// is advised over Verlet; the collision's cubes are impacted (deformable, with a contact
/// stiffness told); the grains of `fixtures/contact/grains.toml`, a `[granular]` set, are
/// advised as a set.
#[test]
fn check_prints_the_advice_and_json_gives_it_to_scripts() {
    let fixtures = concat!(env!("CARGO_MANIFEST_DIR"), "/../fixtures/");
    let cantilever = format!("{fixtures}cantilever/cantilever_lc100.toml");
    let report = success(&["check", &cantilever, "--threads", "1"]);
    for line in [
        "advice body `beam` (rigid or deformable): keep deformable: its fixes hold every rigid motion",
        "advice body `beam` (formulation): keep standard: poisson = 0.167 < 0.45",
        "advice run (integrator): verlet -> newmark: dynamic",
    ] {
        assert!(report.contains(line), "no `{line}` in\n{report}");
    }
    let json = success(&["check", &cantilever, "--advice", "json"]);
    let doc: serde_json::Value = serde_json::from_str(&json).unwrap();
    let topics: Vec<&str> = doc
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["topic"].as_str().unwrap())
        .collect();
    assert_eq!(topics, ["rigidity", "formulation", "integrator"], "{json}");
    assert_eq!(doc[2]["advised"], "newmark");
    assert!(doc[2]["figures"]["advised_dt"].as_f64().unwrap() > 0.0);
    let collision = format!("{fixtures}contact/collision.toml");
    let doc: serde_json::Value =
        serde_json::from_str(&success(&["check", &collision, "--advice", "json"])).unwrap();
    let advice = doc.as_array().unwrap();
    assert!(advice.iter().any(|a| a["subject"] == "contacts"), "{doc:#}");
    assert!(advice
        .iter()
        .any(|a| a["subject"] == "body `left`" && a["advised"] == "deformable"));
    let grains = format!("{fixtures}contact/grains.toml");
    let report = success(&["check", &grains, "--threads", "1"]);
    let line = "advice [granular] `grains` (rigid or deformable): ";
    assert!(report.contains(line), "no `{line}` in\n{report}");
}

#[test]
fn check_prints_the_rayleigh_time_beside_the_contacts_step_and_a_pours_settled_run_time() {
    // 2,000 grains of diameter 9–11 mm (E = 50 MPa, ν = 0.25, ρ = 2,500 kg/m³) on a loose
    // lattice: the smallest's Rayleigh time is π r √(ρ/G)/(0.1631 ν + 0.8766) = 1.7231e-4 s.
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../fixtures/contact/grains.toml"
    );
    let out = success(&["check", scene, "--threads", "1"]);
    let number = |after: &str| -> f64 {
        let at = out
            .find(after)
            .unwrap_or_else(|| panic!("no `{after}` in\n{out}"));
        let rest = &out[at + after.len()..];
        let word = rest.split_whitespace().next().unwrap();
        word.trim_end_matches([',', ';']).parse().unwrap()
    };
    let r = 0.0045;
    let shear: f64 = 5e7 / (2.0 * 1.25);
    let expected = std::f64::consts::PI * r * (2500.0 / shear).sqrt() / (0.1631 * 0.25 + 0.8766);
    let rayleigh = number("Rayleigh time of the smallest sphere: ");
    assert!(
        (rayleigh / expected - 1.0).abs() < 1e-4,
        "{rayleigh} vs {expected}"
    );
    let fifth = number("LIGGGHTS's and EDEM's users usually take: ");
    assert!((fifth / (0.2 * expected) - 1.0).abs() < 1e-4, "{fifth}");
    assert!(number("step limit of the contacts: ") > 0.0);
    // No grain touches yet: the measured step is a lower bound of a poured bed's, stated so,
    // with the run time at a settled bed's 6 contacts per grain beside it.
    assert!(out.contains("estimated run time at least "), "{out}");
    let settled =
        "the step was measured with 0 contacts; as a bed settles to about 6000 (6 per grain)";
    assert!(out.contains(settled), "{out}");
}
