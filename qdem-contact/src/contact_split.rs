//! [`ContactSplit`]: one rank's part of the contacts in a run decomposed with a halo exchange
//! ([`qdem_core::distributed`]), bit-identical to one process.
//!
//! A sphere belongs to the rank that owns its particle (the mesh's decomposition for a
//! deformable body's vertices, recursive bisection of the positions for one-sphere grains).
//! A rank evaluates every candidate contact that touches a sphere it owns; a pair of two
//! ranks' spheres is evaluated on both, from the same values, so both hold the same record.
//! The candidate lists are sorted by partners, so a rank's list is a sub-sequence of the one
//! a single process holds and each of its spheres sums its contacts in that process's order
//! (paper 000 §4's gather, in the fixed order of `dem_contacts.rs`).
//!
//! What a rank reads of the other ranks' spheres, the **ghosts** (the partners of its
//! candidates that it does not own), their owners send at each evaluation: the centre,
//! velocity and spin they read after the prediction. At a rebuild of the lists, which the
//! ranks decide on the largest displacement among all spheres (a max: exact), every rank
//! receives every sphere's record, finds the pairs near its own spheres, and asks the owners
//! for its new ghosts. Owners do not change, so the tangential springs of a rank's pairs
//! are always on that rank. Before an output or a checkpoint reads the contacts, the ranks'
//! lists are merged into the one list a single process holds ([`ContactSplit::merge`]).

use crate::contact_list::{Contact, ContactList};
use crate::dem_contacts::SphereNow;
use qdem_core::{Communicator, Vec3};
use std::sync::Arc;

/// Values sent per sphere: centre, velocity, spin.
const SPHERE_VALUES: usize = 9;

/// Values per contact record in a merge: partners, spring, force, n × f, δ/2, image shift.
const CONTACT_VALUES: usize = 15;

/// One rank's part of a contact set.
pub(crate) struct ContactSplit {
    comm: Arc<dyn Communicator>,
    /// Per sphere, the rank that owns it.
    owner: Vec<u32>,
    /// This rank's spheres, ascending.
    pub(crate) own: Vec<u32>,
    /// Every sphere, grouped by owner rank, ascending within a rank.
    by_rank: Vec<u32>,
    /// Spheres per rank in `by_rank`.
    by_rank_counts: Vec<usize>,
    /// The own spheres each other rank reads as ghosts, grouped by rank.
    send: Vec<u32>,
    send_counts: Vec<usize>,
    /// This rank's ghosts, grouped by owner, ascending within an owner.
    recv: Vec<u32>,
    recv_counts: Vec<usize>,
    /// Whether the lists hold every rank's contacts (after a merge or a restore): they are
    /// cut down to this rank's before the next evaluation.
    pub(crate) whole: bool,
    /// The own spheres that are partners of this rank's candidates, ascending: those whose
    /// motion the lists read and whose contacts are summed.
    pub(crate) partners: Vec<u32>,
    /// Scratch: the partners' sums.
    pub(crate) sums: Vec<(Vec3, Vec3)>,
    mine: Vec<f64>,
    all: Vec<f64>,
}

impl ContactSplit {
    /// The part of the rank `comm.rank()` when sphere `s` sits on particle
    /// `particle[s]` and particle `p` is owned by rank `owner[p]`.
    pub(crate) fn new(
        particle: &[u32],
        owner: &[u32],
        comm: Arc<dyn Communicator>,
    ) -> ContactSplit {
        let owner: Vec<u32> = particle.iter().map(|&p| owner[p as usize]).collect();
        let ranks = comm.size();
        let mut grouped = vec![Vec::new(); ranks];
        for (s, &r) in owner.iter().enumerate() {
            grouped[r as usize].push(s as u32);
        }
        ContactSplit {
            own: grouped[comm.rank()].clone(),
            by_rank_counts: grouped.iter().map(Vec::len).collect(),
            by_rank: grouped.concat(),
            owner,
            send: Vec::new(),
            send_counts: vec![0; ranks],
            recv: Vec::new(),
            recv_counts: vec![0; ranks],
            whole: false,
            partners: Vec::new(),
            sums: Vec::new(),
            comm,
            mine: Vec::new(),
            all: Vec::new(),
        }
    }

    /// The number of ghosts this rank receives at each evaluation.
    pub(crate) fn ghosts(&self) -> usize {
        self.recv.len()
    }

    /// Whether this rank owns sphere `s`.
    #[inline]
    pub(crate) fn owns(&self, s: u32) -> bool {
        self.owner[s as usize] == self.comm.rank() as u32
    }

    /// Whether a contact belongs to this rank's list: a pair touching an own sphere, a wall
    /// contact of one.
    pub(crate) fn keeps(&self, c: &Contact, wall: bool) -> bool {
        self.owns(c.first) || (!wall && self.owns(c.second))
    }

    /// The largest of the ranks' `value`s (≥ 0, or infinite), on every rank: exact, since
    /// the order of non-negative floats is that of their bits.
    pub(crate) fn max_over_ranks(&self, value: f64) -> f64 {
        f64::from_bits(!self.comm.min(!value.to_bits()))
    }

    /// Every sphere's centre and record, from its owner, into `center` and `now` (the
    /// velocity and spin are current for the partners of the owner's candidates only).
    pub(crate) fn share_all(&mut self, now: &mut [SphereNow], center: &mut [Vec3]) {
        pack(now, center, &self.own, &mut self.mine);
        let counts: Vec<usize> = self
            .by_rank_counts
            .iter()
            .map(|n| SPHERE_VALUES * n)
            .collect();
        self.all.resize(SPHERE_VALUES * self.by_rank.len(), 0.0);
        self.comm.all_gather(&self.mine, &mut self.all, &counts);
        unpack(&self.all, &self.by_rank, now, center);
    }

    /// The ghosts' records, from their owners, into `now` and `center`.
    pub(crate) fn share_ghosts(&mut self, now: &mut [SphereNow], center: &mut [Vec3]) {
        pack(now, center, &self.send, &mut self.mine);
        let counts = |c: &[usize]| c.iter().map(|n| SPHERE_VALUES * n).collect::<Vec<_>>();
        let (send_counts, recv_counts) = (counts(&self.send_counts), counts(&self.recv_counts));
        self.all.resize(SPHERE_VALUES * self.recv.len(), 0.0);
        self.comm
            .all_to_all(&self.mine, &send_counts, &mut self.all, &recv_counts);
        unpack(&self.all, &self.recv, now, center);
    }

    /// Makes `ghosts` (ascending) the spheres this rank receives at each evaluation, and
    /// learns which of its own the others receive: a collective.
    pub(crate) fn set_ghosts(&mut self, ghosts: &[u32]) {
        let ranks = self.comm.size();
        let mut asked = vec![Vec::new(); ranks];
        for &g in ghosts {
            asked[self.owner[g as usize] as usize].push(g);
        }
        self.recv_counts = asked.iter().map(Vec::len).collect();
        self.recv = asked.concat();
        // Every rank's request counts (a ranks × ranks table), then the requests.
        let mine: Vec<f64> = self.recv_counts.iter().map(|&n| n as f64).collect();
        let mut table = vec![0.0; ranks * ranks];
        self.comm.all_gather(&mine, &mut table, &vec![ranks; ranks]);
        let per_rank: Vec<usize> = table
            .chunks_exact(ranks)
            .map(|row| row.iter().sum::<f64>() as usize)
            .collect();
        let requests: Vec<f64> = self.recv.iter().map(|&s| s as f64).collect();
        let mut all = vec![0.0; per_rank.iter().sum()];
        self.comm.all_gather(&requests, &mut all, &per_rank);
        let me = self.comm.rank();
        let (mut send, mut send_counts, mut at) = (Vec::new(), vec![0; ranks], 0);
        for (r, row) in table.chunks_exact(ranks).enumerate() {
            let before: usize = row[..me].iter().map(|&n| n as usize).sum();
            let n = row[me] as usize;
            if r != me {
                let from = at + before;
                send.extend(all[from..from + n].iter().map(|&s| s as u32));
                send_counts[r] = n;
            }
            at += per_rank[r];
        }
        self.send = send;
        self.send_counts = send_counts;
    }

    /// The average magnitude of the touching pairs' forces among every rank's pairs `c` for
    /// which `counted(c)`, as one process measures it over its list: the ranks' pairs merged
    /// by partners (a pair two ranks hold taken once) and summed in that order. A
    /// collective.
    pub(crate) fn mean_force_of(
        &mut self,
        list: &ContactList,
        counted: impl Fn(&Contact) -> bool,
    ) -> f64 {
        self.mine.clear();
        for c in &list.items {
            if c.force != Vec3::zeros() && counted(c) {
                self.mine
                    .extend([c.first as f64, c.second as f64, c.force.norm()]);
            }
        }
        self.comm.all_gather_varying(&self.mine, &mut self.all);
        let mut forces: Vec<(u32, u32, f64)> = self
            .all
            .chunks_exact(3)
            .map(|v| (v[0] as u32, v[1] as u32, v[2]))
            .collect();
        forces.sort_by_key(|&(a, b, _)| (a, b));
        forces.dedup_by_key(|&mut (a, b, _)| (a, b));
        let mut sum = 0.0;
        for &(_, _, f) in &forces {
            sum += f;
        }
        match forces.len() {
            0 => 0.0,
            n => sum / n as f64,
        }
    }

    /// Every rank's `list` merged into the one list a single process holds: sorted by
    /// partners, a pair that two ranks hold taken once (their records are equal). A
    /// collective.
    pub(crate) fn merge(&mut self, list: &ContactList) -> ContactList {
        self.mine.clear();
        for c in &list.items {
            self.mine.extend([c.first as f64, c.second as f64]);
            for v in [c.history, c.force, c.turn] {
                self.mine.extend_from_slice(v.as_slice());
            }
            self.mine.push(c.half_overlap);
            self.mine.extend_from_slice(c.shift.as_slice());
        }
        self.comm.all_gather_varying(&self.mine, &mut self.all);
        let at = |v: &[f64], k: usize| Vec3::new(v[k], v[k + 1], v[k + 2]);
        let mut items: Vec<Contact> = self
            .all
            .chunks_exact(CONTACT_VALUES)
            .map(|v| Contact {
                first: v[0] as u32,
                second: v[1] as u32,
                history: at(v, 2),
                force: at(v, 5),
                turn: at(v, 8),
                half_overlap: v[11],
                shift: at(v, 12),
            })
            .collect();
        items.sort_by_key(|c| (c.first, c.second));
        items.dedup_by_key(|c| (c.first, c.second));
        ContactList { items }
    }
}

/// Appends the centre, velocity and spin of `spheres` to `out` (cleared first).
fn pack(now: &[SphereNow], center: &[Vec3], spheres: &[u32], out: &mut Vec<f64>) {
    out.clear();
    for &s in spheres {
        let n = &now[s as usize];
        for v in [center[s as usize], n.velocity, n.spin] {
            out.extend_from_slice(v.as_slice());
        }
    }
}

/// Sets the records of `spheres` from what [`pack`] wrote.
fn unpack(values: &[f64], spheres: &[u32], now: &mut [SphereNow], center: &mut [Vec3]) {
    for (&s, v) in spheres.iter().zip(values.chunks_exact(SPHERE_VALUES)) {
        let n = &mut now[s as usize];
        n.center = Vec3::new(v[0], v[1], v[2]);
        n.velocity = Vec3::new(v[3], v[4], v[5]);
        n.spin = Vec3::new(v[6], v[7], v[8]);
        center[s as usize] = n.center;
    }
}
