//! Rigid bodies held at points: a `[[fix]]` on some members of a rigid body holds the body at
//! those members, in the directions it names, and leaves it free otherwise (a bar held at one
//! end swings as a pendulum; held at two points, it turns about their line).
//!
//! Each held member i and held direction e (a world axis) is one linear constraint on the
//! body's generalised velocity q̇ = (v, Ω), v the centre's velocity and Ω the angular velocity
//! in the body's principal frame (ω = R Ω, r_i = R s_i the member's arm):
//!
//! ```text
//!   J_k q̇ = e·(v + ω × r_i) = eᵀ v + (s_i × Rᵀe)ᵀ Ω = 0.                              (1)
//! ```
//!
//! The body's kinetic energy is ½ q̇ᵀ M q̇ with M = diag(m, m, m, I₁, I₂, I₃) (its principal
//! moments). In y = M^½ q̇ the constraints read A y = 0 with A = J M^-½, and G = AᵀA is a 6×6
//! matrix whatever the number of constraints: its eigenvectors u_j with an eigenvalue above
//! [`RANK_TOLERANCE`] of the largest span A's rows. That is the rank-revealing solve, so
//! redundant constraints (many members held in y, one member held by two fixes) are fine.
//!
//! - **Velocity** (after each kick and drift): the projection in the mass metric,
//!   q̇ ← q̇ − M⁻¹Jᵀ(JM⁻¹Jᵀ)⁺J q̇, which is y ← y − Σ_j u_j u_jᵀ y.                  (2)
//! - **Acceleration** (after the forces): forces μ_k e at the held points make the points'
//!   accelerations along e vanish, J q̈ = −e·(ω × (ω × r)). With ρ_k = e·(a + α × r +
//!   ω × (ω × r)) the held point's acceleration under the other forces alone (a = f/m, α the
//!   solution of Euler's equations I_w α = τ − ω × L),
//!   μ = −(AAᵀ)⁺ ρ = −A G⁺² Aᵀ ρ,                                                       (3)
//!   the least-norm forces: a load shared by alike constraints is shared equally. The body gets
//!   F = Σ μ_k e_k and τ = Σ μ_k r_k × e_k; the constrained acceleration is then that of
//!   its first half kick in the next step, as Verlet's is.
//! - **Position** (after each drift): the held points go back to where they were held, their
//!   anchors e·x⁰, by the least-norm pose correction δy = G⁺ Aᵀ d with d_k = e·(x⁰ − x_k),
//!   applied [`POSE_PASSES`] times (each pass takes the last one's residual), so that they
//!   stay at their anchors to round-off over any number of steps.                      (4)
//!
//! This is RATTLE (Andersen 1983) for the linear point constraints of a rigid body, with (4)
//! in place of its iterated position solve.
//!
//! Singular poses: where the held points allow a motion at first order that they forbid at
//! second order, (2) lets it start and (4) stops it, the points then off their anchors by
//! the square of the motion's first step. A face's nodes held along the face (a sleeper's
//! rail seats held in y) are such a pose: the face may roll about a line in it at first
//! order (qdem-io's `rigid_holds.rs` measured 2·10⁻⁹ m for a cube thrown across its held
//! face at 0.5 m/s with ∆t = 2·10⁻⁴ s). A body whose holds leave it no motion (rank 6)
//! is held whole instead, its centre fixed and its rotation held as before; (3) then gives
//! only the reactions. The reactions μ_k e_k go into the stepper's force buffer at each held
//! member as −μ_k e_k, the sign of a fixed node's force, so that `reactions.csv` sums a rigid
//! body's fixes as it sums a deformable body's.

use crate::step::state::{Dofs, State};
use crate::Vec3;
use nalgebra::{Matrix6, SymmetricEigen, UnitQuaternion, Vector6};

/// Eigenvalues of G below this fraction of the largest one count as zero: the directions
/// the constraints do not hold (or hold only redundantly).
pub const RANK_TOLERANCE: f64 = 1e-10;

/// Passes of the position correction (4) per step.
pub const POSE_PASSES: usize = 2;

/// A member held in some directions by a fix: what [`State::hold_members`] takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemberHold {
    /// The member particle.
    pub particle: usize,
    /// The held directions (world axes).
    pub dofs: Dofs,
    /// The fix's number (from 1), which its reactions and refusals name.
    pub fix: usize,
}

/// The point constraints of every rigid body held at points, grouped by body.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointHolds {
    /// The bodies held, increasing.
    body: Vec<usize>,
    /// Body `body[j]`'s constraints are `start[j]..start[j + 1]`.
    start: Vec<usize>,
    /// Per constraint: the member particle.
    member: Vec<usize>,
    /// Per constraint: the member's slot ([`crate::step::RigidBodies`]' offsets).
    slot: Vec<usize>,
    /// Per constraint: the held direction e (a world axis).
    direction: Vec<Vec3>,
    /// Per constraint: e·x⁰, where the member was held.
    anchor: Vec<f64>,
    /// Per constraint: the fix's number.
    fix: Vec<usize>,
}

impl PointHolds {
    /// Whether no body is held at points.
    pub fn is_empty(&self) -> bool {
        self.body.is_empty()
    }

    /// Whether fix number `fix` holds a rigid body at points.
    pub fn holds_fix(&self, fix: usize) -> bool {
        self.fix.contains(&fix)
    }

    /// The bodies held at points, increasing, each with the first fix that holds it.
    pub fn bodies(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.body
            .iter()
            .zip(&self.start)
            .map(|(&b, &k)| (b, self.fix[k]))
    }

    /// The constraints of the `j`-th held body.
    fn of(&self, j: usize) -> std::ops::Range<usize> {
        self.start[j]..self.start[j + 1]
    }
}

/// Body `b`'s mass metric at its current pose and its constraints' rows A = J M^-½.
struct Metric {
    /// √m.
    root_mass: f64,
    /// √I of the principal moments.
    root_inertia: Vec3,
    /// The body's orientation R.
    rotation: UnitQuaternion<f64>,
    /// A_k, one per constraint.
    rows: Vec<Vector6<f64>>,
    /// The eigenpairs (u_j, λ_j) of G = AᵀA that span A's rows.
    space: Vec<(Vector6<f64>, f64)>,
}

impl Metric {
    /// The metric of the `j`-th held body of `holds` in `state`.
    fn new(state: &State, holds: &PointHolds, j: usize) -> Metric {
        let b = holds.body[j];
        let rigid = &state.rigid;
        let rotation = rigid.orientation[b];
        let root_mass = state.mass[rigid.center[b]].sqrt();
        let root_inertia = rigid.inertia[b].map(f64::sqrt);
        let rows: Vec<Vector6<f64>> = holds
            .of(j)
            .map(|k| {
                let e = holds.direction[k];
                let lever = rigid
                    .offset(holds.slot[k])
                    .cross(&(rotation.inverse() * e))
                    .component_div(&root_inertia);
                let t = e / root_mass;
                Vector6::new(t.x, t.y, t.z, lever.x, lever.y, lever.z)
            })
            .collect();
        let gram = rows
            .iter()
            .fold(Matrix6::zeros(), |g, a| g + a * a.transpose());
        let eigen = SymmetricEigen::new(gram);
        let largest = eigen.eigenvalues.max();
        let space = (0..6)
            .filter(|&i| eigen.eigenvalues[i] > RANK_TOLERANCE * largest)
            .map(|i| {
                (
                    eigen.eigenvectors.column(i).into_owned(),
                    eigen.eigenvalues[i],
                )
            })
            .collect();
        Metric {
            root_mass,
            root_inertia,
            rotation,
            rows,
            space,
        }
    }

    /// How many independent directions the constraints hold (of 6).
    fn rank(&self) -> usize {
        self.space.len()
    }

    /// y = M^½ q̇ of the velocity `v` and the angular velocity `w` (world).
    fn scaled(&self, v: Vec3, w: Vec3) -> Vector6<f64> {
        let t = v * self.root_mass;
        let r = (self.rotation.inverse() * w).component_mul(&self.root_inertia);
        Vector6::new(t.x, t.y, t.z, r.x, r.y, r.z)
    }

    /// The velocity and angular velocity (world) of y = M^½ q̇.
    fn unscaled(&self, y: &Vector6<f64>) -> (Vec3, Vec3) {
        let v = y.fixed_rows::<3>(0) / self.root_mass;
        let body = y.fixed_rows::<3>(3).component_div(&self.root_inertia);
        (v, self.rotation * body)
    }

    /// y less its part in A's row space: (2).
    fn project(&self, y: &Vector6<f64>) -> Vector6<f64> {
        self.space.iter().fold(*y, |p, (u, _)| p - u * u.dot(y))
    }

    /// G⁺ z.
    fn pseudo_inverse(&self, z: &Vector6<f64>) -> Vector6<f64> {
        self.space
            .iter()
            .fold(Vector6::zeros(), |p, (u, l)| p + u * (u.dot(z) / l))
    }

    /// G⁺ Aᵀ d: the least-norm y with A y = d (in A's row space).
    fn least_norm(&self, d: &[f64]) -> Vector6<f64> {
        let at_d = self
            .rows
            .iter()
            .zip(d)
            .fold(Vector6::zeros(), |s, (a, &d)| s + a * d);
        self.pseudo_inverse(&at_d)
    }
}

impl State {
    /// Holds rigid bodies at some of their members ([`crate::step::rigid_constraints`]),
    /// replacing any earlier holds: each member of `holds` in its directions, at the place it
    /// has now. A particle that is no member of a rigid body is left alone. A body whose
    /// rotation is held already ([`crate::step::RigidBodies::spin_fixed`]) can only move
    /// along: its centre is fixed in every direction a member is held in, and no point
    /// constraint is kept. A body its holds leave no motion is held whole (its centre fixed,
    /// its rotation held), keeping the constraints for its reactions. The held bodies'
    /// velocities are projected onto their constraints.
    ///
    /// ```
    /// use qdem_core::{step::Dofs, step::MemberHold, step::State, Mat3, Vec3};
    ///
    /// // A bar of two members at ±1 m on x, held at the +x end in all directions: it may
    /// // turn about that end, so its centre stays free.
    /// let mut s = State::at_rest(vec![Vec3::zeros(), Vec3::x(), -Vec3::x()]);
    /// s.mass[0] = 2.0;
    /// s.add_rigid_body("bar", 0, &[1, 2], Mat3::from_diagonal(&Vec3::new(0.1, 2.0, 2.0)))?;
    /// s.velocity[0] = Vec3::new(0.0, 0.0, 1.0);
    /// s.hold_members(&[MemberHold { particle: 1, dofs: Dofs::ALL, fix: 1 }]);
    /// assert!(!s.rigid.spin_fixed[0] && s.fixed[0].is_empty());
    /// // The held end's velocity is zero: the centre moves as the body turns about it.
    /// let w = s.rigid.angular_velocity[0];
    /// assert!((s.velocity[0] + w.cross(&Vec3::x())).norm() < 1e-12);
    /// # Ok::<(), qdem_core::error::CoreError>(())
    /// ```
    pub fn hold_members(&mut self, holds: &[MemberHold]) {
        let mut per_body: Vec<(usize, usize, Vec3, usize)> = Vec::new();
        for h in holds {
            let Some(b) = self.rigid.body_of_member(h.particle) else {
                continue;
            };
            for axis in (0..3).filter(|&a| h.dofs.contains(a)) {
                per_body.push((b, h.particle, Vec3::ith(axis, 1.0), h.fix));
            }
        }
        per_body.sort_by_key(|&(b, ..)| b);
        let mut built = PointHolds::default();
        for (b, particle, e, fix) in per_body {
            if self.rigid.spin_fixed[b] {
                let axis = (0..3).find(|&a| e[a] != 0.0).expect("an axis");
                self.fix(self.rigid.center[b], dofs_of(axis));
                continue;
            }
            if built.body.last() != Some(&b) {
                built.body.push(b);
                built.start.push(built.member.len());
            }
            let slot = self.rigid.member_slot(particle).expect("a member");
            built.member.push(particle);
            built.slot.push(slot);
            built.direction.push(e);
            built.anchor.push(0.0);
            built.fix.push(fix);
        }
        built.start.push(built.member.len());
        self.rigid.holds = built;
        for j in 0..self.rigid.holds.body.len() {
            let metric = Metric::new(self, &self.rigid.holds, j);
            if metric.rank() == 6 {
                let b = self.rigid.holds.body[j];
                self.fix(self.rigid.center[b], Dofs::ALL);
                self.rigid.spin_fixed[b] = true;
                self.rigid.set_angular_velocity(b, Vec3::zeros());
            }
        }
        self.anchor_holds();
    }

    /// Holds the held members ([`State::hold_members`]) where their bodies' poses put them
    /// now, and projects the bodies' velocities onto their constraints: for a state whose
    /// motion was written from elsewhere (a checkpoint), as [`State::hold_fixed`] does.
    pub fn anchor_holds(&mut self) {
        let mut holds = std::mem::take(&mut self.rigid.holds);
        for j in 0..holds.body.len() {
            let b = holds.body[j];
            let (c, q) = (
                self.position[self.rigid.center[b]],
                self.rigid.orientation[b],
            );
            for k in holds.of(j) {
                let x = c + q * self.rigid.offset(holds.slot[k]);
                holds.anchor[k] = holds.direction[k].dot(&x);
            }
        }
        self.rigid.holds = holds;
        self.hold_velocities();
        self.place_held_members();
    }

    /// The moving held bodies (those not held whole), each as its place among the holds.
    fn moving_holds(&self) -> impl Iterator<Item = usize> + '_ {
        let holds = &self.rigid.holds;
        (0..holds.body.len()).filter(|&j| !self.rigid.spin_fixed[holds.body[j]])
    }

    /// The position correction (4): every moving held body's pose moved, least in its mass
    /// metric, so that its held members are back at their anchors; its angular velocity
    /// follows the new orientation (its angular momentum stands).
    pub(crate) fn hold_pose(&mut self) {
        let moving: Vec<usize> = self.moving_holds().collect();
        for j in moving {
            for _ in 0..POSE_PASSES {
                let metric = Metric::new(self, &self.rigid.holds, j);
                let holds = &self.rigid.holds;
                let b = holds.body[j];
                let c = self.rigid.center[b];
                let miss: Vec<f64> = holds
                    .of(j)
                    .map(|k| {
                        let x =
                            self.position[c] + metric.rotation * self.rigid.offset(holds.slot[k]);
                        holds.anchor[k] - holds.direction[k].dot(&x)
                    })
                    .collect();
                let (shift, turn) = metric.unscaled(&metric.least_norm(&miss));
                self.position[c] += shift;
                self.rigid.orientation[b] =
                    UnitQuaternion::from_scaled_axis(turn) * metric.rotation;
                let l = self.rigid.angular_momentum[b];
                self.rigid.set_angular_momentum(b, l);
            }
        }
    }

    /// The velocity projection (2) of every moving held body.
    pub(crate) fn hold_velocities(&mut self) {
        let moving: Vec<usize> = self.moving_holds().collect();
        for j in moving {
            let metric = Metric::new(self, &self.rigid.holds, j);
            let b = self.rigid.holds.body[j];
            let c = self.rigid.center[b];
            let y = metric.scaled(self.velocity[c], self.rigid.angular_velocity[b]);
            let (v, w) = metric.unscaled(&metric.project(&y));
            self.velocity[c] = v;
            self.rigid.set_angular_velocity(b, w);
        }
    }

    /// The constraint forces (3) of every held body, from the forces `force` (per particle)
    /// and the torques `torque` (per rigid body) of an evaluation: on a moving body they are
    /// added to its centre's acceleration (and, with `kick` = `Some(h)`, its velocity kicked
    /// by h times their part) and to its torque; at each held member the force buffer gets
    /// −Σ μ_k e_k, the reaction with a fixed node's sign.
    pub(crate) fn hold_forces(
        &mut self,
        force: &mut [Vec3],
        torque: &mut [Vec3],
        kick: Option<f64>,
    ) {
        for j in 0..self.rigid.holds.body.len() {
            let metric = Metric::new(self, &self.rigid.holds, j);
            let holds = &self.rigid.holds;
            let rigid = &self.rigid;
            let b = holds.body[j];
            let c = rigid.center[b];
            let mass = self.mass[c];
            let (w, l) = (rigid.angular_velocity[b], rigid.angular_momentum[b]);
            let a = force[c] / mass;
            let q = metric.rotation;
            let body_alpha =
                (q.inverse() * (torque[b] - w.cross(&l))).component_div(&rigid.inertia[b]);
            let alpha = q * body_alpha;
            let arm = |k: usize| q * rigid.offset(holds.slot[k]);
            let rho: Vec<f64> = holds
                .of(j)
                .map(|k| {
                    let r = arm(k);
                    holds.direction[k].dot(&(a + alpha.cross(&r) + w.cross(&w.cross(&r))))
                })
                .collect();
            let z = metric.pseudo_inverse(&metric.least_norm(&rho));
            let (mut total, mut moment) = (Vec3::zeros(), Vec3::zeros());
            for (n, k) in holds.of(j).enumerate() {
                let f = -metric.rows[n].dot(&z) * holds.direction[k];
                total += f;
                moment += arm(k).cross(&f);
                force[holds.member[k]] -= f;
            }
            if self.rigid.spin_fixed[b] {
                continue;
            }
            self.acceleration[c] += total / mass;
            if let Some(h) = kick {
                self.velocity[c] += h * total / mass;
            }
            torque[b] += moment;
        }
    }

    /// Places the members of the held bodies at their poses (after [`State::anchor_holds`]
    /// changed their velocities).
    fn place_held_members(&mut self) {
        let bodies = self.rigid.holds.body.clone();
        for b in bodies {
            crate::step::rigid_body::place_body_members(self, b);
        }
    }
}

/// The set of one axis.
fn dofs_of(axis: usize) -> Dofs {
    let mut mask = [false; 3];
    mask[axis] = true;
    Dofs::from_mask(mask)
}
