//! The pair kernel, the one loop of narrow phase → contact law → per-sphere sums that every
//! evaluation runs: one process, a rank of a decomposed run, and the evaluation with a
//! time-delayed boundary (paper 000 §4; the law of each pair is `contact_law.rs`'s, its
//! forces on delayed ghosts scaled by paper 003 Eqs. 6–7).
//!
//! The spheres are cut into fixed runs ([`run_length`]: by sphere index, whatever the number
//! of threads or ranks; an even number of runs of at most [`RUN_CHUNK`], so that two
//! threads share them equally). A run owns the candidate pairs whose first sphere it holds
//! (the lists are sorted by partners, so these are one slice of the list) and the wall
//! contacts of its spheres. It evaluates them in list order and adds each contact's force and
//! moment straight into the sums of its own spheres (pairs, then walls) and, for a second
//! sphere beyond the run, into a small accumulator of that run's own ("foreign" sums, one
//! slot per distinct such sphere, planned at each build). A serial pass then adds, for every
//! partner of a candidate, its foreign sums in ascending run order and its own run's sum
//! last, and the total to its particle: each sphere's sum is the same sequence of additions
//! for any thread count, without atomics. A sphere that receives no foreign sums and whose
//! particle and rotation no other sphere shares (a one-sphere grain, a vertex of a deformable
//! body) is complete when its run ends: the run adds it to its particle itself, so the serial
//! pass runs over the spheres near a run's start alone.
//!
//! A rank's lists are the sub-sequence of one process's that touches its own spheres, so
//! each own sphere's sum is the same sequence of additions as on one process; a rank adds
//! only its own spheres' sums. When a reduction must read this evaluation's forces first (a
//! time-delayed boundary's ghost scales, a servo wall's load: `stages.rs`), the kernel runs
//! in two passes over the same runs, the law (keeping each contact's n × f beside its
//! record) and then the sums, which add the same shares in the same order as the fused pass.
//! A time-delayed boundary reads only the pairs through it, so once the lists' image
//! translations are taken (below) its first pass is the law of those pairs alone
//! ([`DemContacts::boundary_laws`]), and the fused pass runs the law of every other contact
//! and adds every share, a boundary pair's from its record: the same forces (a pair's law
//! reads its own record only, and the lanes give the scalar law's bits) added in the same
//! order, without a second pass over the lists. One process only: a rank keeps the two
//! passes.
//!
//! Per step a candidate pair costs its record (read and written once) and two additions into
//! sums that are in cache, and the serial add runs over the partners of candidates only.
//!
//! Through a periodic boundary a pair's image translation t (the whole periods that make
//! d + t the minimum image of d = x_b − x_a, paper 003 Eq. 1) is taken at the first law pass
//! after each build of the lists, kept in the lists' column, and read from it at the passes
//! after: between two builds no sphere moves half the skin, so the separation of a candidate,
//! within reach + skin of its image at the build and L/2 > reach + skin
//! ([`PeriodicBox::check_reach`](crate::boundaries::periodic_boundary::PeriodicBox::check_reach)),
//! rounds to the same whole periods; a body that the periodic wrap moves by a whole period
//! has moved beyond the skin, so the lists are rebuilt before the next law pass. Only a pair
//! drawn L/2 apart along a periodic axis could keep an image the minimum image would change
//! (in a cell shorter than 2 (reach + 2 skin)), and it is apart through either image.

use super::rolling::{first_rolls, second_rolls};
use super::*;
use crate::dem::laws::law_lanes::{LawLanes, LANES as LAW_LANES};
use qdem_core::continuum::tet_lanes::LaneSet;
use std::ops::Range;

/// The most spheres in a run of the fused pass.
pub(crate) const RUN_CHUNK: usize = 2048;

/// A force and a moment.
type Sum = (Vec3, Vec3);

/// Spheres per run of `n` spheres: one run of up to [`RUN_CHUNK`], else an even number
/// of runs of at most [`RUN_CHUNK`], as equal as can be. It depends on `n` alone, so the
/// order of every sum does not depend on the number of threads or ranks.
pub(super) fn run_length(n: usize) -> usize {
    match n <= RUN_CHUNK {
        true => RUN_CHUNK,
        false => n.div_ceil(2 * n.div_ceil(2 * RUN_CHUNK)),
    }
}

#[cfg(test)]
impl DemContacts {
    /// The run of sphere `s`.
    fn run_of(&self, s: u32) -> usize {
        s as usize / run_length(self.spheres.len())
    }

    /// Runs the law of the pairs with the lanes of `set`, whatever this CPU's choice.
    fn force_lanes(&mut self, set: LaneSet) {
        self.kernel.lanes = LawSet(set);
    }

    /// Makes the next law pass take every pair's image translation again, as after a build.
    fn forget_images(&mut self) {
        self.kernel.images = false;
    }
}

/// What the fused pass knows of the lists, made at each build, and its per-sphere sums.
#[derive(Default)]
pub(super) struct KernelPlan {
    /// The lane set the law of the pairs runs with.
    lanes: LawSet,
    /// Per sphere, the sum of its contacts' forces and moments at the last evaluation.
    sums: Vec<Sum>,
    /// Per run: its pairs (a slice of the pair list), wall contacts and partners (a slice of
    /// [`DemContacts::partners`]).
    runs: Vec<RunPlan>,
    /// Per pair: where its second sphere's share goes in its run: `s − lo` for a sphere of the
    /// run, `RUN_CHUNK + k` for the run's k-th foreign sphere.
    slot: Vec<u32>,
    /// The foreign sums: (sphere, run, slot in that run's accumulator), sorted.
    receive: Vec<(u32, u32, u32)>,
    /// Per run, its foreign accumulator (scratch).
    foreign: Vec<Vec<Sum>>,
    /// Per partner (as [`DemContacts::partners`]), whether its run adds it to its particle.
    early: Vec<bool>,
    /// The partners the serial pass adds, ascending.
    late: Vec<u32>,
    /// Whether the lists' column of image translations was taken by a law pass since this
    /// plan was made: a candidate's image is the same until the next build (module doc).
    images: bool,
    /// The delay axis, when [`DemContacts::boundary_laws`] ran the law of the pairs through
    /// it in this evaluation: the fused pass reads their records instead.
    boundary: Option<usize>,
    /// The indices of those pairs, ascending (what the boundary's reduction reads).
    boundary_pairs: Vec<u32>,
}

/// The lane set the pair kernel runs the law with: [`LaneSet::detected`], the tetrahedron
/// kernel's choice.
#[derive(Clone, Copy)]
struct LawSet(LaneSet);

impl Default for LawSet {
    fn default() -> LawSet {
        LawSet(LaneSet::detected())
    }
}

/// One run's share of the lists.
#[derive(Clone, Default)]
struct RunPlan {
    pairs: Range<usize>,
    walls: Range<usize>,
    partners: Range<usize>,
}

impl KernelPlan {
    /// No plan yet, and zero sums for `spheres` spheres.
    pub(super) fn new(spheres: usize) -> KernelPlan {
        KernelPlan {
            sums: vec![(Vec3::zeros(), Vec3::zeros()); spheres],
            ..KernelPlan::default()
        }
    }

    /// Sphere `s`'s sum of its contacts' forces and moments at the last evaluation.
    pub(super) fn sum(&self, s: usize) -> &Sum {
        &self.sums[s]
    }

    /// Zero sums for `spheres` (which touch nothing now).
    pub(super) fn clear_sums(&mut self, spheres: &[u32]) {
        for &s in spheres {
            self.sums[s as usize] = (Vec3::zeros(), Vec3::zeros());
        }
    }
}

impl DemContacts {
    /// The plan of the fused pass for the current lists.
    pub(super) fn plan_runs(&mut self) {
        let n = self.spheres.len();
        let length = run_length(n);
        let runs = n.div_ceil(length);
        let (pairs, walls) = (
            &self.candidates.pairs().items,
            &self.candidates.wall_contacts().items,
        );
        let mut plan = std::mem::take(&mut self.kernel);
        plan.runs.clear();
        plan.slot.clear();
        plan.slot.resize(pairs.len(), 0);
        plan.receive.clear();
        plan.foreign.resize(runs, Vec::new());
        let start = |lo: u32| {
            (
                pairs.partition_point(|c| c.first < lo),
                walls.partition_point(|c| c.first < lo),
                self.candidates.partners().partition_point(|&s| s < lo),
            )
        };
        let mut foreign = Vec::new();
        for r in 0..runs {
            let (lo, hi) = ((r * length) as u32, ((r + 1) * length).min(n) as u32);
            let (from, to) = (start(lo), start(hi));
            let run = RunPlan {
                pairs: from.0..to.0,
                walls: from.1..to.1,
                partners: from.2..to.2,
            };
            foreign.clear();
            foreign.extend(
                pairs[run.pairs.clone()]
                    .iter()
                    .map(|c| c.second)
                    .filter(|&b| b >= hi),
            );
            foreign.sort_unstable();
            foreign.dedup();
            for k in run.pairs.clone() {
                let b = pairs[k].second;
                plan.slot[k] = match b < hi {
                    true => b - lo,
                    false => RUN_CHUNK as u32 + foreign.binary_search(&b).expect("planned") as u32,
                };
            }
            let r32 = r as u32;
            plan.receive
                .extend(foreign.iter().enumerate().map(|(k, &b)| (b, r32, k as u32)));
            plan.foreign[r].resize(foreign.len(), (Vec3::zeros(), Vec3::zeros()));
            plan.runs.push(run);
        }
        plan.receive.sort_unstable();
        plan.early.clear();
        plan.late.clear();
        let mut receive = plan.receive.iter().map(|e| e.0).peekable();
        for &s in self.candidates.partners() {
            let receives = receive.next_if_eq(&s).is_some();
            while receive.next_if_eq(&s).is_some() {}
            let early = self.spheres.exclusive(s as usize) && !receives;
            plan.early.push(early);
            if !early {
                plan.late.push(s);
            }
        }
        // Spheres that touch nothing keep a zero sum until the next build.
        plan.sums.fill((Vec3::zeros(), Vec3::zeros()));
        plan.images = false;
        self.kernel = plan;
    }

    /// The pair kernel over every run in parallel: with `LAW`, the narrow phase and the law
    /// of every candidate (its record, and its n × f column when a later pass or a merge
    /// reads it); with `SUM`, each contact's shares added into the per-sphere sums, then the
    /// serial pass that completes the sums of the spheres a run could not. With `out` (the
    /// particle forces and the rotations' torques), each complete sum of a sphere this
    /// process or rank owns is added there too: by its run for an early sphere, in the serial
    /// pass for the others.
    pub(super) fn run_kernel<const LAW: bool, const SUM: bool>(
        &mut self,
        time: f64,
        dt: f64,
        mut out: Option<(&mut [Vec3], &mut [Vec3])>,
    ) {
        let keep_turn = LAW && (!SUM || self.split.is_some());
        let mut plan = std::mem::take(&mut self.kernel);
        let boundary = plan.boundary.take();
        let mut pairs = std::mem::take(self.candidates.pairs_mut());
        let mut walls = std::mem::take(self.candidates.wall_contacts_mut());
        if LAW {
            for (list, pair_list) in [(&mut pairs, true), (&mut walls, false)] {
                // The boundary pairs' n × f, from `boundary_laws`, stays for this pass.
                if !(pair_list && boundary.is_some()) {
                    list.turn.clear();
                }
                if keep_turn {
                    list.turn.resize(list.items.len(), Vec3::zeros());
                }
                if self.rolling().is_some() {
                    list.keep_rolling();
                }
            }
        }
        let mut sums = std::mem::take(&mut plan.sums);
        {
            let carriers = out
                .as_mut()
                .map(|(force, torque)| (Carriers::new(force), Carriers::new(torque)));
            let runs = &plan.runs;
            let pair_lengths = || runs.iter().map(|r| r.pairs.len());
            let wall_lengths = || runs.iter().map(|r| r.walls.len());
            let lists: Vec<RunLists<'_>> = cut(&mut pairs.items, pair_lengths())
                .into_iter()
                .zip(cut_column(&mut pairs.shift, pair_lengths()))
                .zip(cut_column(&mut pairs.turn, pair_lengths()))
                .zip(cut(&mut walls.items, wall_lengths()))
                .zip(cut_column(&mut walls.turn, wall_lengths()))
                .zip(cut_column(&mut pairs.roll, pair_lengths()))
                .zip(cut_column(&mut walls.roll, wall_lengths()))
                .map(
                    |((((((pairs, shifts), turns), walls), wall_turns), rolls), wall_rolls)| {
                        RunLists {
                            pairs,
                            shifts,
                            turns,
                            walls,
                            wall_turns,
                            rolls,
                            wall_rolls,
                        }
                    },
                )
                .collect();
            let this = &*self;
            // A time-delayed boundary scales the shares of pairs through it; without one the
            // kernel is compiled with unit scales (the multiplications folded away).
            let scaled = self.time_delay.is_some();
            let (slot, early, lanes) = (&plan.slot, &plan.early, plan.lanes.0);
            let images = plan.images;
            let length = run_length(sums.len());
            let inputs: Vec<_> = sums
                .chunks_mut(length)
                .zip(plan.foreign.iter_mut())
                .zip(lists)
                .collect();
            let cost =
                |r: usize| runs[r].pairs.len() + runs[r].walls.len() + runs[r].partners.len();
            run_threads::for_each_run(inputs, cost, |(r, ((own, foreign), lists))| {
                let run = &runs[r];
                let lo = (r * length) as u32;
                let slots = &slot[run.pairs.clone()];
                let partners = &this.candidates.partners()[run.partners.clone()];
                let sums = RunSums { own, foreign, lo };
                let input = (lists, slots, partners, sums);
                let known = (images, boundary);
                match scaled {
                    true => this.evaluate_run::<LAW, SUM, true>(time, dt, lanes, known, input),
                    false => this.evaluate_run::<LAW, SUM, false>(time, dt, lanes, known, input),
                }
                let (true, Some(carriers)) = (SUM, &carriers) else {
                    return;
                };
                let early = &early[run.partners.clone()];
                for (&s, _) in partners.iter().zip(early).filter(|(_, &e)| e) {
                    if !this.adds_to(s) {
                        continue;
                    }
                    let (f, t) = &own[(s - lo) as usize];
                    // SAFETY: an early sphere's particle and rotation are its own
                    // (`exclusive_carriers`), and each sphere is in one run.
                    unsafe { this.add_exclusive(s as usize, f, t, carriers) };
                }
            });
        }
        self.candidates.set_lists(pairs, walls);
        plan.images |= LAW;
        if SUM {
            let mut receive = plan.receive.iter().peekable();
            for &s in &plan.late {
                let mut total: Option<Sum> = None;
                while let Some(&(_, r, k)) = receive.next_if(|e| e.0 == s) {
                    total = Some(add_sum(total, plan.foreign[r as usize][k as usize]));
                }
                let total = add_sum(total, sums[s as usize]);
                sums[s as usize] = total;
                if let Some((force, torque)) = &mut out {
                    if self.adds_to(s) {
                        self.spheres
                            .add_to(s as usize, &total.0, &total.1, force, torque);
                    }
                }
            }
        }
        plan.sums = sums;
        self.kernel = plan;
    }

    /// Pair `k`'s image translation as a law pass taking it now would write it, for what a
    /// checkpoint or a merge of the ranks' records keeps: the column's whole periods (they
    /// hold since the build), with the sign of each zero component from this evaluation's
    /// separation d = x_b − x_a as [`PeriodicBox::image_shift`](crate::PeriodicBox::image_shift)
    /// signs it, −l · (±0): −0 for d ≥ +0, +0 below. The column as it is when no law pass
    /// ran since the lists were made (a restore, a merge: it holds what was written).
    pub(super) fn image_as_written(&self, k: usize) -> Vec3 {
        let pairs = self.candidates.pairs();
        let mut t = pairs.shift(k);
        let Some(cell) = self.periodic.as_ref().filter(|_| self.kernel.images) else {
            return t;
        };
        let c = &pairs.items[k];
        let d =
            self.spheres.now(c.second as usize).center - self.spheres.now(c.first as usize).center;
        for axis in 0..3 {
            if cell.length(axis).is_some() && t[axis] == 0.0 {
                t[axis] = -(0.0f64.copysign(d[axis]));
            }
        }
        t
    }

    /// Stage 5 with a time-delayed boundary along `axis`, on one process, once the lists'
    /// image translations are taken (module doc): the law of the pairs whose image crosses
    /// `axis` alone, each one's n × f kept beside its record for the reduction and for the
    /// fused pass of stage 6, which runs the law of every other contact. Returns false, and
    /// runs nothing, where that does not hold (a rank, a servo wall, the first law pass after
    /// a build): the caller then runs the law of every contact.
    pub(super) fn boundary_laws(&mut self, dt: f64, axis: usize) -> bool {
        let pairs = self.candidates.pairs();
        if !self.kernel.images
            || self.split.is_some()
            || self.has_servo()
            || pairs.shift.len() != pairs.items.len()
        {
            return false;
        }
        let mut pairs = std::mem::take(self.candidates.pairs_mut());
        pairs.turn.clear();
        pairs.turn.resize(pairs.items.len(), Vec3::zeros());
        if self.rolling().is_some() {
            pairs.keep_rolling();
        }
        let law = &self.settings.law;
        let mut through = std::mem::take(&mut self.kernel.boundary_pairs);
        through.clear();
        let mut lists = RunLists {
            pairs: &mut pairs.items,
            shifts: &mut pairs.shift,
            turns: &mut pairs.turn,
            walls: &mut [],
            wall_turns: &mut [],
            rolls: &mut pairs.roll,
            wall_rolls: &mut [],
        };
        for k in 0..lists.pairs.len() {
            let shift = lists.shifts[k];
            if shift[axis] == 0.0 {
                continue;
            }
            through.push(k as u32);
            let contact = &mut lists.pairs[k];
            let Some((pair, e)) = self.spheres_through(contact, shift) else {
                part(contact, [lists.turns.get_mut(k), lists.rolls.get_mut(k)]);
                continue;
            };
            let g = pair.geometry();
            let f = law.force(&g, &e, &mut contact.history, dt);
            let touching = (g.normal, g.overlap);
            self.record_pair(k, f, touching, || (g, e), &mut lists, dt);
        }
        *self.candidates.pairs_mut() = pairs;
        self.kernel.boundary = Some(axis);
        self.kernel.boundary_pairs = through;
        true
    }

    /// The pairs through the time-delayed boundary whose law [`DemContacts::boundary_laws`]
    /// ran in this evaluation, by index in the list; `None` where it did not run.
    pub(super) fn boundary_pairs(&self) -> Option<&[u32]> {
        self.kernel
            .boundary
            .map(|_| self.kernel.boundary_pairs.as_slice())
    }

    /// Adds the complete sum of every partner this process or rank owns to its particle
    /// (`force`) and rotation (`torque`), in ascending sphere order: after a kernel pass that
    /// summed without them.
    pub(super) fn add_partner_sums(&self, force: &mut [Vec3], torque: &mut [Vec3]) {
        for &s in self
            .candidates
            .partners()
            .iter()
            .filter(|&&s| self.adds_to(s))
        {
            let (f, t) = self.kernel.sum(s as usize);
            self.spheres.add_to(s as usize, f, t, force, torque);
        }
    }

    /// One run: its partners' sums set to zero, then each pair in list order (its shares to
    /// its first sphere and to its second, in the run or foreign), then each wall contact.
    /// With `LAW`, a contact's force comes from the narrow phase and the law, and a contact
    /// found apart adds nothing; without, from its record and n × f column, scaled for a
    /// ghost beyond a time-delayed boundary (paper 003 Eqs. 6–7) when `SCALED`. With a vector
    /// lane set, the touching pairs wait in a batch for the law across lanes
    /// ([`LawLanes`]) and are recorded and summed in list order when it is full: the sums
    /// take the same additions in the same order, since an apart pair adds nothing. A
    /// pair's image translation is taken into the lists' column unless `images` says the
    /// column holds it since the build. With `boundary` (the delay axis, `SCALED` only), the
    /// pairs through it had their law in [`DemContacts::boundary_laws`]: each is summed from
    /// its record, after the waiting batch, so that the shares stay in list order.
    #[inline(always)]
    fn evaluate_run<const LAW: bool, const SUM: bool, const SCALED: bool>(
        &self,
        time: f64,
        dt: f64,
        lanes: LaneSet,
        (images, boundary): (bool, Option<usize>),
        (mut lists, slots, partners, mut sums): (RunLists<'_>, &[u32], &[u32], RunSums<'_>),
    ) {
        let law = &self.settings.law;
        let delay = self.time_delay.as_ref().map(TimeDelay::ghosts);
        if SUM {
            for &s in partners {
                sums.own[(s - sums.lo) as usize] = (Vec3::zeros(), Vec3::zeros());
            }
            sums.foreign.fill((Vec3::zeros(), Vec3::zeros()));
        }
        let in_lanes = LAW && lanes != LaneSet::Scalar;
        let mut batch = Batch {
            lanes: LawLanes::default(),
            pairs: [0; LAW_LANES],
            set: lanes,
        };
        for k in 0..lists.pairs.len() {
            let turn = match LAW {
                true => {
                    let contact = &mut lists.pairs[k];
                    let shift = match lists.shifts.get_mut(k) {
                        Some(at) if !images => {
                            *at = self.image_of(contact);
                            *at
                        }
                        Some(at) => *at,
                        None => Vec3::zeros(),
                    };
                    if SCALED && boundary.is_some_and(|axis| shift[axis] != 0.0) {
                        if in_lanes && batch.lanes.len() > 0 {
                            self.finish_batch::<SUM, SCALED>(
                                dt, &mut batch, &mut lists, slots, &delay, &mut sums,
                            );
                        }
                        if SUM {
                            let turn = lists.turns[k];
                            self.add_pair::<SCALED>(k, &turn, &lists, slots[k], &delay, &mut sums);
                        }
                        continue;
                    }
                    let Some((pair, e)) = self.spheres_through(contact, shift) else {
                        part(contact, [lists.turns.get_mut(k), lists.rolls.get_mut(k)]);
                        continue;
                    };
                    if in_lanes {
                        batch.pairs[batch.lanes.push_spheres(&pair, &e, &contact.history)] = k;
                        if batch.lanes.is_full() {
                            self.finish_batch::<SUM, SCALED>(
                                dt, &mut batch, &mut lists, slots, &delay, &mut sums,
                            );
                        }
                        continue;
                    }
                    let g = pair.geometry();
                    let f = law.force(&g, &e, &mut contact.history, dt);
                    let touching = (g.normal, g.overlap);
                    self.record_pair(k, f, touching, || (g, e), &mut lists, dt)
                }
                false => lists.turns[k],
            };
            if SUM {
                self.add_pair::<SCALED>(k, &turn, &lists, slots[k], &delay, &mut sums);
            }
        }
        if in_lanes && batch.lanes.len() > 0 {
            self.finish_batch::<SUM, SCALED>(dt, &mut batch, &mut lists, slots, &delay, &mut sums);
        }
        let RunLists {
            walls,
            wall_turns,
            wall_rolls,
            ..
        } = lists;
        let RunSums { own, lo, .. } = sums;
        for (k, contact) in walls.iter_mut().enumerate() {
            let s = contact.first as usize;
            let turn = match LAW {
                true => {
                    let Some((g, e)) = self.wall_contact(time, s, contact.second as usize) else {
                        part(contact, [wall_turns.get_mut(k), wall_rolls.get_mut(k)]);
                        continue;
                    };
                    let f = law.force(&g, &e, &mut contact.history, dt);
                    if let Some(roll) = wall_rolls.get_mut(k) {
                        self.roll_wall(contact, (&g, &e), &f, roll, dt);
                    }
                    let turn = contact.touch(f, &g.normal, g.overlap);
                    if let Some(at) = wall_turns.get_mut(k) {
                        *at = turn;
                    }
                    turn
                }
                false => wall_turns[k],
            };
            if SUM {
                let share = wall_share(contact, &turn, self.spheres.now(s).radius);
                add_to(
                    &mut own[s - lo as usize],
                    first_rolls(share, wall_rolls.get(k), 1.0),
                );
            }
        }
    }

    /// The law of the waiting pairs of `batch` across its lanes, then each pair recorded
    /// (and summed with `SUM`) in list order; empties the batch.
    #[inline(always)]
    fn finish_batch<const SUM: bool, const SCALED: bool>(
        &self,
        dt: f64,
        batch: &mut Batch,
        lists: &mut RunLists<'_>,
        slots: &[u32],
        delay: &Option<(usize, GhostScales)>,
        sums: &mut RunSums<'_>,
    ) {
        batch.lanes.evaluate(&self.settings.law, batch.set, dt);
        for (l, &k) in batch.pairs[..batch.lanes.len()].iter().enumerate() {
            lists.pairs[k].history = batch.lanes.history(l);
            let (f, lanes) = (batch.lanes.force(l), &batch.lanes);
            let touching = (lanes.normal(l), lanes.overlap(l));
            let turn = self.record_pair(k, f, touching, || lanes.contact(l), lists, dt);
            if SUM {
                self.add_pair::<SCALED>(k, &turn, lists, slots[k], delay, sums);
            }
        }
        batch.lanes.clear();
    }

    /// Records touching pair `k`'s force `f` with its (normal, overlap) (its spring already
    /// updated), and its rolling spring from its geometry and elasticity (`contact`, read
    /// only with rolling friction); returns n × f, kept in the run's column when the lists
    /// hold one.
    #[inline(always)]
    fn record_pair(
        &self,
        k: usize,
        f: Vec3,
        (normal, overlap): (Vec3, f64),
        contact: impl FnOnce() -> (PairGeometry, PairElasticity),
        lists: &mut RunLists<'_>,
        dt: f64,
    ) -> Vec3 {
        let record = &mut lists.pairs[k];
        if let Some(roll) = lists.rolls.get_mut(k) {
            let (g, e) = contact();
            self.roll_pair(record, (&g, &e), &f, roll, dt);
        }
        let turn = record.touch(f, &normal, overlap);
        if let Some(at) = lists.turns.get_mut(k) {
            *at = turn;
        }
        turn
    }

    /// Adds pair `k`'s shares (n × f `turn`) to its first sphere's sum and to its second's
    /// (`slot`: in the run or foreign), with the rolling torque, scaled for a ghost beyond a
    /// time-delayed boundary when `SCALED`.
    #[inline(always)]
    fn add_pair<const SCALED: bool>(
        &self,
        k: usize,
        turn: &Vec3,
        lists: &RunLists<'_>,
        slot: u32,
        delay: &Option<(usize, GhostScales)>,
        sums: &mut RunSums<'_>,
    ) {
        let contact = &lists.pairs[k];
        let (a, b) = (contact.first as usize, contact.second as usize);
        let (scale_a, scale_b) = match (SCALED, delay) {
            (true, Some((axis, scales))) => pair_scales(lists.shifts[k][*axis], scales),
            _ => (1.0, 1.0),
        };
        let (first, second) = (
            pair_share(contact, turn, true, self.spheres.now(a).radius, scale_a),
            pair_share(contact, turn, false, self.spheres.now(b).radius, scale_b),
        );
        let roll = lists.rolls.get(k);
        let (first, second) = (
            first_rolls(first, roll, scale_a),
            second_rolls(second, roll, scale_b),
        );
        add_to(&mut sums.own[a - sums.lo as usize], first);
        match (slot as usize).checked_sub(RUN_CHUNK) {
            None => add_to(&mut sums.own[slot as usize], second),
            Some(k) => add_to(&mut sums.foreign[k], second),
        }
    }
}

/// Force or torque sums that the runs of the pair kernel add to in parallel, each element
/// from one sphere only.
struct Carriers {
    at: *mut Vec3,
    len: usize,
}

// SAFETY: the runs write disjoint elements (`DemContacts::add_exclusive`).
unsafe impl Sync for Carriers {}

impl Carriers {
    fn new(sums: &mut [Vec3]) -> Carriers {
        Carriers {
            at: sums.as_mut_ptr(),
            len: sums.len(),
        }
    }

    /// `sums[i] += v`.
    ///
    /// # Safety
    /// No other thread reads or writes element `i` while the `Carriers` lives.
    #[inline]
    unsafe fn add(&self, i: usize, v: &Vec3) {
        assert!(i < self.len, "carrier {i} beyond {}", self.len);
        *self.at.add(i) += v;
    }
}

/// Parts a contact whose spheres are apart: its record, and its n × f and rolling columns
/// zeroed where the lists hold them.
#[inline(always)]
fn part(contact: &mut Contact, columns: [Option<&mut Vec3>; 2]) {
    contact.part();
    for at in columns.into_iter().flatten() {
        *at = Vec3::zeros();
    }
}

/// Per sphere on `particle` adding its moment to `turn`, whether no other sphere shares its
/// particle or the rotation it adds to (always so for one-sphere grains and the vertices of
/// deformable bodies; not for the spheres of a rigid body).
pub(super) fn exclusive_carriers(particle: &[u32], turn: &[u32]) -> Vec<bool> {
    let mut count = std::collections::HashMap::<(bool, u32), u32>::new();
    let keys = |s: usize| [(false, particle[s]), (true, turn[s])];
    for s in 0..particle.len() {
        for key in keys(s).into_iter().filter(|k| k.1 != NOT_RIGID) {
            *count.entry(key).or_default() += 1;
        }
    }
    (0..particle.len())
        .map(|s| keys(s).iter().all(|k| k.1 == NOT_RIGID || count[k] == 1))
        .collect()
}

impl DemContacts {
    /// [`Spheres::add_to`](super::spheres::Spheres::add_to) from a run of the fused pass.
    ///
    /// # Safety
    /// No other sphere adds to sphere `s`'s particle or rotation at the same time.
    #[inline]
    unsafe fn add_exclusive(
        &self,
        s: usize,
        f: &Vec3,
        t: &Vec3,
        (force, torque): &(Carriers, Carriers),
    ) {
        force.add(self.spheres.particle()[s] as usize, f);
        if self.spheres.turn()[s] != NOT_RIGID {
            torque.add(self.spheres.turn()[s] as usize, t);
        }
    }
}

/// The share of pair `c` (with n × f `turn`) of sphere `first` (else the second), of radius
/// `radius`, with its ghost scale `scale`: ±`scale` f and the moment (r − δ/2) `scale` n × f.
#[inline]
fn pair_share(c: &Contact, turn: &Vec3, first: bool, radius: f64, scale: f64) -> Sum {
    let f = if first { scale } else { -scale } * c.force;
    (f, c.moment(turn, radius, scale))
}

/// The share of wall contact `c` (with n × f `turn`) of its sphere, of radius `radius`.
#[inline]
fn wall_share(c: &Contact, turn: &Vec3, radius: f64) -> Sum {
    (c.force, c.moment(turn, radius, 1.0))
}

/// A run's slices of the candidate lists: its pairs, their image translations and n × f
/// (each empty when the lists hold no such column), its wall contacts and their n × f, and
/// the rolling springs of both (empty without rolling friction).
struct RunLists<'a> {
    pairs: &'a mut [Contact],
    shifts: &'a mut [Vec3],
    turns: &'a mut [Vec3],
    walls: &'a mut [Contact],
    wall_turns: &'a mut [Vec3],
    rolls: &'a mut [Vec3],
    wall_rolls: &'a mut [Vec3],
}

/// The touching pairs of a run waiting for the law across lanes: their geometry and springs
/// in `lanes`, their indices in the run's pairs, and the lane set.
struct Batch {
    lanes: LawLanes,
    pairs: [usize; LAW_LANES],
    set: LaneSet,
}

/// A run's sums: those of its own spheres (from sphere `lo` on) and its foreign sums.
struct RunSums<'a> {
    own: &'a mut [Sum],
    foreign: &'a mut [Sum],
    lo: u32,
}

/// `sum += share`.
#[inline]
fn add_to(sum: &mut Sum, share: Sum) {
    sum.0 += share.0;
    sum.1 += share.1;
}

/// The running total of a sphere's partial sums, in run order: the first partial itself,
/// then each further one added.
#[inline]
fn add_sum(total: Option<Sum>, partial: Sum) -> Sum {
    match total {
        None => partial,
        Some((f, t)) => (f + partial.0, t + partial.1),
    }
}

/// A column of the lists (`column`, empty when the lists hold none) cut into the runs'
/// slices of `lengths`: empty slices when empty.
fn cut_column<T>(column: &mut [T], lengths: impl Iterator<Item = usize>) -> Vec<&mut [T]> {
    let empty = column.is_empty();
    cut(column, lengths.map(|n| if empty { 0 } else { n }))
}

/// `items` cut into consecutive slices of `lengths`.
fn cut<T>(items: &mut [T], lengths: impl Iterator<Item = usize>) -> Vec<&mut [T]> {
    let mut rest = items;
    let mut out = Vec::new();
    for len in lengths {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
        out.push(head);
        rest = tail;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::laws::hertz_mindlin::HertzMindlin;
    use crate::dem::walls::plane_wall::PlaneWall;
    use crate::dem::walls::wall::WallShape;

    /// 18 × 18 × 16 spheres (2.5 runs) on a jittered lattice closer than their diameter,
    /// turning, with velocities and spins, over a floor: many pairs cross a run boundary.
    fn packing() -> (State, DemContacts) {
        let law = ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.2 });
        packing_with(law)
    }

    /// [`packing`] with the contact law `law`.
    fn packing_with(law: ContactLaw) -> (State, DemContacts) {
        let r = 0.005;
        let mut centers = Vec::new();
        for k in 0..16 {
            for j in 0..18 {
                for i in 0..18 {
                    let jitter = ((i * 7 + j * 13 + k * 29) % 17) as f64 / 17.0 - 0.5;
                    centers.push(Vec3::new(
                        (1.98 * i as f64) * r + 0.02 * r * jitter,
                        (1.98 * j as f64) * r - 0.02 * r * jitter,
                        (1.98 * k as f64 + 0.99) * r,
                    ));
                }
            }
        }
        let n = centers.len();
        let mut state = State::at_rest(centers);
        state.mass = vec![1e-3; n];
        for p in 0..n {
            let f = |m: usize| ((p * m) % 101) as f64 / 101.0 - 0.5;
            state.velocity[p] = Vec3::new(f(37), f(53), f(71));
            state.let_turn(p, 1e-8);
            state.spin.velocity[p] = Vec3::new(f(11), f(17), f(23)) * 10.0;
        }
        let spheres: Vec<ContactSphere> = (0..n)
            .map(|p| ContactSphere {
                particle: p,
                radius: r,
                body: p,
                material: 0,
            })
            .collect();
        let floor = Wall {
            shape: WallShape::Plane(PlaneWall::new(Vec3::zeros(), Vec3::z(), Vec3::zeros())),
            friction: 0.4,
        };
        let settings = ContactSettings {
            law,
            friction: 0.5,
            skin: 0.001,
        };
        let names = (0..n).map(|p| p.to_string()).collect();
        let contacts = DemContacts::new(
            &state,
            &spheres,
            names,
            &[(5e7, 0.25)],
            settings,
            vec![floor],
        );
        (state, contacts)
    }

    /// Three evaluations 10 µs apart (the springs grow), by the fused pass or by a law pass
    /// then a sum pass (as with a time-delayed boundary): the particle forces and torques of
    /// the last.
    fn forces(fused: bool, threads: usize) -> (Vec<Vec3>, Vec<Vec3>, usize) {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let (mut state, mut contacts) = packing();
            let n = state.len();
            let (mut force, mut torque) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
            for step in 0..3 {
                state.time = 1e-5 * step as f64;
                force.fill(Vec3::zeros());
                torque.fill(Vec3::zeros());
                if fused {
                    contacts.add_forces(&state, &mut force, &mut torque);
                } else {
                    let moved = contacts.read_own_stage(&state);
                    if contacts.needs_rebuild_stage(moved, state.time) {
                        contacts.rebuild_stage(state.time);
                    }
                    contacts.read_partners_stage(&state);
                    let (time, dt) = (state.time, contacts.evaluation.dt());
                    contacts.run_kernel::<true, false>(time, dt, None);
                    let out = Some((&mut force[..], &mut torque[..]));
                    contacts.run_kernel::<false, true>(time, dt, out);
                }
            }
            (force, torque, contacts.contacts())
        })
    }

    #[test]
    fn the_law_and_the_sums_in_two_passes_sum_as_the_fused_pass_bit_for_bit_on_any_thread_count() {
        let (_, contacts) = packing();
        assert!(contacts.spheres() > 2 * RUN_CHUNK);
        let apart = forces(false, 1);
        // Most spheres touch: the comparison is not one of zeros.
        assert!(apart.2 > 10_000, "{} touching contacts", apart.2);
        for threads in [1, 2, 3] {
            let fused = forces(true, threads);
            assert_eq!(fused.2, apart.2);
            for p in 0..fused.0.len() {
                assert_eq!(
                    fused.0[p], apart.0[p],
                    "force on particle {p}, {threads} threads"
                );
                assert_eq!(
                    fused.1[p], apart.1[p],
                    "torque on particle {p}, {threads} threads"
                );
            }
        }
    }

    /// 10 × 10 × 3 spinning spheres about 1.98 r apart in a cell periodic in x and y, thrown
    /// across its faces at about (5, 2.5) m/s with a spread of ±0.15 m/s, moved and wrapped
    /// (as `PeriodicWrap` wraps them) for `steps` steps of 10 µs: per step the particle
    /// forces and torques, the pairs' springs and image translations as a checkpoint writes
    /// them (bits; some with a zero of either sign), with the images
    /// taken once per build, or at every step when `every_step`; and the rebuilds, the wraps
    /// and the touching pairs through the boundary.
    fn periodic_run(every_step: bool, steps: usize) -> (Vec<Vec<u64>>, u64, usize, usize) {
        let (r, a) = (0.005, 1.98 * 0.005);
        let side = 10.0 * a;
        let mut centers = Vec::new();
        for k in 0..3 {
            for j in 0..10 {
                for i in 0..10 {
                    // ±20 µm off the lattice, so that separations cross zero between builds.
                    let off = |m: usize| (((i + 10 * j + 100 * k) * m) % 97) as f64 / 97.0 - 0.5;
                    let at = |n: usize, m: usize| (n as f64 + 0.5) * a + 4e-5 * off(m);
                    centers.push(Vec3::new(at(i, 41), at(j, 43), at(k, 47)));
                }
            }
        }
        let n = centers.len();
        let mut state = State::at_rest(centers);
        state.mass = vec![1e-3; n];
        for p in 0..n {
            let f = |m: usize| ((p * m) % 101) as f64 / 101.0 - 0.5;
            state.velocity[p] = Vec3::new(5.0 + 0.3 * f(37), 2.5 + 0.3 * f(53), 0.3 * f(71));
            state.let_turn(p, 1e-8);
            state.spin.velocity[p] = Vec3::new(f(11), f(17), f(23)) * 10.0;
        }
        let spheres: Vec<ContactSphere> = (0..n)
            .map(|p| ContactSphere {
                particle: p,
                radius: r,
                body: p,
                material: 0,
            })
            .collect();
        let settings = ContactSettings {
            law: ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.2 }),
            friction: 0.5,
            skin: 0.001,
        };
        let names = (0..n).map(|p| p.to_string()).collect();
        let cell = crate::PeriodicBox::new(Vec3::zeros(), [Some(side), Some(side), None]).unwrap();
        let groups: Vec<_> = (0..n)
            .map(|p| crate::WrapGroup {
                anchor: p,
                particles: vec![p],
            })
            .collect();
        let contacts = DemContacts::new(&state, &spheres, names, &[(5e7, 0.25)], settings, vec![]);
        let mut contacts = contacts.with_periodic(cell.clone()).unwrap();
        let (mut force, mut torque) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
        let (mut rows, mut wraps, mut through, mut positive_zeros) = (Vec::new(), 0, 0, 0);
        let bits = |v: &Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        for step in 0..steps {
            state.time = 1e-5 * step as f64;
            for p in 0..n {
                let v = state.velocity[p];
                state.position[p] += 1e-5 * v;
            }
            wraps += cell.wrap_bodies(&mut state, &groups);
            force.fill(Vec3::zeros());
            torque.fill(Vec3::zeros());
            if every_step {
                contacts.forget_images();
            }
            contacts.add_forces(&state, &mut force, &mut torque);
            let pairs = contacts.candidates.pairs();
            through += pairs
                .with_shifts()
                .filter(|(c, t)| c.force != Vec3::zeros() && *t != Vec3::zeros())
                .count();
            let mut row: Vec<u64> = force.iter().chain(&torque).flat_map(bits).collect();
            row.extend(pairs.items.iter().flat_map(|c| bits(&c.history)));
            // Taken at every step, the column is what the law pass wrote at this one.
            let written: Vec<Vec3> = match every_step {
                true => pairs.shift.clone(),
                false => (0..pairs.len())
                    .map(|k| contacts.image_as_written(k))
                    .collect(),
            };
            row.extend(written.iter().flat_map(bits));
            positive_zeros += written
                .iter()
                .filter(|t| {
                    (t.x == 0.0 && t.x.is_sign_positive()) || (t.y == 0.0 && t.y.is_sign_positive())
                })
                .count();
            rows.push(row);
        }
        assert!(
            positive_zeros > 0,
            "no separation below zero along a periodic axis"
        );
        (rows, contacts.rebuilds(), wraps, through)
    }

    #[test]
    fn images_taken_once_per_build_give_the_bits_of_images_taken_at_every_step_across_wraps() {
        // The spheres cross both periodic faces and are wrapped back many times; each wrap
        // moves a sphere by a whole period, which must rebuild the lists before its pairs'
        // images are read again. The images kept from the build give every force, torque,
        // spring and written image translation (the sign of a zero one included) of images
        // taken afresh at every step, to the bit.
        let steps = 300;
        let (kept, rebuilds, wraps, through) = periodic_run(false, steps);
        let (fresh, ..) = periodic_run(true, steps);
        assert!(wraps > 50, "{wraps} wraps");
        assert!(rebuilds > 20, "{rebuilds} rebuilds");
        assert!(
            through > 20 * steps,
            "{through} touching pair-steps through the faces"
        );
        for (step, (a, b)) in kept.iter().zip(&fresh).enumerate() {
            assert_eq!(a.len(), b.len(), "step {step}");
            assert!(a == b, "step {step}: the kept images change the run");
        }
    }

    #[test]
    fn the_runs_are_an_even_number_of_at_most_run_chunk_spheres_beyond_one_run() {
        assert_eq!(run_length(RUN_CHUNK), RUN_CHUNK);
        for n in [2049, 4096, 4097, 10_000, 100_000, 279_074] {
            let length = run_length(n);
            assert!(length <= RUN_CHUNK, "{n} spheres: runs of {length}");
            assert_eq!(n.div_ceil(length) % 2, 0, "{n} spheres: runs of {length}");
        }
        assert_eq!(run_length(10_000), 1667);
    }

    #[test]
    fn the_plan_routes_second_spheres_beyond_a_run_through_its_foreign_sums() {
        let (state, mut contacts) = packing();
        contacts.read_own_stage(&state);
        contacts.rebuild_stage(0.0);
        let plan = &contacts.kernel;
        let mut crossing = 0;
        for (k, c) in contacts.candidates.pairs().items.iter().enumerate() {
            let slot = plan.slot[k] as usize;
            let length = run_length(contacts.spheres());
            if contacts.run_of(c.second) == contacts.run_of(c.first) {
                assert_eq!(slot, c.second as usize % length);
            } else {
                crossing += 1;
                let (r, f) = (contacts.run_of(c.first) as u32, (slot - RUN_CHUNK) as u32);
                assert!(plan.receive.binary_search(&(c.second, r, f)).is_ok());
            }
        }
        assert!(crossing > 0);
    }

    /// Three evaluations 10 µs apart of [`packing_with`] `law`, with rolling friction of
    /// coefficient `rolling` (none for 0), the law of the pairs run with the lanes of `set`:
    /// the particle forces and torques of the last, and the pairs' springs.
    fn forces_in_lanes(law: &ContactLaw, rolling: f64, set: LaneSet) -> Vec<[u64; 9]> {
        let (mut state, contacts) = packing_with(law.clone());
        let mut contacts = contacts.with_rolling_friction(rolling).unwrap();
        contacts.force_lanes(set);
        let n = state.len();
        let (mut force, mut torque) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
        for step in 0..3 {
            state.time = 1e-5 * step as f64;
            force.fill(Vec3::zeros());
            torque.fill(Vec3::zeros());
            contacts.add_forces(&state, &mut force, &mut torque);
        }
        let bits = |v: &Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        let springs = contacts.candidates.pairs().items.iter().map(|c| c.history);
        let mut out: Vec<[u64; 9]> = force
            .iter()
            .zip(&torque)
            .map(|(f, t)| {
                let mut row = [0; 9];
                row[..3].copy_from_slice(&bits(f));
                row[3..6].copy_from_slice(&bits(t));
                row
            })
            .collect();
        out.extend(springs.map(|h| {
            let mut row = [0; 9];
            row[6..].copy_from_slice(&bits(&h));
            row
        }));
        out
    }

    #[test]
    fn the_law_across_lanes_sums_as_the_scalar_law_bit_for_bit_on_every_lane_set() {
        // The packing above (more than 10,000 touching pairs, its spheres thrown at up to
        // 0.5 m/s and spun at up to 5 rad/s, so that contacts stick and slide) with
        // Hertz–Mindlin and the linear spring, damped, with and without rolling friction:
        // each vector lane set this CPU has gives every particle force and torque and every
        // spring of the scalar law to the last bit, over three steps.
        let linear = ContactLaw::Linear(crate::dem::laws::linear_spring::LinearSpring {
            normal_stiffness: 2e4,
            tangential_stiffness: 1.6e4,
            damping_ratio: 0.3,
        });
        let hertz = ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.2 });
        let widest = LaneSet::detected();
        let sets = [LaneSet::Avx2, LaneSet::Avx512];
        let sets: Vec<_> = sets
            .into_iter()
            .filter(|s| s.width() <= widest.width())
            .collect();
        for law in [hertz, linear] {
            for rolling in [0.0, 0.1] {
                let scalar = forces_in_lanes(&law, rolling, LaneSet::Scalar);
                for &set in &sets {
                    let lanes = forces_in_lanes(&law, rolling, set);
                    assert_eq!(lanes.len(), scalar.len());
                    for (p, (a, b)) in lanes.iter().zip(&scalar).enumerate() {
                        assert_eq!(a, b, "{law:?}, rolling {rolling}, {set:?}: row {p}");
                    }
                }
            }
        }
    }
}
