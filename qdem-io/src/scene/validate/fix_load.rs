//! `[[fix]]` and `[[load]]`: a defined body, particles selected by a physical `group` or a
//! `box` (one of the two; a box with its lower corner below its upper one), and for a fix
//! `dofs` (a subset of "xyz") and `rotation` only on a rigid body; for a load one finite
//! `total_force`, `pressure` or `traction` and one time factor: a `ramp` (non-decreasing times, at most two points at a
//! time), a `cyclic` factor or a `series` file.

use std::collections::HashSet;

use super::super::schema::{
    AreaLoad, CyclicLoad, Fix, Load, Ramp, RawFix, RawLoad, RawScene, Selection, Series,
};
use super::body::Bodies;
use super::checker::{label, Checker};
use super::Refs;

/// Every `[[fix]]` as validated; fills their bodies' indices.
pub(super) fn fix_tables(
    c: &mut Checker<'_>,
    raw: &RawScene,
    bodies: &Bodies<'_>,
    refs: &mut Refs,
) -> Vec<Fix> {
    let rigid_bodies: HashSet<&str> = raw
        .bodies
        .iter()
        .filter(|b| b.rigid)
        .map(|b| b.name.as_str())
        .collect();
    let mut fixes = Vec::with_capacity(raw.fixes.len());
    for (i, f) in raw.fixes.iter().enumerate() {
        let rigid = rigid_bodies.contains(f.body.as_str());
        let (body, fix) = fix(c, i, f, bodies, rigid);
        if let Some(fix) = fix {
            fixes.push(fix);
            refs.fix_bodies.extend(body);
        }
    }
    fixes
}

/// One `[[fix]]` (`rigid`: whether its body is rigid): its body's index and the fix.
fn fix(
    c: &mut Checker<'_>,
    i: usize,
    f: &RawFix,
    bodies: &Bodies<'_>,
    rigid: bool,
) -> (Option<usize>, Option<Fix>) {
    let idx = i.to_string();
    let l = label("fix", i, None);
    let body = bodies.reference(c, &["fix", &idx, "body"], &l, &f.body);
    let sel = selection(c, "fix", &idx, &l, &f.group, &f.bbox);
    let mask = dofs(c, &["fix", &idx, "dofs"], &l, &f.dofs);
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
    let fix = sel.zip(mask).map(|(selection, dofs)| Fix {
        body: f.body.clone(),
        selection,
        dofs,
        rotation: f.rotation,
    });
    (body, fix)
}

/// Every `[[load]]` as validated; fills their bodies' indices.
pub(super) fn load_tables(
    c: &mut Checker<'_>,
    raw: &RawScene,
    bodies: &Bodies<'_>,
    refs: &mut Refs,
) -> Vec<Load> {
    let mut loads = Vec::with_capacity(raw.loads.len());
    for (i, ld) in raw.loads.iter().enumerate() {
        let (body, load) = load(c, i, ld, bodies);
        if let Some(load) = load {
            loads.push(load);
            refs.load_bodies.extend(body);
        }
    }
    loads
}

/// One `[[load]]`: its body's index and the load.
fn load(
    c: &mut Checker<'_>,
    i: usize,
    ld: &RawLoad,
    bodies: &Bodies<'_>,
) -> (Option<usize>, Option<Load>) {
    let idx = i.to_string();
    let l = label("load", i, None);
    let body = bodies.reference(c, &["load", &idx, "body"], &l, &ld.body);
    let sel = selection(c, "load", &idx, &l, &ld.group, &ld.bbox);
    let (total_force, area) = load_force(c, &idx, &l, ld);
    let ramp = ramp(c, &["load", &idx, "ramp"], &l, &ld.ramp);
    if let Some(cyclic) = &ld.cyclic {
        cyclic_load(c, &idx, &l, cyclic, ld.ramp.is_some());
    }
    if let Some(series) = &ld.series {
        series_load(
            c,
            &idx,
            &l,
            series,
            ld.ramp.is_some() || ld.cyclic.is_some(),
        );
    }
    let load = sel.map(|selection| Load {
        body: ld.body.clone(),
        selection,
        total_force,
        area,
        ramp,
        cyclic: ld.cyclic,
        series: ld.series.clone(),
    });
    (body, load)
}

/// What a `[[load]]` applies: exactly one of `total_force` (finite), `pressure` (finite) and
/// `traction` (finite); the total force is zero for a pressure or traction.
fn load_force(
    c: &mut Checker<'_>,
    idx: &str,
    l: &str,
    ld: &RawLoad,
) -> ([f64; 3], Option<AreaLoad>) {
    let given = [
        ld.total_force.is_some(),
        ld.pressure.is_some(),
        ld.traction.is_some(),
    ];
    match given.iter().filter(|&&g| g).count() {
        0 => c.error(
            &["load", idx],
            format!(
                "missing key `total_force` in {l}; give the load as `total_force = [fx, fy, fz]` \
                 (N, shared equally by the selected particles), `pressure = p` (Pa, on the \
                 selected boundary faces) or `traction = [tx, ty, tz]` (Pa)"
            ),
        ),
        1 => {}
        _ => c.error(
            &["load", idx],
            format!("{l}: give one of `total_force`, `pressure` and `traction`; drop the others"),
        ),
    }
    if let Some(f) = ld.total_force {
        c.finite(&["load", idx, "total_force"], l, "total_force", &f);
    }
    if let Some(p) = ld.pressure {
        c.finite(&["load", idx, "pressure"], l, "pressure", &[p]);
    }
    if let Some(t) = ld.traction {
        c.finite(&["load", idx, "traction"], l, "traction", &t);
    }
    let area = match (ld.pressure, ld.traction) {
        (Some(p), _) => Some(AreaLoad::Pressure(p)),
        (None, Some(t)) => Some(AreaLoad::Traction(t)),
        (None, None) => None,
    };
    (ld.total_force.unwrap_or([0.0; 3]), area)
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
        (None, Some(b)) => box_selection(c, &[table, idx, "box"], owner, b),
    }
}

/// `box` of a fix or load: finite corners, the lower one below the upper one on every axis.
fn box_selection(
    c: &mut Checker<'_>,
    at: &[&str],
    owner: &str,
    b: &[[f64; 3]; 2],
) -> Option<Selection> {
    if !c.finite(
        at,
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
                at,
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

/// A `ramp` (of a `[[load]]`, a servo's) at the key path `at`: finite points, times that do
/// not decrease, at most two at a time.
pub(super) fn ramp(
    c: &mut Checker<'_>,
    at: &[&str],
    owner: &str,
    points: &Option<Vec<[f64; 2]>>,
) -> Ramp {
    let Some(points) = points else {
        return Ramp::constant();
    };
    if points.is_empty() {
        c.error(
            at,
            format!(
                "{owner}: ramp has no points; give at least one [t, factor] point, or remove \
                 `ramp` for a constant factor 1"
            ),
        );
        return Ramp::constant();
    }
    let flat: Vec<f64> = points.iter().flatten().copied().collect();
    if !c.finite(at, owner, "ramp", &flat) {
        return Ramp::constant();
    }
    for (k, w) in points.windows(2).enumerate() {
        if w[1][0] < w[0][0] {
            let i = (k + 1).to_string();
            c.error(
                &[at, &[i.as_str()]].concat(),
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
                &[at, &[i.as_str()]].concat(),
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

/// `cyclic` of a `[[load]]`: finite factors, `min` not above `max`, a positive frequency,
/// not with `ramp`.
fn cyclic_load(c: &mut Checker<'_>, idx: &str, l: &str, cyclic: &CyclicLoad, has_ramp: bool) {
    let at = ["load", idx, "cyclic"];
    let CyclicLoad {
        min,
        max,
        frequency,
        phase_deg,
        start,
    } = *cyclic;
    for (key, value) in [
        ("min", min),
        ("max", max),
        ("phase_deg", phase_deg),
        ("start", start),
    ] {
        c.finite(&at, l, &format!("cyclic.{key}"), &[value]);
    }
    if min > max {
        c.error(
            &at,
            format!(
                "{l}: cyclic min = {min} is above max = {max}; the factor runs from min up to \
                 max, each cycle beginning at min: swap them (phase_deg = 180 begins the \
                 cycles at the maximum)"
            ),
        );
    }
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
