//! Motions nothing resists, for a modal analysis ([`crate::modal::lanczos`]): a stone of a settled
//! bed that rests on fewer than three contacts (or touches nothing) turns or slides freely
//! about them, an exact zero mode of the linearised K (the contacts' springs carry no
//! geometric stiffness). Dozens of such modes would fill the bottom of the spectrum with
//! meaningless zeros and stall the Lanczos iteration on their cluster, so they are found
//! directly and deflated, like a free body's rigid-body modes.
//!
//! Each connected piece of the deformable bodies' tetrahedra (a stone, the sleeper) moves
//! rigidly in a mechanism, since its own tetrahedra resist every deformation, and so does each
//! rigid body (whose six DOFs are its rigid motions, [`crate::modal::rigid_reduction`]): the
//! mechanisms lie in the span of the pieces' rigid motions. With R the six rigid motions of
//! every piece (translations, small rotations about its centre) over the free DOFs,
//! G = Rᵀ K R (dense, 6 per piece, coupled through the contacts) and H = Rᵀ M R (block
//! diagonal), the motions R v with G v = λ H v and λ below [`ZERO`] times the largest λ are the
//! mechanisms, those that move several stones together included. Pieces with a fixed DOF are left to the fixity. The
//! dense solve bounds the pieces at [`MAX_PIECES`]; beyond, each piece is tested alone (its
//! own 6 × 6 block), which misses the mechanisms of several pieces.

use crate::solvers::sparse::rigid_motion;
use crate::step::tangent::Entry;
use crate::Vec3;
use nalgebra::{DMatrix, DVector, Matrix6, SymmetricEigen, Vector6};
use std::ops::Range;

/// λ / λ_max below which a rigid motion counts as unresisted (rounding of a zero).
pub const ZERO: f64 = 1e-9;

/// Pieces up to which the mechanisms of several pieces together are sought (a dense
/// eigenproblem of 6 per piece).
pub const MAX_PIECES: usize = 600;

/// The free DOFs and their masses, as the modal problem holds them.
pub(crate) struct SystemDofs<'a> {
    /// The system index of each global DOF (3 · particle + axis), `None` where fixed.
    pub index: &'a dyn Fn(usize) -> Option<usize>,
    /// The lumped mass of each system DOF.
    pub mass: &'a [f64],
    /// The global DOF of each system DOF.
    pub global: &'a [usize],
}

/// Each system DOF's piece and its row of the piece's six rigid motions (translations, small
/// rotations about the piece's centre), for the connected pieces of tetrahedra (`piece[p]`:
/// the piece of particle p, `None` outside every deformable body); `None` for a DOF of no
/// piece or of a piece with a fixed DOF.
pub(crate) fn tet_piece_rows(
    position: &[Vec3],
    piece: &[Option<u32>],
    pieces: usize,
    dofs: &SystemDofs<'_>,
) -> Vec<PieceRow> {
    let centre = piece_centres(position, piece, pieces);
    let held = held_pieces(piece, pieces, dofs);
    dofs.global
        .iter()
        .map(|&d| {
            let p = d / 3;
            let c = piece.get(p).copied().flatten()? as usize;
            (!held[c]).then(|| {
                (
                    c,
                    rigid_motion(position[p] - centre[c]).row(d % 3).transpose(),
                )
            })
        })
        .collect()
}

/// A system DOF's piece and its row of the piece's six rigid motions.
pub(crate) type PieceRow = Option<(usize, Vector6<f64>)>;

/// The unresisted rigid motions of `pieces` pieces whose rigid motions over the system DOFs
/// are `rows` (one per system DOF, [`tet_piece_rows`] and the rigid bodies' own), each as a
/// vector over the system DOFs (not normalised).
pub(crate) fn unresisted_motions(
    rows: &[PieceRow],
    pieces: usize,
    dofs: &SystemDofs<'_>,
    stiffness: &[Entry],
) -> Vec<Vec<f64>> {
    let motion = |d: usize| -> PieceRow { rows[(dofs.index)(d)?] };
    let mut h = vec![Matrix6::zeros(); pieces];
    for &d in dofs.global {
        if let Some((c, r)) = motion(d) {
            h[c] += r * r.transpose() * dofs.mass[(dofs.index)(d).expect("a system DOF")];
        }
    }
    // The pieces free to move in all six ways, numbered in order.
    let mut slot = vec![None; pieces];
    let mut active = Vec::new();
    for (c, block) in h.iter().enumerate() {
        if let Some(inverse) = block.cholesky().and_then(|ch| ch.l().try_inverse()) {
            slot[c] = Some(active.len());
            active.push(inverse);
        }
    }
    let motion = |d: usize| motion(d).and_then(|(c, r)| slot[c].map(|s| (s, r)));
    // Up to MAX_PIECES the pieces are one group, solved together; beyond, each is its own.
    let groups: Vec<Range<usize>> = match active.len() <= MAX_PIECES {
        true => std::iter::once(0..active.len()).collect(),
        false => (0..active.len()).map(|c| c..c + 1).collect(),
    };
    let group_of = |c: usize| if groups.len() == 1 { 0 } else { c };
    let mut g: Vec<DMatrix<f64>> = groups
        .iter()
        .map(|r| DMatrix::zeros(6 * r.len(), 6 * r.len()))
        .collect();
    for e in stiffness {
        let (Some((ci, ri)), Some((cj, rj))) = (motion(e.row), motion(e.col)) else {
            continue;
        };
        let k = group_of(ci);
        if k != group_of(cj) {
            continue;
        }
        let (a, b) = (ci - groups[k].start, cj - groups[k].start);
        let block = ri * rj.transpose() * e.val;
        add_block(&mut g[k], a, b, &block);
        if e.row != e.col {
            add_block(&mut g[k], b, a, &block.transpose());
        }
    }
    let mut found = Vec::new();
    for (k, range) in groups.iter().enumerate() {
        for v in null_motions(&g[k], &active[range.clone()]) {
            let x = dofs.global.iter().map(|&d| match motion(d) {
                Some((c, r)) if range.contains(&c) => {
                    r.dot(&v.fixed_rows::<6>(6 * (c - range.start)))
                }
                _ => 0.0,
            });
            found.push(x.collect());
        }
    }
    found
}

/// Adds `block` at piece rows `a`, piece columns `b` of `g`.
fn add_block(g: &mut DMatrix<f64>, a: usize, b: usize, block: &Matrix6<f64>) {
    let mut view = g.view_mut((6 * a, 6 * b), (6, 6));
    view += block;
}

/// The vectors v of G v = λ H v with λ below [`ZERO`] times the largest, H block diagonal
/// and given by the inverses of its blocks' Cholesky factors `l_inv` (a 6 × 6 block per piece).
fn null_motions(g: &DMatrix<f64>, l_inv: &[Matrix6<f64>]) -> Vec<DVector<f64>> {
    let n = g.nrows();
    if n == 0 {
        return Vec::new();
    }
    let mut l = DMatrix::zeros(n, n);
    for (c, block) in l_inv.iter().enumerate() {
        l.view_mut((6 * c, 6 * c), (6, 6)).copy_from(block);
    }
    let a = &l * g * l.transpose();
    let eigen = SymmetricEigen::new((&a + a.transpose()) * 0.5);
    let largest = eigen.eigenvalues.max();
    (0..n)
        .filter(|&k| eigen.eigenvalues[k] <= ZERO * largest)
        .map(|k| l.transpose() * eigen.eigenvectors.column(k))
        .collect()
}

/// The mean position of each piece's particles.
fn piece_centres(position: &[Vec3], piece: &[Option<u32>], pieces: usize) -> Vec<Vec3> {
    let mut sum = vec![(Vec3::zeros(), 0usize); pieces];
    for (p, c) in piece.iter().enumerate() {
        if let Some(c) = c {
            sum[*c as usize].0 += position[p];
            sum[*c as usize].1 += 1;
        }
    }
    sum.iter().map(|(s, n)| s / (*n).max(1) as f64).collect()
}

/// Whether each piece has a fixed DOF.
fn held_pieces(piece: &[Option<u32>], pieces: usize, dofs: &SystemDofs<'_>) -> Vec<bool> {
    let mut held = vec![false; pieces];
    for (p, c) in piece.iter().enumerate() {
        if let Some(c) = c {
            held[*c as usize] |= (0..3).any(|a| (dofs.index)(3 * p + a).is_none());
        }
    }
    held
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::step::tangent::Entry as Triplet;

    /// The four corners of a tetrahedron, one piece, each held to the ground along z by a
    /// spring: the z translation and the rotations about x and y stretch them, the x and y
    /// translations and the rotation about z do not.
    #[test]
    fn a_piece_on_vertical_springs_keeps_its_three_horizontal_rigid_motions() {
        let position = vec![Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
        let piece = vec![Some(0); 4];
        let stiffness: Vec<Triplet> = (0..4)
            .map(|p| Triplet::new(3 * p + 2, 3 * p + 2, 10.0))
            .collect();
        let global: Vec<usize> = (0..12).collect();
        let mass = vec![1.0; 12];
        let index = |d: usize| (d < 12).then_some(d);
        let dofs = SystemDofs {
            index: &index,
            mass: &mass,
            global: &global,
        };
        let rows = tet_piece_rows(&position, &piece, 1, &dofs);
        let free = unresisted_motions(&rows, 1, &dofs, &stiffness);
        assert_eq!(free.len(), 3);
        for x in &free {
            let vertical: f64 = (0..4).map(|p| x[3 * p + 2].abs()).sum();
            let size: f64 = x.iter().map(|v| v.abs()).sum();
            assert!(vertical < 1e-9 * size, "no vertical motion: {x:?}");
        }
    }
}
