//! The servo law of stress-controlled plane walls (the loads it reads and the walls it
//! drives are `dem_contacts/servo_loads.rs`'s), as PFC's wall servo and LIGGGHTS's
//! `fix mesh/surface/stress/servo`: after each force evaluation the wall's speed along its
//! normal (towards the bodies) is set to
//!
//! v = clamp(G (σ_target(t) − σ), −v_max, v_max),
//!
//! with σ_target(t) = σ₀ f(t), the target stress times a time factor (a piecewise-linear load
//! path of stress steps, LIGGGHTS's `fix_modify servo target_val` between runs; f = 1 by
//! default),
//! with σ = F·(−n)/A the compressive stress the spheres put on it (F their total force on the
//! wall, n its inward normal, A the area it stands for). Without a given gain, G follows PFC's
//! servo, G = α A / (Σ k_n Δt) with α = 0.5, with the contacts' normal dashpots c_n = 2ζ√(k_n m)
//! added: G = α A / Σ (k_n Δt + c_n), summed over the wall's touching contacts, Δt the time
//! since the last evaluation. A wall speed v changes the wall's force by Σ (k_n Δt + c_n) v over
//! a step (the springs through the distance moved, the dashpots at once), so one step closes at
//! most half the stress error; without the dashpots' term a damped contact law makes the
//! servo chatter between ±v_max. A wall that touches nothing moves at v_max towards the bodies.

use qdem_core::loads::TimeFunction;

/// The fraction α of the stress error the default gain closes in one step.
pub const DEFAULT_GAIN_FRACTION: f64 = 0.5;

/// A stress-controlled plane wall's target and limits.
#[derive(Clone, Debug, PartialEq)]
pub struct Servo {
    /// Target compressive normal stress σ₀ (Pa), times `factor`.
    pub stress: f64,
    /// The time factor f(t) on `stress`: σ_target(t) = σ₀ f(t).
    pub factor: TimeFunction,
    /// The area the wall's force is divided by, A (m²).
    pub area: f64,
    /// Gain G (m/(s·Pa)); `None`: α A / Σ (k_n Δt + c_n), renewed at every evaluation.
    pub gain: Option<f64>,
    /// Largest speed v_max (m/s), also the wall's speed bound for the neighbour lists.
    pub max_velocity: f64,
}

impl Servo {
    /// The target stress σ_target(t) = σ₀ f(t) (Pa) at `time`.
    ///
    /// ```
    /// use qdem_contact::Servo;
    /// use qdem_core::loads::TimeFunction;
    /// let path = TimeFunction::new(vec![(0.0, 1.0), (0.1, 0.25)]).unwrap();
    /// let servo = Servo { stress: 2e4, factor: path, area: 0.01, gain: None, max_velocity: 0.1 };
    /// assert_eq!(servo.target(0.0), 2e4);
    /// assert_eq!(servo.target(0.2), 5e3);
    /// ```
    pub fn target(&self, time: f64) -> f64 {
        self.stress * self.factor.value(time)
    }

    /// The speed along the inward normal (m/s) at `time` for a measured compressive stress
    /// `stress` (Pa) and the response Σ (k_n Δt + c_n) (N·s/m) of the wall's touching
    /// contacts: positive moves towards the bodies.
    pub fn speed(&self, time: f64, stress: f64, response: f64) -> f64 {
        let error = self.target(time) - stress;
        let gain = self
            .gain
            .unwrap_or(DEFAULT_GAIN_FRACTION * self.area / response);
        let speed = gain * error;
        match speed.is_nan() {
            true => 0.0,
            false => speed.clamp(-self.max_velocity, self.max_velocity),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_servo_pushes_when_under_stressed_and_backs_off_when_over() {
        let servo = Servo {
            stress: 1e5,
            factor: TimeFunction::constant(1.0),
            area: 0.01,
            gain: None,
            max_velocity: 0.1,
        };
        // Σ (k_n Δt + c_n) = 10 N·s/m: G = 0.5 · 0.01 / 10 = 5e-4 m/(s·Pa).
        assert!((servo.speed(0.0, 0.9e5, 10.0) - 0.1).abs() < 1e-15);
        assert!((servo.speed(0.0, 1e5 + 10.0, 10.0) + 5e-3).abs() < 1e-15);
        // Touching nothing (or at the first evaluation): as fast as allowed towards the bodies.
        assert_eq!(servo.speed(0.0, 0.0, 0.0), 0.1);
        assert_eq!(servo.speed(0.0, 1e5, 0.0), 0.0);
        let fixed = Servo {
            gain: Some(1e-7),
            ..servo.clone()
        };
        assert!((fixed.speed(0.0, 2e5, 0.0) + 0.01).abs() < 1e-15);
    }

    #[test]
    fn the_target_follows_its_load_path() {
        // Load to 20 kPa, unload to 5 kPa over 0.1 s, hold, then step to 40 kPa.
        let path = vec![(0.0, 1.0), (0.1, 0.25), (0.2, 0.25), (0.2, 2.0)];
        let servo = Servo {
            stress: 2e4,
            factor: TimeFunction::new(path).unwrap(),
            area: 0.01,
            gain: Some(1e-6),
            max_velocity: 1.0,
        };
        assert_eq!(servo.target(0.05), 12500.0);
        assert_eq!(servo.target(0.15), 5000.0);
        assert_eq!(servo.target(0.2), 40000.0);
        // At 5 kPa the wall backs off a bed that pushes with 20 kPa: G (5e3 − 2e4).
        assert!((servo.speed(0.15, 2e4, 0.0) + 0.015).abs() < 1e-15);
    }
}
