//! The files a scene refers to, checked by [`Scene::load`](super::super::Scene::load) after
//! parsing: every body's mesh, the `[granular]` sample, the `[ballast]` stone meshes, the loads'
//! series files, the checkpoint of `[run] start_from`, and the mesh walls' meshes.

use std::path::Path;

use super::super::error::{located, Diagnostic};
use super::super::spans::SpanIndex;
use super::super::Scene;
use super::checker::label;

/// Problems with the files a scene refers to: every body's mesh must exist.
pub(crate) fn missing_files(
    scene: &Scene,
    text: Option<&str>,
    spans: Option<&SpanIndex>,
) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for (i, b) in scene.bodies.iter().enumerate() {
        let resolved = scene.mesh_path(b);
        if resolved.is_file() {
            continue;
        }
        let idx = i.to_string();
        let offset = spans.and_then(|s| s.offset(&["body", &idx, "mesh"]));
        let what = if resolved.exists() {
            "is not a file"
        } else {
            "does not exist"
        };
        out.push((
            offset,
            format!(
                "{}: mesh file {} {what} (mesh = {:?} is resolved relative to the scene file's \
                 directory)",
                label("body", i, Some(&b.name)),
                resolved.display(),
                b.mesh.display().to_string()
            ),
        ));
    }
    if let Some(sample) = scene.sample_path().filter(|p| !p.is_file()) {
        let offset = spans.and_then(|s| s.offset(&["granular", "sample"]));
        out.push((
            offset,
            format!(
                "[granular]: sample file {} does not exist (resolved relative to the scene \
                 file's directory; a run with [granular] writes its stones to stones.csv)",
                sample.display()
            ),
        ));
    }
    out.extend(named_files(scene, spans));
    out.extend(wall_meshes(scene, spans));
    located(&scene.path, text, out)
}

/// The ballast's stone meshes, the loads' series files and the checkpoint to start from that
/// do not exist.
fn named_files(scene: &Scene, spans: Option<&SpanIndex>) -> Vec<(Option<usize>, String)> {
    let mut files: Vec<(Vec<String>, String, &Path, &str)> = Vec::new();
    if let Some(b) = &scene.ballast {
        for (i, mesh) in b.meshes.iter().enumerate() {
            let at = vec!["ballast".to_string(), "meshes".to_string()];
            files.push((at, format!("[ballast]: stone mesh #{}", i + 1), mesh, ""));
        }
    }
    for (i, l) in scene.loads.iter().enumerate() {
        if let Some(series) = &l.series {
            let at = vec!["load".to_string(), i.to_string(), "series".to_string()];
            files.push((
                at,
                format!("{}: series file", label("load", i, None)),
                &series.file,
                "",
            ));
        }
    }
    if let Some(start) = &scene.run.start_from {
        let at = vec!["run".to_string(), "start_from".to_string()];
        let hint = "; run the scene that writes it first (its [output] dir holds checkpoint.qdc \
                    when it has `checkpoint_every`)";
        files.push((at, "[run] start_from: checkpoint".to_string(), start, hint));
    }
    files
        .into_iter()
        .filter(|(_, _, file, _)| !scene.resolve(file).is_file())
        .map(|(at, what, file, hint)| {
            let at: Vec<&str> = at.iter().map(String::as_str).collect();
            (
                spans.and_then(|s| s.offset(&at)),
                format!(
                    "{what} {} does not exist (resolved relative to the scene file's \
                     directory){hint}",
                    scene.resolve(file).display()
                ),
            )
        })
        .collect()
}

/// The mesh walls' meshes that do not exist.
fn wall_meshes(scene: &Scene, spans: Option<&SpanIndex>) -> Vec<(Option<usize>, String)> {
    let mut out = Vec::new();
    for (i, w) in scene.walls.iter().enumerate() {
        let Some(mesh) = &w.mesh else { continue };
        let resolved = scene.wall_mesh_path(mesh);
        if resolved.is_file() {
            continue;
        }
        let idx = i.to_string();
        let offset = spans.and_then(|s| s.offset(&["wall", &idx, "mesh"]));
        out.push((
            offset,
            format!(
                "{}: mesh file {} does not exist (resolved relative to the scene file's \
                 directory)",
                label("wall", i, None),
                resolved.display()
            ),
        ));
    }
    out
}
