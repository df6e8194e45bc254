//! Sparse assembly and Cholesky factorisation for the implicit Newmark step (paper 001 Eq. 26)
//! and the linear static solve.
//!
//! - The models' tangent stiffness K and damping C arrive as a [`Tangent`] (lower-triangle
//!   3×3 blocks per particle pair, [`crate::step::tangent`]).
//! - [`FreeDofs`] eliminates the constraints of Eqs. 23 and 27 (B∆u = 0, Bü = 0 with B selecting
//!   the fixed directions): fixed DOFs are removed from the system, the others numbered
//!   compactly in ascending order (so the lower triangle stays lower).
//! - [`Assembler`] forms s_M M + s_C C + s_K K over the free DOFs (M the lumped mass), e.g.
//!   M + γ∆t C + β∆t² K of Eq. 26 or K alone for a static solve.
//! - [`SparseCholesky`] factorises such a matrix with faer's sparse LLᵀ. The symbolic analysis
//!   (fill-reducing AMD ordering, elimination tree, supernodes) is kept and reused as long as the
//!   sparsity pattern is unchanged; the numeric factorisation runs only when asked, and a solve
//!   is a pair of triangular solves.
//! - [`unconstrained_bodies`] finds the deformable bodies that the constraints leave free to
//!   move rigidly (a singular stiffness), and [`explain_failure`] turns a failed factorisation
//!   into a message naming the particle of the failing pivot, its body and the free bodies.

use crate::checkpoint::{CheckpointError, Decoder, Encoder};
use crate::error::CoreError;
use crate::step::frames::ParticleFrames;
use crate::step::model::Model;
use crate::step::solve_report::FactorStats;
use crate::step::state::{Dofs, State};
use crate::step::stepper::PARTICLE_CHUNK;
use crate::{Mat3, Vec3};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltError;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat, Triplet};
use faer::{Conj, MatMut, Side};
use nalgebra::{Matrix6, SMatrix, SymmetricEigen, Vector6};
use rayon::prelude::*;
use std::collections::HashMap;
use std::time::Instant;

pub(crate) use crate::step::tangent::Tangent;
use crate::step::tangent::{Entry, KeptEntries};

/// The damping C of a [`Tangent`] as whole rows (each stored lower-triangle entry on both
/// sides, duplicates kept, in the tangent's order), so that C x runs row by row in parallel and
/// still sums every row in the same order on any number of threads. The rows of a model's kept
/// entries ([`KeptEntries`]) are kept apart and updated in place where they changed; a row
/// sums its kept entries, then the others, as one pass over the whole row would.
#[derive(Clone, Debug, Default)]
pub(crate) struct DampingRows {
    kept: Rows,
    /// Where each kept entry lies in `kept` (its row's copy, then its column's, or [`FIXED`]
    /// on the diagonal).
    kept_at: Vec<[usize; 2]>,
    /// The kept list the rows are of: its source, revision and the order of the system.
    kept_of: Option<(u64, usize, usize)>,
    rest: Rows,
}

/// Whole rows of a list of lower-triangle entries.
#[derive(Clone, Debug, Default)]
struct Rows {
    start: Vec<usize>,
    col: Vec<usize>,
    val: Vec<f64>,
}

impl Rows {
    /// Rebuilds the rows of `entries` over `dofs` degrees of freedom, noting where each entry
    /// went in `at` when given.
    fn build(&mut self, entries: &[Entry], dofs: usize, mut at: Option<&mut Vec<[usize; 2]>>) {
        self.start.clear();
        self.start.resize(dofs + 1, 0);
        for e in entries {
            self.start[e.row + 1] += 1;
            if e.row != e.col {
                self.start[e.col + 1] += 1;
            }
        }
        for i in 0..dofs {
            self.start[i + 1] += self.start[i];
        }
        let mut next = self.start[..dofs].to_vec();
        self.col.resize(self.start[dofs], 0);
        self.val.resize(self.start[dofs], 0.0);
        if let Some(at) = at.as_deref_mut() {
            at.clear();
        }
        let mut put = |row: usize, col: usize, val: f64| {
            self.col[next[row]] = col;
            self.val[next[row]] = val;
            next[row] += 1;
            next[row] - 1
        };
        for e in entries {
            let first = put(e.row, e.col, e.val);
            let second = if e.row != e.col {
                put(e.col, e.row, e.val)
            } else {
                FIXED
            };
            if let Some(at) = at.as_deref_mut() {
                at.push([first, second]);
            }
        }
    }

    /// The stored columns and values of row `dof` (none if the rows are empty).
    fn row(&self, dof: usize) -> (&[usize], &[f64]) {
        if self.start.is_empty() {
            return (&[], &[]);
        }
        let range = self.start[dof]..self.start[dof + 1];
        (&self.col[range.clone()], &self.val[range])
    }
}

impl DampingRows {
    /// Rebuilds the rows of `tangent`'s damping over `dofs` degrees of freedom; the rows of
    /// kept entries seen before only where they changed since.
    pub(crate) fn build(&mut self, tangent: &Tangent, dofs: usize) {
        let kept = tangent.kept.as_ref();
        let split = kept.map_or(0, |k| k.damping);
        match (kept, self.kept_of) {
            (Some(k), Some((source, revision, n)))
                if source == k.source
                    && n == dofs
                    && revision <= k.changes.len()
                    && self.kept_at.len() == k.damping =>
            {
                for change in &k.changes[revision..] {
                    for i in change.clone().filter(|&i| i < split) {
                        let value = tangent.damping[i].val;
                        for slot in self.kept_at[i].into_iter().filter(|&p| p != FIXED) {
                            self.kept.val[slot] = value;
                        }
                    }
                }
                self.kept_of = Some((source, k.changes.len(), dofs));
            }
            (Some(k), _) => {
                let entries = &tangent.damping[..split];
                self.kept.build(entries, dofs, Some(&mut self.kept_at));
                self.kept_of = Some((k.source, k.changes.len(), dofs));
            }
            (None, _) => {
                self.kept = Rows::default();
                self.kept_at.clear();
                self.kept_of = None;
            }
        }
        self.rest.build(&tangent.damping[split..], dofs, None);
    }

    /// Subtracts C x from `y`; x and y run over the generalised nodes (particles, then their
    /// rotations) as [`FreeDofs::gather_nodes`] reads them.
    pub(crate) fn subtract_times(&self, x: (&[Vec3], &[Vec3]), y: (&mut [Vec3], &mut [Vec3])) {
        if self.kept.val.is_empty() && self.rest.val.is_empty() {
            return;
        }
        let n = x.0.len();
        let value = |dof: usize| {
            let node = dof / 3;
            let v = if node < n { &x.0[node] } else { &x.1[node - n] };
            v[dof % 3]
        };
        let row = |dof: usize| -> f64 {
            let (cols, vals) = self.kept.row(dof);
            let kept: f64 = cols.iter().zip(vals).map(|(&c, &v)| v * value(c)).sum();
            let (cols, vals) = self.rest.row(dof);
            cols.iter()
                .zip(vals)
                .map(|(&c, &v)| v * value(c))
                .fold(kept, |sum, term| sum + term)
        };
        let update = |offset: usize| {
            move |(node, out): (usize, &mut Vec3)| {
                for c in 0..3 {
                    out[c] -= row(3 * (offset + node) + c);
                }
            }
        };
        y.0.par_iter_mut()
            .enumerate()
            .with_min_len(PARTICLE_CHUNK)
            .for_each(update(0));
        y.1.par_iter_mut()
            .enumerate()
            .with_min_len(PARTICLE_CHUNK)
            .for_each(update(n));
    }
}

/// Marker in [`FreeDofs`] for a fixed DOF.
const FIXED: usize = usize::MAX;

/// What to do about a deformable body that is free to move rigidly.
pub const FIX_HINT: &str = "fix at least 3 non-collinear particles of it, or a face, with [[fix]]";

/// The diagnosis of a matrix that is not positive definite when no cause is known.
const GENERIC_CAUSE: &str = "a body is probably not constrained against rigid motion (fix some \
                             of its nodes) or a free particle belongs to no tetrahedron";

/// The numbering of the free DOFs: fixed DOFs (Eqs. 23, 27) are eliminated. A particle held
/// in a local frame has its DOFs numbered in that frame ([`crate::step::frames`]): vectors
/// are rotated into it when gathered and out of it when scattered, and the tangent is
/// transformed to it before assembly ([`FreeDofs::local_tangent`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FreeDofs {
    index: Vec<usize>,
    count: usize,
    frames: ParticleFrames,
}

impl FreeDofs {
    /// The numbering of `state`'s free DOFs (its [`State::node_fixity`]), in the local frames
    /// of its framed particles.
    pub fn of(state: &State) -> FreeDofs {
        FreeDofs::new(&state.node_fixity()).in_frames(state.frames.clone())
    }

    /// The same numbering with the particles of `frames` in their local frames (their entries
    /// of the fixity given to [`FreeDofs::new`] are their held local directions).
    pub fn in_frames(mut self, frames: ParticleFrames) -> FreeDofs {
        self.frames = frames;
        self
    }

    /// The local basis of particle `node`, if it is framed.
    pub fn frame(&self, node: usize) -> Option<&Mat3> {
        self.frames.get(node).map(|(r, _)| r)
    }

    /// `tangent` in the numbering's frames (itself when no particle is framed).
    pub fn local_tangent<'a>(&self, tangent: &'a Tangent) -> std::borrow::Cow<'a, Tangent> {
        match self.frames.is_empty() {
            true => std::borrow::Cow::Borrowed(tangent),
            false => std::borrow::Cow::Owned(self.frames.tangent_in_frames(tangent)),
        }
    }

    /// Numbers the free directions of every particle in ascending DOF order.
    pub fn new(fixed: &[Dofs]) -> FreeDofs {
        let mut count = 0;
        let index = fixed
            .iter()
            .flat_map(|d| (0..3).map(move |axis| d.contains(axis)))
            .map(|is_fixed| {
                if is_fixed {
                    FIXED
                } else {
                    count += 1;
                    count - 1
                }
            })
            .collect();
        FreeDofs {
            index,
            count,
            frames: ParticleFrames::default(),
        }
    }

    /// `rows` (3 × k, one row per world axis of particle `node`) in the particle's local
    /// frame when it is framed (Rᵀ rows), else unchanged.
    pub fn local_rows<const K: usize>(
        &self,
        node: usize,
        rows: SMatrix<f64, 3, K>,
    ) -> SMatrix<f64, 3, K> {
        match self.frame(node) {
            Some(r) => r.transpose() * rows,
            None => rows,
        }
    }

    /// Number of free DOFs (the size of the system).
    pub fn len(&self) -> usize {
        self.count
    }

    /// The system index of global DOF `dof`, `None` if it is fixed.
    #[inline]
    pub fn index(&self, dof: usize) -> Option<usize> {
        let i = self.index[dof];
        (i != FIXED).then_some(i)
    }

    /// The global DOF (3·particle + axis) of system index `i`, `None` if out of range.
    pub fn dof(&self, i: usize) -> Option<usize> {
        if i >= self.count {
            return None;
        }
        // System indices ascend with the DOF: the i-th free DOF.
        self.index.iter().position(|&k| k == i)
    }

    /// Copies the free components of the generalised nodes' vectors into `out` (length
    /// [`Self::len`]): the particles' vectors `parts.0`, then their rotations' `parts.1`
    /// (empty when nothing rotates).
    pub fn gather_nodes(&self, parts: (&[Vec3], &[Vec3]), out: &mut [f64]) {
        let n = parts.0.len();
        for (dof, &i) in self.index.iter().enumerate() {
            if i != FIXED {
                let node = dof / 3;
                let v = if node < n {
                    &parts.0[node]
                } else {
                    &parts.1[node - n]
                };
                out[i] = v[dof % 3];
            }
        }
        for (node, frame, _) in self.frames.iter() {
            let local = frame.transpose() * parts.0[node];
            for axis in 0..3 {
                if let Some(i) = self.index(3 * node + axis) {
                    out[i] = local[axis];
                }
            }
        }
    }

    /// [`FreeDofs::scatter`] over generalised nodes, as [`FreeDofs::gather_nodes`] reads them.
    pub fn scatter_nodes(&self, x: &[f64], parts: (&mut [Vec3], &mut [Vec3])) {
        let n = parts.0.len();
        for (dof, &i) in self.index.iter().enumerate() {
            let node = dof / 3;
            let v = if node < n {
                &mut parts.0[node]
            } else {
                &mut parts.1[node - n]
            };
            v[dof % 3] = if i == FIXED { 0.0 } else { x[i] };
        }
        for (node, frame, _) in self.frames.iter() {
            parts.0[node] = frame * parts.0[node];
        }
    }
}

/// Coefficients of the combination s_M M + s_C C + s_K K that [`Assembler`] forms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scales {
    /// Factor of the lumped mass M.
    pub mass: f64,
    /// Factor of the damping C.
    pub damping: f64,
    /// Factor of the stiffness K.
    pub stiffness: f64,
}

/// Assembles s_M M + s_C C + s_K K over the free DOFs, lower triangle, duplicates summed
/// (the left-hand side of paper 001 Eq. 26 with s = (1, γ∆t, β∆t²)). A term with a zero factor
/// is left out of the pattern.
///
/// The compressed-column pattern is kept between calls, and so is the slot of every entry
/// of the tangent in it: while the models add the same entries (the bonded beam keeps its
/// broken bonds' zero entries so that its pattern holds), assembling is one pass that adds
/// each value into its slot; an entry the pattern lacks rebuilds it from triplets. Every
/// slot sums its entries in the tangent's order (stiffness, damping, mass) either way, so
/// the values do not depend on which path ran.
///
/// A model's kept entries ([`KeptEntries`], the bonds of the bonded beam) are summed per slot
/// once, apart from the scales, and only the slots of entries that changed are summed again
/// (issue 44): a slot's value is then s_K ΣK_kept + s_C ΣC_kept, each sum in the tangent's
/// order, plus the other entries in the tangent's order, whichever entries changed when.
#[derive(Clone, Debug, Default)]
pub struct Assembler {
    matrix: Option<SparseColMat<usize, f64>>,
    /// The slot of each stiffness, damping and mass entry at the last assembly ([`FIXED`]
    /// for an entry of a fixed DOF).
    slots: [Vec<usize>; 3],
    /// The sums of the kept entries per slot of `matrix`.
    kept: Option<KeptSums>,
    /// Seconds the last assembly took.
    seconds: f64,
}

/// The kept stiffness and damping entries of a tangent summed per slot of a pattern.
#[derive(Clone, Debug)]
struct KeptSums {
    source: u64,
    revision: usize,
    dofs: FreeDofs,
    /// Kept entries per list (stiffness, damping).
    counts: [usize; 2],
    /// Per list, each kept entry's slot ([`FIXED`] for an entry of a fixed DOF).
    slot_of: [Vec<usize>; 2],
    /// Per list, the kept entries of each slot in the tangent's order (compressed by slot).
    start: [Vec<usize>; 2],
    entries: [Vec<usize>; 2],
    /// Per list, the sum of each slot's kept entries.
    sums: [Vec<f64>; 2],
}

impl KeptSums {
    /// The sums of `tangent`'s kept entries `kept` in the slots of `matrix`'s pattern; `None`
    /// if an entry has no place in it.
    fn new(
        tangent: &Tangent,
        kept: &KeptEntries,
        dofs: &FreeDofs,
        matrix: &SparseColMat<usize, f64>,
    ) -> Option<KeptSums> {
        let pattern = matrix.symbolic();
        let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
        let slots = row_idx.len();
        let lists = [
            &tangent.stiffness[..kept.stiffness],
            &tangent.damping[..kept.damping],
        ];
        let mut sums = KeptSums {
            source: kept.source,
            revision: kept.changes.len(),
            dofs: dofs.clone(),
            counts: [kept.stiffness, kept.damping],
            slot_of: Default::default(),
            start: Default::default(),
            entries: Default::default(),
            sums: Default::default(),
        };
        for (list, entries) in lists.into_iter().enumerate() {
            let mut slot_of = Vec::with_capacity(entries.len());
            for e in entries {
                let slot = match (dofs.index(e.row), dofs.index(e.col)) {
                    (Some(row), Some(col)) => {
                        let column = col_ptr[col]..col_ptr[col + 1];
                        let offset = row_idx[column.clone()].binary_search(&row).ok()?;
                        column.start + offset
                    }
                    _ => FIXED,
                };
                slot_of.push(slot);
            }
            let mut start = vec![0usize; slots + 1];
            for &slot in slot_of.iter().filter(|&&s| s != FIXED) {
                start[slot + 1] += 1;
            }
            for s in 0..slots {
                start[s + 1] += start[s];
            }
            let mut next = start[..slots].to_vec();
            let mut members = vec![0usize; start[slots]];
            for (i, &slot) in slot_of.iter().enumerate().filter(|(_, &s)| s != FIXED) {
                members[next[slot]] = i;
                next[slot] += 1;
            }
            sums.slot_of[list] = slot_of;
            sums.start[list] = start;
            sums.entries[list] = members;
            sums.sums[list] = vec![0.0; slots];
            for slot in 0..slots {
                sums.sums[list][slot] = sums.sum(list, slot, entries);
            }
        }
        Some(sums)
    }

    /// The sum of the kept entries of `list` in `slot`, in the tangent's order.
    fn sum(&self, list: usize, slot: usize, entries: &[Entry]) -> f64 {
        let members = &self.entries[list][self.start[list][slot]..self.start[list][slot + 1]];
        members.iter().map(|&i| entries[i].val).sum()
    }

    /// Whether these sums are of `kept` over `dofs`, at its revision or an earlier one.
    fn fits(&self, kept: &KeptEntries, dofs: &FreeDofs) -> bool {
        self.source == kept.source
            && self.counts == [kept.stiffness, kept.damping]
            && self.revision <= kept.changes.len()
            && self.dofs == *dofs
    }

    /// Sums again the slots of the entries that `kept` changed since these sums were made.
    fn update(&mut self, tangent: &Tangent, kept: &KeptEntries) {
        let lists = [&tangent.stiffness[..], &tangent.damping[..]];
        for change in &kept.changes[self.revision..] {
            for (list, entries) in lists.into_iter().enumerate() {
                for i in change.clone().filter(|&i| i < self.counts[list]) {
                    let slot = self.slot_of[list][i];
                    if slot != FIXED {
                        self.sums[list][slot] = self.sum(list, slot, entries);
                    }
                }
            }
        }
        self.revision = kept.changes.len();
    }
}

impl Assembler {
    /// An assembler with no pattern yet.
    pub fn new() -> Assembler {
        Assembler::default()
    }

    /// The assembled matrix of `tangent` and the lumped `mass` (one per generalised node)
    /// over `dofs`, scaled by `scales`, and the seconds the assembly took.
    pub fn assemble(
        &mut self,
        tangent: &Tangent,
        mass: &[f64],
        dofs: &FreeDofs,
        scales: Scales,
    ) -> Result<(SparseColMatRef<'_, usize, f64>, f64), CoreError> {
        let start = Instant::now();
        let terms = Terms {
            tangent,
            mass,
            dofs,
            scales,
        };
        let kept = tangent
            .kept
            .as_ref()
            .filter(|_| scales.stiffness != 0.0 && scales.damping != 0.0);
        let fits = match &mut self.matrix {
            Some(matrix) if matrix.nrows() == dofs.len() => match kept {
                Some(kept) => terms.fill_kept(kept, matrix, &mut self.kept, &mut self.slots),
                None => terms.fill(matrix, &mut self.slots, [0, 0]),
            },
            _ => false,
        };
        if !fits {
            let mut matrix = terms.pattern()?;
            self.kept = None;
            let filled = match kept {
                Some(kept) => terms.fill_kept(kept, &mut matrix, &mut self.kept, &mut self.slots),
                None => terms.fill(&mut matrix, &mut self.slots, [0, 0]),
            };
            debug_assert!(filled, "a pattern built from the entries holds them");
            self.matrix = Some(matrix);
        }
        self.seconds = start.elapsed().as_secs_f64();
        Ok(self.matrix().expect("assembled above"))
    }

    /// The matrix of the last [`Self::assemble`] and the seconds it took; `None` before one.
    pub fn matrix(&self) -> Option<(SparseColMatRef<'_, usize, f64>, f64)> {
        Some((self.matrix.as_ref()?.as_ref(), self.seconds))
    }

    /// Writes the pattern (not the values): the pattern decides the fill-reducing ordering of
    /// every later factorisation, and it only grows during a run (entries that left the
    /// tangent keep their places), so a resumed run must start from the same one.
    pub(crate) fn save(&self, out: &mut Encoder) {
        out.bool(self.matrix.is_some());
        if let Some(matrix) = &self.matrix {
            save_matrix(matrix.as_ref(), out);
        }
    }

    /// Reads back what [`Self::save`] wrote.
    pub(crate) fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        *self = Assembler::default();
        if input.bool("an assembled pattern")? {
            self.matrix = Some(restore_matrix(input)?);
        }
        Ok(())
    }
}

/// Writes a compressed-column matrix: its order, pattern and values.
pub(crate) fn save_matrix(matrix: SparseColMatRef<'_, usize, f64>, out: &mut Encoder) {
    out.u64(matrix.nrows() as u64);
    let narrow = |xs: &[usize]| xs.iter().map(|&x| x as u32).collect::<Vec<u32>>();
    out.u32s(&narrow(matrix.symbolic().col_ptr()));
    out.u32s(&narrow(matrix.symbolic().row_idx()));
    out.f64s(matrix.val());
}

/// Reads back a matrix [`save_matrix`] wrote, checking its pattern.
pub(crate) fn restore_matrix(
    input: &mut Decoder<'_>,
) -> Result<SparseColMat<usize, f64>, CheckpointError> {
    let n = input.u64("a matrix order")? as usize;
    let widen = |xs: Vec<u32>| xs.into_iter().map(|x| x as usize).collect::<Vec<usize>>();
    let col_ptr = widen(input.u32s("a matrix pattern")?);
    let row_idx = widen(input.u32s("a matrix pattern")?);
    let values = input.f64s("matrix values")?;
    let invalid = |detail: &str| CheckpointError::Invalid {
        what: "matrix",
        detail: detail.to_string(),
    };
    let ordered = col_ptr.len() == n + 1
        && col_ptr.first() == Some(&0)
        && col_ptr.windows(2).all(|w| w[0] <= w[1])
        && col_ptr[n] == row_idx.len()
        && values.len() == row_idx.len();
    if !ordered {
        return Err(invalid("column pointers and entries do not match"));
    }
    let sorted = (0..n).all(|j| {
        let rows = &row_idx[col_ptr[j]..col_ptr[j + 1]];
        rows.windows(2).all(|w| w[0] < w[1]) && rows.iter().all(|&i| i < n)
    });
    if !sorted {
        return Err(invalid("row indices out of order or range"));
    }
    let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    Ok(SparseColMat::new(pattern, values))
}

/// An owned copy of `matrix`.
pub(crate) fn copy_matrix(matrix: SparseColMatRef<'_, usize, f64>) -> SparseColMat<usize, f64> {
    let (n, symbolic) = (matrix.nrows(), matrix.symbolic());
    let pattern = SymbolicSparseColMat::new_checked(
        n,
        matrix.ncols(),
        symbolic.col_ptr().to_vec(),
        None,
        symbolic.row_idx().to_vec(),
    );
    SparseColMat::new(pattern, matrix.val().to_vec())
}

/// The entries of one assembly: s_K K, s_C C and s_M M over the free DOFs.
struct Terms<'a> {
    tangent: &'a Tangent,
    mass: &'a [f64],
    dofs: &'a FreeDofs,
    scales: Scales,
}

impl Terms<'_> {
    /// Calls `add(list, k, row, column, value)` for the k-th entry of each list (stiffness,
    /// damping, mass) whose factor is not zero, with system indices, or [`FIXED`] as the row
    /// of an entry of a fixed DOF.
    /// The first `skip` entries of the stiffness and damping lists are left out.
    fn for_each(
        &self,
        skip: [usize; 2],
        mut add: impl FnMut(usize, usize, usize, usize, f64) -> bool,
    ) -> bool {
        let s = self.scales;
        let lists = [
            (&self.tangent.stiffness, s.stiffness),
            (&self.tangent.damping, s.damping),
        ];
        for (list, (entries, scale)) in lists.into_iter().enumerate() {
            if scale == 0.0 {
                continue;
            }
            for (k, e) in entries.iter().enumerate().skip(skip[list]) {
                let (row, col) = match (self.dofs.index(e.row), self.dofs.index(e.col)) {
                    (Some(row), Some(col)) => (row, col),
                    _ => (FIXED, FIXED),
                };
                if !add(list, k, row, col, scale * e.val) {
                    return false;
                }
            }
        }
        if s.mass != 0.0 {
            for dof in 0..3 * self.mass.len() {
                let i = self.dofs.index(dof).unwrap_or(FIXED);
                if !add(2, dof, i, i, s.mass * self.mass[dof / 3]) {
                    return false;
                }
            }
        }
        true
    }

    /// A matrix with the pattern of these entries (built from triplets).
    fn pattern(&self) -> Result<SparseColMat<usize, f64>, CoreError> {
        let mut entries = Vec::new();
        self.for_each([0, 0], |_, _, row, col, val| {
            if row != FIXED {
                entries.push(Triplet::new(row, col, val));
            }
            true
        });
        let n = self.dofs.len();
        SparseColMat::try_new_from_triplets(n, n, &entries).map_err(sparse_error)
    }

    /// Sums the entries into `matrix`'s values through their slots, found again (binary
    /// search in the column) where the last assembly's slot no longer fits; false if an entry
    /// has no place in the pattern. The first `skip` stiffness and damping entries are left
    /// out, and the values are not cleared first when some are.
    fn fill(
        &self,
        matrix: &mut SparseColMat<usize, f64>,
        slots: &mut [Vec<usize>; 3],
        skip: [usize; 2],
    ) -> bool {
        let (pattern, values) = matrix.parts_mut();
        let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
        if skip == [0, 0] {
            values.fill(0.0);
        }
        self.for_each(skip, |list, k, row, col, val| {
            let cached = &mut slots[list];
            if cached.len() <= k {
                cached.resize(k + 1, FIXED);
            }
            if row == FIXED {
                cached[k] = FIXED;
                return true;
            }
            let column = col_ptr[col]..col_ptr[col + 1];
            let slot = cached[k];
            let slot = if column.contains(&slot) && row_idx[slot] == row {
                slot
            } else {
                match row_idx[column.clone()].binary_search(&row) {
                    Ok(offset) => column.start + offset,
                    Err(_) => return false,
                }
            };
            cached[k] = slot;
            values[slot] += val;
            true
        })
    }

    /// [`Self::fill`] with the `kept` entries taken from their sums per slot (made, or
    /// updated where they changed, in `sums`): s_K ΣK + s_C ΣC, then the other entries.
    fn fill_kept(
        &self,
        kept: &KeptEntries,
        matrix: &mut SparseColMat<usize, f64>,
        sums: &mut Option<KeptSums>,
        slots: &mut [Vec<usize>; 3],
    ) -> bool {
        match sums {
            Some(sums) if sums.fits(kept, self.dofs) => sums.update(self.tangent, kept),
            _ => match KeptSums::new(self.tangent, kept, self.dofs, matrix) {
                Some(made) => *sums = Some(made),
                None => return false,
            },
        }
        let sums = sums.as_ref().expect("made above");
        let (k, c) = (self.scales.stiffness, self.scales.damping);
        let values = matrix.val_mut();
        values
            .iter_mut()
            .zip(sums.sums[0].iter().zip(&sums.sums[1]))
            .for_each(|(value, (sk, sc))| *value = k * sk + c * sc);
        self.fill(matrix, slots, [kept.stiffness, kept.damping])
    }
}

/// The symbolic analysis of one sparsity pattern, with the scratch space its numeric
/// factorisations and its solves need.
struct Analysis {
    pattern: SymbolicSparseColMat<usize>,
    symbolic: SymbolicCholesky<usize>,
    factor_scratch: MemBuffer,
    solve_scratch: MemBuffer,
}

impl std::fmt::Debug for Analysis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Analysis")
            .field("pattern", &self.pattern)
            .field("symbolic", &self.symbolic)
            .finish_non_exhaustive()
    }
}

/// A sparse LLᵀ factorisation that keeps its symbolic analysis per sparsity pattern.
#[derive(Debug, Default)]
pub struct SparseCholesky {
    analysis: Option<Analysis>,
    values: Vec<f64>,
    factored: bool,
    failed_pivot: Option<usize>,
    stats: FactorStats,
}

impl SparseCholesky {
    /// Whether a numeric factorisation is available for [`Self::solve_in_place`].
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// The system index (in the matrix's own ordering) of the pivot that was not positive in
    /// the last [`Self::factorize`], where faer tells it; `None` after a success.
    pub fn failed_pivot(&self) -> Option<usize> {
        self.failed_pivot
    }

    /// Statistics of the last analysis and factorisation.
    pub fn stats(&self) -> &FactorStats {
        &self.stats
    }

    /// Factorises the symmetric matrix `a`, given by its lower triangle, which took
    /// `assembly_seconds` to assemble: the symbolic analysis is redone only if the pattern
    /// differs from the last one. `what` names the matrix in the error raised when it is not
    /// positive definite; the failing pivot is then kept for [`Self::failed_pivot`] (see
    /// [`explain_failure`] for a message naming its body).
    pub fn factorize(
        &mut self,
        (a, assembly_seconds): (SparseColMatRef<'_, usize, f64>, f64),
        what: &'static str,
    ) -> Result<(), CoreError> {
        self.factored = false;
        self.failed_pivot = None;
        self.analyse(a)?;
        let analysis = self.analysis.as_mut().expect("analysed above");
        let symbolic = &analysis.symbolic;
        let par = faer::get_global_parallelism();
        self.values.resize(symbolic.len_val(), 0.0);
        let start = Instant::now();
        let result = symbolic.factorize_numeric_llt(
            &mut self.values,
            a,
            Side::Lower,
            Default::default(),
            par,
            MemStack::new(&mut analysis.factor_scratch),
            Default::default(),
        );
        if let Err(error) = result {
            self.failed_pivot = failed_column(&error, symbolic);
            return Err(CoreError::NotPositiveDefinite {
                what,
                dofs: a.nrows(),
                particle: None,
                body: None,
                detail: GENERIC_CAUSE.to_string(),
            });
        }
        self.stats.numeric_seconds = start.elapsed().as_secs_f64();
        self.stats.assembly_seconds = assembly_seconds;
        self.stats.factorizations += 1;
        self.factored = true;
        Ok(())
    }

    /// Runs the symbolic analysis of `a` unless its pattern is the one analysed last.
    fn analyse(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<(), CoreError> {
        let pattern = a.symbolic();
        let same = self.analysis.as_ref().is_some_and(|old| {
            old.pattern.col_ptr() == pattern.col_ptr() && old.pattern.row_idx() == pattern.row_idx()
        });
        if same {
            return Ok(());
        }
        let start = Instant::now();
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .map_err(sparse_error)?;
        self.stats = FactorStats {
            dofs: a.nrows(),
            nonzeros: pattern.compute_nnz(),
            factor_nonzeros: symbolic.len_val(),
            symbolic_seconds: start.elapsed().as_secs_f64(),
            numeric_seconds: 0.0,
            assembly_seconds: 0.0,
            solve_seconds: 0.0,
            analyses: self.stats.analyses + 1,
            factorizations: self.stats.factorizations,
        };
        let par = faer::get_global_parallelism();
        let factor_scratch =
            MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()));
        let solve_scratch = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, par));
        self.analysis = Some(Analysis {
            pattern: pattern.to_owned().map_err(sparse_error)?,
            symbolic,
            factor_scratch,
            solve_scratch,
        });
        Ok(())
    }

    /// Overwrites `rhs` with A⁻¹ rhs (forward and backward triangular solves).
    ///
    /// # Panics
    /// If no factorisation is available or `rhs` has the wrong length.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        assert!(self.factored, "solve_in_place before a factorisation");
        let start = Instant::now();
        let analysis = self.analysis.as_mut().expect("factored implies analysed");
        let n = rhs.len();
        let rhs = MatMut::from_column_major_slice_mut(rhs, n, 1);
        LltRef::new(&analysis.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            faer::get_global_parallelism(),
            MemStack::new(&mut analysis.solve_scratch),
        );
        self.stats.solve_seconds = start.elapsed().as_secs_f64();
    }
}

/// The column, in the matrix's own ordering, of the pivot faer found not positive. faer reports
/// it in the fill-reducing order, one-based from its simplicial and zero-based from its
/// supernodal factorisation.
fn failed_column(error: &LltError, symbolic: &SymbolicCholesky<usize>) -> Option<usize> {
    let LltError::NonPositivePivot { index } = *error;
    let permuted = match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(_) => index.checked_sub(1)?,
        SymbolicCholeskyRaw::Supernodal(_) => index,
    };
    if permuted >= symbolic.ncols() {
        return None;
    }
    Some(match symbolic.perm() {
        Some(perm) => perm.arrays().0[permuted],
        None => permuted,
    })
}

/// Turns a [`CoreError::NotPositiveDefinite`] from [`SparseCholesky::factorize`] into one that
/// names the particle of the failing pivot (`pivot`, a system index of `dofs`, from
/// [`SparseCholesky::failed_pivot`]) and the model that owns it, and lists the bodies that the
/// constraints leave free to move rigidly ([`unconstrained_bodies`]) with the fix. Any other
/// error is returned unchanged.
pub fn explain_failure(
    error: CoreError,
    pivot: Option<usize>,
    dofs: &FreeDofs,
    state: &State,
    models: &[Box<dyn Model>],
    tangent: &Tangent,
) -> CoreError {
    let CoreError::NotPositiveDefinite { what, dofs: n, .. } = error else {
        return error;
    };
    let (mut particle, mut body) = (None, None);
    let mut detail = match pivot.and_then(|i| dofs.dof(i)) {
        Some(dof) => {
            let p = dof / 3;
            particle = Some(p);
            body = models
                .iter()
                .find(|m| particles_of(m.as_ref()).binary_search(&p).is_ok())
                .map(|m| m.name().to_string());
            let axis = ["x", "y", "z"][dof % 3];
            match &body {
                Some(name) => {
                    format!("the pivot of particle {p} ({axis}) of body `{name}` is not positive; ")
                }
                None => format!(
                    "the pivot of particle {p} ({axis}), which belongs to no body, is not \
                     positive; "
                ),
            }
        }
        None => "the factorisation did not tell which pivot failed; ".to_string(),
    };
    let free = unconstrained_bodies(state, models, tangent, dofs);
    if free.is_empty() {
        detail.push_str(GENERIC_CAUSE);
    } else {
        let names: Vec<String> = free
            .iter()
            .map(|(name, modes)| format!("`{name}` ({modes} of 6 rigid-body modes free)"))
            .collect();
        detail.push_str(&format!(
            "not constrained against rigid motion: {}; for each, {FIX_HINT}",
            names.join(", ")
        ));
    }
    CoreError::NotPositiveDefinite {
        what,
        dofs: n,
        particle,
        body,
        detail,
    }
}

/// The models owning particles ([`crate::step::Linearized::particles`], i.e. deformable bodies) that the fixed
/// directions of `dofs` leave free to move rigidly with no stiffness against it, each with the
/// number of its free rigid-body modes (of 3 translations and 3 rotations, at the current
/// positions).
///
/// A mode counts when it vanishes in every fixed direction of the body's particles and the
/// stiffness of `tangent` (all models together, so bonds to other bodies count) maps it to zero
/// in every free direction, up to rounding: the stiffness matrix over the free DOFs is then
/// singular. The check is sufficient, not necessary (bodies that are only free together, as a
/// group, are not found), so it never refuses a solvable system.
pub fn unconstrained_bodies(
    state: &State,
    models: &[Box<dyn Model>],
    tangent: &Tangent,
    dofs: &FreeDofs,
) -> Vec<(String, usize)> {
    models
        .iter()
        .filter_map(|m| {
            let modes = free_rigid_modes(state, &particles_of(m.as_ref()), tangent, dofs);
            (modes > 0).then(|| (m.name().to_string(), modes))
        })
        .collect()
}

/// The motion at arm `r` from a centre of the rigid motion v = (translation, small rotation):
/// t = R v with R = [I | −[r]×].
pub(crate) fn rigid_motion(r: Vec3) -> SMatrix<f64, 3, 6> {
    let mut m = SMatrix::<f64, 3, 6>::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&Mat3::identity());
    m.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(-r.cross_matrix()));
    m
}

/// Relative size below which a rigid mode counts as unconstrained or as stress-free.
const RIGID_TOLERANCE: f64 = 1e-8;

/// The number of rigid-body modes of the particles `particles` that the fixity leaves free and
/// the stiffness does not resist (see [`unconstrained_bodies`]).
fn free_rigid_modes(
    state: &State,
    particles: &[usize],
    tangent: &Tangent,
    dofs: &FreeDofs,
) -> usize {
    if particles.is_empty() {
        return 0;
    }
    let centre =
        particles.iter().map(|&i| state.position[i]).sum::<Vec3>() / particles.len() as f64;
    let size = particles
        .iter()
        .map(|&i| (state.position[i] - centre).norm())
        .fold(0.0, f64::max);
    if size.is_nan() || size <= 0.0 {
        return 0;
    }
    // The arm is scaled so that every mode is of order one; a framed particle's rows in its
    // frame, as its DOFs are numbered.
    let modes = |i: usize| dofs.local_rows(i, rigid_motion((state.position[i] - centre) / size));
    let fixed = |i: usize, axis: usize| dofs.index(3 * i + axis).is_none();
    let mut gram = Matrix6::zeros();
    let mut rows = 0usize;
    for &i in particles {
        let m = modes(i);
        for axis in (0..3).filter(|&a| fixed(i, a)) {
            let row = m.row(axis).transpose();
            gram += row * row.transpose();
            rows += 1;
        }
    }
    let eigen = SymmetricEigen::new(gram);
    let null: Vec<Vector6<f64>> = (0..6)
        .filter(|&k| eigen.eigenvalues[k] <= 1e-10 * rows.max(1) as f64)
        .map(|k| eigen.eigenvectors.column(k).into_owned())
        .collect();
    if null.is_empty() {
        return 0;
    }
    // The null modes as displacements of the body's free DOFs, then K t over all free DOFs.
    let mut local = vec![usize::MAX; state.len()];
    for (k, &i) in particles.iter().enumerate() {
        local[i] = k;
    }
    let motion: Vec<Vec<f64>> = null
        .iter()
        .map(|v| {
            let mut t = vec![0.0; 3 * particles.len()];
            for (k, &i) in particles.iter().enumerate() {
                let u = modes(i) * v;
                for axis in (0..3).filter(|&a| !fixed(i, a)) {
                    t[3 * k + axis] = u[axis];
                }
            }
            t
        })
        .collect();
    // A particle's rotation (a node past the particles: a bonded body's spins) is outside.
    let inside = |dof: usize| {
        let k = local.get(dof / 3).copied().unwrap_or(usize::MAX);
        (k != usize::MAX).then(|| 3 * k + dof % 3)
    };
    let mut product = vec![vec![0.0; 3 * particles.len()]; null.len()];
    let mut outside: HashMap<usize, Vec<f64>> = HashMap::new();
    let mut diagonal = vec![0.0; 3 * particles.len()];
    let mut add = |row: usize, col: usize, value: f64| {
        let Some(c) = inside(col) else { return };
        if dofs.index(row).is_none() || dofs.index(col).is_none() {
            return;
        }
        match inside(row) {
            Some(r) => {
                if r == c {
                    diagonal[r] += value;
                }
                for (y, t) in product.iter_mut().zip(&motion) {
                    y[r] += value * t[c];
                }
            }
            None => {
                let y = outside.entry(row).or_insert_with(|| vec![0.0; null.len()]);
                for (y, t) in y.iter_mut().zip(&motion) {
                    *y += value * t[c];
                }
            }
        }
    };
    for e in tangent.stiffness_entries() {
        add(e.row, e.col, e.val);
        if e.row != e.col {
            add(e.col, e.row, e.val);
        }
    }
    let stiffness = diagonal.iter().fold(0.0, |m: f64, d| m.max(d.abs()));
    (0..null.len())
        .filter(|&k| {
            let scale = motion[k].iter().fold(0.0, |m: f64, t| m.max(t.abs()));
            let inner = product[k].iter().fold(0.0, |m: f64, y| m.max(y.abs()));
            let outer = outside.values().fold(0.0, |m: f64, y| m.max(y[k].abs()));
            scale > 0.0 && inner.max(outer) <= RIGID_TOLERANCE * stiffness * scale
        })
        .count()
}

/// Maps a faer error to a core error.
pub(crate) fn sparse_error(e: impl std::fmt::Debug) -> CoreError {
    CoreError::Sparse(format!("{e:?}"))
}

/// The particles a model's elements join ([`crate::step::Linearized::particles`]); none for a model
/// without a linearisation.
fn particles_of(model: &dyn Model) -> Vec<usize> {
    model.linearized().map_or_else(Vec::new, |l| l.particles())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dense lower triangle of s_M M + s_C C + s_K K, summed entry by entry.
    fn dense(tangent: &Tangent, mass: &[f64], dofs: &FreeDofs, s: Scales) -> Vec<Vec<f64>> {
        let n = dofs.len();
        let mut a = vec![vec![0.0; n]; n];
        for (list, scale) in [
            (&tangent.stiffness, s.stiffness),
            (&tangent.damping, s.damping),
        ] {
            for e in list {
                if let (Some(r), Some(c)) = (dofs.index(e.row), dofs.index(e.col)) {
                    a[r][c] += scale * e.val;
                }
            }
        }
        for dof in 0..3 * mass.len() {
            if let Some(i) = dofs.index(dof) {
                a[i][i] += s.mass * mass[dof / 3];
            }
        }
        a
    }

    /// The matrix's stored lower triangle as a dense one.
    fn stored(m: SparseColMatRef<'_, usize, f64>) -> Vec<Vec<f64>> {
        let mut a = vec![vec![0.0; m.nrows()]; m.nrows()];
        let entries = (0..m.ncols()).flat_map(|c| {
            m.row_idx_of_col(c)
                .zip(m.val_of_col(c))
                .map(move |e| (e, c))
        });
        for ((r, v), c) in entries {
            a[r][c] += v;
        }
        a
    }

    fn assert_close(a: &[Vec<f64>], b: &[Vec<f64>]) {
        for (ra, rb) in a.iter().zip(b) {
            for (x, y) in ra.iter().zip(rb) {
                assert!((x - y).abs() <= 1e-12 * (1.0 + x.abs()), "{x} vs {y}");
            }
        }
    }

    /// A chain of 4 particles with a fixed one: coupled blocks, duplicates and fixed DOFs.
    fn chain(stiffness: f64) -> Tangent {
        let mut t = Tangent::new();
        for p in 0..3 {
            let k = Mat3::from_fn(|r, c| stiffness * (1.0 + r as f64 + 0.5 * c as f64));
            let k = k + k.transpose();
            t.add_stiffness(p, p, &k);
            t.add_stiffness(p + 1, p + 1, &k);
            t.add_stiffness(p + 1, p, &(-k));
            t.add_damping(p, p, &(0.1 * k));
            t.add_damping(p + 1, p, &(-0.1 * k));
        }
        t
    }

    #[test]
    fn reassembly_through_the_kept_pattern_matches_a_fresh_assembly() {
        let mass = [2.0, 3.0, 4.0, 5.0];
        let dofs = FreeDofs::new(&[Dofs::ALL, Dofs::NONE, Dofs::NONE, Dofs::NONE]);
        let s = Scales {
            mass: 1.0,
            damping: 0.5,
            stiffness: 0.25,
        };
        let mut assembler = Assembler::new();
        let first = chain(1.0);
        assert_close(
            &stored(assembler.assemble(&first, &mass, &dofs, s).unwrap().0),
            &dense(&first, &mass, &dofs, s),
        );
        // New values at the same entries: filled through the kept slots.
        let second = chain(7.0);
        let kept = stored(assembler.assemble(&second, &mass, &dofs, s).unwrap().0);
        assert_close(&kept, &dense(&second, &mass, &dofs, s));
        assert_close(
            &kept,
            &stored(
                Assembler::new()
                    .assemble(&second, &mass, &dofs, s)
                    .unwrap()
                    .0,
            ),
        );
        // An entry outside the pattern (particles 1 and 3) rebuilds it.
        let mut third = chain(7.0);
        third.add_stiffness(3, 1, &Mat3::from_element(0.3));
        let rebuilt = assembler.assemble(&third, &mass, &dofs, s).unwrap().0;
        assert_eq!(
            rebuilt.compute_nnz(),
            kept_nnz(&second, &mass, &dofs, s) + 9
        );
        assert_close(&stored(rebuilt), &dense(&third, &mass, &dofs, s));
    }

    /// `chain`'s entries as kept entries, a contact-like block after them, and the kept
    /// list's changes: `zeroed` ranges of kept entries set to zero, in order.
    fn with_kept(source: u64, zeroed: &[std::ops::Range<usize>]) -> Tangent {
        let base = chain(3.0);
        let (mut stiffness, mut damping) = (base.stiffness.clone(), base.damping.clone());
        for range in zeroed {
            for e in stiffness[range.clone()]
                .iter_mut()
                .chain(&mut damping[range.clone()])
            {
                e.val = 0.0;
            }
        }
        let kept = KeptEntries {
            source,
            stiffness: stiffness.len(),
            damping: damping.len(),
            changes: zeroed.to_vec(),
        };
        let mut t = Tangent::new();
        t.extend_kept(&stiffness, &damping, kept);
        t.add_stiffness(2, 1, &Mat3::from_element(0.7));
        t.add_damping(2, 1, &Mat3::from_element(0.07));
        t
    }

    /// Kept entries summed per slot once and updated where they changed give the matrix of a
    /// fresh assembly (to rounding: s_K ΣK differs from Σ s_K K in the last bits), at any
    /// step, and the same bits as a fresh assembly of the same kept entries.
    #[test]
    fn kept_entries_updated_where_they_changed_match_a_fresh_assembly() {
        let mass = [2.0, 3.0, 4.0, 5.0];
        let dofs = FreeDofs::new(&[Dofs::ALL, Dofs::NONE, Dofs::NONE, Dofs::NONE]);
        let scales = |h: f64| Scales {
            mass: 1.0,
            damping: 0.5 * h,
            stiffness: 0.25 * h * h,
        };
        let source = KeptEntries::new_source();
        let mut assembler = Assembler::new();
        let mut changes = Vec::new();
        for (round, zero) in [None, Some(0..9), Some(12..14), None, Some(30..33)]
            .into_iter()
            .enumerate()
        {
            changes.extend(zero);
            let t = with_kept(source, &changes);
            let s = scales(1.0 + round as f64);
            let kept = stored(assembler.assemble(&t, &mass, &dofs, s).unwrap().0);
            assert_close(&kept, &dense(&t, &mass, &dofs, s));
            let fresh = with_kept(KeptEntries::new_source(), &changes);
            let again = stored(
                Assembler::new()
                    .assemble(&fresh, &mass, &dofs, s)
                    .unwrap()
                    .0,
            );
            assert_eq!(kept, again, "round {round}: the same bits as a fresh sum");
        }
    }

    /// C x by rows with kept rows updated in place gives the bits of rows built at once.
    #[test]
    fn damping_rows_with_kept_entries_sum_as_whole_rows() {
        let n = 4;
        let x: Vec<Vec3> = (0..n)
            .map(|p| Vec3::new(1.0, -0.3, 0.7) * (p as f64 + 0.1))
            .collect();
        let spin = vec![Vec3::zeros(); n];
        let times = |rows: &DampingRows| {
            let (mut y, mut m) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
            rows.subtract_times((&x, &spin), (&mut y, &mut m));
            y
        };
        let source = KeptEntries::new_source();
        let mut rows = DampingRows::default();
        let mut changes = Vec::new();
        for zero in [None, Some(0..9), Some(12..14)] {
            changes.extend(zero);
            let t = with_kept(source, &changes);
            rows.build(&t, 6 * n);
            let mut plain = t.clone();
            plain.kept = None;
            let mut whole = DampingRows::default();
            whole.build(&plain, 6 * n);
            assert_eq!(times(&rows), times(&whole));
        }
    }

    fn kept_nnz(t: &Tangent, mass: &[f64], dofs: &FreeDofs, s: Scales) -> usize {
        Assembler::new()
            .assemble(t, mass, dofs, s)
            .unwrap()
            .0
            .compute_nnz()
    }
}
