//! One rank's part of a [`DemContacts`] in a run decomposed with a halo exchange
//! ([`qdem_core::parallel`]), bit-identical to one process: its facets ([`Facets`]), whose
//! stages the world's [`qdem_core::parallel::ParallelRuntime`] runs with the collectives in between.
//!
//! A sphere belongs to the rank that owns its particle (the mesh's decomposition for a
//! deformable body's vertices, runs of particle order for one-sphere grains, a rigid body
//! whole). A rank evaluates every candidate contact that touches a sphere it owns; a pair of
//! two ranks' spheres is evaluated on both, from the same values, so both hold the same
//! record. The candidate lists are sorted by partners, so a rank's list is a sub-sequence of
//! the one a single process holds and each of its spheres sums its contacts in that
//! process's order (the pair kernel's sums, `pair_kernel.rs`).
//!
//! What a rank reads of the other ranks' spheres, the **ghosts** (the partners of its
//! candidates that it does not own), their owners send at each evaluation: the centre,
//! velocity and spin ([`Halo::pack`]). At a rebuild of the lists, which the ranks
//! decide on the largest displacement among all spheres, every rank receives every sphere's
//! record, finds the pairs near its own spheres, and declares its new ghosts. Owners do not
//! change between re-partitions, so the tangential springs of a rank's pairs are always on
//! that rank. Before an output or a checkpoint reads the contacts, the ranks' lists are
//! merged into the one list a single process holds ([`Merge::merge`]).

use super::*;
use qdem_core::step::split::{
    Balance, Evaluation, Facets, Halo, Lists, Merge, Ownership, Part, Reduction,
};

/// Values per sphere record: centre, velocity, spin.
const SPHERE_VALUES: usize = 9;

/// Values per contact record in a merge: the list (0 pairs, 1 walls), partners, spring,
/// force, n × f, δ/2, image shift; then, with rolling friction, the rolling spring.
const CONTACT_VALUES: usize = 16;

/// One rank's part of a contact set.
pub(super) struct ContactPart {
    /// Per sphere, the rank that owns it.
    owner: Vec<u32>,
    /// This rank.
    me: u32,
    /// This rank's spheres, ascending.
    own: Vec<u32>,
    /// Whether the lists hold every rank's contacts (after a merge or a restore): they are
    /// cut down to this rank's before the next evaluation.
    pub(super) whole: bool,
    /// Whether the lists changed since the ghosts were last declared.
    pub(super) lists_changed: bool,
    /// The own spheres that are partners of this rank's candidates, ascending: those whose
    /// motion the lists read and whose contacts are summed.
    partners: Vec<u32>,
    /// The spheres of other ranks this rank reads at each evaluation.
    pub(super) ghosts: usize,
}

impl ContactPart {
    /// The part of rank `me` when sphere `s` sits on particle `particle[s]` and particle `p`
    /// is owned by rank `owner[p]`; whole until its first evaluation.
    fn new(particle: &[u32], owner: &[u32], me: u32) -> ContactPart {
        let owner: Vec<u32> = particle.iter().map(|&p| owner[p as usize]).collect();
        ContactPart {
            own: (0..owner.len() as u32)
                .filter(|&s| owner[s as usize] == me)
                .collect(),
            owner,
            me,
            whole: true,
            lists_changed: false,
            partners: Vec::new(),
            ghosts: 0,
        }
    }

    /// Renumbers the spheres (`spatial_order.rs`): slot `s` takes the owner of slot
    /// `from[s]`; the own spheres follow (the partners at the next declaration of ghosts).
    pub(super) fn renumber(&mut self, from: &[u32]) {
        self.owner = super::spatial_order::permuted(&self.owner, from);
        self.own = (0..self.owner.len() as u32)
            .filter(|&s| self.owner[s as usize] == self.me)
            .collect();
        self.partners.clear();
        self.lists_changed = true;
    }

    /// Whether this rank owns sphere `s`.
    #[inline]
    fn owns(&self, s: u32) -> bool {
        self.owner[s as usize] == self.me
    }

    /// This rank's spheres, ascending.
    pub(super) fn own(&self) -> &[u32] {
        &self.own
    }

    /// The own spheres that are partners of this rank's candidates, ascending.
    pub(super) fn partners(&self) -> &[u32] {
        &self.partners
    }

    /// Whether a contact belongs to this rank's list: a pair touching an own sphere, a wall
    /// contact of one.
    fn keeps(&self, c: &Contact, wall: bool) -> bool {
        self.owns(c.first) || (!wall && self.owns(c.second))
    }
}

impl DemContacts {
    /// Whether this process or rank adds sphere `s`'s sum to its particle: it owns it.
    #[inline]
    pub(super) fn adds_to(&self, s: u32) -> bool {
        self.split.as_ref().is_none_or(|p| p.owns(s))
    }

    /// Runs `stage` on this rank's part, which it holds for the while.
    pub(super) fn with_part<T>(
        &mut self,
        stage: impl FnOnce(&mut Self, &mut ContactPart) -> T,
    ) -> T {
        let mut part = self.split.take().expect("a split contact set");
        let out = stage(self, &mut part);
        self.split = Some(part);
        out
    }

    /// Reads the centres of the spheres `own` from `state`; returns the largest distance one
    /// has moved since the last build (infinite before it).
    pub(super) fn read_own_centers(&mut self, state: &State, own: &[u32]) -> f64 {
        let built_at = self.lists_built().then_some(self.candidates.built_at());
        self.spheres.read_centers_of(state, own, built_at)
    }

    /// After new lists: the own spheres whose motion the lists read, and zero force on the
    /// own spheres that touch nothing now.
    fn learn_partners(&mut self, part: &mut ContactPart) {
        part.partners = self
            .candidates
            .partners()
            .iter()
            .copied()
            .filter(|&s| part.owns(s))
            .collect();
        self.kernel.clear_sums(&part.own);
    }

    /// The broad phase of one rank, once it holds every sphere's centre: the pairs that touch
    /// a sphere it owns, found among the spheres within reach of the box around its own
    /// (along a periodic axis, those with an image there), and its own spheres' wall
    /// candidates; the springs of the pairs that stay are kept.
    pub(super) fn rebuild_near(&mut self, part: &ContactPart, time: f64) {
        let reach =
            2.0 * self.spheres.radius().iter().cloned().fold(0.0, f64::max) + self.settings.skin;
        let (mut low, mut high) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for &s in &part.own {
            low = low.inf(&self.spheres.center()[s as usize]);
            high = high.sup(&self.spheres.center()[s as usize]);
        }
        let (start, width) = (
            low.add_scalar(-reach),
            high - low + Vec3::repeat(2.0 * reach),
        );
        let period = |k: usize| self.periodic.as_ref().and_then(|p| p.length(k));
        let within = |k: usize, x: f64| match period(k) {
            Some(l) if width[k] < l => (x - start[k]).rem_euclid(l) <= width[k],
            Some(_) => true,
            None => x >= start[k] && x - start[k] <= width[k],
        };
        let near: Vec<u32> = (0..self.spheres.center().len() as u32)
            .filter(|&s| (0..3).all(|k| within(k, self.spheres.center()[s as usize][k])))
            .collect();
        self.rebuild_among(part, &near, time);
    }

    /// [`DemContacts::rebuild_near`] among the spheres `near` (ascending).
    fn rebuild_among(&mut self, part: &ContactPart, near: &[u32], time: f64) {
        let skin = self.settings.skin;
        let (center, radius, body) = (
            pick(near, self.spheres.center()),
            pick(near, self.spheres.radius()),
            pick(near, self.spheres.body()),
        );
        let set = SphereSet {
            center: &center,
            radius: &radius,
            body: &body,
            periodic: self.periodic.as_ref(),
        };
        let keys = find_pairs(&set, skin)
            .into_iter()
            .map(|(a, b)| (near[a as usize], near[b as usize]))
            .filter(|&(a, b)| part.owns(a) || part.owns(b))
            .collect();
        self.candidates
            .pairs_mut()
            .rebuild(keys, self.periodic.is_some());
        let own = part.own.par_iter().map(|&s| s as usize);
        let wall_keys = self.wall_keys(own, time);
        self.candidates
            .wall_contacts_mut()
            .rebuild(wall_keys, false);
        self.finish_build(time);
    }

    /// When the lists changed since the last call: the own partners of the new lists, and
    /// the spheres of other ranks they read (ascending).
    pub(super) fn declare_ghosts(&mut self, part: &mut ContactPart) -> Option<Vec<u32>> {
        if !std::mem::take(&mut part.lists_changed) {
            return None;
        }
        self.learn_partners(part);
        let ghosts = self.ghosts_of(part);
        part.ghosts = ghosts.len();
        Some(ghosts)
    }

    /// The partners of this rank's pairs that other ranks own, ascending.
    fn ghosts_of(&self, part: &ContactPart) -> Vec<u32> {
        let mut ghosts: Vec<u32> = self
            .candidates
            .pairs()
            .items
            .iter()
            .flat_map(|c| [c.first, c.second])
            .filter(|&s| !part.owns(s))
            .collect();
        ghosts.sort_unstable();
        ghosts.dedup();
        ghosts
    }

    /// Cuts lists that hold every rank's contacts (after a merge, a restore) down to this
    /// rank's.
    pub(super) fn cut_to_rank(&mut self, part: &mut ContactPart) {
        self.candidates.pairs_mut().retain(|c| part.keeps(c, false));
        self.candidates
            .wall_contacts_mut()
            .retain(|c| part.keeps(c, true));
        self.index_partners();
        part.whole = false;
        part.lists_changed = true;
    }
}

impl DemContacts {
    /// The particle of every contact sphere, the items whose records the ranks exchange, by
    /// stable id (the runtime keeps the items; the engine's slots change at every build:
    /// `spatial_order.rs`).
    pub(super) fn sphere_particles(&self) -> Vec<usize> {
        self.stable_particles()
            .iter()
            .map(|&p| p as usize)
            .collect()
    }

    /// From now on, this rank's part of the contacts (`None`: whole again).
    pub(super) fn set_part(&mut self, part: Option<Part>) {
        self.split = part.map(|p| ContactPart::new(self.spheres.particle(), &p.owner, p.rank));
    }

    /// Appends the records of the spheres of stable ids `items`: centre, velocity and spin.
    pub(super) fn pack_spheres(&self, items: &[u32], out: &mut Vec<f64>) {
        for &id in items {
            let s = self.slot_of(id as usize);
            let n = self.spheres.now(s);
            for v in [self.spheres.center()[s], n.velocity, n.spin] {
                out.extend_from_slice(v.as_slice());
            }
        }
    }

    /// Sets the records of the spheres `items` from what [`DemContacts::pack_spheres`] wrote.
    pub(super) fn unpack_spheres(&mut self, items: &[u32], values: &[f64]) {
        for (&id, v) in items.iter().zip(values.chunks_exact(SPHERE_VALUES)) {
            let (center, velocity) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
            let spin = Vec3::new(v[6], v[7], v[8]);
            let s = self.slot_of(id as usize);
            self.spheres.set_motion(s, center, velocity, spin);
        }
    }

    /// Appends this rank's pairs, then its wall contacts, and returns true; false once
    /// whole.
    pub(super) fn rank_records(&self, out: &mut Vec<f64>) -> bool {
        if self.split.as_ref().is_none_or(|p| p.whole) {
            return false;
        }
        for (list, tag) in [
            (&self.candidates.pairs(), 0.0),
            (&self.candidates.wall_contacts(), 1.0),
        ] {
            for (k, (c, shift)) in list.with_shifts().enumerate() {
                let shift = match tag == 0.0 {
                    true => self.image_as_written(k),
                    false => shift,
                };
                out.extend([tag, c.first as f64, c.second as f64]);
                for v in [c.history, c.force, list.turn[k]] {
                    out.extend_from_slice(v.as_slice());
                }
                out.push(c.half_overlap);
                out.extend_from_slice(shift.as_slice());
                if self.rolling().is_some() {
                    let roll = list.roll.get(k).copied().unwrap_or_default();
                    out.extend_from_slice(roll.as_slice());
                }
            }
        }
        true
    }

    /// Every rank's lists merged into the ones a single process holds (sorted by partners,
    /// a pair that two ranks hold taken once: their records are equal), and every sphere's
    /// contacts summed as one process does (the pair kernel's sums over the records).
    pub(super) fn merge_records(&mut self, all: &[f64]) {
        let at = |v: &[f64], k: usize| Vec3::new(v[k], v[k + 1], v[k + 2]);
        let (mut pairs, mut walls) = (Vec::new(), Vec::new());
        let rolling = self.rolling().is_some();
        let values = CONTACT_VALUES + 3 * rolling as usize;
        for v in all.chunks_exact(values) {
            let contact = Contact {
                first: v[1] as u32,
                second: v[2] as u32,
                history: at(v, 3),
                force: at(v, 6),
                half_overlap: v[12],
            };
            let roll = rolling.then(|| at(v, CONTACT_VALUES));
            let contact = (contact, at(v, 9), at(v, 13), roll);
            match v[0] == 0.0 {
                true => pairs.push(contact),
                false => walls.push(contact),
            }
        }
        let [pairs, walls] = [pairs, walls].map(|mut items| {
            items.sort_by_key(|(c, _, _, _)| (c.first, c.second));
            items.dedup_by_key(|(c, _, _, _)| (c.first, c.second));
            ContactList {
                items: items.iter().map(|e| e.0).collect(),
                turn: items.iter().map(|e| e.1).collect(),
                shift: items.iter().map(|e| e.2).collect(),
                roll: items.iter().filter_map(|e| e.3).collect(),
            }
        });
        self.candidates.set_lists(pairs, walls);
        self.index_partners();
        self.run_kernel::<false, true>(0.0, 0.0, None);
        if let Some(part) = &mut self.split {
            part.whole = true;
        }
    }

    /// Whether the lists were rebuilt since the last call.
    pub(super) fn take_rebuilt(&mut self) -> bool {
        self.candidates.take_rebuilt()
    }

    /// This rank's work at its last evaluation: `SPHERE_WORK` per own sphere and
    /// `CANDIDATE_WORK` per candidate contact.
    pub(super) fn candidate_work(&self) -> f64 {
        SPHERE_WORK * self.own_spheres() as f64 + CANDIDATE_WORK * self.candidates() as f64
    }

    /// Adds `SPHERE_WORK` per sphere to its particle, half of `CANDIDATE_WORK` per candidate
    /// pair to each partner's, all of it per wall candidate.
    pub(super) fn add_candidate_costs(&self, cost: &mut [f64]) {
        let particle = self.spheres.particle();
        for &p in particle {
            cost[p as usize] += SPHERE_WORK;
        }
        let half = 0.5 * CANDIDATE_WORK;
        for c in &self.candidates.pairs().items {
            cost[particle[c.first as usize] as usize] += half;
            cost[particle[c.second as usize] as usize] += half;
        }
        for c in &self.candidates.wall_contacts().items {
            cost[particle[c.first as usize] as usize] += CANDIDATE_WORK;
        }
    }
}

impl Ownership for DemContacts {
    /// The particles of every sphere (those of deformable bodies already have owners).
    fn free_particles(&self) -> Vec<usize> {
        self.sphere_particles()
    }

    fn split(&mut self, part: Option<Part>) {
        self.set_part(part);
    }
}

impl Facets for DemContacts {
    fn evaluation(&mut self) -> Option<&mut dyn Evaluation> {
        Some(self)
    }

    fn lists(&mut self) -> Option<&mut dyn Lists> {
        Some(self)
    }

    fn halo(&mut self) -> Option<&mut dyn Halo> {
        Some(self)
    }

    fn reduction(&mut self) -> Option<&mut dyn Reduction> {
        Some(self)
    }

    fn merge(&mut self) -> Option<&mut dyn Merge> {
        Some(self)
    }

    fn balance(&mut self) -> Option<&mut dyn Balance> {
        Some(self)
    }
}

impl Halo for DemContacts {
    /// The contact spheres.
    fn items(&self) -> Vec<usize> {
        self.sphere_particles()
    }

    /// Centre, velocity and spin.
    fn record_values(&self) -> usize {
        SPHERE_VALUES
    }

    fn pack(&self, items: &[u32], out: &mut Vec<f64>) {
        self.pack_spheres(items, out);
    }

    fn unpack(&mut self, items: &[u32], values: &[f64]) {
        self.unpack_spheres(items, values);
    }

    fn new_ghosts(&mut self) -> Option<Vec<u32>> {
        self.new_ghosts_stage()
    }

    fn read_partners(&mut self, state: &State) {
        self.read_partners_stage(state);
    }
}

impl Lists for DemContacts {
    /// Stage 1 (`stages.rs`).
    fn moved(&mut self, state: &State) -> f64 {
        self.read_own_stage(state)
    }

    fn needs_rebuild(&self, moved: f64, time: f64) -> bool {
        self.needs_rebuild_stage(moved, time)
    }

    fn rebuild(&mut self, time: f64) {
        self.rebuild_stage(time);
    }
}

impl Evaluation for DemContacts {
    fn compute(&mut self, state: &State) {
        self.compute_stage(state.time);
    }

    /// Each own partner's sum, in the single process's order, added to its particle.
    fn apply(&mut self, force: &mut [Vec3], torque: &mut [Vec3]) {
        self.apply_stage(force, torque);
    }
}

impl Reduction for DemContacts {
    /// A time-delayed boundary's pairs and the servo walls' contacts (`stages.rs`).
    fn mine(&mut self, out: &mut Vec<f64>) -> bool {
        self.reduction_stage(out)
    }

    fn reduced(&mut self, time: f64, all: &[f64]) {
        self.reduced_stage(time, all);
    }
}

impl Merge for DemContacts {
    fn records(&self, out: &mut Vec<f64>) -> bool {
        self.rank_records(out)
    }

    fn merge(&mut self, all: &[f64]) {
        self.merge_records(all);
    }
}

impl Balance for DemContacts {
    fn rebuilt(&mut self) -> bool {
        self.take_rebuilt()
    }

    fn work(&self) -> f64 {
        self.candidate_work()
    }

    fn add_costs(&self, cost: &mut [f64]) {
        self.add_candidate_costs(cost);
    }
}

/// The entries `indices` of `values`.
fn pick<T: Copy>(indices: &[u32], values: &[T]) -> Vec<T> {
    indices.iter().map(|&i| values[i as usize]).collect()
}
