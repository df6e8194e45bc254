//! The measured cost of each model's items, by which a decomposition weighs them
//! ([`crate::parallel::decomposition`]) in place of its fixed shares.
//!
//! The fixed shares (a tetrahedron [`TET_WORK`](crate::parallel::decomposition) = 1.2 particle
//! steps times its body's cost, a contact sphere 5, a candidate contact 3) were measured on one
//! machine and one scene; on the paper-size loading step two ranks cut by them left the
//! sleeper's rank 1.23 times the mean kernel time. A model's **weight** w_m scales its items'
//! shares by what they were measured to cost on the ranks:
//!
//! w_m = (Σ_r s_m,r / Σ_r W_m,r) / (Σ_r s_p,r / Σ_r N_r),
//!
//! with s_m,r the seconds rank r spent in model m's forces (a deformable body's without its
//! exchange of block sums, which waits for the slowest rank), W_m,r the model's work on rank r
//! in the fixed shares (per step, times the steps), s_p,r the rank's seconds predicting and
//! integrating and N_r the particle steps it computed: the cost of the model's work per
//! particle step, in particle steps. The sums run over ranks in rank order on every rank
//! (the values are gathered first), so every rank gets the same weights and the cut, a
//! function of them alone, is the same on every rank. A model not measured (no work or no
//! time on any rank) keeps weight 1; a weight is kept within [`LOWEST`]..[`HIGHEST`], so
//! that one disturbed measurement cannot put every item on one rank.
//!
//! The weights come from wall-clock timings, so two runs may cut differently; a run's results
//! do not depend on the cut (each value is computed by one rank in the single-process order,
//! [`crate::parallel::decomposition`]), so its outputs are the same bits whatever weights
//! it measured.

/// The smallest weight a measurement gives a model.
const LOWEST: f64 = 0.1;

/// The largest weight a measurement gives a model.
const HIGHEST: f64 = 10.0;

/// Per model of a world, the factor on its items' fixed shares of work (1: the fixed shares).
///
/// ```
/// use qdem_core::parallel::WorkWeights;
/// // Two ranks, two models: a body whose kernel took 3 s for 1e9 particle steps of work
/// // (3 ns each) and a model without work; 0.5 s of prediction and integration for 2.5e8
/// // particle steps (2 ns each) on each rank.
/// let rank = [1.5, 0.5e9, 0.0, 0.0, 0.5, 2.5e8];
/// let all = [rank, rank].concat();
/// let weights = WorkWeights::from_measured(&all, 2);
/// assert!((weights.of(0) - 1.5).abs() < 1e-12);
/// assert_eq!(weights.of(1), 1.0);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WorkWeights {
    /// The weight of each model, by its index in the world; a model past the end weighs 1.
    pub models: Vec<f64>,
}

impl WorkWeights {
    /// The weight of model `model`.
    pub fn of(&self, model: usize) -> f64 {
        self.models.get(model).copied().unwrap_or(1.0)
    }

    /// The weights from every rank's measurements `all`, in rank order, each rank's row
    /// holding for each of the `models` models its seconds and its work (particle steps, in
    /// the fixed shares), then its seconds of prediction and integration and its particle
    /// steps (module docs).
    pub fn from_measured(all: &[f64], models: usize) -> WorkWeights {
        let row = 2 * models + 2;
        let total = |k: usize| all.chunks_exact(row).map(|r| r[k]).sum::<f64>();
        let particle = total(row - 2) / total(row - 1);
        let weight = |m: usize| {
            let (seconds, work) = (total(2 * m), total(2 * m + 1));
            let w = seconds / work / particle;
            match w.is_finite() && w > 0.0 {
                true => w.clamp(LOWEST, HIGHEST),
                false => 1.0,
            }
        };
        WorkWeights {
            models: (0..models).map(weight).collect(),
        }
    }
}
