//! The areas of qdem-core import one another in one direction only, bottom to top:
//!
//! 0. `step` (the state, the model and its facets, what a model declares of a decomposed run,
//!    the stepper, the tangent, the stages, the step settings), with the crate's `error` and
//!    `checkpoint` modules;
//! 1. the physics, `continuum` and `loads`, and the `solvers`, each on its own;
//! 2. `modal` (its modes are a solve of the tangents);
//! 3. `parallel`, which distributes what the models declare;
//! 4. `world`, which holds the parallel runtime.
//!
//! A file may name its own area and the areas of lower layers, never an area of its own layer
//! or above; and it names them by their area paths (`crate::step::model::Model`), not by the
//! flat aliases of `lib.rs` (kept for other crates), `crate::Vec3` and `crate::Mat3` aside.
//! The check reads the `crate::` paths of each file's code (comments and `#[cfg(test)]`
//! modules left out).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The layers, bottom first: each a list of (area, module names at the crate root).
const LAYERS: &[&[(&str, &[&str])]] = &[
    &[("step", &["step", "error", "checkpoint"])],
    &[
        ("continuum", &["continuum"]),
        ("loads", &["loads"]),
        ("solvers", &["solvers"]),
    ],
    &[("modal", &["modal"])],
    &[("parallel", &["parallel"])],
    &[("world", &["world"])],
];

/// What every area may name at the crate root besides the areas.
const ROOT_TYPES: &[&str] = &["Vec3", "Mat3"];

/// The area and layer of a crate-root module name.
fn area_of(module: &str) -> Option<(&'static str, usize)> {
    LAYERS.iter().enumerate().find_map(|(layer, areas)| {
        areas
            .iter()
            .find(|(_, modules)| modules.contains(&module))
            .map(|(area, _)| (*area, layer))
    })
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a file: without comments, and cut at its `#[cfg(test)]` module.
fn code(text: &str) -> String {
    let mut out = String::new();
    let mut lines = text.lines().peekable();
    while let Some(line) = lines.next() {
        let trimmed = line.trim_start();
        let test_module = lines
            .peek()
            .is_some_and(|next| next.trim_start().starts_with("mod "));
        if trimmed.starts_with("#[cfg(test)]") && test_module {
            break;
        }
        let line = match line.find("//") {
            Some(at) if !line[..at].contains('"') => &line[..at],
            _ => line,
        };
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// The first name of every `crate::` path in `code`, the names of a `crate::{a, b::c}`
/// group included.
fn crate_names(code: &str) -> BTreeSet<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut names = BTreeSet::new();
    for (at, _) in code.match_indices("crate::") {
        let rest = &code[at + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let (mut depth, mut start) = (0, 0);
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        names.insert(ident(&group[start..i]));
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        names.insert(ident(&group[start..i]));
                        start = i + 1;
                    }
                    _ => {}
                }
            }
        } else {
            names.insert(ident(rest));
        }
    }
    names.remove("");
    names
}

/// The crate-root module of a file (its path under src/).
fn root_module(relative: &str) -> &str {
    relative
        .split('/')
        .next()
        .unwrap_or(relative)
        .trim_end_matches(".rs")
}

/// Every import that breaks the layering: (file, the name it imports, why).
fn violations(src: &Path) -> Vec<(String, String, String)> {
    let mut files = Vec::new();
    sources(src, &mut files);
    files.sort();
    let mut found = Vec::new();
    for path in files {
        let relative = path
            .strip_prefix(src)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        let module = root_module(&relative);
        if module == "lib" {
            continue;
        }
        let Some((area, layer)) = area_of(module) else {
            let why = "the module is in no layer: give it one in LAYERS".to_string();
            found.push((relative.clone(), module.to_string(), why));
            continue;
        };
        let text = std::fs::read_to_string(&path).unwrap();
        for name in crate_names(&code(&text)) {
            let why = match area_of(&name) {
                Some((named, _)) if named == area => continue,
                Some((_, named_layer)) if named_layer < layer => continue,
                Some((named, named_layer)) if named_layer == layer => {
                    format!("`{named}` is beside `{area}`, in the same layer")
                }
                Some((named, _)) => format!("`{named}` is above `{area}`"),
                None if ROOT_TYPES.contains(&name.as_str()) => continue,
                None => format!("`crate::{name}` is a flat alias: name it by its area path"),
            };
            found.push((relative.clone(), name, why));
        }
    }
    found
}

#[test]
fn areas_import_only_their_own_and_lower_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let broken: Vec<String> = violations(&src)
        .iter()
        .map(|(file, name, why)| format!("src/{file}: crate::{name}: {why}"))
        .collect();
    assert!(
        broken.is_empty(),
        "imports against the layers:\n{}",
        broken.join("\n")
    );
}

#[test]
fn the_check_reads_grouped_and_plain_paths_without_comments() {
    let text = "use crate::step::model::Model; // crate::world in a comment\n\
                use crate::{parallel::Exchange, Vec3};\n\
                /// [`crate::modal`] in a doc comment\n\
                fn f() { crate::loads::gravity::Gravity::new(crate::Vec3::zeros()); }\n\
                #[cfg(test)]\nmod tests { use crate::world::World; }\n";
    let names: Vec<String> = crate_names(&code(text)).into_iter().collect();
    assert_eq!(names, ["Vec3", "loads", "parallel", "step"]);
}
