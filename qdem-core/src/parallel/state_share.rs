//! [`StateShare`]: what ends each integration of a decomposed run ([`crate::parallel::decomposition`]),
//! and the whole gathers in between.
//!
//! A step's share copies the motion a rank integrated to the ranks that read it: the
//! acceleration and velocity (and the rotation's) of each owned particle, which is all the
//! next prediction (paper 000 §2.4: x += ∆t (v + ½∆t a), v += ½∆t a) needs besides the
//! position, and the position follows bit for bit from them. Two ways:
//! - **whole**: every owned particle to every rank ([`Communicator::all_gather`]), when some
//!   model or hook reads any particle ([`crate::step::Reads::All`]) or the stepper steps
//!   every particle; every rank then holds the state one process holds after every step;
//! - **halo**: each owned particle only to the ranks whose tetrahedra touch it
//!   ([`Communicator::all_to_all`]); a rank steps its own particles and its halo, and the
//!   others keep the value of the last whole gather. Whoever reads the whole state (the
//!   outputs, a checkpoint, a failure's report) asks for a [`StateShare::gather`] first,
//!   which sends the positions too.
//!
//! A rigid body is owned, whole, by the rank that owns its centre; in halo mode the other
//! ranks' copies of its rotation go stale between gathers, and a gather brings its
//! orientation, angular momentum and velocity and the stepper's torque on it (which the next
//! step's first half kick reads) from its owner.
//!
//! Values are copied, never summed, so any number of ranks gives the same bits. The one sum
//! over ranks is the kinetic energy of the failure check in halo mode: each rank's part, in
//! rank order, equal to one process's sum up to its rounding.

use crate::parallel::communicator::Communicator;
use crate::parallel::decomposition::RankFigures;
use crate::step::local_particles::ParticleRuns;
use crate::step::state::State;
use crate::Vec3;
use nalgebra::{Quaternion, UnitQuaternion};
use std::ops::Range;
use std::sync::Arc;

/// The exchange that ends each integration of a decomposed run, and the whole gathers.
pub(crate) struct StateShare {
    comm: Arc<dyn Communicator>,
    /// The particles each rank owns, rank after rank, ascending within a rank.
    particles: Vec<u32>,
    /// This rank's part of `particles`.
    own: Range<usize>,
    /// Owned particles per rank.
    owned: Vec<usize>,
    /// Per particle, the rank that owns it (`u32::MAX`: computed by every rank).
    owner: Vec<u32>,
    /// Whether the particles have rotational DOFs.
    spin: bool,
    /// The halo exchange, when a step shares only the halo.
    halo: Option<StateHalo>,
    mine: Vec<f64>,
    all: Vec<f64>,
}

/// The particles a rank sends to and receives from each other rank after each step: grouped
/// by rank, ascending within a rank, so that both sides list them alike.
pub(crate) struct StateHalo {
    pub send: Vec<u32>,
    /// Particles sent to each rank.
    pub send_counts: Vec<usize>,
    pub recv: Vec<u32>,
    /// Particles received from each rank.
    pub recv_counts: Vec<usize>,
    /// This rank's part of the kinetic energy: the particles it owns, and on rank 0 also
    /// those every rank computes whole.
    pub counted: ParticleRuns,
}

impl StateShare {
    /// The share of the particles `owner` gives each rank (`u32::MAX`: computed by all), in
    /// halo mode with `halo`.
    pub fn new(
        owner: &[u32],
        state: &State,
        halo: Option<StateHalo>,
        comm: Arc<dyn Communicator>,
    ) -> StateShare {
        let ranks = comm.size();
        let mut by_rank = vec![Vec::new(); ranks];
        for (p, &r) in owner.iter().enumerate() {
            if r != u32::MAX {
                by_rank[r as usize].push(p as u32);
            }
        }
        let start: usize = by_rank[..comm.rank()].iter().map(Vec::len).sum();
        StateShare {
            own: start..start + by_rank[comm.rank()].len(),
            owned: by_rank.iter().map(Vec::len).collect(),
            owner: owner.to_vec(),
            particles: by_rank.concat(),
            spin: !state.spin.is_empty(),
            halo,
            comm,
            mine: Vec::new(),
            all: Vec::new(),
        }
    }

    /// Per particle, the rank that owns it (`u32::MAX`: computed by every rank).
    pub fn owner(&self) -> &[u32] {
        &self.owner
    }

    /// Shares the whole state after every step from now on (a stepper that cannot step a
    /// rank's particles alone); `figures` learn what each rank then receives.
    pub fn share_whole_every_step(&mut self, figures: &mut RankFigures) {
        self.halo = None;
        let total: usize = self.owned.iter().sum();
        for (received, owned) in figures.received.iter_mut().zip(&self.owned) {
            *received = total - owned;
        }
    }

    /// After an integration: copies each rank's owned particles' new motion to the ranks
    /// that read it.
    pub fn share(&mut self, state: &mut State) {
        match &self.halo {
            Some(_) => self.exchange_halo(state),
            None => self.all_gather(state, Motion::Rates),
        }
    }

    /// Makes the state whole on every rank (positions too, and the rigid bodies' rotation
    /// with `torque`, the stepper's torques on them); nothing to do unless a step shares
    /// only the halo. Every rank calls it at the same step.
    pub fn gather(&mut self, state: &mut State, torque: &mut [Vec3]) {
        if self.halo.is_some() {
            self.all_gather(state, Motion::Whole);
            self.gather_rigid(state, torque);
        }
    }

    /// Makes `values` (one vector per particle, e.g. the stepper's forces) whole on every
    /// rank: each owned particle's from the rank that owns it; those every rank computes are
    /// whole already. Every rank calls it at the same step.
    pub fn gather_vectors(&mut self, values: &mut [Vec3]) {
        if values.len() != self.owner.len() {
            return;
        }
        self.mine.clear();
        for &p in &self.particles[self.own.clone()] {
            self.mine.extend_from_slice(values[p as usize].as_slice());
        }
        let counts: Vec<usize> = self.owned.iter().map(|n| 3 * n).collect();
        self.all.resize(3 * self.particles.len(), 0.0);
        self.comm.all_gather(&self.mine, &mut self.all, &counts);
        for (&p, v) in self.particles.iter().zip(self.all.chunks_exact(3)) {
            values[p as usize] = Vec3::new(v[0], v[1], v[2]);
        }
    }

    /// Every rigid body's orientation, angular momentum and velocity and `torque`, from the
    /// rank that owns its centre (those every rank computes are whole already).
    fn gather_rigid(&mut self, state: &mut State, torque: &mut [Vec3]) {
        let rigid = &mut state.rigid;
        if rigid.is_empty() {
            return;
        }
        const PER: usize = 13;
        let (me, ranks) = (self.comm.rank() as u32, self.comm.size());
        let mut counts = vec![0; ranks];
        self.mine.clear();
        for (b, &c) in rigid.center.iter().enumerate() {
            match self.owner[c] {
                u32::MAX => continue,
                r => counts[r as usize] += PER,
            }
            if self.owner[c] == me {
                self.mine
                    .extend_from_slice(rigid.orientation[b].as_ref().coords.as_slice());
                for v in [
                    rigid.angular_momentum[b],
                    rigid.angular_velocity[b],
                    torque[b],
                ] {
                    self.mine.extend_from_slice(v.as_slice());
                }
            }
        }
        let mut at = self.gather_mine(&counts);
        let v3 = |v: &[f64], k: usize| Vec3::new(v[k], v[k + 1], v[k + 2]);
        for (b, &c) in rigid.center.iter().enumerate() {
            let Some(k) = at.get_mut(self.owner[c] as usize) else {
                continue;
            };
            let v = &self.all[*k..*k + PER];
            *k += PER;
            let q = Quaternion::new(v[3], v[0], v[1], v[2]);
            rigid.orientation[b] = UnitQuaternion::new_unchecked(q);
            rigid.angular_momentum[b] = v3(v, 4);
            rigid.angular_velocity[b] = v3(v, 7);
            torque[b] = v3(v, 10);
        }
    }

    /// Makes `particles`' motion whole on every rank (positions too); nothing to do unless a
    /// step shares only the halo. Every rank calls it at the same step with the same list.
    pub fn gather_some(&mut self, state: &mut State, particles: &[usize]) {
        if self.halo.is_none() {
            return;
        }
        let per = Motion::Whole.values(self.spin);
        let me = self.comm.rank() as u32;
        let mut counts = vec![0; self.comm.size()];
        self.mine.clear();
        for &p in particles {
            let owner = self.owner[p];
            if owner == me {
                pack(state, p, Motion::Whole, &mut self.mine);
            }
            if owner != u32::MAX {
                counts[owner as usize] += per;
            }
        }
        let mut at = self.gather_mine(&counts);
        for &p in particles {
            let owner = self.owner[p];
            if owner != u32::MAX {
                let k = &mut at[owner as usize];
                unpack(state, p, Motion::Whole, &self.all[*k..*k + per]);
                *k += per;
            }
        }
    }

    /// Every rank's `mine` (`counts[q]` values from rank `q`) into `all`; returns where each
    /// rank's part starts.
    fn gather_mine(&mut self, counts: &[usize]) -> Vec<usize> {
        self.all.resize(counts.iter().sum(), 0.0);
        self.comm.all_gather(&self.mine, &mut self.all, counts);
        counts
            .iter()
            .scan(0, |start, n| {
                let here = *start;
                *start += n;
                Some(here)
            })
            .collect()
    }

    /// Every rank's owned particles' `what` into `state`, on every rank.
    fn all_gather(&mut self, state: &mut State, what: Motion) {
        let per = what.values(self.spin);
        self.mine.clear();
        for &p in &self.particles[self.own.clone()] {
            pack(state, p as usize, what, &mut self.mine);
        }
        let counts: Vec<usize> = self.owned.iter().map(|n| per * n).collect();
        self.all.resize(per * self.particles.len(), 0.0);
        self.comm.all_gather(&self.mine, &mut self.all, &counts);
        for (&p, values) in self.particles.iter().zip(self.all.chunks_exact(per)) {
            unpack(state, p as usize, what, values);
        }
    }

    /// The halo's new motion from the ranks that own it.
    fn exchange_halo(&mut self, state: &mut State) {
        let halo = self.halo.as_ref().expect("halo mode");
        let per = Motion::Rates.values(self.spin);
        self.mine.clear();
        for &p in &halo.send {
            pack(state, p as usize, Motion::Rates, &mut self.mine);
        }
        self.all.resize(per * halo.recv.len(), 0.0);
        let send_counts: Vec<usize> = halo.send_counts.iter().map(|n| per * n).collect();
        let recv_counts: Vec<usize> = halo.recv_counts.iter().map(|n| per * n).collect();
        self.comm
            .all_to_all(&self.mine, &send_counts, &mut self.all, &recv_counts);
        for (&p, values) in halo.recv.iter().zip(self.all.chunks_exact(per)) {
            unpack(state, p as usize, Motion::Rates, values);
        }
    }

    /// The kinetic energy of the whole state (J), the same on every rank: one process's
    /// [`State::kinetic_energy`] when every rank holds the whole state; in halo mode the sum
    /// of the ranks' parts in rank order.
    pub fn kinetic_energy(&self, state: &State) -> f64 {
        let Some(halo) = &self.halo else {
            return state.kinetic_energy();
        };
        let mut part = 0.0;
        for p in halo.counted.indices() {
            part += 0.5 * state.mass[p] * state.velocity[p].norm_squared();
            if self.spin {
                part += 0.5 * state.spin.inertia[p] * state.spin.velocity[p].norm_squared();
            }
        }
        let me = self.comm.rank() as u32;
        for (b, &c) in state.rigid.center.iter().enumerate() {
            if self.owner[c] == me || (me == 0 && self.owner[c] == u32::MAX) {
                part += state.rigid.body_kinetic_energy(b);
            }
        }
        self.comm.all_gather_one(part).iter().sum()
    }

    /// The failure every rank reports: the one of the lowest rank that found one.
    pub fn agree(&self, local: Option<String>) -> Option<String> {
        let mine = match local {
            Some(_) => self.comm.rank() as u64,
            None => u64::MAX,
        };
        let root = self.comm.min(mine);
        if root == u64::MAX {
            return None;
        }
        let mut bytes = local.map(String::into_bytes).unwrap_or_default();
        self.comm.broadcast(root as usize, &mut bytes);
        Some(String::from_utf8_lossy(&bytes).into_owned())
    }
}

/// What of a particle's motion is copied.
#[derive(Clone, Copy)]
enum Motion {
    /// Acceleration and velocity (and the rotation's): after an integration, when the
    /// position is already the same everywhere.
    Rates,
    /// The position too (and the rotation angle): a whole gather.
    Whole,
}

impl Motion {
    /// Values per particle.
    fn values(self, spin: bool) -> usize {
        let translation = match self {
            Motion::Rates => 6,
            Motion::Whole => 9,
        };
        match spin {
            true => 2 * translation,
            false => translation,
        }
    }
}

/// Appends particle `p`'s `what`.
fn pack(state: &State, p: usize, what: Motion, out: &mut Vec<f64>) {
    out.extend_from_slice(state.acceleration[p].as_slice());
    out.extend_from_slice(state.velocity[p].as_slice());
    if let Motion::Whole = what {
        out.extend_from_slice(state.position[p].as_slice());
    }
    if !state.spin.is_empty() {
        out.extend_from_slice(state.spin.acceleration[p].as_slice());
        out.extend_from_slice(state.spin.velocity[p].as_slice());
        if let Motion::Whole = what {
            out.extend_from_slice(state.spin.angle[p].as_slice());
        }
    }
}

/// Sets particle `p`'s `what` from what [`pack`] wrote.
fn unpack(state: &mut State, p: usize, what: Motion, v: &[f64]) {
    let at = |k: usize| Vec3::new(v[k], v[k + 1], v[k + 2]);
    state.acceleration[p] = at(0);
    state.velocity[p] = at(3);
    let mut k = 6;
    if let Motion::Whole = what {
        state.position[p] = at(6);
        k = 9;
    }
    if !state.spin.is_empty() {
        state.spin.acceleration[p] = at(k);
        state.spin.velocity[p] = at(k + 3);
        if let Motion::Whole = what {
            state.spin.angle[p] = at(k + 6);
        }
    }
}
