//! Beam-bonded DEM in 2D (paper 001 §2): discs with u, v, θ joined by Timoshenko beam bonds
//! that break at their strength, and unbonded contacts between discs that touch.
//!
//! [`BondedParticles`] is the [`Model`]:
//!
//! - **forces**: every intact bond's K_b u_L + C_b u̇_L (Eqs. 7, 8, 10) and every touching pair's
//!   unbonded force (Eqs. 5, 6) into per-bond buffers in parallel, gathered per particle over a
//!   fixed incidence list (no atomics: bit-identical on any number of threads);
//! - **tangent** (Eq. 4): K = Σ T K_d Tᵀ and C likewise, as DOF entries (x, y of particle p are
//!   DOFs 3p, 3p+1, its θ is DOF 3(N + p) + 2, N the number of particles). A broken bond keeps
//!   zero entries in the pattern so that breaking bonds never forces a new symbolic analysis.
//!   Unbonded contacts enter with their frame at the step's start, where the implicit step
//!   linearises (Eq. 26, see `qdem_core::solvers::Newmark`), not at Eq. 21's Taylor mid-point
//!   u + ∆t u̇/2 + ∆t² ü/4: in a long implicit step the accelerations carry the undamped
//!   ringing of the stiff modes (a = ω²x with ω∆t ≫ 1), and ∆t² ü/4 moved discs of the
//!   benchmark by 6 cm (10⁴ m/s² after the first break, ∆t = 5 ms; spacing 2.5 cm), ∆t u̇/2
//!   still by 7 mm (2.8 m/s; spacing 1 cm), turning the frames of the matrix away from the
//!   force's; measured on the 0.01 m beam: 51,570 bonds broken within two steps of the first
//!   break with the mid-point, 2,491 with the frame at the start. Contacts enter
//!   always with the sticking k_t0: Eq. 5's k_t(u) drops to zero for a sliding contact, but a
//!   contact that sticks again within the step then pushes with a stiffness the matrix lacks,
//!   which a long implicit step integrates explicitly and blows up (measured: rotations of
//!   10³ rad/s within a step of the benchmark); sliding is left to the force, which caps the
//!   tangential spring at μF_n;
//! - **events** (§2.2, §4): after a trial step every intact bond's stress (Eq. 11) is
//!   computed; a stress above the strength by more than the tolerance ε asks the stepper to
//!   retake the step with α = (σ_lim − σ_n)/(σ_{n+1} − σ_n) (Eqs. 29–30), as does an unbonded
//!   contact that opened early in the step; on commit, bonds at or above their strength
//!   break and pairs that touch get unbonded contacts, and the tangent is reported changed;
//! - **step bounds**: [`BondedParticles::critical_step_eq28`] is the paper's
//!   ∆t_crit = min 2√(m_ii/k_ii) (Eq. 28), which is not a stability bound (it overestimates the
//!   explicit limit); [`Model::stable_dt`] is the rigorous Gershgorin bound on M⁻¹K with the
//!   damping, which explicit runs are checked against.
//!
//! Contact candidates are the pairs of broken bonds (the crack faces) and the pairs the cell
//! grid of [`crate::dem::broad_phase`] finds within a skin of the discs, rebuilt when a disc has
//! moved more than half the skin.

use crate::bonded::beam_bond::{to_global_matrix, BeamBond, Dof2};
use crate::bonded::bond_tangent::{lower_entries, BondTangent};
use crate::bonded::particle_packing::{lattice_section, Packing, SplitMix64};
use crate::bonded::unbonded_contact::{overlap, PairKinematics, UnbondedLaw, UnbondedPair};
use crate::dem::broad_phase::{find_pairs, SphereSet};
use crate::error::ContactError;
use qdem_core::checkpoint::same_count;
use qdem_core::continuum::stable_step::critical_step;
use qdem_core::{
    checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, step::Linearized,
    step::Model, step::Persistence, step::Persistent, step::State, step::StepEvents,
    step::StepSettings, step::Tangent, Vec3,
};
use rayon::prelude::*;
use std::collections::HashSet;

/// Bonds per parallel task.
const BOND_CHUNK: usize = 2048;

/// How unbonded contacts and events behave.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BondSettings {
    /// Unbonded contact law.
    pub contact: UnbondedLaw,
    /// Relative overshoot ε of a bond's strength (or of the step past a contact's opening)
    /// above which a step is retaken.
    pub tolerance: f64,
}

/// The material of a bonded body: the continuum it represents and its bonds' strength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BondedMaterial {
    /// Density ρ (kg/m³).
    pub density: f64,
    /// Young's modulus E (Pa), plane stress.
    pub young: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Out-of-plane thickness b (m).
    pub thickness: f64,
    /// Damping ratio ξ_b of the bonds (Eq. 8).
    pub damping_ratio: f64,
    /// Mean bond strength (Pa).
    pub strength_mean: f64,
    /// Standard deviation of the bond strength (Pa); 0 gives every bond the mean.
    pub strength_std: f64,
    /// Seed of the strengths.
    pub seed: u64,
}

/// Discs joined by beam bonds, with unbonded contacts; see the module docs.
#[derive(Debug)]
pub struct BondedParticles {
    name: String,
    radius: Vec<f64>,
    bonds: Vec<BeamBond>,
    intact: Vec<bool>,
    /// The bonds' tangent entries (zero for broken bonds).
    bond_tangent: BondTangent,
    /// Per particle, the (bond, end) pairs touching it, in bond order (CSR).
    incidence_start: Vec<usize>,
    incidence: Vec<(u32, u8)>,
    bond_force: Vec<[Dof2; 2]>,
    /// Displacement and velocity (x, y, θ) of every particle, packed for the bond loop.
    motion: Vec<(Dof2, Dof2)>,
    stress_eval: Vec<f64>,
    stress_trial: Vec<f64>,
    stress_committed: Vec<f64>,
    pairs: Vec<UnbondedPair>,
    pair_index: HashSet<(u32, u32)>,
    grid_reference: Vec<[f64; 2]>,
    skin: f64,
    settings: BondSettings,
    /// Implicit stepping ([`Model::prepare`]): only the active contacts (touching at the last
    /// commit, or met by a trial step and activated) push, so that every contact force has
    /// its stiffness in the matrix; explicit stepping lets every overlapping pair push.
    implicit: bool,
    broken: usize,
    broken_log: Vec<(f64, u32)>,
    /// Whether a trial step activated a contact since the last commit.
    activated: bool,
    /// Whether the last check activated a contact.
    stale: bool,
    /// Whether a bond's trial stress reached its strength at the last check (it breaks on
    /// commit): saves the commit a pass over every bond at the steps where none breaks.
    breaking: bool,
    /// Eq. 28's ∆t_crit of the intact body (s).
    critical_step: f64,
}

impl BondedParticles {
    /// Particles `0..radius.len()` of the state (discs in the x–y plane) joined by `bonds`.
    pub fn new(
        name: &str,
        state: &State,
        radius: Vec<f64>,
        bonds: Vec<BeamBond>,
        settings: BondSettings,
    ) -> BondedParticles {
        let n = radius.len();
        let mut count = vec![0usize; n + 1];
        for b in &bonds {
            count[b.i as usize + 1] += 1;
            count[b.j as usize + 1] += 1;
        }
        for p in 0..n {
            count[p + 1] += count[p];
        }
        let mut fill = count.clone();
        let mut incidence = vec![(0u32, 0u8); 2 * bonds.len()];
        for (k, b) in bonds.iter().enumerate() {
            for (end, p) in [(0u8, b.i), (1u8, b.j)] {
                incidence[fill[p as usize]] = (k as u32, end);
                fill[p as usize] += 1;
            }
        }
        let m = bonds.len();
        let max_r = radius.iter().cloned().fold(0.0, f64::max);
        let mut model = BondedParticles {
            name: name.to_string(),
            radius,
            intact: vec![true; m],
            bond_tangent: BondTangent::new(&bonds, &vec![true; m], state.len()),
            incidence_start: count,
            incidence,
            bond_force: vec![[[0.0; 3]; 2]; m],
            motion: vec![([0.0; 3], [0.0; 3]); n],
            stress_eval: vec![0.0; m],
            stress_trial: vec![0.0; m],
            stress_committed: vec![0.0; m],
            bonds,
            pairs: Vec::new(),
            pair_index: HashSet::new(),
            grid_reference: Vec::new(),
            skin: 0.5 * max_r,
            settings,
            implicit: false,
            broken: 0,
            broken_log: Vec::new(),
            activated: false,
            stale: false,
            breaking: false,
            critical_step: 0.0,
        };
        model.critical_step = model.critical_step_eq28(state);
        model.rebuild_candidates(state);
        model
    }

    /// A state of the packing's discs at rest (x–y plane: z translation and x, y rotations
    /// fixed, mass ρ·cell·b and J = m r²/2 each) and the model bonding them, the section from
    /// [`lattice_section`] and strengths drawn from N(mean, std) with the material's seed
    /// (bond order).
    pub fn from_packing(
        name: &str,
        packing: &Packing,
        material: &BondedMaterial,
        settings: BondSettings,
    ) -> Result<(State, BondedParticles), ContactError> {
        let section = lattice_section(material.poisson).ok_or(ContactError::LatticePoisson {
            body: name.to_string(),
            poisson: material.poisson,
        })?;
        let reference = packing.centers.iter().map(|c| Vec3::new(c[0], c[1], 0.0));
        let mut state = State::at_rest(reference.collect());
        let mass = material.density * packing.cell_area * material.thickness;
        let r = packing.radius();
        state.mass.fill(mass);
        state
            .fixed
            .fill(qdem_core::step::Dofs::parse("z").expect("valid"));
        state.add_spin(
            vec![0.5 * mass * r * r; packing.len()],
            qdem_core::step::Dofs::parse("xy").expect("valid"),
        );
        let mut rng = SplitMix64(material.seed);
        let bonds = packing
            .bonds
            .iter()
            .map(|&(i, j)| {
                let (xi, xj) = (packing.centers[i as usize], packing.centers[j as usize]);
                let length = (xj[0] - xi[0]).hypot(xj[1] - xi[1]);
                let strength = material.strength_mean + material.strength_std * rng.normal();
                BeamBond::new(
                    (i, xi),
                    (j, xj),
                    material.young,
                    section.section(length, material.thickness),
                    [mass, mass],
                    [0.5 * mass * r * r; 2],
                    material.damping_ratio,
                    strength,
                )
            })
            .collect();
        let model = BondedParticles::new(name, &state, vec![r; packing.len()], bonds, settings);
        Ok((state, model))
    }

    /// The bonds (broken ones included, see [`BondedParticles::is_intact`]).
    pub fn bonds(&self) -> &[BeamBond] {
        &self.bonds
    }

    /// Whether bond `k` still holds.
    pub fn is_intact(&self, k: usize) -> bool {
        self.intact[k]
    }

    /// Number of broken bonds.
    pub fn broken(&self) -> usize {
        self.broken
    }

    /// (time, bond) of every break, in order.
    pub fn broken_log(&self) -> &[(f64, u32)] {
        &self.broken_log
    }

    /// Number of pairs in unbonded contact at the last committed step.
    pub fn touching(&self) -> usize {
        self.pairs.iter().filter(|p| p.touching).count()
    }

    /// Disc radii (m).
    pub fn radii(&self) -> &[f64] {
        &self.radius
    }

    /// The stress (Eq. 11) of every bond at the last [`StepEvents::check_step`] (Pa).
    pub fn trial_stresses(&self) -> &[f64] {
        &self.stress_trial
    }

    /// The stress (Eq. 11) of every bond at the last committed step (Pa).
    pub fn stresses(&self) -> &[f64] {
        &self.stress_committed
    }

    /// The paper's critical step ∆t_crit = min 2√(m_ii/k_ii) over the translational and
    /// rotational DOFs (Eq. 28), k_ii the diagonal of the intact bonds' stiffness.
    pub fn critical_step_eq28(&self, state: &State) -> f64 {
        let mut diagonal = vec![[0.0; 3]; self.radius.len()];
        for (b, _) in self.bonds.iter().zip(&self.intact).filter(|(_, &ok)| ok) {
            let g = to_global_matrix(&b.local_stiffness(), b.axis);
            for (end, p) in [(0, b.i), (1, b.j)] {
                for c in 0..3 {
                    diagonal[p as usize][c] += g[3 * end + c][3 * end + c];
                }
            }
        }
        diagonal
            .iter()
            .enumerate()
            .flat_map(|(p, d)| {
                let m = [state.mass[p], state.mass[p], state.spin.inertia[p]];
                (0..3)
                    .filter(move |&c| d[c] > 0.0)
                    .map(move |c| 2.0 * (m[c] / d[c]).sqrt())
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Eq. 28's ∆t_crit of the body as built, before any bond broke (s).
    pub fn initial_critical_step(&self) -> f64 {
        self.critical_step
    }

    /// The largest displacement of a particle and the particle, if it exceeds `limit` (m):
    /// the linear (small-displacement) bonds and contacts of this model no longer describe
    /// a body that has moved that far (a collapsed beam, a flying fragment).
    pub fn beyond_small_displacement(&self, state: &State, limit: f64) -> Option<(usize, f64)> {
        (0..self.radius.len())
            .map(|p| (p, state.displacement(p).norm()))
            .filter(|(_, u)| *u > limit)
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Displacement and velocity (x, y, θ) of particle p.
    #[inline]
    fn dofs(state: &State, p: usize) -> (Dof2, Dof2) {
        let (v, r, w) = (
            &state.velocity[p],
            &state.spin.angle[p],
            &state.spin.velocity[p],
        );
        planar(state.displacement(p), r, v, w)
    }

    /// [`BondedParticles::dofs`] of every particle into `motion`, walking the state's arrays
    /// in step rather than indexing each per particle.
    fn pack_motion(state: &State, motion: &mut [(Dof2, Dof2)]) {
        let n = motion.len();
        let translation = state.position[..n]
            .par_iter()
            .zip(&state.reference[..n])
            .zip(&state.velocity[..n]);
        let rotation = state.spin.angle[..n]
            .par_iter()
            .zip(&state.spin.velocity[..n]);
        motion
            .par_iter_mut()
            .with_min_len(BOND_CHUNK)
            .zip(translation.zip(rotation))
            .for_each(|(m, (((x, x0), v), (r, w)))| *m = planar(*x - *x0, r, v, w));
    }

    /// Elastic end forces and stress of bond `b` at `state`.
    #[inline]
    fn bond_elastic(b: &BeamBond, state: &State) -> ([f64; 6], [f64; 6]) {
        let (ui, _) = Self::dofs(state, b.i as usize);
        let (uj, _) = Self::dofs(state, b.j as usize);
        let local = b.to_local(&ui, &uj);
        (local, b.local_forces(&local))
    }

    /// Stresses of the intact bonds at `state` into `out` (0 for broken bonds).
    fn bond_stresses(&self, state: &State, out: &mut [f64]) {
        out.par_iter_mut()
            .with_min_len(BOND_CHUNK)
            .zip(self.bonds.par_iter())
            .zip(self.intact.par_iter())
            .for_each(|((s, b), &intact)| {
                *s = if intact {
                    b.stress(&Self::bond_elastic(b, state).1)
                } else {
                    0.0
                };
            });
    }

    /// Kinematics of pair (i, j).
    fn kinematics(&self, state: &State, i: usize, j: usize) -> PairKinematics {
        let (ui, vi) = Self::dofs(state, i);
        let (uj, vj) = Self::dofs(state, j);
        let (xi, xj) = (state.position[i], state.position[j]);
        PairKinematics {
            x: [[xi[0], xi[1]], [xj[0], xj[1]]],
            u: [ui, uj],
            v: [vi, vj],
            r: [self.radius[i], self.radius[j]],
        }
    }

    /// The overlap of `pair` at `state` from the centres alone (what [`PairKinematics::frame`]
    /// gives, without the displacements, velocities and tangent the frame also needs).
    #[inline]
    fn overlap(state: &State, pair: &UnbondedPair) -> f64 {
        let (xi, xj) = (
            state.position[pair.i as usize],
            state.position[pair.j as usize],
        );
        overlap([xi[0], xi[1]], [xj[0], xj[1]], pair.rest)
    }

    /// A candidate pair (i, j) with rest distance `rest`.
    fn candidate(&self, state: &State, i: u32, j: u32, rest: f64, stiffness: f64) -> UnbondedPair {
        let (mi, mj) = (state.mass[i as usize], state.mass[j as usize]);
        UnbondedPair {
            i,
            j,
            rest,
            normal_stiffness: stiffness,
            reduced_mass: mi * mj / (mi + mj),
            touching: false,
            elastic: 0.0,
            slip_reference: 0.0,
            overlap: 0.0,
        }
    }

    /// Normal stiffness of an unbonded contact: that of the pair's bond, or for pairs never
    /// bonded, k_a of the first bond (the lattice's; k_a = λbE does not depend on length).
    fn contact_stiffness(&self) -> f64 {
        self.bonds.first().map_or(0.0, |b| b.stiffness[0])
    }

    /// Adds the non-bonded pairs within the skin (cell grid) to the candidates.
    fn rebuild_candidates(&mut self, state: &State) {
        let n = self.radius.len();
        let center: Vec<Vec3> = state.position[..n].to_vec();
        let body: Vec<u32> = (0..n as u32).collect();
        let spheres = SphereSet {
            center: &center,
            radius: &self.radius,
            body: &body,
            periodic: None,
        };
        let bonded: HashSet<(u32, u32)> = self
            .bonds
            .iter()
            .zip(&self.intact)
            .filter(|(_, &ok)| ok)
            .map(|(b, _)| (b.i.min(b.j), b.i.max(b.j)))
            .collect();
        let k = self.contact_stiffness();
        for (i, j) in find_pairs(&spheres, self.skin) {
            let key = (i.min(j), i.max(j));
            if !bonded.contains(&key) && self.pair_index.insert(key) {
                let rest = self.radius[i as usize] + self.radius[j as usize];
                let pair = self.candidate(state, key.0, key.1, rest, k);
                self.pairs.push(pair);
            }
        }
        self.grid_reference = center.iter().map(|x| [x[0], x[1]]).collect();
    }

    /// Whether some disc moved more than half the skin since the last grid.
    fn moved_past_skin(&self, state: &State) -> bool {
        let limit = 0.25 * self.skin * self.skin;
        self.grid_reference
            .par_iter()
            .zip(state.position.par_iter())
            .any(|(a, x)| (x[0] - a[0]).powi(2) + (x[1] - a[1]).powi(2) > limit)
    }

    /// The α of the earliest contact event of a trial step: a touching pair that opened, or a
    /// pair that started touching, early in the step (before 1 − ε of it). A pair that starts
    /// touching in an implicit trial step is made active at once (zero tangential history), so
    /// that the retaken step has it in its matrix: met only in the right-hand side, a contact as
    /// stiff as a bond is integrated explicitly and a long implicit step overshoots it.
    fn contact_overshoot(&mut self, state: &State, forces_here: bool) -> Option<f64> {
        let eps = self.settings.tolerance;
        let mut earliest: Option<f64> = None;
        for idx in 0..self.pairs.len() {
            let p = self.pairs[idx];
            let (before, now) = (p.overlap, Self::overlap(state, &p));
            let alpha = match (p.touching, now > 0.0) {
                (true, false) if before > 0.0 => before / (before - now),
                (false, true) => {
                    if !forces_here {
                        let pair = &mut self.pairs[idx];
                        pair.touching = true;
                        // The tangential spring starts from the slip at the step's start (kept
                        // for every pair at commit), not the trial's end: the retaken step
                        // starts there.
                        pair.elastic = 0.0;
                        self.activated = true;
                        self.stale = true;
                    }
                    -before / (now - before)
                }
                _ => continue,
            };
            if alpha < 1.0 - eps {
                earliest = earlier(earliest, Some(alpha));
            }
        }
        earliest
    }

    /// Breaks every intact bond whose trial stress reached its strength (§2.2): its tangent
    /// entries go to zero and its two particles become an unbonded candidate pair. Whether
    /// one broke.
    fn break_bonds(&mut self, state: &State) -> bool {
        let before = self.broken;
        for k in 0..self.bonds.len() {
            if !(self.intact[k] && self.stress_trial[k] >= self.bonds[k].strength) {
                continue;
            }
            self.intact[k] = false;
            self.bond_tangent.remove(k);
            self.broken += 1;
            self.broken_log.push((state.time, k as u32));
            let b = self.bonds[k];
            let key = (b.i.min(b.j), b.i.max(b.j));
            if self.pair_index.insert(key) {
                let rest = b
                    .length
                    .min(self.radius[b.i as usize] + self.radius[b.j as usize]);
                let pair = self.candidate(state, key.0, key.1, rest, b.stiffness[0]);
                self.pairs.push(pair);
            }
        }
        self.broken > before
    }

    /// Adds a 6×6 global matrix of pair (i, j) to the tangent.
    fn add_block(
        tangent: &mut Tangent,
        n: usize,
        (i, j): (u32, u32),
        a: &[[f64; 6]; 6],
        damping: bool,
    ) {
        for e in lower_entries((i, j), n, a) {
            if damping {
                tangent.add_damping_entry(e.row, e.col, e.val);
            } else {
                tangent.add_stiffness_entry(e.row, e.col, e.val);
            }
        }
    }
}

/// The earlier of two optional event fractions α (the smaller; either if one is absent).
fn earlier(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(std::cmp::min_by(a, b, f64::total_cmp)),
        (a, b) => a.or(b),
    }
}

/// Writes the unbonded pairs with their committed contact state.
fn save_pairs(pairs: &[UnbondedPair], out: &mut Encoder) {
    out.u32s(&pairs.iter().flat_map(|p| [p.i, p.j]).collect::<Vec<_>>());
    let values: Vec<f64> = pairs
        .iter()
        .flat_map(|p| {
            [
                p.rest,
                p.normal_stiffness,
                p.reduced_mass,
                p.elastic,
                p.slip_reference,
                p.overlap,
            ]
        })
        .collect();
    out.f64s(&values);
    out.bools(&pairs.iter().map(|p| p.touching).collect::<Vec<_>>());
}

/// Reads back the pairs of [`save_pairs`] for `particles` discs.
fn restore_pairs(
    input: &mut Decoder<'_>,
    particles: usize,
) -> Result<Vec<UnbondedPair>, CheckpointError> {
    let ends = input.u32s("unbonded pairs")?;
    let values = input.f64s("unbonded pair states")?;
    let touching = input.bools("unbonded contact flags")?;
    let n = touching.len();
    same_count("unbonded pair ends", 2 * n, ends.len())?;
    same_count("unbonded pair values", 6 * n, values.len())?;
    if let Some(&bad) = ends.iter().find(|&&e| e as usize >= particles) {
        return Err(CheckpointError::Invalid {
            what: "unbonded pair",
            detail: format!("disc {bad} is beyond the scene's {particles}"),
        });
    }
    Ok((0..n)
        .map(|k| {
            let v = &values[6 * k..6 * k + 6];
            UnbondedPair {
                i: ends[2 * k],
                j: ends[2 * k + 1],
                rest: v[0],
                normal_stiffness: v[1],
                reduced_mass: v[2],
                touching: touching[k],
                elastic: v[3],
                slip_reference: v[4],
                overlap: v[5],
            }
        })
        .collect())
}

/// The in-plane (x, y, θ) parts of a particle's displacement `u` and rotation `r` and of their
/// rates `v`, `w`: the degrees of freedom of paper 001's particles.
#[inline]
fn planar(u: Vec3, r: &Vec3, v: &Vec3, w: &Vec3) -> (Dof2, Dof2) {
    ([u[0], u[1], r[2]], [v[0], v[1], w[2]])
}

impl Model for BondedParticles {
    fn name(&self) -> &str {
        &self.name
    }

    fn prepare(&mut self, settings: &StepSettings) {
        self.implicit = settings.is_implicit();
    }

    fn add_forces(&mut self, state: &State, force: &mut [Vec3], torque: &mut [Vec3]) {
        let bonds = &self.bonds;
        Self::pack_motion(state, &mut self.motion);
        let motion = &self.motion;
        self.bond_force
            .par_iter_mut()
            .with_min_len(BOND_CHUNK)
            .zip(self.stress_eval.par_iter_mut())
            .zip(bonds.par_iter().zip(self.intact.par_iter()))
            .for_each(|((out, stress), (b, &intact))| {
                if !intact {
                    *out = [[0.0; 3]; 2];
                    *stress = 0.0;
                    return;
                }
                let (ui, vi) = motion[b.i as usize];
                let (uj, vj) = motion[b.j as usize];
                let local = b.to_local(&ui, &uj);
                let elastic = b.local_forces(&local);
                *stress = b.stress(&elastic);
                let viscous = b.local_damping_forces(&b.to_local(&vi, &vj));
                let total: [f64; 6] = std::array::from_fn(|k| -(elastic[k] + viscous[k]));
                *out = b.to_global(&total);
            });
        let moment = &mut torque[state.rigid.len()..];
        let (start, incidence, bond_force) =
            (&self.incidence_start, &self.incidence, &self.bond_force);
        force
            .par_iter_mut()
            .zip(moment.par_iter_mut())
            .with_min_len(BOND_CHUNK)
            .enumerate()
            .take(self.radius.len())
            .for_each(|(p, (f, m))| {
                let mut sum = [0.0; 3];
                for &(k, end) in &incidence[start[p]..start[p + 1]] {
                    let g = &bond_force[k as usize][end as usize];
                    sum[0] += g[0];
                    sum[1] += g[1];
                    sum[2] += g[2];
                }
                f[0] += sum[0];
                f[1] += sum[1];
                m[2] += sum[2];
            });
        let law = self.settings.contact;
        let implicit = self.implicit;
        let touching = self.pairs.iter().filter(|p| p.touching || !implicit);
        for pair in touching.filter(|p| Self::overlap(state, p) > 0.0) {
            let (i, j) = (pair.i as usize, pair.j as usize);
            let k = self.kinematics(state, i, j);
            let out = law.forces_in(pair, &k, &k.frame(pair.rest));
            for (p, g) in [(i, out.force[0]), (j, out.force[1])] {
                force[p][0] += g[0];
                force[p][1] += g[1];
                moment[p][2] += g[2];
            }
        }
    }

    /// Gershgorin's bound on the largest eigenvalue of M^{-1/2} K M^{-1/2} (the eigenvalues
    /// of M⁻¹K, scaled so that rotations and translations compare) and likewise of the
    /// damping, into [`critical_step`].
    fn stable_dt(&self, state: &State) -> Option<f64> {
        let n = self.radius.len();
        let mut k_rows = vec![[0.0; 3]; n];
        let mut c_rows = vec![[0.0; 3]; n];
        let inertia = |p: usize| [state.mass[p], state.mass[p], state.spin.inertia[p]];
        for b in self
            .bonds
            .iter()
            .zip(&self.intact)
            .filter(|(_, &ok)| ok)
            .map(|(b, _)| b)
        {
            let k = to_global_matrix(&b.local_stiffness(), b.axis);
            let c = to_global_matrix(&b.local_damping(), b.axis);
            let (i, j) = (b.i as usize, b.j as usize);
            let m: Vec<f64> = inertia(i).into_iter().chain(inertia(j)).collect();
            for (end, p) in [(0, i), (1, j)] {
                for r in 0..3 {
                    let row = 3 * end + r;
                    let scaled = |a: &[[f64; 6]; 6]| -> f64 {
                        (0..6)
                            .map(|col| a[row][col].abs() / (m[row] * m[col]).sqrt())
                            .sum()
                    };
                    k_rows[p][r] += scaled(&k);
                    c_rows[p][r] += scaled(&c);
                }
            }
        }
        let omega2 = k_rows.iter().flatten().cloned().fold(0.0, f64::max);
        let rate = c_rows.iter().flatten().cloned().fold(0.0, f64::max);
        (omega2 > 0.0).then(|| critical_step(omega2, rate))
    }

    fn potential_energy(&self, state: &State) -> Option<f64> {
        let bonds: f64 = self
            .bonds
            .iter()
            .zip(&self.intact)
            .filter(|(_, &ok)| ok)
            .map(|(b, _)| {
                let (local, f) = Self::bond_elastic(b, state);
                0.5 * local.iter().zip(&f).map(|(u, f)| u * f).sum::<f64>()
            })
            .sum();
        let contacts: f64 = self
            .pairs
            .iter()
            .map(|p| {
                let d = self
                    .kinematics(state, p.i as usize, p.j as usize)
                    .frame(p.rest);
                0.5 * p.normal_stiffness * d.overlap.max(0.0).powi(2)
            })
            .sum();
        Some(bonds + contacts)
    }

    fn linearized(&self) -> Option<&dyn Linearized> {
        Some(self)
    }

    fn events(&mut self) -> Option<&mut dyn StepEvents> {
        Some(self)
    }

    fn persistence(&self) -> Persistence<'_> {
        Persistence::Saved(self)
    }

    fn persistent_mut(&mut self) -> Option<&mut dyn Persistent> {
        Some(self)
    }
}

impl Linearized for BondedParticles {
    /// Every particle of the body: the modal analysis takes their DOFs as the body's, and a
    /// singular implicit system names the body.
    fn particles(&self) -> Vec<usize> {
        (0..self.radius.len()).collect()
    }

    fn add_tangent(&self, state: &State, tangent: &mut Tangent) {
        let n = state.len();
        if self.bond_tangent.nodes() == n {
            self.bond_tangent.add_to(tangent);
        } else {
            BondTangent::new(&self.bonds, &self.intact, n).add_to(tangent);
        }
        let law = self.settings.contact;
        for pair in self.pairs.iter().filter(|p| p.touching) {
            let (i, j) = (pair.i as usize, pair.j as usize);
            let k = self.kinematics(state, i, j);
            let frame = k.frame(pair.rest);
            let key = (pair.i, pair.j);
            let stiffness = law.matrix(pair, &frame, k.r, false);
            Self::add_block(tangent, n, key, &stiffness, false);
            let damping = law.matrix(pair, &frame, k.r, true);
            Self::add_block(tangent, n, key, &damping, true);
        }
    }
}

impl StepEvents for BondedParticles {
    fn check_step(&mut self, state: &State, forces_here: bool) -> Option<f64> {
        self.stale = false;
        if forces_here {
            self.stress_trial.copy_from_slice(&self.stress_eval);
        } else {
            let mut trial = std::mem::take(&mut self.stress_trial);
            self.bond_stresses(state, &mut trial);
            self.stress_trial = trial;
        }
        let eps = self.settings.tolerance;
        let trial = self.stress_trial.par_iter().zip(&self.stress_committed);
        // One pass: whether a bond reached its strength (it breaks on commit) and the α of
        // the earliest that overshot it by more than ε.
        let (breaking, bonds) = self
            .bonds
            .par_iter()
            .zip(trial)
            .with_min_len(BOND_CHUNK)
            .map(|(b, (&now, &before))| {
                let overshot = now > b.strength * (1.0 + eps);
                let alpha = overshot.then(|| (b.strength - before) / (now - before));
                (now >= b.strength, alpha)
            })
            .reduce(|| (false, None), |a, b| (a.0 || b.0, earlier(a.1, b.1)));
        self.breaking = breaking;
        earlier(bonds, self.contact_overshoot(state, forces_here))
    }
    fn tangent_stale(&self) -> bool {
        self.stale
    }
    fn commit_step(&mut self, state: &State) -> bool {
        let mut changed = std::mem::take(&mut self.activated);
        if std::mem::take(&mut self.breaking) {
            changed |= self.break_bonds(state);
        }
        self.stress_committed.copy_from_slice(&self.stress_trial);
        if self.moved_past_skin(state) {
            self.rebuild_candidates(state);
        }
        let law = self.settings.contact;
        for idx in 0..self.pairs.len() {
            let pair = self.pairs[idx];
            let k = self.kinematics(state, pair.i as usize, pair.j as usize);
            let frame = k.frame(pair.rest);
            let touching = frame.overlap > 0.0;
            let elastic = if touching {
                law.forces_in(&pair, &k, &frame).elastic
            } else {
                0.0
            };
            let p = &mut self.pairs[idx];
            if touching != p.touching {
                changed = true;
            }
            p.touching = touching;
            p.elastic = elastic;
            p.slip_reference = frame.slip;
            p.overlap = frame.overlap;
        }
        changed
    }
}

impl Persistent for BondedParticles {
    /// The bonds left intact, their stresses, the unbonded pairs with their committed
    /// contact state, the broad phase's reference positions and the breakage log.
    fn save(&self, out: &mut Encoder) {
        out.tag("bonded particles");
        out.bools(&self.intact);
        for stress in [
            &self.stress_eval,
            &self.stress_trial,
            &self.stress_committed,
        ] {
            out.f64s(stress);
        }
        save_pairs(&self.pairs, out);
        out.f64s(&self.grid_reference.concat());
        out.u64(self.broken as u64);
        out.f64s(&self.broken_log.iter().map(|b| b.0).collect::<Vec<_>>());
        out.u32s(&self.broken_log.iter().map(|b| b.1).collect::<Vec<_>>());
        out.bool(self.activated);
        out.bool(self.stale);
    }
    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        input.tag("bonded particles")?;
        let bonds = self.bonds.len();
        self.intact = input.bools("intact bonds")?;
        same_count("bonds", bonds, self.intact.len())?;
        self.bond_tangent = BondTangent::new(&self.bonds, &self.intact, self.bond_tangent.nodes());
        for stress in [
            &mut self.stress_eval,
            &mut self.stress_trial,
            &mut self.stress_committed,
        ] {
            *stress = input.f64s("bond stresses")?;
            same_count("bond stresses", bonds, stress.len())?;
        }
        self.pairs = restore_pairs(input, self.radius.len())?;
        self.pair_index = self.pairs.iter().map(|p| (p.i, p.j)).collect();
        let grid = input.f64s("the broad phase's positions")?;
        self.grid_reference = grid.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
        self.broken = input.u64("the broken-bond count")? as usize;
        let times = input.f64s("the breakage log")?;
        let which = input.u32s("the breakage log")?;
        same_count("breakage log entries", times.len(), which.len())?;
        self.broken_log = times.into_iter().zip(which).collect();
        self.activated = input.bool("the activation flag")?;
        self.stale = input.bool("the stale flag")?;
        Ok(())
    }
}
