//! The time-delayed periodic boundary (TDPBC) of paper 003 §5, Eqs. 2–7.
//!
//! A periodic cell holds one sleeper loaded by a sinusoid between a minimum and a maximum
//! ([`LoadCycle`]). An ordinary periodic boundary treats the neighbour cells as if their sleepers
//! were loaded in phase with this one; under a moving load they are not: the cell behind (left
//! ghosts) is a phase lag δ behind, at Φ − δ, the cell ahead (right ghosts) δ ahead, at Φ + δ
//! (paper 003 Eqs. 4–5 take δ = π/2). The time-delayed boundary scales the force that a ghost
//! exerts on a particle by the ratio of the neighbour's predicted boundary force to this cell's.
//!
//! # The model (paper 003)
//! The average magnitude of the contact forces on both boundaries follows the load:
//!
//! - Eq. 2, [`average_force`]: A(Φ) = (F_max + F_min)/2 + (F_max − F_min)/2 · sin Φ.
//! - Eq. 3, [`estimate_max`]: F_max = (2 F_current − (1 − sin Φ) F_min) / (1 + sin Φ), Eq. 2
//!   solved for F_max, F_min being a cycle's first data point.
//! - Eqs. 4–5: the ghosts' averages A(Φ − δ) (left) and A(Φ + δ) (right).
//! - Eqs. 6–7: f_ghost = F_ghost / F_current · f_detected, i.e. the ghost forces are scaled by
//!   [`GhostScales`].
//!
//! # The controller
//! [`TimeDelayedBoundary::update`] takes the measured F_current once per force evaluation and
//! applies these rules:
//!
//! 1. Before the cycle's start, while no F_max estimate exists, or when F_current is not finite,
//!    the scales are exactly 1 (the ordinary periodic boundary) and nothing is recorded.
//! 2. The first call inside a new cycle index sets F_min := F_current (the paper's "first data
//!    point for each sinusoidal cycle").
//! 3. F_max := Eq. 3 at each call where 1 + sin Φ ≥ 1/2. Eq. 3 divides by 1 + sin Φ, which
//!    vanishes at the cycle's start; within the guard an error ε in F_current moves the
//!    half-range (F_max − F_min)/2 by at most 2ε (F_max by at most 4ε). Elsewhere the previous
//!    estimate is kept (the previous cycle's, early in a cycle).
//! 4. The scales are ratios of Eq. 2 predictions, s_left = A(Φ − δ)/A(Φ) and
//!    s_right = A(Φ + δ)/A(Φ), written as s = 1 + (F_max − F_min)/2 · (sin(Φ ∓ δ) − sin Φ)/A(Φ)
//!    so that δ = 0 gives exactly 1.0 in floating point: a zero-lag boundary reproduces the
//!    ordinary periodic boundary bit for bit. Where F_max came from Eq. 3 at the same call,
//!    A(Φ) = F_current (up to round-off) and these are Eqs. 6–7 exactly; where F_max is held,
//!    the ratio stays consistent with the fitted sinusoid.
//! 5. If A(Φ) ≤ 0 or is not finite, or a scale is not finite (a non-finite lag), the scales are
//!    1. Each scale is clamped to ≥ 0: a negative scale would turn a ghost's push into a pull.
//! 6. Each scale is at most a limit ([`TimeDelayedBoundary::with_scale_limit`]), the load's
//!    max/min ratio in a scene. The paper's premise is that the boundary forces follow the
//!    sleeper load (its Fig. 13), so a neighbour's force is at most L_max/L_min times this
//!    cell's. Without the cap, a cycle whose first data point F_min is near zero (the boundary
//!    contacts relaxed at the minimum load) gets scales of hundreds towards its end, where
//!    A(Φ) → F_min, and the ghosts' pushes blow the sample apart: in the seed-1 box-test study
//!    F_current fell to 0.015 N, the scales rose to 1,086 and an acceleration became infinite.
//! 7. Optionally (shared faces, [`TimeDelayedBoundary::with_shared_faces`]; not in paper
//!    003), both sides take one scale, [`GhostScales::shared`].
//!
//! # Shared faces (qdem's variant)
//! Eqs. 6–7 scale the two ends of one pair through the boundary differently: the sphere near
//! the left face feels s_left · f, its partner near the right face s_right · f, so the pair's
//! action is not its reaction and the boundary pushes the sample as a whole by
//! (s_left − s_right) f per pair, back and forth over a cycle. In a box of several cells a face
//! is shared by two cells and one set of pairs carries its force both ways; measured in the
//! box-test study (`docs/boxtest.md`), the force through each face of the middle cell follows
//! both cells' loads (it peaks between their peaks) and swings less than a periodic cell's.
//! With shared faces each face is taken to carry the mean of its two cells' Eq. 2 forces,
//! (A(Φ) + A(Φ ∓ δ))/2, and the cell's one set of boundary pairs, standing for both faces, is
//! scaled by their mean over A(Φ): s = (2A(Φ) + A(Φ − δ) + A(Φ + δ))/(4A(Φ)) on both
//! spheres. For δ = π/2 the swing of the boundary force about its mean is halved; for δ = 0
//! s is exactly 1.

use qdem_core::{checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder};
use std::f64::consts::{FRAC_PI_2, TAU};

/// Cycle counts this close below an integer count as that integer, so that a time computed as
/// start + n/f lands in cycle n despite round-off (Φ differs from the cycle start by ≤ 2π·1e-9).
const CYCLE_SNAP: f64 = 1e-9;

/// The sinusoidal load cycle the boundary follows: load = min + (max − min)(1 + sin Φ)/2 with
/// Φ(t) = 2π f (t − start) + phase − π/2, so each cycle begins at the minimum
/// (Φ = −π/2 + 2πn), as paper 003 takes F_Ave_min as a cycle's first point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadCycle {
    /// Load frequency f (Hz).
    pub frequency: f64,
    /// Phase offset (rad) added to Φ; 0 starts the first cycle at the minimum.
    pub phase: f64,
    /// Time the load starts (s).
    pub start: f64,
}

impl LoadCycle {
    /// Φ(t) = 2π f (t − start) + phase − π/2, or `None` before `start` (or at a NaN time).
    pub fn phase_at(&self, t: f64) -> Option<f64> {
        (t >= self.start)
            .then_some(TAU * self.frequency * (t - self.start) + self.phase - FRAC_PI_2)
    }

    /// Index n of the cycle t lies in, floor((Φ + π/2)/2π) = floor(f (t − start) + phase/2π)
    /// (a count within 1e-9 below an integer is taken as that integer); `None` before `start`.
    pub fn cycle_at(&self, t: f64) -> Option<i64> {
        (t >= self.start).then(|| {
            let count = self.frequency * (t - self.start) + self.phase / TAU;
            (count + CYCLE_SNAP).floor() as i64
        })
    }
}

/// Eq. 2: the average boundary force at phase Φ of a cycle with extremes `f_max`, `f_min`,
/// (f_max + f_min)/2 + (f_max − f_min)/2 · sin Φ.
pub fn average_force(f_max: f64, f_min: f64, phi: f64) -> f64 {
    0.5 * (f_max + f_min) + 0.5 * (f_max - f_min) * phi.sin()
}

/// Eq. 3: f_max from the current average, the cycle's minimum and Φ,
/// (2 f_current − (1 − sin Φ) f_min)/(1 + sin Φ). Infinite or NaN where 1 + sin Φ = 0.
pub fn estimate_max(f_current: f64, f_min: f64, phi: f64) -> f64 {
    let sin = phi.sin();
    (2.0 * f_current - (1.0 - sin) * f_min) / (1.0 + sin)
}

/// The lag of a neighbour cell for a load travelling at `speed` (m/s) over sleepers `spacing`
/// (m) apart, loaded at `frequency` (Hz): δ = 2π f · spacing / speed (rad). Paper 003's
/// δ = π/2 is a speed of 4 f · spacing.
pub fn lag_from_spacing(frequency: f64, spacing: f64, speed: f64) -> f64 {
    TAU * frequency * spacing / speed
}

/// Scales for forces from left and right ghosts (Eqs. 6–7).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GhostScales {
    /// Scale of forces from ghosts on the left side (the cell behind, phase Φ − δ).
    pub left: f64,
    /// Scale of forces from ghosts on the right side (the cell ahead, phase Φ + δ).
    pub right: f64,
}

impl GhostScales {
    /// Both scales 1: the ordinary periodic boundary.
    pub const PERIODIC: GhostScales = GhostScales {
        left: 1.0,
        right: 1.0,
    };

    /// Shared faces: both sides at s = (1 + (s_left + s_right)/2)/2, i.e.
    /// (2A(Φ) + A(Φ − δ) + A(Φ + δ))/(4A(Φ)): each face carries the mean of its two cells'
    /// Eq. 2 forces, and the cell's one set of boundary pairs stands for both faces. Exactly 1
    /// where both scales are 1.
    pub fn shared(self) -> GhostScales {
        let s = 0.5 * (1.0 + 0.5 * (self.left + self.right));
        GhostScales { left: s, right: s }
    }
}

/// The controller's state: the load cycle, the lag and the current cycle's extremes.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeDelayedBoundary {
    cycle: LoadCycle,
    lag: f64,
    /// The current cycle's index and F_min (its first data point).
    current: Option<(i64, f64)>,
    f_max: Option<f64>,
    /// Rule 6's cap on either scale.
    limit: f64,
    /// Rule 7: one scale for both sides of the boundary ([`GhostScales::shared`]).
    shared: bool,
}

impl TimeDelayedBoundary {
    /// A controller following `cycle` with neighbour lag `lag` δ (rad; paper 003: π/2), with no
    /// estimates yet.
    pub fn new(cycle: LoadCycle, lag: f64) -> TimeDelayedBoundary {
        TimeDelayedBoundary {
            cycle,
            lag,
            current: None,
            f_max: None,
            limit: f64::INFINITY,
            shared: false,
        }
    }

    /// The same controller with shared faces (rule 7): a pair through the boundary pushes
    /// both its spheres with one scale, so its action equals its reaction.
    pub fn with_shared_faces(self) -> TimeDelayedBoundary {
        TimeDelayedBoundary {
            shared: true,
            ..self
        }
    }

    /// The same controller with both scales capped at `limit` (rule 6; ≥ 1, so a zero lag
    /// still gives exactly the ordinary boundary).
    pub fn with_scale_limit(self, limit: f64) -> TimeDelayedBoundary {
        TimeDelayedBoundary {
            limit: limit.max(1.0),
            ..self
        }
    }

    /// Takes the measured F_current (average magnitude of the contact forces across both
    /// boundaries) at time `time` and returns the ghost scales, by rules 1–7 of the module docs.
    /// Call once per force evaluation, in time order.
    pub fn update(&mut self, time: f64, f_current: f64) -> GhostScales {
        let (Some(phi), Some(index)) = (self.cycle.phase_at(time), self.cycle.cycle_at(time))
        else {
            return GhostScales::PERIODIC;
        };
        if !f_current.is_finite() {
            return GhostScales::PERIODIC;
        }
        let f_min = self.record_min(index, f_current);
        if 1.0 + phi.sin() >= 0.5 {
            self.f_max = Some(estimate_max(f_current, f_min, phi));
        }
        let Some(f_max) = self.f_max else {
            return GhostScales::PERIODIC;
        };
        let scales = ghost_scales(f_max, f_min, phi, self.lag, self.limit);
        if self.shared {
            scales.shared()
        } else {
            scales
        }
    }

    /// Rule 2: on the first call in cycle `index`, `f_current` becomes the cycle's F_min.
    /// Returns the cycle's F_min.
    fn record_min(&mut self, index: i64, f_current: f64) -> f64 {
        match self.current {
            Some((known, f_min)) if known == index => f_min,
            _ => {
                self.current = Some((index, f_current));
                f_current
            }
        }
    }

    /// The phase lag δ of the neighbour cells (rad).
    pub fn lag(&self) -> f64 {
        self.lag
    }

    /// Current estimates (F_min, F_max) for output and tests.
    pub fn extremes(&self) -> (Option<f64>, Option<f64>) {
        (self.current.map(|(_, f_min)| f_min), self.f_max)
    }

    /// Writes the running estimates (the cycle and its F_min, F_max) into a checkpoint.
    pub fn save(&self, out: &mut Encoder) {
        out.bool(self.current.is_some());
        let (index, f_min) = self.current.unwrap_or((0, 0.0));
        out.u64(index as u64);
        out.f64(f_min);
        out.option_f64(self.f_max);
    }

    /// Reads back what [`TimeDelayedBoundary::save`] wrote.
    pub fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        let known = input.bool("the boundary's cycle flag")?;
        let index = input.u64("the boundary's cycle")? as i64;
        let f_min = input.f64("the boundary's F_min")?;
        self.current = known.then_some((index, f_min));
        self.f_max = input.option_f64("the boundary's F_max")?;
        Ok(())
    }
}

/// Rules 4–6: s = 1 + (f_max − f_min)/2 · (sin(Φ ∓ δ) − sin Φ)/A(Φ) = A(Φ ∓ δ)/A(Φ) (Eqs. 4–7),
/// exactly 1 for δ = 0, clamped to [0, `limit`]; both 1 where A(Φ) ≤ 0 or a value is not
/// finite.
fn ghost_scales(f_max: f64, f_min: f64, phi: f64, lag: f64, limit: f64) -> GhostScales {
    let current = average_force(f_max, f_min, phi);
    if !(current > 0.0 && current.is_finite()) {
        return GhostScales::PERIODIC;
    }
    let half_range = 0.5 * (f_max - f_min);
    let sin_phi = phi.sin();
    let scale = |shifted: f64| 1.0 + half_range * (shifted.sin() - sin_phi) / current;
    let (left, right) = (scale(phi - lag), scale(phi + lag));
    if !(left.is_finite() && right.is_finite()) {
        return GhostScales::PERIODIC;
    }
    GhostScales {
        left: left.clamp(0.0, limit),
        right: right.clamp(0.0, limit),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_6, PI};

    /// 3 Hz from t = 0, first cycle starting at the minimum.
    const CYCLE: LoadCycle = LoadCycle {
        frequency: 3.0,
        phase: 0.0,
        start: 0.0,
    };

    /// The true boundary force, a sinusoid between 10 and 30: A(Φ) = 20 + 10 sin Φ.
    fn true_force(phi: f64) -> f64 {
        average_force(30.0, 10.0, phi)
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1.0)
    }

    #[test]
    fn shared_faces_scale_both_sides_by_the_mean_of_the_two_faces() {
        // f_max = 30, f_min = 10, δ = π/2. At Φ = 0: A = 20, A(−π/2) = 10, A(π/2) = 30, so
        // s_left = 0.5, s_right = 1.5 and the shared scale (2·20 + 10 + 30)/(4·20) = 1.
        // At the peak Φ = π/2: A = 30, both neighbours at 20: (60 + 40)/120 = 5/6.
        let at = |phi: f64| ghost_scales(30.0, 10.0, phi, FRAC_PI_2, f64::INFINITY);
        let zero = at(0.0);
        assert!(close(zero.left, 0.5, 1e-15) && close(zero.right, 1.5, 1e-15));
        let shared = zero.shared();
        assert!(close(shared.left, 1.0, 1e-15) && shared.left == shared.right);
        let peak = at(FRAC_PI_2).shared();
        assert!(close(peak.left, 5.0 / 6.0, 1e-15) && peak.left == peak.right);
        assert_eq!(GhostScales::PERIODIC.shared(), GhostScales::PERIODIC);
    }

    #[test]
    fn eq2_at_hand_computed_phases() {
        // f_max = 30, f_min = 10: mean 20, half-range 10.
        // Φ = −π/2: 20 − 10 = 10; Φ = 0: 20; Φ = π/2: 20 + 10 = 30; Φ = π/6: 20 + 10·½ = 25.
        assert!(close(average_force(30.0, 10.0, -FRAC_PI_2), 10.0, 1e-15));
        assert_eq!(average_force(30.0, 10.0, 0.0), 20.0);
        assert!(close(average_force(30.0, 10.0, FRAC_PI_2), 30.0, 1e-15));
        assert!(close(average_force(30.0, 10.0, FRAC_PI_6), 25.0, 1e-15));
    }

    #[test]
    fn eq3_inverts_eq2() {
        // Φ = π/6: (2·25 − (1 − ½)·10)/(1 + ½) = 45/1.5 = 30.
        assert!(close(estimate_max(25.0, 10.0, FRAC_PI_6), 30.0, 1e-15));
        for k in 0..200 {
            let phi = -FRAC_PI_6 + k as f64 * (4.0 * PI / 3.0) / 199.0;
            for (f_max, f_min) in [(30.0, 10.0), (40.0e3, 3.0e3), (1.0, 0.999)] {
                let f = average_force(f_max, f_min, phi);
                let back = estimate_max(f, f_min, phi);
                assert!(close(back, f_max, 1e-12), "Φ = {phi}: {back} vs {f_max}");
            }
        }
    }

    #[test]
    fn load_cycle_phase_and_index() {
        let cycle = LoadCycle {
            frequency: 3.0,
            phase: 0.0,
            start: 0.5,
        };
        assert_eq!(cycle.phase_at(0.4), None);
        assert_eq!(cycle.cycle_at(0.4), None);
        assert_eq!(cycle.phase_at(f64::NAN), None);
        assert_eq!(cycle.phase_at(0.5), Some(-FRAC_PI_2));
        assert_eq!(cycle.cycle_at(0.5), Some(0));
        // A quarter period after the start, Φ = 2π·3·(1/12) − π/2 = 0.
        assert!(cycle.phase_at(0.5 + 1.0 / 12.0).unwrap().abs() < 1e-14);
        assert_eq!(cycle.cycle_at(0.5 + 1.0 / 3.0 - 1e-6), Some(0));
        assert_eq!(cycle.cycle_at(0.5 + 1.0 / 3.0), Some(1));
        assert_eq!(cycle.cycle_at(0.5 + 2.0 / 3.0), Some(2));
        assert_eq!(cycle.cycle_at(0.5 + 2.0 / 3.0 + 0.1), Some(2));
        // A phase of π shifts Φ by π: t = 0.5 → Φ = π/2, still cycle 0 (count ½).
        let shifted = LoadCycle { phase: PI, ..cycle };
        assert!(close(shifted.phase_at(0.5).unwrap(), FRAC_PI_2, 1e-15));
        assert_eq!(shifted.cycle_at(0.5), Some(0));
        assert_eq!(shifted.cycle_at(0.5 + 1.0 / 6.0), Some(1));
    }

    #[test]
    fn lag_of_hand_computed_spacings() {
        // 2π·3·0.65/1.95 = 2π·3·(1/3) = 2π: one sleeper spacing per period, a whole cycle.
        assert!(close(lag_from_spacing(3.0, 0.65, 1.95), TAU, 1e-15));
        // Paper 003's quarter cycle: speed 4·3·0.65 = 7.8 m/s → 2π·3·0.65/7.8 = π/2.
        assert!(close(lag_from_spacing(3.0, 0.65, 7.8), FRAC_PI_2, 1e-15));
    }

    #[test]
    fn before_start_and_without_estimate_the_boundary_is_ordinary() {
        let cycle = LoadCycle {
            start: 1.0,
            ..CYCLE
        };
        let mut b = TimeDelayedBoundary::new(cycle, FRAC_PI_2);
        assert_eq!(b.update(0.5, 123.0), GhostScales::PERIODIC);
        assert_eq!(b.extremes(), (None, None));
        // At the start Φ = −π/2: F_min recorded, 1 + sin Φ = 0 < ½, no F_max yet.
        assert_eq!(b.update(1.0, 10.0), GhostScales::PERIODIC);
        assert_eq!(b.extremes(), (Some(10.0), None));
        assert_eq!(b.update(1.01, f64::NAN), GhostScales::PERIODIC);
        assert_eq!(b.extremes(), (Some(10.0), None));
        assert_eq!(b.lag(), FRAC_PI_2);
    }

    #[test]
    fn quarter_period_matches_the_paper_example() {
        // Start at the minimum 10, then Φ = 0 with F = 20: Eq. 3 gives (40 − 10)/1 = 30;
        // left A(−π/2)/A(0) = 10/20 = 0.5, right A(π/2)/A(0) = 30/20 = 1.5.
        let mut b = TimeDelayedBoundary::new(CYCLE, FRAC_PI_2);
        b.update(0.0, 10.0);
        let s = b.update(1.0 / 12.0, 20.0);
        assert!(close(b.extremes().1.unwrap(), 30.0, 1e-12));
        assert!(
            close(s.left, 0.5, 1e-12) && close(s.right, 1.5, 1e-12),
            "{s:?}"
        );
    }

    /// Feeds the true force over three cycles, sampled every 1e-3 s from each cycle's start,
    /// and returns (Φ, scales) of every call.
    fn run_three_cycles(lag: f64) -> Vec<(f64, GhostScales)> {
        let mut b = TimeDelayedBoundary::new(CYCLE, lag);
        let mut out = Vec::new();
        for n in 0..3 {
            for j in 0..=333 {
                let t = n as f64 / 3.0 + j as f64 * 1e-3;
                let phi = CYCLE.phase_at(t).unwrap();
                assert_eq!(CYCLE.cycle_at(t), Some(n));
                out.push((phi, b.update(t, true_force(phi))));
            }
            let (f_min, _) = b.extremes();
            assert!(close(f_min.unwrap(), 10.0, 1e-12), "cycle {n}: {f_min:?}");
        }
        out
    }

    #[test]
    fn quarter_lag_follows_the_true_sinusoid() {
        // From the first guard point (1 + sin Φ ≥ ½) on, F_min = 10 and F_max = 30 (fitted, then
        // held early in the next cycle), so s = A(Φ ∓ π/2)/A(Φ) of the true sinusoid.
        let samples = run_three_cycles(FRAC_PI_2);
        let first_guard = samples
            .iter()
            .position(|(phi, _)| 1.0 + phi.sin() >= 0.5)
            .unwrap();
        for (phi, s) in &samples[..first_guard] {
            assert_eq!(*s, GhostScales::PERIODIC, "Φ = {phi}");
        }
        for (phi, s) in &samples[first_guard..] {
            let a = true_force(*phi);
            let left = true_force(phi - FRAC_PI_2) / a;
            let right = true_force(phi + FRAC_PI_2) / a;
            assert!(close(s.left, left, 1e-9), "Φ = {phi}: {} vs {left}", s.left);
            assert!(
                close(s.right, right, 1e-9),
                "Φ = {phi}: {} vs {right}",
                s.right
            );
        }
    }

    #[test]
    fn uniform_sampling_is_close_to_the_true_sinusoid() {
        // Sampled every 1e-3 s from t = 0 the first point of a cycle lies up to 1e-3 s after the
        // minimum: F_min is then up to 10(1 − cos(2π·3·1e-3)) ≈ 1.8e-3 above 10, which moves the
        // scales by ~1e-4 (2.7e-4 measured) after cycle 0.
        let mut b = TimeDelayedBoundary::new(CYCLE, FRAC_PI_2);
        for k in 0..=1000 {
            let t = k as f64 * 1e-3;
            let phi = CYCLE.phase_at(t).unwrap();
            let a = true_force(phi);
            let s = b.update(t, a);
            if t > 1.0 / 3.0 {
                assert!(
                    (s.left - true_force(phi - FRAC_PI_2) / a).abs() < 1e-3,
                    "t = {t}"
                );
                assert!(
                    (s.right - true_force(phi + FRAC_PI_2) / a).abs() < 1e-3,
                    "t = {t}"
                );
            }
        }
    }

    #[test]
    fn zero_lag_is_exactly_the_ordinary_boundary() {
        for (phi, s) in run_three_cycles(0.0) {
            assert_eq!(s, GhostScales::PERIODIC, "Φ = {phi}");
        }
        // Also with a held F_max far from the data and an arbitrary phase offset.
        let cycle = LoadCycle {
            frequency: 3.0,
            phase: 0.3,
            start: 0.2,
        };
        let mut b = TimeDelayedBoundary::new(cycle, 0.0);
        for k in 0..2000 {
            let t = 0.2 + k as f64 * 7.3e-4;
            let f = 3.0e3 + 37.0e3 * (k as f64 * 0.37).sin().abs();
            assert_eq!(b.update(t, f), GhostScales::PERIODIC, "t = {t}");
        }
    }

    #[test]
    fn scales_are_clamped_and_guarded() {
        // f_max = 30, f_min = 10 at Φ = π/2 with δ = π: left/right A(−π/2)/A(π/2) = 10/30 ≥ 0.
        let s = ghost_scales(30.0, 10.0, FRAC_PI_2, PI, f64::INFINITY);
        assert!(close(s.left, 1.0 / 3.0, 1e-12) && close(s.right, 1.0 / 3.0, 1e-12));
        // f_max = 30, f_min = −10 (a fit gone wrong): A(π/2) = 30, A(−π/2) = −10 → −1/3 → 0.
        let s = ghost_scales(30.0, -10.0, FRAC_PI_2, PI, f64::INFINITY);
        assert_eq!((s.left, s.right), (0.0, 0.0));
        // A(Φ) ≤ 0 or not finite, or a NaN lag: ordinary boundary.
        assert_eq!(
            ghost_scales(30.0, -10.0, -FRAC_PI_2, 1.0, f64::INFINITY),
            GhostScales::PERIODIC
        );
        assert_eq!(
            ghost_scales(f64::INFINITY, 10.0, 0.0, 1.0, f64::INFINITY),
            GhostScales::PERIODIC
        );
        assert_eq!(
            ghost_scales(30.0, 10.0, 0.0, f64::NAN, f64::INFINITY),
            GhostScales::PERIODIC
        );
        // F_min = 0.1 N, F_max = 150 N near a cycle's end (Φ = 3π/2 − 0.1), δ = π/2:
        // A(Φ) = 75.05 − 74.95 cos 0.1 = 0.474 N against A(Φ ∓ δ) = 75.05 ± 74.95 sin 0.1 =
        // 82.5 and 67.6 N: scales 174 and 142, capped at the load ratio 40/3.
        let s = ghost_scales(150.0, 0.1, 1.5 * PI - 0.1, FRAC_PI_2, 40.0 / 3.0);
        assert_eq!((s.left, s.right), (40.0 / 3.0, 40.0 / 3.0));
        let free = ghost_scales(150.0, 0.1, 1.5 * PI - 0.1, FRAC_PI_2, f64::INFINITY);
        assert!(
            close(free.left, 173.9586, 1e-6) && close(free.right, 142.4159, 1e-6),
            "{free:?}"
        );
    }
}
