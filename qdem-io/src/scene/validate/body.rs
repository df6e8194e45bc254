//! `[[body]]`: at least one body (or a `[bonded]`, `[granular]` or `[ballast]` instead), unique
//! names, a mesh and a defined material; its placement keys (finite `translate`, `rotate_deg`,
//! `velocity`, `angular_velocity`, `rest_on` on a `[granular]` sample, `pose_from` for rigid bodies only) and
//! `rigid` only with the Verlet integrator. The names it collects (the `[[body]]`s, then the
//! `[bonded]` or `[ballast]` body) are what `[[fix]]`, `[[load]]` and `[[probe]]` refer to.

use std::collections::HashMap;

use super::super::schema::{Body, Integrator, RawScene};
use super::checker::{label, quoted_names, unique_names, Checker};
use super::material::Materials;
use super::Refs;
use super::{ballast, bonded};

/// The bodies' names, to resolve references to them.
pub(super) struct Bodies<'a> {
    /// Index of each name: the `[[body]]`s in file order, then the `[bonded]` or `[ballast]`.
    index: HashMap<&'a str, usize>,
    /// Every body's name, in that order.
    names: Vec<&'a str>,
}

impl<'a> Bodies<'a> {
    /// Adds the body of a `[bonded]` or `[ballast]` table after the `[[body]]`s.
    fn push(&mut self, name: &'a str) {
        self.index.insert(name, self.names.len());
        self.names.push(name);
    }

    /// Whether a body is called `name`.
    pub(super) fn defines(&self, name: &str) -> bool {
        self.index.contains_key(name)
    }

    /// Index of the body `body` that `owner` (at `at`) refers to, or an error listing the
    /// defined bodies.
    pub(super) fn reference(
        &self,
        c: &mut Checker<'_>,
        at: &[&str],
        owner: &str,
        body: &str,
    ) -> Option<usize> {
        if let Some(&index) = self.index.get(body) {
            return Some(index);
        }
        let mut m = format!("{owner}: body {body:?} is not defined");
        if let Some(s) = c.suggest(body, &self.names) {
            m.push_str(&format!("; did you mean {s:?}?"));
        }
        if self.names.is_empty() {
            m.push_str(" (no [[body]] is defined)");
        } else {
            m.push_str(&format!(
                " (defined bodies: {})",
                quoted_names(self.names.iter().copied())
            ));
        }
        c.error(at, m);
        None
    }
}

/// Every `[[body]]`, and the `[bonded]` and `[ballast]` tables that add a body; returns the
/// bodies' names and fills the materials of the bodies, the ballast and the bonded body.
pub(super) fn body_tables<'a>(
    c: &mut Checker<'_>,
    raw: &'a RawScene,
    materials: &Materials<'_>,
    refs: &mut Refs,
) -> Bodies<'a> {
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
    let mut bodies = Bodies {
        index: unique_names(c, "body", raw.bodies.iter().map(|b| b.name.as_str())),
        names: raw.bodies.iter().map(|b| b.name.as_str()).collect(),
    };
    if let Some(b) = &raw.bonded {
        refs.bonded_material = bonded::bonded_table(c, raw, b, materials);
        bodies.push(b.name.as_str());
    }
    if let Some(b) = &raw.ballast {
        refs.ballast_material = ballast::ballast_table(c, raw, b, materials);
        if bodies.index.contains_key(b.name.as_str()) {
            c.error(
                &["ballast", "name"],
                format!(
                    "[ballast] {:?}: a [[body]] has the same name; rename one",
                    b.name
                ),
            );
        }
        bodies.push(b.name.as_str());
    }
    for (i, b) in raw.bodies.iter().enumerate() {
        if let Some(material) = body(c, i, b, materials) {
            refs.body_materials.push(material);
        }
    }
    bodies
}

/// One `[[body]]`'s mesh and material; returns the material's index.
fn body(c: &mut Checker<'_>, i: usize, b: &Body, materials: &Materials<'_>) -> Option<usize> {
    let idx = i.to_string();
    let l = label("body", i, Some(&b.name));
    if b.mesh.as_os_str().is_empty() {
        c.error(
            &["body", &idx, "mesh"],
            format!("{l}: mesh is empty; give the gmsh file, relative to the scene file"),
        );
    }
    let found = materials.get(&b.material);
    if found.is_none() {
        let mut m = format!("{l}: material {:?} is not defined", b.material);
        if let Some(s) = c.suggest(&b.material, &materials.names) {
            m.push_str(&format!("; did you mean {s:?}?"));
        }
        if materials.names.is_empty() {
            m.push_str(" (no [[material]] is defined)");
        } else {
            m.push_str(&format!(
                " (defined materials: {})",
                quoted_names(materials.names.iter().copied())
            ));
        }
        c.error(&["body", &idx, "material"], m);
    }
    found
}

/// The placement keys of every `[[body]]`: `contact_radius`, `translate`, `rotate_deg`,
/// `velocity`, `angular_velocity`, `rest_on`, `pose_from` and its options, `rigid`. Returns whether any body has
/// contact spheres.
pub(super) fn placement_keys(c: &mut Checker<'_>, raw: &RawScene) -> bool {
    let mut spheres = false;
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
            spheres = true;
        }
        c.finite(&["body", &idx, "translate"], &l, "translate", &b.translate);
        c.finite(
            &["body", &idx, "rotate_deg"],
            &l,
            "rotate_deg",
            &b.rotate_deg,
        );
        c.finite(&["body", &idx, "velocity"], &l, "velocity", &b.velocity);
        c.finite(
            &["body", &idx, "angular_velocity"],
            &l,
            "angular_velocity",
            &b.angular_velocity,
        );
        if let Some(sample) = &b.rest_on {
            rest_on_key(c, raw, &idx, &l, b.contact_radius.is_some(), sample);
        }
        if b.pose_from.is_some() {
            pose_from_key(c, &idx, &l, b);
        }
        pose_options(c, &idx, &l, b);
        rigid_key(c, raw, &idx, &l, b);
    }
    spheres
}

/// `[[body]] rigid`: integrated by Verlet only.
fn rigid_key(c: &mut Checker<'_>, raw: &RawScene, idx: &str, l: &str, b: &Body) {
    let integrator = raw.run.integrator;
    if b.rigid && integrator != Integrator::Verlet {
        c.error(
            &["body", idx, "rigid"],
            format!(
                "{l}: rigid bodies are integrated by integrator = \"verlet\" only, not \
                 {:?}; use verlet or make the body deformable",
                integrator.name()
            ),
        );
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
