//! `[bonded]`: a defined material; no `[[body]]`, `[[fix]]` or `[[load]]` beside it (it is held
//! by its `supports` and loaded by its `top_load`) and the Newmark integrator; a positive size,
//! thickness, element size, strength, tolerance, a finite origin, non-negative strength spread,
//! contact shear ratio, friction, load and ramp; damping ratios in [0, 1), jitter in [0, 0.25).

use super::super::schema::{Bonded, Integrator, RawScene};
use super::checker::{fraction, Checker};
use super::material::Materials;

/// `[bonded]`: its material (returned as an index), what a bonded scene cannot have, its
/// numbers.
pub(super) fn bonded_table(
    c: &mut Checker<'_>,
    raw: &RawScene,
    b: &Bonded,
    materials: &Materials<'_>,
) -> Option<usize> {
    let l = "[bonded]";
    let material = materials.position(&b.material);
    if material.is_none() {
        let mut m = format!("{l}: material {:?} is not defined", b.material);
        if let Some(s) = c.suggest(&b.material, &materials.names) {
            m.push_str(&format!("; did you mean {s:?}?"));
        }
        c.error(&["bonded", "material"], m);
    }
    exclusions(c, raw);
    bonded_numbers(c, b);
    material
}

/// What a bonded scene cannot have: `[[body]]`s, an integrator other than Newmark, fixes and
/// loads.
fn exclusions(c: &mut Checker<'_>, raw: &RawScene) {
    let l = "[bonded]";
    if !raw.bodies.is_empty() {
        c.error(
            &["bonded", "name"],
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
}

/// The numbers of `[bonded]`: sizes, strengths, tolerance, friction, load, damping, jitter.
fn bonded_numbers(c: &mut Checker<'_>, b: &Bonded) {
    let l = "[bonded]";
    let at = |key: &'static str| ["bonded", key];
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
    bonded_dynamics(c, b);
}

/// The step and damping keys of `[bonded]` and the packing's jitter.
fn bonded_dynamics(c: &mut Checker<'_>, b: &Bonded) {
    let l = "[bonded]";
    let at = |key: &'static str| ["bonded", key];
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
