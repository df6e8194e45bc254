//! A deformable QDEM body: a set of tetrahedra sharing particles, as a [`Model`].
//!
//! Each step computes the Kelvin–Voigt stress and the four particle forces of every
//! tetrahedron in parallel into a buffer (paper 000 Eqs. 1–10, see [`crate::tet_kernel`]), then
//! sums them per particle over a fixed incidence list (Eq. 11). The gather runs in parallel over
//! particles, each summing its own incident entries in ascending order, so the result is
//! bit-identical for any number of threads (no atomics, no reduction-order dependence).
//! Elastic materials take a path without the viscous stress.
//!
//! For implicit and static solves the body adds its tangent (its [`crate::Linearized`] facet):
//! the small-strain linear-tetrahedron stiffness K_e = V Gᵀ D G per element, with the volume V
//! and shape-function gradients G of the current configuration, and the same operator with the
//! viscous Lamé pair for the damping C_e. This is the exact linearisation of Eqs. 1–10 about an
//! unstrained configuration (it omits the stress-dependent geometric stiffness, of the order of
//! the strain), so for small strain f(x + ∆x, v) ≈ f(x, v) − K ∆x (paper 001 Eq. 20).

use crate::error::CoreError;
use crate::material::{Lame, Material};
use crate::model::{Linearized, Model, Persistence};
use crate::stable_step::{critical_step, element_rate_bound};
use crate::state::State;
use crate::tangent::Tangent;
use crate::tet_kernel::{
    deformation_gradient, edge_matrix, strain_energy, tet_stress, vertex_forces, von_mises,
};
use crate::{Mat3, Vec3};
use rayon::prelude::*;

/// Tetrahedra per parallel task: large enough to amortise scheduling, small enough to balance.
const TET_CHUNK: usize = 512;
/// Particles per parallel task in the gather.
const PARTICLE_CHUNK: usize = 1024;

/// A deformable body of linear QDEM tetrahedra.
///
/// ```
/// use qdem_core::{Material, Model, State, TetBody, Vec3};
///
/// // One tetrahedron of volume 1/6 m³.
/// let nodes = vec![Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
/// let material = Material::elastic(1200.0, 1e6, 0.25);
/// let mut body = TetBody::new("tet", &nodes, vec![[0, 1, 2, 3]], material)?;
/// let mut state = State::at_rest(nodes);
/// body.lump_mass(&mut state.mass);
/// assert!(state.mass.iter().all(|&m| (m - 1200.0 / 6.0 / 4.0).abs() < 1e-9));
///
/// // Stretch one vertex: the body pulls it back, and its internal forces sum to zero.
/// state.position[1].x += 0.01;
/// let mut force = vec![Vec3::zeros(); state.len()];
/// body.add_forces(&state, &mut force, &mut []);
/// assert!(force[1].x < 0.0);
/// let total: Vec3 = force.iter().sum();
/// assert!(total.norm() < 1e-9 * force[1].norm());
/// # Ok::<(), qdem_core::CoreError>(())
/// ```
#[derive(Clone, Debug)]
pub struct TetBody {
    name: String,
    material: Material,
    elastic: Lame,
    viscous: Lame,
    tets: Vec<[u32; 4]>,
    dm_inv: Vec<Mat3>,
    volume: Vec<f64>,
    first: usize,
    incidence_start: Vec<u32>,
    incidence: Vec<u32>,
    tet_forces: Vec<Vec3>,
    omega_squared: f64,
    damping_rate: f64,
    /// The first tetrahedron found inverted at the last force evaluation.
    inverted: Option<usize>,
}

impl TetBody {
    /// Builds a body from tetrahedra given as indices into `reference` (the positions of all
    /// particles of the scene). Every tetrahedron must have positive reference volume.
    pub fn new(
        name: &str,
        reference: &[Vec3],
        tets: Vec<[u32; 4]>,
        material: Material,
    ) -> Result<TetBody, CoreError> {
        material.validate().map_err(|source| CoreError::Material {
            body: name.to_string(),
            source,
        })?;
        if tets.is_empty() {
            return Err(CoreError::EmptyBody(name.to_string()));
        }
        let mut dm_inv = Vec::with_capacity(tets.len());
        let mut volume = Vec::with_capacity(tets.len());
        for (index, tet) in tets.iter().enumerate() {
            for &node in tet {
                if node as usize >= reference.len() {
                    return Err(CoreError::NodeOutOfRange {
                        body: name.to_string(),
                        tet: index,
                        node,
                        count: reference.len(),
                    });
                }
            }
            let x = tet.map(|n| reference[n as usize]);
            let dm = edge_matrix(&x);
            let v = dm.determinant() / 6.0;
            let scale = dm.norm().powi(3);
            let inverse = dm.try_inverse().filter(|_| v > 1e-12 * scale);
            let Some(inverse) = inverse else {
                return Err(CoreError::BadTet {
                    body: name.to_string(),
                    tet: index,
                    volume: v,
                });
            };
            dm_inv.push(inverse);
            volume.push(v);
        }
        let (first, incidence_start, incidence) = incidence_lists(&tets);
        let elastic = material.elastic_lame();
        let viscous = material.viscous_lame();
        let omega_squared = rate_bound(&dm_inv, &material, elastic);
        let damping_rate = if material.is_elastic() {
            0.0
        } else {
            rate_bound(&dm_inv, &material, viscous)
        };
        Ok(TetBody {
            name: name.to_string(),
            tet_forces: vec![Vec3::zeros(); 4 * tets.len()],
            material,
            elastic,
            viscous,
            tets,
            dm_inv,
            volume,
            first,
            incidence_start,
            incidence,
            omega_squared,
            damping_rate,
            inverted: None,
        })
    }

    /// The body's tetrahedra (indices into the scene's particles).
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// Adds a quarter of each tetrahedron's mass to each of its particles (paper 000 §2.4).
    pub fn lump_mass(&self, mass: &mut [f64]) {
        for (tet, v) in self.tets.iter().zip(&self.volume) {
            let quarter = 0.25 * self.material.density * v;
            for &n in tet {
                mass[n as usize] += quarter;
            }
        }
    }

    /// Von Mises stress (Pa) and volumetric strain det F − 1 of every tetrahedron.
    pub fn tet_fields(&self, state: &State) -> (Vec<f64>, Vec<f64>) {
        let viscous = !self.material.is_elastic();
        (0..self.tets.len())
            .into_par_iter()
            .with_min_len(TET_CHUNK)
            .map(|e| {
                let x = self.tets[e].map(|n| state.position[n as usize]);
                let v = viscous.then(|| self.tets[e].map(|n| state.velocity[n as usize]));
                let (t, _) = tet_stress(&x, v.as_ref(), &self.dm_inv[e], self.pair(), self.vpair());
                let j = deformation_gradient(&x, &self.dm_inv[e]).determinant();
                (von_mises(&t), j - 1.0)
            })
            .unzip()
    }

    fn pair(&self) -> (f64, f64) {
        (self.elastic.lambda, self.elastic.mu)
    }

    fn vpair(&self) -> (f64, f64) {
        (self.viscous.lambda, self.viscous.mu)
    }

    /// Stage 1: stress and particle forces of every tetrahedron into the buffer.
    fn compute_tet_forces<const VISCOUS: bool>(&mut self, state: &State) {
        let (elastic, viscous) = (self.pair(), self.vpair());
        let (tets, dm_inv) = (&self.tets, &self.dm_inv);
        let inverted = self
            .tet_forces
            .par_chunks_mut(4 * TET_CHUNK)
            .enumerate()
            .map(|(chunk, out)| {
                let start = chunk * TET_CHUNK;
                let mut first_inverted = usize::MAX;
                for (local, f) in out.chunks_exact_mut(4).enumerate() {
                    let e = start + local;
                    let tet = &tets[e];
                    let x = tet.map(|n| state.position[n as usize]);
                    let v = VISCOUS.then(|| tet.map(|n| state.velocity[n as usize]));
                    let (t, cof) = tet_stress(&x, v.as_ref(), &dm_inv[e], elastic, viscous);
                    f.copy_from_slice(&vertex_forces(&t, &cof));
                    // 6 × the current volume; B = FFᵀ cannot tell an inverted tetrahedron
                    // from its mirror image, so the sign is checked here.
                    let six_volume = (x[1] - x[0]).dot(&cof.column(0));
                    let positive =
                        six_volume.partial_cmp(&0.0) == Some(std::cmp::Ordering::Greater);
                    if !positive && first_inverted == usize::MAX {
                        first_inverted = e;
                    }
                }
                first_inverted
            })
            .min()
            .unwrap_or(usize::MAX);
        self.inverted = (inverted != usize::MAX).then_some(inverted);
    }

    /// Stage 2: per-particle sums over the incidence list, in a fixed order (Eq. 11).
    fn gather(&self, force: &mut [Vec3]) {
        let count = self.incidence_start.len() - 1;
        let (starts, entries, buffer) = (&self.incidence_start, &self.incidence, &self.tet_forces);
        force[self.first..self.first + count]
            .par_iter_mut()
            .with_min_len(PARTICLE_CHUNK)
            .enumerate()
            .for_each(|(i, f)| {
                let range = starts[i] as usize..starts[i + 1] as usize;
                let mut sum = Vec3::zeros();
                for &entry in &entries[range] {
                    sum += buffer[entry as usize];
                }
                *f += sum;
            });
    }
}

/// Volume and shape-function gradients ∇N₀..∇N₃ of a tetrahedron at positions `x` (zero
/// gradients for a degenerate one, which then adds no tangent).
fn current_gradients(x: &[Vec3; 4]) -> (f64, [Vec3; 4]) {
    let dx = edge_matrix(x);
    let inverse = dx.try_inverse().unwrap_or_else(Mat3::zeros);
    let g: [Vec3; 3] = std::array::from_fn(|k| inverse.row(k).transpose());
    (
        dx.determinant() / 6.0,
        [-(g[0] + g[1] + g[2]), g[0], g[1], g[2]],
    )
}

/// Block (a, b) of the linear-tet operator V Gᵀ D G with the Lamé pair (λ, μ):
/// V (λ g_a g_bᵀ + μ g_b g_aᵀ + μ (g_a·g_b) I).
fn lame_block(volume: f64, ga: &Vec3, gb: &Vec3, (lambda, mu): (f64, f64)) -> Mat3 {
    (ga * gb.transpose() * lambda
        + gb * ga.transpose() * mu
        + Mat3::from_diagonal_element(mu * ga.dot(gb)))
        * volume
}

/// Largest element rate bound over all tetrahedra, for an elastic or a viscous Lamé pair.
fn rate_bound(dm_inv: &[Mat3], material: &Material, lame: Lame) -> f64 {
    dm_inv
        .par_iter()
        .map(|m| element_rate_bound(m, material.density, lame))
        .reduce(|| 0.0, f64::max)
}

/// Compressed incidence lists: for each particle from the smallest to the largest index the
/// tetrahedra use, the buffer entries `4·tet + corner` that belong to it, in ascending order.
fn incidence_lists(tets: &[[u32; 4]]) -> (usize, Vec<u32>, Vec<u32>) {
    let first = tets.iter().flatten().min().copied().unwrap_or(0) as usize;
    let last = tets.iter().flatten().max().copied().unwrap_or(0) as usize;
    let mut start = vec![0u32; last - first + 2];
    for &n in tets.iter().flatten() {
        start[n as usize - first + 1] += 1;
    }
    for i in 1..start.len() {
        start[i] += start[i - 1];
    }
    let mut fill = start.clone();
    let mut entries = vec![0u32; 4 * tets.len()];
    for (e, tet) in tets.iter().enumerate() {
        for (corner, &n) in tet.iter().enumerate() {
            let slot = &mut fill[n as usize - first];
            entries[*slot as usize] = (4 * e + corner) as u32;
            *slot += 1;
        }
    }
    (first, start, entries)
}

impl Model for TetBody {
    fn failure(&self, state: &State) -> Option<CoreError> {
        let tet = self.inverted?;
        let x = self.tets[tet].map(|n| state.position[n as usize]);
        Some(CoreError::Inverted {
            body: self.name.clone(),
            tet,
            det: (edge_matrix(&x) * self.dm_inv[tet]).determinant(),
            time: state.time,
        })
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn add_forces(&mut self, state: &State, force: &mut [Vec3], _torque: &mut [Vec3]) {
        if self.material.is_elastic() {
            self.compute_tet_forces::<false>(state);
        } else {
            self.compute_tet_forces::<true>(state);
        }
        self.gather(force);
    }

    fn stable_dt(&self, _state: &State) -> Option<f64> {
        Some(critical_step(self.omega_squared, self.damping_rate))
    }

    fn potential_energy(&self, state: &State) -> Option<f64> {
        let (lambda, mu) = self.pair();
        let energy = (0..self.tets.len())
            .map(|e| {
                let x = self.tets[e].map(|n| state.position[n as usize]);
                let f = deformation_gradient(&x, &self.dm_inv[e]);
                strain_energy(&f, self.volume[e], lambda, mu)
            })
            .sum();
        Some(energy)
    }

    fn linearized(&self) -> Option<&dyn Linearized> {
        Some(self)
    }

    /// No history: the forces follow from the state alone.
    fn persistence(&self) -> Persistence<'_> {
        Persistence::Stateless
    }
}

impl Linearized for TetBody {
    fn add_tangent(&self, state: &State, tangent: &mut Tangent) {
        let viscous = !self.material.is_elastic();
        for tet in &self.tets {
            let (volume, g) = current_gradients(&tet.map(|n| state.position[n as usize]));
            for (a, &i) in tet.iter().enumerate() {
                for (b, &j) in tet.iter().enumerate() {
                    let (i, j) = (i as usize, j as usize);
                    tangent.add_stiffness(i, j, &lame_block(volume, &g[a], &g[b], self.pair()));
                    if viscous {
                        tangent.add_damping(i, j, &lame_block(volume, &g[a], &g[b], self.vpair()));
                    }
                }
            }
        }
    }

    fn particles(&self) -> Vec<usize> {
        self.incidence_start
            .windows(2)
            .enumerate()
            .filter(|(_, w)| w[1] > w[0])
            .map(|(i, _)| self.first + i)
            .collect()
    }
}
