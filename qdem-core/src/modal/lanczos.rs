//! Natural frequencies and mode shapes by shift-invert Lanczos: the lowest eigenpairs of
//! K φ = ω² M φ about a state (a scene's reference configuration, or the settled state a run
//! starts from).
//!
//! - K is the models' tangent stiffness at the state's positions ([`Model::modal_stiffness`];
//!   for QDEM tetrahedra the small-strain linear-tet stiffness, so these are the mesh's linear
//!   FEM modes with lumped mass; for DEM contacts the touching contacts' springs), M the
//!   lumped mass (a quarter of each tetrahedron's mass to each
//!   vertex), both over the free DOFs of the deformable bodies' particles (fixed directions
//!   are eliminated as in the static solve, paper 001 Eq. 23). Models without a modal
//!   stiffness (loads, gravity) add nothing and are listed in [`Modes::ignored`].
//! - A rigid body takes part with its six DOFs, its centre's translation and its rotations
//!   about its principal axes: its members' entries of K are condensed onto them
//!   (`rigid_reduction.rs`), and its members follow in the mode shapes. One that nothing
//!   touches and nothing fixes reports its six rigid-body modes. One held at points and free
//!   to turn about them ([`crate::step::rigid_constraints`]) is refused.
//! - Shift and invert (Ericsson & Ruhe 1980): with A = K − σM, σ = −(2π · 1 Hz)² < 0 so that A
//!   is positive definite even for a body free to move rigidly, the eigenvalues θ of the
//!   operator A⁻¹M, self-adjoint in the M inner product ⟨x, y⟩ = xᵀMy, are θ = 1/(ω² − σ):
//!   the lowest ω² become the largest, best separated θ. A is factorised once with faer's
//!   sparse Cholesky (the crate's `sparse::SparseCholesky`); each Lanczos step is one pair of
//!   triangular solves.
//! - Lanczos in the M inner product (Golub & Van Loan §10.1, with full reorthogonalisation:
//!   classical Gram–Schmidt twice against every earlier vector): A⁻¹M Q_m = Q_m T_m +
//!   β_m q_{m+1} e_mᵀ, T_m tridiagonal. A Ritz pair (θ, Q_m y) of T_m y = θ y has residual
//!   norm |β_m y_m|, so an eigenvalue is accepted when |β_m y_m| ≤ [`TOLERANCE`] · θ; then
//!   |θ − θ_true| ≤ (β_m y_m)²/gap, far below the tolerance. T_m is taken as the
//!   projection QᵀM A⁻¹M Q from every Gram–Schmidt coefficient (tridiagonal to rounding), so
//!   the Ritz pairs stay a Rayleigh–Ritz projection also near the end of the space; when a
//!   Krylov space closes (β ≈ 0) Lanczos continues from a fresh vector orthogonal to it.
//! - Rigid-body modes: a deformable body with no fixed direction has six exact zero modes (3
//!   translations, 3 small rotations about its mass centre, K r = 0 for the linear-tet K).
//!   Single-vector Lanczos finds only one vector of a repeated eigenvalue, so these are not
//!   iterated: they are formed directly, M-orthonormalised, reported first (with their
//!   Rayleigh quotient rᵀKr/rᵀMr, zero to rounding) and projected out of every Lanczos vector,
//!   which then iterates in their M-orthogonal complement. A body that is fixed in some
//!   directions but still free to move rigidly (a plate simply supported on its edges, free
//!   in its plane) has the rigid motions its fixes leave free as zero modes alike
//!   (`partly_fixed.rs`): the shifted operator is positive definite whatever K's null space.
//!   Other exactly repeated eigenvalues (a square section's two bending planes) are likewise
//!   found once only: give such test geometries distinct dimensions.
//! - Participation: for an M-normalised mode φ and a unit rigid motion r_d (translation along
//!   x, y, z or rotation about the axes through the mass centre, restricted to the free DOFs),
//!   the effective modal mass fraction is Γ_d² / (r_dᵀ M r_d) with Γ_d = φᵀ M r_d; over all
//!   modes the fractions of each direction sum to 1 (the modes are an M-orthonormal basis of
//!   the free DOFs). The direction with the largest fraction is the mode's dominant direction.

use crate::error::CoreError;
use crate::modal::mechanisms::{tet_piece_rows, unresisted_motions, SystemDofs};
use crate::modal::partly_fixed;
use crate::modal::rigid_reduction::RigidReduction;
use crate::solvers::sparse::{
    unconstrained_bodies, Assembler, FreeDofs, Scales, SparseCholesky, Tangent,
};
use crate::step::model::Model;
use crate::step::state::{Dofs, State};
use crate::Vec3;
use nalgebra::{DMatrix, SymmetricEigen, Vector6};
use std::f64::consts::PI;
use thiserror::Error;

/// Relative residual |β_m y_m| / θ below which a Ritz value counts as converged.
pub const TOLERANCE: f64 = 1e-12;

/// Frequency of the shift σ = −(2π f)² (Hz): makes K − σM positive definite for free bodies.
pub const SHIFT_HZ: f64 = 1.0;

/// Names of the participation directions, in the order of [`Mode::participation`].
pub const DIRECTIONS: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

/// Everything a modal analysis refuses.
#[derive(Debug, Error)]
pub enum ModalError {
    /// No model has particles with stiffness (no deformable body).
    #[error(
        "nothing deformable: no model gives a stiffness to particles with mass, so there are no \
         natural modes to compute (add a deformable [[body]] with a tetrahedral mesh, or \
         contacts that hold a rigid one)"
    )]
    NothingDeformable,
    /// Zero modes asked for.
    #[error("asked for 0 modes: give a count of at least 1")]
    ZeroCount,
    /// More modes than free degrees of freedom.
    #[error(
        "asked for {count} modes, but the bodies have only {dofs} free degrees of \
         freedom: give a count of at most {dofs}"
    )]
    TooManyModes {
        /// Modes asked for.
        count: usize,
        /// Free DOFs.
        dofs: usize,
    },
    /// More modes than the free DOFs give once the unresisted motions are left out.
    #[error(
        "asked for {count} modes, but only {modes} are left once the {mechanisms} rigid motions \
         of single pieces that nothing resists are left out: give a count of at most {modes}"
    )]
    TooFewResisted {
        /// Modes asked for.
        count: usize,
        /// Modes there are.
        modes: usize,
        /// Unresisted motions left out.
        mechanisms: usize,
    },
    /// A body fixed in some directions but still free to move rigidly, in motions that its
    /// fixes alone do not say (something else, a bond or a contact, resists some of them).
    #[error(
        "body `{body}` is fixed in some directions but {modes} of its 6 rigid-body modes are \
         still free: either fix it against rigid motion (at least 3 non-collinear particles or \
         a face, with [[fix]]) or remove its fixes to get its free-free modes"
    )]
    PartlyConstrained {
        /// The body's name.
        body: String,
        /// Free rigid-body modes.
        modes: usize,
    },
    /// A rigid body that nothing touches, fixed in some directions but still free to move.
    #[error(
        "rigid body {body} (of state.rigid) is fixed in some directions but {modes} of its 6 \
         DOFs are still free and nothing touches it: fix it whole, or remove its fixes to get \
         its rigid-body modes"
    )]
    PartlyConstrainedRigid {
        /// Its index in [`State::rigid`].
        body: usize,
        /// Its free DOFs.
        modes: usize,
    },
    /// A rigid body held at points ([`crate::step::rigid_constraints`]) and free to turn
    /// about them: the analysis moves a rigid body by its centre's translation and its whole
    /// rotation, and cannot hold it at a point.
    #[error(
        "{body} is held at points by [[fix]] #{fix}, which leave it free to turn about them, \
         and a modal analysis holds a rigid body only at its centre and its whole rotation; \
         fix: hold its rotation too (rotation = true on the fix), or hold it whole (members \
         at three points not on one line, in x, y and z)"
    )]
    HeldAtPoints {
        /// The body (`rigid body K`, K its index in [`State::rigid`], or its scene name).
        body: String,
        /// The number of the first fix holding it.
        fix: usize,
    },
    /// Lanczos stopped before the wanted modes converged.
    #[error(
        "Lanczos did not converge: {converged} of {wanted} modes after {steps} steps; ask for \
         fewer modes"
    )]
    NotConverged {
        /// Modes converged.
        converged: usize,
        /// Modes wanted (excluding rigid-body modes).
        wanted: usize,
        /// Lanczos steps taken.
        steps: usize,
    },
    /// The factorisation or the assembly failed.
    #[error(transparent)]
    Core(#[from] CoreError),
}

/// One natural mode.
#[derive(Clone, Debug)]
pub struct Mode {
    /// ω² (rad²/s²); for a rigid-body mode its Rayleigh quotient (zero to rounding).
    pub eigenvalue: f64,
    /// Natural frequency √max(ω², 0) / 2π (Hz).
    pub frequency_hz: f64,
    /// Whether this is a rigid-body mode: a motion of a body that its fixes leave free and no
    /// stiffness resists (and, for a rigid body, with nothing touching it).
    pub rigid: bool,
    /// The mode shape, M-normalised (φᵀMφ = 1), one vector per particle: zero where fixed
    /// and on particles of no body; a rigid body's members move with it, its centre particle
    /// carries its translation.
    pub shape: Vec<Vec3>,
    /// Effective modal mass fractions along x, y, z and about the axes x, y, z through the mass
    /// centre ([`DIRECTIONS`]).
    pub participation: [f64; 6],
    /// Share of the mode's kinetic energy in x, y and z motion, Σ m u_d² / Σ m |u|² (sums to
    /// 1): what tells the elastic modes of a free body apart, whose effective masses are all
    /// zero (vertical bending is z motion, lateral bending and torsion y, extension x).
    pub motion: [f64; 3],
}

impl Mode {
    /// The direction with the largest effective mass fraction (index into [`DIRECTIONS`]) and
    /// that fraction.
    pub fn dominant(&self) -> (usize, f64) {
        self.participation.iter().copied().enumerate().fold(
            (0, f64::NEG_INFINITY),
            |best, (d, p)| {
                if p > best.1 {
                    (d, p)
                } else {
                    best
                }
            },
        )
    }
}

/// The result of [`natural_modes`].
#[derive(Clone, Debug)]
pub struct Modes {
    /// The modes by increasing frequency, rigid-body modes first.
    pub modes: Vec<Mode>,
    /// Free degrees of freedom of the eigenproblem.
    pub dofs: usize,
    /// Zero-stiffness rigid motions of single pieces (a stone resting on fewer than three
    /// contacts) found and left out of the modes (`mechanisms.rs`).
    pub mechanisms: usize,
    /// Models that gave no stiffness and were left out (contacts, say).
    pub ignored: Vec<String>,
    /// Lanczos steps taken.
    pub steps: usize,
    /// Wall time of the assembly and factorisation of K − σM (s).
    pub factor_seconds: f64,
}

/// The `count` lowest natural modes of the deformable bodies of `models` about the positions
/// of `state`, with the lumped masses and the fixity of `state`. Models that keep what they
/// saw at their last force evaluation (DEM contacts: which touch) must have been evaluated
/// at `state`.
///
/// ```
/// use qdem_core::modal::lanczos::natural_modes;
/// use qdem_core::{step::Dofs, continuum::Material, step::Model, step::State, continuum::TetBody, Vec3};
///
/// // One tetrahedron, three vertices fixed: 3 free DOFs, 3 modes.
/// let nodes = vec![Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
/// let body = TetBody::new("tet", &nodes, vec![[0, 1, 2, 3]], Material::elastic(1000.0, 1e6, 0.25))?;
/// let mut state = State::at_rest(nodes);
/// body.lump_mass(&mut state.mass);
/// state.fixed[..3].fill(Dofs::ALL);
/// let models: Vec<Box<dyn Model>> = vec![Box::new(body)];
/// let modes = natural_modes(&state, &models, 3)?;
/// assert_eq!(modes.modes.len(), 3);
/// assert!(modes.modes.windows(2).all(|w| w[0].frequency_hz <= w[1].frequency_hz));
/// # Ok::<(), qdem_core::modal::lanczos::ModalError>(())
/// ```
pub fn natural_modes(
    state: &State,
    models: &[Box<dyn Model>],
    count: usize,
) -> Result<Modes, ModalError> {
    if count == 0 {
        return Err(ModalError::ZeroCount);
    }
    let mut held = state.rigid.holds.bodies();
    if let Some((b, fix)) = held.find(|&(b, _)| !state.rigid.spin_fixed[b]) {
        return Err(ModalError::HeldAtPoints {
            body: format!("rigid body {b}"),
            fix,
        });
    }
    let problem = Problem::new(state, models)?;
    if count > problem.dofs.len() {
        return Err(ModalError::TooManyModes {
            count,
            dofs: problem.dofs.len(),
        });
    }
    let mut rigid = problem.rigid_basis(state, models)?;
    let mechanisms = problem.add_mechanisms(state, models, &mut rigid);
    if count > problem.dofs.len() - mechanisms {
        return Err(ModalError::TooFewResisted {
            count,
            modes: problem.dofs.len() - mechanisms,
            mechanisms,
        });
    }
    let start = std::time::Instant::now();
    let mut solver = ShiftInvert::new(&problem)?;
    let factor_seconds = start.elapsed().as_secs_f64();
    let mut modes: Vec<Mode> = rigid[..rigid.len() - mechanisms]
        .iter()
        .take(count)
        .map(|r| problem.mode(state, problem.rayleigh(r), r.clone(), true))
        .collect();
    let wanted = count - modes.len();
    let mut steps = 0;
    if wanted > 0 {
        let (pairs, taken) = lanczos(&problem, &mut solver, &rigid, wanted)?;
        steps = taken;
        let shift = solver.shift;
        modes.extend(
            pairs
                .into_iter()
                .map(|(theta, x)| problem.mode(state, 1.0 / theta + shift, x, false)),
        );
    }
    Ok(Modes {
        modes,
        dofs: problem.dofs.len(),
        mechanisms,
        ignored: problem.ignored,
        steps,
        factor_seconds,
    })
}

/// K, M and the free DOFs of the eigenproblem, with what the outputs need.
struct Problem {
    tangent: Tangent,
    node_mass: Vec<f64>,
    dofs: FreeDofs,
    /// Lumped mass of each system DOF.
    mass: Vec<f64>,
    /// For each system DOF, its global DOF.
    global: Vec<usize>,
    /// Particles (not rotations) in the state.
    particles: usize,
    /// The rigid bodies' six DOFs.
    reduction: RigidReduction,
    /// Unit rigid motions (6 directions) over the system DOFs.
    directions: Vec<Vec<f64>>,
    ignored: Vec<String>,
}

/// What a global DOF of the modal problem moves.
#[derive(Clone, Copy)]
enum Dof {
    /// Particle p's translation along an axis.
    Translation(usize, usize),
    /// Particle p's rotation about an axis.
    Spin(usize, usize),
    /// Scaled principal rotation k of rigid body b (`rigid_reduction.rs`).
    Body(usize, usize),
}

impl Problem {
    /// Collects K from every model with a linearisation and the free DOFs of their particles.
    fn new(state: &State, models: &[Box<dyn Model>]) -> Result<Problem, ModalError> {
        let reduction = RigidReduction::new(state);
        let mut tangent = Tangent::new();
        let ignored = collect_stiffness(state, models, &mut tangent);
        let tangent = reduction.reduce(state, tangent);
        let n = state.len();
        let mut in_body = vec![false; n];
        for l in models.iter().filter_map(|m| m.modal_stiffness()) {
            for p in l.particles() {
                in_body[p] = true;
            }
        }
        for &c in &state.rigid.center {
            in_body[c] = true;
        }
        let mut fixity = state.node_fixity();
        for (node, fixed) in fixity.iter_mut().enumerate() {
            if !in_body[node % n.max(1)] {
                *fixed = Dofs::ALL;
            }
        }
        let fixity = reduction.fixity(state, fixity);
        // A particle held in a local frame has its DOFs, and K's rows and columns, in that
        // frame (`crate::step::frames`); the lumped mass is the same in any frame.
        let dofs = FreeDofs::new(&fixity).in_frames(state.frames.clone());
        let tangent = dofs.local_tangent(&tangent).into_owned();
        let limp = tangent.stiffness_entries().is_empty() && state.rigid.is_empty();
        if dofs.len() == 0 || limp {
            return Err(ModalError::NothingDeformable);
        }
        let node_mass = reduction.node_mass(state.node_mass());
        let global: Vec<usize> = (0..3 * fixity.len())
            .filter(|&d| dofs.index(d).is_some())
            .collect();
        let mass: Vec<f64> = global.iter().map(|&d| node_mass[d / 3]).collect();
        let mut problem = Problem {
            tangent,
            node_mass,
            dofs,
            mass,
            global,
            particles: n,
            reduction,
            directions: Vec::new(),
            ignored,
        };
        problem.directions = problem.unit_motions(state, None);
        Ok(problem)
    }

    /// What global DOF `d` moves.
    fn kind(&self, d: usize) -> Dof {
        let (node, axis) = (d / 3, d % 3);
        if node < self.particles {
            return Dof::Translation(node, axis);
        }
        match self.reduction.body_of_node(node) {
            Some(b) => Dof::Body(b, axis),
            None => Dof::Spin(node - self.particles, axis),
        }
    }

    /// The six unit rigid motions (translations along x, y, z, rotations about axes through
    /// the mass centre) over the system DOFs, of the particles `only` where given (else of
    /// all, the rigid bodies included).
    fn unit_motions(&self, state: &State, only: Option<&[bool]>) -> Vec<Vec<f64>> {
        let included = |p: usize| only.is_none_or(|o| o[p]);
        let (mut centre, mut total) = (Vec3::zeros(), 0.0);
        for (i, &d) in self.global.iter().enumerate() {
            if let Dof::Translation(p, _) = self.kind(d) {
                if included(p) {
                    centre += self.mass[i] * state.position[p];
                    total += self.mass[i];
                }
            }
        }
        let centre = centre / total.max(f64::MIN_POSITIVE);
        (0..6usize)
            .map(|k| {
                let omega = Vec3::ith(k.saturating_sub(3), 1.0);
                self.global
                    .iter()
                    .map(|&d| match self.kind(d) {
                        Dof::Translation(p, axis) if included(p) => {
                            let w = match k < 3 {
                                true => Vec3::ith(k, 1.0),
                                false => omega.cross(&(state.position[p] - centre)),
                            };
                            match self.dofs.frame(p) {
                                Some(r) => r.column(axis).dot(&w),
                                None => w[axis],
                            }
                        }
                        Dof::Spin(p, axis) if included(p) && k >= 3 => omega[axis],
                        Dof::Body(b, j) if only.is_none() && k >= 3 => {
                            self.reduction.psi(b, &omega)[j]
                        }
                        _ => 0.0,
                    })
                    .collect()
            })
            .collect()
    }

    /// The six global DOFs of rigid body `b`: its centre's translations, then its scaled
    /// principal rotations.
    fn body_dofs(state: &State, b: usize) -> [usize; 6] {
        let (c, node) = (state.rigid.center[b], state.body_rotation_node(b));
        std::array::from_fn(|j| if j < 3 { 3 * c + j } else { 3 * node + j - 3 })
    }

    /// The M-orthonormal rigid-body modes of the bodies with no fixity; refuses a body fixed
    /// in some directions but free to move rigidly.
    fn rigid_basis(
        &self,
        state: &State,
        models: &[Box<dyn Model>],
    ) -> Result<Vec<Vec<f64>>, ModalError> {
        let mut basis: Vec<Vec<f64>> = Vec::new();
        for (body, modes) in unconstrained_bodies(state, models, &self.tangent, &self.dofs) {
            let model = models.iter().find(|m| m.name() == body);
            let particles = model
                .and_then(|m| m.modal_stiffness())
                .map_or_else(Vec::new, |l| l.particles());
            let fixed = particles
                .iter()
                .any(|&p| (0..3).any(|a| self.dofs.index(3 * p + a).is_none()));
            if fixed || modes < 6 {
                // The rigid motions the fixity leaves free: zero-frequency modes as well.
                let free = partly_fixed::free_rigid_motions(
                    &state.position,
                    &particles,
                    &|d| self.dofs.index(d),
                    &|p| self.dofs.frame(p).copied(),
                    &self.global,
                );
                if free.len() != modes {
                    return Err(ModalError::PartlyConstrained { body, modes });
                }
                for mut r in free {
                    self.orthogonalize(&mut r, &basis, &[]);
                    let norm = self.norm(&r);
                    r.iter_mut().for_each(|x| *x /= norm);
                    basis.push(r);
                }
                continue;
            }
            let mut only = vec![false; self.particles];
            for p in particles {
                only[p] = true;
            }
            for mut r in self.unit_motions(state, Some(&only)) {
                self.orthogonalize(&mut r, &basis, &[]);
                let norm = self.norm(&r);
                if norm > 0.0 {
                    r.iter_mut().for_each(|x| *x /= norm);
                    basis.push(r);
                }
            }
        }
        self.free_rigid_bodies(state, &mut basis)?;
        Ok(basis)
    }

    /// Appends to `basis` the six unit DOFs, M-normalised, of every rigid body that nothing
    /// touches and nothing fixes; refuses one that nothing touches but something fixes in
    /// part.
    fn free_rigid_bodies(
        &self,
        state: &State,
        basis: &mut Vec<Vec<f64>>,
    ) -> Result<(), ModalError> {
        if state.rigid.is_empty() {
            return Ok(());
        }
        let mut touched = vec![false; self.dofs.len()];
        for e in self.tangent.stiffness_entries() {
            for d in [e.row, e.col] {
                if let Some(i) = self.dofs.index(d).filter(|_| e.val != 0.0) {
                    touched[i] = true;
                }
            }
        }
        for b in 0..state.rigid.len() {
            let free: Vec<usize> = Problem::body_dofs(state, b)
                .iter()
                .filter_map(|&d| self.dofs.index(d))
                .collect();
            if free.is_empty() || free.iter().any(|&i| touched[i]) {
                continue;
            }
            if free.len() < 6 {
                return Err(ModalError::PartlyConstrainedRigid {
                    body: b,
                    modes: free.len(),
                });
            }
            for i in free {
                let mut r = vec![0.0; self.dofs.len()];
                r[i] = 1.0 / self.mass[i].sqrt();
                basis.push(r);
            }
        }
        Ok(())
    }

    /// Appends to `basis` the M-orthonormalised motions of single pieces that nothing resists
    /// (`mechanisms.rs`), so that Lanczos iterates without them; returns how many.
    fn add_mechanisms(
        &self,
        state: &State,
        models: &[Box<dyn Model>],
        basis: &mut Vec<Vec<f64>>,
    ) -> usize {
        let (piece, pieces) = tet_pieces(state.len(), models);
        let index = |d: usize| self.dofs.index(d);
        let dofs = SystemDofs {
            index: &index,
            mass: &self.mass,
            global: &self.global,
        };
        let mut rows = tet_piece_rows(&state.position, &piece, pieces, &dofs);
        for b in 0..state.rigid.len() {
            let body: Option<Vec<usize>> = Problem::body_dofs(state, b)
                .iter()
                .map(|&d| self.dofs.index(d))
                .collect();
            for (j, i) in body.into_iter().flatten().enumerate() {
                rows[i] = Some((pieces + b, self.body_row(b, j)));
            }
        }
        let stiffness = self.tangent.stiffness_entries();
        let before = basis.len();
        let all = pieces + state.rigid.len();
        for mut x in unresisted_motions(&rows, all, &dofs, stiffness) {
            let scale = self.norm(&x);
            self.orthogonalize(&mut x, basis, &[]);
            let norm = self.norm(&x);
            if norm > 1e-6 * scale {
                x.iter_mut().for_each(|v| *v /= norm);
                basis.push(x);
            }
        }
        basis.len() - before
    }

    /// The row of rigid body `b`'s DOF `j` (of [`Problem::body_dofs`]) in its six rigid
    /// motions (translations, then rotations about world axes through its centre).
    fn body_row(&self, b: usize, j: usize) -> Vector6<f64> {
        let mut row = Vector6::zeros();
        if j < 3 {
            row[j] = 1.0;
        } else {
            for axis in 0..3 {
                row[3 + axis] = self.reduction.psi(b, &Vec3::ith(axis, 1.0))[j - 3];
            }
        }
        row
    }

    /// ⟨x, y⟩_M.
    fn inner(&self, x: &[f64], y: &[f64]) -> f64 {
        x.iter()
            .zip(y)
            .zip(&self.mass)
            .map(|((a, b), m)| a * m * b)
            .sum()
    }

    fn norm(&self, x: &[f64]) -> f64 {
        self.inner(x, x).sqrt()
    }

    /// Removes from `x` its M-components along the M-orthonormal vectors of `fixed` and
    /// `basis` together (classical Gram–Schmidt, twice), returning the coefficients removed
    /// along `basis`.
    fn orthogonalize(&self, x: &mut [f64], fixed: &[Vec<f64>], basis: &[Vec<f64>]) -> Vec<f64> {
        let mut total = vec![0.0; basis.len()];
        for _ in 0..2 {
            let h: Vec<f64> = fixed
                .iter()
                .chain(basis)
                .map(|q| self.inner(q, x))
                .collect();
            for (q, c) in fixed.iter().chain(basis).zip(&h) {
                x.iter_mut().zip(q).for_each(|(a, b)| *a -= c * b);
            }
            for (t, c) in total.iter_mut().zip(&h[fixed.len()..]) {
                *t += c;
            }
        }
        total
    }

    /// xᵀKx / xᵀMx.
    fn rayleigh(&self, x: &[f64]) -> f64 {
        let system = |dof: usize| self.dofs.index(dof).map(|i| x[i]);
        let mut quadratic = 0.0;
        for e in self.tangent.stiffness_entries() {
            if let (Some(a), Some(b)) = (system(e.row), system(e.col)) {
                let twice = if e.row == e.col { 1.0 } else { 2.0 };
                quadratic += twice * a * e.val * b;
            }
        }
        quadratic / self.inner(x, x)
    }

    /// A [`Mode`] of eigenvalue `lambda` and shape `x` over the system DOFs.
    fn mode(&self, state: &State, lambda: f64, mut x: Vec<f64>, rigid: bool) -> Mode {
        let norm = self.norm(&x);
        x.iter_mut().for_each(|v| *v /= norm);
        let mut participation = [0.0; 6];
        for (p, r) in participation.iter_mut().zip(&self.directions) {
            let total = self.inner(r, r);
            *p = if total > 0.0 {
                self.inner(&x, r).powi(2) / total
            } else {
                0.0
            };
        }
        let mut motion = [0.0; 3];
        let mut shape = vec![Vec3::zeros(); self.particles];
        let mut psi = vec![Vec3::zeros(); state.rigid.len()];
        for ((&d, v), m) in self.global.iter().zip(&x).zip(&self.mass) {
            match self.kind(d) {
                Dof::Translation(p, axis) => {
                    if self.dofs.frame(p).is_none() {
                        motion[axis] += m * v * v;
                    }
                    shape[p][axis] = *v;
                }
                Dof::Body(b, k) => psi[b][k] = *v,
                Dof::Spin(..) => {}
            }
        }
        for (p, r, _) in state.frames.iter() {
            shape[p] = r * shape[p];
            for (axis, total) in motion.iter_mut().enumerate() {
                *total += self.node_mass[p] * shape[p][axis] * shape[p][axis];
            }
        }
        let theta: Vec<Vec3> = psi
            .iter()
            .enumerate()
            .map(|(b, p)| self.reduction.rotation(b, p))
            .collect();
        for (b, t) in theta.iter().enumerate() {
            let energy = self.reduction.rotation_energy(b, t);
            motion.iter_mut().zip(energy).for_each(|(e, r)| *e += r);
        }
        self.reduction.place_members(state, &theta, &mut shape);
        let total: f64 = motion.iter().sum();
        motion
            .iter_mut()
            .for_each(|e| *e /= total.max(f64::MIN_POSITIVE));
        Mode {
            eigenvalue: lambda,
            frequency_hz: lambda.max(0.0).sqrt() / (2.0 * PI),
            rigid,
            shape,
            participation,
            motion,
        }
    }
}

/// The factorised K − σM and its solve.
struct ShiftInvert {
    cholesky: SparseCholesky,
    shift: f64,
    rhs: Vec<f64>,
}

impl ShiftInvert {
    fn new(problem: &Problem) -> Result<ShiftInvert, ModalError> {
        let shift = -(2.0 * PI * SHIFT_HZ).powi(2);
        let scales = Scales {
            mass: -shift,
            damping: 0.0,
            stiffness: 1.0,
        };
        let mut assembler = Assembler::new();
        let matrix =
            assembler.assemble(&problem.tangent, &problem.node_mass, &problem.dofs, scales)?;
        let mut cholesky = SparseCholesky::default();
        cholesky.factorize(matrix, "shifted stiffness")?;
        Ok(ShiftInvert {
            cholesky,
            shift,
            rhs: Vec::new(),
        })
    }

    /// w = (K − σM)⁻¹ M q.
    fn apply(&mut self, mass: &[f64], q: &[f64]) -> Vec<f64> {
        self.rhs.clear();
        self.rhs.extend(q.iter().zip(mass).map(|(x, m)| x * m));
        self.cholesky.solve_in_place(&mut self.rhs);
        self.rhs.clone()
    }
}

/// Adds the tangent of every model with a linearisation to `tangent`; returns the names of
/// the models without one (they add no stiffness).
fn collect_stiffness(
    state: &State,
    models: &[Box<dyn Model>],
    tangent: &mut Tangent,
) -> Vec<String> {
    let mut ignored = Vec::new();
    for model in models {
        match model.modal_stiffness() {
            Some(linear) => linear.add_tangent(state, tangent),
            None => ignored.push(model.name().to_string()),
        }
    }
    ignored
}

/// The connected pieces of the deformable bodies' tetrahedra (union-find over their
/// corners): each particle's piece (`None` outside every body) and the number of pieces.
fn tet_pieces(particles: usize, models: &[Box<dyn Model>]) -> (Vec<Option<u32>>, usize) {
    let mut parent: Vec<usize> = (0..particles).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut in_body = vec![false; particles];
    for model in models {
        let Some(body) = model.deformable() else {
            continue;
        };
        for tet in body.tets() {
            let first = root(&mut parent, tet[0] as usize);
            in_body[tet[0] as usize] = true;
            for &n in &tet[1..] {
                let r = root(&mut parent, n as usize);
                parent[r] = first;
                in_body[n as usize] = true;
            }
        }
    }
    let mut id = vec![u32::MAX; particles];
    let mut pieces = 0;
    let piece = (0..particles)
        .map(|p| {
            if !in_body[p] {
                return None;
            }
            let r = root(&mut parent, p);
            if id[r] == u32::MAX {
                id[r] = pieces;
                pieces += 1;
            }
            Some(id[r])
        })
        .collect();
    (piece, pieces as usize)
}

/// A Ritz value θ and its vector.
type RitzPair = (f64, Vec<f64>);

/// A deterministic start vector (a fixed xorshift sequence in (−1, 1)).
fn start_vector(n: usize) -> Vec<f64> {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        })
        .collect()
}

/// The `wanted` largest eigenpairs (θ, x) of (K − σM)⁻¹M in the M-orthogonal complement of
/// `rigid`, and the Lanczos steps taken.
fn lanczos(
    problem: &Problem,
    solver: &mut ShiftInvert,
    rigid: &[Vec<f64>],
    wanted: usize,
) -> Result<(Vec<RitzPair>, usize), ModalError> {
    let space = problem.dofs.len() - rigid.len();
    let max_steps = space.min(10 * wanted + 60);
    let mut q = start_vector(problem.dofs.len());
    problem.orthogonalize(&mut q, rigid, &[]);
    let norm = problem.norm(&q);
    q.iter_mut().for_each(|x| *x /= norm);
    let mut basis = vec![q];
    // Column j: the coefficients of A⁻¹M q_j along q_0..q_j (both Gram–Schmidt passes).
    let mut columns: Vec<Vec<f64>> = Vec::new();
    let mut restarts = 1usize;
    loop {
        let j = basis.len() - 1;
        let mut w = solver.apply(&problem.mass, &basis[j]);
        let h = problem.orthogonalize(&mut w, rigid, &basis);
        let scale = h[j].abs();
        columns.push(h);
        let b = problem.norm(&w);
        let steps = basis.len();
        let (converged, ritz) = ritz_pairs(&columns, b, wanted);
        // The whole space spanned: the Ritz pairs are the eigenpairs.
        let complete = steps == space && steps >= wanted;
        if converged >= wanted || complete {
            let pairs = ritz
                .into_iter()
                .take(wanted)
                .map(|(theta, y)| (theta, combine(&basis, &y)))
                .collect();
            return Ok((pairs, steps));
        }
        if steps == max_steps {
            return Err(ModalError::NotConverged {
                converged,
                wanted,
                steps,
            });
        }
        if b <= 1e-10 * scale {
            // An invariant subspace: continue from a fresh vector orthogonal to it.
            w = start_vector(problem.dofs.len() + restarts).split_off(restarts);
            restarts += 1;
            problem.orthogonalize(&mut w, rigid, &basis);
        }
        let b = problem.norm(&w);
        w.iter_mut().for_each(|x| *x /= b);
        basis.push(w);
    }
}

/// The Ritz values of the projected operator H = QᵀM(K − σM)⁻¹MQ (its columns as
/// [`lanczos`] kept them; tridiagonal to rounding) by
/// decreasing θ with their eigenvectors, and how many of the first `wanted` have converged
/// given the norm `next` of the next Lanczos vector before normalisation: the residual of a
/// Ritz pair (θ, Qy) is `next`·|y_m|.
fn ritz_pairs(columns: &[Vec<f64>], next: f64, wanted: usize) -> (usize, Vec<RitzPair>) {
    let m = columns.len();
    // H[r][c] for r ≤ c is ⟨q_r, A⁻¹M q_c⟩_M; the operator is M-self-adjoint, so the
    // upper triangle, mirrored, is the projection (its subdiagonal, the norms that
    // normalised the vectors, equals the first superdiagonal to rounding).
    let t = DMatrix::from_fn(m, m, |r, c| columns[r.max(c)][r.min(c)]);
    let eigen = SymmetricEigen::new(t);
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
    let pairs: Vec<RitzPair> = order
        .iter()
        .map(|&k| {
            let y = eigen.eigenvectors.column(k).iter().copied().collect();
            (eigen.eigenvalues[k], y)
        })
        .collect();
    let converged = pairs
        .iter()
        .take(wanted)
        .take_while(|(theta, y)| (next * y[m - 1]).abs() <= TOLERANCE * theta.abs())
        .count();
    (converged, pairs)
}

/// Q y.
fn combine(basis: &[Vec<f64>], y: &[f64]) -> Vec<f64> {
    let mut x = vec![0.0; basis[0].len()];
    for (q, c) in basis.iter().zip(y) {
        x.iter_mut().zip(q).for_each(|(a, b)| *a += c * b);
    }
    x
}
