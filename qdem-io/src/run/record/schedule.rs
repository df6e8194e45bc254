//! [`Schedule`]: samples due every so many seconds of simulated time, to the nearest step.

/// Samples that fall due every `every` seconds (to the nearest step), from `next` on.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Schedule {
    every: f64,
    /// The time of the next sample (s), which a checkpoint keeps.
    pub(crate) next: f64,
}

impl Schedule {
    /// Due at t = 0, then every `every` seconds; never if `every` ≤ 0.
    pub(crate) fn new(every: f64) -> Schedule {
        Schedule { every, next: 0.0 }
    }

    /// Due first at t = `every`.
    pub(crate) fn after_start(every: f64) -> Schedule {
        Schedule { every, next: every }
    }

    /// Whether a sample is due at `time`, given the step `dt`, without advancing.
    pub(crate) fn is_due(&self, time: f64, dt: f64) -> bool {
        self.every > 0.0 && time >= self.next - 0.5 * dt
    }

    /// Whether a sample is due at `time`, given the step `dt`; advances past it if so.
    pub(crate) fn due(&mut self, time: f64, dt: f64) -> bool {
        if !self.is_due(time, dt) {
            return false;
        }
        // An interval far below the step (a checkpoint at every step) skips ahead at once,
        // and one below the rounding of `next` still advances it.
        let horizon = time + 0.5 * dt;
        let behind = (horizon - self.next) / self.every;
        if behind > 64.0 {
            self.next += behind.floor() * self.every;
        }
        while self.next <= horizon {
            self.next = (self.next + self.every).max(self.next.next_up());
        }
        true
    }
}

/// The probe interval of `sim`'s scene: `probe_every`, else t_end/1000.
pub(crate) fn probe_interval(sim: &crate::build::Simulation) -> f64 {
    let run = &sim.scene.run;
    run.probe_every.unwrap_or(run.t_end / 1000.0)
}

#[cfg(test)]
mod tests {
    use super::Schedule;

    #[test]
    fn a_schedule_is_due_once_per_interval_and_at_every_step_when_the_interval_is_tiny() {
        let mut every_tenth = Schedule::new(0.1);
        let due = (0..=100)
            .filter(|&n| every_tenth.due(n as f64 * 0.01, 0.01))
            .count();
        assert_eq!(due, 11);
        let mut tiny = Schedule::after_start(1e-300);
        assert!((1..=1000).all(|n| tiny.due(n as f64 * 1e-3, 1e-3)));
        let mut never = Schedule::new(0.0);
        assert!(!never.due(0.0, 1e-3));
    }
}
