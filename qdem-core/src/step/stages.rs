//! Stage counters: the wall time a step spends in each of its named stages, in the spirit of
//! rapier's `PhysicsPipeline` counters.
//!
//! A [`crate::world::World`] step runs as stages — predict, the forces of each model, integrate,
//! solve (implicit steps: tangent, factorisation, back substitution), events (the models'
//! step checks and commits), the post-step hooks, and the failure check — and the steppers
//! mark the end of each stage on a [`StageTimes`] as they go. Marking a disabled clock
//! ([`StageTimes::off`]) costs a branch, so the plain [`crate::step::Stepper::step`] pays nothing.

use std::time::Instant;

/// One stage of a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The predictor: drift, half kick, rigid bodies' rotation and members' placement.
    Predict,
    /// The forces of the model at this index of the world's models.
    Forces(usize),
    /// Forces to accelerations, local damping, the corrector and the last half kick.
    Integrate,
    /// An implicit step's linear algebra: tangent, factorisation, solve.
    Solve,
    /// The models' step checks, retakes and commits (bond breaks, contacts opening).
    Events,
    /// A decomposed run's exchange of the particles each process owns
    /// ([`crate::parallel::decomposition`]).
    Share,
    /// The post-step hook at this index of the world's hooks.
    Hook(usize),
    /// The failure check: inverted elements, non-finite values, runaway energy.
    Check,
}

/// Seconds accumulated per stage over the steps taken.
#[derive(Clone, Debug, Default)]
pub struct StageTimes {
    on: bool,
    mark: Option<Instant>,
    predict: f64,
    forces: Vec<f64>,
    integrate: f64,
    solve: f64,
    events: f64,
    share: f64,
    hooks: Vec<f64>,
    check: f64,
    steps: u64,
}

/// One line of a stage report: a stage's name, its seconds per step and its share of the step.
#[derive(Clone, Debug, PartialEq)]
pub struct StageShare {
    /// `predict`, `forces: NAME` (the model's name), `integrate`, `solve`, `events`,
    /// `share`, `hook: NAME` or `failure check`.
    pub name: String,
    /// Mean wall seconds per step.
    pub seconds_per_step: f64,
    /// Fraction of the summed stage time.
    pub share: f64,
}

impl StageTimes {
    /// A clock that records nothing (marks are no-ops).
    pub fn off() -> StageTimes {
        StageTimes::default()
    }

    /// A clock for `models` force models and `hooks` post-step hooks, all stages at zero.
    pub fn new(models: usize, hooks: usize) -> StageTimes {
        StageTimes {
            forces: vec![0.0; models],
            hooks: vec![0.0; hooks],
            on: true,
            ..StageTimes::default()
        }
    }

    /// Starts a step: the next [`StageTimes::mark`] counts from now.
    pub fn begin_step(&mut self) {
        if self.on {
            self.steps += 1;
            self.mark = Some(Instant::now());
        }
    }

    /// Adds the time since the last mark (or [`StageTimes::begin_step`]) to `stage`.
    pub fn mark(&mut self, stage: Stage) {
        let Some(last) = self.mark else { return };
        let now = Instant::now();
        let seconds = (now - last).as_secs_f64();
        self.mark = Some(now);
        let slot = match stage {
            Stage::Predict => &mut self.predict,
            Stage::Forces(i) => match self.forces.get_mut(i) {
                Some(slot) => slot,
                None => return,
            },
            Stage::Integrate => &mut self.integrate,
            Stage::Solve => &mut self.solve,
            Stage::Events => &mut self.events,
            Stage::Share => &mut self.share,
            Stage::Hook(i) => match self.hooks.get_mut(i) {
                Some(slot) => slot,
                None => return,
            },
            Stage::Check => &mut self.check,
        };
        *slot += seconds;
    }

    /// Steps counted since the clock was made.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Seconds recorded in `stage` over all steps.
    pub fn seconds(&self, stage: Stage) -> f64 {
        match stage {
            Stage::Predict => self.predict,
            Stage::Forces(i) => self.forces.get(i).copied().unwrap_or(0.0),
            Stage::Integrate => self.integrate,
            Stage::Solve => self.solve,
            Stage::Events => self.events,
            Stage::Share => self.share,
            Stage::Hook(i) => self.hooks.get(i).copied().unwrap_or(0.0),
            Stage::Check => self.check,
        }
    }

    /// Every stage with its seconds per step and share, in step order, the models and hooks
    /// named by `model_names` and `hook_names`; stages that took no time are left out.
    pub fn report(&self, model_names: &[&str], hook_names: &[&str]) -> Vec<StageShare> {
        let mut named: Vec<(String, f64)> = vec![("predict".into(), self.predict)];
        named.extend(
            self.forces
                .iter()
                .zip(model_names)
                .map(|(s, n)| (format!("forces: {n}"), *s)),
        );
        named.push(("integrate".into(), self.integrate));
        named.push(("solve".into(), self.solve));
        named.push(("events".into(), self.events));
        named.push(("share".into(), self.share));
        named.extend(
            self.hooks
                .iter()
                .zip(hook_names)
                .map(|(s, n)| (format!("hook: {n}"), *s)),
        );
        named.push(("failure check".into(), self.check));
        let total: f64 = named.iter().map(|(_, s)| s).sum();
        let per = 1.0 / self.steps.max(1) as f64;
        named
            .into_iter()
            .filter(|(_, s)| *s > 0.0)
            .map(|(name, s)| StageShare {
                name,
                seconds_per_step: s * per,
                share: s / total.max(f64::MIN_POSITIVE),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marks_go_to_their_stage_and_shares_sum_to_one() {
        let mut clock = StageTimes::new(2, 1);
        for _ in 0..3 {
            clock.begin_step();
            std::thread::sleep(std::time::Duration::from_millis(2));
            clock.mark(Stage::Forces(1));
            clock.mark(Stage::Hook(0));
        }
        assert_eq!(clock.steps(), 3);
        assert!(clock.seconds(Stage::Forces(1)) >= 0.006);
        assert_eq!(clock.seconds(Stage::Forces(0)), 0.0);
        let report = clock.report(&["a", "b"], &["wrap"]);
        assert_eq!(report[0].name, "forces: b");
        let sum: f64 = report.iter().map(|s| s.share).sum();
        assert!((sum - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_clock_that_is_off_records_nothing() {
        let mut clock = StageTimes::off();
        clock.begin_step();
        clock.mark(Stage::Predict);
        assert_eq!(clock.steps(), 0);
        assert_eq!(clock.seconds(Stage::Predict), 0.0);
        assert!(clock.report(&[], &[]).is_empty());
    }
}
