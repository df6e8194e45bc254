//! `[[material]]`: at least one, unique non-empty names, a positive density and Young's
//! modulus, a Poisson ratio in (−1, 0.5), non-negative viscosities. The names it collects are
//! what `[[body]]`, `[granular]`, `[ballast]` and `[bonded]` refer to.

use std::collections::HashMap;

use super::super::schema::Material;
use super::checker::{label, unique_names, Checker};

/// The materials' names, to resolve references to them.
pub(super) struct Materials<'a> {
    /// Index of each non-empty name (the first material of that name).
    index: HashMap<&'a str, usize>,
    /// Every material's name, in file order.
    pub(super) names: Vec<&'a str>,
}

impl Materials<'_> {
    /// Index of the material `name` as `[[body]] material` finds it (empty names never match).
    pub(super) fn get(&self, name: &str) -> Option<usize> {
        self.index.get(name).copied()
    }

    /// Index of the first material called `name`, as the stone and bonded tables find it.
    pub(super) fn position(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| *n == name)
    }
}

/// Every `[[material]]`; returns their names.
pub(super) fn material_tables<'a>(c: &mut Checker<'_>, materials: &'a [Material]) -> Materials<'a> {
    if materials.is_empty() {
        c.error(
            &[],
            "no [[material]] is defined; a scene needs at least one material".to_owned(),
        );
    }
    let index = unique_names(c, "material", materials.iter().map(|m| m.name.as_str()));
    for (i, m) in materials.iter().enumerate() {
        material(c, i, m);
    }
    Materials {
        index,
        names: materials.iter().map(|m| m.name.as_str()).collect(),
    }
}

/// One `[[material]]`'s numbers.
fn material(c: &mut Checker<'_>, i: usize, m: &Material) {
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
    poisson(c, &idx, &l, m.poisson);
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

/// `poisson` in (−1, 0.5).
fn poisson(c: &mut Checker<'_>, idx: &str, l: &str, nu: f64) {
    let at = ["material", idx, "poisson"];
    if !c.finite(&at, l, "poisson", &[nu]) {
        return;
    }
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
            format!("{l}: poisson = {nu}: ν must be above −1 (the material would be unstable)"),
        );
    }
}
