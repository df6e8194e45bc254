//! Time functions for loads: piecewise-linear (the scene's `ramp`) and cyclic (its `cyclic`,
//! the sinusoidal sleeper loads of paper 003 §2: 3 Hz between 3 and 40 kN, three sleepers 90°
//! apart).
//!
//! Piecewise-linear: points (t, factor) with non-decreasing t; linear in between; the first
//! value before the first point and the last value after the last; a repeated t makes a jump,
//! the function taking the later value from that time on.
//!
//! Cyclic: min + (max − min)(1 + sin Φ)/2 with Φ(t) = 2πf(t − start) + phase − π/2, so that a
//! load of zero phase begins its first cycle at its minimum at `start`. Before its own first
//! cycle begins (Φ < −π/2: a lagging load's first quarter) the factor is the minimum, so a
//! load never jumps.

use crate::error::CoreError;
use std::f64::consts::{FRAC_PI_2, PI};

/// A function of time: piecewise-linear or cyclic.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeFunction {
    kind: Kind,
}

#[derive(Clone, Debug, PartialEq)]
enum Kind {
    Piecewise(Vec<(f64, f64)>),
    Cyclic(Cyclic),
}

/// A sinusoid between two factors (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cyclic {
    /// Factor at the cycle's minimum.
    pub min: f64,
    /// Factor at its maximum.
    pub max: f64,
    /// Cycles per second (Hz).
    pub frequency: f64,
    /// Phase lead (rad): a load with phase π/2 is a quarter cycle ahead of one with 0.
    pub phase: f64,
    /// Time (s) at which a zero-phase load begins its first cycle.
    pub start: f64,
}

impl Cyclic {
    /// Φ(t) = 2πf(t − start) + phase − π/2.
    pub fn phase_at(&self, t: f64) -> f64 {
        2.0 * PI * self.frequency * (t - self.start) + self.phase - FRAC_PI_2
    }

    /// Time at which this load's first cycle begins (Φ = −π/2).
    pub fn first_cycle_start(&self) -> f64 {
        self.start - self.phase / (2.0 * PI * self.frequency)
    }

    /// The factor at time `t`.
    pub fn value(&self, t: f64) -> f64 {
        let phi = self.phase_at(t);
        if phi < -FRAC_PI_2 {
            return self.min;
        }
        self.min + (self.max - self.min) * 0.5 * (1.0 + phi.sin())
    }
}

impl TimeFunction {
    /// A constant factor.
    pub fn constant(value: f64) -> TimeFunction {
        TimeFunction {
            kind: Kind::Piecewise(vec![(0.0, value)]),
        }
    }

    /// A cyclic function; refused unless every number is finite and the frequency positive.
    pub fn cyclic(cyclic: Cyclic) -> Result<TimeFunction, CoreError> {
        let c = cyclic;
        let finite = [c.min, c.max, c.phase, c.start, c.frequency]
            .iter()
            .all(|v| v.is_finite());
        if !finite || c.frequency <= 0.0 {
            return Err(CoreError::TimeFunction(format!(
                "a cyclic load needs finite min, max, phase and start and a positive frequency, \
                 not {c:?}"
            )));
        }
        Ok(TimeFunction {
            kind: Kind::Cyclic(c),
        })
    }

    /// The cycle, when the function is cyclic.
    pub fn as_cyclic(&self) -> Option<&Cyclic> {
        match &self.kind {
            Kind::Cyclic(c) => Some(c),
            Kind::Piecewise(_) => None,
        }
    }

    /// A piecewise-linear function through `points`; refused if empty, non-finite, decreasing
    /// in time, or with more than two points at one time.
    pub fn new(points: Vec<(f64, f64)>) -> Result<TimeFunction, CoreError> {
        let bad = |why: String| Err(CoreError::TimeFunction(why));
        if points.is_empty() {
            return bad("needs at least one (t, factor) point".into());
        }
        if let Some(p) = points
            .iter()
            .find(|p| !(p.0.is_finite() && p.1.is_finite()))
        {
            return bad(format!("point ({}, {}) is not finite", p.0, p.1));
        }
        for (i, w) in points.windows(2).enumerate() {
            if w[1].0 < w[0].0 {
                return bad(format!(
                    "times must not decrease: point {} has t = {} after t = {}",
                    i + 1,
                    w[1].0,
                    w[0].0
                ));
            }
        }
        if let Some(w) = points.windows(3).find(|w| w[0].0 == w[2].0) {
            return bad(format!(
                "more than two points at t = {}: a jump needs exactly two",
                w[0].0
            ));
        }
        Ok(TimeFunction {
            kind: Kind::Piecewise(points),
        })
    }

    /// The value at time `t`.
    pub fn value(&self, t: f64) -> f64 {
        let p = match &self.kind {
            Kind::Piecewise(p) => p,
            Kind::Cyclic(c) => return c.value(t),
        };
        // Index of the first point strictly after t.
        let after = p.partition_point(|q| q.0 <= t);
        if after == 0 {
            return p[0].1;
        }
        if after == p.len() {
            return p[after - 1].1;
        }
        let (a, b) = (p[after - 1], p[after]);
        a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_hold_and_jump() {
        let f = TimeFunction::new(vec![(0.0, 0.0), (1.0, 1.0), (2.0, 1.0), (2.0, 0.0)]).unwrap();
        assert_eq!(f.value(-1.0), 0.0);
        assert_eq!(f.value(0.25), 0.25);
        assert_eq!(f.value(1.5), 1.0);
        assert_eq!(f.value(1.999), 1.0);
        assert_eq!(f.value(2.0), 0.0);
        assert_eq!(f.value(7.0), 0.0);
    }

    #[test]
    fn cyclic_load_runs_between_its_extremes_from_its_minimum() {
        // 3 Hz between 0.075 and 1 (3 and 40 kN on 40 kN), starting at t = 0.5 s.
        let c = Cyclic {
            min: 0.075,
            max: 1.0,
            frequency: 3.0,
            phase: 0.0,
            start: 0.5,
        };
        let f = TimeFunction::cyclic(c).unwrap();
        let period = 1.0 / 3.0;
        assert_eq!(f.value(0.0), 0.075);
        assert!((f.value(0.5) - 0.075).abs() < 1e-15);
        assert!((f.value(0.5 + 0.25 * period) - 0.5375).abs() < 1e-12);
        assert!((f.value(0.5 + 0.5 * period) - 1.0).abs() < 1e-12);
        assert!((f.value(0.5 + period) - 0.075).abs() < 1e-12);
        // A load 90° behind stays at its minimum for a quarter cycle, then follows the same
        // curve a quarter period later; one 90° ahead begins a quarter period earlier.
        let lag = TimeFunction::cyclic(Cyclic {
            phase: -FRAC_PI_2,
            ..c
        })
        .unwrap();
        let lead = TimeFunction::cyclic(Cyclic {
            phase: FRAC_PI_2,
            ..c
        })
        .unwrap();
        assert_eq!(lag.value(0.5 + 0.2 * period), 0.075);
        for t in [0.61, 0.7, 0.93, 1.2] {
            assert!((lag.value(t + 0.25 * period) - f.value(t)).abs() < 1e-12);
            assert!((lead.value(t - 0.25 * period) - f.value(t)).abs() < 1e-12);
        }
        assert!(
            (lead.as_cyclic().unwrap().first_cycle_start() - (0.5 - 0.25 * period)).abs() < 1e-15
        );
        assert!(TimeFunction::cyclic(Cyclic {
            frequency: 0.0,
            ..c
        })
        .is_err());
    }

    #[test]
    fn bad_functions_are_refused() {
        assert!(TimeFunction::new(vec![]).is_err());
        assert!(TimeFunction::new(vec![(1.0, 0.0), (0.5, 1.0)]).is_err());
        assert!(TimeFunction::new(vec![(1.0, 0.0), (1.0, 1.0), (1.0, 2.0)]).is_err());
        assert!(TimeFunction::new(vec![(f64::NAN, 0.0)]).is_err());
    }
}
