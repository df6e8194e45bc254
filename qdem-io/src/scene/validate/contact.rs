//! `[contact]` and `[[wall]]`: a contact table exactly when something can touch (bodies with
//! `contact_radius`, stones); the linear law's stiffnesses (and none for Hertz–Mindlin), a
//! non-negative friction and rolling friction, damping in [0, 1), local damping and contacts only with an explicit
//! integrator, a positive skin and overlap tolerance; each wall a plane (point and non-zero
//! normal) or a mesh; a servo only on a plane without a velocity, with a positive area and
//! maximum speed and a load path (`ramp`) as a `[[load]]`'s.

use super::super::schema::{Contact, ContactLawName, Integrator, RawScene, Wall, WallServo};
use super::checker::{fraction, label, Checker};

/// `[contact]` and every `[[wall]]` (`spheres`: whether a `[[body]]` has contact spheres).
pub(super) fn contact_tables(c: &mut Checker<'_>, raw: &RawScene, spheres: bool) {
    let Some(contact) = &raw.contact else {
        no_contact(c, raw, spheres);
        return;
    };
    if !spheres && raw.granular.is_none() && raw.ballast.is_none() {
        c.error(
            &["contact"],
            "[contact]: no [[body]] has contact_radius, so nothing can touch: give the bodies \
             that touch a contact_radius (m)"
                .to_owned(),
        );
    }
    law_keys(c, contact);
    contact_numbers(c, raw, contact, spheres);
    for (i, w) in raw.walls.iter().enumerate() {
        wall(c, i, w);
    }
}

/// Without `[contact]`: no body may have contact spheres and there may be no wall.
fn no_contact(c: &mut Checker<'_>, raw: &RawScene, spheres: bool) {
    if spheres {
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
}

/// The stiffnesses the law needs, and none it does not.
fn law_keys(c: &mut Checker<'_>, contact: &Contact) {
    let l = "[contact]";
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
}

/// Friction, damping, skin and overlap tolerance, and the integrator contacts need.
fn contact_numbers(c: &mut Checker<'_>, raw: &RawScene, contact: &Contact, spheres: bool) {
    let (l, run) = ("[contact]", &raw.run);
    c.non_negative(
        &["contact", "friction"],
        l,
        "friction",
        contact.friction,
        "",
    );
    c.non_negative(
        &["contact", "rolling_friction"],
        l,
        "rolling_friction",
        contact.rolling_friction,
        "0 for none",
    );
    fraction(
        c,
        &["contact", "damping_ratio"],
        l,
        "damping_ratio",
        contact.damping_ratio,
        "0 for no dashpot",
    );
    restitution(c, contact);
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
    if spheres && run.integrator != Integrator::Verlet && run.beta > 0.0 {
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
}

/// One `[[wall]]`: a plane or a mesh, a non-negative friction, a finite velocity.
fn wall(c: &mut Checker<'_>, i: usize, w: &Wall) {
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
    if let Some(servo) = &w.servo {
        wall_servo(c, &idx, &l, w, servo);
    }
}

/// A `[[wall]] servo`: on a plane without a `velocity`, a finite stress, a positive area and
/// maximum speed, a positive gain when given, a `ramp` as a `[[load]]`'s.
fn wall_servo(c: &mut Checker<'_>, idx: &str, l: &str, w: &Wall, servo: &WallServo) {
    if w.mesh.is_some() {
        c.error(
            &["wall", idx, "servo"],
            format!("{l}: servo is for a plane wall (point and normal), not a mesh wall"),
        );
    }
    if w.velocity != [0.0; 3] {
        c.error(
            &["wall", idx, "velocity"],
            format!("{l}: a servo wall's velocity is set by its servo; drop `velocity` or `servo`"),
        );
    }
    let at = ["wall", idx, "servo"];
    c.finite(&at, l, "servo.stress", &[servo.stress]);
    c.positive(&at, l, "servo.area", servo.area, "m²");
    c.positive(&at, l, "servo.max_velocity", servo.max_velocity, "m/s");
    if let Some(gain) = servo.gain {
        c.positive(&at, l, "servo.gain", gain, "m/(s·Pa)");
    }
    let owner = format!("{l} servo");
    super::fix_load::ramp(c, &["wall", idx, "servo", "ramp"], &owner, &servo.ramp);
}

/// `restitution`: in (0, 1], and not beside a `damping_ratio` (one of them sets the dashpots).
fn restitution(c: &mut Checker<'_>, contact: &Contact) {
    let Some(e) = contact.restitution else {
        return;
    };
    let at = ["contact", "restitution"];
    if c.finite(&at, "[contact]", "restitution", &[e]) && !(e > 0.0 && e <= 1.0) {
        c.error(
            &at,
            format!(
                "[contact]: restitution = {e}: must be in (0, 1] (1: no dashpot; a rebound \
                 ratio of 0 would need infinite damping)"
            ),
        );
    }
    if contact.damping_ratio != 0.0 {
        c.error(
            &at,
            format!(
                "[contact]: restitution = {e} and damping_ratio = {} both set the dashpots; \
                 give one of them",
                contact.damping_ratio
            ),
        );
    }
}
