//! [`Tangent`]: the tangent stiffness K = −∂f/∂x and damping C = −∂f/∂v that the models'
//! linearisations ([`crate::step::Linearized`]) add for implicit and static solves (paper 001
//! Eq. 26), as 3×3 blocks per particle pair in global numbering (DOF 3·particle + axis). Only
//! the lower triangle (row ≥ column) is kept: both matrices are symmetric and the Cholesky
//! factorisation reads the lower triangle only. The solvers assemble and factorise it
//! (`crate::solvers::sparse`).

use crate::checkpoint::{CheckpointError, Decoder, Encoder};
use crate::Mat3;
use faer::sparse::Triplet;
use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

/// One stored value of a tangent: (row DOF, column DOF, value).
pub type Entry = Triplet<usize, usize, f64>;

/// The tangent stiffness K = −∂f/∂x and damping C = −∂f/∂v of a scene, as lower-triangle
/// triplets in global DOF numbering; duplicates are summed on assembly.
#[derive(Clone, Debug, Default)]
pub struct Tangent {
    pub(crate) stiffness: Vec<Entry>,
    pub(crate) damping: Vec<Entry>,
    /// The leading entries that a model keeps between assemblies ([`Tangent::extend_kept`]).
    pub(crate) kept: Option<KeptEntries>,
}

/// A list of tangent entries that a model keeps between assemblies, in the same places, and
/// whose values change only where it says (a broken bond's entries going to zero): the
/// implicit solver then updates those entries of the matrix it keeps instead of summing every
/// entry again (issue 44).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct KeptEntries {
    /// Names the list for the life of the process ([`KeptEntries::new_source`]).
    pub source: u64,
    /// Entries in the stiffness list.
    pub stiffness: usize,
    /// Entries in the damping list.
    pub damping: usize,
    /// The entries changed since the list was made, one range per change, in order (the same
    /// indices in both lists); the list's revision is the number of changes.
    pub changes: Vec<Range<usize>>,
}

impl KeptEntries {
    /// A source number that no other call in this process returns.
    pub fn new_source() -> u64 {
        static NEXT: AtomicU64 = AtomicU64::new(0);
        NEXT.fetch_add(1, Ordering::Relaxed)
    }
}

impl Tangent {
    /// An empty tangent.
    pub fn new() -> Tangent {
        Tangent::default()
    }

    /// Removes every entry, keeping the allocations.
    pub fn clear(&mut self) {
        self.stiffness.clear();
        self.damping.clear();
        self.kept = None;
    }

    /// Adds the stiffness block K_ij (∂ of the force on particle i by the position of j,
    /// negated). Entries above the diagonal are dropped: add every block of a symmetric matrix.
    pub fn add_stiffness(&mut self, i: usize, j: usize, block: &Mat3) {
        push_lower(&mut self.stiffness, i, j, block);
    }

    /// Adds the damping block C_ij, as [`Tangent::add_stiffness`] does for K.
    pub fn add_damping(&mut self, i: usize, j: usize, block: &Mat3) {
        push_lower(&mut self.damping, i, j, block);
    }

    /// Adds K at (row DOF, column DOF), if on or below the diagonal: for models whose blocks
    /// are mostly zero (a 2D beam couples x, y and the rotation about z only). A DOF is
    /// 3·node + axis, node `state.len() + i` being the rotation of particle i.
    pub fn add_stiffness_entry(&mut self, row: usize, col: usize, value: f64) {
        if row >= col {
            self.stiffness.push(Triplet::new(row, col, value));
        }
    }

    /// Adds C at (row DOF, column DOF), as [`Tangent::add_stiffness_entry`] does for K.
    pub fn add_damping_entry(&mut self, row: usize, col: usize, value: f64) {
        if row >= col {
            self.damping.push(Triplet::new(row, col, value));
        }
    }

    /// Appends ready stiffness and damping entries (global DOFs, on or below the diagonal,
    /// as [`Tangent::add_stiffness_entry`] keeps them): for models that keep their entries
    /// between assemblies.
    pub fn extend(&mut self, stiffness: &[Entry], damping: &[Entry]) {
        debug_assert!(stiffness.iter().chain(damping).all(|e| e.row >= e.col));
        self.stiffness.extend_from_slice(stiffness);
        self.damping.extend_from_slice(damping);
    }

    /// Appends a model's kept entries, as [`Tangent::extend`] does, and marks them kept when
    /// they lead the tangent (nothing was added before them): `kept` says which they are and
    /// what changed in them since they were made.
    pub fn extend_kept(&mut self, stiffness: &[Entry], damping: &[Entry], kept: KeptEntries) {
        let leading = self.stiffness.is_empty() && self.damping.is_empty();
        let sized = kept.stiffness == stiffness.len() && kept.damping == damping.len();
        if leading && sized {
            self.kept = Some(kept);
        }
        self.extend(stiffness, damping);
    }

    /// The stored stiffness entries (lower triangle, global DOFs, duplicates not summed).
    pub fn stiffness_entries(&self) -> &[Entry] {
        &self.stiffness
    }

    /// Writes the entries into a checkpoint (an implicit stepper's factorised tangent), and
    /// how many of them are kept: a resumed run sums them per slot as the first run did.
    pub(crate) fn save(&self, out: &mut Encoder) {
        for list in [&self.stiffness, &self.damping] {
            out.u64(list.len() as u64);
            for e in list {
                out.u64(e.row as u64);
                out.u64(e.col as u64);
                out.f64(e.val);
            }
        }
        out.bool(self.kept.is_some());
        if let Some(kept) = &self.kept {
            out.u64(kept.stiffness as u64);
            out.u64(kept.damping as u64);
        }
    }

    /// Reads back what [`Tangent::save`] wrote, for `dofs` degrees of freedom.
    pub(crate) fn restore(
        &mut self,
        input: &mut Decoder<'_>,
        dofs: usize,
    ) -> Result<(), CheckpointError> {
        for list in [&mut self.stiffness, &mut self.damping] {
            let n = input.u64("tangent entries")?;
            list.clear();
            for _ in 0..n {
                let (row, col) = (input.u64("a tangent row")?, input.u64("a tangent column")?);
                let val = input.f64("a tangent value")?;
                if row >= dofs as u64 || col > row {
                    return Err(CheckpointError::Invalid {
                        what: "tangent",
                        detail: format!(
                            "entry ({row}, {col}) outside the lower triangle of {dofs} DOFs"
                        ),
                    });
                }
                list.push(Triplet::new(row as usize, col as usize, val));
            }
        }
        self.kept = None;
        if input.bool("whether the tangent has kept entries")? {
            let stiffness = input.u64("kept stiffness entries")? as usize;
            let damping = input.u64("kept damping entries")? as usize;
            if stiffness > self.stiffness.len() || damping > self.damping.len() {
                return Err(CheckpointError::Invalid {
                    what: "tangent",
                    detail: format!("{stiffness} and {damping} kept entries of fewer"),
                });
            }
            self.kept = Some(KeptEntries {
                source: KeptEntries::new_source(),
                stiffness,
                damping,
                changes: Vec::new(),
            });
        }
        Ok(())
    }
}

/// Pushes the entries of block (i, j) that lie on or below the diagonal.
fn push_lower(list: &mut Vec<Entry>, i: usize, j: usize, block: &Mat3) {
    for a in 0..3 {
        for b in 0..3 {
            let (row, col) = (3 * i + a, 3 * j + b);
            if row >= col {
                list.push(Triplet::new(row, col, block[(a, b)]));
            }
        }
    }
}
