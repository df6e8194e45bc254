//! Detecting a run that has gone unstable, so that it stops with a diagnosis instead of
//! writing garbage: non-finite accelerations (the steppers), inverted tetrahedra (the
//! bodies, [`crate::step::Model::failure`]) and runaway kinetic energy ([`EnergyGrowth`]).

/// Kinetic energy growth at every step by at least this factor counts towards runaway.
pub const GROWTH_PER_STEP: f64 = 1.2;
/// Consecutive steps of such growth that signal an instability (a growth of at least
/// 1.2⁶⁰ ≈ 6·10⁴).
pub const GROWTH_STEPS: u32 = 60;

/// Watches the kinetic energy for the exponential growth of an unstable explicit step.
///
/// Beyond the stable step the highest mode is amplified by the same factor |λ| > 1 at every
/// step, so the energy grows geometrically. Physical growth does not keep that pace: from
/// rest under a load growing like tᵏ the kinetic energy grows like t^(2k+2), whose ratio
/// from step n to n + 1, (1 + 1/n)^(2k+2), stays above 1.2 for at most (2k + 2)/ln 1.2 ≈
/// 11(k + 1) steps, fewer than [`GROWTH_STEPS`] for any load up to quartic in time; and a
/// physical instability (buckling) that grows by 20% per step would have a rate of about
/// 5% of the highest frequency the step resolves, far beyond a structure's.
#[derive(Clone, Debug, Default)]
pub struct EnergyGrowth {
    last: f64,
    run: u32,
    run_start: f64,
}

impl EnergyGrowth {
    /// A watcher that has seen nothing.
    pub fn new() -> EnergyGrowth {
        EnergyGrowth::default()
    }

    /// Takes the kinetic energy after a step; returns the growth factor over the run of
    /// growing steps once that run reaches [`GROWTH_STEPS`].
    pub fn observe(&mut self, kinetic: f64) -> Option<f64> {
        if self.last > 0.0 && kinetic >= GROWTH_PER_STEP * self.last {
            if self.run == 0 {
                self.run_start = self.last;
            }
            self.run += 1;
        } else {
            self.run = 0;
        }
        self.last = kinetic;
        (self.run >= GROWTH_STEPS).then(|| kinetic / self.run_start)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geometric_growth_is_caught_and_polynomial_growth_from_rest_is_not() {
        let mut watch = EnergyGrowth::new();
        let caught = (1..=200).find_map(|n| watch.observe(1e-20 * 1.44f64.powi(n)));
        let growth = caught.expect("a growth of 1.44 per step is an instability");
        assert!((growth / 1.44f64.powi(GROWTH_STEPS as i32) - 1.0).abs() < 1e-9);
        // Kinetic energy under a load growing like t^4 from rest: t^10.
        let mut watch = EnergyGrowth::new();
        assert!((1..=10_000).all(|n| watch.observe((n as f64).powi(10)).is_none()));
        let mut watch = EnergyGrowth::new();
        assert!((1..=10_000).all(|n| watch.observe(1e-9 * (n as f64).powi(2)).is_none()));
        // Oscillating energy never grows for long.
        let mut watch = EnergyGrowth::new();
        assert!((0..10_000).all(|n| watch.observe(1.0 + (0.3 * n as f64).sin()).is_none()));
    }
}
