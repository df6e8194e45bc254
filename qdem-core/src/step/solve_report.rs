//! What a stepper reports of its solves ([`SolveReport`]), in terms of no one solver: the
//! counts of an adaptive or implicit stepper ([`StepCounts`]: retakes, sub-steps, event
//! steps, factorisations, solves) and the size and cost of a sparse factorisation
//! ([`FactorStats`]). The steppers of [`crate::solvers`] fill it; summaries and `qdem check`
//! read it through [`crate::step::stepper::Stepper::report`] without knowing which stepper ran.

/// What a stepper did so far: its counts, and its last factorisation if it solves a linear
/// system. The default (all zero, no factorisation) is an explicit stepper's report.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolveReport {
    /// Retakes, sub-steps and event steps of an adaptive stepper, the solves of an implicit
    /// or static one; zero for the others.
    pub counts: StepCounts,
    /// Size and cost of the sparse factorisation; `None` for explicit steppers and before
    /// the first factorisation.
    pub factor: Option<FactorStats>,
}

/// What the adaptive control and the events did (for summaries and the paper's Tables 1–2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepCounts {
    /// Steps rejected and retaken with ∆t·√α (Eqs. 29–30).
    pub retakes: u64,
    /// Accepted steps (sub-steps included: a retaken step is finished by further sub-steps so
    /// that every step still ends at t + ∆t).
    pub substeps: u64,
    /// Accepted steps at whose end a model's tangent changed (bonds broke, contacts changed).
    pub event_steps: u64,
    /// Numeric factorisations of the effective matrix (nominal and sub-step), implicit only.
    pub factorizations: u64,
    /// Trial steps redone with the contacts the trial met in the matrix (implicit only).
    pub redos: u64,
    /// Linear solves of the implicit step (one per trial step).
    pub solves: u64,
    /// Of the solves, those by conjugate gradients on a kept factor
    /// ([`crate::step::step_settings::EventSolve`]).
    pub iterative_solves: u64,
    /// Conjugate-gradient iterations of those solves, together.
    pub iterations: u64,
}

impl StepCounts {
    /// The number of counts.
    pub const LEN: usize = 8;

    /// The counts in field order (for checkpoints).
    ///
    /// ```
    /// use qdem_core::step::StepCounts;
    /// let counts = StepCounts { retakes: 2, iterations: 7, ..StepCounts::default() };
    /// assert_eq!(StepCounts::from_array(counts.to_array()), counts);
    /// ```
    pub fn to_array(&self) -> [u64; StepCounts::LEN] {
        [
            self.retakes,
            self.substeps,
            self.event_steps,
            self.factorizations,
            self.redos,
            self.solves,
            self.iterative_solves,
            self.iterations,
        ]
    }

    /// The counts [`Self::to_array`] listed.
    pub fn from_array(n: [u64; StepCounts::LEN]) -> StepCounts {
        let [retakes, substeps, event_steps, factorizations, redos, solves, iterative_solves, iterations] =
            n;
        StepCounts {
            retakes,
            substeps,
            event_steps,
            factorizations,
            redos,
            solves,
            iterative_solves,
            iterations,
        }
    }
}

/// Size, sparsity and cost of the last factorisation (for `qdem check`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FactorStats {
    /// Order of the matrix (free DOFs).
    pub dofs: usize,
    /// Stored non-zeros of the matrix (lower triangle).
    pub nonzeros: usize,
    /// Stored values of the Cholesky factor L (its fill; supernodes are stored dense).
    pub factor_nonzeros: usize,
    /// Time of the last symbolic analysis (s).
    pub symbolic_seconds: f64,
    /// Time of the last numeric factorisation (s).
    pub numeric_seconds: f64,
    /// Time of the assembly of the matrix last factorised (s).
    pub assembly_seconds: f64,
    /// Time of the last solve, a forward and a backward triangular solve (s).
    pub solve_seconds: f64,
    /// Number of symbolic analyses so far (one per sparsity pattern met).
    pub analyses: usize,
    /// Number of numeric factorisations so far.
    pub factorizations: usize,
}
