//! The contact laws across SIMD lanes: [`HertzMindlin::force`] and [`LinearSpring::force`],
//! each with its Coulomb spring ([`tangential_force`]), for [`LANES`] touching contacts at once,
//! one per lane of an AVX-512 register (two AVX2 registers of 4).
//!
//! The equations are the scalar laws' (paper 003 §3 and paper 000 §4):
//!
//! - Hertz–Mindlin: S_n = 2E*√(R*δ), S_t = 8G*√(R*δ), F_n = (2/3) S_n δ + γ_n δ̇ with
//!   γ = 2√(5/6) ζ √(S m*); linear: F_n = k_n δ + c_n δ̇ with c = 2ζ√(k m*);
//! - the spring ξ turned into the tangent plane (its length kept), grown by v_t ∆t, the trial
//!   force F_t = −k_t ξ − γ_t v_t, capped at μ F_n⁺ with ξ = −F_t/k_t on a slide;
//! - the force on the first partner F_t − F_n n.
//!
//! The pair kernel gathers touching pairs of spheres, as the narrow phase's test found them,
//! into a [`LawLanes`] with [`LawLanes::push_spheres`], evaluates them with
//! [`LawLanes::evaluate`] and reads each lane's force and spring back in lane order
//! ([`LawLanes::force`], [`LawLanes::history`]), so it can add the forces in the same order as
//! the scalar loop. The lanes take the narrow phase's tail first ([`SpherePair::geometry`]:
//! the distance √|d|², the overlap, the normal d/|d|, the contact point's velocity, R* and m*),
//! one square root and five divisions a pair, packed, where the scalar tail took them pair by
//! pair; then the law.
//!
//! **The same bits as the scalar law.** Every operation is an IEEE addition, subtraction,
//! product, quotient or square root, each rounded once, in the order the scalar law takes them
//! (no multiply-adds: the scalar law has none), so each lane's result is the scalar law's to the
//! last bit, on any lane width: the AVX2 and AVX-512 passes and the scalar law agree. The
//! scalar law's branches become blends of both arms, with comparisons that are false on NaN as
//! the scalar `>` and `<=` are. `max(F_n, 0)` is `maxpd`, which returns 0 for a NaN F_n as
//! `f64::max` does; the two could differ only in the sign of a zero limit for F_n = −0, which
//! the laws never produce (F_n = a δ + b δ̇ with a δ ≥ +0). The instruction set is chosen at run
//! time ([`LaneSet::detected`], the tetrahedron kernel's choice, lowered by
//! `QDEM_KERNEL_LANES`); a CPU with neither set runs the scalar law.
//!
//! [`HertzMindlin::force`]: crate::dem::laws::hertz_mindlin::HertzMindlin::force
//! [`LinearSpring::force`]: crate::dem::laws::linear_spring::LinearSpring::force
//! [`tangential_force`]: crate::dem::laws::coulomb::tangential_force

use crate::dem::laws::contact_law::{ContactLaw, PairElasticity, PairGeometry, SpherePair};
use crate::dem::laws::hertz_mindlin::DAMPING_PREFACTOR;
use qdem_core::continuum::tet_lanes::LaneSet;
use qdem_core::Vec3;

/// Contacts per batch: the lanes of one AVX-512 register of f64.
pub(crate) const LANES: usize = 8;

/// One lane value per contact of the batch.
type Lane = [f64; LANES];

/// A batch of up to [`LANES`] touching contacts, structure of arrays: what the law reads of
/// each (its geometry, elasticity and spring) and what it returns (its force and spring).
/// The lanes beyond [`LawLanes::len`] hold whatever an earlier batch left; their results are
/// never read.
#[derive(Clone, Debug, Default)]
#[repr(C, align(64))]
pub(crate) struct LawLanes {
    overlap: Lane,
    normal: [Lane; 3],
    /// The contact point's relative velocity (v_a − v_b of the centres while `spheres`).
    velocity: [Lane; 3],
    /// R* (r_a while `spheres`).
    radius: Lane,
    /// m* (m_a while `spheres`).
    mass: Lane,
    friction: Lane,
    e_star: Lane,
    g_star: Lane,
    /// The spring ξ: read by the law, then its update.
    history: [Lane; 3],
    /// The force on the first partner, after [`LawLanes::evaluate`].
    force: [Lane; 3],
    /// Of sphere pairs before their geometry ([`SpherePair`]): d, |d|², r_b, m_b, ω_a, ω_b.
    separation: [Lane; 3],
    distance_squared: Lane,
    radius_b: Lane,
    mass_b: Lane,
    spin_a: [Lane; 3],
    spin_b: [Lane; 3],
    /// Whether the batch holds sphere pairs whose geometry the evaluation takes first.
    spheres: bool,
    len: usize,
}

impl LawLanes {
    /// The number of contacts in the batch.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Whether the batch holds [`LANES`] contacts.
    pub(crate) fn is_full(&self) -> bool {
        self.len == LANES
    }

    /// Empties the batch.
    pub(crate) fn clear(&mut self) {
        self.len = 0;
    }

    /// Adds the contact `g` with elasticity `e` and spring `history`; returns its lane. A
    /// batch holds contacts or sphere pairs ([`LawLanes::push_spheres`]), not both. The pair
    /// kernel pushes sphere pairs; the tests push contacts of any geometry.
    #[cfg(test)]
    pub(crate) fn push(&mut self, g: &PairGeometry, e: &PairElasticity, history: &Vec3) -> usize {
        let l = self.len;
        assert!(l < LANES, "a full batch of {LANES} contacts");
        debug_assert!(
            l == 0 || !self.spheres,
            "a contact in a batch of sphere pairs"
        );
        self.spheres = false;
        self.overlap[l] = g.overlap;
        self.radius[l] = g.radius;
        self.mass[l] = g.mass;
        self.friction[l] = g.friction;
        self.e_star[l] = e.e_star;
        self.g_star[l] = e.g_star;
        for k in 0..3 {
            self.normal[k][l] = g.normal[k];
            self.velocity[k][l] = g.velocity[k];
            self.history[k][l] = history[k];
        }
        self.len = l + 1;
        l
    }

    /// Adds the touching pair of spheres `pair` with elasticity `e` and spring `history`, its
    /// geometry to be taken by [`LawLanes::evaluate`]; returns its lane. A batch holds sphere
    /// pairs or contacts (the tests' `push`), not both.
    #[inline(always)]
    pub(crate) fn push_spheres(
        &mut self,
        pair: &SpherePair,
        e: &PairElasticity,
        history: &Vec3,
    ) -> usize {
        let l = self.len;
        assert!(l < LANES, "a full batch of {LANES} contacts");
        debug_assert!(
            l == 0 || self.spheres,
            "a sphere pair in a batch of contacts"
        );
        self.spheres = true;
        self.distance_squared[l] = pair.distance_squared;
        (self.radius[l], self.radius_b[l]) = pair.radii;
        (self.mass[l], self.mass_b[l]) = pair.masses;
        self.friction[l] = pair.friction;
        self.e_star[l] = e.e_star;
        self.g_star[l] = e.g_star;
        for k in 0..3 {
            self.separation[k][l] = pair.separation[k];
            self.velocity[k][l] = pair.velocity[k];
            self.spin_a[k][l] = pair.spins.0[k];
            self.spin_b[k][l] = pair.spins.1[k];
            self.history[k][l] = history[k];
        }
        self.len = l + 1;
        l
    }

    /// The sphere pair in lane `l`, as pushed (before the evaluation).
    fn sphere_pair(&self, l: usize) -> SpherePair {
        SpherePair {
            separation: lane_vector(&self.separation, l),
            distance_squared: self.distance_squared[l],
            radii: (self.radius[l], self.radius_b[l]),
            masses: (self.mass[l], self.mass_b[l]),
            velocity: lane_vector(&self.velocity, l),
            spins: (lane_vector(&self.spin_a, l), lane_vector(&self.spin_b, l)),
            friction: self.friction[l],
        }
    }

    /// The geometry and elasticity of the contact in lane `l`, as pushed or, for a sphere
    /// pair, as the evaluation took it.
    #[inline(always)]
    pub(crate) fn contact(&self, l: usize) -> (PairGeometry, PairElasticity) {
        let g = PairGeometry {
            overlap: self.overlap[l],
            normal: self.normal(l),
            velocity: lane_vector(&self.velocity, l),
            radius: self.radius[l],
            mass: self.mass[l],
            friction: self.friction[l],
        };
        let e = PairElasticity {
            e_star: self.e_star[l],
            g_star: self.g_star[l],
        };
        (g, e)
    }

    /// The unit normal of the contact in lane `l`.
    #[inline(always)]
    pub(crate) fn normal(&self, l: usize) -> Vec3 {
        lane_vector(&self.normal, l)
    }

    /// The overlap of the contact in lane `l`.
    #[inline(always)]
    pub(crate) fn overlap(&self, l: usize) -> f64 {
        self.overlap[l]
    }

    /// The spring of the contact in lane `l` (after [`LawLanes::evaluate`], its update).
    #[inline(always)]
    pub(crate) fn history(&self, l: usize) -> Vec3 {
        lane_vector(&self.history, l)
    }

    /// The force on the first partner of the contact in lane `l`, after
    /// [`LawLanes::evaluate`].
    #[inline(always)]
    pub(crate) fn force(&self, l: usize) -> Vec3 {
        lane_vector(&self.force, l)
    }

    /// The law over a step `dt` for every contact of the batch, with the lanes of `set`: the
    /// same bits as [`ContactLaw::force`] on each contact (module doc), after the geometry of
    /// each sphere pair, the same bits as [`SpherePair::geometry`]. A law without a lane form,
    /// or the scalar set, runs the scalar geometry and law on each contact.
    pub(crate) fn evaluate(&mut self, law: &ContactLaw, set: LaneSet, dt: f64) {
        let spheres = std::mem::take(&mut self.spheres);
        match (set, Params::of(law)) {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `detected` chooses a set only when the CPU has its features.
            (LaneSet::Avx512, Some(params)) => unsafe {
                evaluate_avx512(self, &params, spheres, dt)
            },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            (LaneSet::Avx2, Some(params)) => unsafe { evaluate_avx2(self, &params, spheres, dt) },
            _ => {
                if spheres {
                    self.geometry_scalar();
                }
                self.evaluate_scalar(law, dt)
            }
        }
    }

    /// The geometry of each sphere pair in turn, in place of what it was pushed with.
    fn geometry_scalar(&mut self) {
        for l in 0..self.len {
            let g = self.sphere_pair(l).geometry();
            self.overlap[l] = g.overlap;
            self.radius[l] = g.radius;
            self.mass[l] = g.mass;
            for k in 0..3 {
                self.normal[k][l] = g.normal[k];
                self.velocity[k][l] = g.velocity[k];
            }
        }
    }

    /// The scalar law on each contact in turn.
    fn evaluate_scalar(&mut self, law: &ContactLaw, dt: f64) {
        for l in 0..self.len {
            let mut history = self.history(l);
            let (g, e) = self.contact(l);
            let f = law.force(&g, &e, &mut history, dt);
            for k in 0..3 {
                self.history[k][l] = history[k];
                self.force[k][l] = f[k];
            }
        }
    }
}

/// Lane `l` of three lane arrays, as a vector.
#[inline(always)]
fn lane_vector(v: &[Lane; 3], l: usize) -> Vec3 {
    Vec3::new(v[0][l], v[1][l], v[2][l])
}

/// What a law adds to the lanes' common arithmetic: its stiffnesses and damping factor.
#[derive(Clone, Copy)]
enum Params {
    /// Hertz–Mindlin: the damping factor 2√(5/6) ζ, `None` without damping.
    Hertz { damping: Option<f64> },
    /// The linear spring: k_n, k_t and, with damping, (2ζ, √k_n, √k_t).
    Linear {
        normal: f64,
        tangential: f64,
        damping: Option<(f64, f64, f64)>,
    },
}

impl Params {
    /// The factors of `law`, each computed as its scalar `force` computes it; `None` for a
    /// law without a lane form (none yet: a new law may start so).
    fn of(law: &ContactLaw) -> Option<Params> {
        Some(match law {
            ContactLaw::HertzMindlin(law) => Params::Hertz {
                damping: (law.damping_ratio > 0.0).then_some(DAMPING_PREFACTOR * law.damping_ratio),
            },
            ContactLaw::Linear(law) => Params::Linear {
                normal: law.normal_stiffness,
                tangential: law.tangential_stiffness,
                damping: (law.damping_ratio > 0.0).then(|| {
                    (
                        2.0 * law.damping_ratio,
                        law.normal_stiffness.sqrt(),
                        law.tangential_stiffness.sqrt(),
                    )
                }),
            },
        })
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2")]
unsafe fn evaluate_avx512(lanes: &mut LawLanes, params: &Params, spheres: bool, dt: f64) {
    pass::<x86::Avx512>(lanes, params, spheres, dt)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn evaluate_avx2(lanes: &mut LawLanes, params: &Params, spheres: bool, dt: f64) {
    pass::<x86::Avx2>(lanes, params, spheres, dt)
}

/// The vector operations of the law, one implementation per instruction set. Every method is
/// `unsafe`: it may run only on a CPU with the set's features, inlined into a function that
/// enables them. Each is one correctly rounded IEEE operation per lane.
trait Simd {
    /// Lanes per vector.
    const N: usize;
    /// A vector of `N` f64.
    type V: Copy;
    /// A lane mask.
    type M: Copy;
    unsafe fn splat(a: f64) -> Self::V;
    /// `N` values from `a[..N]`.
    unsafe fn load(a: &[f64]) -> Self::V;
    unsafe fn store(a: Self::V, to: &mut [f64]);
    unsafe fn add(a: Self::V, b: Self::V) -> Self::V;
    unsafe fn sub(a: Self::V, b: Self::V) -> Self::V;
    unsafe fn mul(a: Self::V, b: Self::V) -> Self::V;
    unsafe fn div(a: Self::V, b: Self::V) -> Self::V;
    unsafe fn sqrt(a: Self::V) -> Self::V;
    /// −a (the sign flipped, as the scalar negation).
    unsafe fn neg(a: Self::V) -> Self::V;
    /// a > b ? a : b, so b where a is NaN (`maxpd`).
    unsafe fn max(a: Self::V, b: Self::V) -> Self::V;
    /// a > b, false on NaN.
    unsafe fn gt(a: Self::V, b: Self::V) -> Self::M;
    /// a ≤ b, false on NaN.
    unsafe fn le(a: Self::V, b: Self::V) -> Self::M;
    /// `yes` where `mask`, else `no`.
    unsafe fn select(mask: Self::M, yes: Self::V, no: Self::V) -> Self::V;
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::Simd;
    use std::arch::x86_64::*;

    /// AVX-512: 8 lanes.
    pub(super) struct Avx512;
    /// AVX2: 4 lanes.
    pub(super) struct Avx2;

    impl Simd for Avx512 {
        const N: usize = 8;
        type V = __m512d;
        type M = __mmask8;
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
        unsafe fn sqrt(a: __m512d) -> __m512d {
            _mm512_sqrt_pd(a)
        }
        #[inline(always)]
        unsafe fn neg(a: __m512d) -> __m512d {
            _mm512_xor_pd(a, _mm512_set1_pd(-0.0))
        }
        #[inline(always)]
        unsafe fn max(a: __m512d, b: __m512d) -> __m512d {
            _mm512_max_pd(a, b)
        }
        #[inline(always)]
        unsafe fn gt(a: __m512d, b: __m512d) -> __mmask8 {
            _mm512_cmp_pd_mask::<_CMP_GT_OQ>(a, b)
        }
        #[inline(always)]
        unsafe fn le(a: __m512d, b: __m512d) -> __mmask8 {
            _mm512_cmp_pd_mask::<_CMP_LE_OQ>(a, b)
        }
        #[inline(always)]
        unsafe fn select(mask: __mmask8, yes: __m512d, no: __m512d) -> __m512d {
            _mm512_mask_blend_pd(mask, no, yes)
        }
    }

    impl Simd for Avx2 {
        const N: usize = 4;
        type V = __m256d;
        type M = __m256d;
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
        unsafe fn sqrt(a: __m256d) -> __m256d {
            _mm256_sqrt_pd(a)
        }
        #[inline(always)]
        unsafe fn neg(a: __m256d) -> __m256d {
            _mm256_xor_pd(a, _mm256_set1_pd(-0.0))
        }
        #[inline(always)]
        unsafe fn max(a: __m256d, b: __m256d) -> __m256d {
            _mm256_max_pd(a, b)
        }
        #[inline(always)]
        unsafe fn gt(a: __m256d, b: __m256d) -> __m256d {
            _mm256_cmp_pd::<_CMP_GT_OQ>(a, b)
        }
        #[inline(always)]
        unsafe fn le(a: __m256d, b: __m256d) -> __m256d {
            _mm256_cmp_pd::<_CMP_LE_OQ>(a, b)
        }
        #[inline(always)]
        unsafe fn select(mask: __m256d, yes: __m256d, no: __m256d) -> __m256d {
            _mm256_blendv_pd(no, yes, mask)
        }
    }
}

/// A 3-vector of lane vectors.
type V3<S> = [<S as Simd>::V; 3];

// No closures below: a closure does not inherit the target features of the function it is
// inlined into, and one left out of line would call the intrinsics out of line.

/// The law over the batch with `S::N` lanes per vector, `LANES / S::N` vectors per batch,
/// after the geometry of its sphere pairs when `spheres`; compiled inside the functions that
/// enable the features.
#[inline(always)]
unsafe fn pass<S: Simd>(lanes: &mut LawLanes, params: &Params, spheres: bool, dt: f64) {
    for o in (0..lanes.len).step_by(S::N) {
        if spheres {
            geometry::<S>(lanes, o);
        }
        let (n, v, h) = (&lanes.normal, &lanes.velocity, &lanes.history);
        let contact = Contact::<S> {
            overlap: S::load(&lanes.overlap[o..]),
            normal: [
                S::load(&n[0][o..]),
                S::load(&n[1][o..]),
                S::load(&n[2][o..]),
            ],
            velocity: [
                S::load(&v[0][o..]),
                S::load(&v[1][o..]),
                S::load(&v[2][o..]),
            ],
            radius: S::load(&lanes.radius[o..]),
            mass: S::load(&lanes.mass[o..]),
            friction: S::load(&lanes.friction[o..]),
        };
        let mut history = [
            S::load(&h[0][o..]),
            S::load(&h[1][o..]),
            S::load(&h[2][o..]),
        ];
        let force = match *params {
            Params::Hertz { damping } => hertz::<S>(
                &contact,
                (S::load(&lanes.e_star[o..]), S::load(&lanes.g_star[o..])),
                damping,
                &mut history,
                dt,
            ),
            Params::Linear {
                normal,
                tangential,
                damping,
            } => linear::<S>(&contact, (normal, tangential), damping, &mut history, dt),
        };
        for k in 0..3 {
            S::store(history[k], &mut lanes.history[k][o..]);
            S::store(force[k], &mut lanes.force[k][o..]);
        }
    }
}

/// [`SpherePair::geometry`] of the sphere pairs in lanes `o..o + S::N`, its operations in its
/// order, stored in place of what they were pushed with.
#[inline(always)]
unsafe fn geometry<S: Simd>(lanes: &mut LawLanes, o: usize) {
    let (ra, rb) = (S::load(&lanes.radius[o..]), S::load(&lanes.radius_b[o..]));
    let (ma, mb) = (S::load(&lanes.mass[o..]), S::load(&lanes.mass_b[o..]));
    let distance = S::sqrt(S::load(&lanes.distance_squared[o..]));
    let reach = S::add(ra, rb);
    let overlap = S::sub(reach, distance);
    let mut normal = [distance; 3];
    for (n, d) in normal.iter_mut().zip(&lanes.separation) {
        *n = S::div(S::load(&d[o..]), distance);
    }
    let half = S::mul(S::splat(0.5), overlap);
    let (arm_a, arm_b) = (S::sub(ra, half), S::sub(rb, half));
    let mut spin = normal;
    for ((w, a), b) in spin.iter_mut().zip(&lanes.spin_a).zip(&lanes.spin_b) {
        *w = S::add(
            S::mul(arm_a, S::load(&a[o..])),
            S::mul(arm_b, S::load(&b[o..])),
        );
    }
    // spin × n, as nalgebra's `cross`.
    let turn = [
        S::sub(S::mul(spin[1], normal[2]), S::mul(spin[2], normal[1])),
        S::sub(S::mul(spin[2], normal[0]), S::mul(spin[0], normal[2])),
        S::sub(S::mul(spin[0], normal[1]), S::mul(spin[1], normal[0])),
    ];
    for k in 0..3 {
        let velocity = S::add(S::load(&lanes.velocity[k][o..]), turn[k]);
        S::store(velocity, &mut lanes.velocity[k][o..]);
        S::store(normal[k], &mut lanes.normal[k][o..]);
    }
    S::store(overlap, &mut lanes.overlap[o..]);
    S::store(S::div(S::mul(ra, rb), reach), &mut lanes.radius[o..]);
    S::store(S::div(S::mul(ma, mb), S::add(ma, mb)), &mut lanes.mass[o..]);
}

/// [`PairGeometry`] in lanes.
struct Contact<S: Simd> {
    overlap: S::V,
    normal: V3<S>,
    velocity: V3<S>,
    radius: S::V,
    mass: S::V,
    friction: S::V,
}

/// (a₀b₀ + a₁b₁) + a₂b₂, as nalgebra's `dot` of two 3-vectors.
#[inline(always)]
unsafe fn dot3<S: Simd>(a: &V3<S>, b: &V3<S>) -> S::V {
    S::add(
        S::add(S::mul(a[0], b[0]), S::mul(a[1], b[1])),
        S::mul(a[2], b[2]),
    )
}

/// Hertz–Mindlin ([`HertzMindlin::force`](crate::dem::laws::hertz_mindlin::HertzMindlin::force))
/// with elasticity (E*, G*) and damping factor 2√(5/6) ζ.
#[inline(always)]
unsafe fn hertz<S: Simd>(
    g: &Contact<S>,
    (e_star, g_star): (S::V, S::V),
    damping: Option<f64>,
    history: &mut V3<S>,
    dt: f64,
) -> V3<S> {
    let zero = S::splat(0.0);
    let contact_radius = S::sqrt(S::mul(g.radius, S::max(g.overlap, zero)));
    let s_n = S::mul(S::mul(S::splat(2.0), e_star), contact_radius);
    let s_t = S::mul(S::mul(S::splat(8.0), g_star), contact_radius);
    let (gamma_n, gamma_t) = match damping {
        Some(factor) => {
            let scale = S::mul(S::splat(factor), S::sqrt(g.mass));
            (S::mul(scale, S::sqrt(s_n)), S::mul(scale, S::sqrt(s_t)))
        }
        None => (zero, zero),
    };
    let rate = dot3::<S>(&g.velocity, &g.normal);
    let normal = S::add(
        S::mul(S::mul(S::splat(2.0 / 3.0), s_n), g.overlap),
        S::mul(gamma_n, rate),
    );
    let tangential = coulomb::<S>(g, rate, normal, s_t, gamma_t, history, dt);
    less_normal::<S>(tangential, normal, &g.normal)
}

/// The linear spring ([`LinearSpring::force`](crate::dem::laws::linear_spring::LinearSpring::force))
/// of stiffnesses (k_n, k_t), with damping (2ζ, √k_n, √k_t).
#[inline(always)]
unsafe fn linear<S: Simd>(
    g: &Contact<S>,
    (k_n, k_t): (f64, f64),
    damping: Option<(f64, f64, f64)>,
    history: &mut V3<S>,
    dt: f64,
) -> V3<S> {
    let rate = dot3::<S>(&g.velocity, &g.normal);
    let (c_n, c_t) = match damping {
        Some((twice_ratio, root_n, root_t)) => {
            let scale = S::mul(S::splat(twice_ratio), S::sqrt(g.mass));
            (
                S::mul(scale, S::splat(root_n)),
                S::mul(scale, S::splat(root_t)),
            )
        }
        None => (S::splat(0.0), S::splat(0.0)),
    };
    let normal = S::add(S::mul(S::splat(k_n), g.overlap), S::mul(c_n, rate));
    let tangential = coulomb::<S>(g, rate, normal, S::splat(k_t), c_t, history, dt);
    less_normal::<S>(tangential, normal, &g.normal)
}

/// F_t − F_n n.
#[inline(always)]
unsafe fn less_normal<S: Simd>(tangential: V3<S>, normal_force: S::V, n: &V3<S>) -> V3<S> {
    let mut f = tangential;
    for k in 0..3 {
        f[k] = S::sub(tangential[k], S::mul(normal_force, n[k]));
    }
    f
}

/// The tangential spring and its Coulomb slider
/// ([`tangential_force`](crate::dem::laws::coulomb::tangential_force)): the force, and the
/// spring `history` updated; `rate` is n · v.
#[inline(always)]
unsafe fn coulomb<S: Simd>(
    g: &Contact<S>,
    rate: S::V,
    normal_force: S::V,
    stiffness: S::V,
    damping: S::V,
    history: &mut V3<S>,
    dt: f64,
) -> V3<S> {
    let (n, zero) = (&g.normal, S::splat(0.0));
    let mut v_t = g.velocity;
    for k in 0..3 {
        v_t[k] = S::sub(g.velocity[k], S::mul(n[k], rate));
    }
    // The spring carried into the tangent plane, its length kept.
    let length_squared = dot3::<S>(history, history);
    let along = dot3::<S>(n, history);
    let mut projected = *history;
    for k in 0..3 {
        projected[k] = S::sub(history[k], S::mul(n[k], along));
    }
    let projected_squared = dot3::<S>(&projected, &projected);
    let stretch = S::sqrt(S::div(length_squared, projected_squared));
    let (turns, keeps) = (S::gt(length_squared, zero), S::gt(projected_squared, zero));
    let step = S::splat(dt);
    let minus_stiffness = S::neg(stiffness);
    let mut trial = v_t;
    for k in 0..3 {
        let turned = S::select(keeps, S::mul(projected[k], stretch), zero);
        history[k] = S::add(S::select(turns, turned, history[k]), S::mul(v_t[k], step));
        trial[k] = S::sub(S::mul(minus_stiffness, history[k]), S::mul(damping, v_t[k]));
    }
    // The Coulomb cap: a slide scales the trial back to μ F_n⁺ and resets the spring.
    let limit = S::mul(g.friction, S::max(normal_force, zero));
    let magnitude_squared = dot3::<S>(&trial, &trial);
    let sticks = S::le(magnitude_squared, S::mul(limit, limit));
    let scale = S::div(limit, S::sqrt(magnitude_squared));
    let springs = S::gt(stiffness, zero);
    let mut force = trial;
    for k in 0..3 {
        let sliding = S::mul(trial[k], scale);
        let reset = S::select(springs, S::div(S::neg(sliding), stiffness), zero);
        force[k] = S::select(sticks, trial[k], sliding);
        history[k] = S::select(sticks, history[k], reset);
    }
    force
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::laws::hertz_mindlin::HertzMindlin;
    use crate::dem::laws::linear_spring::LinearSpring;

    /// A reproducible uniform number in [0, 1) (a 64-bit linear congruential generator).
    struct Random(u64);

    impl Random {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }

        /// A uniform number in [lo, hi).
        fn within(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }

        fn unit(&mut self) -> Vec3 {
            Vec3::new(
                self.within(-1.0, 1.0),
                self.within(-1.0, 1.0),
                self.within(-1.0, 1.0),
            )
            .normalize()
        }
    }

    /// A touching contact of spheres of about 5 mm and 1 g with a spring ξ: zero for one in
    /// six, else of up to 20 µm in any direction (not in the current tangent plane, so the
    /// turn is exercised), with relative velocities of up to 2 m/s, so that some contacts
    /// stick and some slide.
    fn contact(random: &mut Random) -> (PairGeometry, PairElasticity, Vec3) {
        let g = PairGeometry {
            overlap: random.within(1e-7, 1e-4),
            normal: random.unit(),
            velocity: random.unit() * random.within(0.0, 2.0),
            radius: random.within(1e-3, 5e-3),
            mass: random.within(1e-4, 1e-2),
            friction: random.within(0.0, 0.8),
        };
        let young = random.within(1e7, 1e9);
        let e = PairElasticity::new((young, 0.25), Some((2.0 * young, 0.3)));
        let history = match random.next() < 1.0 / 6.0 {
            true => Vec3::zeros(),
            false => random.unit() * random.within(0.0, 2e-5),
        };
        (g, e, history)
    }

    fn laws() -> Vec<ContactLaw> {
        let linear = |damping_ratio, tangential_stiffness| {
            ContactLaw::Linear(LinearSpring {
                normal_stiffness: 1e5,
                tangential_stiffness,
                damping_ratio,
            })
        };
        vec![
            ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.0 }),
            ContactLaw::HertzMindlin(HertzMindlin {
                damping_ratio: 0.2155,
            }),
            linear(0.0, 8e4),
            linear(0.3, 8e4),
            linear(0.3, 0.0),
        ]
    }

    /// The lane sets this CPU runs: the scalar law and each vector set it has.
    fn sets() -> Vec<LaneSet> {
        let widest = LaneSet::detected();
        [LaneSet::Scalar, LaneSet::Avx2, LaneSet::Avx512]
            .into_iter()
            .filter(|set| set.width() <= widest.width())
            .collect()
    }

    /// Bits of a vector, for comparing without tolerance (and ±0 apart).
    fn bits(v: &Vec3) -> [u64; 3] {
        [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
    }

    #[test]
    fn every_lane_set_gives_the_scalar_laws_bits_on_random_contacts_sliding_and_sticking() {
        // 3,000 random touching contacts per law (Hertz–Mindlin and linear, with and without
        // damping, a linear law without tangential spring), in batches of 1 to 8 (the last
        // lanes of a short batch hold an earlier batch's contacts), three steps each with the
        // updated springs fed back: every force and spring bit for bit as the scalar law
        // gives them, on every lane set this CPU has.
        let mut random = Random(57);
        let dt = 1e-6;
        for law in laws() {
            let (mut sliding, mut sticking) = (0, 0);
            let mut batches: Vec<(LaneSet, LawLanes)> = sets()
                .into_iter()
                .map(|set| (set, LawLanes::default()))
                .collect();
            let mut left = 3000;
            while left > 0 {
                let size = (1 + (random.next() * LANES as f64) as usize).min(left);
                left -= size;
                let contacts: Vec<_> = (0..size).map(|_| contact(&mut random)).collect();
                let mut springs: Vec<Vec3> = contacts.iter().map(|c| c.2).collect();
                for _ in 0..3 {
                    let mut expected = Vec::new();
                    for ((g, e, _), spring) in contacts.iter().zip(&springs) {
                        let mut after = *spring;
                        let f = law.force(g, e, &mut after, dt);
                        let normal = -f.dot(&g.normal);
                        let tangential = (f + g.normal * normal).norm();
                        match tangential >= g.friction * normal.max(0.0) * (1.0 - 1e-9) {
                            true => sliding += 1,
                            false => sticking += 1,
                        }
                        expected.push((f, after));
                    }
                    for (set, batch) in &mut batches {
                        batch.clear();
                        for ((g, e, _), spring) in contacts.iter().zip(&springs) {
                            batch.push(g, e, spring);
                        }
                        batch.evaluate(&law, *set, dt);
                        assert_eq!(batch.len(), size);
                        for (l, (f, after)) in expected.iter().enumerate() {
                            let what = format!("{law:?}, {set:?}, lane {l} of {size}");
                            assert_eq!(bits(&batch.force(l)), bits(f), "force, {what}");
                            assert_eq!(bits(&batch.history(l)), bits(after), "spring, {what}");
                        }
                    }
                    springs = expected.iter().map(|e| e.1).collect();
                }
            }
            assert!(
                sliding > 500 && sticking > 500,
                "{law:?}: {sliding} sliding, {sticking} sticking"
            );
        }
    }

    /// A touching pair of spheres of 1–5 mm and 0.1–10 g (the narrow phase's test passed, by
    /// up to 0.1 mm), spinning at up to 20 rad/s, with a spring as [`contact`]'s.
    fn sphere_pair(random: &mut Random) -> (SpherePair, PairElasticity, Vec3) {
        let radii = (random.within(1e-3, 5e-3), random.within(1e-3, 5e-3));
        let separation = random.unit() * (radii.0 + radii.1 - random.within(1e-7, 1e-4));
        let masses = (random.within(1e-4, 1e-2), random.within(1e-4, 1e-2));
        let velocity = random.unit() * random.within(0.0, 2.0);
        let spins = (
            random.unit() * random.within(0.0, 20.0),
            random.unit() * random.within(0.0, 20.0),
        );
        let pair = SpherePair {
            separation,
            distance_squared: separation.norm_squared(),
            radii,
            masses,
            velocity,
            spins,
            friction: random.within(0.0, 0.8),
        };
        let (_, e, history) = contact(random);
        (pair, e, history)
    }

    #[test]
    fn every_lane_set_gives_the_scalar_narrow_phase_and_laws_bits_on_random_sphere_pairs() {
        // 3,000 random touching sphere pairs per law, in batches of 1 to 8 (the last lanes of
        // a short batch hold an earlier batch's pairs): every overlap, normal, contact-point
        // velocity, R*, m*, force and spring bit for bit as `SpherePair::geometry` and the
        // scalar law give them, on every lane set this CPU has.
        let mut random = Random(58);
        let dt = 1e-6;
        for law in laws() {
            let mut batches: Vec<(LaneSet, LawLanes)> = sets()
                .into_iter()
                .map(|set| (set, LawLanes::default()))
                .collect();
            let mut left = 3000;
            while left > 0 {
                let size = (1 + (random.next() * LANES as f64) as usize).min(left);
                left -= size;
                let pairs: Vec<_> = (0..size).map(|_| sphere_pair(&mut random)).collect();
                let expected: Vec<_> = pairs
                    .iter()
                    .map(|(pair, e, spring)| {
                        let (g, mut after) = (pair.geometry(), *spring);
                        let f = law.force(&g, e, &mut after, dt);
                        (g, f, after)
                    })
                    .collect();
                for (set, batch) in &mut batches {
                    batch.clear();
                    for (pair, e, spring) in &pairs {
                        batch.push_spheres(pair, e, spring);
                    }
                    batch.evaluate(&law, *set, dt);
                    for (l, (g, f, after)) in expected.iter().enumerate() {
                        let what = format!("{law:?}, {set:?}, lane {l} of {size}");
                        let (lane, _) = batch.contact(l);
                        let scalars =
                            |g: &PairGeometry| [g.overlap, g.radius, g.mass].map(f64::to_bits);
                        assert_eq!(scalars(&lane), scalars(g), "δ, R*, m*, {what}");
                        assert_eq!(bits(&lane.normal), bits(&g.normal), "normal, {what}");
                        assert_eq!(bits(&lane.velocity), bits(&g.velocity), "velocity, {what}");
                        assert_eq!(bits(&batch.force(l)), bits(f), "force, {what}");
                        assert_eq!(bits(&batch.history(l)), bits(after), "spring, {what}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_full_batch_takes_no_more_contacts() {
        let mut batch = LawLanes::default();
        let (g, e, h) = contact(&mut Random(1));
        for l in 0..LANES {
            assert!(!batch.is_full());
            assert_eq!(batch.push(&g, &e, &h), l);
        }
        assert!(batch.is_full());
        let pushed = std::panic::catch_unwind(move || batch.clone().push(&g, &e, &h));
        assert!(pushed.is_err());
    }
}
