//! Helpers shared by the output tests.

#![allow(dead_code)] // each test binary uses a subset

use qdem_io::build::Simulation;
use qdem_io::runner::{run_with, RunError, RunOptions};
use qdem_io::scene::Scene;
use std::path::{Path, PathBuf};

/// The simulation of the scene file `scene` (panics on a bad scene: the tests' scenes are
/// their own).
pub fn build(scene: &Path) -> Simulation {
    Simulation::build(Scene::load(scene).unwrap()).unwrap()
}

/// [`run_with`] without a progress callback, its summary dropped.
pub fn run(sim: &mut Simulation, out: &Path, options: RunOptions<'_>) -> Result<(), RunError> {
    run_with(sim, out, options, &mut |_| {}).map(|_| ())
}

/// A fresh, empty directory for one test.
pub fn test_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("qdem-io-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The names of all entries of `dir`, sorted.
pub fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// `rel` under the workspace's `fixtures/`.
pub fn fixture(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fixtures")
        .join(rel)
}

/// The paper's cantilever on its coarse mesh (named by absolute path), shortened to 0.02 s
/// with its load ramped on over 0.01 s, with the further `(from, to)` text `edits`; written
/// to `dir/cantilever.toml`.
pub fn short_cantilever(dir: &Path, edits: &[(&str, &str)]) -> PathBuf {
    let mesh = format!(
        "mesh = \"{}\"",
        fixture("cantilever/cantilever_lc100.msh").display()
    );
    let base = [
        ("t_end = 3.0", "t_end = 0.02"),
        ("[0.0, 0.0], [1.0, 1.0]", "[0.0, 0.0], [0.01, 1.0]"),
        ("mesh = \"cantilever_lc100.msh\"", mesh.as_str()),
    ];
    let text = std::fs::read_to_string(fixture("cantilever/cantilever_lc100.toml")).unwrap();
    let text = base
        .iter()
        .chain(edits)
        .fold(text, |text, (from, to)| text.replace(from, to));
    let path = dir.join("cantilever.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// A CSV file as columns by name.
pub fn columns(path: &Path) -> std::collections::HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut cols: std::collections::HashMap<String, Vec<f64>> =
        names.iter().map(|n| (n.clone(), vec![])).collect();
    for line in lines {
        for (name, value) in names.iter().zip(line.split(',')) {
            cols.get_mut(name).unwrap().push(value.parse().unwrap());
        }
    }
    cols
}

/// Density (kg/m³), gravity (m/s²) and cell width (m) of [`grain_bed`].
pub const BED_DENSITY: f64 = 2600.0;
/// See [`BED_DENSITY`].
pub const BED_G: f64 = 9.81;
/// See [`BED_DENSITY`].
pub const BED_WIDTH: f64 = 0.06;

/// A scene of `count` one-sphere grains of 10–14 mm poured from a 0.01–0.25 m high region
/// of a cell `BED_WIDTH` wide, periodic in x and y, onto a floor at z = 0 (linear law,
/// friction 0.5, local damping 0.7), run to `t_end` with `probe_every`; `extra` is appended.
pub fn grain_bed(t_end: f64, probe_every: f64, count: usize, extra: &str) -> String {
    let (g, density, width) = (BED_G, BED_DENSITY, BED_WIDTH);
    format!(
        r#"
[run]
t_end = {t_end}
gravity = [0.0, 0.0, -{g}]
probe_every = {probe_every}

[[material]]
name = "stone"
density = {density}
young = 1e9
poisson = 0.25

[contact]
law = "linear"
normal_stiffness = 5e3
tangential_stiffness = 2.5e3
friction = 0.5
damping_ratio = 0.3
local_damping = 0.7

[granular]
name = "bed"
material = "stone"
region = [[0.0, 0.0, 0.01], [{width}, {width}, 0.25]]
count = {count}
grading = [[0.010, 0.0], [0.014, 1.0]]
spheres_per_stone = [1, 1]

[periodic]
axes = "xy"
length = [{width}, {width}]

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
{extra}"#
    )
}

/// The 8-byte values of the binary `<DataArray>` called `name` of a VTU written by qdem
/// (base64 of a u64 byte count, then the little-endian values).
pub fn vtu_values(vtu: &str, name: &str) -> Vec<[u8; 8]> {
    let start = vtu
        .find(&format!("Name=\"{name}\""))
        .unwrap_or_else(|| panic!("no array {name}"));
    let text = &vtu[start..];
    let body = &text[text.find('>').unwrap() + 1..text.find("</DataArray>").unwrap()];
    let bytes = base64(body.trim());
    bytes[8..]
        .chunks_exact(8)
        .map(|c| c.try_into().unwrap())
        .collect()
}

/// The f64 values of the VTU array `name` ([`vtu_values`]).
pub fn vtu_array(vtu: &str, name: &str) -> Vec<f64> {
    vtu_values(vtu, name)
        .into_iter()
        .map(f64::from_le_bytes)
        .collect()
}

/// The i64 values of the VTU array `name` ([`vtu_values`]).
pub fn vtu_integers(vtu: &str, name: &str) -> Vec<i64> {
    vtu_values(vtu, name)
        .into_iter()
        .map(i64::from_le_bytes)
        .collect()
}

/// The nodes (id to coordinates) and linear tetrahedra (id to node ids) of an ASCII MSH 2.2
/// file's text, read by hand.
pub fn parse_msh22(
    text: &str,
) -> (
    std::collections::HashMap<i64, [f64; 3]>,
    std::collections::HashMap<i64, [i64; 4]>,
) {
    let section = |name: &str| {
        let start = text.find(&format!("${name}\n")).unwrap() + name.len() + 2;
        let end = text.find(&format!("$End{name}")).unwrap();
        text[start..end].lines().skip(1).collect::<Vec<_>>()
    };
    let numbers = |line: &str| -> Vec<f64> {
        line.split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect()
    };
    let nodes = section("Nodes")
        .into_iter()
        .map(|l| {
            let v = numbers(l);
            (v[0] as i64, [v[1], v[2], v[3]])
        })
        .collect();
    let tets = section("Elements")
        .into_iter()
        .map(numbers)
        .filter(|v| v[1] == 4.0)
        .map(|v| {
            let n = v.len();
            (
                v[0] as i64,
                [v[n - 4], v[n - 3], v[n - 2], v[n - 1]].map(|x| x as i64),
            )
        })
        .collect();
    (nodes, tets)
}

/// Standard base64 (RFC 4648, `=` padding) decoded.
pub fn base64(text: &str) -> Vec<u8> {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let value = |c: u8| ALPHABET.iter().position(|&a| a == c).unwrap() as u32;
    let mut out = Vec::new();
    for group in text.as_bytes().chunks(4) {
        let digits: Vec<u8> = group.iter().copied().filter(|&c| c != b'=').collect();
        let n = digits
            .iter()
            .enumerate()
            .fold(0u32, |n, (k, &c)| n | value(c) << (18 - 6 * k));
        out.extend(n.to_be_bytes()[1..digits.len()].iter());
    }
    out
}
