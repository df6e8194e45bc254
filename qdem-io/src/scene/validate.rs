//! Semantic validation: everything serde cannot check. Every problem is collected (not just
//! the first) and reported in file order, each naming its table and saying how to fix it.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use super::error::{located, Diagnostic, SceneError};
use super::schema::{
    Ballast, Body, ContactLawName, CyclicLoad, Fix, Granular, Integrator, Load, Periodic, Ramp,
    RawFix, RawLoad, RawScene, Selection, Series, TimeStep,
};
use super::spans::SpanIndex;
use super::suggest::did_you_mean;
use super::Scene;

/// The most edit-distance cells (characters of the word times characters of the candidates)
/// that "did you mean" suggestions may cost in one scene: plenty for any real scene, and a bound
/// for a huge one with thousands of undefined references (whose messages then go without
/// suggestions).
const SUGGESTION_BUDGET: usize = 20_000_000;

/// The most names listed in a "defined bodies: ..." message; the rest are counted.
const MAX_LISTED_NAMES: usize = 20;

/// Collects located problems.
struct Checker<'a> {
    text: Option<&'a str>,
    spans: Option<&'a SpanIndex>,
    /// Problems as (byte offset, message); positions are resolved once, at the end.
    found: Vec<(Option<usize>, String)>,
    /// Byte offsets of the starts of the text's lines.
    line_starts: Vec<usize>,
    /// What is left of [`SUGGESTION_BUDGET`].
    suggestion_budget: usize,
}

impl<'a> Checker<'a> {
    fn new(text: Option<&'a str>, spans: Option<&'a SpanIndex>) -> Self {
        let line_starts = text.map_or_else(Vec::new, |t| {
            std::iter::once(0)
                .chain(t.match_indices('\n').map(|(k, _)| k + 1))
                .collect()
        });
        Checker {
            text,
            spans,
            found: Vec::new(),
            line_starts,
            suggestion_budget: SUGGESTION_BUDGET,
        }
    }

    fn offset(&self, at: &[&str]) -> Option<usize> {
        self.spans.and_then(|s| s.offset(at))
    }

    fn line_of(&self, at: &[&str]) -> Option<usize> {
        let offset = self.offset(at)?;
        self.text
            .map(|_| self.line_starts.partition_point(|&start| start <= offset))
    }

    fn error(&mut self, at: &[&str], message: String) {
        let offset = self.offset(at);
        self.found.push((offset, message));
    }

    /// [`did_you_mean`] within the scene's [`SUGGESTION_BUDGET`].
    fn suggest<'n>(&mut self, word: &str, candidates: &[&'n str]) -> Option<&'n str> {
        let cells = candidates
            .iter()
            .fold(0usize, |sum, c| sum.saturating_add(c.len() + 1))
            .saturating_mul(word.len() + 1);
        if cells > self.suggestion_budget {
            return None;
        }
        self.suggestion_budget -= cells;
        did_you_mean(word, candidates.iter().copied())
    }

    /// Check that every component is finite; true when they all are.
    fn finite(&mut self, at: &[&str], label: &str, key: &str, values: &[f64]) -> bool {
        let bad: Vec<String> = values
            .iter()
            .filter(|v| !v.is_finite())
            .map(|v| v.to_string())
            .collect();
        if bad.is_empty() {
            return true;
        }
        self.error(
            at,
            format!(
                "{label}: `{key}` must be a finite number, not {}",
                bad.join(", ")
            ),
        );
        false
    }

    /// A finite, strictly positive number.
    fn positive(&mut self, at: &[&str], label: &str, key: &str, v: f64, unit: &str) {
        if self.finite(at, label, key, &[v]) && v <= 0.0 {
            self.error(
                at,
                format!("{label}: {key} = {v}: must be positive ({unit}); give a value above 0"),
            );
        }
    }

    /// A finite, non-negative number.
    fn non_negative(&mut self, at: &[&str], label: &str, key: &str, v: f64, unit: &str) {
        if self.finite(at, label, key, &[v]) && v < 0.0 {
            self.error(
                at,
                format!("{label}: {key} = {v}: must not be negative ({unit}); use 0 to disable"),
            );
        }
    }

    /// The line where `name` was first defined, for duplicate messages.
    fn first_seen(&self, table: &str, index: usize) -> String {
        let i = index.to_string();
        match self.line_of(&[table, &i, "name"]) {
            Some(line) => format!("line {line}"),
            None => format!("[[{table}]] #{}", index + 1),
        }
    }
}

fn label(table: &str, index: usize, name: Option<&str>) -> String {
    match name {
        Some(n) if !n.is_empty() => format!("[[{table}]] {n:?}"),
        _ => format!("[[{table}]] #{}", index + 1),
    }
}

/// `"a", "b", "c"`, at most [`MAX_LISTED_NAMES`] of them, then `… and N more`.
fn quoted_names<'a>(names: impl ExactSizeIterator<Item = &'a str>) -> String {
    let total = names.len();
    let mut listed: Vec<String> = names
        .take(MAX_LISTED_NAMES)
        .map(|n| format!("{n:?}"))
        .collect();
    if total > listed.len() {
        listed.push(format!("… and {} more", total - listed.len()));
    }
    listed.join(", ")
}

/// Check names: non-empty and unique within their table.
fn unique_names<'n>(
    c: &mut Checker<'_>,
    table: &str,
    names: impl Iterator<Item = &'n str>,
) -> HashMap<&'n str, usize> {
    let mut seen: HashMap<&str, usize> = HashMap::new();
    for (i, name) in names.enumerate() {
        let idx = i.to_string();
        let at = [table, idx.as_str(), "name"];
        if name.is_empty() {
            c.error(
                &at,
                format!("{}: name is empty; give it a name", label(table, i, None)),
            );
            continue;
        }
        if let Some(&first) = seen.get(name) {
            let where_ = c.first_seen(table, first);
            c.error(
                &at,
                format!(
                    "{} (#{}): duplicate {table} name {name:?}, already used at {where_}; rename one of them",
                    label(table, i, Some(name)),
                    i + 1
                ),
            );
        } else {
            seen.insert(name, i);
        }
    }
    seen
}

/// Check a reference to a body by name.
fn body_ref(
    c: &mut Checker<'_>,
    at: &[&str],
    owner: &str,
    body: &str,
    bodies: &HashMap<&str, usize>,
    body_names: &[&str],
) {
    if bodies.contains_key(body) {
        return;
    }
    let mut m = format!("{owner}: body {body:?} is not defined");
    if let Some(s) = c.suggest(body, body_names) {
        m.push_str(&format!("; did you mean {s:?}?"));
    }
    if body_names.is_empty() {
        m.push_str(" (no [[body]] is defined)");
    } else {
        m.push_str(&format!(
            " (defined bodies: {})",
            quoted_names(body_names.iter().copied())
        ));
    }
    c.error(at, m);
}

/// Turn `group`/`box` into a [`Selection`], reporting problems.
fn selection(
    c: &mut Checker<'_>,
    table: &str,
    idx: &str,
    owner: &str,
    group: &Option<String>,
    bbox: &Option<[[f64; 3]; 2]>,
) -> Option<Selection> {
    match (group, bbox) {
        (Some(_), Some(_)) => {
            c.error(
                &[table, idx, "box"],
                format!("{owner}: give either `group` or `box`, not both; remove one of them"),
            );
            None
        }
        (None, None) => {
            c.error(
                &[table, idx],
                format!(
                    "{owner}: no particles selected; add `group = \"<physical group>\"` or \
                     `box = [[xmin, ymin, zmin], [xmax, ymax, zmax]]`"
                ),
            );
            None
        }
        (Some(g), None) => {
            if g.is_empty() {
                c.error(
                    &[table, idx, "group"],
                    format!("{owner}: group is empty; name a gmsh physical group"),
                );
                None
            } else {
                Some(Selection::Group(g.clone()))
            }
        }
        (None, Some(b)) => {
            let at = [table, idx, "box"];
            if !c.finite(
                &at,
                owner,
                "box",
                &[b[0][0], b[0][1], b[0][2], b[1][0], b[1][1], b[1][2]],
            ) {
                return None;
            }
            let mut ok = true;
            for (axis, name) in ["x", "y", "z"].iter().enumerate() {
                if b[0][axis] > b[1][axis] {
                    c.error(
                        &at,
                        format!(
                            "{owner}: box min {name} = {} is above max {name} = {}; write \
                             box = [[xmin, ymin, zmin], [xmax, ymax, zmax]]",
                            b[0][axis], b[1][axis]
                        ),
                    );
                    ok = false;
                }
            }
            ok.then_some(Selection::Box(*b))
        }
    }
}

/// Parse `dofs` ("xyz", "xz", …) into an `[x, y, z]` mask.
fn dofs(c: &mut Checker<'_>, at: &[&str], owner: &str, dofs: &str) -> Option<[bool; 3]> {
    if dofs.is_empty() {
        c.error(
            at,
            format!(
                "{owner}: dofs is empty; give a non-empty subset of \"xyz\", e.g. \"xyz\" or \"z\""
            ),
        );
        return None;
    }
    let mut mask = [false; 3];
    for ch in dofs.chars() {
        let axis = match ch {
            'x' => 0,
            'y' => 1,
            'z' => 2,
            other => {
                c.error(
                    at,
                    format!(
                        "{owner}: dofs = {dofs:?}: `{other}` is not a direction; use only the \
                         letters x, y, z (lower case)"
                    ),
                );
                return None;
            }
        };
        if mask[axis] {
            c.error(
                at,
                format!("{owner}: dofs = {dofs:?}: `{ch}` appears twice; give each letter once"),
            );
            return None;
        }
        mask[axis] = true;
    }
    Some(mask)
}

fn ramp(c: &mut Checker<'_>, idx: &str, owner: &str, points: &Option<Vec<[f64; 2]>>) -> Ramp {
    let Some(points) = points else {
        return Ramp::constant();
    };
    let at = ["load", idx, "ramp"];
    if points.is_empty() {
        c.error(
            &at,
            format!(
                "{owner}: ramp has no points; give at least one [t, factor] point, or remove \
                 `ramp` for a constant factor 1"
            ),
        );
        return Ramp::constant();
    }
    let flat: Vec<f64> = points.iter().flatten().copied().collect();
    if !c.finite(&at, owner, "ramp", &flat) {
        return Ramp::constant();
    }
    for (k, w) in points.windows(2).enumerate() {
        if w[1][0] < w[0][0] {
            let i = (k + 1).to_string();
            c.error(
                &["load", idx, "ramp", &i],
                format!(
                    "{owner}: ramp times must not decrease, but point {} (t = {}) comes after \
                     t = {}; sort the points by time",
                    k + 2,
                    w[1][0],
                    w[0][0]
                ),
            );
        }
    }
    for (k, w) in points.windows(3).enumerate() {
        if w[0][0] == w[1][0] && w[1][0] == w[2][0] {
            let i = (k + 2).to_string();
            c.error(
                &["load", idx, "ramp", &i],
                format!(
                    "{owner}: ramp has more than two points at t = {}; a jump needs exactly two \
                     (the value before and the value after)",
                    w[0][0]
                ),
            );
        }
    }
    Ramp {
        points: points.clone(),
    }
}

/// Validate a parsed scene, turning it into a [`Scene`], or list every problem.
pub(crate) fn validate(
    raw: RawScene,
    path: &Path,
    text: Option<&str>,
    spans: Option<&SpanIndex>,
) -> Result<Scene, SceneError> {
    let mut c = Checker::new(text, spans);

    // [run]
    let run = &raw.run;
    c.positive(&["run", "t_end"], "[run]", "t_end", run.t_end, "seconds");
    if let TimeStep::Fixed(dt) = run.dt {
        c.positive(&["run", "dt"], "[run]", "dt", dt, "seconds, or \"auto\"");
    }
    c.finite(&["run", "gravity"], "[run]", "gravity", &run.gravity);
    if let Some(every) = run.probe_every {
        c.positive(
            &["run", "probe_every"],
            "[run]",
            "probe_every",
            every,
            "seconds",
        );
    }
    let safety = run.dt_safety;
    if c.finite(&["run", "dt_safety"], "[run]", "dt_safety", &[safety])
        && !(safety > 0.0 && safety <= 1.0)
    {
        c.error(
            &["run", "dt_safety"],
            format!(
                "[run]: dt_safety = {safety}: must be in (0, 1], the fraction of the stable time \
                 step used by dt = \"auto\"; e.g. 0.9"
            ),
        );
    }

    if run.integrator == Integrator::Newmark {
        let (beta, gamma) = (run.beta, run.gamma);
        if c.finite(&["run", "beta"], "[run]", "beta", &[beta, gamma])
            && !((0.0..=1.0).contains(&gamma) && (0.0..=0.5).contains(&beta))
        {
            c.error(
                &["run", "beta"],
                format!(
                    "[run]: beta = {beta}, gamma = {gamma}: Newmark needs 0 <= gamma <= 1 and \
                     0 <= 2 beta <= 1 (paper 001 Eq. 16); e.g. beta = 0.25, gamma = 0.5"
                ),
            );
        }
        let fraction = raw.bonded.as_ref().and_then(|b| b.critical_fraction);
        if beta > 0.0 && run.dt == TimeStep::Auto && fraction.is_none() {
            c.error(
                &["run", "dt"],
                "[run]: implicit Newmark (beta > 0) has no stable-step bound to choose dt from: \
                 give dt in seconds"
                    .to_owned(),
            );
        }
    }

    // [[material]]
    if raw.materials.is_empty() {
        c.error(
            &[],
            "no [[material]] is defined; a scene needs at least one material".to_owned(),
        );
    }
    let materials = unique_names(
        &mut c,
        "material",
        raw.materials.iter().map(|m| m.name.as_str()),
    );
    for (i, m) in raw.materials.iter().enumerate() {
        let idx = i.to_string();
        let l = label("material", i, Some(&m.name));
        c.positive(
            &["material", &idx, "density"],
            &l,
            "density",
            m.density,
            "kg/m³",
        );
        c.positive(&["material", &idx, "young"], &l, "young", m.young, "Pa");
        let at = ["material", idx.as_str(), "poisson"];
        let nu = m.poisson;
        if c.finite(&at, &l, "poisson", &[nu]) {
            if nu >= 0.5 {
                c.error(
                    &at,
                    format!(
                        "{l}: poisson = {nu}: ν must be below 0.5 (incompressible materials are \
                         not supported by an explicit step; use 0.49 at most)"
                    ),
                );
            } else if nu <= -1.0 {
                c.error(
                    &at,
                    format!(
                        "{l}: poisson = {nu}: ν must be above −1 (the material would be unstable)"
                    ),
                );
            }
        }
        c.non_negative(
            &["material", &idx, "shear_viscosity"],
            &l,
            "shear_viscosity",
            m.shear_viscosity,
            "Pa s",
        );
        c.non_negative(
            &["material", &idx, "bulk_viscosity"],
            &l,
            "bulk_viscosity",
            m.bulk_viscosity,
            "Pa s",
        );
    }
    let material_names: Vec<&str> = raw.materials.iter().map(|m| m.name.as_str()).collect();

    // [[body]]
    if raw.bodies.is_empty()
        && raw.bonded.is_none()
        && raw.granular.is_none()
        && raw.ballast.is_none()
    {
        c.error(
            &[],
            "no [[body]] is defined; a scene needs at least one body".to_owned(),
        );
    }
    let mut bodies = unique_names(&mut c, "body", raw.bodies.iter().map(|b| b.name.as_str()));
    let mut body_names: Vec<&str> = raw.bodies.iter().map(|b| b.name.as_str()).collect();
    if let Some(b) = &raw.bonded {
        bonded_table(&mut c, &raw, b, &material_names);
        bodies.insert(b.name.as_str(), body_names.len());
        body_names.push(b.name.as_str());
    }
    if let Some(b) = &raw.ballast {
        ballast_table(&mut c, &raw, b, &material_names);
        if bodies.contains_key(b.name.as_str()) {
            c.error(
                &["ballast", "name"],
                format!(
                    "[ballast] {:?}: a [[body]] has the same name; rename one",
                    b.name
                ),
            );
        }
        bodies.insert(b.name.as_str(), body_names.len());
        body_names.push(b.name.as_str());
    }
    for (i, b) in raw.bodies.iter().enumerate() {
        let idx = i.to_string();
        let l = label("body", i, Some(&b.name));
        if b.mesh.as_os_str().is_empty() {
            c.error(
                &["body", &idx, "mesh"],
                format!("{l}: mesh is empty; give the gmsh file, relative to the scene file"),
            );
        }
        if !materials.contains_key(b.material.as_str()) {
            let mut m = format!("{l}: material {:?} is not defined", b.material);
            if let Some(s) = c.suggest(&b.material, &material_names) {
                m.push_str(&format!("; did you mean {s:?}?"));
            }
            if material_names.is_empty() {
                m.push_str(" (no [[material]] is defined)");
            } else {
                m.push_str(&format!(
                    " (defined materials: {})",
                    quoted_names(material_names.iter().copied())
                ));
            }
            c.error(&["body", &idx, "material"], m);
        }
    }

    // [[fix]]
    let rigid_bodies: HashSet<&str> = raw
        .bodies
        .iter()
        .filter(|b| b.rigid)
        .map(|b| b.name.as_str())
        .collect();
    let mut fixes = Vec::with_capacity(raw.fixes.len());
    for (i, f) in raw.fixes.iter().enumerate() {
        let idx = i.to_string();
        let l = label("fix", i, None);
        body_ref(
            &mut c,
            &["fix", &idx, "body"],
            &l,
            &f.body,
            &bodies,
            &body_names,
        );
        let sel = selection(&mut c, "fix", &idx, &l, &f.group, &f.bbox);
        let mask = dofs(&mut c, &["fix", &idx, "dofs"], &l, &f.dofs);
        let rigid = rigid_bodies.contains(f.body.as_str());
        if f.rotation && !rigid {
            c.error(
                &["fix", &idx, "rotation"],
                format!(
                    "{l}: rotation = true holds a rigid body's rotation, but body {:?} is not \
                     rigid; fix: set `rigid = true` on the body or drop `rotation`",
                    f.body
                ),
            );
        }
        if let (Some(selection), Some(dofs)) = (sel, mask) {
            fixes.push(Fix {
                body: f.body.clone(),
                selection,
                dofs,
                rotation: f.rotation,
            });
        }
    }

    // [[load]]
    let mut loads = Vec::with_capacity(raw.loads.len());
    for (i, ld) in raw.loads.iter().enumerate() {
        let idx = i.to_string();
        let l = label("load", i, None);
        body_ref(
            &mut c,
            &["load", &idx, "body"],
            &l,
            &ld.body,
            &bodies,
            &body_names,
        );
        let sel = selection(&mut c, "load", &idx, &l, &ld.group, &ld.bbox);
        c.finite(
            &["load", &idx, "total_force"],
            &l,
            "total_force",
            &ld.total_force,
        );
        let ramp = ramp(&mut c, &idx, &l, &ld.ramp);
        if let Some(cyclic) = &ld.cyclic {
            cyclic_load(&mut c, &idx, &l, cyclic, ld.ramp.is_some());
        }
        if let Some(series) = &ld.series {
            series_load(
                &mut c,
                &idx,
                &l,
                series,
                ld.ramp.is_some() || ld.cyclic.is_some(),
            );
        }
        if let Some(selection) = sel {
            loads.push(Load {
                body: ld.body.clone(),
                selection,
                total_force: ld.total_force,
                ramp,
                cyclic: ld.cyclic,
                series: ld.series.clone(),
            });
        }
    }

    // [[probe]]
    unique_names(&mut c, "probe", raw.probes.iter().map(|p| p.name.as_str()));
    for (i, p) in raw.probes.iter().enumerate() {
        let idx = i.to_string();
        let l = label("probe", i, Some(&p.name));
        body_ref(
            &mut c,
            &["probe", &idx, "body"],
            &l,
            &p.body,
            &bodies,
            &body_names,
        );
        c.finite(&["probe", &idx, "point"], &l, "point", &p.point);
    }

    section_tables(&mut c, &raw);
    contact_tables(&mut c, &raw);
    if let Some(g) = &raw.granular {
        granular_table(&mut c, &raw, g, &material_names);
    }
    if let Some(p) = &raw.periodic {
        periodic_table(&mut c, &raw, p);
    }

    // [output]
    c.non_negative(
        &["output", "vtu_every"],
        "[output]",
        "vtu_every",
        raw.output.vtu_every,
        "seconds",
    );
    c.non_negative(
        &["output", "checkpoint_every"],
        "[output]",
        "checkpoint_every",
        raw.output.checkpoint_every,
        "seconds",
    );

    if !c.found.is_empty() {
        let mut found = c.found;
        found.sort_by_key(|(offset, _)| offset.unwrap_or(usize::MAX));
        return Err(SceneError::Invalid(located(path, text, found)));
    }
    Ok(Scene {
        run: raw.run,
        materials: raw.materials,
        bodies: raw.bodies,
        fixes,
        loads,
        probes: raw.probes,
        sections: raw.sections,
        contact: raw.contact,
        walls: raw.walls,
        bonded: raw.bonded,
        periodic: raw.periodic,
        granular: raw.granular,
        ballast: raw.ballast,
        output: raw.output,
        path: path.to_path_buf(),
    })
}

/// `cyclic` of a `[[load]]`: finite factors, a positive frequency, not with `ramp`.
fn cyclic_load(c: &mut Checker<'_>, idx: &str, l: &str, cyclic: &CyclicLoad, has_ramp: bool) {
    let at = ["load", idx, "cyclic"];
    let CyclicLoad {
        min,
        max,
        frequency,
        phase_deg,
        start,
    } = *cyclic;
    c.finite(&at, l, "cyclic", &[min, max, phase_deg, start]);
    c.positive(&at, l, "cyclic.frequency", frequency, "Hz");
    if has_ramp {
        c.error(
            &at,
            format!("{l}: give either `ramp` or `cyclic`, not both; drop one"),
        );
    }
}

/// `series` of a `[[load]]`: a file and a column, not with `ramp` or `cyclic`.
fn series_load(c: &mut Checker<'_>, idx: &str, l: &str, series: &Series, other: bool) {
    let at = ["load", idx, "series"];
    if series.column.trim().is_empty() {
        c.error(
            &at,
            format!("{l}: series.column is empty; name a column of the CSV header"),
        );
    }
    if other {
        c.error(
            &at,
            format!("{l}: give one time factor: `ramp`, `cyclic` or `series`; drop the others"),
        );
    }
}

/// `[ballast]`: its material, meshes, count, radius, boxes and that it can touch.
fn ballast_table(c: &mut Checker<'_>, raw: &RawScene, b: &Ballast, materials: &[&str]) {
    let l = format!("[ballast] {:?}", b.name);
    stone_table(c, raw, "ballast", &l, &b.material, materials, "ballast");
    if b.meshes.is_empty() {
        c.error(
            &["ballast", "meshes"],
            format!("{l}: meshes is empty; list the stone meshes (gmsh files)"),
        );
    }
    if b.count == 0 {
        c.error(
            &["ballast", "count"],
            format!("{l}: count must be at least 1"),
        );
    }
    c.finite(&["ballast", "velocity"], &l, "velocity", &b.velocity);
    c.positive(
        &["ballast", "contact_radius"],
        &l,
        "contact_radius",
        b.contact_radius,
        "m",
    );
    for (key, bx) in [("region", Some(&b.region)), ("exclude", b.exclude.as_ref())] {
        if let Some(bx) = bx {
            box_corners(c, "ballast", &l, key, bx);
        }
    }
}

/// What `[granular]` and `[ballast]` share: a defined material, a `[contact]` table, no
/// `[bonded]` body (`holds` names what a bonded scene cannot hold).
fn stone_table(
    c: &mut Checker<'_>,
    raw: &RawScene,
    table: &str,
    l: &str,
    material: &str,
    materials: &[&str],
    holds: &str,
) {
    if !materials.contains(&material) {
        c.error(
            &[table, "material"],
            format!(
                "{l}: material {material:?} is not defined (defined materials: {})",
                quoted_names(materials.iter().copied())
            ),
        );
    }
    if raw.contact.is_none() {
        c.error(
            &[table],
            format!("{l}: stones touch through contacts: add a [contact] table"),
        );
    }
    if raw.bonded.is_some() {
        c.error(
            &[table],
            format!("{l}: a [bonded] scene cannot hold {holds}; drop one"),
        );
    }
}

/// A box `key` of `table`: finite corners, the upper above the lower on every axis.
fn box_corners(c: &mut Checker<'_>, table: &str, l: &str, key: &str, b: &[[f64; 3]; 2]) {
    if c.finite(&[table, key], l, key, &b.concat()) && (0..3).any(|k| b[1][k] <= b[0][k]) {
        c.error(
            &[table, key],
            format!(
                "{l}: {key} = {b:?}: the upper corner must lie above the lower one on every axis"
            ),
        );
    }
}

/// `[[section]]`: unique names, one axis, a finite plane, and contacts to measure.
fn section_tables(c: &mut Checker<'_>, raw: &RawScene) {
    unique_names(c, "section", raw.sections.iter().map(|s| s.name.as_str()));
    for (i, s) in raw.sections.iter().enumerate() {
        let idx = i.to_string();
        let l = label("section", i, Some(&s.name));
        if !matches!(s.axis.as_str(), "x" | "y" | "z") {
            c.error(
                &["section", &idx, "axis"],
                format!(
                    "{l}: axis = {:?}: name the one axis the plane is normal to, \"x\", \"y\" \
                     or \"z\"",
                    s.axis
                ),
            );
        }
        c.finite(&["section", &idx, "at"], &l, "at", &[s.at]);
        if raw.contact.is_none() {
            c.error(
                &["section", &idx],
                format!(
                    "{l} measures contact forces, but the scene has no [contact]; add one or \
                     remove the section"
                ),
            );
        }
    }
}

/// The axes named by `text` ("x", "y", "z" once each), or an error naming the table.
fn axes_of(c: &mut Checker<'_>, at: &[&str], label: &str, text: &str) -> Option<Vec<usize>> {
    let mut axes = Vec::new();
    for ch in text.chars() {
        match "xyz".find(ch) {
            Some(k) if !axes.contains(&k) => axes.push(k),
            _ => {
                c.error(
                    at,
                    format!(
                        "{label}: axes = {text:?}: give each of x, y, z at most once, e.g. \"y\" \
                         or \"xy\""
                    ),
                );
                return None;
            }
        }
    }
    if axes.is_empty() {
        c.error(
            at,
            format!("{label}: axes is empty; name the periodic axes, e.g. \"y\""),
        );
        return None;
    }
    Some(axes)
}

/// `[periodic]`: axes, one period each (from `length` or `box`), the time delay's body,
/// axis and lag.
fn periodic_table(c: &mut Checker<'_>, raw: &RawScene, p: &Periodic) {
    let l = "[periodic]";
    let axes = axes_of(c, &["periodic", "axes"], l, &p.axes);
    match (&p.length, &p.bbox) {
        (Some(_), Some(_)) | (None, None) => c.error(
            &["periodic"],
            format!("{l}: give the periods as `length` (one per axis) or the cell as `box`, one of the two"),
        ),
        (Some(length), None) => {
            if axes.as_ref().is_some_and(|a| a.len() != length.len()) {
                c.error(
                    &["periodic", "length"],
                    format!(
                        "{l}: length has {} entries for axes = {:?}; give one period per axis",
                        length.len(),
                        p.axes
                    ),
                );
            }
            for v in length {
                c.positive(&["periodic", "length"], l, "length", *v, "m");
            }
        }
        (None, Some(b)) => {
            if let Some(axes) = &axes {
                for &k in axes {
                    c.positive(&["periodic", "box"], l, "box extent", b[1][k] - b[0][k], "m");
                }
            }
        }
    }
    if p.bbox.is_some() && p.origin.is_some() {
        c.error(
            &["periodic", "origin"],
            format!("{l}: `box` already sets the origin; drop `origin`"),
        );
    }
    let Some(d) = &p.time_delay else { return };
    let l = "[periodic.time_delay]";
    let cyclic = raw
        .loads
        .iter()
        .any(|ld| ld.body == d.body && ld.cyclic.is_some());
    if !cyclic {
        c.error(
            &["periodic", "time_delay", "body"],
            format!(
                "{l}: body {:?} carries no [[load]] with `cyclic`; the delay follows the phase of \
                 that load: give the sleeper's [[load]] a `cyclic` factor",
                d.body
            ),
        );
    }
    match (&d.axis, &axes) {
        (Some(a), Some(axes))
            if a.len() != 1 || !axes.contains(&"xyz".find(a.as_str()).unwrap_or(3)) =>
        {
            c.error(
                &["periodic", "time_delay", "axis"],
                format!(
                    "{l}: axis = {a:?} is not one of the periodic axes {:?}",
                    p.axes
                ),
            );
        }
        (None, Some(axes)) if axes.len() > 1 => c.error(
            &["periodic", "time_delay"],
            format!(
                "{l}: the cell is periodic along {:?}; say which axis the load travels along \
                 with `axis`",
                p.axes
            ),
        ),
        _ => {}
    }
    match (d.lag_deg, d.sleeper_spacing, d.speed) {
        (Some(lag), None, None) => {
            c.finite(&["periodic", "time_delay", "lag_deg"], l, "lag_deg", &[lag]);
        }
        (None, Some(s), Some(v)) => {
            c.positive(
                &["periodic", "time_delay", "sleeper_spacing"],
                l,
                "sleeper_spacing",
                s,
                "m",
            );
            c.positive(&["periodic", "time_delay", "speed"], l, "speed", v, "m/s");
        }
        (None, None, None) => {}
        _ => c.error(
            &["periodic", "time_delay"],
            format!(
                "{l}: give the lag as `lag_deg`, or as `sleeper_spacing` with `speed`, not a mix"
            ),
        ),
    }
}

/// `[[body]] rest_on`: a `[granular]` of that name, and contact spheres to rest with.
fn rest_on_key(
    c: &mut Checker<'_>,
    raw: &RawScene,
    idx: &str,
    l: &str,
    has_spheres: bool,
    sample: &str,
) {
    let at = ["body", idx, "rest_on"];
    match &raw.granular {
        Some(g) if g.name == sample => {}
        Some(g) => c.error(
            &at,
            format!("{l}: rest_on = {sample:?} names no sample; the [granular] sample is {:?}", g.name),
        ),
        None => c.error(
            &at,
            format!("{l}: rest_on = {sample:?} needs a [granular] sample of that name to rest on; add one or drop rest_on"),
        ),
    }
    if !has_spheres {
        c.error(
            &at,
            format!("{l}: rest_on needs the body's contact_radius (its contact spheres are what rest on the stones)"),
        );
    }
}

/// `[[body]] pose_from`: a rigid body (a deformable one's shape would be lost), not also laid
/// with `rest_on`.
fn pose_from_key(c: &mut Checker<'_>, idx: &str, l: &str, b: &Body) {
    let at = ["body", idx, "pose_from"];
    if !b.rigid {
        c.error(
            &at,
            format!("{l}: pose_from places rigid bodies only (a poses file holds no shape); set rigid = true or drop pose_from"),
        );
    }
    if b.rest_on.is_some() {
        c.error(
            &at,
            format!("{l}: pose_from and rest_on both place the body; keep one"),
        );
    }
}

/// `[[body]] pose_body`, `pose_shift`: say which pose of a `pose_from` file, and where.
fn pose_options(c: &mut Checker<'_>, idx: &str, l: &str, b: &Body) {
    if b.pose_from.is_none() {
        for (key, given) in [
            ("pose_body", b.pose_body.is_some()),
            ("pose_shift", b.pose_shift != [0.0; 3]),
        ] {
            if given {
                c.error(
                    &["body", idx, key],
                    format!("{l}: {key} chooses a pose of a `pose_from` file; give pose_from or drop {key}"),
                );
            }
        }
    }
    c.finite(&["body", idx, "pose_shift"], l, "pose_shift", &b.pose_shift);
}

/// `[granular]`: its material, a sample file or a generation (region, count, grading), a crop.
fn granular_table(c: &mut Checker<'_>, raw: &RawScene, g: &Granular, materials: &[&str]) {
    let l = format!("[granular] {:?}", g.name);
    stone_table(
        c,
        raw,
        "granular",
        &l,
        &g.material,
        materials,
        "a [granular] sample",
    );
    let generates = g.region.is_some() || g.count.is_some() || g.grading.is_some();
    if !generates && g.sample.is_none() {
        c.error(
            &["granular"],
            format!("{l}: give a `sample` file, or `region`, `count` and `grading` to generate stones (or both: the generated stones go above the sample's)"),
        );
    }
    if generates {
        if g.region.is_none() || g.count.is_none() || g.grading.is_none() {
            c.error(
                &["granular"],
                format!("{l}: generating stones needs all of `region`, `count` and `grading`"),
            );
        }
        let [lo, hi] = g.spheres_per_stone;
        if lo == 0 || lo > hi {
            c.error(
                &["granular", "spheres_per_stone"],
                format!(
                    "{l}: spheres_per_stone = [{lo}, {hi}]: give [min, max] with 1 <= min <= max"
                ),
            );
        }
    }
    for (key, b) in [("region", &g.region), ("crop", &g.crop)] {
        if let Some(b) = b {
            box_corners(c, "granular", &l, key, b);
        }
    }
    copies_key(c, &l, g);
}

/// `[granular] copies`: translations of a sample file's stones, at least one.
fn copies_key(c: &mut Checker<'_>, l: &str, g: &Granular) {
    let at = ["granular", "copies"];
    if g.copies.is_empty() {
        c.error(
            &at,
            format!("{l}: copies = [] places no stone; give at least one translation, [[0, 0, 0]] for the sample where it is"),
        );
    }
    if g.sample.is_none() && g.copies != [[0.0; 3]] {
        c.error(
            &at,
            format!("{l}: copies repeats the stones of a `sample` file; give one or drop copies"),
        );
    }
    for t in &g.copies {
        c.finite(&at, l, "copies", t);
    }
}

/// `[bonded]`: ranges, its material, and what a bonded scene cannot have.
fn bonded_table(
    c: &mut Checker<'_>,
    raw: &RawScene,
    b: &super::schema::Bonded,
    materials: &[&str],
) {
    let l = "[bonded]";
    let at = |key: &'static str| ["bonded", key];
    if !materials.contains(&b.material.as_str()) {
        let mut m = format!("{l}: material {:?} is not defined", b.material);
        if let Some(s) = c.suggest(&b.material, materials) {
            m.push_str(&format!("; did you mean {s:?}?"));
        }
        c.error(&at("material"), m);
    }
    if !raw.bodies.is_empty() {
        c.error(
            &at("name"),
            format!(
                "{l}: a scene with a bonded body has no [[body]] (bonded bodies are 2D); fix: \
                 remove the [[body]] tables or the [bonded] table"
            ),
        );
    }
    if raw.run.integrator != Integrator::Newmark {
        c.error(
            &["run", "integrator"],
            "[run]: a bonded body needs integrator = \"newmark\" (its particles rotate); use \
             beta = 0 for explicit, beta = 0.25 for implicit"
                .to_owned(),
        );
    }
    for (what, list) in [("[[fix]]", raw.fixes.len()), ("[[load]]", raw.loads.len())] {
        if list > 0 {
            c.error(
                &[],
                format!(
                    "{what} does not apply to a bonded body; fix: hold it with [bonded] \
                     supports and load it with [bonded] top_load"
                ),
            );
        }
    }
    if c.finite(&at("size"), l, "size", &b.size) && !(b.size[0] > 0.0 && b.size[1] > 0.0) {
        c.error(
            &at("size"),
            format!("{l}: size = {:?}: both must be positive (m)", b.size),
        );
    }
    c.finite(&at("origin"), l, "origin", &b.origin);
    c.positive(&at("thickness"), l, "thickness", b.thickness, "m");
    c.positive(&at("element_size"), l, "element_size", b.element_size, "m");
    c.positive(
        &at("strength_mean"),
        l,
        "strength_mean",
        b.strength_mean,
        "Pa",
    );
    c.non_negative(&at("strength_std"), l, "strength_std", b.strength_std, "Pa");
    c.positive(&at("tolerance"), l, "tolerance", b.tolerance, "(relative)");
    c.non_negative(
        &at("contact_shear_ratio"),
        l,
        "contact_shear_ratio",
        b.contact_shear_ratio,
        "",
    );
    c.non_negative(&at("friction"), l, "friction", b.friction, "");
    c.non_negative(
        &at("top_load"),
        l,
        "top_load",
        b.top_load,
        "N/m (downwards)",
    );
    c.non_negative(&at("load_ramp"), l, "load_ramp", b.load_ramp, "s");
    if let Some(f) = b.critical_fraction {
        c.positive(
            &at("critical_fraction"),
            l,
            "critical_fraction",
            f,
            "(times ∆t_crit)",
        );
    }
    fraction(
        c,
        &at("damping_ratio"),
        l,
        "damping_ratio",
        b.damping_ratio,
        "a damping ratio",
    );
    fraction(
        c,
        &at("contact_damping_ratio"),
        l,
        "contact_damping_ratio",
        b.contact_damping_ratio,
        "a damping ratio",
    );
    if !(0.0..0.25).contains(&b.jitter) {
        c.error(
            &at("jitter"),
            format!("{l}: jitter = {}: must be in [0, 0.25) spacings", b.jitter),
        );
    }
}

/// A number in [0, 1).
fn fraction(c: &mut Checker<'_>, at: &[&str], label: &str, key: &str, v: f64, meaning: &str) {
    if c.finite(at, label, key, &[v]) && !(0.0..1.0).contains(&v) {
        c.error(
            at,
            format!("{label}: {key} = {v}: must be in [0, 1) ({meaning})"),
        );
    }
}

/// The body keys of contact, `[contact]` and `[[wall]]`.
fn contact_tables(c: &mut Checker<'_>, raw: &RawScene) {
    let run = &raw.run;
    let mut radii = Vec::new();
    for (i, b) in raw.bodies.iter().enumerate() {
        let idx = i.to_string();
        let l = label("body", i, Some(&b.name));
        if let Some(r) = b.contact_radius {
            c.positive(
                &["body", &idx, "contact_radius"],
                &l,
                "contact_radius",
                r,
                "m",
            );
            radii.push(r);
        }
        c.finite(&["body", &idx, "translate"], &l, "translate", &b.translate);
        c.finite(
            &["body", &idx, "rotate_deg"],
            &l,
            "rotate_deg",
            &b.rotate_deg,
        );
        c.finite(&["body", &idx, "velocity"], &l, "velocity", &b.velocity);
        if let Some(sample) = &b.rest_on {
            rest_on_key(c, raw, &idx, &l, b.contact_radius.is_some(), sample);
        }
        if b.pose_from.is_some() {
            pose_from_key(c, &idx, &l, b);
        }
        pose_options(c, &idx, &l, b);
        if b.rigid && run.integrator != Integrator::Verlet {
            c.error(
                &["body", &idx, "rigid"],
                format!(
                    "{l}: rigid bodies are integrated by integrator = \"verlet\" only, not \
                     {:?}; use verlet or make the body deformable",
                    run.integrator.name()
                ),
            );
        }
    }
    let Some(contact) = &raw.contact else {
        if !radii.is_empty() {
            c.error(
                &[],
                "a [[body]] has contact_radius but there is no [contact] table: add one with \
                 law, normal_stiffness, tangential_stiffness and friction"
                    .to_owned(),
            );
        }
        if !raw.walls.is_empty() {
            c.error(
                &["wall", "0"],
                "[[wall]] needs a [contact] table and bodies with contact_radius".to_owned(),
            );
        }
        return;
    };
    let l = "[contact]";
    if radii.is_empty() && raw.granular.is_none() && raw.ballast.is_none() {
        c.error(
            &["contact"],
            "[contact]: no [[body]] has contact_radius, so nothing can touch: give the bodies \
             that touch a contact_radius (m)"
                .to_owned(),
        );
    }
    match contact.law {
        ContactLawName::Linear => {
            for (key, v) in [
                ("normal_stiffness", contact.normal_stiffness),
                ("tangential_stiffness", contact.tangential_stiffness),
            ] {
                match v {
                    Some(k) => c.positive(&["contact", key], l, key, k, "N/m"),
                    None => c.error(
                        &["contact", "law"],
                        format!("{l}: the linear law needs {key} (N/m), e.g. 1.6e9"),
                    ),
                }
            }
        }
        ContactLawName::HertzMindlin => {
            for (key, v) in [
                ("normal_stiffness", contact.normal_stiffness),
                ("tangential_stiffness", contact.tangential_stiffness),
            ] {
                if v.is_some() {
                    c.error(
                        &["contact", key],
                        format!(
                            "{l}: {key} is for the linear law; hertz-mindlin takes its \
                             stiffness from each body's young and poisson: remove it, or use law = \"linear\""
                        ),
                    );
                }
            }
        }
    }
    c.non_negative(
        &["contact", "friction"],
        l,
        "friction",
        contact.friction,
        "",
    );
    fraction(
        c,
        &["contact", "damping_ratio"],
        l,
        "damping_ratio",
        contact.damping_ratio,
        "0 for no dashpot",
    );
    fraction(
        c,
        &["contact", "local_damping"],
        l,
        "local_damping",
        contact.local_damping,
        "0 for none, 0.7 for quasi-static packing",
    );
    if contact.local_damping > 0.0 && run.integrator != Integrator::Verlet {
        c.error(
            &["contact", "local_damping"],
            format!("{l}: local_damping needs integrator = \"verlet\""),
        );
    }
    if !radii.is_empty() && run.integrator != Integrator::Verlet && run.beta > 0.0 {
        c.error(
            &["run", "integrator"],
            "[run]: contacts need an explicit integrator (verlet, or newmark with beta = 0): \
             contact forces have no tangent"
                .to_owned(),
        );
    }
    if let Some(skin) = contact.skin {
        c.positive(&["contact", "skin"], l, "skin", skin, "m");
    }
    c.positive(
        &["contact", "overlap_tolerance"],
        l,
        "overlap_tolerance",
        contact.overlap_tolerance,
        "fraction of the reduced radius",
    );
    for (i, w) in raw.walls.iter().enumerate() {
        wall(c, i, w);
    }
}

fn wall(c: &mut Checker<'_>, i: usize, w: &super::schema::Wall) {
    let idx = i.to_string();
    let l = label("wall", i, None);
    match (&w.point, &w.normal, &w.mesh) {
        (Some(p), Some(n), None) => {
            c.finite(&["wall", &idx, "point"], &l, "point", p);
            if c.finite(&["wall", &idx, "normal"], &l, "normal", n) && n.iter().all(|&v| v == 0.0) {
                c.error(
                    &["wall", &idx, "normal"],
                    format!("{l}: normal is zero; give the direction towards the bodies"),
                );
            }
        }
        (None, None, Some(mesh)) if mesh.as_os_str().is_empty() => c.error(
            &["wall", &idx, "mesh"],
            format!("{l}: mesh is empty; give a gmsh file relative to the scene file"),
        ),
        (None, None, Some(_)) => {}
        _ => c.error(
            &["wall", &idx],
            format!(
                "{l}: give either point and normal (a plane) or mesh (a triangulated wall), not \
                 both and not only one of point and normal"
            ),
        ),
    }
    if let Some(f) = w.friction {
        c.non_negative(&["wall", &idx, "friction"], &l, "friction", f, "");
    }
    c.finite(&["wall", &idx, "velocity"], &l, "velocity", &w.velocity);
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
                let dofs = ['x', 'y', 'z']
                    .iter()
                    .zip(f.dofs)
                    .filter(|(_, on)| *on)
                    .map(|(c, _)| *c)
                    .collect();
                RawFix {
                    body: f.body.clone(),
                    group,
                    bbox,
                    dofs,
                    rotation: f.rotation,
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
                    total_force: l.total_force,
                    ramp: (!l.ramp.points.is_empty()).then(|| l.ramp.points.clone()),
                    cyclic: l.cyclic,
                    series: l.series.clone(),
                }
            })
            .collect(),
        probes: scene.probes.clone(),
        sections: scene.sections.clone(),
        contact: scene.contact.clone(),
        walls: scene.walls.clone(),
        bonded: scene.bonded.clone(),
        periodic: scene.periodic.clone(),
        granular: scene.granular.clone(),
        ballast: scene.ballast.clone(),
        output: scene.output.clone(),
    }
}

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
