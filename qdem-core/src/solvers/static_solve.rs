//! Linear static solve K u = f (paper 001 Eq. 17 with the incremental form of Eqs. 19–20 taken
//! from the reference state in one step, the constraints of Eq. 23 eliminated).
//!
//! f is the total force the models give on the reference configuration at the requested time
//! (loads and gravity; the internal force vanishes there), K the models' tangent stiffness at
//! the reference configuration ([`crate::step::Linearized::add_tangent`]). For QDEM tetrahedra this is the
//! small-strain linear-tetrahedron stiffness, so the answer is the mesh's linear FEM solution.
//! K is assembled and factorised by `sparse::SparseCholesky` on the first solve (with the fixity of
//! that moment) and reused for every later load level: one further force evaluation per
//! level and two triangular solves per distinct one.
//!
//! One solve per distinct load level: the load vector f of every level is compared, bit for
//! bit, with that of the last level solved, and a level whose loads are the same (a constant
//! load, the hold of a ramp or a series, gravity alone) takes that level's answer without
//! solving again: the same f and the same factorisation give the same u, so the outputs are
//! those of a solve at every level, and only the work goes. The comparison was chosen over
//! asking each model whether its time function is constant between two levels: it needs no
//! knowledge of the models (loads, gravity, a series' flat stretches all count alike) and
//! can never skip a level whose loads changed. [`StaticSolver::solves`] counts the solves.
//!
//! The levels are the multiples k·dt of the step, computed as such rather than summed (a sum
//! of a hundred 0.01 s steps is not 1 s), and the last one is the run's end exactly when it
//! lies within rounding of it ([`StaticSteps::ending_at`]): a level's time is printed as
//! given.
//!
//! K alone is singular when a deformable body is free to move rigidly (no or too few fixed
//! directions), so such a body is refused before factorising with
//! [`CoreError::Unconstrained`], naming it (`sparse::unconstrained_bodies`); any other
//! failed factorisation names the particle of the failing pivot and its body
//! (`sparse::explain_failure`).
//!
//! A static run is checkpointed like the others: what a load level depends on beyond the
//! state and the models is the factorisation of the first solve, so [`StaticSteps`] saves the
//! tangent it factorised and a resumed run factorises that same matrix again (the models' own
//! tangent at the resumed moment need not be the first one's), giving the same answers bit
//! for bit.

use crate::checkpoint::{CheckpointError, Decoder, Encoder};
use crate::error::CoreError;
use crate::solvers::newmark::collect_tangent;
use crate::solvers::sparse::{
    explain_failure, unconstrained_bodies, Assembler, FreeDofs, Scales, SparseCholesky, Tangent,
    FIX_HINT,
};
use crate::step::model::Model;
use crate::step::seam::{OneProcess, Seam};
use crate::step::solve_report::{FactorStats, SolveReport, StepCounts};
use crate::step::stages::{Stage, StageTimes};
use crate::step::state::State;
use crate::step::stepper::{refuse_rigid, Stepper};
use crate::Vec3;

/// A linear static solver that keeps the factorisation of K across load levels.
#[derive(Debug, Default)]
pub struct StaticSolver {
    dofs: Option<FreeDofs>,
    /// The tangent factorised (kept for checkpoints).
    tangent: Tangent,
    cholesky: SparseCholesky,
    force: Vec<Vec3>,
    torque: Vec<Vec3>,
    rhs: Vec<f64>,
    levels: Levels,
}

/// The load vector of the last level solved, its answer, and the solves made.
#[derive(Debug, Default)]
struct Levels {
    loads: Vec<f64>,
    answer: Vec<f64>,
    solves: u64,
}

impl Levels {
    /// Turns the load vector in `rhs` into the answer: by a solve with `cholesky` when it
    /// differs from the last level solved, else that level's answer.
    fn solve(&mut self, cholesky: &mut SparseCholesky, rhs: &mut Vec<f64>) {
        let same = self.loads.len() == rhs.len()
            && self
                .loads
                .iter()
                .zip(rhs.iter())
                .all(|(a, b)| a.to_bits() == b.to_bits());
        if same {
            rhs.clone_from(&self.answer);
            return;
        }
        self.loads.clone_from(rhs);
        cholesky.solve_in_place(rhs);
        self.answer.clone_from(rhs);
        self.solves += 1;
    }
}

impl StaticSolver {
    /// A solver with nothing factorised yet.
    pub fn new() -> StaticSolver {
        StaticSolver::default()
    }

    /// Size, fill and factorisation time of K; `None` before the first solve.
    pub fn factor_stats(&self) -> Option<&FactorStats> {
        self.cholesky.is_factored().then(|| self.cholesky.stats())
    }

    /// The linear solves made: one per distinct load level (see the module docs).
    pub fn solves(&self) -> u64 {
        self.levels.solves
    }

    /// Solves K u = f(`time`) and sets `state` to the static answer at `time`: positions
    /// X + u, rotations θ, zero velocities and accelerations. Loads equal bit for bit to
    /// those of the last solve take its answer without solving again.
    pub fn solve(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        time: f64,
    ) -> Result<(), CoreError> {
        refuse_rigid(state, "static")?;
        state.time = time;
        state.position.clone_from(&state.reference);
        state.velocity.fill(Vec3::zeros());
        state.acceleration.fill(Vec3::zeros());
        let spin = &mut state.spin;
        for v in [&mut spin.angle, &mut spin.velocity, &mut spin.acceleration] {
            v.fill(Vec3::zeros());
        }
        if !self.cholesky.is_factored() {
            self.factorize(state, models)?;
        }
        OneProcess.sum_forces(
            state,
            models,
            &mut self.force,
            &mut self.torque,
            &mut StageTimes::off(),
        );
        let dofs = self.dofs.as_ref().expect("factorised above");
        self.rhs.resize(dofs.len(), 0.0);
        let moments = &self.torque[state.rigid.len()..];
        dofs.gather_nodes((&self.force, moments), &mut self.rhs);
        self.levels.solve(&mut self.cholesky, &mut self.rhs);
        let mut u = vec![Vec3::zeros(); state.len()];
        dofs.scatter_nodes(&self.rhs, (&mut u, &mut state.spin.angle));
        for (x, d) in state.position.iter_mut().zip(&u) {
            *x += d;
        }
        self.subtract_stiffness_times(&u, &state.spin.angle);
        Ok(())
    }

    /// The force on every particle at the last answer: f − K u (N), zero at the free DOFs up
    /// to the solver's rounding, minus the reaction at a fixed one.
    pub fn forces(&self) -> &[Vec3] {
        &self.force
    }

    /// Turns the force buffer f (the loads on the reference state) into f − K u for the
    /// displacements `u` and particle rotations `angles`, K the factorised tangent (its lower
    /// triangle, each off-diagonal entry acting both ways).
    fn subtract_stiffness_times(&mut self, u: &[Vec3], angles: &[Vec3]) {
        let n = u.len();
        let value = |dof: usize| {
            let node = dof / 3;
            let v = if node < n { u[node] } else { angles[node - n] };
            v[dof % 3]
        };
        let force = &mut self.force;
        let mut subtract = |dof: usize, amount: f64| {
            if dof / 3 < n {
                force[dof / 3][dof % 3] -= amount;
            }
        };
        for e in &self.tangent.stiffness {
            subtract(e.row, e.val * value(e.col));
            if e.row != e.col {
                subtract(e.col, e.val * value(e.row));
            }
        }
    }

    /// Assembles K at the reference state and factorises it; refuses a body free to move
    /// rigidly first.
    fn factorize(&mut self, state: &State, models: &[Box<dyn Model>]) -> Result<(), CoreError> {
        collect_tangent(state, models, &mut self.tangent)?;
        self.factorize_tangent(state, models)
    }

    /// Factorises the stored tangent with the state's fixity and masses.
    fn factorize_tangent(
        &mut self,
        state: &State,
        models: &[Box<dyn Model>],
    ) -> Result<(), CoreError> {
        let dofs = FreeDofs::of(state);
        let tangent = &*dofs.local_tangent(&self.tangent);
        if let Some((body, modes)) = unconstrained_bodies(state, models, tangent, &dofs)
            .into_iter()
            .next()
        {
            return Err(CoreError::Unconstrained {
                body,
                modes,
                what: "stiffness",
                fix: FIX_HINT,
            });
        }
        let scales = Scales {
            mass: 0.0,
            damping: 0.0,
            stiffness: 1.0,
        };
        let mass = state.node_mass();
        let mut assembler = Assembler::new();
        let matrix = assembler.assemble(tangent, &mass, &dofs, scales)?;
        if let Err(error) = self.cholesky.factorize(matrix, "stiffness") {
            let pivot = self.cholesky.failed_pivot();
            return Err(explain_failure(error, pivot, &dofs, state, models, tangent));
        }
        self.dofs = Some(dofs);
        Ok(())
    }
}

/// The static solve as a [`Stepper`] (`integrator = "static"`): each step moves the load
/// time to the next level k·dt and solves K·u = f(t), reusing the factorisation of the first
/// solve (and the answer of the last level whose loads were the same).
#[derive(Debug)]
pub struct StaticSteps {
    solver: StaticSolver,
    dt: f64,
    end: Option<f64>,
}

impl StaticSteps {
    /// Load levels every `dt` seconds of the ramp.
    pub fn new(dt: f64) -> StaticSteps {
        StaticSteps {
            solver: StaticSolver::new(),
            dt,
            end: None,
        }
    }

    /// The levels end at `end` (s): the level within rounding of it (10⁻⁹ dt, the tolerance
    /// of [`crate::step::StepSettings::steps_to`]) is solved at `end` itself.
    pub fn ending_at(mut self, end: Option<f64>) -> StaticSteps {
        self.end = end;
        self
    }

    /// The time of the level after the one at `time`: the next multiple of dt, or the end.
    fn next_level(&self, time: f64) -> f64 {
        let next = ((time / self.dt).round() + 1.0) * self.dt;
        match self.end {
            Some(end) if (next - end).abs() <= 1e-9 * self.dt => end,
            _ => next,
        }
    }
}

impl Stepper for StaticSteps {
    fn name(&self) -> &str {
        "static"
    }

    fn dt(&self) -> f64 {
        self.dt
    }

    /// A static solve is never decomposed ([`crate::world::World::decompose`] refuses it): the
    /// exchange is a single process's.
    fn initialize_in(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        _seam: &mut dyn Seam,
    ) -> Result<(), CoreError> {
        let time = state.time;
        self.solver.solve(state, models, time)
    }

    /// The whole solve is one stage, [`Stage::Solve`].
    fn step_timed(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        stages: &mut StageTimes,
        _seam: &mut dyn Seam,
    ) -> Result<(), CoreError> {
        let time = self.next_level(state.time);
        let solved = self.solver.solve(state, models, time);
        stages.mark(Stage::Solve);
        solved
    }

    /// The linear solves made by this process ([`StaticSolver::solves`]), the one
    /// factorisation once made and its size and cost.
    fn report(&self) -> SolveReport {
        let counts = StepCounts {
            solves: self.solver.solves(),
            factorizations: u64::from(self.solver.cholesky.is_factored()),
            ..StepCounts::default()
        };
        let factor = self.solver.factor_stats().cloned();
        SolveReport { counts, factor }
    }

    fn forces(&self) -> &[Vec3] {
        self.solver.forces()
    }

    /// Whether K is factorised and, if so, the tangent it was assembled from: the later load
    /// levels solve with that factorisation. The solver's other buffers are overwritten at
    /// every solve.
    fn save(&self, out: &mut Encoder) -> Result<(), CheckpointError> {
        out.tag("static");
        let factored = self.solver.cholesky.is_factored();
        out.bool(factored);
        if factored {
            self.solver.tangent.save(out);
        }
        Ok(())
    }

    /// Reads back the factorised tangent and factorises it again, evaluating no force.
    fn resume(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        input: &mut Decoder<'_>,
    ) -> Result<(), CoreError> {
        refuse_rigid(state, "static")?;
        input.tag("static")?;
        if input.bool("the factorisation flag")? {
            self.solver.tangent.restore(input, state.dofs())?;
            self.solver.factorize_tangent(state, models)?;
        }
        Ok(())
    }
}
