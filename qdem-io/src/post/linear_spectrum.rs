//! Linear (Fourier amplitude) spectra smoothed by a Parzen spectral window, and mobility, as
//! paper 000 §4.2 analyses the sleeper and ballast accelerations (Figs. 9–11: "linear spectra
//! smoothed by applying a Parzen window with a bandwidth of 20 Hz") and the ballast's response
//! to the rail-seat load (Fig. 12: "the linear spectral function of the ballast particle
//! velocity divided by that of the input load").
//!
//! - Linear spectrum of a record x₀…x_{N−1} sampled every ∆t (mean removed):
//!   |X(f_k)| = ∆t·|Σₙ xₙ e^{−2πi kn/N}| at f_k = k/(N∆t), k = 0…N/2 (unit: the record's unit
//!   times seconds). A sine of amplitude A over a whole number of periods reads A·N∆t/2.
//! - Parzen spectral window of bandwidth b (the classic smoothing window of Fourier amplitude
//!   spectra in Japanese vibration practice): W(f) = ¾·u·[sin(πuf/2)/(πuf/2)]⁴ with
//!   u = 280/(151·b), whose integral is 1; it is applied to the amplitudes over |f| < 4/u
//!   (past its second zero), its weights renormalised at the ends of the spectrum.
//! - Mobility: smoothed |V(f)| / smoothed |F(f)| of a velocity and a force record over the same
//!   samples (m/s per N).

use rustfft::{num_complex::Complex, FftPlanner};

/// One-sided linear spectrum `(f, |X(f)|)` of `samples` taken every `dt` (mean removed, no
/// taper, no padding). Empty for fewer than 2 samples.
pub fn linear_spectrum(samples: &[f64], dt: f64) -> Vec<(f64, f64)> {
    let n = samples.len();
    if n < 2 {
        return Vec::new();
    }
    let mean = samples.iter().sum::<f64>() / n as f64;
    let mut buffer: Vec<Complex<f64>> = samples
        .iter()
        .map(|&s| Complex::new(s - mean, 0.0))
        .collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buffer);
    let df = 1.0 / (n as f64 * dt);
    buffer[..=n / 2]
        .iter()
        .enumerate()
        .map(|(k, c)| (k as f64 * df, c.norm() * dt))
        .collect()
}

/// The Parzen spectral window of bandwidth `bandwidth` (Hz) at frequency offset `f` (Hz).
pub fn parzen_window(f: f64, bandwidth: f64) -> f64 {
    let u = 280.0 / (151.0 * bandwidth);
    let x = 0.5 * std::f64::consts::PI * u * f;
    let sinc = if x == 0.0 { 1.0 } else { x.sin() / x };
    0.75 * u * sinc.powi(4)
}

/// `spectrum` (equally spaced frequencies from 0) smoothed by the Parzen window of
/// `bandwidth` Hz. A bandwidth below the frequency step leaves it unchanged.
pub fn parzen_smooth(spectrum: &[(f64, f64)], bandwidth: f64) -> Vec<(f64, f64)> {
    if spectrum.len() < 2 {
        return spectrum.to_vec();
    }
    let df = spectrum[1].0 - spectrum[0].0;
    let u = 280.0 / (151.0 * bandwidth);
    let half = ((4.0 / u) / df).floor() as usize;
    let weights: Vec<f64> = (0..=half)
        .map(|j| parzen_window(j as f64 * df, bandwidth))
        .collect();
    (0..spectrum.len())
        .map(|k| {
            let lo = k.saturating_sub(half);
            let hi = (k + half).min(spectrum.len() - 1);
            let (mut sum, mut norm) = (0.0, 0.0);
            for (j, &(_, a)) in spectrum.iter().enumerate().take(hi + 1).skip(lo) {
                let w = weights[j.abs_diff(k)];
                sum += w * a;
                norm += w;
            }
            (spectrum[k].0, sum / norm)
        })
        .collect()
}

/// Mobility `(f, |V(f)|/|F(f)|)` of `velocity` over `force` (same length, every `dt`), both
/// linear spectra smoothed with the Parzen window of `bandwidth` Hz; frequencies where the
/// smoothed force spectrum vanishes are left out.
pub fn mobility(velocity: &[f64], force: &[f64], dt: f64, bandwidth: f64) -> Vec<(f64, f64)> {
    let v = parzen_smooth(&linear_spectrum(velocity, dt), bandwidth);
    let f = parzen_smooth(&linear_spectrum(force, dt), bandwidth);
    v.iter()
        .zip(&f)
        .filter(|(_, (_, fa))| *fa > 0.0)
        .map(|(&(freq, va), &(_, fa))| (freq, va / fa))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn a_whole_number_of_sine_periods_reads_half_its_amplitude_times_the_duration() {
        let (n, dt, f0, amplitude) = (1000, 1e-3, 50.0, 3.0);
        let x: Vec<f64> = (0..n)
            .map(|i| 7.0 + amplitude * (2.0 * PI * f0 * i as f64 * dt).sin())
            .collect();
        let s = linear_spectrum(&x, dt);
        let peak = s.iter().max_by(|a, b| a.1.total_cmp(&b.1)).unwrap();
        assert!((peak.0 - f0).abs() < 1e-9);
        assert!((peak.1 - amplitude * n as f64 * dt / 2.0).abs() < 1e-9);
        assert!(s[0].1.abs() < 1e-9, "the mean is removed");
    }

    #[test]
    fn the_parzen_window_has_unit_area_and_its_first_zero_at_two_over_u() {
        let b = 20.0;
        let df = 0.01;
        let area: f64 = (-20_000..=20_000)
            .map(|j| parzen_window(j as f64 * df, b) * df)
            .sum();
        assert!((area - 1.0).abs() < 1e-4, "area {area}");
        let u = 280.0 / (151.0 * b);
        assert!(parzen_window(2.0 / u, b) < 1e-30);
        // Equivalent bandwidth 1/∫W² equals b by construction of u = 280/(151 b).
        let square: f64 = (-20_000..=20_000)
            .map(|j| parzen_window(j as f64 * df, b).powi(2) * df)
            .sum();
        assert!(
            (1.0 / square - b).abs() < 1e-3 * b,
            "bandwidth {}",
            1.0 / square
        );
    }

    #[test]
    fn smoothing_keeps_a_flat_spectrum_and_spreads_a_line_over_the_bandwidth() {
        let flat: Vec<(f64, f64)> = (0..200).map(|k| (k as f64 * 2.0, 5.0)).collect();
        for (_, a) in parzen_smooth(&flat, 20.0) {
            assert!((a - 5.0).abs() < 1e-12);
        }
        let mut line = vec![0.0; 200];
        line[100] = 1.0;
        let spectrum: Vec<(f64, f64)> = line
            .iter()
            .enumerate()
            .map(|(k, &a)| (k as f64, a))
            .collect();
        let smooth = parzen_smooth(&spectrum, 20.0);
        let total: f64 = smooth.iter().map(|p| p.1).sum();
        assert!((total - 1.0).abs() < 1e-3, "area kept: {total}");
        assert!(smooth[100].1 < 0.1 && smooth[110].1 > 0.0);
        assert!(smooth[125].1 < 1e-3 * smooth[100].1 && smooth[150].1 == 0.0);
    }

    #[test]
    fn the_mobility_of_a_scaled_delayed_copy_is_the_scale() {
        let (n, dt) = (2048, 1e-4);
        let mut state = 12345u64;
        let force: Vec<f64> = (0..n)
            .map(|_| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect();
        let velocity: Vec<f64> = (0..n).map(|i| 2.5e-3 * force[(i + n - 37) % n]).collect();
        for (f, m) in mobility(&velocity, &force, dt, 20.0) {
            assert!((m - 2.5e-3).abs() < 1e-12 * 2.5e-3 + 1e-15, "{f} Hz: {m}");
        }
    }
}
