//! The QDEM tetrahedron kernel across SIMD lanes: [`tet_forces`](super::tet_kernel::tet_forces)
//! (paper 000 Eqs. 1–10) for 8 tetrahedra at once, one per lane of an AVX-512 register (two
//! AVX2 registers of 4).
//!
//! A block's tetrahedra are stored in packs of [`PACK`] ([`TetPack`], structure of arrays: each
//! entry of dX⁻¹ and each corner index as one lane vector). A pass gathers the corners'
//! positions (and velocities) lane by lane from the block's scratch copy, runs the same
//! operations as the scalar kernel on whole lane vectors, and adds the four forces of each
//! lane into the block's node sums lane after lane, corner after corner: the very order of
//! the scalar loop, so the sums do not depend on the lane width, the thread count or the rank
//! count.
//!
//! The operations are those of the scalar kernel in the same order, with the products and sums
//! of Eqs. 1–10 fused into multiply-adds (one rounding instead of two): against the scalar
//! kernel a force differs by round-off (a few ulp of the largest term), the same on every CPU
//! that has the AVX2 or AVX-512 path. The instruction set is chosen at run time
//! ([`LaneSet::detected`]), so one binary serves both; a CPU with neither runs the scalar
//! kernel.

use crate::continuum::prefetch;
use crate::continuum::tet_blocks::HotTet;
use crate::Vec3;
use std::sync::OnceLock;

/// Tetrahedra per pack (the lanes of one AVX-512 register of f64).
pub const PACK: usize = 8;

/// Floating-point operations of one elastic tet-step in the lane kernel, a multiply-add
/// counted as two: the edges (9), the cofactor columns (27), 6 × the volume (5), F = dx·dX⁻¹
/// (45), ε (39), the Lamé law (12), T·c_j/6 (54), the fourth force (6) and the scatter into
/// the node sums (12).
pub const FLOPS_ELASTIC: usize = 209;
/// Floating-point operations of one viscoelastic tet-step: the elastic ones and the velocity
/// differences (9), 1/det and ½/det (2), the six components of D (54), the Lamé law (12) and
/// T_E + T_D (6).
pub const FLOPS_VISCOELASTIC: usize = FLOPS_ELASTIC + 83;

/// `PACK` tetrahedra as the lane kernel reads them: each of the nine entries of dX⁻¹ (row
/// major) and each of the four corners (indices into the block's nodes) as one lane vector.
/// A block's last pack repeats its last tetrahedron in the unused lanes, whose results are
/// dropped.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub(crate) struct TetPack {
    pub(crate) dm_inv: [[f64; PACK]; 9],
    pub(crate) local: [[u16; PACK]; 4],
}

/// The packs of one block's tetrahedra, in order.
pub(crate) fn packs(hot: &[HotTet]) -> Vec<TetPack> {
    hot.chunks(PACK)
        .map(|chunk| {
            let lane = |l: usize| &chunk[l.min(chunk.len() - 1)];
            let mut pack = TetPack {
                dm_inv: [[0.0; PACK]; 9],
                local: [[0; PACK]; 4],
            };
            for l in 0..PACK {
                let t = lane(l);
                for (i, entry) in pack.dm_inv.iter_mut().enumerate() {
                    entry[l] = t.dm_inv[(i / 3, i % 3)];
                }
                for (c, corner) in pack.local.iter_mut().enumerate() {
                    corner[l] = t.local[c];
                }
            }
            pack
        })
        .collect()
}

/// The instruction set the lane kernel runs with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LaneSet {
    /// No vector kernel: the scalar [`tet_forces`](super::tet_kernel::tet_forces).
    Scalar,
    /// AVX2 with FMA: two registers of 4 lanes per pack.
    Avx2,
    /// AVX-512 (F, VL, DQ) with FMA: one register of 8 lanes per pack.
    Avx512,
}

impl LaneSet {
    /// The widest set this CPU runs, lowered by the environment variable
    /// `QDEM_KERNEL_LANES` (`scalar`, `avx2` or `avx512`: for comparing the paths in one
    /// binary; a set the CPU lacks is never chosen, other values are ignored). Detected once
    /// per process.
    pub fn detected() -> LaneSet {
        static SET: OnceLock<LaneSet> = OnceLock::new();
        *SET.get_or_init(|| {
            let cpu = cpu_lane_set();
            match std::env::var("QDEM_KERNEL_LANES").as_deref() {
                Ok("scalar") => LaneSet::Scalar,
                Ok("avx2") if cpu == LaneSet::Avx512 => LaneSet::Avx2,
                _ => cpu,
            }
        })
    }

    /// Lanes per vector register (1 for the scalar kernel).
    pub fn width(self) -> usize {
        match self {
            LaneSet::Scalar => 1,
            LaneSet::Avx2 => 4,
            LaneSet::Avx512 => 8,
        }
    }
}

#[cfg(target_arch = "x86_64")]
fn cpu_lane_set() -> LaneSet {
    if is_x86_feature_detected!("avx512f")
        && is_x86_feature_detected!("avx512vl")
        && is_x86_feature_detected!("avx512dq")
        && is_x86_feature_detected!("fma")
    {
        LaneSet::Avx512
    } else if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
        LaneSet::Avx2
    } else {
        LaneSet::Scalar
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn cpu_lane_set() -> LaneSet {
    LaneSet::Scalar
}

/// What a block pass reads besides its packs: the block's node positions and velocities
/// (read only when viscous), the Lamé pairs, the number of real tetrahedra and whether to
/// prefetch the packs ahead ([`crate::continuum::prefetch`]: the same sums either way).
pub(crate) struct BlockInput<'a> {
    pub x: &'a [Vec3],
    pub v: &'a [Vec3],
    pub elastic: (f64, f64),
    pub viscous: (f64, f64),
    pub count: usize,
    pub prefetch: bool,
}

/// The forces of a block's tetrahedra (`packs`) added into `out` (its node sums) with the lane
/// kernel of `set`; returns the block index of the first tetrahedron whose volume is not
/// positive. `None` when `set` is [`LaneSet::Scalar`] (the caller runs the scalar kernel).
pub(crate) fn block_forces<const VISCOUS: bool>(
    set: LaneSet,
    packs: &[TetPack],
    input: &BlockInput,
    out: &mut [Vec3],
) -> Option<Option<usize>> {
    lane_force_sums::<BlockInput, VISCOUS>(set, packs, input, out)
}

/// The force pass of `input`'s kernel ([`LaneForces`]) over a block's `packs` with the lanes
/// of `set`, the forces added into `out`; the block index of the first tetrahedron whose
/// volume is not positive. `None` when `set` is [`LaneSet::Scalar`] (no vector kernel).
pub(crate) fn lane_force_sums<I: LaneForces, const VISCOUS: bool>(
    set: LaneSet,
    packs: &[TetPack],
    input: &I,
    out: &mut [Vec3],
) -> Option<Option<usize>> {
    match set {
        LaneSet::Scalar => None,
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `detected` chooses a set only when the CPU has its features.
        LaneSet::Avx512 => Some(unsafe { force_avx512::<I, VISCOUS>(packs, input, out) }),
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        LaneSet::Avx2 => Some(unsafe { force_avx2::<I, VISCOUS>(packs, input, out) }),
        #[cfg(not(target_arch = "x86_64"))]
        _ => None,
    }
}

/// Defines `$avx512` and `$avx2`: the generic block pass `$pass::<S, ...>` compiled with the
/// target features of AVX-512 and of AVX2 with FMA (S the matching [`Simd`] set), the
/// functions a dispatch on [`LaneSet`] calls. The generic parameters after `S` are given
/// twice, declared (`[I: Bound, const VISCOUS: bool]`) and passed (`[I, VISCOUS]`).
macro_rules! lane_set_fns {
    ($avx512:ident, $avx2:ident = $pass:ident [$($decl:tt)*] [$($pass_args:tt)*]
        ($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
        unsafe fn $avx512<$($decl)*>($($arg: $ty),*) -> $ret {
            $pass::<$crate::continuum::tet_lanes::x86::Avx512, $($pass_args)*>($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        unsafe fn $avx2<$($decl)*>($($arg: $ty),*) -> $ret {
            $pass::<$crate::continuum::tet_lanes::x86::Avx2, $($pass_args)*>($($arg),*)
        }
    };
}
pub(crate) use lane_set_fns;

lane_set_fns!(force_avx512, force_avx2 = force_pass [I: LaneForces, const VISCOUS: bool] [I, VISCOUS]
    (packs: &[TetPack], input: &I, out: &mut [Vec3]) -> Option<usize>);

/// The vector operations of the lane kernel, one implementation per instruction set. Every
/// method is `unsafe`: it may run only on a CPU with the set's features, inlined into a
/// function that enables them.
pub(crate) trait Simd {
    /// Lanes per vector.
    const N: usize;
    /// A vector of `N` f64.
    type V: Copy;
    /// `N` gather offsets.
    type Idx: Copy;
    unsafe fn splat(a: f64) -> Self::V;
    /// `N` values from `a[..N]`.
    unsafe fn load(a: &[f64]) -> Self::V;
    unsafe fn store(a: Self::V, to: &mut [f64]);
    unsafe fn add(a: Self::V, b: Self::V) -> Self::V;
    unsafe fn sub(a: Self::V, b: Self::V) -> Self::V;
    unsafe fn mul(a: Self::V, b: Self::V) -> Self::V;
    unsafe fn div(a: Self::V, b: Self::V) -> Self::V;
    /// a · b + c, rounded once.
    unsafe fn mul_add(a: Self::V, b: Self::V, c: Self::V) -> Self::V;
    unsafe fn neg(a: Self::V) -> Self::V;
    /// The offsets 3·`local[l]` of the corners' first coordinates (`local[..N]`).
    unsafe fn offsets(local: &[u16]) -> Self::Idx;
    /// `base[idx[l]]` per lane.
    unsafe fn gather(base: *const f64, idx: Self::Idx) -> Self::V;
}

#[cfg(target_arch = "x86_64")]
pub(crate) mod x86 {
    use super::Simd;
    use std::arch::x86_64::*;

    /// AVX-512: 8 lanes.
    pub(crate) struct Avx512;
    /// AVX2 with FMA: 4 lanes.
    pub(crate) struct Avx2;

    impl Simd for Avx512 {
        const N: usize = 8;
        type V = __m512d;
        type Idx = __m256i;
        #[inline(always)]
        unsafe fn splat(a: f64) -> __m512d {
            _mm512_set1_pd(a)
        }
        #[inline(always)]
        unsafe fn load(a: &[f64]) -> __m512d {
            debug_assert!(a.len() >= 8);
            _mm512_loadu_pd(a.as_ptr())
        }
        #[inline(always)]
        unsafe fn store(a: __m512d, to: &mut [f64]) {
            debug_assert!(to.len() >= 8);
            _mm512_storeu_pd(to.as_mut_ptr(), a)
        }
        #[inline(always)]
        unsafe fn add(a: __m512d, b: __m512d) -> __m512d {
            _mm512_add_pd(a, b)
        }
        #[inline(always)]
        unsafe fn sub(a: __m512d, b: __m512d) -> __m512d {
            _mm512_sub_pd(a, b)
        }
        #[inline(always)]
        unsafe fn mul(a: __m512d, b: __m512d) -> __m512d {
            _mm512_mul_pd(a, b)
        }
        #[inline(always)]
        unsafe fn div(a: __m512d, b: __m512d) -> __m512d {
            _mm512_div_pd(a, b)
        }
        #[inline(always)]
        unsafe fn mul_add(a: __m512d, b: __m512d, c: __m512d) -> __m512d {
            _mm512_fmadd_pd(a, b, c)
        }
        #[inline(always)]
        unsafe fn neg(a: __m512d) -> __m512d {
            _mm512_xor_pd(a, _mm512_set1_pd(-0.0))
        }
        #[inline(always)]
        unsafe fn offsets(local: &[u16]) -> __m256i {
            debug_assert!(local.len() >= 8);
            let i = _mm256_cvtepu16_epi32(_mm_loadu_si128(local.as_ptr().cast()));
            _mm256_add_epi32(_mm256_add_epi32(i, i), i)
        }
        #[inline(always)]
        unsafe fn gather(base: *const f64, idx: __m256i) -> __m512d {
            _mm512_i32gather_pd::<8>(idx, base)
        }
    }

    impl Simd for Avx2 {
        const N: usize = 4;
        type V = __m256d;
        type Idx = __m128i;
        #[inline(always)]
        unsafe fn splat(a: f64) -> __m256d {
            _mm256_set1_pd(a)
        }
        #[inline(always)]
        unsafe fn load(a: &[f64]) -> __m256d {
            debug_assert!(a.len() >= 4);
            _mm256_loadu_pd(a.as_ptr())
        }
        #[inline(always)]
        unsafe fn store(a: __m256d, to: &mut [f64]) {
            debug_assert!(to.len() >= 4);
            _mm256_storeu_pd(to.as_mut_ptr(), a)
        }
        #[inline(always)]
        unsafe fn add(a: __m256d, b: __m256d) -> __m256d {
            _mm256_add_pd(a, b)
        }
        #[inline(always)]
        unsafe fn sub(a: __m256d, b: __m256d) -> __m256d {
            _mm256_sub_pd(a, b)
        }
        #[inline(always)]
        unsafe fn mul(a: __m256d, b: __m256d) -> __m256d {
            _mm256_mul_pd(a, b)
        }
        #[inline(always)]
        unsafe fn div(a: __m256d, b: __m256d) -> __m256d {
            _mm256_div_pd(a, b)
        }
        #[inline(always)]
        unsafe fn mul_add(a: __m256d, b: __m256d, c: __m256d) -> __m256d {
            _mm256_fmadd_pd(a, b, c)
        }
        #[inline(always)]
        unsafe fn neg(a: __m256d) -> __m256d {
            _mm256_xor_pd(a, _mm256_set1_pd(-0.0))
        }
        #[inline(always)]
        unsafe fn offsets(local: &[u16]) -> __m128i {
            debug_assert!(local.len() >= 4);
            let i = _mm_cvtepu16_epi32(_mm_loadl_epi64(local.as_ptr().cast()));
            _mm_add_epi32(_mm_add_epi32(i, i), i)
        }
        #[inline(always)]
        unsafe fn gather(base: *const f64, idx: __m128i) -> __m256d {
            _mm256_i32gather_pd::<8>(base, idx)
        }
    }
}

/// A block pass's force kernel: what the generic [`force_pass`] computes per lane vector.
pub(crate) trait LaneForces {
    /// The number of real tetrahedra of the block.
    fn count(&self) -> usize;
    /// Whether the pass prefetches the packs ahead ([`crate::continuum::prefetch`]).
    fn prefetch(&self) -> bool {
        false
    }
    /// The forces on the four corners of `S::N` tetrahedra (corner offsets `corners`, dX⁻¹
    /// `dm`) and 6 × their volumes.
    ///
    /// # Safety
    /// Only on a CPU with `S`'s features, inlined into a function that enables them.
    unsafe fn lane_forces<S: Simd, const VISCOUS: bool>(
        &self,
        corners: &[S::Idx; 4],
        dm: &[S::V; 9],
    ) -> ([V3<S>; 4], S::V);
}

impl LaneForces for BlockInput<'_> {
    #[inline(always)]
    fn count(&self) -> usize {
        self.count
    }
    #[inline(always)]
    fn prefetch(&self) -> bool {
        self.prefetch
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

/// The block pass with `S::N` lanes per vector: each pack in `PACK / S::N` steps, the forces
/// of the real lanes added in lane order. Compiled inside the functions that enable the
/// features.
#[inline(always)]
pub(crate) unsafe fn force_pass<S: Simd, I: LaneForces, const VISCOUS: bool>(
    packs: &[TetPack],
    input: &I,
    out: &mut [Vec3],
) -> Option<usize> {
    let mut first = None;
    let mut f = [[0.0f64; PACK]; 12];
    let mut six_volume = [0.0f64; PACK];
    let count = input.count();
    for (p, pack) in packs.iter().enumerate() {
        if input.prefetch() {
            if let Some(ahead) = packs.get(p + prefetch::PACKS_AHEAD) {
                prefetch::lines(ahead);
            }
        }
        for o in (0..PACK).step_by(S::N) {
            let base = p * PACK + o;
            if base >= count {
                break;
            }
            let corners = corner_offsets::<S>(pack, o);
            let dm = dm_inv_lanes::<S>(pack, o);
            let (forces, volume) = input.lane_forces::<S, VISCOUS>(&corners, &dm);
            for (to, from) in f.iter_mut().zip(forces.iter().flatten()) {
                S::store(*from, to);
            }
            S::store(volume, &mut six_volume);
            for l in 0..S::N.min(count - base) {
                for c in 0..4 {
                    let at = pack.local[c][o + l] as usize;
                    out[at] += Vec3::new(f[3 * c][l], f[3 * c + 1][l], f[3 * c + 2][l]);
                }
                // B = FFᵀ cannot tell an inverted tetrahedron from its mirror image.
                if first.is_none() && six_volume[l].partial_cmp(&0.0) != Some(Greater) {
                    first = Some(base + l);
                }
            }
        }
    }
    first
}

/// The corner offsets of lanes `o..o + S::N` of `pack`.
#[inline(always)]
pub(crate) unsafe fn corner_offsets<S: Simd>(pack: &TetPack, o: usize) -> [S::Idx; 4] {
    let mut corners = [S::offsets(&pack.local[0][o..]); 4];
    for (c, offsets) in corners.iter_mut().enumerate().skip(1) {
        *offsets = S::offsets(&pack.local[c][o..]);
    }
    corners
}

/// dX⁻¹ (row major) of lanes `o..o + S::N` of `pack`.
#[inline(always)]
pub(crate) unsafe fn dm_inv_lanes<S: Simd>(pack: &TetPack, o: usize) -> [S::V; 9] {
    let mut dm = [S::splat(0.0); 9];
    for (entry, lanes) in dm.iter_mut().zip(&pack.dm_inv) {
        *entry = S::load(&lanes[o..]);
    }
    dm
}

use std::cmp::Ordering::Greater;

/// A 3-vector (or a matrix column) of lane vectors.
pub(crate) type V3<S> = [<S as Simd>::V; 3];

/// A symmetric tensor of lane vectors: xx, yy, zz, xy, yz, xz.
pub(crate) type Sym<S> = [<S as Simd>::V; 6];

// No closures below: a closure does not inherit the target features of the function it is
// inlined into, and one left out of line would call the intrinsics out of line.

/// The corner values of every lane, x[local] (`values` as flat f64, 3 per node).
#[inline(always)]
pub(crate) unsafe fn gather<S: Simd>(values: &[Vec3], corners: &[S::Idx; 4]) -> [V3<S>; 4] {
    let base = values.as_ptr().cast::<f64>();
    let mut g = [[S::splat(0.0); 3]; 4];
    for (corner, &offsets) in g.iter_mut().zip(corners) {
        for (k, coordinate) in corner.iter_mut().enumerate() {
            *coordinate = S::gather(base.add(k), offsets);
        }
    }
    g
}

/// The edges x₁−x₀, x₂−x₀, x₃−x₀.
#[inline(always)]
pub(crate) unsafe fn edges<S: Simd>(g: &[V3<S>; 4]) -> [V3<S>; 3] {
    let mut e = [[S::splat(0.0); 3]; 3];
    for (edge, corner) in e.iter_mut().zip(&g[1..]) {
        for k in 0..3 {
            edge[k] = S::sub(corner[k], g[0][k]);
        }
    }
    e
}

/// a₀b₀ + a₁b₁ + a₂b₂ of three lane vectors each.
#[inline(always)]
pub(crate) unsafe fn dot3<S: Simd>(a: [S::V; 3], b: [S::V; 3]) -> S::V {
    S::mul_add(a[2], b[2], S::mul_add(a[1], b[1], S::mul(a[0], b[0])))
}

/// ab − cd.
#[inline(always)]
pub(crate) unsafe fn mul_sub<S: Simd>(a: S::V, b: S::V, c: S::V, d: S::V) -> S::V {
    S::mul_add(a, b, S::neg(S::mul(c, d)))
}

/// a · b.
#[inline(always)]
pub(crate) unsafe fn dot<S: Simd>(a: &V3<S>, b: &V3<S>) -> S::V {
    dot3::<S>(*a, *b)
}

/// a × b.
#[inline(always)]
pub(crate) unsafe fn cross<S: Simd>(a: &V3<S>, b: &V3<S>) -> V3<S> {
    [
        mul_sub::<S>(a[1], b[2], a[2], b[1]),
        mul_sub::<S>(a[2], b[0], a[0], b[2]),
        mul_sub::<S>(a[0], b[1], a[1], b[0]),
    ]
}

/// The isotropic law of Eqs. 2 and 7: λ tr(e) I + 2μ e.
#[inline(always)]
pub(crate) unsafe fn lame<S: Simd>(e: &Sym<S>, (lambda, mu): (f64, f64)) -> Sym<S> {
    let p = S::mul(S::splat(lambda), S::add(S::add(e[0], e[1]), e[2]));
    let two_mu = S::splat(2.0 * mu);
    [
        S::mul_add(two_mu, e[0], p),
        S::mul_add(two_mu, e[1], p),
        S::mul_add(two_mu, e[2], p),
        S::mul(two_mu, e[3]),
        S::mul(two_mu, e[4]),
        S::mul(two_mu, e[5]),
    ]
}

/// ε = (F Fᵀ − I)/2 of Eq. 4, with row r of F = [d₁ d₂ d₃] dX⁻¹ the sum Σ_k d_k[r] · (row k
/// of dX⁻¹) (dm: dX⁻¹ row major).
#[inline(always)]
pub(crate) unsafe fn green_strain<S: Simd>(d: &[V3<S>; 3], dm: &[S::V; 9]) -> Sym<S> {
    let mut f = [[S::splat(0.0); 3]; 3];
    for (r, row) in f.iter_mut().enumerate() {
        for (j, entry) in row.iter_mut().enumerate() {
            *entry = dot3::<S>([dm[j], dm[3 + j], dm[6 + j]], [d[0][r], d[1][r], d[2][r]]);
        }
    }
    let [f0, f1, f2] = f;
    let (half, one) = (S::splat(0.5), S::splat(1.0));
    [
        S::mul(half, S::sub(dot::<S>(&f0, &f0), one)),
        S::mul(half, S::sub(dot::<S>(&f1, &f1), one)),
        S::mul(half, S::sub(dot::<S>(&f2, &f2), one)),
        S::mul(half, dot::<S>(&f0, &f1)),
        S::mul(half, dot::<S>(&f1, &f2)),
        S::mul(half, dot::<S>(&f0, &f2)),
    ]
}

/// D = sym(Σ_k dv_k ⊗ c_k) / det of Eqs. 5–6.
#[inline(always)]
pub(crate) unsafe fn rate_of_deformation<S: Simd>(
    dv: &[V3<S>; 3],
    c: &[V3<S>; 3],
    inv_det: S::V,
) -> Sym<S> {
    // l[i][j] = Σ_k dv_k[i] c_k[j] = det · L_ij.
    let mut l = [[S::splat(0.0); 3]; 3];
    for (i, row) in l.iter_mut().enumerate() {
        for (j, entry) in row.iter_mut().enumerate() {
            *entry = dot3::<S>([dv[0][i], dv[1][i], dv[2][i]], [c[0][j], c[1][j], c[2][j]]);
        }
    }
    let h = S::mul(S::splat(0.5), inv_det);
    [
        S::mul(inv_det, l[0][0]),
        S::mul(inv_det, l[1][1]),
        S::mul(inv_det, l[2][2]),
        S::mul(h, S::add(l[0][1], l[1][0])),
        S::mul(h, S::add(l[1][2], l[2][1])),
        S::mul(h, S::add(l[0][2], l[2][0])),
    ]
}

/// The columns c_j of cof(dx) (the area vectors A_j = −½ c_j of the faces opposite vertices
/// 1–3) and 6 × the volume, d₀ · c₀, of edges `d`.
#[inline(always)]
pub(crate) unsafe fn cofactor<S: Simd>(d: &[V3<S>; 3]) -> ([V3<S>; 3], S::V) {
    let c = [
        cross::<S>(&d[1], &d[2]),
        cross::<S>(&d[2], &d[0]),
        cross::<S>(&d[0], &d[1]),
    ];
    let six_volume = dot::<S>(&d[0], &c[0]);
    (c, six_volume)
}

/// −(T · a)/6 for the symmetric T.
#[inline(always)]
pub(crate) unsafe fn face_force<S: Simd>(t: &Sym<S>, a: &V3<S>) -> V3<S> {
    let sixth = S::splat(-1.0 / 6.0);
    [
        S::mul(dot3::<S>([t[0], t[3], t[5]], *a), sixth),
        S::mul(dot3::<S>([t[3], t[1], t[4]], *a), sixth),
        S::mul(dot3::<S>([t[5], t[4], t[2]], *a), sixth),
    ]
}

/// The forces on the four corners of `S::N` tetrahedra and 6 × their volumes: the lane form
/// of [`tet_forces`](super::tet_kernel::tet_forces).
#[inline(always)]
unsafe fn lane_forces<S: Simd, const VISCOUS: bool>(
    corners: &[S::Idx; 4],
    dm: &[S::V; 9],
    input: &BlockInput,
) -> ([V3<S>; 4], S::V) {
    let d = edges::<S>(&gather::<S>(input.x, corners));
    let (c, six_volume) = cofactor::<S>(&d);
    let mut t = lame::<S>(&green_strain::<S>(&d, dm), input.elastic);
    if VISCOUS {
        let dv = edges::<S>(&gather::<S>(input.v, corners));
        let inv_det = S::div(S::splat(1.0), six_volume);
        let rate = lame::<S>(&rate_of_deformation::<S>(&dv, &c, inv_det), input.viscous);
        for (t, r) in t.iter_mut().zip(rate) {
            *t = S::add(*t, r);
        }
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
    use crate::continuum::tet_kernel::tet_forces;
    use crate::Mat3;

    /// A small pseudo-random generator (xorshift), for reproducible tetrahedra.
    fn rng(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    /// `count` tetrahedra over 3·count + 1 nodes (each sharing a corner with the next), well
    /// shaped (6V ≈ 0.9), strained by a smooth map and moving, with their reference inverses.
    fn block(count: usize) -> (Vec<HotTet>, Vec<Vec3>, Vec<Vec3>) {
        let mut seed = 0x9e3779b97f4a7c15;
        let nodes = 3 * count + 1;
        let mut r = |s: f64| rng(&mut seed) * s;
        let reference: Vec<Vec3> = (0..nodes)
            .map(|i| {
                let corner = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)][i % 3];
                Vec3::new(i as f64 * 0.3, corner.0, corner.1) + Vec3::new(r(0.1), r(0.1), r(0.1))
            })
            .collect();
        let x: Vec<Vec3> = reference
            .iter()
            .map(|p| p + 0.02 * Vec3::new((2.0 * p.y).sin(), (3.0 * p.z).sin(), p.x.sin()))
            .collect();
        let v: Vec<Vec3> = (0..nodes)
            .map(|_| Vec3::new(r(3.0), r(3.0), r(3.0)))
            .collect();
        let hot = (0..count)
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
                HotTet {
                    dm_inv: edge(local).try_inverse().unwrap(),
                    local,
                }
            })
            .collect();
        (hot, x, v)
    }

    fn scalar<const VISCOUS: bool>(hot: &[HotTet], input: &BlockInput) -> Vec<Vec3> {
        let mut out = vec![Vec3::zeros(); input.x.len()];
        for t in hot {
            let x = t.local.map(|l| input.x[l as usize]);
            let v = t.local.map(|l| input.v[l as usize]);
            let (f, _) = tet_forces::<VISCOUS>(&x, &v, &t.dm_inv, input.elastic, input.viscous);
            for (l, f) in t.local.iter().zip(f) {
                out[*l as usize] += f;
            }
        }
        out
    }

    /// Every lane set this CPU has gives the same node sums, bit for bit, and each agrees
    /// with the scalar kernel to round-off (a few ulp of the largest force).
    fn lanes_agree<const VISCOUS: bool>() {
        let count = 45; // five packs, the last with 5 of 8 lanes
        let (hot, x, v) = block(count);
        let input = BlockInput {
            x: &x,
            v: &v,
            elastic: (3.0e9, 2.0e9),
            viscous: (4.0e4, 7.0e4),
            count,
            prefetch: false,
        };
        let want = scalar::<VISCOUS>(&hot, &input);
        let scale = want.iter().map(|f| f.norm()).fold(0.0, f64::max);
        let packs = packs(&hot);
        let mut sets = vec![LaneSet::Scalar];
        if cpu_lane_set() != LaneSet::Scalar {
            sets.push(LaneSet::Avx2);
        }
        if cpu_lane_set() == LaneSet::Avx512 {
            sets.push(LaneSet::Avx512);
        }
        let mut first: Option<Vec<Vec3>> = None;
        for set in sets.into_iter().skip(1) {
            let mut out = vec![Vec3::zeros(); x.len()];
            let inverted = block_forces::<VISCOUS>(set, &packs, &input, &mut out);
            assert_eq!(inverted, Some(None), "{set:?}");
            for (got, want) in out.iter().zip(&want) {
                assert!(
                    (got - want).norm() <= 1e-12 * scale,
                    "{set:?}: {got} vs {want}"
                );
            }
            match &first {
                Some(f) => assert_eq!(f, &out, "{set:?} against the narrower set"),
                None => first = Some(out),
            }
        }
        if first.is_none() {
            eprintln!("skipped: this CPU has neither AVX2+FMA nor AVX-512");
        }
    }

    #[test]
    fn elastic_lanes_agree_with_the_scalar_kernel() {
        lanes_agree::<false>();
    }

    #[test]
    fn viscous_lanes_agree_with_the_scalar_kernel() {
        lanes_agree::<true>();
    }

    /// Prefetching the packs ahead moves no value: every lane set gives the same sums, bit for
    /// bit, with it and without, over a block of more packs than it looks ahead.
    fn prefetch_keeps_the_bits<const VISCOUS: bool>() {
        let count = 8 * (3 * prefetch::PACKS_AHEAD) + 3;
        let (hot, x, v) = block(count);
        let packs = packs(&hot);
        let sums = |set: LaneSet, prefetch: bool| {
            let input = BlockInput {
                x: &x,
                v: &v,
                elastic: (3.0e9, 2.0e9),
                viscous: (4.0e4, 7.0e4),
                count,
                prefetch,
            };
            let mut out = vec![Vec3::zeros(); x.len()];
            let inverted = block_forces::<VISCOUS>(set, &packs, &input, &mut out);
            (inverted, out)
        };
        let mut sets = Vec::new();
        if cpu_lane_set() != LaneSet::Scalar {
            sets.push(LaneSet::Avx2);
        }
        if cpu_lane_set() == LaneSet::Avx512 {
            sets.push(LaneSet::Avx512);
        }
        for set in &sets {
            let (without, with) = (sums(*set, false), sums(*set, true));
            assert_eq!(without.0, Some(None), "{set:?}");
            assert!(
                without.1.iter().any(|f| f.norm() > 0.0),
                "{set:?}: no force"
            );
            let bits = |out: &[Vec3]| -> Vec<u64> {
                out.iter()
                    .flat_map(|f| f.iter().map(|c| c.to_bits()))
                    .collect()
            };
            assert_eq!(bits(&with.1), bits(&without.1), "{set:?}");
            assert_eq!(with.0, without.0, "{set:?}");
        }
        if sets.is_empty() {
            eprintln!("skipped: this CPU has neither AVX2+FMA nor AVX-512");
        }
    }

    #[test]
    fn elastic_sums_are_the_same_bits_with_prefetch() {
        prefetch_keeps_the_bits::<false>();
    }

    #[test]
    fn viscous_sums_are_the_same_bits_with_prefetch() {
        prefetch_keeps_the_bits::<true>();
    }

    #[test]
    fn an_inverted_tetrahedron_is_found_in_its_lane() {
        let count = 13;
        let (hot, mut x, v) = block(count);
        // Tetrahedron 10 (pack 1, lane 2): push corner 1 through the opposite face.
        let t = &hot[10];
        let [a, b, c, d] = t.local.map(|l| x[l as usize]);
        x[t.local[1] as usize] = a - (b - a) + (c - a) + (d - a);
        let input = BlockInput {
            x: &x,
            v: &v,
            elastic: (1.0, 1.0),
            viscous: (0.0, 0.0),
            count,
            prefetch: false,
        };
        let set = LaneSet::detected();
        let mut out = vec![Vec3::zeros(); x.len()];
        match block_forces::<false>(set, &packs(&hot), &input, &mut out) {
            Some(inverted) => assert_eq!(inverted, Some(10)),
            None => eprintln!("skipped: no vector kernel on this CPU"),
        }
    }
}
