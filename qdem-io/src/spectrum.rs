//! Spectral analysis of probe signals: the dominant frequency of a sampled record from its
//! FFT (paper 000 §3.1 reads the cantilever's first bending frequency off an FFT).
//!
//! The record's mean is removed, a Hann window applied and the record zero-padded to 16× its
//! length before the FFT; the peak bin is refined by parabolic interpolation of the log
//! magnitude (Gaussian interpolation), which is exact for a Gaussian-shaped peak and good to a
//! small fraction of a bin for the Hann main lobe.

use rustfft::{num_complex::Complex, FftPlanner};

/// Dominant non-zero frequency (Hz) of `samples` taken every `dt` seconds; `None` for fewer
/// than 8 samples or a constant record.
pub fn dominant_frequency(samples: &[f64], dt: f64) -> Option<f64> {
    let n = samples.len();
    if n < 8 {
        return None;
    }
    let mean = samples.iter().sum::<f64>() / n as f64;
    let padded = (16 * n).next_power_of_two();
    let mut buffer: Vec<Complex<f64>> = samples
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / (n - 1) as f64).cos();
            Complex::new((s - mean) * w, 0.0)
        })
        .chain(std::iter::repeat(Complex::new(0.0, 0.0)))
        .take(padded)
        .collect();
    FftPlanner::new()
        .plan_fft_forward(padded)
        .process(&mut buffer);
    let magnitude: Vec<f64> = buffer[..padded / 2].iter().map(|c| c.norm()).collect();
    let (peak, &largest) = magnitude
        .iter()
        .enumerate()
        .skip(1)
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    if largest <= 0.0 || peak + 1 >= magnitude.len() {
        return None;
    }
    let (a, b, c) = (
        magnitude[peak - 1].ln(),
        largest.ln(),
        magnitude[peak + 1].ln(),
    );
    let shift = 0.5 * (a - c) / (a - 2.0 * b + c);
    Some((peak as f64 + shift) / (padded as f64 * dt))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_sine_between_bins_to_a_small_fraction_of_a_bin() {
        let dt = 1e-4;
        let f = 26.874;
        // One second of signal: the raw bin width is 1 Hz.
        let s: Vec<f64> = (0..10_000)
            .map(|i| 3.0 + (2.0 * std::f64::consts::PI * f * i as f64 * dt).sin())
            .collect();
        let got = dominant_frequency(&s, dt).unwrap();
        assert!((got - f).abs() < 0.01, "{got}");
    }
}
