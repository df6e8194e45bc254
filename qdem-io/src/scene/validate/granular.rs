//! `[granular]`: a defined material, a `[contact]` table and no `[bonded]` body (what it shares
//! with `[ballast]`, [`stone_table`]); a `sample` file or a generation (`region`, `count` and
//! `grading`, `count` at least 1, `spheres_per_stone` in order), boxes with the upper corner above the lower one,
//! at least one translation in `copies` (more only with a sample), finite initial velocities
//! (the `region_` ones only with a generation).

use super::super::schema::{Granular, RawScene};
use super::checker::{box_corners, quoted_names, Checker};
use super::material::Materials;

/// `[granular]`: its material (returned as an index), a sample file or a generation (region,
/// count, grading), a crop, a refill (only with a sample).
pub(super) fn granular_table(
    c: &mut Checker<'_>,
    raw: &RawScene,
    g: &Granular,
    materials: &Materials<'_>,
) -> Option<usize> {
    let l = format!("[granular] {:?}", g.name);
    let material = stone_table(
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
        if g.count == Some(0) {
            c.error(
                &["granular", "count"],
                format!(
                    "{l}: count = 0 generates no stone, so `region`, `count` and `grading` do \
                     nothing; fix: give count >= 1 (or, with a `sample`, remove all three to use \
                     the sample alone)"
                ),
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
    for (key, b) in [
        ("region", &g.region),
        ("crop", &g.crop),
        ("refill", &g.refill),
    ] {
        if let Some(b) = b {
            box_corners(c, "granular", &l, key, b);
        }
    }
    copies_key(c, &l, g);
    if g.refill.is_some() && g.sample.is_none() {
        c.error(
            &["granular", "refill"],
            format!(
                "{l}: refill moves a `sample` file's stones into a box; give one or drop refill"
            ),
        );
    }
    motion_keys(c, &l, g);
    material
}

/// `[granular] velocity`, `angular_velocity` and their `region_` forms: finite, and the
/// `region_` forms only with a generation.
fn motion_keys(c: &mut Checker<'_>, l: &str, g: &Granular) {
    c.finite(&["granular", "velocity"], l, "velocity", &g.velocity);
    c.finite(
        &["granular", "angular_velocity"],
        l,
        "angular_velocity",
        &g.angular_velocity,
    );
    for (key, value) in [
        ("region_velocity", g.region_velocity),
        ("region_angular_velocity", g.region_angular_velocity),
    ] {
        let Some(value) = value else { continue };
        c.finite(&["granular", key], l, key, &value);
        if g.region.is_none() {
            c.error(
                &["granular", key],
                format!(
                    "{l}: {key} sets the generated stones' motion, but nothing is generated \
                     (no `region`); use `{}` for the sample's stones",
                    key.trim_start_matches("region_")
                ),
            );
        }
    }
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

/// What `[granular]` and `[ballast]` share: a defined material, a `[contact]` table, no
/// `[bonded]` body (`holds` names what a bonded scene cannot hold). Returns the material's
/// index.
pub(super) fn stone_table(
    c: &mut Checker<'_>,
    raw: &RawScene,
    table: &str,
    l: &str,
    material: &str,
    materials: &Materials<'_>,
    holds: &str,
) -> Option<usize> {
    let found = materials.position(material);
    if found.is_none() {
        c.error(
            &[table, "material"],
            format!(
                "{l}: material {material:?} is not defined (defined materials: {})",
                quoted_names(materials.names.iter().copied())
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
    found
}
