//! The stages of one evaluation of a [`DemContacts`], the same for one process and for a
//! rank of a decomposed run (as LAMMPS's one `Pair::compute()` serves both): the
//! [`qdem_core::step::split::Facets`] (`split.rs`) calls each stage once, and the world's
//! exchange runs the collectives in between; [`DemContacts::evaluate_one_rank`] runs the same
//! stages in the same order on one process, where each collective is the identity (the
//! largest displacement over one rank is its own, the spheres of the other ranks are none,
//! a reduction over one rank is its own values).
//!
//! 1. read the own spheres' centres, and the largest displacement since the last build;
//! 2. rebuild the candidate lists when some sphere (or wall) moved more than the skin
//!    allows ([`crate::dem::broad_phase`]);
//! 3. declare the ghosts the new lists read (a rank only);
//! 4. read the motion of the own partners of candidates;
//! 5. the pair kernel's law pass (`pair_kernel.rs`), when a reduction must read this
//!    evaluation's forces first: the force through a time-delayed boundary (paper 003
//!    Eqs. 6–7: the ghost scales follow from it, so the sums wait for them) or on a
//!    stress-controlled wall (its servo, `servo_loads.rs`); the reduction of those over the ranks;
//! 6. the per-sphere sums (with the law, in one fused pass, when step 5 did not run it)
//!    added to the own spheres' particles and rotations.

use super::*;
use servo_loads::ServoContact;

/// How far the pair kernel has run in this evaluation before the apply stage.
#[derive(Clone, Copy, Debug, Default)]
pub(super) enum Evaluated {
    /// Nothing yet: the apply stage runs the law and the sums in one fused pass.
    #[default]
    Nothing,
    /// The law (the sums need the ghost scales of a time-delayed boundary first).
    Laws,
    /// The law of the pairs through a time-delayed boundary alone (`boundary_laws`): the
    /// apply stage runs the fused pass, which reads their records.
    Boundary,
    /// The law and the sums (a servo wall's reduction read the forces).
    Sums,
}

/// Where the evaluations stand: when the last one ran, the time since the one before, and
/// how far the current one has gone.
pub(super) struct Evaluation {
    last_time: Option<f64>,
    /// The time since the previous evaluation (s), from stage 1 of this one.
    dt: f64,
    /// Whether stage 1 of this evaluation read every sphere (else the partners only).
    read_every: bool,
    /// How far the pair kernel has run in this evaluation.
    evaluated: Evaluated,
}

impl Evaluation {
    /// Before the first evaluation.
    pub(super) fn new() -> Evaluation {
        Evaluation {
            last_time: None,
            dt: 0.0,
            read_every: true,
            evaluated: Evaluated::Nothing,
        }
    }

    /// The time of the last evaluation, if any.
    pub(super) fn last_time(&self) -> Option<f64> {
        self.last_time
    }

    /// Sets the time of the last evaluation (from a checkpoint).
    pub(super) fn set_last_time(&mut self, time: Option<f64>) {
        self.last_time = time;
    }

    /// The time since the previous evaluation (s), set by stage 1.
    #[cfg(test)]
    pub(super) fn dt(&self) -> f64 {
        self.dt
    }
}

/// Values per entry of the reduction: what it is (0 a pair through the time-delayed
/// boundary, 1 a contact on a servo wall), its partners, and three values.
const REDUCED_VALUES: usize = 6;

impl DemContacts {
    /// One evaluation on one process: the stages of a rank, in the exchange's order, with
    /// its collectives over one rank.
    pub(super) fn evaluate_one_rank(
        &mut self,
        state: &State,
        force: &mut [Vec3],
        torque: &mut [Vec3],
    ) {
        let moved = self.read_own_stage(state);
        if self.needs_rebuild_stage(moved, state.time) {
            self.read_borders_one_rank(state);
            self.rebuild_stage(state.time);
            self.anchor(state, 0.0);
        }
        self.read_partners_stage(state);
        self.compute_stage(state.time);
        let mut own = Vec::new();
        if self.reduction_stage(&mut own) {
            self.reduced_stage(state.time, &own);
        }
        self.apply_stage(force, torque);
    }

    /// Stage 1: the time since the previous evaluation; on a rank, lists that hold every
    /// rank's contacts cut down to its own; the own spheres' centres (every sphere's on one
    /// process, or only the partners' under a bound on the others' displacement:
    /// `displacement.rs`). Returns the largest displacement since the last build.
    pub(super) fn read_own_stage(&mut self, state: &State) -> f64 {
        self.evaluation.dt = self.evaluation.last_time.map_or(0.0, |t| state.time - t);
        self.evaluation.last_time = Some(state.time);
        if self.split.is_some() {
            return self.with_part(|this, part| {
                if part.whole {
                    this.cut_to_rank(part);
                }
                this.read_own_centers(state, part.own())
            });
        }
        self.evaluation.read_every = self.reads_every_sphere();
        self.read_centers(state)
    }

    /// Stage 2: whether the lists must be rebuilt, given the largest displacement over every
    /// rank.
    pub(super) fn needs_rebuild_stage(&self, moved: f64, time: f64) -> bool {
        self.outgrew_skin(moved, time)
    }

    /// On one process, what the exchange of every sphere's record before a rebuild gives a
    /// rank: every sphere's centre, when stage 1 read only the partners'.
    fn read_borders_one_rank(&mut self, state: &State) {
        if !self.evaluation.read_every {
            self.read_every_center(state);
        }
    }

    /// Stage 2: the check for spheres gone through a wall or into another body, then the
    /// spheres in spatial order (`spatial_order.rs`), new lists near the own spheres (every
    /// sphere's on one process), and the check of the step their touching contacts need
    /// (`stable_step.rs`).
    pub(super) fn rebuild_stage(&mut self, time: f64) {
        if self.split.is_none() {
            self.check_passage(time, None);
            self.rebuild_all(time);
            self.check_step_need(time);
            return;
        }
        self.sort_spheres();
        self.with_part(|this, part| {
            this.check_passage(time, Some(part.own()));
            this.rebuild_near(part, time);
            part.lists_changed = true;
        });
        self.check_step_need(time);
    }

    /// Stage 3: on a rank, the spheres of other ranks its new lists read, by stable id
    /// (ascending); `None` when the lists did not change, and always on one process.
    pub(super) fn new_ghosts_stage(&mut self) -> Option<Vec<u32>> {
        self.split.as_ref()?;
        let mut ghosts = self.with_part(|this, part| this.declare_ghosts(part))?;
        for g in &mut ghosts {
            *g = self.id_of(*g as usize) as u32;
        }
        ghosts.sort_unstable();
        Some(ghosts)
    }

    /// Stage 4: the motion of the own partners of candidates (on one process, unless stage 1
    /// read every sphere's).
    pub(super) fn read_partners_stage(&mut self, state: &State) {
        if self.split.is_some() {
            self.with_part(|this, part| this.read_motions(state, part.partners()));
        } else if !self.evaluation.read_every {
            self.read_all_partners(state);
        }
    }

    /// Stage 5: the pair kernel's law pass, when the reduction reads this evaluation's
    /// forces: without the sums when they wait for a time-delayed boundary's scales (on one
    /// process, once the images are taken, of the pairs through it alone), with them for a
    /// servo wall's load alone; otherwise nothing yet.
    pub(super) fn compute_stage(&mut self, time: f64) {
        let dt = self.evaluation.dt;
        let axis = self.time_delay.as_ref().map(|delay| delay.ghosts().0);
        self.evaluation.evaluated = if axis.is_some_and(|axis| self.boundary_laws(dt, axis)) {
            Evaluated::Boundary
        } else if self.time_delay.is_some() {
            self.run_kernel::<true, false>(time, dt, None);
            Evaluated::Laws
        } else if self.has_servo() {
            self.run_kernel::<true, true>(time, dt, None);
            Evaluated::Sums
        } else {
            Evaluated::Nothing
        };
    }

    /// Stage 5: what the ranks reduce together, appended to `out`: the touching pairs
    /// through a time-delayed boundary (partners and force magnitude), and the touching
    /// contacts on servo walls (sphere, wall, normal force and response: `servo_loads.rs`). False
    /// when the model has neither.
    pub(super) fn reduction_stage(&mut self, out: &mut Vec<f64>) -> bool {
        if let Some(delay) = &self.time_delay {
            delay.reduction(self.candidates.pairs(), self.boundary_pairs(), out);
        }
        let spheres = (self.spheres.records(), self.spheres.radius());
        let servo = self.walls.servo_contacts(
            self.candidates.wall_contacts(),
            spheres,
            &self.settings.law,
            self.evaluation.dt,
        );
        for c in servo {
            let (sphere, wall) = (c.sphere as f64, c.wall as f64);
            out.extend([1.0, sphere, wall, c.load, c.response.0, c.response.1]);
        }
        self.time_delay.is_some() || self.has_servo()
    }

    /// Stage 5: every rank's reduction (`all`, in rank order), summed as one process sums
    /// its own: the boundary's average force over the pairs merged by partners (a pair two
    /// ranks hold taken once), whence the ghost scales (paper 003 Eqs. 6–7); each servo
    /// wall's load over its contacts by sphere, whence its velocity.
    pub(super) fn reduced_stage(&mut self, time: f64, all: &[f64]) {
        let (mut pairs, mut walls) = (Vec::new(), Vec::new());
        for v in all.chunks_exact(REDUCED_VALUES) {
            let (a, b) = (v[1] as u32, v[2] as u32);
            match v[0] == 0.0 {
                true => pairs.push((a, b, v[3])),
                false => walls.push(ServoContact {
                    sphere: a,
                    wall: b,
                    load: v[3],
                    response: (v[4], v[5]),
                }),
            }
        }
        if let Some(delay) = &mut self.time_delay {
            delay.reduced(time, pairs);
        }
        if self.has_servo() {
            walls.sort_by_key(|c| (c.sphere, c.wall));
            self.walls.drive_servos(time, &walls);
        }
    }

    /// Stage 6: the per-sphere sums, with the law when stage 5 did not run it, added to the
    /// own spheres' particles (`force`) and rotations (`torque`).
    pub(super) fn apply_stage(&mut self, force: &mut [Vec3], torque: &mut [Vec3]) {
        let (time, dt) = (self.evaluation.last_time.unwrap_or(0.0), self.evaluation.dt);
        match std::mem::take(&mut self.evaluation.evaluated) {
            Evaluated::Nothing | Evaluated::Boundary => {
                self.run_kernel::<true, true>(time, dt, Some((force, torque)))
            }
            Evaluated::Laws => self.run_kernel::<false, true>(time, dt, Some((force, torque))),
            Evaluated::Sums => self.add_partner_sums(force, torque),
        }
    }
}
