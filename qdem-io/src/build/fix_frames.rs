//! The local frames of `[[fix]]`es with `frame` ([`qdem_core::step::frames`]): each selected
//! node's basis, and the rule for a node that several fixes hold.
//!
//! - `frame = [[e1], [e2], [e3]]`: the same orthonormal basis (e₁, e₂, e₃ as columns) at every
//!   node.
//! - `frame = "cylindrical"`: at a node x, with the axis through o along the unit a,
//!   e_z = a, e_r = d⊥/|d⊥| with d⊥ = (x − o) − ((x − o)·a) a, e_θ = e_z × e_r: the basis
//!   (e_r, e_θ, e_z), right-handed. A node on the axis (|d⊥| ≤ 10⁻⁹ |x − o|) has no radial
//!   direction and is refused.
//! - A node held by several fixes is held in every direction any of them holds (the span,
//!   [`qdem_core::step::State::fix_in_frame`]). Their held directions there must be pairwise
//!   parallel or at right angles (|e·e′| within 10⁻⁹ of 1 or of 0): the force along a
//!   direction held by n fixes is then shared equally, as on the axes (`reactions.csv`), and
//!   the fixes' reactions sum to the supports' total. Oblique directions leave the split
//!   undefined, so they are refused.

use super::BuildError;
use crate::scene::{Fix, FixFrame};
use qdem_core::step::Dofs;
use qdem_core::{Mat3, Vec3};
use std::path::Path;

/// How far from parallel or perpendicular two held directions at one node may be.
const ALIGNED: f64 = 1e-9;

/// The basis of `fix` at the node at `x`: `None` on the axes; an error for a node on a
/// cylindrical frame's axis (`what` names the fix, `node` the particle).
pub(crate) fn basis_at(
    scene: &Path,
    fix: &Fix,
    what: &str,
    node: usize,
    x: Vec3,
) -> Result<Option<Mat3>, BuildError> {
    match fix.frame {
        FixFrame::Axes => Ok(None),
        FixFrame::Basis(rows) => Ok(Some(Mat3::from_fn(|r, k| rows[k][r]))),
        FixFrame::Cylindrical { origin, axis } => {
            let (o, a) = (Vec3::from(origin), Vec3::from(axis));
            let d = x - o;
            let across = d - d.dot(&a) * a;
            let r = across.norm();
            if r <= ALIGNED * d.norm() || r == 0.0 {
                return Err(BuildError::FixFrame {
                    scene: scene.to_path_buf(),
                    message: format!(
                        "{what}: particle {node} at ({:.6e}, {:.6e}, {:.6e}) lies on the axis of \
                         the fix's cylindrical frame (r = {r:.3e} m), where the radial and \
                         tangential directions are undefined; fix: leave the axis's nodes out of \
                         the selection, or hold them with a fix on x, y, z",
                        x.x, x.y, x.z
                    ),
                });
            }
            let e_r = across / r;
            Ok(Some(Mat3::from_columns(&[e_r, a.cross(&e_r), a])))
        }
    }
}

/// The unit vectors (world axes) of the directions `dofs` of `basis` (`None`: the axes).
pub(crate) fn held_vectors(basis: Option<&Mat3>, dofs: Dofs) -> impl Iterator<Item = Vec3> + '_ {
    (0..3)
        .filter(move |&k| dofs.contains(k))
        .map(move |k| match basis {
            Some(r) => r.column(k).into_owned(),
            None => Vec3::ith(k, 1.0),
        })
}

/// Whether two held unit vectors are parallel (either sign).
pub(crate) fn parallel(a: &Vec3, b: &Vec3) -> bool {
    a.dot(b).abs() >= 1.0 - ALIGNED
}

/// Refuses a node where two fixes hold oblique directions: `held[p]` lists, per particle, each
/// held direction with the fix's number.
pub(crate) fn check_aligned(scene: &Path, held: &[Vec<(usize, Vec3)>]) -> Result<(), BuildError> {
    for (p, directions) in held.iter().enumerate() {
        for (k, (fa, a)) in directions.iter().enumerate() {
            for (fb, b) in &directions[k + 1..] {
                let cosine = a.dot(b).abs();
                if fa != fb && cosine > ALIGNED && cosine < 1.0 - ALIGNED {
                    return Err(BuildError::FixFrame {
                        scene: scene.to_path_buf(),
                        message: format!(
                            "[[fix]] #{fa} and [[fix]] #{fb} both hold particle {p}, in \
                             directions at {:.4}° to each other (neither parallel nor at right \
                             angles), so the force cannot be split between them; fix: hold the \
                             node in one frame (one fix), or in directions of a common frame",
                            cosine.acos().to_degrees()
                        ),
                    });
                }
            }
        }
    }
    Ok(())
}
