//! What a `[[measure]]` reads off a granular packing in a region V (a box or a sphere): the
//! contact stress tensor, the solid fraction, the coordination number and the kinetic energy
//! ([`measure`]). The particles are the stones of the `[granular]` sample (clumps and
//! one-sphere grains); a stone is in V when its centre of mass is (no clipping).
//!
//! **Stress** (Love–Weber, in the particle form: Christoffersen, Mehrabadi & Nemat-Nasser
//! 1981; Bagi 1996):
//!
//! σ_ij = (1/V) Σ_{p ∈ V} Σ_{c ∈ p} (x_c − x_p)_i f_j^{c→p}, symmetrised,
//!
//! over every touching contact c of every stone p in V, whatever its partner (another stone,
//! a wall, a body): x_p the stone's centre of mass, x_c the contact point (the middle of the
//! overlap along the normal: x_c = x_s + (r_s − δ/2) n from the centre x_s of the stone's
//! sphere of radius r_s, δ the overlap), f^{c→p} the force on the stone (a time-delayed
//! boundary's ghost scale included). Tension is positive (the continuum's convention): a
//! packing under gravity has σ_zz < 0. For a contact between two stones inside V the two
//! terms add up to f ⊗ l with l the branch vector between the centres, the textbook form;
//! a wall contact contributes its force times the arm from the centre to the contact point.
//! The body forces (gravity) act at x_p and contribute nothing. At rest, Σ over the stones
//! in a horizontal slab of thickness L telescopes to the forces crossing its faces: σ_zz
//! is −(the weight above the slab's mass-midplane)/A, up to the offset of the crossing
//! contacts' points from the faces (at most the largest radius, so a relative error below
//! 2 r_max / L that averages out over many contacts).
//!
//! **Solid fraction** φ = Σ_{p ∈ V} m_p / (ρ V), the stones' volumes from their masses (a
//! clump's spheres' union, `clump_mass`); porosity n = 1 − φ. A region that cuts stones
//! counts each wholly or not at all, so φ scatters by about a stone's volume over V.
//!
//! **Coordination number** Z = (Σ_{p ∈ V} number of other stones p touches) / N_V: neighbours
//! are stones (several sphere contacts between two clumps count once); walls and bodies are
//! not counted. **Kinetic energy**: Σ_{p ∈ V} ½ m v² (translation) and the rotation's ½ ω·L.

use crate::scene::MeasureRegion;
use qdem_contact::{DemContacts, Partner};
use qdem_core::{step::State, Mat3};
use std::collections::BTreeSet;

/// The stones a measure reads: per stone its centre particle and volume, and per particle
/// the stone it is a member of.
#[derive(Clone, Debug)]
pub struct Stones {
    /// Per stone: its centre particle, its first member particle and its volume (m³).
    pub stones: Vec<(usize, usize, f64)>,
    /// Per particle of the state: the stone whose member it is (`u32::MAX`: none).
    pub stone_of: Vec<u32>,
}

/// One row of a measure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measurement {
    /// The symmetrised contact stress tensor (Pa, tension positive).
    pub stress: Mat3,
    /// Solid fraction φ.
    pub solid_fraction: f64,
    /// Mean number of stones a stone in V touches.
    pub coordination: f64,
    /// Number of stones in V.
    pub stones: usize,
    /// Number of touching contacts of the stones in V (each once).
    pub contacts: usize,
    /// Translational kinetic energy of the stones in V (J).
    pub translation_energy: f64,
    /// Rotational kinetic energy of the stones in V (J).
    pub rotation_energy: f64,
}

/// Measures the stones of `stones` in `region` at `state` from `contacts`' last evaluation
/// (module docs for the definitions).
pub fn measure(
    region: &MeasureRegion,
    stones: &Stones,
    contacts: &DemContacts,
    state: &State,
) -> Measurement {
    let inside: Vec<bool> = stones
        .stones
        .iter()
        .map(|&(c, _, _)| region.contains(state.position[c].into()))
        .collect();
    let (mut stone_of_sphere, mut radius, mut center) = (Vec::new(), Vec::new(), Vec::new());
    for s in contacts.sphere_records(state) {
        stone_of_sphere.push(stones.stone_of.get(s.particle).copied().unwrap_or(u32::MAX));
        radius.push(s.radius);
        center.push(s.center);
    }
    let mut moment = Mat3::zeros();
    let mut neighbours = BTreeSet::new();
    let mut counted = 0usize;
    let is_in = |k: u32| k != u32::MAX && inside[k as usize];
    for c in contacts.touching() {
        let a = stone_of_sphere[c.first];
        let (b, other) = match c.second {
            Partner::Sphere(s) => (stone_of_sphere[s], Some(s)),
            Partner::Wall(_) => (u32::MAX, None),
        };
        if !is_in(a) && !is_in(b) {
            continue;
        }
        counted += 1;
        let r = radius[c.first];
        let overlap = match other {
            Some(s) => r + radius[s] - (c.to - c.from).norm(),
            None => r - (c.to - c.from).norm(),
        };
        let point = c.from + (r - 0.5 * overlap) * c.normal;
        let force = c.force();
        if is_in(a) {
            let arm = point - state.position[stones.stones[a as usize].0];
            moment += c.scales.0 * arm * force.transpose();
        }
        if let (true, Some(s)) = (is_in(b), other) {
            // The second sphere at the image the first touches: its stone's centre there too.
            let image = c.to - center[s];
            let arm = point - state.position[stones.stones[b as usize].0] - image;
            moment -= c.scales.1 * arm * force.transpose();
        }
        if a != u32::MAX && b != u32::MAX && a != b {
            neighbours.insert((a.min(b), a.max(b)));
        }
    }
    let volume = region.volume();
    let moment = moment / volume;
    let mut links = 0usize;
    for &(a, b) in &neighbours {
        links += usize::from(inside[a as usize]) + usize::from(inside[b as usize]);
    }
    let (mut solid, mut count, mut translation, mut rotation) = (0.0, 0usize, 0.0, 0.0);
    for (&(c, member, v), _) in stones.stones.iter().zip(&inside).filter(|(_, &i)| i) {
        solid += v;
        count += 1;
        translation += 0.5 * state.mass[c] * state.velocity[c].norm_squared();
        rotation += rotation_energy(state, c, member);
    }
    Measurement {
        stress: 0.5 * (moment + moment.transpose()),
        solid_fraction: solid / volume,
        coordination: if count == 0 {
            0.0
        } else {
            links as f64 / count as f64
        },
        stones: count,
        contacts: counted,
        translation_energy: translation,
        rotation_energy: rotation,
    }
}

/// Rotational kinetic energy of the stone with centre particle `center` and first member
/// `member`: a clump's rigid body's ½ ω·L, or a one-sphere grain's ½ J ω².
fn rotation_energy(state: &State, center: usize, member: usize) -> f64 {
    match state.rigid.body_of_member(member) {
        Some(b) => state.rigid.body_kinetic_energy(b),
        None => 0.5 * state.spin.inertia[center] * state.spin.velocity[center].norm_squared(),
    }
}

impl Stones {
    /// The stones of a `[granular]` sample: `stones` (centre particle, member particles) of a
    /// material of density `density`; `mass` the state's particle masses.
    pub fn new(stones: &[(usize, std::ops::Range<usize>)], mass: &[f64], density: f64) -> Stones {
        let mut stone_of = vec![u32::MAX; mass.len()];
        for (k, (_, members)) in stones.iter().enumerate() {
            for p in members.clone() {
                stone_of[p] = k as u32;
            }
        }
        Stones {
            stones: stones
                .iter()
                .map(|(c, members)| (*c, members.start, mass[*c] / density))
                .collect(),
            stone_of,
        }
    }
}
