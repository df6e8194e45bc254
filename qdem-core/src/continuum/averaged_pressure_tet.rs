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
//! A step runs in the body's blocks ([`crate::continuum::tet_blocks`]), vectorised as the
//! standard kernel ([`crate::continuum::averaged_pressure_lanes`]), in three passes: the
//! **strain pass** sums each block's (V_e/4) θ_e per node slot; the **average** adds each
//! particle's slots in ascending block order over V̄_a; the **force pass** (the standard
//! kernel's place) adds each block's forces per node slot, which the body's per-particle sums
//! add as for the standard tetrahedron. Every sum runs in an order fixed by the mesh, with no
//! shared accumulator: results are bit-identical for any number of threads. In a run
//! decomposed over processes the strain pass's slot sums of a particle another rank owns go
//! to the owner in a reverse exchange and the owner's averages come back forward
//! ([`crate::step::split::Averaging`]), so the owner averages as one process does and every
//! rank's force pass reads the same bits: byte-identical for any rank count.

use crate::continuum::averaged_pressure_lanes::{force_sums, strain_sums, ForceInput, StrainInput};
use crate::continuum::material::Material;
use crate::continuum::tet_blocks::TetBlocks;
use crate::continuum::tet_body::{current_gradients, for_blocks, lame_block};
use crate::continuum::tet_kernel::{cofactor, edge_matrix, velocity_gradient};
use crate::continuum::tet_lanes::{LaneSet, PACK};
use crate::step::state::State;
use crate::step::tangent::Tangent;
use crate::{Mat3, Vec3};
use rayon::prelude::*;
use std::cell::RefCell;
use std::ops::Range;

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

/// The averaged-pressure forces of one body: per block pack the reference volumes, the
/// nodal volumes, the per-step slot sums and nodal averages; and per tetrahedron and
/// particle's corners what the outputs, the energy and the tangent read.
#[derive(Clone, Debug)]
pub(crate) struct AveragedPressure {
    moduli: Moduli,
    viscous: bool,
    tets: Vec<[u32; 4]>,
    dm_inv: Vec<Mat3>,
    /// Reference volume / 4 of each tetrahedron.
    quarter: Vec<f64>,
    /// Reference volume / 4 of the tetrahedra of the blocks' packs, by lane.
    quarter_packs: Vec<[f64; PACK]>,
    /// The first particle any tetrahedron uses.
    first: usize,
    /// Per particle from `first`, the range of its corners in `corners`.
    corner_start: Vec<u32>,
    /// 4 · tet + corner of every particle's corners, tets ascending.
    corners: Vec<u32>,
    /// 1 / V̄_a per particle from `first` (0 for a particle of no tetrahedron).
    inv_nodal_volume: Vec<f64>,
    /// Per block node slot (laid out as the blocks' node lists): its block's Σ (V_e/4) θ_e
    /// and Σ (V_e/4) tr D_e, written by the strain pass.
    partial: Vec<Vec3>,
    /// Per particle from `first`: the averages (θ̄_a, tr(D)‾_a, 0).
    nodal: Vec<Vec3>,
}

thread_local! {
    /// A worker's copy of one block's node positions, velocities and averages.
    static SCRATCH: RefCell<Scratch> = RefCell::default();
}

/// One block's node values, copied from the particles' arrays.
#[derive(Default)]
struct Scratch {
    x: Vec<Vec3>,
    v: Vec<Vec3>,
    averages: Vec<Vec3>,
}

impl Scratch {
    /// Copies the positions of `nodes`, and their velocities when `viscous`.
    fn load(&mut self, nodes: &[u32], state: &State, viscous: bool) {
        self.x.clear();
        self.x
            .extend(nodes.iter().map(|&n| state.position[n as usize]));
        if viscous {
            self.v.clear();
            self.v
                .extend(nodes.iter().map(|&n| state.velocity[n as usize]));
        }
    }
}

impl AveragedPressure {
    /// The averaging of `tets` with their inverse reference edge matrices, reference volumes
    /// and blocks.
    pub(crate) fn new(
        tets: &[[u32; 4]],
        dm_inv: Vec<Mat3>,
        volume: &[f64],
        material: &Material,
        blocks: &TetBlocks,
    ) -> AveragedPressure {
        let (elastic, viscous) = (material.elastic_lame(), material.viscous_lame());
        let first = blocks.first;
        let count = blocks.entry_start.len() - 1;
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
            quarter_packs: quarter_packs(blocks, volume),
            first,
            corner_start,
            corners,
            inv_nodal_volume: nodal_volume
                .iter()
                .map(|&v| if v > 0.0 { 1.0 / v } else { 0.0 })
                .collect(),
            partial: vec![Vec3::zeros(); blocks.nodes.len()],
            nodal: vec![Vec3::zeros(); count],
        }
    }

    /// The strain pass over the blocks `range` at `state`: each block's Σ (V_e/4) θ_e (and
    /// tr D_e) per node slot, the blocks in parallel.
    pub(crate) fn strain_pass(&mut self, blocks: &TetBlocks, range: Range<usize>, state: &State) {
        if range.is_empty() {
            return;
        }
        let start = &blocks.node_start;
        let slots = start[range.start] as usize..start[range.end] as usize;
        let (quarter, viscous) = (&self.quarter_packs, self.viscous);
        for_blocks(&mut self.partial[slots], range, start, &|b, out| {
            SCRATCH.with_borrow_mut(|scratch| {
                let nodes = &blocks.nodes[start[b] as usize..start[b + 1] as usize];
                scratch.load(nodes, state, viscous);
                out.fill(Vec3::zeros());
                let packs = blocks.pack_start[b] as usize..blocks.pack_start[b + 1] as usize;
                let input = StrainInput {
                    x: &scratch.x,
                    v: &scratch.v,
                    quarter: &quarter[packs.clone()],
                    count: (blocks.tet_start[b + 1] - blocks.tet_start[b]) as usize,
                };
                let (set, packs) = (LaneSet::detected(), &blocks.packs[packs]);
                match viscous {
                    true => strain_sums::<true>(set, packs, &input, out),
                    false => strain_sums::<false>(set, packs, &input, out),
                }
            });
            usize::MAX
        });
    }

    /// The averages θ̄_a (and tr(D)‾_a) of the particles `owned` (all when `None`; else those
    /// whose owner is `me`): each particle's slot sums in ascending block order (Eq. 11's
    /// order, the same bits for any thread or rank count) over its nodal volume.
    pub(crate) fn average(&mut self, blocks: &TetBlocks, owned: Option<(u32, &[u32])>) {
        let (starts, entries, partial) = (&blocks.entry_start, &blocks.entries, &self.partial);
        let inv_volume = &self.inv_nodal_volume;
        self.nodal
            .par_iter_mut()
            .with_min_len(PARTICLE_CHUNK)
            .enumerate()
            .for_each(|(i, average)| {
                if owned.is_some_and(|(me, owner)| owner[i] != me) {
                    return;
                }
                let mut sum = Vec3::zeros();
                for &entry in &entries[starts[i] as usize..starts[i + 1] as usize] {
                    sum += partial[entry as usize];
                }
                *average = sum * inv_volume[i];
            });
    }

    /// The per-slot sums of the strain pass, for the reverse exchange of a decomposed run.
    pub(crate) fn partial_mut(&mut self) -> &mut [Vec3] {
        &mut self.partial
    }

    /// The particles' averages (from `first`), for the forward exchange of a decomposed run.
    pub(crate) fn nodal_mut(&mut self) -> &mut [Vec3] {
        &mut self.nodal
    }

    /// The force pass of block `b` at `state` with the particles' averages, its forces added
    /// into `out` (the block's node sums); returns the body's index of its first inverted
    /// tetrahedron, `usize::MAX` if none.
    pub(crate) fn block_forces<const VISCOUS: bool>(
        &self,
        blocks: &TetBlocks,
        b: usize,
        state: &State,
        out: &mut [Vec3],
    ) -> usize {
        SCRATCH.with_borrow_mut(|scratch| {
            let nodes =
                &blocks.nodes[blocks.node_start[b] as usize..blocks.node_start[b + 1] as usize];
            scratch.load(nodes, state, VISCOUS);
            scratch.averages.clear();
            let nodal = &self.nodal;
            let first = self.first;
            scratch
                .averages
                .extend(nodes.iter().map(|&n| nodal[n as usize - first]));
            out.fill(Vec3::zeros());
            let m = &self.moduli;
            let tets = blocks.tet_start[b] as usize..blocks.tet_start[b + 1] as usize;
            let input = ForceInput {
                x: &scratch.x,
                v: &scratch.v,
                averages: &scratch.averages,
                deviatoric: (-2.0 / 3.0 * m.mu, m.mu),
                viscous_deviatoric: (-2.0 / 3.0 * m.mu_d, m.mu_d),
                bulk: (m.kappa, m.kappa_d),
                count: tets.len(),
            };
            let packs =
                &blocks.packs[blocks.pack_start[b] as usize..blocks.pack_start[b + 1] as usize];
            let inverted = force_sums::<VISCOUS>(LaneSet::detected(), packs, &input, out);
            inverted.map_or(usize::MAX, |k| blocks.order[tets.start + k] as usize)
        })
    }

    /// The stress (Pa) of every tetrahedron at `state`: the tensor its forces follow from
    /// ([`AveragedPressure::block_forces`]: the corners' averaged volumetric strain with the
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

/// Reference volume / 4 of each tetrahedron of the blocks' packs, by lane: a block's last pack
/// repeats its last tetrahedron's, as [`crate::continuum::tet_lanes::packs`] does.
fn quarter_packs(blocks: &TetBlocks, volume: &[f64]) -> Vec<[f64; PACK]> {
    let mut packs = Vec::with_capacity(blocks.packs.len());
    for range in blocks.tet_start.windows(2) {
        let order = &blocks.order[range[0] as usize..range[1] as usize];
        for chunk in order.chunks(PACK) {
            let lane = |l: usize| 0.25 * volume[chunk[l.min(chunk.len() - 1)] as usize];
            packs.push(std::array::from_fn(lane));
        }
    }
    packs
}
