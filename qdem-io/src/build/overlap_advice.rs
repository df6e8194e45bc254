//! What to change in the scene when the contact set-up refuses the start: two bodies that
//! overlap, a body that penetrates a wall, a body inside another
//! ([`qdem_contact::ContactError::InitialOverlap`], `InitialWallOverlap`, `InitialInside`).
//! The contact crate names the bodies; this names, for the table each comes from, the keys
//! that move it or shrink its contact spheres, and `[contact] overlap_tolerance` where a
//! larger tolerance would accept the overlap. Every key named is one of
//! [`crate::scene::keys::SCENE_KEYS`] (the tests hold each table's list to it): a `[granular]`
//! stone has no `translate` or `contact_radius`, its place is a row of its sample.

use crate::scene::Scene;
use qdem_contact::ContactError;

/// The scene table a body of the contact model comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Source {
    /// A `[[body]]`.
    Body,
    /// A stone of the `[granular]` sample.
    Granular,
    /// A stone of the `[ballast]`.
    Ballast,
    /// A `[[wall]]`.
    Wall,
}

/// Every source, for the tests.
#[cfg(test)]
const SOURCES: [Source; 4] = [
    Source::Body,
    Source::Granular,
    Source::Ballast,
    Source::Wall,
];

/// The table (as written in a scene) and the keys of it that move a body of `source`, or
/// shrink its contact spheres.
fn placement(source: Source) -> (&'static str, &'static [&'static str]) {
    match source {
        Source::Body => ("[[body]]", &["translate", "contact_radius"]),
        Source::Granular => ("[granular]", &["sample", "crop"]),
        Source::Ballast => ("[ballast]", &["region", "exclude", "contact_radius"]),
        Source::Wall => ("[[wall]]", &["point"]),
    }
}

/// The key whose larger value accepts an initial overlap.
const TOLERANCE: (&str, &str) = ("[contact]", "overlap_tolerance");

/// The table the contact body `name` comes from: a `[[body]]` of that name, or a stone
/// (`<sample> stone <k>`) of the `[granular]` or `[ballast]` sample.
fn source_of(scene: &Scene, name: &str) -> Option<Source> {
    let stone_of = |sample: &str| {
        name.strip_prefix(sample)
            .and_then(|rest| rest.strip_prefix(" stone "))
            .is_some_and(|k| k.parse::<usize>().is_ok())
    };
    if scene.bodies.iter().any(|b| b.name == name) {
        Some(Source::Body)
    } else if scene.granular.as_ref().is_some_and(|g| stone_of(&g.name)) {
        Some(Source::Granular)
    } else if scene.ballast.as_ref().is_some_and(|b| stone_of(&b.name)) {
        Some(Source::Ballast)
    } else {
        None
    }
}

/// The advice for `error` in `scene`: the keys of each body's table (in the error's order,
/// each table once), then `overlap_tolerance` where a larger one would accept the start;
/// `None` for the contact crate's other errors.
pub(crate) fn advice(scene: &Scene, error: &ContactError) -> Option<String> {
    let (names, wall, tolerance): (Vec<&str>, bool, bool) = match error {
        ContactError::InitialOverlap { a, b, .. } => (vec![a, b], false, true),
        ContactError::InitialWallOverlap { body, .. } => (vec![body], true, true),
        ContactError::InitialInside { body, .. } => (vec![body], false, false),
        _ => return None,
    };
    let mut sources: Vec<Source> = names.iter().filter_map(|n| source_of(scene, n)).collect();
    if wall {
        sources.push(Source::Wall);
    }
    sources.dedup();
    Some(render(&sources, tolerance, scene))
}

/// The advice's text: ``[[body]] `translate` or `contact_radius`; [granular] `sample` (the
/// stones' rows) or `crop`; or a larger [contact] `overlap_tolerance` (now 0.05)``.
fn render(sources: &[Source], tolerance: bool, scene: &Scene) -> String {
    let mut parts: Vec<String> = sources
        .iter()
        .map(|&s| {
            let (table, keys) = placement(s);
            let keys: Vec<String> = keys
                .iter()
                .map(|&k| match (s, k) {
                    (Source::Granular, "sample") => "`sample` (the stones' rows)".to_string(),
                    _ => format!("`{k}`"),
                })
                .collect();
            format!("{table} {}", keys.join(" or "))
        })
        .collect();
    if tolerance {
        let now = scene.contact.as_ref().map(|c| c.overlap_tolerance);
        let now = now.map(|t| format!(" (now {t})")).unwrap_or_default();
        parts.push(format!(
            "or a larger {} `{}`{now}",
            TOLERANCE.0, TOLERANCE.1
        ));
    }
    parts.join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::keys::SCENE_KEYS;

    /// Every key an advice can name is a key of its table.
    #[test]
    fn every_key_named_in_an_advice_is_a_scene_key_of_its_table() {
        let exists =
            |table: &str, key: &str| SCENE_KEYS.iter().any(|k| k.table == table && k.key == key);
        for source in SOURCES {
            let (table, keys) = placement(source);
            for key in keys {
                assert!(
                    exists(table, key),
                    "{source:?}: {table} {key} is no scene key"
                );
            }
        }
        assert!(exists(TOLERANCE.0, TOLERANCE.1));
    }

    /// A `[granular]` stone is placed by its sample, not by a `[[body]]`'s keys.
    #[test]
    fn a_granular_stone_is_not_told_a_bodys_keys() {
        let (table, keys) = placement(Source::Granular);
        assert_eq!(table, "[granular]");
        assert!(!keys.contains(&"translate") && !keys.contains(&"contact_radius"));
    }
}
