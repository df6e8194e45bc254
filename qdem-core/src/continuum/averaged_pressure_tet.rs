//! The average nodal pressure tetrahedron (Bonet & Burton 1998, "A simple average nodal
//! pressure tetrahedral element for incompressible and nearly incompressible dynamic explicit
//! applications", Commun. Numer. Meth. Engng 14:437–449): the locking-free option of a
//! [`crate::continuum::TetBody`] for nearly incompressible materials (ν → ½), chosen per material with
//! [`Formulation::AveragedPressure`].
//!
//! The stress of the QDEM tetrahedron (paper 000 Eqs. 2, 7, 8) splits into a volumetric and a
//! deviatoric part, T_E = λ tr(ε) I + 2μ ε = κ tr(ε) I + 2μ dev(ε) with κ = λ + ⅔μ the bulk
//! modulus, and likewise T_D = κ_D tr(D) I + 2μ_D dev(D). A linear tetrahedron locks because
//! its single volumetric strain must vanish in every element as κ/μ → ∞, which a mesh of
//! linear tetrahedra cannot do in bending. Here the volumetric strain is averaged over each
//! particle's tetrahedra instead (Bonet & Burton Eqs. 9–11, with nodal volumes V̄_a = Σ V_e/4):
//!
//! - per tetrahedron e: θ_e = tr ε_e (Eq. 4) and, when viscous, tr D_e (Eq. 6);
//! - per particle a: θ̄_a = Σ_{e∋a} (V_e/4) θ_e / V̄_a, and likewise the rate (reference
//!   volumes V_e, so the average is a fixed linear map of the element values);
//! - per tetrahedron: the pressure from the mean of its corners' averages,
//!   T = κ θ̄_e I + 2μ dev ε_e + κ_D tr(D)‾_e I + 2μ_D dev D_e, and the particle forces of
//!   Eqs. 9–10 from T as in the standard kernel.
//!
//! The volumetric energy Σ_a V̄_a κ θ̄_a²/2 has exactly this pressure as its derivative, so
//! the small-strain tangent is symmetric: K = Σ_e K_dev,e + Σ_a κ V̄_a b̄_a b̄_aᵀ, with
//! b̄_a = Σ_{e∋a} (V_e/4) b_e / V̄_a the averaged divergence operator (b_e = the element's
//! shape-function gradients, b_eᵀu = tr ε_e). For a homogeneous deformation every average
//! equals its element value and the stress is the standard kernel's.
//!
//! The explicit step: θ̄_a² ≤ Σ_{e∋a} (V_e/4) θ_e² / V̄_a (Jensen), so the averaged energy
//! never exceeds the standard one, and the standard element bound ([`crate::step::stepper::stable_step`])
//! still bounds M⁻¹K: the bulk wave sets the step as before (the option removes the locking,
//! not the short step).
//!
//! Every sum runs in a fixed order (a particle's tetrahedra ascending), in parallel over
//! tetrahedra and over particles with no shared accumulator: results are bit-identical for
//! any number of threads. A run decomposed over processes refuses it ([`crate::world::World::decompose`]).

use crate::continuum::material::Material;
use crate::continuum::tet_body::{current_gradients, lame_block};
use crate::continuum::tet_kernel::{cofactor, edge_matrix, velocity_gradient, vertex_forces};
use crate::step::state::State;
use crate::step::tangent::Tangent;
use crate::{Mat3, Vec3};
use rayon::prelude::*;

/// Tetrahedra per parallel task.
const TET_CHUNK: usize = 512;
/// Particles per parallel task.
const PARTICLE_CHUNK: usize = 1024;

/// How a body's tetrahedra compute their volumetric stress.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Formulation {
    /// Each tetrahedron its own (paper 000 Eqs. 1–10): locks in bending as ν → ½.
    #[default]
    Standard,
    /// The volumetric strain (and strain rate) averaged over each particle's tetrahedra
    /// (Bonet & Burton 1998): free of volumetric locking.
    AveragedPressure,
}

impl Formulation {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Formulation::Standard => "standard",
            Formulation::AveragedPressure => "averaged-pressure",
        }
    }
}

/// The averaged-pressure forces of one body: the particles' tetrahedra, the nodal volumes and
/// the per-step buffers.
#[derive(Clone, Debug)]
pub(crate) struct AveragedPressure {
    moduli: Moduli,
    viscous: bool,
    tets: Vec<[u32; 4]>,
    dm_inv: Vec<Mat3>,
    /// Reference volume / 4 of each tetrahedron.
    quarter: Vec<f64>,
    /// The first particle any tetrahedron uses.
    first: usize,
    /// Per particle from `first`, the range of its corners in `corners`.
    corner_start: Vec<u32>,
    /// 4 · tet + corner of every particle's corners, tets ascending.
    corners: Vec<u32>,
    /// 1 / V̄_a per particle from `first` (0 for a particle of no tetrahedron).
    inv_nodal_volume: Vec<f64>,
    /// Per tetrahedron: tr ε, tr D and, after the force pass, its four forces.
    theta: Vec<(f64, f64)>,
    forces: Vec<[Vec3; 4]>,
    /// Per particle from `first`: the averages θ̄_a and tr(D)‾_a.
    nodal: Vec<(f64, f64)>,
}

impl AveragedPressure {
    /// The averaging of `tets` with their inverse reference edge matrices and reference
    /// volumes.
    pub(crate) fn new(
        tets: &[[u32; 4]],
        dm_inv: Vec<Mat3>,
        volume: &[f64],
        material: &Material,
    ) -> AveragedPressure {
        let (elastic, viscous) = (material.elastic_lame(), material.viscous_lame());
        let first = tets.iter().flatten().min().copied().unwrap_or(0) as usize;
        let last = tets.iter().flatten().max().copied().unwrap_or(0) as usize;
        let count = last + 1 - first;
        let mut corner_start = vec![0u32; count + 1];
        for &n in tets.iter().flatten() {
            corner_start[n as usize - first + 1] += 1;
        }
        for i in 0..count {
            corner_start[i + 1] += corner_start[i];
        }
        let mut next = corner_start.clone();
        let mut corners = vec![0u32; 4 * tets.len()];
        let mut nodal_volume = vec![0.0; count];
        for (e, tet) in tets.iter().enumerate() {
            for (c, &n) in tet.iter().enumerate() {
                let i = n as usize - first;
                corners[next[i] as usize] = (4 * e + c) as u32;
                next[i] += 1;
                nodal_volume[i] += 0.25 * volume[e];
            }
        }
        AveragedPressure {
            moduli: Moduli {
                kappa: elastic.lambda + 2.0 / 3.0 * elastic.mu,
                mu: elastic.mu,
                kappa_d: material.bulk_viscosity,
                mu_d: viscous.mu,
            },
            viscous: !material.is_elastic(),
            tets: tets.to_vec(),
            dm_inv,
            quarter: volume.iter().map(|v| 0.25 * v).collect(),
            first,
            corner_start,
            corners,
            inv_nodal_volume: nodal_volume
                .iter()
                .map(|&v| if v > 0.0 { 1.0 / v } else { 0.0 })
                .collect(),
            theta: vec![(0.0, 0.0); tets.len()],
            forces: vec![[Vec3::zeros(); 4]; tets.len()],
            nodal: vec![(0.0, 0.0); count],
        }
    }

    /// The forces of every tetrahedron at `state` (three parallel passes: element strains,
    /// nodal averages, element forces); returns the first inverted tetrahedron, if any.
    pub(crate) fn compute(&mut self, state: &State) -> Option<usize> {
        let (tets, dm_inv, viscous) = (&self.tets, &self.dm_inv, self.viscous);
        self.theta
            .par_iter_mut()
            .with_min_len(TET_CHUNK)
            .enumerate()
            .for_each(|(e, theta)| {
                let x = tets[e].map(|n| state.position[n as usize]);
                let dx = edge_matrix(&x);
                let eps = green_strain(&(dx * dm_inv[e]));
                let rate = if viscous {
                    let v = tets[e].map(|n| state.velocity[n as usize]);
                    let cof = cofactor(&dx);
                    velocity_gradient(&v, &cof, dx.determinant()).trace()
                } else {
                    0.0
                };
                *theta = (eps.trace(), rate);
            });
        let (theta, quarter, corners, starts) = (
            &self.theta,
            &self.quarter,
            &self.corners,
            &self.corner_start,
        );
        let inv_volume = &self.inv_nodal_volume;
        average_per_particle(theta, quarter, corners, starts, inv_volume, &mut self.nodal);
        let (nodal, first, moduli) = (&self.nodal, self.first, &self.moduli);
        let inverted = self
            .forces
            .par_iter_mut()
            .with_min_len(TET_CHUNK)
            .enumerate()
            .map(|(e, out)| {
                let tet = tets[e];
                let x = tet.map(|n| state.position[n as usize]);
                let dx = edge_matrix(&x);
                let cof = cofactor(&dx);
                let det = dx.column(0).dot(&cof.column(0));
                let mean = |f: fn(&(f64, f64)) -> f64| {
                    0.25 * tet
                        .iter()
                        .map(|&n| f(&nodal[n as usize - first]))
                        .sum::<f64>()
                };
                let eps = green_strain(&(dx * dm_inv[e]));
                let rate = viscous.then(|| {
                    let v = tet.map(|n| state.velocity[n as usize]);
                    let l = velocity_gradient(&v, &cof, det);
                    ((l + l.transpose()) * 0.5, mean(|a| a.1))
                });
                let t = moduli.stress(&eps, mean(|a| a.0), rate);
                *out = vertex_forces(&t, &cof);
                // B = FFᵀ cannot tell an inverted tetrahedron from its mirror image.
                if det.partial_cmp(&0.0) == Some(std::cmp::Ordering::Greater) {
                    usize::MAX
                } else {
                    e
                }
            })
            .min()
            .unwrap_or(usize::MAX);
        (inverted != usize::MAX).then_some(inverted)
    }

    /// The stress (Pa) of every tetrahedron at `state`: the tensor its forces follow from
    /// ([`AveragedPressure::compute`]: the corners' averaged volumetric strain with the
    /// element's own deviatoric strain), not Hooke's law on the element's own strain, whose
    /// pressure checkerboards as ν → ½. With `small_strain`, the linear ε = sym ∇u of a
    /// static solve in place of Eq. 4's, elastic only (the stress that belongs to the
    /// small-strain tangent of [`AveragedPressure::add_tangent`]).
    pub(crate) fn stresses(&self, state: &State, small_strain: bool) -> Vec<Mat3> {
        let viscous = self.viscous && !small_strain;
        let strains: Vec<(Mat3, Option<Mat3>)> = (0..self.tets.len())
            .into_par_iter()
            .with_min_len(TET_CHUNK)
            .map(|e| {
                let tet = self.tets[e];
                if small_strain {
                    let u = tet.map(|n| state.displacement(n as usize));
                    let grad = edge_matrix(&u) * self.dm_inv[e];
                    return ((grad + grad.transpose()) * 0.5, None);
                }
                let dx = edge_matrix(&tet.map(|n| state.position[n as usize]));
                let rate = viscous.then(|| {
                    let v = tet.map(|n| state.velocity[n as usize]);
                    let cof = cofactor(&dx);
                    let l = velocity_gradient(&v, &cof, dx.determinant());
                    (l + l.transpose()) * 0.5
                });
                (green_strain(&(dx * self.dm_inv[e])), rate)
            })
            .collect();
        let theta: Vec<(f64, f64)> = strains
            .iter()
            .map(|(eps, d)| (eps.trace(), d.map_or(0.0, |d| d.trace())))
            .collect();
        let mut nodal = vec![(0.0, 0.0); self.nodal.len()];
        average_per_particle(
            &theta,
            &self.quarter,
            &self.corners,
            &self.corner_start,
            &self.inv_nodal_volume,
            &mut nodal,
        );
        let mean = |tet: &[u32; 4], f: fn(&(f64, f64)) -> f64| {
            0.25 * tet
                .iter()
                .map(|&n| f(&nodal[n as usize - self.first]))
                .sum::<f64>()
        };
        self.tets
            .iter()
            .zip(strains)
            .map(|(tet, (eps, rate))| {
                let rate = rate.map(|d| (d, mean(tet, |a| a.1)));
                self.moduli.stress(&eps, mean(tet, |a| a.0), rate)
            })
            .collect()
    }

    /// Adds each particle's tetrahedron forces of the last [`AveragedPressure::compute`] to
    /// `force`, its tetrahedra in ascending order.
    pub(crate) fn add_particle_sums(&self, force: &mut [Vec3]) {
        let count = self.corner_start.len() - 1;
        let (starts, corners, forces) = (&self.corner_start, &self.corners, &self.forces);
        force[self.first..self.first + count]
            .par_iter_mut()
            .with_min_len(PARTICLE_CHUNK)
            .enumerate()
            .for_each(|(i, f)| {
                let mut sum = Vec3::zeros();
                for &k in &corners[starts[i] as usize..starts[i + 1] as usize] {
                    sum += forces[k as usize / 4][k as usize % 4];
                }
                *f += sum;
            });
    }

    /// The elastic energy Σ_e V_e μ dev ε:dev ε + Σ_a V̄_a κ θ̄_a²/2 at `state`.
    pub(crate) fn energy(&self, state: &State) -> f64 {
        let eps: Vec<Mat3> = (0..self.tets.len())
            .map(|e| {
                let x = self.tets[e].map(|n| state.position[n as usize]);
                green_strain(&(edge_matrix(&x) * self.dm_inv[e]))
            })
            .collect();
        let deviatoric: f64 = eps
            .iter()
            .zip(&self.quarter)
            .map(|(eps, q)| 4.0 * q * self.moduli.mu * deviator(eps).norm_squared())
            .sum();
        let volumetric: f64 = (0..self.inv_nodal_volume.len())
            .filter(|&i| self.inv_nodal_volume[i] > 0.0)
            .map(|i| {
                let range = self.corner_start[i] as usize..self.corner_start[i + 1] as usize;
                let sum: f64 = self.corners[range]
                    .iter()
                    .map(|&k| self.quarter[k as usize / 4] * eps[k as usize / 4].trace())
                    .sum();
                0.5 * self.moduli.kappa * sum * sum * self.inv_nodal_volume[i]
            })
            .sum();
        deviatoric + volumetric
    }

    /// Adds the small-strain tangent at `state`'s positions: per tetrahedron the deviatoric
    /// V Gᵀ D_dev G, per particle κ V̄_a b̄_a b̄_aᵀ (and the viscous pair alike for C).
    pub(crate) fn add_tangent(&self, state: &State, tangent: &mut Tangent) {
        let gradients: Vec<(f64, [Vec3; 4])> = self
            .tets
            .iter()
            .map(|t| current_gradients(&t.map(|n| state.position[n as usize])))
            .collect();
        // D_dev = 2μ (I − ⅓ m mᵀ) is the Lamé law with λ = −⅔μ.
        let deviatoric = (-2.0 / 3.0 * self.moduli.mu, self.moduli.mu);
        let deviatoric_d = (-2.0 / 3.0 * self.moduli.mu_d, self.moduli.mu_d);
        for (tet, (volume, g)) in self.tets.iter().zip(&gradients) {
            for (a, &i) in tet.iter().enumerate() {
                for (b, &j) in tet.iter().enumerate() {
                    let (i, j) = (i as usize, j as usize);
                    tangent.add_stiffness(i, j, &lame_block(*volume, &g[a], &g[b], deviatoric));
                    if self.viscous {
                        let block = lame_block(*volume, &g[a], &g[b], deviatoric_d);
                        tangent.add_damping(i, j, &block);
                    }
                }
            }
        }
        let mut b_bar: Vec<(u32, Vec3)> = Vec::new();
        for i in 0..self.inv_nodal_volume.len() {
            if self.inv_nodal_volume[i] == 0.0 {
                continue;
            }
            b_bar.clear();
            let range = self.corner_start[i] as usize..self.corner_start[i + 1] as usize;
            for &k in &self.corners[range] {
                let e = k as usize / 4;
                let (volume, g) = &gradients[e];
                let w = 0.25 * volume * self.inv_nodal_volume[i];
                for (n, gj) in self.tets[e].iter().zip(g) {
                    b_bar.push((*n, gj * w));
                }
            }
            b_bar.sort_by_key(|(n, _)| *n);
            b_bar.dedup_by(|next, kept| {
                let same = next.0 == kept.0;
                if same {
                    kept.1 += next.1;
                }
                same
            });
            // κ V̄_a b̄ b̄ᵀ with b̄ = Σ (V_e/4) g / V̄_a: κ/V̄_a (Σ (V_e/4) g)(Σ (V_e/4) g)ᵀ.
            let nodal_volume = 1.0 / self.inv_nodal_volume[i];
            for &(p, wp) in &b_bar {
                for &(q, wq) in &b_bar {
                    let outer = wp * wq.transpose() * nodal_volume;
                    tangent.add_stiffness(p as usize, q as usize, &(outer * self.moduli.kappa));
                    if self.viscous {
                        tangent.add_damping(p as usize, q as usize, &(outer * self.moduli.kappa_d));
                    }
                }
            }
        }
    }
}

/// The moduli of the split stress T = κ θ̄ I + 2μ dev ε + κ_D tr(D)‾ I + 2μ_D dev D.
#[derive(Clone, Copy, Debug)]
struct Moduli {
    /// Bulk and shear moduli κ, μ (Pa).
    kappa: f64,
    mu: f64,
    /// Bulk and shear viscosities κ_D, μ_D (Pa s).
    kappa_d: f64,
    mu_d: f64,
}

impl Moduli {
    /// The stress of a tetrahedron of strain `eps` whose corners' averaged volumetric strain
    /// has the mean `theta_bar`, with its rate of deformation D and the mean of its corners'
    /// averaged tr D when viscous (Bonet & Burton Eq. 11 with the Kelvin–Voigt part of
    /// paper 000 Eq. 2).
    #[inline]
    fn stress(&self, eps: &Mat3, theta_bar: f64, rate: Option<(Mat3, f64)>) -> Mat3 {
        let mut t =
            Mat3::from_diagonal_element(self.kappa * theta_bar) + deviator(eps) * (2.0 * self.mu);
        if let Some((d, rate_bar)) = rate {
            t += Mat3::from_diagonal_element(self.kappa_d * rate_bar)
                + deviator(&d) * (2.0 * self.mu_d);
        }
        t
    }
}

/// Per particle, the reference-volume-weighted averages (Bonet & Burton Eq. 9) of its
/// tetrahedra's `theta` pairs, into `nodal`: each particle's corners in ascending order, so
/// the sums are the same bits for any number of threads.
fn average_per_particle(
    theta: &[(f64, f64)],
    quarter: &[f64],
    corners: &[u32],
    starts: &[u32],
    inv_volume: &[f64],
    nodal: &mut [(f64, f64)],
) {
    nodal
        .par_iter_mut()
        .with_min_len(PARTICLE_CHUNK)
        .enumerate()
        .for_each(|(i, avg)| {
            let (mut t, mut r) = (0.0, 0.0);
            for &k in &corners[starts[i] as usize..starts[i + 1] as usize] {
                let e = k as usize / 4;
                t += quarter[e] * theta[e].0;
                r += quarter[e] * theta[e].1;
            }
            *avg = (t * inv_volume[i], r * inv_volume[i]);
        });
}

/// The strain ε = (F Fᵀ − I)/2 of Eq. 4.
fn green_strain(f: &Mat3) -> Mat3 {
    (f * f.transpose() - Mat3::identity()) * 0.5
}

/// The deviator e − ⅓ tr(e) I.
fn deviator(e: &Mat3) -> Mat3 {
    e - Mat3::from_diagonal_element(e.trace() / 3.0)
}
