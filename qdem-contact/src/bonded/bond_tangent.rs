//! The bonds' share of the tangent (paper 001 Eq. 4), K = Σ T K_b Tᵀ and C = Σ T C_b Tᵀ over
//! the beam bonds (Eqs. 7–8), kept as ready entries between assemblies.
//!
//! A bond's matrices are those of its initial axis (the bonds are linear), so the entries
//! change only when a bond breaks: its 21 lower-triangle stiffness and 21 damping entries
//! then stay in place with zero values, so the pattern (and with it the symbolic analysis of
//! the implicit solve) holds, and adding the bonds to a tangent is one copy instead of a
//! 6×6 transformation per bond at every refactorisation. The price is memory: 42 entries of
//! 24 bytes, about 1 kB, per bond (200 MB for the 0.005 m benchmark beam's 204,714 bonds).
//!
//! The entries go to the tangent as kept entries ([`KeptEntries`]) with the bonds broken
//! since they were made, so that the implicit solver updates only those entries of its
//! matrix (issue 44).

use crate::bonded::beam_bond::{to_global_matrix, BeamBond};
use qdem_core::step::tangent::{Entry, KeptEntries};
use qdem_core::step::Tangent;
use std::ops::Range;

/// Entries of one bond's 6×6 block on or below the diagonal (its six DOFs are distinct).
const PER_BOND: usize = 21;

/// The tangent entries of every bond, in bond order, for a state of `nodes` particles.
#[derive(Clone, Debug, Default)]
pub(crate) struct BondTangent {
    nodes: usize,
    stiffness: Vec<Entry>,
    damping: Vec<Entry>,
    /// Names these entries for the assemblies ([`KeptEntries::source`]).
    source: u64,
    /// The entries of the bonds removed since, in order.
    removed: Vec<Range<usize>>,
}

impl BondTangent {
    /// The entries of `bonds` in a state of `nodes` particles, zero for bonds not `intact`.
    pub(crate) fn new(bonds: &[BeamBond], intact: &[bool], nodes: usize) -> BondTangent {
        let mut tangent = BondTangent {
            nodes,
            stiffness: Vec::with_capacity(PER_BOND * bonds.len()),
            damping: Vec::with_capacity(PER_BOND * bonds.len()),
            source: KeptEntries::new_source(),
            removed: Vec::new(),
        };
        for (b, &ok) in bonds.iter().zip(intact) {
            let k = to_global_matrix(&b.local_stiffness(), b.axis);
            let c = to_global_matrix(&b.local_damping(), b.axis);
            for (list, a) in [(&mut tangent.stiffness, &k), (&mut tangent.damping, &c)] {
                let entries = lower_entries((b.i, b.j), nodes, a);
                list.extend(entries.map(|e| if ok { e } else { Entry::new(e.row, e.col, 0.0) }));
            }
        }
        tangent
    }

    /// Number of particles the DOF numbers are for.
    pub(crate) fn nodes(&self) -> usize {
        self.nodes
    }

    /// Sets bond `k`'s entries to zero (it broke), keeping them in the pattern.
    pub(crate) fn remove(&mut self, k: usize) {
        let range = PER_BOND * k..PER_BOND * (k + 1);
        for e in self.stiffness[range.clone()]
            .iter_mut()
            .chain(&mut self.damping[range.clone()])
        {
            e.val = 0.0;
        }
        self.removed.push(range);
    }

    /// Adds every bond's entries to `tangent`, as kept entries.
    pub(crate) fn add_to(&self, tangent: &mut Tangent) {
        let kept = KeptEntries {
            source: self.source,
            stiffness: self.stiffness.len(),
            damping: self.damping.len(),
            changes: self.removed.clone(),
        };
        tangent.extend_kept(&self.stiffness, &self.damping, kept);
    }
}

/// Global DOF numbers of particle p's x, y and θ in a state of `nodes` particles (its
/// rotation is generalised node N + p).
#[inline]
fn particle_dofs(p: u32, nodes: usize) -> [usize; 3] {
    let p = p as usize;
    [3 * p, 3 * p + 1, 3 * (nodes + p) + 2]
}

/// Global DOF numbers of the ends of pair (i, j), x, y and θ each.
fn pair_dofs((i, j): (u32, u32), nodes: usize) -> [usize; 6] {
    let [a, b] = [particle_dofs(i, nodes), particle_dofs(j, nodes)];
    [a[0], a[1], a[2], b[0], b[1], b[2]]
}

/// The entries of the 6×6 block `a` of pair (i, j) that lie on or below the diagonal (global
/// DOFs of [`pair_dofs`]), in row order: the form a tangent keeps.
pub(crate) fn lower_entries(
    pair: (u32, u32),
    nodes: usize,
    a: &[[f64; 6]; 6],
) -> impl Iterator<Item = Entry> + '_ {
    let dofs = pair_dofs(pair, nodes);
    (0..6)
        .flat_map(move |r| (0..6).map(move |c| (r, c)))
        .filter(move |&(r, c)| dofs[r] >= dofs[c])
        .map(move |(r, c)| Entry::new(dofs[r], dofs[c], a[r][c]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bonded::particle_packing::lattice_section;

    /// Three particles, two bonds at different angles sharing particle 1.
    fn bonds() -> Vec<BeamBond> {
        let section = lattice_section(0.25).unwrap().section(0.1, 1.0);
        let x = [[0.0, 0.0], [0.1, 0.0], [0.15, 0.0866]];
        let bond = |i: u32, j: u32, strength| {
            let (a, b) = (x[i as usize], x[j as usize]);
            BeamBond::new(
                (i, a),
                (j, b),
                30e9,
                section,
                [5.0, 5.0],
                [0.01; 2],
                0.05,
                strength,
            )
        };
        vec![bond(0, 1, 1e6), bond(1, 2, 2e6)]
    }

    /// K u with the stored lower triangle expanded symmetrically.
    fn times(entries: &[Entry], u: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; u.len()];
        for e in entries {
            y[e.row] += e.val * u[e.col];
            if e.row != e.col {
                y[e.col] += e.val * u[e.row];
            }
        }
        y
    }

    #[test]
    fn the_entries_times_a_displacement_give_the_bond_end_forces() {
        let (bonds, nodes) = (bonds(), 3);
        let tangent = BondTangent::new(&bonds, &[true, true], nodes);
        let u: Vec<f64> = (0..6 * nodes)
            .map(|k| 1e-4 * (1.0 + k as f64).sin())
            .collect();
        let y = times(&tangent.stiffness, &u);
        let mut expected = vec![0.0; u.len()];
        for b in &bonds {
            let dofs = pair_dofs((b.i, b.j), nodes);
            let end = |e: usize| [u[dofs[3 * e]], u[dofs[3 * e + 1]], u[dofs[3 * e + 2]]];
            let forces = b.to_global(&b.local_forces(&b.to_local(&end(0), &end(1))));
            for (k, value) in forces.iter().flatten().enumerate() {
                expected[dofs[k]] += value;
            }
        }
        for (a, e) in y.iter().zip(&expected) {
            assert!((a - e).abs() <= 1e-9 * e.abs().max(1.0), "{a} vs {e}");
        }
    }

    #[test]
    fn a_removed_bond_keeps_its_entries_at_zero() {
        let bonds = bonds();
        let mut tangent = BondTangent::new(&bonds, &[true, true], 3);
        tangent.remove(0);
        let built = BondTangent::new(&bonds, &[false, true], 3);
        let triples = |list: &[Entry]| -> Vec<(usize, usize, f64)> {
            list.iter().map(|e| (e.row, e.col, e.val)).collect()
        };
        assert_eq!(triples(&tangent.stiffness), triples(&built.stiffness));
        assert_eq!(triples(&tangent.damping), triples(&built.damping));
        assert_eq!(tangent.stiffness.len(), 2 * PER_BOND);
        assert!(tangent.stiffness[..PER_BOND].iter().all(|e| e.val == 0.0));
        assert!(tangent.stiffness[PER_BOND..].iter().any(|e| e.val != 0.0));
    }
}
