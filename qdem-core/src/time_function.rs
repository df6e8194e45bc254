//! Piecewise-linear time functions for loads (the scene's `ramp`).
//!
//! Points (t, factor) with non-decreasing t; linear in between; the first value before the
//! first point and the last value after the last; a repeated t makes a jump, the function
//! taking the later value from that time on.

use crate::error::CoreError;

/// A piecewise-linear function of time.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeFunction {
    points: Vec<(f64, f64)>,
}

impl TimeFunction {
    /// A constant factor.
    pub fn constant(value: f64) -> TimeFunction {
        TimeFunction {
            points: vec![(0.0, value)],
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
        Ok(TimeFunction { points })
    }

    /// The value at time `t`.
    pub fn value(&self, t: f64) -> f64 {
        let p = &self.points;
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
    fn bad_functions_are_refused() {
        assert!(TimeFunction::new(vec![]).is_err());
        assert!(TimeFunction::new(vec![(1.0, 0.0), (0.5, 1.0)]).is_err());
        assert!(TimeFunction::new(vec![(1.0, 0.0), (1.0, 1.0), (1.0, 2.0)]).is_err());
        assert!(TimeFunction::new(vec![(f64::NAN, 0.0)]).is_err());
    }
}
