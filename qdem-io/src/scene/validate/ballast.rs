//! `[ballast]`: what it shares with `[granular]` (a defined material, a `[contact]` table, no
//! `[bonded]` body), at least one stone mesh and one stone, a finite velocity, a positive
//! contact radius, and `region` and `exclude` boxes with the upper corner above the lower one.
//! Its name, which `[[fix]]`, `[[load]]` and `[[probe]]` may use, is checked with the bodies'.

use super::super::schema::{Ballast, RawScene};
use super::checker::{box_corners, Checker};
use super::granular::stone_table;
use super::material::Materials;

/// `[ballast]`: its material (returned as an index), meshes, count, radius, boxes and that it
/// can touch.
pub(super) fn ballast_table(
    c: &mut Checker<'_>,
    raw: &RawScene,
    b: &Ballast,
    materials: &Materials<'_>,
) -> Option<usize> {
    let l = format!("[ballast] {:?}", b.name);
    let material = stone_table(c, raw, "ballast", &l, &b.material, materials, "ballast");
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
    c.finite(
        &["ballast", "angular_velocity"],
        &l,
        "angular_velocity",
        &b.angular_velocity,
    );
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
    material
}
