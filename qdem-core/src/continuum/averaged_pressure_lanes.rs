//! The two block passes of the averaged-pressure tetrahedron
//! ([`crate::continuum::averaged_pressure_tet`], Bonet & Burton 1998 Eqs. 9–11) across SIMD
//! lanes, 8 tetrahedra at once as the standard kernel's ([`crate::continuum::tet_lanes`]),
//! against a block's scratch copy of its nodes:
//!
//! - the **strain pass** sums (V_e/4) θ_e, θ_e = tr ε_e (Eq. 4), and, when viscous,
//!   (V_e/4) tr D_e (Eq. 6) into the block's node slots: the numerators of the particles'
//!   averages θ̄_a = Σ_{e∋a} (V_e/4) θ_e / V̄_a. It computes only what these traces need:
//!   (V_e/4) tr ε_e = (V_e/8)(tr FᵀF − 3) from the six products d_k · d_l of the current
//!   edges and weights fixed by the reference ([`StrainPack`]: G = dX⁻¹ dX⁻ᵀ), not F's nine
//!   entries; tr D_e = Σ_k dv_k · c_k / 6V, not D's diagonal;
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
    cofactor, corner_offsets, dot, edges, face_force, force_pass, gather, green_strain, lame,
    lane_force_sums, lane_set_fns, rate_of_deformation, LaneForces, LaneSet, Simd, TetPack, PACK,
    V3,
};
use crate::{Mat3, Vec3};

/// Floating-point operations of one elastic tet-step of the averaged-pressure tetrahedron, a
/// multiply-add counted as two: the standard kernel's
/// ([`crate::continuum::tet_lanes::FLOPS_ELASTIC`], the deviatoric law costing what the Lamé
/// law does), the strain pass (edges 9, the six products d_k · d_l 30, their weighted sum 12,
/// the slot sums 4) and the corners' mean pressure (8).
pub const FLOPS_AVERAGED_ELASTIC: usize = crate::continuum::tet_lanes::FLOPS_ELASTIC + 63;
/// Floating-point operations of one viscoelastic tet-step of the averaged-pressure
/// tetrahedron: the standard viscoelastic kernel's, the elastic strain pass and pressure
/// (63), and the strain pass's rate (cofactor and volume 32, velocity edges 9, Σ dv_k · c_k
/// 17, weight and 1/det 2, slot sums 4) and its mean (6).
pub const FLOPS_AVERAGED_VISCOELASTIC: usize =
    crate::continuum::tet_lanes::FLOPS_VISCOELASTIC + 63 + 70;

/// The weights of the strain pass for `PACK` tetrahedra (by lane, as [`TetPack`]): with
/// G = dX⁻¹ dX⁻ᵀ, (V_e/4) tr ε_e = (V_e/8)(tr FᵀF − 3) = Σ_{k≤l} w_kl (d_k · d_l) − 3V_e/8 for
/// the current edges d_k (F = [d₀ d₁ d₂] dX⁻¹, so tr FᵀF = Σ_kl G_kl d_k · d_l): six
/// products of edges in place of F's nine entries and ε's diagonal.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub(crate) struct StrainPack {
    /// w_kl: (V_e/8) G_kk for k = 0, 1, 2, then (V_e/4) G_kl for (k, l) = (0, 1), (1, 2),
    /// (0, 2).
    pub(crate) metric: [[f64; PACK]; 6],
    /// −3V_e/8, the weighted sum at rest.
    pub(crate) rest: [f64; PACK],
    /// V_e/4, the weight of tr D_e.
    pub(crate) quarter: [f64; PACK],
}

impl StrainPack {
    /// The weights of tetrahedra `lanes` (dX⁻¹ and the reference volume V_e of each, at most
    /// [`PACK`], at least one), the last repeated in the unused lanes as
    /// [`crate::continuum::tet_lanes::packs`] does.
    pub(crate) fn new(lanes: &[(Mat3, f64)]) -> StrainPack {
        let mut pack = StrainPack {
            metric: [[0.0; PACK]; 6],
            rest: [0.0; PACK],
            quarter: [0.0; PACK],
        };
        for l in 0..PACK {
            let (dm_inv, volume) = &lanes[l.min(lanes.len() - 1)];
            let g = dm_inv * dm_inv.transpose();
            let (eighth, quarter) = (0.125 * volume, 0.25 * volume);
            let w = [
                eighth * g[(0, 0)],
                eighth * g[(1, 1)],
                eighth * g[(2, 2)],
                quarter * g[(0, 1)],
                quarter * g[(1, 2)],
                quarter * g[(0, 2)],
            ];
            for (lanes, w) in pack.metric.iter_mut().zip(w) {
                lanes[l] = w;
            }
            pack.rest[l] = -3.0 * eighth;
            pack.quarter[l] = quarter;
        }
        pack
    }
}

/// What the strain pass reads: the block's node positions (and velocities, read only when
/// viscous), each pack's strain weights and the number of real tetrahedra.
pub(crate) struct StrainInput<'a> {
    pub x: &'a [Vec3],
    pub v: &'a [Vec3],
    pub weights: &'a [StrainPack],
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
    assert_eq!(packs.len(), input.weights.len(), "strain weights per pack");
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

/// Σ_{k≤l} w_kl (d_k · d_l) − 3V_e/8 = (V_e/4) tr ε_e of the lanes `o..o + S::N` of
/// `weights` ([`StrainPack`]) with edges `d`.
#[inline(always)]
unsafe fn weighted_dilatation<S: Simd>(d: &[V3<S>; 3], weights: &StrainPack, o: usize) -> S::V {
    let products = [
        dot::<S>(&d[0], &d[0]),
        dot::<S>(&d[1], &d[1]),
        dot::<S>(&d[2], &d[2]),
        dot::<S>(&d[0], &d[1]),
        dot::<S>(&d[1], &d[2]),
        dot::<S>(&d[0], &d[2]),
    ];
    let mut sum = S::load(&weights.rest[o..]);
    for (product, lanes) in products.iter().zip(&weights.metric) {
        sum = S::mul_add(S::load(&lanes[o..]), *product, sum);
    }
    sum
}

/// (V_e/4) tr D_e = (V_e/4) Σ_k dv_k · c_k / (6V) (Eqs. 5–6: tr L with L = Σ_k dv_k ⊗ c_k /
/// 6V) of the lanes `o..o + S::N` of `weights` with edges `d` and velocity edges `dv`.
#[inline(always)]
unsafe fn weighted_rate<S: Simd>(
    d: &[V3<S>; 3],
    dv: &[V3<S>; 3],
    weights: &StrainPack,
    o: usize,
) -> S::V {
    let (c, six_volume) = cofactor::<S>(d);
    let mut trace = dot::<S>(&dv[0], &c[0]);
    for k in 1..3 {
        for i in 0..3 {
            trace = S::mul_add(dv[k][i], c[k][i], trace);
        }
    }
    S::div(S::mul(S::load(&weights.quarter[o..]), trace), six_volume)
}

/// The strain pass with `S::N` lanes per vector.
#[inline(always)]
unsafe fn strain_pass<S: Simd, const VISCOUS: bool>(
    packs: &[TetPack],
    input: &StrainInput,
    out: &mut [Vec3],
) {
    let (mut theta, mut rate) = ([0.0f64; PACK], [0.0f64; PACK]);
    for (p, (pack, weights)) in packs.iter().zip(input.weights).enumerate() {
        for o in (0..PACK).step_by(S::N) {
            let base = p * PACK + o;
            if base >= input.count {
                break;
            }
            let corners = corner_offsets::<S>(pack, o);
            let d = edges::<S>(&gather::<S>(input.x, &corners));
            S::store(weighted_dilatation::<S>(&d, weights, o), &mut theta);
            if VISCOUS {
                let dv = edges::<S>(&gather::<S>(input.v, &corners));
                S::store(weighted_rate::<S>(&d, &dv, weights, o), &mut rate);
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

    /// A block of tetrahedra with their reference volumes, and its nodes' reference
    /// positions, positions and velocities.
    struct Chain {
        hot: Vec<HotTet>,
        volume: Vec<f64>,
        reference: Vec<Vec3>,
        x: Vec<Vec3>,
        v: Vec<Vec3>,
    }

    /// `count` tetrahedra along a chain (each sharing a corner with the next: every node in
    /// one or two), strained by a smooth map and moving.
    fn chain(count: usize) -> Chain {
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
        Chain {
            hot,
            volume,
            reference,
            x,
            v,
        }
    }

    /// The strain weights of the packs of `hot` with reference volumes `volume`.
    fn weights(hot: &[HotTet], volume: &[f64]) -> Vec<StrainPack> {
        let lanes: Vec<(Mat3, f64)> = hot.iter().map(|t| t.dm_inv).zip(volume.to_vec()).collect();
        lanes.chunks(PACK).map(StrainPack::new).collect()
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
        let Chain {
            hot, volume, x, v, ..
        } = chain(count);
        let weights = weights(&hot, &volume);
        let packs = packs(&hot);
        let (kappa, mu, kappa_d, mu_d) = (5.0e9, 2.0e9, 3.0e4, 7.0e4);
        let mut results = Vec::new();
        for set in sets() {
            let strain = StrainInput {
                x: &x,
                v: &v,
                weights: &weights,
                count,
            };
            let mut sums = vec![Vec3::zeros(); x.len()];
            strain_sums::<VISCOUS>(set, &packs, &strain, &mut sums);
            // Nodal volumes of the chain: the quarters of the node's tetrahedra.
            let mut nodal_volume = vec![0.0; x.len()];
            for (e, t) in hot.iter().enumerate() {
                for &l in &t.local {
                    nodal_volume[l as usize] += 0.25 * volume[e];
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

    /// The strain weights give (V_e/4) tr ε_e of Eq. 4 from the current edges alone, on every
    /// lane set: nothing under a rigid rotation, and (V_e/4) · 3((1 + s)² − 1)/2 under a
    /// uniform stretch 1 + s. The sums cancel terms of about 3V_e/8 each (six per
    /// tetrahedron), so the tolerance is round-off of those: 1e-13 of a node's Σ V_e/4.
    #[test]
    fn the_strain_weights_give_the_trace_of_the_green_strain() {
        let count = 45; // five packs, the last with 5 of 8 lanes
        let Chain {
            hot,
            volume,
            reference,
            v,
            ..
        } = chain(count);
        let weights = weights(&hot, &volume);
        let packs = packs(&hot);
        let mut nodal_quarter = vec![0.0; reference.len()];
        for (t, volume) in hot.iter().zip(&volume) {
            for &l in &t.local {
                nodal_quarter[l as usize] += 0.25 * volume;
            }
        }
        let rotation = nalgebra::Rotation3::from_euler_angles(0.3, -1.1, 0.7).into_inner();
        let s = 0.01;
        let cases = [
            (rotation, 0.0),
            (
                Mat3::identity() * (1.0 + s),
                1.5 * ((1.0 + s) * (1.0 + s) - 1.0),
            ),
        ];
        for set in sets() {
            for (map, trace) in cases {
                let x: Vec<Vec3> = reference.iter().map(|p| map * p).collect();
                let input = StrainInput {
                    x: &x,
                    v: &v,
                    weights: &weights,
                    count,
                };
                let mut sums = vec![Vec3::zeros(); x.len()];
                strain_sums::<false>(set, &packs, &input, &mut sums);
                for (got, quarter) in sums.iter().zip(&nodal_quarter) {
                    let want = quarter * trace;
                    assert!(
                        (got.x - want).abs() <= 1e-13 * quarter,
                        "{set:?}: {} vs {want}",
                        got.x
                    );
                }
            }
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
