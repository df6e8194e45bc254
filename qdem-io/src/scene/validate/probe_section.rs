//! `[[probe]]` and `[[section]]`, what a run measures: probes with unique names, a defined
//! body (or the `[granular]` sample) and a finite point (on the sample: a point, a stone from 1
//! or a box, one of them); sections with unique names, one axis, a finite plane and a
//! `[contact]` whose forces they sum.

use super::super::refs::ProbeTarget;
use super::super::schema::{Probe, RawScene};
use super::body::Bodies;
use super::checker::{box_corners, label, unique_names, Checker};
use super::Refs;

/// Every `[[probe]]`; fills what they sample.
pub(super) fn probe_tables(
    c: &mut Checker<'_>,
    raw: &RawScene,
    bodies: &Bodies<'_>,
    refs: &mut Refs,
) {
    unique_names(c, "probe", raw.probes.iter().map(|p| p.name.as_str()));
    for (i, p) in raw.probes.iter().enumerate() {
        let idx = i.to_string();
        let l = label("probe", i, Some(&p.name));
        let on_sample =
            raw.granular.as_ref().is_some_and(|g| g.name == p.body) && !bodies.defines(&p.body);
        if on_sample {
            grain_probe(c, &idx, &l, p);
            refs.probe_targets.push(ProbeTarget::Granular);
            continue;
        }
        let body = bodies.reference(c, &["probe", &idx, "body"], &l, &p.body);
        refs.probe_targets.extend(body.map(ProbeTarget::Body));
        for (key, given) in [("stone", p.stone.is_some()), ("box", p.region.is_some())] {
            if given {
                c.error(
                    &["probe", &idx, key],
                    format!(
                        "{l}: `{key}` picks stones of the [granular] sample, but {:?} is a body; \
                         give `point` (its nearest particle is sampled)",
                        p.body
                    ),
                );
            }
        }
        match p.point {
            Some(point) => {
                c.finite(&["probe", &idx, "point"], &l, "point", &point);
            }
            None => c.error(
                &["probe", &idx],
                format!("{l}: give `point`, the place on the body to sample"),
            ),
        }
    }
}

/// A probe on the `[granular]` sample: exactly one of `point`, `stone` (from 1) and `box`.
fn grain_probe(c: &mut Checker<'_>, idx: &str, l: &str, p: &Probe) {
    let given = [p.point.is_some(), p.stone.is_some(), p.region.is_some()];
    if given.iter().filter(|&&g| g).count() != 1 {
        c.error(
            &["probe", idx],
            format!(
                "{l}: a probe on the [granular] sample {:?} takes one of `point` (the stone \
                 nearest), `stone` (its number, from 1) and `box` (the stones inside, averaged)",
                p.body
            ),
        );
    }
    if let Some(point) = p.point {
        c.finite(&["probe", idx, "point"], l, "point", &point);
    }
    if p.stone == Some(0) {
        c.error(
            &["probe", idx, "stone"],
            format!("{l}: stone = 0: stones are counted from 1"),
        );
    }
    if let Some(b) = &p.region {
        box_corners(c, "probe", l, "box", b);
    }
}

/// `[[section]]`: unique names, one axis, a finite plane, and contacts to measure.
pub(super) fn section_tables(c: &mut Checker<'_>, raw: &RawScene) {
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
        if let Some(area) = s.area {
            c.positive(&["section", &idx, "area"], &l, "area", area, "m²");
        }
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
