//! What a contact law sees of one contact, and the choice of law.
//!
//! Both laws share the same frame: the normal n points from sphere a to sphere b (or from the
//! sphere into the wall), the overlap δ > 0 while the surfaces interpenetrate, and v is the
//! velocity of a's contact point relative to b's. A law returns the force on a; b gets its
//! opposite, so every contact conserves momentum exactly.

use crate::dem::laws::hertz_mindlin::HertzMindlin;
use crate::dem::laws::linear_spring::LinearSpring;
use qdem_core::Vec3;

/// The geometry and kinematics of one contact at the current step.
#[derive(Clone, Copy, Debug)]
pub struct PairGeometry {
    /// Overlap δ (m), positive in contact.
    pub overlap: f64,
    /// Unit normal from a to b.
    pub normal: Vec3,
    /// Velocity of a's contact point relative to b's (m/s).
    pub velocity: Vec3,
    /// Reduced radius R* = r_a r_b / (r_a + r_b) (r_a for a wall) (m).
    pub radius: f64,
    /// Reduced mass m* = m_a m_b / (m_a + m_b) (m_a for a wall) (kg).
    pub mass: f64,
    /// Coulomb friction coefficient of the pair.
    pub friction: f64,
}

/// The two spheres of a touching pair as the narrow phase finds them, before their
/// [`PairGeometry`]: what [`SpherePair::geometry`] (one pair) and the lanes (`law_lanes.rs`,
/// several at once, to the same bits) turn into it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SpherePair {
    /// d = x_b − x_a, b's image when periodic (m).
    pub(crate) separation: Vec3,
    /// |d|², below (r_a + r_b)² and above 0.
    pub(crate) distance_squared: f64,
    /// (r_a, r_b) (m).
    pub(crate) radii: (f64, f64),
    /// The masses of the carriers (m_a, m_b) (kg).
    pub(crate) masses: (f64, f64),
    /// v_a − v_b, the centres' relative velocity (m/s).
    pub(crate) velocity: Vec3,
    /// The angular velocities (ω_a, ω_b) (rad/s).
    pub(crate) spins: (Vec3, Vec3),
    /// Coulomb friction coefficient of the pair.
    pub(crate) friction: f64,
}

impl SpherePair {
    /// The contact: overlap δ = r_a + r_b − |d|, normal n = d/|d|, the velocity of a's
    /// contact point relative to b's, v_a − v_b + ((r_a − δ/2) ω_a + (r_b − δ/2) ω_b) × n,
    /// R* = r_a r_b/(r_a + r_b) and m* = m_a m_b/(m_a + m_b).
    #[inline(always)]
    pub(crate) fn geometry(&self) -> PairGeometry {
        let ((ra, rb), (ma, mb)) = (self.radii, self.masses);
        let distance = self.distance_squared.sqrt();
        let overlap = (ra + rb) - distance;
        let normal = self.separation / distance;
        let half = 0.5 * overlap;
        let spin = (ra - half) * self.spins.0 + (rb - half) * self.spins.1;
        PairGeometry {
            overlap,
            normal,
            velocity: self.velocity + spin.cross(&normal),
            radius: ra * rb / (ra + rb),
            mass: ma * mb / (ma + mb),
            friction: self.friction,
        }
    }
}

/// Elastic constants of a pair for Hertz–Mindlin: E* and G* from both sides' E and ν.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairElasticity {
    /// Effective modulus E*, 1/E* = (1 − ν_a²)/E_a + (1 − ν_b²)/E_b (Pa).
    pub e_star: f64,
    /// Effective shear modulus G*, 1/G* = 2(2 − ν_a)(1 + ν_a)/E_a + (same for b) (Pa).
    pub g_star: f64,
}

impl PairElasticity {
    /// The pair of two elastic solids (E in Pa, ν); `None` for b makes b rigid.
    pub fn new(a: (f64, f64), b: Option<(f64, f64)>) -> PairElasticity {
        let compliance =
            |(e, nu): (f64, f64)| ((1.0 - nu * nu) / e, 2.0 * (2.0 - nu) * (1.0 + nu) / e);
        let (ca, sa) = compliance(a);
        let (cb, sb) = b.map_or((0.0, 0.0), compliance);
        PairElasticity {
            e_star: 1.0 / (ca + cb),
            g_star: 1.0 / (sa + sb),
        }
    }
}

/// The contact law of a scene's `[contact]` table.
#[derive(Clone, Debug, PartialEq)]
pub enum ContactLaw {
    /// Linear Voigt spring and Coulomb slider (`law = "linear"`, paper 000 §4).
    Linear(LinearSpring),
    /// Hertz–Mindlin with a Mohr–Coulomb limit (`law = "hertz-mindlin"`, paper 003 §3).
    HertzMindlin(HertzMindlin),
}

impl ContactLaw {
    /// The force on a, updating the tangential spring `history` over a step `dt`.
    #[inline(always)]
    pub fn force(
        &self,
        g: &PairGeometry,
        elasticity: &PairElasticity,
        history: &mut Vec3,
        dt: f64,
    ) -> Vec3 {
        match self {
            ContactLaw::Linear(law) => law.force(g, history, dt),
            ContactLaw::HertzMindlin(law) => law.force(g, elasticity, history, dt),
        }
    }

    /// Elastic energy stored in the contact (J): normal spring plus tangential spring.
    pub fn energy(&self, g: &PairGeometry, elasticity: &PairElasticity, history: &Vec3) -> f64 {
        match self {
            ContactLaw::Linear(law) => law.energy(g, history),
            ContactLaw::HertzMindlin(law) => law.energy(g, elasticity, history),
        }
    }

    /// Normal and tangential stiffness (N/m) of a contact at overlap `overlap` with reduced
    /// radius `radius`, for the stable-step bound.
    pub fn stiffness(&self, overlap: f64, radius: f64, elasticity: &PairElasticity) -> (f64, f64) {
        match self {
            ContactLaw::Linear(law) => (law.normal_stiffness, law.tangential_stiffness),
            ContactLaw::HertzMindlin(_) => HertzMindlin::stiffness(overlap, radius, elasticity),
        }
    }

    /// The dashpot (N s/m) the law puts beside a spring of stiffness `stiffness` (N/m) on a
    /// pair of reduced mass `mass` (kg): 2ζ√(k m*) for the linear law, 2√(5/6) ζ √(S m*) for
    /// Hertz–Mindlin; 0 without damping.
    pub fn dashpot(&self, stiffness: f64, mass: f64) -> f64 {
        let prefactor = match self {
            ContactLaw::Linear(_) => 2.0,
            ContactLaw::HertzMindlin(_) => crate::dem::laws::hertz_mindlin::DAMPING_PREFACTOR,
        };
        prefactor * self.damping_ratio() * (stiffness * mass).sqrt()
    }

    /// The damping ratio ζ of the law.
    pub fn damping_ratio(&self) -> f64 {
        match self {
            ContactLaw::Linear(law) => law.damping_ratio,
            ContactLaw::HertzMindlin(law) => law.damping_ratio,
        }
    }
}
