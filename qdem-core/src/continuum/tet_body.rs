//! A deformable QDEM body: a set of tetrahedra sharing particles, as a [`Model`].
//!
//! Each step computes the Kelvin–Voigt stress and the four particle forces of every
//! tetrahedron (paper 000 Eqs. 1–10, see [`crate::continuum::tet_kernel`]) block by block: the blocks of
//! [`crate::continuum::tet_blocks`] run in parallel, each against a cached copy of its nodes' positions,
//! summing its forces per node; a per-particle sum then adds each particle's block sums in
//! ascending block order (Eq. 11). Blocks are fixed by the mesh, so every particle sums its
//! contributions in the same order for any number of threads: results are bit-identical (no
//! atomics, no reduction-order dependence).
//! Elastic materials take a path without the viscous stress.
//!
//! For implicit and static solves the body adds its tangent (its [`crate::step::Linearized`] facet):
//! the small-strain linear-tetrahedron stiffness K_e = V Gᵀ D G per element, with the volume V
//! and shape-function gradients G of the current configuration, and the same operator with the
//! viscous Lamé pair for the damping C_e. This is the exact linearisation of Eqs. 1–10 about an
//! unstrained configuration (it omits the stress-dependent geometric stiffness, of the order of
//! the strain), so for small strain f(x + ∆x, v) ≈ f(x, v) − K ∆x (paper 001 Eq. 20).

use crate::continuum::averaged_pressure_tet::{AveragedPressure, Formulation};
use crate::continuum::material::{Lame, Material};
use crate::continuum::prefetch;
use crate::continuum::stable_step::{critical_step, element_rate_bound};
use crate::continuum::tet_blocks::{BlockLayout, TetBlocks};
use crate::continuum::tet_kernel::{
    deformation_gradient, edge_matrix, strain_energy, tet_forces, tet_stress,
};
use crate::continuum::tet_lanes::{block_forces, BlockInput, LaneSet};
use crate::error::CoreError;
use crate::step::model::{Deformable, Linearized, Model, Persistence};
use crate::step::split::{Averaging, NodalValues};
use crate::step::split::{BodyLayout, BodySplit};
use crate::step::split::{Evaluation, Facets, Ownership, Part, PartialSums, Reads};
use crate::step::state::State;
use crate::step::tangent::Tangent;
use crate::{Mat3, Vec3};
use rayon::prelude::*;
use std::sync::Mutex;

/// Tetrahedra per parallel task in the per-element fields.
const TET_CHUNK: usize = 512;
/// Particles per parallel task in the per-particle sums.
const PARTICLE_CHUNK: usize = 1024;

/// Cost of a viscous tetrahedron relative to an elastic one, for the decomposition's cut of
/// the blocks: the viscous path costs about 1.6 times the elastic one (docs/BENCHMARKS.md,
/// kernel section).
const VISCOUS_COST: f64 = 1.6;

/// A deformable body of linear QDEM tetrahedra.
///
/// ```
/// use qdem_core::{continuum::Material, step::Model, step::State, continuum::TetBody, Vec3};
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
/// # Ok::<(), qdem_core::error::CoreError>(())
/// ```
#[derive(Clone, Debug)]
pub struct TetBody {
    name: String,
    material: Material,
    elastic: Lame,
    viscous: Lame,
    tets: Vec<[u32; 4]>,
    volume: Vec<f64>,
    blocks: TetBlocks,
    /// Per block node, the sum of its block's tetrahedron forces (laid out like the blocks'
    /// node lists), written by the block pass and read by the per-particle sums.
    sums: Vec<Vec3>,
    scratch: ScratchPool,
    omega_squared: f64,
    damping_rate: f64,
    /// The first tetrahedron found inverted at the last force evaluation.
    inverted: Option<usize>,
    /// In a run decomposed over processes, this process's share of the body
    /// ([`crate::parallel::decomposition`]); `None`: the whole body.
    split: Option<BodySplit>,
    /// The averaged-pressure forces ([`crate::continuum::averaged_pressure_tet`]) when the
    /// body's material asks for them; `None`: the standard kernel.
    averaged: Option<Box<AveragedPressure>>,
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
        let blocks = TetBlocks::new(reference, &tets, &dm_inv);
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
            sums: vec![Vec3::zeros(); blocks.nodes.len()],
            material,
            elastic,
            viscous,
            tets,
            volume,
            blocks,
            scratch: ScratchPool::default(),
            omega_squared,
            damping_rate,
            inverted: None,
            split: None,
            averaged: None,
        })
    }

    /// The body with its tetrahedra's volumetric stress computed by `formulation`
    /// ([`crate::continuum::averaged_pressure_tet`]); [`Formulation::Standard`] is the default.
    pub fn with_formulation(mut self, formulation: Formulation) -> TetBody {
        self.averaged = match formulation {
            Formulation::Standard => None,
            Formulation::AveragedPressure => {
                let dm_inv = (0..self.tets.len()).map(|e| *self.blocks.dm_inv(e));
                let averaged = AveragedPressure::new(
                    &self.tets,
                    dm_inv.collect(),
                    &self.volume,
                    &self.material,
                    &self.blocks,
                );
                Some(Box::new(averaged))
            }
        };
        self
    }

    /// How the body's tetrahedra compute their volumetric stress.
    pub fn formulation(&self) -> Formulation {
        match self.averaged {
            Some(_) => Formulation::AveragedPressure,
            None => Formulation::Standard,
        }
    }

    /// The body's tetrahedra (indices into the scene's particles).
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// How the tetrahedra are cut into blocks for the force pass ([`crate::continuum::tet_blocks`]).
    pub fn block_layout(&self) -> BlockLayout {
        self.blocks.layout()
    }

    /// The blocks this process computes: in a decomposed run its share, else all.
    fn my_blocks(&self) -> std::ops::Range<usize> {
        self.split
            .as_ref()
            .map_or(0..self.blocks.len(), |s| s.mine.clone())
    }

    /// What a decomposition reads of the blocks.
    fn body_layout(&self) -> BodyLayout<'_> {
        let b = &self.blocks;
        BodyLayout {
            tet_cost: match self.material.is_elastic() {
                true => 1.0,
                false => VISCOUS_COST,
            },
            tet_start: &b.tet_start,
            node_start: &b.node_start,
            nodes: &b.nodes,
            first: b.first,
            entry_start: &b.entry_start,
            entries: &b.entries,
        }
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

    /// The stress (Pa) of every tetrahedron, the tensor its forces follow from (paper 000
    /// Eq. 2, with the viscous part when the material has one: the Cauchy stress of the
    /// kernel, [`crate::continuum::tet_kernel::von_mises`] of it is the equivalent stress;
    /// in [`Formulation::AveragedPressure`], with the averaged pressure its forces use), and
    /// its volumetric strain det F − 1.
    pub fn tet_fields(&self, state: &State) -> (Vec<Mat3>, Vec<f64>) {
        let Some(averaged) = &self.averaged else {
            return self.standard_fields(state);
        };
        let volumetric = (0..self.tets.len())
            .into_par_iter()
            .with_min_len(TET_CHUNK)
            .map(|e| self.volumetric_strain(e, &self.tets[e].map(|n| state.position[n as usize])))
            .collect();
        (averaged.stresses(&self.blocks, state, false), volumetric)
    }

    /// [`TetBody::tet_fields`] of the standard tetrahedron, in one pass.
    fn standard_fields(&self, state: &State) -> (Vec<Mat3>, Vec<f64>) {
        let viscous = !self.material.is_elastic();
        (0..self.tets.len())
            .into_par_iter()
            .with_min_len(TET_CHUNK)
            .map(|e| {
                let x = self.tets[e].map(|n| state.position[n as usize]);
                let v = viscous.then(|| self.tets[e].map(|n| state.velocity[n as usize]));
                let dm_inv = self.blocks.dm_inv(e);
                let (t, _) = tet_stress(&x, v.as_ref(), dm_inv, self.pair(), self.vpair());
                (t, self.volumetric_strain(e, &x))
            })
            .unzip()
    }

    /// The volumetric strain det F − 1 of tetrahedron `e` at its corners' positions `x`.
    fn volumetric_strain(&self, e: usize, x: &[Vec3; 4]) -> f64 {
        deformation_gradient(x, self.blocks.dm_inv(e)).determinant() - 1.0
    }

    /// The small-strain stress σ = λ tr(ε) I + 2μ ε of every tetrahedron, ε = sym(∇u) with
    /// ∇u = du · dX⁻¹ from the particles' displacements (the linear-tetrahedron stress that
    /// belongs to a static solve's answer, [`crate::solvers::StaticSolver`]: exact for any
    /// displacement that is linear in space, without the O(ε) of [`TetBody::tet_fields`]'s
    /// finite-strain tensor). In [`Formulation::AveragedPressure`], the deviatoric part of
    /// each element's own ε with the pressure κ θ̄ of its corners' averaged tr ε, the stress
    /// of that formulation's small-strain tangent.
    pub fn small_strain_stresses(&self, state: &State) -> Vec<Mat3> {
        if let Some(averaged) = &self.averaged {
            return averaged.stresses(&self.blocks, state, true);
        }
        let (lambda, mu) = self.pair();
        (0..self.tets.len())
            .into_par_iter()
            .with_min_len(TET_CHUNK)
            .map(|e| {
                let u = self.tets[e].map(|n| state.displacement(n as usize));
                let grad = edge_matrix(&u) * self.blocks.dm_inv(e);
                let eps = (grad + grad.transpose()) * 0.5;
                Mat3::from_diagonal_element(lambda * eps.trace()) + eps * (2.0 * mu)
            })
            .collect()
    }

    fn pair(&self) -> (f64, f64) {
        (self.elastic.lambda, self.elastic.mu)
    }

    fn vpair(&self) -> (f64, f64) {
        (self.viscous.lambda, self.viscous.mu)
    }

    /// Stage 1: every block's tetrahedra (this process's blocks, in a decomposed run), their
    /// forces summed per block node into `self.sums` ([`crate::continuum::tet_blocks`]), the blocks in
    /// parallel.
    fn compute_block_sums<const VISCOUS: bool>(&mut self, state: &State) {
        let range = self.my_blocks();
        self.inverted = None;
        if range.is_empty() {
            return;
        }
        self.scratch.fit(rayon::current_num_threads());
        let mut sums = std::mem::take(&mut self.sums);
        let this = &*self;
        let start = &self.blocks.node_start;
        let inverted = for_blocks(
            &mut sums[start[range.start] as usize..start[range.end] as usize],
            range,
            start,
            &|b, out| match &this.averaged {
                Some(averaged) => averaged.block_forces::<VISCOUS>(&this.blocks, b, state, out),
                None => {
                    let mut scratch = this.scratch.for_this_thread();
                    this.block_pass::<VISCOUS>(b, state, out, &mut scratch)
                }
            },
        );
        self.sums = sums;
        self.inverted = (inverted != usize::MAX).then_some(inverted);
    }

    /// The tetrahedra of block `b` against a local copy of its nodes' positions (and
    /// velocities), their forces added into `out` (the block's sums, one per node, in tet
    /// order). Returns the body's index of its first inverted tetrahedron, `usize::MAX` if none.
    fn block_pass<const VISCOUS: bool>(
        &self,
        b: usize,
        state: &State,
        out: &mut [Vec3],
        scratch: &mut Scratch,
    ) -> usize {
        let blocks = &self.blocks;
        let nodes = &blocks.nodes[blocks.node_start[b] as usize..blocks.node_start[b + 1] as usize];
        let prefetch = prefetch::enabled();
        scratch.load(
            nodes,
            &state.position,
            VISCOUS.then_some(&state.velocity[..]),
            prefetch,
        );
        out.fill(Vec3::zeros());
        let (elastic, viscous) = (self.pair(), self.vpair());
        let range = blocks.tet_start[b] as usize..blocks.tet_start[b + 1] as usize;
        let packs = &blocks.packs[blocks.pack_start[b] as usize..blocks.pack_start[b + 1] as usize];
        let input = BlockInput {
            x: &scratch.x,
            v: &scratch.v,
            elastic,
            viscous,
            count: range.len(),
            prefetch,
        };
        if let Some(inverted) = block_forces::<VISCOUS>(LaneSet::detected(), packs, &input, out) {
            return inverted.map_or(usize::MAX, |k| blocks.order[range.start + k] as usize);
        }
        let mut first_inverted = usize::MAX;
        for (k, hot) in range.clone().zip(&blocks.hot[range]) {
            let x = corners(&scratch.x, hot.local);
            let v = if VISCOUS {
                corners(&scratch.v, hot.local)
            } else {
                x
            };
            let (forces, six_volume) = tet_forces::<VISCOUS>(&x, &v, &hot.dm_inv, elastic, viscous);
            for (&l, f) in hot.local.iter().zip(forces) {
                out[l as usize] += f;
            }
            // B = FFᵀ cannot tell an inverted tetrahedron from its mirror image, so the sign
            // of the volume is checked here.
            if six_volume.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                first_inverted = first_inverted.min(blocks.order[k] as usize);
            }
        }
        first_inverted
    }

    /// Stage 2: per-particle sums of its block entries, in ascending block order (Eq. 11);
    /// in a decomposed run, of the particles this process owns only.
    fn add_particle_sums(&self, force: &mut [Vec3]) {
        let blocks = &self.blocks;
        let count = blocks.entry_start.len() - 1;
        let (starts, entries, sums) = (&blocks.entry_start, &blocks.entries, &self.sums);
        // A rank owns a particle only where it computes the particle's first block.
        if self.split.as_ref().is_some_and(|s| s.mine.is_empty()) {
            return;
        }
        let owner = self.split.as_ref().map(|s| (s.me, &s.owner[..]));
        force[blocks.first..blocks.first + count]
            .par_iter_mut()
            .with_min_len(PARTICLE_CHUNK)
            .enumerate()
            .for_each(|(i, f)| {
                if owner.is_some_and(|(me, owner)| owner[i] != me) {
                    return;
                }
                let range = starts[i] as usize..starts[i + 1] as usize;
                let mut sum = Vec3::zeros();
                for &entry in &entries[range] {
                    sum += sums[entry as usize];
                }
                *f += sum;
            });
    }
}

/// The four values of a tetrahedron's corners (written out: `array::map` is not inlined here).
#[inline(always)]
fn corners(values: &[Vec3], local: [u16; 4]) -> [Vec3; 4] {
    let [a, b, c, d] = local.map(usize::from);
    [values[a], values[b], values[c], values[d]]
}

/// Runs `pass(b, sums of b)` for the blocks in `range` in parallel, splitting `sums` (laid out
/// per block by `node_start`) between them; returns the smallest index `pass` returned.
pub(crate) fn for_blocks(
    sums: &mut [Vec3],
    range: std::ops::Range<usize>,
    node_start: &[u32],
    pass: &(dyn Fn(usize, &mut [Vec3]) -> usize + Sync),
) -> usize {
    if range.len() == 1 {
        return pass(range.start, sums);
    }
    let mid = range.start + range.len() / 2;
    let (left, right) = sums.split_at_mut((node_start[mid] - node_start[range.start]) as usize);
    let (a, b) = rayon::join(
        || for_blocks(left, range.start..mid, node_start, pass),
        || for_blocks(right, mid..range.end, node_start, pass),
    );
    a.min(b)
}

/// A worker's copy of one block's node positions and velocities.
#[derive(Debug, Default)]
struct Scratch {
    x: Vec<Vec3>,
    v: Vec<Vec3>,
}

impl Scratch {
    /// Copies the positions (and velocities, when given) of `nodes`, with `prefetch` asking
    /// for the values [`prefetch::NODES_AHEAD`] nodes ahead (the same copies either way).
    fn load(
        &mut self,
        nodes: &[u32],
        position: &[Vec3],
        velocity: Option<&[Vec3]>,
        prefetch: bool,
    ) {
        copy_nodes(&mut self.x, nodes, position, prefetch);
        if let Some(velocity) = velocity {
            copy_nodes(&mut self.v, nodes, velocity, prefetch);
        }
    }
}

/// `to` = the `values` of `nodes`, in order; with `prefetch`, each copy asks for the value
/// [`prefetch::NODES_AHEAD`] nodes further on.
fn copy_nodes(to: &mut Vec<Vec3>, nodes: &[u32], values: &[Vec3], prefetch: bool) {
    to.clear();
    if !prefetch {
        to.extend(nodes.iter().map(|&n| values[n as usize]));
        return;
    }
    to.extend(nodes.iter().enumerate().map(|(k, &n)| {
        if let Some(&ahead) = nodes.get(k + prefetch::NODES_AHEAD) {
            prefetch::lines(&values[ahead as usize]);
        }
        values[n as usize]
    }));
}

/// One [`Scratch`] per worker thread, kept from step to step (no allocation once warm). A
/// clone starts empty.
#[derive(Debug, Default)]
struct ScratchPool(Vec<Mutex<Scratch>>);

impl Clone for ScratchPool {
    fn clone(&self) -> ScratchPool {
        ScratchPool::default()
    }
}

impl ScratchPool {
    /// At least one scratch per thread of a pool of `threads`.
    fn fit(&mut self, threads: usize) {
        while self.0.len() < threads.max(1) {
            self.0.push(Mutex::default());
        }
    }

    /// The calling worker's scratch (each worker runs one block at a time, so the lock is
    /// never contended).
    fn for_this_thread(&self) -> std::sync::MutexGuard<'_, Scratch> {
        let i = rayon::current_thread_index().unwrap_or(0) % self.0.len();
        self.0[i]
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// Volume and shape-function gradients ∇N₀..∇N₃ of a tetrahedron at positions `x` (zero
/// gradients for a degenerate one, which then adds no tangent).
pub(crate) fn current_gradients(x: &[Vec3; 4]) -> (f64, [Vec3; 4]) {
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
pub(crate) fn lame_block(volume: f64, ga: &Vec3, gb: &Vec3, (lambda, mu): (f64, f64)) -> Mat3 {
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

impl Deformable for TetBody {
    fn tets(&self) -> &[[u32; 4]] {
        TetBody::tets(self)
    }

    fn tet_fields(&self, state: &State) -> (Vec<Mat3>, Vec<f64>) {
        TetBody::tet_fields(self, state)
    }

    fn small_strain_stresses(&self, state: &State) -> Vec<Mat3> {
        TetBody::small_strain_stresses(self, state)
    }

    fn averages_pressure(&self) -> bool {
        self.averaged.is_some()
    }
}

impl Model for TetBody {
    fn failure(&self, state: &State) -> Option<CoreError> {
        let tet = self.inverted?;
        let x = self.tets[tet].map(|n| state.position[n as usize]);
        Some(CoreError::Inverted {
            body: self.name.clone(),
            tet,
            det: (edge_matrix(&x) * self.blocks.dm_inv(tet)).determinant(),
            time: state.time,
        })
    }

    fn name(&self) -> &str {
        &self.name
    }

    /// The nodes of its own blocks: in a decomposed run, the rank's particles and its halo.
    fn reads(&mut self) -> Reads<'_> {
        Reads::Split(self)
    }

    fn add_forces(&mut self, state: &State, force: &mut [Vec3], _torque: &mut [Vec3]) {
        // One process runs a decomposed run's stages, each exchange over one rank.
        if self.averaged.is_some() {
            self.partial(state);
            self.average();
        }
        self.compute(state);
        self.add_particle_sums(force);
    }

    fn deformable(&self) -> Option<&dyn Deformable> {
        Some(self)
    }

    fn stable_dt(&self, _state: &State) -> Option<f64> {
        Some(critical_step(self.omega_squared, self.damping_rate))
    }

    fn potential_energy(&self, state: &State) -> Option<f64> {
        if let Some(averaged) = &self.averaged {
            return Some(averaged.energy(&self.blocks, state));
        }
        let (lambda, mu) = self.pair();
        let energy = (0..self.tets.len())
            .map(|e| {
                let x = self.tets[e].map(|n| state.position[n as usize]);
                let f = deformation_gradient(&x, self.blocks.dm_inv(e));
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

/// In a decomposed run a rank computes the blocks the decomposition gives it
/// ([`crate::parallel::decomposition`]) and sums the particles it owns; the block sums of a
/// node another rank owns go to the owner in the exchange's reverse stage.
impl Ownership for TetBody {
    fn split(&mut self, part: Option<Part>) {
        self.split = part.and_then(|p| p.body);
    }
}

impl Facets for TetBody {
    fn body(&self) -> Option<BodyLayout<'_>> {
        Some(self.body_layout())
    }

    fn evaluation(&mut self) -> Option<&mut dyn Evaluation> {
        Some(self)
    }

    fn averaging(&mut self) -> Option<&mut dyn Averaging> {
        self.averaged.is_some().then_some(self)
    }

    fn reverse_sums(&mut self) -> Option<PartialSums<'_>> {
        let plan = self.split.as_mut().and_then(|s| s.exchange.as_mut())?;
        Some(PartialSums {
            sums: &mut self.sums,
            plan,
        })
    }
}

impl Evaluation for TetBody {
    /// Stage 1 of Eqs. 9–11: the block sums of this rank's blocks (of an averaged-pressure
    /// body, with the averages of [`Averaging`] at `state`).
    fn compute(&mut self, state: &State) {
        if self.material.is_elastic() {
            self.compute_block_sums::<false>(state);
        } else {
            self.compute_block_sums::<true>(state);
        }
    }

    fn apply(&mut self, force: &mut [Vec3], _torque: &mut [Vec3]) {
        self.add_particle_sums(force);
    }
}

/// The nodal averages of an averaged-pressure body in a decomposed run: the strain pass over
/// this rank's blocks, whose slot sums for other ranks' particles go to their owners; each
/// owner's averages, which come back to the ranks whose blocks hold the particle.
impl Averaging for TetBody {
    fn partial(&mut self, state: &State) {
        let range = self.my_blocks();
        if let Some(averaged) = &mut self.averaged {
            averaged.strain_pass(&self.blocks, range, state);
        }
    }

    fn partial_sums(&mut self) -> Option<PartialSums<'_>> {
        let plan = self.split.as_mut().and_then(|s| s.exchange.as_mut())?;
        let sums = self.averaged.as_mut()?.partial_mut();
        Some(PartialSums { sums, plan })
    }

    fn average(&mut self) {
        let owned = self.split.as_ref().map(|s| (s.me, &s.owner[..]));
        if let Some(averaged) = &mut self.averaged {
            averaged.average(&self.blocks, owned);
        }
    }

    fn averages(&mut self) -> Option<NodalValues<'_>> {
        let plan = self.split.as_mut().and_then(|s| s.exchange.as_mut())?;
        let values = self.averaged.as_mut()?.nodal_mut();
        Some(NodalValues {
            values,
            nodes: &self.blocks.nodes,
            first: self.blocks.first,
            plan,
        })
    }
}

impl Linearized for TetBody {
    fn add_tangent(&self, state: &State, tangent: &mut Tangent) {
        if let Some(averaged) = &self.averaged {
            return averaged.add_tangent(state, tangent);
        }
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
        self.blocks
            .entry_start
            .windows(2)
            .enumerate()
            .filter(|(_, w)| w[1] > w[0])
            .map(|(i, _)| self.blocks.first + i)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_block_copies_the_same_bits_with_prefetch() {
        // Nodes out of order and with gaps, more than the prefetch looks ahead.
        let values: Vec<Vec3> = (0..500)
            .map(|i| Vec3::new(i as f64 / 7.0, (i as f64).sin(), -(i as f64).sqrt()))
            .collect();
        let nodes: Vec<u32> = (0..3 * prefetch::NODES_AHEAD as u32)
            .map(|k| (k * 37 + 11) % 500)
            .collect();
        let (mut without, mut with) = (Vec::new(), vec![Vec3::zeros(); 3]);
        copy_nodes(&mut without, &nodes, &values, false);
        copy_nodes(&mut with, &nodes, &values, true);
        let want: Vec<Vec3> = nodes.iter().map(|&n| values[n as usize]).collect();
        assert_eq!(without, want);
        let bits = |v: &[Vec3]| -> Vec<u64> { v.iter().flatten().map(|c| c.to_bits()).collect() };
        assert_eq!(bits(&with), bits(&want));
    }
}
