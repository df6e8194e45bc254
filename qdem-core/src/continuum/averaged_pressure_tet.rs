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
//! rank's force pass reads the same bits: byte-identical for any rank count. The outputs'
//! stresses and the energy read the averages of the same strain pass and nodal average
//! ([`nodal_average`], the one implementation of Eq. 9), so a reported pressure is the one
//! the forces used, to the bit; the tangent's averaged divergence b̄_a sums in the same order.

use crate::continuum::averaged_pressure_lanes::{
    force_sums, strain_sums, ForceInput, StrainInput, StrainPack,
};
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
    /// The strain pass's weights of the tetrahedra of the blocks' packs.
    strain_packs: Vec<StrainPack>,
    /// The first particle any tetrahedron uses.
    first: usize,
    /// Per particle from `first`, the range of its corners in `corners`.
    corner_start: Vec<u32>,
    /// 4 · tet + corner of every particle's corners, the tetrahedra in block order (the
    /// order of the nodal average's sums), for the tangent's averaged divergence.
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
        for &e in &blocks.order {
            for (c, &n) in tets[e as usize].iter().enumerate() {
                let i = n as usize - first;
                corners[next[i] as usize] = 4 * e + c as u32;
                next[i] += 1;
            }
        }
        let mut nodal_volume = vec![0.0; count];
        for (tet, v) in tets.iter().zip(volume) {
            for &n in tet {
                nodal_volume[n as usize - first] += 0.25 * v;
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
            strain_packs: strain_packs(blocks, volume),
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
        let (weights, viscous) = (&self.strain_packs, self.viscous);
        strain_slots(blocks, range, weights, viscous, state, &mut self.partial);
    }

    /// The averages θ̄_a (and tr(D)‾_a) of the particles `owned` (all when `None`; else those
    /// whose owner is `me`) from the strain pass's slot sums ([`nodal_average`]).
    pub(crate) fn average(&mut self, blocks: &TetBlocks, owned: Option<(u32, &[u32])>) {
        let inv_volume = &self.inv_nodal_volume;
        nodal_average(blocks, &self.partial, inv_volume, owned, &mut self.nodal);
    }

    /// The particles' averages (θ̄_a, tr(D)‾_a, 0) at `state`, from `first`: the strain pass
    /// and the average of a step over the whole body, the same bits as the forces of a step
    /// at `state` read, for the outputs. With `small_strain`, of the linear tr ε = div u of a
    /// static solve (elastic), summed in the same order.
    fn averages_at(&self, blocks: &TetBlocks, state: &State, small_strain: bool) -> Vec<Vec3> {
        let mut partial = vec![Vec3::zeros(); blocks.nodes.len()];
        if small_strain {
            small_strain_slots(blocks, &self.quarter, state, &mut partial);
        } else {
            let weights = &self.strain_packs;
            strain_slots(
                blocks,
                0..blocks.len(),
                weights,
                self.viscous,
                state,
                &mut partial,
            );
        }
        let mut nodal = vec![Vec3::zeros(); self.nodal.len()];
        nodal_average(blocks, &partial, &self.inv_nodal_volume, None, &mut nodal);
        nodal
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
    pub(crate) fn stresses(
        &self,
        blocks: &TetBlocks,
        state: &State,
        small_strain: bool,
    ) -> Vec<Mat3> {
        let viscous = self.viscous && !small_strain;
        let nodal = self.averages_at(blocks, state, small_strain);
        (0..self.tets.len())
            .into_par_iter()
            .with_min_len(TET_CHUNK)
            .map(|e| {
                let tet = self.tets[e];
                let mean = |k: usize| corner_mean(&nodal, &tet, self.first, k);
                if small_strain {
                    let u = tet.map(|n| state.displacement(n as usize));
                    let grad = edge_matrix(&u) * self.dm_inv[e];
                    return self
                        .moduli
                        .stress(&((grad + grad.transpose()) * 0.5), mean(0), None);
                }
                let dx = edge_matrix(&tet.map(|n| state.position[n as usize]));
                let rate = viscous.then(|| {
                    let v = tet.map(|n| state.velocity[n as usize]);
                    let cof = cofactor(&dx);
                    let l = velocity_gradient(&v, &cof, dx.determinant());
                    ((l + l.transpose()) * 0.5, mean(1))
                });
                self.moduli
                    .stress(&green_strain(&(dx * self.dm_inv[e])), mean(0), rate)
            })
            .collect()
    }

    /// The elastic energy Σ_e V_e μ dev ε:dev ε + Σ_a V̄_a κ θ̄_a²/2 at `state`, with the
    /// averages θ̄_a of a step at `state`.
    pub(crate) fn energy(&self, blocks: &TetBlocks, state: &State) -> f64 {
        let deviatoric: f64 = (0..self.tets.len())
            .map(|e| {
                let x = self.tets[e].map(|n| state.position[n as usize]);
                let eps = green_strain(&(edge_matrix(&x) * self.dm_inv[e]));
                4.0 * self.quarter[e] * self.moduli.mu * deviator(&eps).norm_squared()
            })
            .sum();
        let nodal = self.averages_at(blocks, state, false);
        let volumetric: f64 = nodal
            .iter()
            .zip(&self.inv_nodal_volume)
            .filter(|(_, &inv)| inv > 0.0)
            .map(|(a, inv)| 0.5 * self.moduli.kappa * a.x * a.x / inv)
            .sum();
        deviatoric + volumetric
    }

    /// Adds the small-strain tangent at `state`'s positions: per tetrahedron the deviatoric
    /// V Gᵀ D_dev G, per particle κ V̄_a b̄_a b̄_aᵀ (and the viscous pair alike for C), b̄_a
    /// summed over the particle's tetrahedra in block order, the nodal average's order.
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

/// The strain pass over the blocks `range` at `state` into `partial` (the slot sums, laid out
/// as the blocks' node lists): each block's Σ (V_e/4) θ_e, and Σ (V_e/4) tr D_e when
/// `viscous`, per node slot, in the lanes' order
/// ([`crate::continuum::averaged_pressure_lanes::strain_sums`]), the blocks in parallel.
fn strain_slots(
    blocks: &TetBlocks,
    range: Range<usize>,
    weights: &[StrainPack],
    viscous: bool,
    state: &State,
    partial: &mut [Vec3],
) {
    if range.is_empty() {
        return;
    }
    let start = &blocks.node_start;
    let slots = start[range.start] as usize..start[range.end] as usize;
    for_blocks(&mut partial[slots], range, start, &|b, out| {
        SCRATCH.with_borrow_mut(|scratch| {
            let nodes = &blocks.nodes[start[b] as usize..start[b + 1] as usize];
            scratch.load(nodes, state, viscous);
            out.fill(Vec3::zeros());
            let packs = blocks.pack_start[b] as usize..blocks.pack_start[b + 1] as usize;
            let input = StrainInput {
                x: &scratch.x,
                v: &scratch.v,
                weights: &weights[packs.clone()],
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

/// The slot sums Σ (V_e/4) tr ε_e of the small-strain ε = sym ∇u at `state`'s displacements
/// into `partial`, each block's tetrahedra in block order as the strain pass adds them.
fn small_strain_slots(blocks: &TetBlocks, quarter: &[f64], state: &State, partial: &mut [Vec3]) {
    for b in 0..blocks.len() {
        let nodes = &blocks.nodes[blocks.node_start[b] as usize..];
        let out = &mut partial[blocks.node_start[b] as usize..];
        for k in blocks.tet_start[b] as usize..blocks.tet_start[b + 1] as usize {
            let hot = &blocks.hot[k];
            let u = hot
                .local
                .map(|l| state.displacement(nodes[l as usize] as usize));
            let theta = quarter[blocks.order[k] as usize] * (edge_matrix(&u) * hot.dm_inv).trace();
            for &l in &hot.local {
                out[l as usize].x += theta;
            }
        }
    }
}

/// The nodal average of Bonet & Burton Eq. 9, the one every reader of θ̄ uses: per particle
/// (from the blocks' `first`; those `owned` only, when given as (me, owner per particle)),
/// its block slots' sums in `partial` added in ascending block order and multiplied by its
/// `inv_volume`, into `nodal`. The order is fixed by the mesh: the same bits for any thread
/// or rank count.
fn nodal_average(
    blocks: &TetBlocks,
    partial: &[Vec3],
    inv_volume: &[f64],
    owned: Option<(u32, &[u32])>,
    nodal: &mut [Vec3],
) {
    let (starts, entries) = (&blocks.entry_start, &blocks.entries);
    nodal
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

/// ¼ (a₀ + a₁ + a₂ + a₃) of component `k` of the averages (from particle `first`) at the
/// corners of `tet`, added in the force pass's order.
fn corner_mean(nodal: &[Vec3], tet: &[u32; 4], first: usize, k: usize) -> f64 {
    let at = |c: usize| nodal[tet[c] as usize - first][k];
    0.25 * (((at(0) + at(1)) + at(2)) + at(3))
}

/// The strain ε = (F Fᵀ − I)/2 of Eq. 4.
fn green_strain(f: &Mat3) -> Mat3 {
    (f * f.transpose() - Mat3::identity()) * 0.5
}

/// The deviator e − ⅓ tr(e) I.
fn deviator(e: &Mat3) -> Mat3 {
    e - Mat3::from_diagonal_element(e.trace() / 3.0)
}

/// The strain pass's weights ([`StrainPack`]) of the tetrahedra of the blocks' packs: a
/// block's last pack repeats its last tetrahedron's, as
/// [`crate::continuum::tet_lanes::packs`] does.
fn strain_packs(blocks: &TetBlocks, volume: &[f64]) -> Vec<StrainPack> {
    let mut packs = Vec::with_capacity(blocks.packs.len());
    let mut lanes = Vec::with_capacity(PACK);
    for range in blocks.tet_start.windows(2) {
        for chunk in (range[0] as usize..range[1] as usize).step_by(PACK) {
            lanes.clear();
            lanes.extend(
                (chunk..(chunk + PACK).min(range[1] as usize))
                    .map(|k| (blocks.hot[k].dm_inv, volume[blocks.order[k] as usize])),
            );
            packs.push(StrainPack::new(&lanes));
        }
    }
    packs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuum::tet_kernel::edge_matrix;

    /// An averaged-pressure bar of 1,440 tetrahedra (several blocks), viscous, displaced and
    /// moving irregularly: its averaging, blocks and state.
    fn bar() -> (AveragedPressure, TetBlocks, State) {
        let mesh = qdem_mesh::structured_box([0.0; 3], [2.0, 0.6, 0.5], [12, 4, 5]).unwrap();
        let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
        let dm_inv: Vec<Mat3> = mesh
            .tets
            .iter()
            .map(|t| {
                edge_matrix(&t.map(|n| reference[n as usize]))
                    .try_inverse()
                    .unwrap()
            })
            .collect();
        let volume: Vec<f64> = mesh
            .tets
            .iter()
            .map(|t| edge_matrix(&t.map(|n| reference[n as usize])).determinant() / 6.0)
            .collect();
        let blocks = TetBlocks::new(&reference, &mesh.tets, &dm_inv);
        assert!(blocks.len() > 1, "the averages cross blocks");
        let material = Material {
            shear_viscosity: 40.0,
            bulk_viscosity: 25.0,
            ..Material::elastic(1100.0, 5e6, 0.499)
        };
        let averaged = AveragedPressure::new(&mesh.tets, dm_inv, &volume, &material, &blocks);
        let mut state = State::at_rest(reference);
        for (i, (x, v)) in state
            .position
            .iter_mut()
            .zip(&mut state.velocity)
            .enumerate()
        {
            let t = i as f64;
            *x += Vec3::new((1.3 * t).sin(), (0.7 * t).cos(), (2.1 * t).sin()) * 1e-3;
            *v = Vec3::new((0.9 * t).cos(), (1.7 * t).sin(), (0.4 * t).cos()) * 0.1;
        }
        (averaged, blocks, state)
    }

    /// The averages the outputs (stresses, energy) read are the bits the step's forces read:
    /// one nodal average, not a second scalar one beside the strain pass.
    #[test]
    fn the_outputs_read_the_steps_averages_to_the_bit() {
        let (mut averaged, blocks, state) = bar();
        averaged.strain_pass(&blocks, 0..blocks.len(), &state);
        averaged.average(&blocks, None);
        let outputs = averaged.averages_at(&blocks, &state, false);
        assert!(outputs.iter().any(|a| a.x != 0.0 && a.y != 0.0));
        let differ = outputs
            .iter()
            .zip(&averaged.nodal)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(differ, 0, "of {} particles", outputs.len());
    }
}
