//! Semantic validation: everything serde cannot check. Every problem is collected (not just
//! the first) and reported in file order, each naming its table and saying how to fix it.
//!
//! One module per table or group of related tables, each checking its keys and the references
//! it makes; [`validate`] runs them in a fixed order (problems without a position in the file
//! are reported in that order, after the others) and resolves the references into [`Refs`]:
//!
//! - `run`: `[run]` and `[output]`;
//! - `material`: `[[material]]`;
//! - `body`: `[[body]]` (with the bodies `[bonded]` and `[ballast]` add) and its placement keys;
//! - `fix_load`: `[[fix]]` and `[[load]]`;
//! - `probe_section`: `[[probe]]` and `[[section]]`;
//! - `contact`: `[contact]` and `[[wall]]`;
//! - `granular`, `ballast`, `bonded`, `periodic`: the table of that name;
//! - `files`: the files a scene refers to (for [`Scene::load`]);
//! - `checker`: the collector of problems and the checks the tables share.

mod ballast;
mod body;
mod bonded;
mod checker;
mod contact;
mod files;
mod fix_load;
mod granular;
mod material;
mod measure;
mod periodic;
mod probe_section;
mod run;

use std::path::Path;

use super::error::SceneError;
use super::schema::{
    AreaLoad, FixFrame, FrameName, RawFix, RawFrame, RawLoad, RawScene, Selection,
};
use super::spans::SpanIndex;
use super::{Refs, Scene};
use checker::Checker;

pub(crate) use files::missing_files;

/// Validate a parsed scene, turning it into a [`Scene`] with its references resolved, or list
/// every problem.
pub(crate) fn validate(
    raw: RawScene,
    path: &Path,
    text: Option<&str>,
    spans: Option<&SpanIndex>,
) -> Result<Scene, SceneError> {
    let mut c = Checker::new(text, spans);
    let mut refs = Refs::default();
    run::run_table(&mut c, &raw);
    let materials = material::material_tables(&mut c, &raw.materials);
    let bodies = body::body_tables(&mut c, &raw, &materials, &mut refs);
    let fixes = fix_load::fix_tables(&mut c, &raw, &bodies, &mut refs);
    let loads = fix_load::load_tables(&mut c, &raw, &bodies, &mut refs);
    probe_section::probe_tables(&mut c, &raw, &bodies, &mut refs);
    probe_section::section_tables(&mut c, &raw);
    measure::measure_tables(&mut c, &raw);
    let spheres = body::placement_keys(&mut c, &raw);
    contact::contact_tables(&mut c, &raw, spheres);
    if let Some(g) = &raw.granular {
        refs.granular_material = granular::granular_table(&mut c, &raw, g, &materials);
    }
    if let Some(p) = &raw.periodic {
        periodic::periodic_table(&mut c, &raw, p, &mut refs);
    }
    run::output_table(&mut c, &raw);
    c.finish(path)?;
    Ok(Scene {
        run: raw.run,
        materials: raw.materials,
        bodies: raw.bodies,
        fixes,
        loads,
        probes: raw.probes,
        sections: raw.sections,
        measures: raw.measures,
        contact: raw.contact,
        walls: raw.walls,
        bonded: raw.bonded,
        periodic: raw.periodic,
        granular: raw.granular,
        ballast: raw.ballast,
        output: raw.output,
        path: path.to_path_buf(),
        refs,
    })
}

/// The scene in its as-written form, to re-run [`validate`] on a scene built in code.
pub(crate) fn to_raw(scene: &Scene) -> RawScene {
    fn split(sel: &Selection) -> (Option<String>, Option<[[f64; 3]; 2]>) {
        match sel {
            Selection::Group(g) => (Some(g.clone()), None),
            Selection::Box(b) => (None, Some(*b)),
        }
    }
    RawScene {
        run: scene.run.clone(),
        materials: scene.materials.clone(),
        bodies: scene.bodies.clone(),
        fixes: scene
            .fixes
            .iter()
            .map(|f| {
                let (group, bbox) = split(&f.selection);
                let dofs = f
                    .frame
                    .letters()
                    .iter()
                    .zip(f.dofs)
                    .filter(|(_, on)| *on)
                    .map(|(c, _)| *c)
                    .collect();
                let (frame, axis_origin, axis) = match f.frame {
                    FixFrame::Axes => (None, None, None),
                    FixFrame::Basis(rows) => (Some(RawFrame::Basis(rows)), None, None),
                    FixFrame::Cylindrical { origin, axis } => (
                        Some(RawFrame::Name(FrameName::Cylindrical)),
                        Some(origin),
                        Some(axis),
                    ),
                };
                RawFix {
                    body: f.body.clone(),
                    group,
                    bbox,
                    dofs,
                    rotation: f.rotation,
                    frame,
                    axis_origin,
                    axis,
                }
            })
            .collect(),
        loads: scene
            .loads
            .iter()
            .map(|l| {
                let (group, bbox) = split(&l.selection);
                RawLoad {
                    body: l.body.clone(),
                    group,
                    bbox,
                    total_force: l.area.is_none().then_some(l.total_force),
                    pressure: match l.area {
                        Some(AreaLoad::Pressure(p)) => Some(p),
                        _ => None,
                    },
                    traction: match l.area {
                        Some(AreaLoad::Traction(t)) => Some(t),
                        _ => None,
                    },
                    ramp: (!l.ramp.points.is_empty()).then(|| l.ramp.points.clone()),
                    cyclic: l.cyclic,
                    series: l.series.clone(),
                }
            })
            .collect(),
        probes: scene.probes.clone(),
        sections: scene.sections.clone(),
        measures: scene.measures.clone(),
        contact: scene.contact.clone(),
        walls: scene.walls.clone(),
        bonded: scene.bonded.clone(),
        periodic: scene.periodic.clone(),
        granular: scene.granular.clone(),
        ballast: scene.ballast.clone(),
        output: scene.output.clone(),
    }
}
