//! Ways a run went wrong without a word (issue 38), through the `qdem` binary: a second run
//! into a folder another run holds, a fresh run over an earlier run's files, two bodies that
//! pass through each other, and a mesh whose volumes share no nodes. The bad values that
//! cannot run (a zero step, counts of 10¹², Newmark γ < ½) are in `bad_input.rs`.

mod common;
use common::{variant, workspace, TempDir};
use std::ffi::OsStr;
use std::fmt::Write as _;
use std::path::Path;
use std::process::{Command, Output};

/// `qdem ARGS` from the workspace root.
fn qdem<S: AsRef<OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_qdem"))
        .args(args)
        .current_dir(workspace())
        .env("CI", "1")
        .output()
        .expect("start the qdem binary")
}

/// `qdem run SCENE --out OUT`.
fn run(scene: &Path, out: &Path) -> Output {
    qdem(&[
        OsStr::new("run"),
        scene.as_os_str(),
        OsStr::new("--out"),
        out.as_os_str(),
    ])
}

/// The stderr of a failed run, which must be one clean error (status 1, no panic) with each
/// of `needles`.
fn refused(out: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "expected a refusal:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "no {needle:?} in:\n{stderr}");
    }
    stderr
}

#[test]
fn a_second_run_into_a_held_folder_is_refused_and_a_lock_nobody_holds_is_taken_over() {
    let tmp = TempDir::new("lock");
    let out = tmp.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let scene = workspace().join("fixtures/contact/collision.toml");
    // A live holder: this process, which locks the file as a run does and names itself.
    let lock = out.join(".qdem-run.lock");
    let held = std::fs::File::create(&lock).unwrap();
    held.try_lock().expect("lock the file");
    std::fs::write(&lock, format!("{}\n", std::process::id())).unwrap();
    let message = refused(
        &run(&scene, &out),
        &[
            &format!("in use by another qdem run (pid {},", std::process::id()),
            "fix: wait for that run to end (or stop it: Ctrl-C or SIGTERM checkpoints it), or \
             give this one another --out",
        ],
    );
    assert!(message.contains(&lock.display().to_string()), "{message}");
    assert!(
        !out.join("probes.csv").exists(),
        "the refused run wrote into the held folder"
    );
    assert!(
        lock.exists(),
        "the refused run removed the holder's lock file"
    );
    // The holder ends (as one killed by SIGKILL: the kernel frees its lock) and leaves the file
    // behind, naming a process that runs (the sleep), or nothing: the lock is taken over.
    drop(held);
    let mut sleep = Command::new("sleep")
        .arg("60")
        .spawn()
        .expect("start sleep");
    for stale in [format!("{}\n", sleep.id()), String::new()] {
        std::fs::write(&lock, stale).unwrap();
        let done = run(&scene, &out);
        assert!(
            done.status.success(),
            "{}",
            String::from_utf8_lossy(&done.stderr)
        );
        assert!(!lock.exists(), "the lock outlived the run");
    }
    sleep.kill().unwrap();
    sleep.wait().unwrap();
}

/// Trials of two runs started at once into one folder whose lock file a run left behind:
/// empty, holding garbage, or the pid of a process that has ended (cycled).
const RACE_TRIALS: usize = 12;

#[test]
fn of_two_runs_started_at_once_over_any_stale_lock_one_runs_and_one_is_refused() {
    let tmp = TempDir::new("lock-trials");
    // Two scenes that tell their outputs apart: 11 and 21 state VTUs.
    let longer = [
        ("t_end = 0.05", "t_end = 0.5"),
        ("vtu_every = 0.005", "vtu_every = 0.05"),
    ];
    let a = variant("contact/collision.toml", &longer, &tmp);
    let b_dir = tmp.path().join("b");
    std::fs::create_dir_all(&b_dir).unwrap();
    let b_scene = std::fs::read_to_string(&a)
        .unwrap()
        .replace("vtu_every = 0.05", "vtu_every = 0.025");
    let b = b_dir.join("collision.toml");
    std::fs::write(&b, b_scene).unwrap();
    let mut ended = Command::new("true").spawn().expect("start true");
    let dead = ended.id();
    ended.wait().unwrap();
    for trial in 0..RACE_TRIALS {
        let out = tmp.path().join(format!("out{trial}"));
        std::fs::create_dir_all(&out).unwrap();
        let stale = ["", "garbage\n", &format!("{dead}\n")][trial % 3].to_string();
        std::fs::write(out.join(".qdem-run.lock"), &stale).unwrap();
        let start = |scene: &Path| {
            Command::new(env!("CARGO_BIN_EXE_qdem"))
                .args([OsStr::new("run"), scene.as_os_str(), OsStr::new("--out")])
                .arg(&out)
                .env("CI", "1")
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("start a run")
        };
        let (first, second) = (start(&a), start(&b));
        let runs = [
            first.wait_with_output().unwrap(),
            second.wait_with_output().unwrap(),
        ];
        let said = |r: &Output| String::from_utf8_lossy(&r.stderr).into_owned();
        let won: Vec<usize> = (0..2).filter(|&k| runs[k].status.success()).collect();
        assert_eq!(
            won.len(),
            1,
            "trial {trial} over {stale:?}: not exactly one run ran:\n{}\n{}",
            said(&runs[0]),
            said(&runs[1])
        );
        let loser = &runs[1 - won[0]];
        let message = refused(loser, &["is in use by another qdem run (pid "]);
        assert!(!message.contains("cannot"), "trial {trial}: {message}");
        // The winner's outputs are whole and its own: every VTU it lists is there, the count
        // its scene writes (11 for `a`, 21 for `b`), and nothing else.
        let listed = std::fs::read_to_string(out.join("results.pvd")).unwrap();
        let states: Vec<String> = std::fs::read_dir(out.join("vtu"))
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|name| name.starts_with("state_"))
            .collect();
        assert_eq!(states.len(), [11, 21][won[0]], "trial {trial}: {states:?}");
        assert!(
            states.iter().all(|s| listed.contains(s.as_str())),
            "trial {trial}"
        );
        assert_eq!(
            listed.matches("state_").count(),
            states.len(),
            "trial {trial}"
        );
        assert!(
            !out.join(".qdem-run.lock").exists(),
            "trial {trial}: the lock stayed"
        );
    }
}

#[test]
fn a_real_second_run_started_during_the_first_is_refused() {
    let tmp = TempDir::new("lock-race");
    let out = tmp.path().join("out");
    let scene = workspace().join("fixtures/contact/collision.toml");
    let mut first = Command::new(env!("CARGO_BIN_EXE_qdem"))
        .args([OsStr::new("run"), scene.as_os_str(), OsStr::new("--out")])
        .arg(&out)
        .env("CI", "1")
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("start the first run");
    let lock = out.join(".qdem-run.lock");
    let started = std::time::Instant::now();
    while !lock.exists() && started.elapsed().as_secs() < 30 {
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let second = run(&scene, &out);
    let finished = first.try_wait().unwrap().is_some();
    let status = first.wait().unwrap();
    assert!(status.success());
    if finished {
        eprintln!("skipped: the first run ended before the second started");
        return;
    }
    refused(
        &second,
        &[&format!("in use by another qdem run (pid {},", first.id())],
    );
}

/// Three single-sphere stones above a floor, read from `SAMPLE`, written into `OUT`.
const GRAINS: &str = r#"
[run]
t_end = 0.01
gravity = [0.0, 0.0, -9.81]
probe_every = 0.001

[[material]]
name = "granite"
density = 2600.0
young = 1e9
poisson = 0.25

[contact]
law = "hertz-mindlin"
friction = 0.6

[granular]
name = "ballast"
material = "granite"
sample = "SAMPLE"

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[output]
dir = "OUT"
"#;

#[test]
fn a_run_that_would_write_over_a_file_it_reads_is_refused_naming_both() {
    let tmp = TempDir::new("own-input");
    let stones = "stone,x,y,z,radius\n1,0.0,0.0,0.06,0.05\n2,0.2,0.0,0.06,0.05\n";
    let out = tmp.path().join("out");
    std::fs::create_dir_all(out.join("vtu")).unwrap();
    // The sample as the stones.csv a run writes, as a VTU the fresh start removes, and as
    // the checkpoint a run writes, in the output folder given by the scene or by --out.
    for (sample, given) in [
        ("out/stones.csv", None),
        ("out/vtu/state_00003.vtu", None),
        ("elsewhere/../out/checkpoint.qdc", Some(&out)),
    ] {
        std::fs::create_dir_all(tmp.path().join("elsewhere")).unwrap();
        let file = tmp.path().join(sample);
        std::fs::write(&file, stones).unwrap();
        let scene = tmp.path().join("grains.toml");
        let text = GRAINS.replace("SAMPLE", sample).replace("OUT", "out");
        std::fs::write(&scene, text).unwrap();
        let mut args = vec![OsStr::new("run"), scene.as_os_str()];
        if let Some(dir) = given {
            args.extend([OsStr::new("--out"), dir.as_os_str()]);
        }
        let message = refused(
            &qdem(&args),
            &[
                &format!("the scene reads (\"{sample}\")"),
                "a run must not change its own input; fix: give the run another --out",
            ],
        );
        let output = file.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            message.contains(&format!("remove) {}", out.display())),
            "{message}"
        );
        assert!(message.contains(&output), "{message}");
        assert_eq!(std::fs::read_to_string(&file).unwrap(), stones, "{sample}");
        assert!(!out.join("probes.csv").exists(), "the refused run wrote");
        std::fs::remove_file(&file).unwrap();
    }
    // The same sample beside the output folder: the run runs and leaves it as it was.
    let file = tmp.path().join("stones.csv");
    std::fs::write(&file, stones).unwrap();
    let scene = tmp.path().join("grains.toml");
    std::fs::write(
        &scene,
        GRAINS.replace("SAMPLE", "stones.csv").replace("OUT", "out"),
    )
    .unwrap();
    let done = qdem(&[OsStr::new("run"), scene.as_os_str()]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), stones);
    assert!(out.join("stones.csv").exists());
}

#[test]
fn a_fresh_run_removes_the_files_of_an_earlier_longer_run() {
    let tmp = TempDir::new("fresh");
    let out = tmp.path().join("out");
    let vtu = out.join("vtu");
    std::fs::create_dir_all(&vtu).unwrap();
    // An earlier run's last VTUs (beyond this run's ten), its boundary record and a file of
    // the user's.
    for name in [
        "vtu/state_00030.vtu",
        "vtu/spheres_00030.vtu",
        "boundary.csv",
    ] {
        std::fs::write(out.join(name), "earlier run").unwrap();
    }
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let scene = workspace().join("fixtures/contact/collision.toml");
    let done = run(&scene, &out);
    assert!(done.status.success());
    for gone in [
        "vtu/state_00030.vtu",
        "vtu/spheres_00030.vtu",
        "boundary.csv",
    ] {
        assert!(!out.join(gone).exists(), "{gone} of the earlier run stayed");
    }
    assert!(out.join("notes.txt").exists());
    let listed = std::fs::read_to_string(out.join("results.pvd")).unwrap();
    let states = std::fs::read_dir(&vtu)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with("state_"))
        .count();
    assert_eq!(states, listed.matches("state_").count());
}

#[test]
fn bodies_thrown_through_each_other_are_stopped_with_a_report() {
    let tmp = TempDir::new("tunnel");
    let scene = variant(
        "contact/collision.toml",
        &[
            ("velocity = [4.0, 0.0, 0.0]", "velocity = [40.0, 0.0, 0.0]"),
            (
                "velocity = [-1.0, 0.0, 0.0]",
                "velocity = [-40.0, 0.0, 0.0]",
            ),
        ],
        &tmp,
    );
    let message = refused(
        &run(&scene, &tmp.path().join("out")),
        &[
            "pass through each other",
            "more than the sphere radius 8.000e-3 m",
            "fix: larger contact spheres (contact_radius), a stiffer contact",
            "a smaller dt does not help here",
        ],
    );
    assert!(
        message.contains("`left`") && message.contains("`right`"),
        "{message}"
    );
    // The speed named is the blocks' relative speed, below the 80 m/s they were thrown at
    // (the contact has slowed them) and well above the fixture's 5 m/s.
    let speed: f64 = message
        .split("the bodies move at ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|word| word.parse().ok())
        .unwrap_or_else(|| panic!("no speed in:\n{message}"));
    assert!((20.0..80.0).contains(&speed), "{speed} m/s:\n{message}");
    // At the fixture's own speeds the watch stays silent (same_outputs.py shows the outputs
    // unchanged).
    let out = tmp.path().join("fixture");
    let done = run(&workspace().join("fixtures/contact/collision.toml"), &out);
    assert!(done.status.success());
}

/// A bar of four cubes (edge 0.1 m, along x from 0 to 0.4 m) of six tetrahedra each, as
/// MSH 2.2; with `split`, the nodes at x = 0.2 are written twice, once for each side.
fn four_cubes(split: bool) -> String {
    let h = 0.1;
    let mut nodes: Vec<[f64; 3]> = Vec::new();
    let mut id = std::collections::HashMap::new();
    let mut node = |i: usize, j: usize, k: usize, side: usize| -> usize {
        let key = (i, j, k, if split && i == 2 { side } else { 0 });
        *id.entry(key).or_insert_with(|| {
            nodes.push([i as f64 * h, j as f64 * h, k as f64 * h]);
            nodes.len()
        })
    };
    let mut tets: Vec<[usize; 4]> = Vec::new();
    // Kuhn's six tetrahedra of a cube: the paths from corner 000 to 111 along the axes.
    let orders = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    for cube in 0..4 {
        let side = usize::from(cube >= 2);
        for order in orders {
            let mut at = [cube, 0, 0];
            let mut tet = [node(at[0], at[1], at[2], side); 4];
            for (n, axis) in order.iter().enumerate() {
                at[*axis] += 1;
                tet[n + 1] = node(at[0], at[1], at[2], side);
            }
            tets.push(tet);
        }
    }
    let mut msh = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    msh.push_str("$PhysicalNames\n1\n3 1 \"bar\"\n$EndPhysicalNames\n");
    writeln!(msh, "$Nodes\n{}", nodes.len()).unwrap();
    for (n, p) in nodes.iter().enumerate() {
        writeln!(msh, "{} {} {} {}", n + 1, p[0], p[1], p[2]).unwrap();
    }
    writeln!(msh, "$EndNodes\n$Elements\n{}", tets.len()).unwrap();
    for (e, t) in tets.iter().enumerate() {
        let [a, b, c, d] = *t;
        // Positive orientation: det[b - a, c - a, d - a] > 0, else swap the last two.
        let v = |m: usize| nodes[m - 1];
        let (p, q, r, s) = (v(a), v(b), v(c), v(d));
        let e1 = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let e2 = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
        let e3 = [s[0] - p[0], s[1] - p[1], s[2] - p[2]];
        let det = e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0])
            + e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]);
        let (c, d) = if det > 0.0 { (c, d) } else { (d, c) };
        writeln!(msh, "{} 4 2 1 1 {a} {b} {c} {d}", e + 1).unwrap();
    }
    msh.push_str("$EndElements\n");
    msh
}

/// The bar clamped at x = 0 and pulled down at x = 0.4 by 100 N for 10 ms.
fn bar_scene(merge: bool) -> String {
    format!(
        "[run]\nt_end = 0.01\nprobe_every = 1e-3\n\n\
         [[material]]\nname = \"stiff\"\ndensity = 1000.0\nyoung = 1e9\npoisson = 0.25\n\n\
         [[body]]\nname = \"bar\"\nmesh = \"bar.msh\"\nmaterial = \"stiff\"\nmerge_nodes = {merge}\n\n\
         [[fix]]\nbody = \"bar\"\nbox = [[-0.01, -0.01, -0.01], [0.01, 0.11, 0.11]]\ndofs = \"xyz\"\n\n\
         [[load]]\nbody = \"bar\"\nbox = [[0.39, -0.01, -0.01], [0.41, 0.11, 0.11]]\n\
         total_force = [0.0, 0.0, -100.0]\nramp = [[0.0, 1.0], [1.0, 1.0]]\n\n\
         [[probe]]\nname = \"tip\"\nbody = \"bar\"\npoint = [0.4, 0.1, 0.1]\n"
    )
}

#[test]
fn duplicate_nodes_are_reported_and_merged_on_request() {
    let tmp = TempDir::new("dup-nodes");
    std::fs::write(tmp.path().join("bar.msh"), four_cubes(true)).unwrap();
    let detached = tmp.path().join("detached.toml");
    std::fs::write(&detached, bar_scene(false)).unwrap();
    let check = qdem(&[OsStr::new("check"), detached.as_os_str()]);
    let stdout = String::from_utf8_lossy(&check.stdout);
    assert!(check.status.success(), "{stdout}");
    let warning = stdout
        .lines()
        .find(|l| l.contains("nodes coincide"))
        .unwrap_or_else(|| panic!("no warning of coincident nodes:\n{stdout}"));
    for needle in [
        "bar.msh",
        "body `bar`: 4 nodes coincide with another node",
        "at (0.2, ",
        "fix: merge_nodes = true on the body",
    ] {
        assert!(warning.contains(needle), "no {needle:?} in {warning}");
    }
    let out = tmp.path().join("out-detached");
    let done = run(&detached, &out);
    assert!(String::from_utf8_lossy(&done.stderr).contains("4 nodes coincide"));
    let loose = common::last_probe(&out, "tip.uz");

    let merged = tmp.path().join("merged.toml");
    std::fs::write(&merged, bar_scene(true)).unwrap();
    let check = qdem(&[OsStr::new("check"), merged.as_os_str()]);
    assert!(!String::from_utf8_lossy(&check.stdout).contains("nodes coincide"));
    let out = tmp.path().join("out-merged");
    let done = run(&merged, &out);
    assert!(done.status.success());
    let held = common::last_probe(&out, "tip.uz");

    // Detached, the outer half is a free body under the tip load: small rigid motion from
    // rest, with the lumped masses the run uses (a quarter of each tetrahedron's mass at each
    // node), gives the tip's fall; its elastic part is some 1e-6 m here.
    let rigid = rigid_tip_fall(100.0, 0.01);
    assert!(
        (loose + rigid).abs() < 0.03 * rigid,
        "detached tip {loose} m, rigid outer half {rigid} m"
    );
    // Merged, the bar is one cantilever: below twice (a step load's dynamic overshoot) its
    // static Timoshenko deflection F L³/(3EI) + F L/(κ G A), which the stiffer coarse
    // tetrahedra do not reach.
    let (e, g, area, inertia) = (1e9, 1e9 / 2.5, 0.01, 0.1f64.powi(4) / 12.0);
    let beam = 100.0 * 0.4f64.powi(3) / (3.0 * e * inertia) + 100.0 * 0.4 / (5.0 / 6.0 * g * area);
    assert!(
        held < 0.0 && held.abs() < 2.0 * beam,
        "merged tip {held} m, beam {beam} m"
    );
    assert!(loose.abs() > 10.0 * held.abs());
}

/// The fall (m) of the probe node (0.4, 0.1, 0.1) of the outer half (x from 0.2 to 0.4) of
/// the four cubes, moving as a rigid body from rest under `force` (N, down, shared by its
/// four nodes at x = 0.4) for `time` (s): u = ½ t² (F/m + α × r), α = I⁻¹ τ.
fn rigid_tip_fall(force: f64, time: f64) -> f64 {
    let msh = four_cubes(true);
    let nodes: Vec<[f64; 3]> = section(&msh, "$Nodes")
        .map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .skip(1)
                .map(|w| w.parse().unwrap())
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let mut mass = vec![0.0; nodes.len()];
    for line in section(&msh, "$Elements") {
        let ids: Vec<usize> = line
            .split_whitespace()
            .skip(5)
            .map(|w| w.parse().unwrap())
            .collect();
        if ids.iter().all(|&n| nodes[n - 1][0] >= 0.2 - 1e-12) {
            for n in ids {
                mass[n - 1] += 1000.0 * 0.1f64.powi(3) / 6.0 / 4.0;
            }
        }
    }
    let m: f64 = mass.iter().sum();
    let c: Vec<f64> = (0..3)
        .map(|k| (0..nodes.len()).map(|i| mass[i] * nodes[i][k]).sum::<f64>() / m)
        .collect();
    let mut inertia = [[0.0; 3]; 3];
    let mut torque = [0.0; 3];
    for (i, p) in nodes.iter().enumerate() {
        let r = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        for a in 0..3 {
            for b in 0..3 {
                inertia[a][b] += mass[i] * (if a == b { r2 } else { 0.0 } - r[a] * r[b]);
            }
        }
        if p[0] == 0.4 {
            // r × (0, 0, -F/4)
            let f = -force / 4.0;
            torque[0] += r[1] * f;
            torque[1] -= r[0] * f;
        }
    }
    let alpha = solve3(inertia, torque);
    let r = [0.4 - c[0], 0.1 - c[1], 0.1 - c[2]];
    // z of α × r, plus F/m.
    let accel = -force / m + alpha[0] * r[1] - alpha[1] * r[0];
    -0.5 * accel * time * time
}

/// The lines of a MSH 2.2 section after its count line.
fn section<'a>(msh: &'a str, name: &str) -> impl Iterator<Item = &'a str> {
    let body = msh.split(name).nth(1).expect("the section");
    let end = format!("$End{}", &name[1..]);
    let body = body.split(end.as_str()).next().expect("its end");
    body.lines().skip(2).filter(|l| !l.trim().is_empty())
}

/// x with `a` x = `b` (Cramer's rule; `a` symmetric positive definite).
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    let mut x = [0.0; 3];
    for (k, xk) in x.iter_mut().enumerate() {
        let mut m = a;
        for row in 0..3 {
            m[row][k] = b[row];
        }
        *xk = det(m) / d;
    }
    x
}

#[test]
fn stop_after_a_step_a_resumed_checkpoint_has_passed_is_refused() {
    let tmp = TempDir::new("stop-after");
    let out = tmp.path().join("out");
    let scene = workspace().join("fixtures/contact/collision.toml");
    let with = |extra: &[&str]| {
        let mut args = vec![
            OsStr::new("run"),
            scene.as_os_str(),
            OsStr::new("--out"),
            out.as_os_str(),
        ];
        args.extend(extra.iter().map(OsStr::new));
        qdem(&args)
    };
    let checkpoint = out.join("checkpoint.qdc");
    let checkpoint = checkpoint.to_str().expect("a UTF-8 path");
    assert_eq!(with(&["--stop-after", "100"]).status.code(), Some(130));
    refused(
        &with(&["--resume", checkpoint, "--stop-after", "50"]),
        &[
            "--stop-after 50 counts steps from the run's start",
            "the checkpoint is at step 100",
            "fix: give a step after 100, e.g. --stop-after 150",
        ],
    );
    let resumed = with(&["--resume", checkpoint, "--stop-after", "150"]);
    let stderr = String::from_utf8_lossy(&resumed.stderr);
    assert_eq!(resumed.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("(step 150)"), "{stderr}");
}

#[test]
fn a_run_modelled_to_take_days_is_refused_without_yes() {
    let tmp = TempDir::new("days");
    // A contact stiffness of 10^30 N/m bounds the step at about 10^-16 s: 6.8e14 steps,
    // which `qdem check` measures as 3.1e6 hours and `qdem run` once started.
    let scene = variant(
        "contact/collision.toml",
        &[("normal_stiffness = 2e5", "normal_stiffness = 1e30")],
        &tmp,
    );
    let out = tmp.path().join("out");
    // --stop-after: a run that starts stops at once (exit 130) rather than run for years.
    let stop_after = |yes: bool| {
        let mut args = vec![OsStr::new("run"), scene.as_os_str(), OsStr::new("--out")];
        args.extend([out.as_os_str(), OsStr::new("--stop-after"), OsStr::new("2")]);
        args.extend(yes.then_some(OsStr::new("--yes")));
        qdem(&args)
    };
    let message = refused(
        &stop_after(false),
        &[
            "days of wall time on",
            "more than the day a run starts without asking",
            "fix: shorten it (a shorter t_end; a larger step",
            "or give --yes to start it anyway",
        ],
    );
    assert!(!out.exists(), "the refused run made its folder");
    // At least 10^-7 s a step (the model's floor): at least 7.8e2 days.
    let days: f64 = message
        .split("at least ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|word| word.parse().ok())
        .unwrap_or_else(|| panic!("no days in:\n{message}"));
    let steps: f64 = message
        .split("the run is ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|word| word.parse().ok())
        .unwrap_or_else(|| panic!("no steps in:\n{message}"));
    assert!(
        days >= steps * 1e-7 / 86_400.0 * 0.999,
        "{days} days for {steps} steps"
    );
    // With --yes it starts: stopped after its second step, checkpointed (exit 130).
    let started = stop_after(true);
    let said = String::from_utf8_lossy(&started.stderr);
    assert_eq!(started.status.code(), Some(130), "{said}");
    assert!(out.join("checkpoint.qdc").exists(), "{said}");
}
