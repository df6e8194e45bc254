//! `[[probe]]` and `[[section]]`, what a run measures: probes with unique names, a defined
//! body and a finite point; sections with unique names, one axis, a finite plane and a
//! `[contact]` whose forces they sum.

use super::super::schema::RawScene;
use super::body::Bodies;
use super::checker::{label, unique_names, Checker};
use super::Refs;

/// Every `[[probe]]`; fills their bodies' indices.
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
        let body = bodies.reference(c, &["probe", &idx, "body"], &l, &p.body);
        refs.probe_bodies.extend(body);
        c.finite(&["probe", &idx, "point"], &l, "point", &p.point);
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
