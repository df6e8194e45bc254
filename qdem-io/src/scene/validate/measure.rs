//! `[[measure]]`: unique names, one region (a box, or a centre and a radius), a positive
//! interval, a wall to follow that the scene has, a `[granular]` sample whose stones it
//! measures and a `[contact]` whose forces make its stress.

use super::super::schema::RawScene;
use super::checker::{box_corners, label, unique_names, Checker};

/// Every `[[measure]]`.
pub(super) fn measure_tables(c: &mut Checker<'_>, raw: &RawScene) {
    unique_names(c, "measure", raw.measures.iter().map(|m| m.name.as_str()));
    for (i, m) in raw.measures.iter().enumerate() {
        let idx = i.to_string();
        let l = label("measure", i, Some(&m.name));
        match (m.region, m.center, m.radius) {
            (Some(b), None, None) => box_corners(c, "measure", &l, "box", &b),
            (None, Some(center), Some(r)) => {
                c.finite(&["measure", &idx, "center"], &l, "center", &center);
                c.positive(&["measure", &idx, "radius"], &l, "radius", r, "m");
            }
            _ => c.error(
                &["measure", &idx],
                format!(
                    "{l}: give one region: `box = [[x0, y0, z0], [x1, y1, z1]]`, or `center = \
                     [x, y, z]` with `radius`"
                ),
            ),
        }
        if let Some(every) = m.every {
            c.positive(&["measure", &idx, "every"], &l, "every", every, "s");
        }
        if let Some(k) = m.follow_wall {
            let walls = raw.walls.len();
            if k == 0 || k > walls {
                c.error(
                    &["measure", &idx, "follow_wall"],
                    format!(
                        "{l}: follow_wall = {k}, but the scene has {walls} [[wall]]s; fix: give \
                         the wall's number from 1 in scene order (walls.csv's wallK), or drop \
                         follow_wall"
                    ),
                );
            }
        }
        if raw.granular.is_none() {
            c.error(
                &["measure", &idx],
                format!(
                    "{l} measures the stones of a [granular] sample, but the scene has none; \
                     add one or remove the measure"
                ),
            );
        }
        if raw.contact.is_none() {
            c.error(
                &["measure", &idx],
                format!(
                    "{l} measures contact forces, but the scene has no [contact]; add one or \
                     remove the measure"
                ),
            );
        }
    }
}
