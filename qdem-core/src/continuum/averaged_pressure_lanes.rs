//! The two block passes of the averaged-pressure tetrahedron
//! ([`crate::continuum::averaged_pressure_tet`], Bonet & Burton 1998 Eqs. 9–11) across SIMD
//! lanes, 8 tetrahedra at once as the standard kernel's ([`crate::continuum::tet_lanes`]),
//! against a block's scratch copy of its nodes:
//!
//! - the **strain pass** sums (V_e/4) θ_e, θ_e = tr ε_e (Eq. 4), and, when viscous,
//!   (V_e/4) tr D_e (Eq. 6) into the block's node slots: the numerators of the particles'
//!   averages θ̄_a = Σ_{e∋a} (V_e/4) θ_e / V̄_a;
//! - the **force pass** computes each tetrahedron's stress from its own deviatoric strain and
//!   the mean of its corners' averages, T = κ θ̄_e I + 2μ dev ε_e (+ κ_D tr(D)‾_e I +
//!   2μ_D dev D_e), the deviatoric part as the Lamé law with λ = −⅔μ, and adds the forces of
//!   Eqs. 9–10 into the block's node sums.
//!
//! Both add their lanes' values into the node slots lane after lane, corner after corner (the
//! order of a scalar loop over the block's tetrahedra), and every instruction set runs the
//! same operations with the same fused multiply-adds, the scalar path included
//! ([`Scalar`]: one lane): the sums are the same bits on any CPU, for any thread or rank count.

use crate::continuum::tet_lanes::{
    cofactor, corner_offsets, dm_inv_lanes, edges, face_force, force_pass, gather, green_strain,
    lame, lane_force_sums, lane_set_fns, rate_of_deformation, LaneForces, LaneSet, Simd, TetPack,
    PACK, V3,
};
use crate::Vec3;

/// Floating-point operations of one elastic tet-step of the averaged-pressure tetrahedron, a
/// multiply-add counted as two: the standard kernel's
/// ([`crate::continuum::tet_lanes::FLOPS_ELASTIC`], the deviatoric law costing what the Lamé
/// law does), the strain pass (edges 9, F 45, tr ε 21, the weight 3, the slot sums 4) and the
/// corners' mean pressure (8).
pub const FLOPS_AVERAGED_ELASTIC: usize = crate::continuum::tet_lanes::FLOPS_ELASTIC + 90;
/// Floating-point operations of one viscoelastic tet-step of the averaged-pressure
/// tetrahedron: the standard viscoelastic kernel's, the elastic strain pass and pressure
/// (90), and the strain pass's rate (cofactor and volume 32, velocity edges 9, 1/det 1,
/// tr D 18, weight and slot sums 7) and its mean (6).
pub const FLOPS_AVERAGED_VISCOELASTIC: usize =
    crate::continuum::tet_lanes::FLOPS_VISCOELASTIC + 90 + 73;

/// What the strain pass reads: the block's node positions (and velocities, read only when
/// viscous), each pack's reference volumes / 4 by lane, and the number of real tetrahedra.
pub(crate) struct StrainInput<'a> {
    pub x: &'a [Vec3],
    pub v: &'a [Vec3],
    pub quarter: &'a [[f64; PACK]],
    pub count: usize,
}

/// What the force pass reads: the block's node positions and velocities, its nodes' averages
/// (θ̄, tr(D)‾, 0), the deviatoric Lamé pairs (−⅔μ, μ) and (−⅔μ_D, μ_D), the bulk modulus
/// and viscosity (κ, κ_D) and the number of real tetrahedra.
pub(crate) struct ForceInput<'a> {
    pub x: &'a [Vec3],
    pub v: &'a [Vec3],
    pub averages: &'a [Vec3],
    pub deviatoric: (f64, f64),
    pub viscous_deviatoric: (f64, f64),
    pub bulk: (f64, f64),
    pub count: usize,
}

/// Adds (V_e/4) θ_e (into x) and, when `VISCOUS`, (V_e/4) tr D_e (into y) of a block's
/// tetrahedra (`packs`) to the slots of their corners in `out`.
pub(crate) fn strain_sums<const VISCOUS: bool>(
    set: LaneSet,
    packs: &[TetPack],
    input: &StrainInput,
    out: &mut [Vec3],
) {
    assert_eq!(out.len(), input.x.len(), "a slot per node of the block");
    match set {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `LaneSet::detected` chooses a set only when the CPU has its features.
        LaneSet::Avx512 => unsafe { strain_avx512::<VISCOUS>(packs, input, out) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        LaneSet::Avx2 => unsafe { strain_avx2::<VISCOUS>(packs, input, out) },
        // SAFETY: the scalar lane needs no feature.
        _ => unsafe { strain_pass::<Scalar, VISCOUS>(packs, input, out) },
    }
}

/// Adds the forces of a block's tetrahedra (`packs`) into `out` (its node sums); returns the
/// block index of the first tetrahedron whose volume is not positive.
pub(crate) fn force_sums<const VISCOUS: bool>(
    set: LaneSet,
    packs: &[TetPack],
    input: &ForceInput,
    out: &mut [Vec3],
) -> Option<usize> {
    match lane_force_sums::<ForceInput, VISCOUS>(set, packs, input, out) {
        Some(first) => first,
        // SAFETY: the scalar lane needs no feature.
        None => unsafe { force_pass::<Scalar, ForceInput, VISCOUS>(packs, input, out) },
    }
}

lane_set_fns!(strain_avx512, strain_avx2 = strain_pass [const VISCOUS: bool] [VISCOUS]
    (packs: &[TetPack], input: &StrainInput, out: &mut [Vec3]) -> ());

/// One lane of plain f64, with the fused multiply-add of the vector sets, so that a CPU
/// without AVX2 computes the same bits.
pub(crate) struct Scalar;

impl Simd for Scalar {
    const N: usize = 1;
    type V = f64;
    type Idx = usize;
    #[inline(always)]
    unsafe fn splat(a: f64) -> f64 {
        a
    }
    #[inline(always)]
    unsafe fn load(a: &[f64]) -> f64 {
        a[0]
    }
    #[inline(always)]
    unsafe fn store(a: f64, to: &mut [f64]) {
        to[0] = a;
    }
    #[inline(always)]
    unsafe fn add(a: f64, b: f64) -> f64 {
        a + b
    }
    #[inline(always)]
    unsafe fn sub(a: f64, b: f64) -> f64 {
        a - b
    }
    #[inline(always)]
    unsafe fn mul(a: f64, b: f64) -> f64 {
        a * b
    }
    #[inline(always)]
    unsafe fn div(a: f64, b: f64) -> f64 {
        a / b
    }
    #[inline(always)]
    unsafe fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a.mul_add(b, c)
    }
    #[inline(always)]
    unsafe fn neg(a: f64) -> f64 {
        -a
    }
    #[inline(always)]
    unsafe fn offsets(local: &[u16]) -> usize {
        3 * local[0] as usize
    }
    #[inline(always)]
    unsafe fn gather(base: *const f64, idx: usize) -> f64 {
        *base.add(idx)
    }
}

/// The strain pass with `S::N` lanes per vector.
#[inline(always)]
unsafe fn strain_pass<S: Simd, const VISCOUS: bool>(
    packs: &[TetPack],
    input: &StrainInput,
    out: &mut [Vec3],
) {
    let (mut theta, mut rate) = ([0.0f64; PACK], [0.0f64; PACK]);
    for (p, pack) in packs.iter().enumerate() {
        for o in (0..PACK).step_by(S::N) {
            let base = p * PACK + o;
            if base >= input.count {
                break;
            }
            let corners = corner_offsets::<S>(pack, o);
            let dm = dm_inv_lanes::<S>(pack, o);
            let d = edges::<S>(&gather::<S>(input.x, &corners));
            let e = green_strain::<S>(&d, &dm);
            let quarter = S::load(&input.quarter[p][o..]);
            S::store(
                S::mul(quarter, S::add(S::add(e[0], e[1]), e[2])),
                &mut theta,
            );
            if VISCOUS {
                let (c, six_volume) = cofactor::<S>(&d);
                let dv = edges::<S>(&gather::<S>(input.v, &corners));
                let inv_det = S::div(S::splat(1.0), six_volume);
                let r = rate_of_deformation::<S>(&dv, &c, inv_det);
                S::store(S::mul(quarter, S::add(S::add(r[0], r[1]), r[2])), &mut rate);
            }
            for l in 0..S::N.min(input.count - base) {
                for local in &pack.local {
                    // SAFETY: `o + l < PACK`, and a corner indexes the block's nodes, which
                    // `out` holds as `input.x` does (checked in `strain_sums`; the gathers
                    // read `input.x` at the same indices).
                    let slot = out.get_unchecked_mut(*local.get_unchecked(o + l) as usize);
                    slot.x += theta[l];
                    if VISCOUS {
                        slot.y += rate[l];
                    }
                }
            }
        }
    }
}

/// ¼ (a₀ + a₁ + a₂ + a₃) of component `k` of the corners' `values`.
#[inline(always)]
unsafe fn corner_mean<S: Simd>(values: &[Vec3], corners: &[S::Idx; 4], k: usize) -> S::V {
    let base = values.as_ptr().cast::<f64>().add(k);
    let mut sum = S::gather(base, corners[0]);
    for &offsets in &corners[1..] {
        sum = S::add(sum, S::gather(base, offsets));
    }
    S::mul(S::splat(0.25), sum)
}

impl LaneForces for ForceInput<'_> {
    #[inline(always)]
    fn count(&self) -> usize {
        self.count
    }
    #[inline(always)]
    unsafe fn lane_forces<S: Simd, const VISCOUS: bool>(
        &self,
        corners: &[S::Idx; 4],
        dm: &[S::V; 9],
    ) -> ([V3<S>; 4], S::V) {
        lane_forces::<S, VISCOUS>(corners, dm, self)
    }
}

/// The forces on the four corners of `S::N` tetrahedra and 6 × their volumes.
#[inline(always)]
unsafe fn lane_forces<S: Simd, const VISCOUS: bool>(
    corners: &[S::Idx; 4],
    dm: &[S::V; 9],
    input: &ForceInput,
) -> ([V3<S>; 4], S::V) {
    let d = edges::<S>(&gather::<S>(input.x, corners));
    let (c, six_volume) = cofactor::<S>(&d);
    let mut t = lame::<S>(&green_strain::<S>(&d, dm), input.deviatoric);
    let mut pressure = S::mul(
        S::splat(input.bulk.0),
        corner_mean::<S>(input.averages, corners, 0),
    );
    if VISCOUS {
        let dv = edges::<S>(&gather::<S>(input.v, corners));
        let inv_det = S::div(S::splat(1.0), six_volume);
        let rate = rate_of_deformation::<S>(&dv, &c, inv_det);
        for (t, r) in t.iter_mut().zip(lame::<S>(&rate, input.viscous_deviatoric)) {
            *t = S::add(*t, r);
        }
        let rate_bar = corner_mean::<S>(input.averages, corners, 1);
        pressure = S::mul_add(S::splat(input.bulk.1), rate_bar, pressure);
    }
    for t in &mut t[..3] {
        *t = S::add(*t, pressure);
    }
    let f = [
        face_force::<S>(&t, &c[0]),
        face_force::<S>(&t, &c[1]),
        face_force::<S>(&t, &c[2]),
    ];
    let mut f0 = [S::splat(0.0); 3];
    for (k, f0) in f0.iter_mut().enumerate() {
        *f0 = S::neg(S::add(S::add(f[0][k], f[1][k]), f[2][k]));
    }
    ([f0, f[0], f[1], f[2]], six_volume)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuum::tet_blocks::HotTet;
    use crate::continuum::tet_lanes::packs;
    use crate::Mat3;

    /// `count` tetrahedra along a chain (each sharing a corner with the next: every node in
    /// one or two), strained by a smooth map and moving, with their packs' quarter volumes;
    /// and the block's positions and velocities.
    fn block(count: usize) -> (Vec<HotTet>, Vec<[f64; PACK]>, Vec<Vec3>, Vec<Vec3>) {
        let nodes = 3 * count + 1;
        let wobble = |i: usize, k: f64| ((i as f64 + 1.0) * k).sin() * 0.1;
        let reference: Vec<Vec3> = (0..nodes)
            .map(|i| {
                let corner = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)][i % 3];
                Vec3::new(
                    i as f64 * 0.3 + wobble(i, 1.3),
                    corner.0 + wobble(i, 2.1),
                    corner.1,
                )
            })
            .collect();
        let x: Vec<Vec3> = reference
            .iter()
            .map(|p| p + 0.02 * Vec3::new((2.0 * p.y).sin(), (3.0 * p.z).sin(), p.x.sin()))
            .collect();
        let v: Vec<Vec3> = (0..nodes)
            .map(|i| Vec3::new(wobble(i, 0.7), wobble(i, 1.9), wobble(i, 3.1)) * 30.0)
            .collect();
        let mut volume = Vec::new();
        let hot: Vec<HotTet> = (0..count)
            .map(|e| {
                let mut local = [3 * e, 3 * e + 1, 3 * e + 2, 3 * e + 3].map(|n| n as u16);
                let edge = |l: [u16; 4]| {
                    Mat3::from_columns(
                        &[1, 2, 3].map(|k| reference[l[k] as usize] - reference[l[0] as usize]),
                    )
                };
                if edge(local).determinant() < 0.0 {
                    local.swap(1, 2);
                }
                volume.push(edge(local).determinant() / 6.0);
                let dm_inv = edge(local).try_inverse().unwrap();
                HotTet { dm_inv, local }
            })
            .collect();
        let quarter = volume
            .chunks(PACK)
            .map(|c| std::array::from_fn(|l| 0.25 * c[l.min(c.len() - 1)]))
            .collect();
        (hot, quarter, x, v)
    }

    /// The lane sets this CPU runs, the scalar lane first.
    fn sets() -> Vec<LaneSet> {
        let mut sets = vec![LaneSet::Scalar];
        for set in [LaneSet::Avx2, LaneSet::Avx512] {
            if set.width() <= LaneSet::detected().width() {
                sets.push(set);
            }
        }
        sets
    }

    /// Both passes give the same bits on every lane set (the scalar lane included), and agree
    /// with the stress of Bonet & Burton computed with matrices to round-off.
    fn passes_agree<const VISCOUS: bool>() {
        let count = 45; // five packs, the last with 5 of 8 lanes
        let (hot, quarter, x, v) = block(count);
        let packs = packs(&hot);
        let (kappa, mu, kappa_d, mu_d) = (5.0e9, 2.0e9, 3.0e4, 7.0e4);
        let mut results = Vec::new();
        for set in sets() {
            let strain = StrainInput {
                x: &x,
                v: &v,
                quarter: &quarter,
                count,
            };
            let mut sums = vec![Vec3::zeros(); x.len()];
            strain_sums::<VISCOUS>(set, &packs, &strain, &mut sums);
            // Nodal volumes of the chain: the quarters of the node's tetrahedra.
            let mut nodal_volume = vec![0.0; x.len()];
            for (e, t) in hot.iter().enumerate() {
                for &l in &t.local {
                    nodal_volume[l as usize] += quarter[e / PACK][e % PACK];
                }
            }
            let averages: Vec<Vec3> = sums
                .iter()
                .zip(&nodal_volume)
                .map(|(s, w)| s / *w)
                .collect();
            let input = ForceInput {
                x: &x,
                v: &v,
                averages: &averages,
                deviatoric: (-2.0 / 3.0 * mu, mu),
                viscous_deviatoric: (-2.0 / 3.0 * mu_d, mu_d),
                bulk: (kappa, kappa_d),
                count,
            };
            let mut forces = vec![Vec3::zeros(); x.len()];
            assert_eq!(
                force_sums::<VISCOUS>(set, &packs, &input, &mut forces),
                None
            );
            results.push((set, averages, forces));
        }
        let (_, averages, forces) = &results[0];
        for (set, a, f) in &results[1..] {
            assert!(
                a == averages && f == forces,
                "{set:?} differs from the scalar lane"
            );
        }
        // The matrix form: T = κ θ̄ I + 2μ dev ε (+ κ_D tr(D)‾ I + 2μ_D dev D), forces −T c/6.
        use crate::continuum::tet_kernel::{cofactor, edge_matrix, velocity_gradient};
        let dev = |m: Mat3| m - Mat3::from_diagonal_element(m.trace() / 3.0);
        let mut want = vec![Vec3::zeros(); x.len()];
        for t in &hot {
            let c4 = t.local.map(|l| x[l as usize]);
            let dx = edge_matrix(&c4);
            let f = dx * t.dm_inv;
            let eps = (f * f.transpose() - Mat3::identity()) * 0.5;
            let mean = |k: usize| {
                t.local
                    .iter()
                    .map(|&l| averages[l as usize][k])
                    .sum::<f64>()
                    / 4.0
            };
            let mut stress = Mat3::from_diagonal_element(kappa * mean(0)) + dev(eps) * (2.0 * mu);
            let cof = cofactor(&dx);
            if VISCOUS {
                let l = velocity_gradient(&t.local.map(|l| v[l as usize]), &cof, dx.determinant());
                let d = (l + l.transpose()) * 0.5;
                stress += Mat3::from_diagonal_element(kappa_d * mean(1)) + dev(d) * (2.0 * mu_d);
            }
            let fc = stress * cof * (-1.0 / 6.0);
            let f3: [Vec3; 3] = std::array::from_fn(|j| fc.column(j).into());
            for (l, f) in t
                .local
                .iter()
                .zip([-(f3[0] + f3[1] + f3[2]), f3[0], f3[1], f3[2]])
            {
                want[*l as usize] += f;
            }
        }
        let scale = want.iter().map(|f| f.norm()).fold(0.0, f64::max);
        for (got, want) in forces.iter().zip(&want) {
            assert!((got - want).norm() <= 1e-12 * scale, "{got} vs {want}");
        }
    }

    #[test]
    fn elastic_passes_agree_on_every_lane_set_and_with_the_matrix_form() {
        passes_agree::<false>();
    }

    #[test]
    fn viscous_passes_agree_on_every_lane_set_and_with_the_matrix_form() {
        passes_agree::<true>();
    }
}
