//! The unbonded contact of beam-bonded DEM between two discs that touch (paper 001 Eqs. 5, 6
//! and 21), in 2D.
//!
//! With n the unit vector from disc i to disc j, t = e_z × n, the overlap δ = ℓ − |x_j − x_i|
//! (ℓ the rest distance: r_i + r_j, or the length of the bond the pair had before it broke)
//! and the tangential displacement of the contact point s = (u_j − u_i)·t − r_i θ_i − r_j θ_j:
//!
//! - normal: F_n = k_n δ + c_n (v_i − v_j)·n, never tensile, with k_n = AE/l the axial
//!   stiffness of the bond of that pair (Eq. 5: "models that keep the compressive strength for
//!   bound and unbound contacts identical");
//! - tangential: an elastic spring k_t0 on the elastic part e of s, capped by Coulomb's
//!   |F_t| ≤ μ F_n; past the cap the contact slides and e is reset to the cap. Eq. 5's
//!   displacement-dependent k_t(u) is this cap written as a stiffness (k_t0 + k_t(u) is the
//!   secant μF_n/|e| while sliding), evaluated with the rest of the force at the state the
//!   force is asked at; the matrix keeps k_t0 (see [`crate::bonded::bonded_particles`]);
//! - damping c = 2ξ√(k m_r) on the relative normal and tangential velocities (Eq. 6, as
//!   relative dashpots like the bond's).
//!
//! The contact point is at r_i along n from disc i, so the tangential force F_t (acting as
//! −F_t t on j, +F_t t on i) gives both discs the moment r F_t.

/// Stiffness, damping and friction of unbonded contacts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnbondedLaw {
    /// Tangential over normal stiffness, k_t0/k_n.
    pub shear_ratio: f64,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
    /// Damping ratio ξ_u.
    pub damping_ratio: f64,
}

/// A pair of discs that may touch, with its committed tangential history.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnbondedPair {
    /// First disc.
    pub i: u32,
    /// Second disc.
    pub j: u32,
    /// Distance below which they touch (m).
    pub rest: f64,
    /// Normal stiffness k_n (N/m).
    pub normal_stiffness: f64,
    /// Reduced mass (kg).
    pub reduced_mass: f64,
    /// Whether they touched at the last committed step.
    pub touching: bool,
    /// Elastic tangential displacement e at the last committed step (m).
    pub elastic: f64,
    /// Tangential displacement s at the last committed step (m).
    pub slip_reference: f64,
    /// Overlap δ at the last committed step (m).
    pub overlap: f64,
}

/// Positions, displacements and velocities of the two discs, and their radii.
#[derive(Clone, Copy, Debug)]
pub struct PairKinematics {
    /// Current centres.
    pub x: [[f64; 2]; 2],
    /// Displacements (x, y, θ).
    pub u: [[f64; 3]; 2],
    /// Velocities (x, y, θ̇).
    pub v: [[f64; 3]; 2],
    /// Radii.
    pub r: [f64; 2],
}

/// The contact frame and measures of a pair.
#[derive(Clone, Copy, Debug)]
pub struct PairFrame {
    /// Unit vector from i to j.
    pub n: [f64; 2],
    /// e_z × n.
    pub t: [f64; 2],
    /// Overlap δ (m), positive when touching.
    pub overlap: f64,
    /// Tangential displacement s (m).
    pub slip: f64,
}

/// The vector from centre `xi` to centre `xj` and its length.
#[inline]
fn separation(xi: [f64; 2], xj: [f64; 2]) -> ([f64; 2], f64) {
    let d = [xj[0] - xi[0], xj[1] - xi[1]];
    (d, d[0].hypot(d[1]))
}

/// The overlap δ = ℓ − |x_j − x_i| of discs centred at `xi` and `xj` for rest distance `rest`
/// (positive when touching): [`PairFrame::overlap`] from the centres alone, for the passes
/// that only ask whether pairs touch.
#[inline]
pub fn overlap(xi: [f64; 2], xj: [f64; 2], rest: f64) -> f64 {
    rest - separation(xi, xj).1
}

impl PairKinematics {
    /// Frame, overlap and tangential displacement for rest distance `rest`.
    pub fn frame(&self, rest: f64) -> PairFrame {
        let (d, dist) = separation(self.x[0], self.x[1]);
        let n = [d[0] / dist, d[1] / dist];
        let t = [-n[1], n[0]];
        let du = [self.u[1][0] - self.u[0][0], self.u[1][1] - self.u[0][1]];
        let slip =
            du[0] * t[0] + du[1] * t[1] - self.r[0] * self.u[0][2] - self.r[1] * self.u[1][2];
        PairFrame {
            n,
            t,
            overlap: rest - dist,
            slip,
        }
    }
}

/// Forces (x, y, moment) on disc i and disc j, and the new elastic tangential displacement.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairForces {
    /// On i, then on j.
    pub force: [[f64; 3]; 2],
    /// Elastic tangential displacement after the Coulomb cap.
    pub elastic: f64,
    /// Whether the tangential force is at the Coulomb cap.
    pub sliding: bool,
}

impl UnbondedLaw {
    /// The forces of `pair` at `k` (zero when the discs do not touch).
    pub fn forces(&self, pair: &UnbondedPair, k: &PairKinematics) -> PairForces {
        self.forces_in(pair, k, &k.frame(pair.rest))
    }

    /// [`UnbondedLaw::forces`] with the pair's frame `f` at `k` already computed.
    pub fn forces_in(&self, pair: &UnbondedPair, k: &PairKinematics, f: &PairFrame) -> PairForces {
        if f.overlap <= 0.0 {
            return PairForces::default();
        }
        let (kn, m) = (pair.normal_stiffness, pair.reduced_mass);
        let kt = self.shear_ratio * kn;
        let dv = [k.v[1][0] - k.v[0][0], k.v[1][1] - k.v[0][1]];
        let vn = dv[0] * f.n[0] + dv[1] * f.n[1];
        let vt = dv[0] * f.t[0] + dv[1] * f.t[1] - k.r[0] * k.v[0][2] - k.r[1] * k.v[1][2];
        let cn = 2.0 * self.damping_ratio * (kn * m).sqrt();
        let ct = 2.0 * self.damping_ratio * (kt * m).sqrt();
        let normal = (kn * f.overlap - cn * vn).max(0.0);
        let base = if pair.touching { pair.elastic } else { 0.0 };
        let reference = if pair.touching {
            pair.slip_reference
        } else {
            f.slip
        };
        let mut elastic = base + (f.slip - reference);
        let cap = self.friction * normal;
        let sliding = (kt * elastic).abs() > cap;
        if sliding {
            elastic = cap / kt * elastic.signum();
        }
        let tangential = kt * elastic + ct * vt;
        let tangential = tangential.clamp(-cap, cap);
        let fj = [
            normal * f.n[0] - tangential * f.t[0],
            normal * f.n[1] - tangential * f.t[1],
        ];
        PairForces {
            force: [
                [-fj[0], -fj[1], k.r[0] * tangential],
                [fj[0], fj[1], k.r[1] * tangential],
            ],
            elastic,
            sliding,
        }
    }

    /// The 6×6 stiffness (or, with `damping`, damping) of a touching pair in global
    /// coordinates over (x_i, y_i, θ_i, x_j, y_j, θ_j): normal k_n n nᵀ on the relative
    /// displacement, tangential k_t0 g gᵀ with g the gradient of s (the sticking stiffness; see
    /// [`crate::bonded::bonded_particles`] for why a sliding contact keeps it in the matrix).
    pub fn matrix(
        &self,
        pair: &UnbondedPair,
        frame: &PairFrame,
        r: [f64; 2],
        damping: bool,
    ) -> [[f64; 6]; 6] {
        let kn = pair.normal_stiffness;
        let kt = self.shear_ratio * kn;
        let (normal, tangential) = if damping {
            let m = pair.reduced_mass;
            let z = 2.0 * self.damping_ratio;
            (z * (kn * m).sqrt(), z * (kt * m).sqrt())
        } else {
            (kn, kt)
        };
        let (n, t) = (frame.n, frame.t);
        let gn = [-n[0], -n[1], 0.0, n[0], n[1], 0.0];
        let gt = [-t[0], -t[1], -r[0], t[0], t[1], -r[1]];
        let mut a = [[0.0; 6]; 6];
        for (row, out) in a.iter_mut().enumerate() {
            for (col, value) in out.iter_mut().enumerate() {
                *value = normal * gn[row] * gn[col] + tangential * gt[row] * gt[col];
            }
        }
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair() -> UnbondedPair {
        UnbondedPair {
            i: 0,
            j: 1,
            rest: 0.02,
            normal_stiffness: 1e8,
            reduced_mass: 0.5,
            touching: true,
            elastic: 0.0,
            slip_reference: 0.0,
            overlap: 0.0,
        }
    }

    fn law() -> UnbondedLaw {
        UnbondedLaw {
            shear_ratio: 0.2,
            friction: 0.5,
            damping_ratio: 0.0,
        }
    }

    fn kinematics(gap: f64, slide: f64) -> PairKinematics {
        PairKinematics {
            x: [[0.0, 0.0], [0.02 + gap, slide]],
            u: [[0.0; 3], [gap, slide, 0.0]],
            v: [[0.0; 3]; 2],
            r: [0.01, 0.01],
        }
    }

    #[test]
    fn open_pairs_carry_nothing_and_touching_pairs_push_apart() {
        assert_eq!(
            law().forces(&pair(), &kinematics(1e-6, 0.0)).force,
            [[0.0; 3]; 2]
        );
        let f = law().forces(&pair(), &kinematics(-1e-6, 0.0));
        assert!((f.force[1][0] - 100.0).abs() < 1e-9 && (f.force[0][0] + 100.0).abs() < 1e-9);
    }

    #[test]
    fn tangential_force_sticks_then_slides_at_the_coulomb_cap() {
        let stick = law().forces(&pair(), &kinematics(-1e-6, 1e-7));
        // δ = 1e-6 (to first order), F_n = 100 N, cap 50 N; k_t s = 2e7 · 1e-7 = 2 N.
        assert!((stick.force[1][1] + 2.0).abs() < 0.01, "{:?}", stick.force);
        assert!(!stick.sliding);
        let k = kinematics(-1e-6, 1e-5);
        let slide = law().forces(&pair(), &k);
        assert!(slide.sliding);
        let f = k.frame(0.02);
        let fj = slide.force[1];
        let ft = -(fj[0] * f.t[0] + fj[1] * f.t[1]);
        let fnormal = fj[0] * f.n[0] + fj[1] * f.n[1];
        assert!(
            (ft - 0.5 * fnormal).abs() < 1e-9 * fnormal,
            "{ft} {fnormal}"
        );
        // Moments r F_t on both discs.
        assert!((slide.force[0][2] - 0.01 * ft).abs() < 1e-12 * ft);
    }

    #[test]
    #[allow(clippy::needless_range_loop)]
    fn matrix_is_the_derivative_of_the_sticking_force() {
        let (p, l) = (pair(), law());
        let k0 = kinematics(-1e-6, 1e-8);
        let frame = k0.frame(p.rest);
        let m = l.matrix(&p, &frame, k0.r, false);
        let f0 = l.forces(&p, &k0);
        for col in 0..6 {
            let mut k = k0;
            let h = 1e-10;
            let (end, c) = (col / 3, col % 3);
            k.u[end][c] += h;
            if c < 2 {
                k.x[end][c] += h;
            }
            let f = l.forces(&p, &k);
            for row in 0..6 {
                let df = -(f.force[row / 3][row % 3] - f0.force[row / 3][row % 3]) / h;
                assert!(
                    (df - m[row][col]).abs() < 1e-3 * 1e8,
                    "({row},{col}) {df} {}",
                    m[row][col]
                );
            }
        }
    }
}
