//! The servo law of stress-controlled plane walls (the loads it reads and the walls it
//! drives are `dem_contacts/servo_loads.rs`'s), as PFC's wall servo and LIGGGHTS's
//! `fix mesh/surface/stress/servo`: after each force evaluation the wall's speed along its
//! normal (towards the bodies) is set to
//!
//! v = clamp(G (σ_target − σ), −v_max, v_max),
//!
//! with σ = F·(−n)/A the compressive stress the spheres put on it (F their total force on the
//! wall, n its inward normal, A the area it stands for). Without a given gain, G follows PFC's
//! servo, G = α A / (Σ k_n Δt) with α = 0.5, with the contacts' normal dashpots c_n = 2ζ√(k_n m)
//! added: G = α A / Σ (k_n Δt + c_n), summed over the wall's touching contacts, Δt the time
//! since the last evaluation. A wall speed v changes the wall's force by Σ (k_n Δt + c_n) v over
//! a step (the springs through the distance moved, the dashpots at once), so one step closes at
//! most half the stress error; without the dashpots' term a damped contact law makes the
//! servo chatter between ±v_max. A wall that touches nothing moves at v_max towards the bodies.

/// The fraction α of the stress error the default gain closes in one step.
pub const DEFAULT_GAIN_FRACTION: f64 = 0.5;

/// A stress-controlled plane wall's target and limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Servo {
    /// Target compressive normal stress σ_target (Pa).
    pub stress: f64,
    /// The area the wall's force is divided by, A (m²).
    pub area: f64,
    /// Gain G (m/(s·Pa)); `None`: α A / Σ (k_n Δt + c_n), renewed at every evaluation.
    pub gain: Option<f64>,
    /// Largest speed v_max (m/s), also the wall's speed bound for the neighbour lists.
    pub max_velocity: f64,
}

impl Servo {
    /// The speed along the inward normal (m/s) for a measured compressive stress `stress`
    /// (Pa) and the response Σ (k_n Δt + c_n) (N·s/m) of the wall's touching contacts:
    /// positive moves towards the bodies.
    pub fn speed(&self, stress: f64, response: f64) -> f64 {
        let error = self.stress - stress;
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
            area: 0.01,
            gain: None,
            max_velocity: 0.1,
        };
        // Σ (k_n Δt + c_n) = 10 N·s/m: G = 0.5 · 0.01 / 10 = 5e-4 m/(s·Pa).
        assert!((servo.speed(0.9e5, 10.0) - 0.1).abs() < 1e-15);
        assert!((servo.speed(1e5 + 10.0, 10.0) + 5e-3).abs() < 1e-15);
        // Touching nothing (or at the first evaluation): as fast as allowed towards the bodies.
        assert_eq!(servo.speed(0.0, 0.0), 0.1);
        assert_eq!(servo.speed(1e5, 0.0), 0.0);
        let fixed = Servo {
            gain: Some(1e-7),
            ..servo
        };
        assert!((fixed.speed(2e5, 0.0) + 0.01).abs() < 1e-15);
    }
}
