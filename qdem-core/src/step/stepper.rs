//! The [`Stepper`] trait and what every stepper shares: force evaluation into accelerations
//! with fixity, and the choice of the time step from the models' stable bounds.

use crate::checkpoint::{CheckpointError, Decoder, Encoder};
use crate::error::CoreError;
use crate::step::local_particles::ParticleRuns;
use crate::step::model::Model;
use crate::step::seam::{OneProcess, Seam};
use crate::step::solve_report::SolveReport;
use crate::step::stages::{Stage, StageTimes};
use crate::step::state::{Dofs, State};
use crate::Vec3;
use rayon::prelude::*;

/// Particles per parallel task in per-particle loops. A kick, a drift or a = f/m costs a few
/// ns per particle, and waking a second worker costs tens of µs on the 2-core benchmark
/// machine (measured: at 10⁴ particles with tasks of 4096 both passes of a Verlet step took
/// longer on 2 threads than on 1), so a loop splits only beyond some 10⁵ particles' work.
pub(crate) const PARTICLE_CHUNK: usize = 32768;

/// Advances a [`State`] by one step under a list of models, without knowing their physics.
pub trait Stepper: Send {
    /// A short name for messages and summaries.
    fn name(&self) -> &str;

    /// The step size (s).
    fn dt(&self) -> f64;

    /// Makes the accelerations consistent with the forces at the current state; call once
    /// before the first step.
    fn initialize(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
    ) -> Result<(), CoreError> {
        self.initialize_in(state, models, &mut OneProcess)
    }

    /// [`Stepper::initialize`], evaluating the forces through `seam` (a
    /// [`crate::world::World`]'s, decomposed or not).
    fn initialize_in(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        seam: &mut dyn Seam,
    ) -> Result<(), CoreError>;

    /// Advances `state` by one step.
    fn step(&mut self, state: &mut State, models: &mut [Box<dyn Model>]) -> Result<(), CoreError> {
        self.step_timed(state, models, &mut StageTimes::off(), &mut OneProcess)
    }

    /// [`Stepper::step`], marking the end of each of its stages on `stages` (predict, each
    /// model's forces, integrate, solve, events: [`crate::step::stages`]), evaluating the forces
    /// through `seam` ([`Seam::sum_forces`]) and ending each integration with
    /// [`Seam::complete`] (in a decomposed run, the share of the ranks' new motion), on
    /// `seam`'s particles only when it says so ([`Seam::stepped`], [`Seam::computed`]).
    fn step_timed(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        stages: &mut StageTimes,
        seam: &mut dyn Seam,
    ) -> Result<(), CoreError>;

    /// Whether the stepper steps only the particles [`Seam::stepped`] and
    /// [`Seam::computed`] name, so that a decomposed run may share only its halo; the
    /// default cannot, and a decomposed run then shares the whole state after every step.
    fn steps_in_part(&self) -> bool {
        false
    }

    /// The force buffer of [`Stepper::forces`], for a decomposed run's gather
    /// ([`crate::world::World::gather_forces`]); empty (the default) for a stepper that keeps none.
    fn forces_mut(&mut self) -> &mut [Vec3] {
        &mut []
    }

    /// The torques on the rigid bodies that the next step reads (Verlet's first half kick),
    /// which a run decomposed with a halo exchange gathers from the bodies' owners with the
    /// state ([`crate::world::World::gather`]); empty (the default) for a stepper that keeps none
    /// from one step to the next or cannot step in part.
    fn rigid_torques_mut(&mut self) -> &mut [Vec3] {
        &mut []
    }

    /// The torques on the rigid bodies at the current state (the last evaluation's), from
    /// which their angular accelerations follow; empty (the default) for a stepper that keeps
    /// none.
    fn rigid_torques(&self) -> &[Vec3] {
        &[]
    }

    /// The total force on each particle (N) at the current state, from the step's last force
    /// evaluation (every model's; local damping leaves a fixed DOF's alone, as it does not
    /// move): at a fixed DOF, where the fixity
    /// holds the particle, minus the force the fix carries (its reaction); at a member of a
    /// rigid body held at points ([`crate::step::rigid_constraints`]), minus the force its
    /// holds carry there. Empty (the
    /// default) for a stepper that keeps none.
    fn forces(&self) -> &[Vec3] {
        &[]
    }

    /// What the stepper did so far: its retakes, sub-steps, event steps and solves, and its
    /// last sparse factorisation if it solves a linear system. The default, an explicit
    /// stepper's: all zero, no factorisation.
    fn report(&self) -> SolveReport {
        SolveReport::default()
    }

    /// Writes what the next step depends on beyond the state and the models (a force buffer
    /// carried from one step to the next, the tangent of a reused factorisation), or refuses
    /// with [`CheckpointError::Unsupported`] (the default).
    fn save(&self, out: &mut Encoder) -> Result<(), CheckpointError> {
        let _ = out;
        Err(CheckpointError::Unsupported {
            what: format!("the {} stepper", self.name()),
        })
    }

    /// Instead of [`Stepper::initialize`] when a run resumes: reads back what
    /// [`Stepper::save`] wrote, for a state and models already restored, without evaluating
    /// any force (which would advance the models' histories).
    fn resume(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        input: &mut Decoder<'_>,
    ) -> Result<(), CoreError> {
        let _ = (state, models, input);
        Err(CheckpointError::Unsupported {
            what: format!("the {} stepper", self.name()),
        }
        .into())
    }
}

/// Fails unless the state has no rigid body: for steppers that integrate translations only.
pub(crate) fn refuse_rigid(state: &State, stepper: &str) -> Result<(), CoreError> {
    match state.rigid.len() {
        0 => Ok(()),
        count => Err(CoreError::RigidNeedsVerlet {
            stepper: stepper.to_string(),
            count,
        }),
    }
}

/// Fails on the first particle with a non-finite acceleration.
pub(crate) fn check_finite(state: &State) -> Result<(), CoreError> {
    match state
        .acceleration
        .iter()
        .position(|a| !a.iter().all(|c| c.is_finite()))
    {
        Some(particle) => Err(CoreError::NonFinite {
            time: state.time,
            particle,
        }),
        None => Ok(()),
    }
}

/// Fails on the first rigid body with a non-finite torque.
pub(crate) fn check_finite_torque(state: &State, torque: &[Vec3]) -> Result<(), CoreError> {
    match torque.iter().position(|t| !t.iter().all(|c| c.is_finite())) {
        Some(body) => Err(CoreError::NonFinite {
            time: state.time,
            particle: state.rigid.center[body],
        }),
        None => Ok(()),
    }
}

/// Sums the forces of all models into `force` and `torque` (resized and zeroed here) and sets
/// a = f/m, zero in fixed directions and on members of rigid bodies. Fails on a non-finite
/// acceleration.
pub fn compute_accelerations(
    state: &mut State,
    models: &mut [Box<dyn Model>],
    force: &mut Vec<Vec3>,
    torque: &mut Vec<Vec3>,
) -> Result<(), CoreError> {
    let mut stages = StageTimes::off();
    compute_accelerations_timed(state, models, force, torque, &mut stages, &mut OneProcess)
}

/// [`compute_accelerations`] through `seam`, marking each model's forces and then the
/// integrate stage.
pub(crate) fn compute_accelerations_timed(
    state: &mut State,
    models: &mut [Box<dyn Model>],
    force: &mut Vec<Vec3>,
    torque: &mut Vec<Vec3>,
    stages: &mut StageTimes,
    seam: &mut dyn Seam,
) -> Result<(), CoreError> {
    seam.sum_forces(state, models, force, torque, stages);
    set_accelerations(state, force)?;
    let spun = set_spin_accelerations(state, &torque[state.rigid.len()..]);
    stages.mark(Stage::Integrate);
    spun
}

/// Sets θ̈ = M/J for the particles' rotations (`moment`: one per particle), zero about fixed
/// axes. Fails on a non-finite value.
pub(crate) fn set_spin_accelerations(state: &mut State, moment: &[Vec3]) -> Result<(), CoreError> {
    accelerate_spin(state, moment, None, None)
}

/// The rates a pass of [`divide_free`] writes: the accelerations, the velocities and the kick
/// h they get (v += h a; `None` leaves them alone).
type Rates<'a> = (&'a mut [Vec3], &'a mut [Vec3], Option<f64>);

/// out_i = load_i / inertia_i with the fixed directions zeroed, and zero where `follows(i)`
/// (members of rigid bodies, which follow their body), then v_i += h out_i with a kick h; in
/// parallel, one pass, over every particle or over `only`'s. Returns the first index with a
/// non-finite result, `usize::MAX` if none.
fn divide_free(
    (out, rate, kick): Rates<'_>,
    load: &[Vec3],
    inertia: &[f64],
    fixed: &[Dofs],
    follows: impl Fn(usize) -> bool + Sync,
    only: Option<&ParticleRuns>,
) -> usize {
    let one = |i: usize, a: &mut Vec3, v: &mut Vec3| {
        if follows(i) {
            *a = Vec3::zeros();
            return usize::MAX;
        }
        let mut acc = load[i] / inertia[i];
        for axis in 0..3 {
            if fixed[i].contains(axis) {
                acc[axis] = 0.0;
            }
        }
        *a = acc;
        if let Some(h) = kick {
            *v += h * acc;
        }
        if acc.iter().all(|c| c.is_finite()) {
            usize::MAX
        } else {
            i
        }
    };
    let Some(runs) = only else {
        return out
            .par_iter_mut()
            .zip(rate.par_iter_mut())
            .with_min_len(PARTICLE_CHUNK)
            .enumerate()
            .map(|(i, (a, v))| one(i, a, v))
            .min()
            .unwrap_or(usize::MAX);
    };
    runs.split(out)
        .into_par_iter()
        .zip(runs.split(rate))
        .zip(runs.batches())
        .map(|((a, v), ranges)| {
            let mut bad = usize::MAX;
            for ((a, v), r) in a.into_iter().zip(v).zip(ranges) {
                for ((a, v), i) in a.iter_mut().zip(v.iter_mut()).zip(r.clone()) {
                    bad = bad.min(one(i, a, v));
                }
            }
            bad
        })
        .min()
        .unwrap_or(usize::MAX)
}

/// The error for the first non-finite index `first_bad` of [`divide_free`], if any.
fn non_finite_at(first_bad: usize, time: f64) -> Result<(), CoreError> {
    match first_bad {
        usize::MAX => Ok(()),
        particle => Err(CoreError::NonFinite { time, particle }),
    }
}

/// Sets a = f/m, zero in fixed directions and on members of rigid bodies (which follow their
/// body). Fails on a non-finite acceleration.
pub(crate) fn set_accelerations(state: &mut State, force: &[Vec3]) -> Result<(), CoreError> {
    accelerate(state, force, None, None)
}

/// [`set_accelerations`], then the kick v += h a of every particle with `kick` = `Some(h)`, in
/// the same pass (the second half kick of a Verlet step); of `only`'s particles if given.
pub(crate) fn accelerate(
    state: &mut State,
    force: &[Vec3],
    kick: Option<f64>,
    only: Option<&ParticleRuns>,
) -> Result<(), CoreError> {
    let rigid = &state.rigid;
    let first_bad = divide_free(
        (&mut state.acceleration, &mut state.velocity, kick),
        force,
        &state.mass,
        &state.fixed,
        |i| rigid.body_of_member(i).is_some(),
        only,
    );
    hold_in_frames(state);
    non_finite_at(first_bad, state.time)
}

/// Projects the acceleration and velocity of every particle held in a local frame onto its
/// free directions (a ← a − Σ_held (e_k·a) e_k, [`crate::step::frames`]): what zeroing a
/// fixed axis's components does for a particle held on axes.
pub(crate) fn hold_in_frames(state: &mut State) {
    if !state.frames.is_empty() {
        state.frames.hold(&mut state.acceleration);
        state.frames.hold(&mut state.velocity);
    }
}

/// θ̈ = M/J for the particles' rotations, zero about fixed axes, then ω += h θ̈ with `kick`
/// = `Some(h)`, in one pass, of `only`'s particles if given. Fails on a non-finite value.
pub(crate) fn accelerate_spin(
    state: &mut State,
    moment: &[Vec3],
    kick: Option<f64>,
    only: Option<&ParticleRuns>,
) -> Result<(), CoreError> {
    let spin = &mut state.spin;
    let first_bad = divide_free(
        (&mut spin.acceleration, &mut spin.velocity, kick),
        moment,
        &spin.inertia,
        &spin.fixed,
        |_| false,
        only,
    );
    non_finite_at(first_bad, state.time)
}

/// Checks that every particle that is free in some direction, and no member of a rigid body,
/// has a positive mass, and a positive moment of inertia if it may rotate.
pub fn check_masses(state: &State) -> Result<(), CoreError> {
    let bad = (0..state.len()).find(|&i| {
        let free = (0..3).any(|axis| !state.fixed[i].contains(axis))
            && state.rigid.body_of_member(i).is_none();
        let turns = !state.spin.is_empty()
            && (0..3).any(|axis| !state.spin.fixed[i].contains(axis))
            && state.spin.inertia[i].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater);
        turns || free && state.mass[i].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
    });
    match bad {
        Some(particle) => Err(CoreError::Massless { particle }),
        None => Ok(()),
    }
}

/// The smallest stable step over all models and the name of the model that sets it.
pub fn stable_step(state: &State, models: &[Box<dyn Model>]) -> Option<(f64, String)> {
    models
        .iter()
        .filter_map(|m| m.stable_dt(state).map(|dt| (dt, m.name().to_string())))
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// The smallest step above which some model is unstable whatever else happens
/// ([`Model::unstable_above`]) and the name of that model.
pub fn unstable_step(state: &State, models: &[Box<dyn Model>]) -> Option<(f64, String)> {
    models
        .iter()
        .filter_map(|m| m.unstable_above(state).map(|dt| (dt, m.name().to_string())))
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// Chooses the step: `safety` times the stable bound when `requested` is `None`, otherwise the
/// requested step, refused if it exceeds the step some model cannot be stepped above
/// ([`unstable_step`]; the stable bound, except where a model's bound is an estimate).
pub fn choose_step(
    state: &State,
    models: &[Box<dyn Model>],
    requested: Option<f64>,
    safety: f64,
) -> Result<f64, CoreError> {
    let (bound, limiter) =
        stable_step(state, models).unwrap_or((f64::INFINITY, "nothing".to_string()));
    let (refused_above, refuser) =
        unstable_step(state, models).unwrap_or((f64::INFINITY, "nothing".to_string()));
    match requested {
        Some(dt) if dt > refused_above => Err(CoreError::StepTooLarge {
            dt,
            bound: refused_above,
            limiter: refuser,
        }),
        Some(dt) => Ok(dt),
        None if bound.is_finite() => Ok(safety * bound),
        None => Err(CoreError::NoStableBound { bound, limiter }),
    }
}
