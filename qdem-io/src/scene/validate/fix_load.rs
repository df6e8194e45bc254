//! `[[fix]]` and `[[load]]`: a defined body, particles selected by a physical `group` or a
//! `box` (one of the two; a box with its lower corner below its upper one), and for a fix
//! `dofs` (a subset of "xyz", or of its frame's letters), `rotation` only on a rigid body and
//! a `frame` (cylindrical with a non-zero `axis`, or an orthonormal basis) only on a
//! deformable one; for a load one finite
//! `total_force`, `pressure` or `traction` and one time factor: a `ramp` (non-decreasing times, at most two points at a
//! time), a `cyclic` factor or a `series` file.

use std::collections::HashSet;

use super::super::schema::{
    AreaLoad, CyclicLoad, Fix, FixFrame, FrameName, Load, Ramp, RawFix, RawFrame, RawLoad,
    RawScene, Selection, Series,
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
    let frame = fix_frame(c, &idx, &l, f, rigid);
    let mask =
        frame.and_then(|frame| dofs(c, &["fix", &idx, "dofs"], &l, &f.dofs, &frame.letters()));
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
    let fix = sel
        .zip(mask)
        .zip(frame)
        .map(|((selection, dofs), frame)| Fix {
            body: f.body.clone(),
            selection,
            dofs,
            rotation: f.rotation,
            frame,
        });
    (body, fix)
}

/// The frame of a `[[fix]]`: the axes without `frame`; a cylindrical frame with a finite
/// `axis_origin` and a finite, non-zero `axis` (normalised here); an orthonormal basis.
/// `axis` and `axis_origin` only with `frame = "cylindrical"`; no frame on a rigid body.
fn fix_frame(c: &mut Checker<'_>, idx: &str, l: &str, f: &RawFix, rigid: bool) -> Option<FixFrame> {
    let at = |key| ["fix", idx, key];
    let cylindrical = matches!(&f.frame, Some(RawFrame::Name(_)));
    for (key, given) in [
        ("axis", f.axis.is_some()),
        ("axis_origin", f.axis_origin.is_some()),
    ] {
        if given && !cylindrical {
            c.error(
                &at(key),
                format!(
                    "{l}: `{key}` is the axis of a cylindrical frame, but the fix has no \
                     `frame = \"cylindrical\"`; fix: add it, or drop `{key}`"
                ),
            );
            return None;
        }
    }
    let Some(frame) = f.frame.as_ref() else {
        return Some(FixFrame::Axes);
    };
    if rigid {
        c.error(
            &at("frame"),
            format!(
                "{l}: body {:?} is rigid, and a local frame holds the nodes of a deformable \
                 body only; fix: drop `frame` (a rigid body is held on x, y, z)",
                f.body
            ),
        );
        return None;
    }
    match frame {
        RawFrame::Name(FrameName::Cylindrical) => {
            let origin = f.axis_origin.unwrap_or([0.0; 3]);
            let Some(axis) = f.axis else {
                c.error(
                    &at("frame"),
                    format!(
                        "{l}: frame = \"cylindrical\" needs `axis`, the direction of the \
                         cylinder's axis, e.g. axis = [0.0, 0.0, 1.0] (and `axis_origin`, a point \
                         of it, default the origin)"
                    ),
                );
                return None;
            };
            let length = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
            let finite = origin.iter().all(|v| v.is_finite()) && length.is_finite();
            if !finite || length == 0.0 {
                c.error(
                    &at("axis"),
                    format!(
                        "{l}: axis = {axis:?} with axis_origin = {origin:?}: give finite \
                         numbers and a non-zero axis"
                    ),
                );
                return None;
            }
            let axis = axis.map(|v| v / length);
            Some(FixFrame::Cylindrical { origin, axis })
        }
        RawFrame::Basis(rows) => {
            let basis = qdem_core::Mat3::from_fn(|r, k| rows[k][r]);
            let finite = basis.iter().all(|v| v.is_finite());
            match finite.then(|| qdem_core::step::frames::check_orthonormal(&basis)) {
                Some(Ok(())) => Some(FixFrame::Basis(*rows)),
                Some(Err(e)) => {
                    c.error(&at("frame"), format!("{l}: frame = {rows:?}: {e}"));
                    None
                }
                None => {
                    c.error(
                        &at("frame"),
                        format!("{l}: frame = {rows:?}: give finite numbers"),
                    );
                    None
                }
            }
        }
    }
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

/// Parse `dofs` ("xyz", "xz", …, or of the frame's `letters`: "t" of "rtz") into a mask of the
/// frame's three directions.
fn dofs(
    c: &mut Checker<'_>,
    at: &[&str],
    owner: &str,
    dofs: &str,
    letters: &[char; 3],
) -> Option<[bool; 3]> {
    let names: String = letters.iter().collect();
    let framed = names != "xyz";
    if dofs.is_empty() {
        c.error(
            at,
            format!(
                "{owner}: dofs is empty; give a non-empty subset of \"{names}\", e.g. \
                 \"{names}\" or \"{}\"",
                letters[2]
            ),
        );
        return None;
    }
    let mut mask = [false; 3];
    for ch in dofs.chars() {
        let Some(axis) = letters.iter().position(|&l| l == ch) else {
            let hint = match framed {
                true => format!(
                    "; with `frame`, dofs names the frame's directions (default \"xyz\" does \
                     not: give them, e.g. dofs = \"{}\")",
                    letters[1]
                ),
                false => String::new(),
            };
            c.error(
                at,
                format!(
                    "{owner}: dofs = {dofs:?}: `{ch}` is not a direction; use only the letters \
                     {} (lower case){hint}",
                    letters.map(String::from).join(", ")
                ),
            );
            return None;
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
