//! Spectral analysis of probe signals: the amplitude spectrum of a sampled record and its
//! dominant frequency (paper 000 §3.1 reads the cantilever's first bending frequency off an
//! FFT).
//!
//! The record's mean is removed, a Hann window applied and the record zero-padded to 16× its
//! length before the FFT; the peak bin is refined by parabolic interpolation of the log
//! magnitude (Gaussian interpolation), which is exact for a Gaussian-shaped peak and good to a
//! small fraction of a bin for the Hann main lobe.

use rustfft::{num_complex::Complex, FftPlanner};

/// One-sided amplitude spectrum (frequency in Hz, amplitude in the record's unit) of `samples`
/// taken every `dt` seconds, Hann-windowed and zero-padded 16×; the amplitude of a pure sine
/// reads as its amplitude at the peak. Empty for fewer than 8 samples.
pub fn amplitude_spectrum(samples: &[f64], dt: f64) -> Vec<(f64, f64)> {
    let n = samples.len();
    if n < 8 {
        return Vec::new();
    }
    let mean = samples.iter().sum::<f64>() / n as f64;
    let padded = (16 * n).next_power_of_two();
    let window =
        |i: usize| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / (n - 1) as f64).cos();
    let mut buffer: Vec<Complex<f64>> = samples
        .iter()
        .enumerate()
        .map(|(i, &s)| Complex::new((s - mean) * window(i), 0.0))
        .chain(std::iter::repeat(Complex::new(0.0, 0.0)))
        .take(padded)
        .collect();
    FftPlanner::new()
        .plan_fft_forward(padded)
        .process(&mut buffer);
    // The Hann window's coherent gain is 1/2: a sine of amplitude A peaks at A·n/4.
    let scale = 4.0 / n as f64;
    buffer[..padded / 2]
        .iter()
        .enumerate()
        .map(|(k, c)| (k as f64 / (padded as f64 * dt), c.norm() * scale))
        .collect()
}

/// Dominant non-zero frequency (Hz) of `samples` taken every `dt` seconds; `None` for fewer
/// than 8 samples or a constant record.
pub fn dominant_frequency(samples: &[f64], dt: f64) -> Option<f64> {
    let spectrum = amplitude_spectrum(samples, dt);
    let (peak, &(_, largest)) = spectrum
        .iter()
        .enumerate()
        .skip(1)
        .max_by(|a, b| a.1 .1.total_cmp(&b.1 .1))?;
    if largest <= 0.0 || peak + 1 >= spectrum.len() {
        return None;
    }
    let (a, b, c) = (
        spectrum[peak - 1].1.ln(),
        largest.ln(),
        spectrum[peak + 1].1.ln(),
    );
    let shift = 0.5 * (a - c) / (a - 2.0 * b + c);
    let bin = spectrum[1].0;
    Some((peak as f64 + shift) * bin)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sine(f: f64, amplitude: f64, dt: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| 3.0 + amplitude * (2.0 * std::f64::consts::PI * f * i as f64 * dt).sin())
            .collect()
    }

    #[test]
    fn finds_a_sine_between_bins_to_a_small_fraction_of_a_bin() {
        // One second of signal: the raw bin width is 1 Hz.
        let got = dominant_frequency(&sine(26.874, 1.0, 1e-4, 10_000), 1e-4).unwrap();
        assert!((got - 26.874).abs() < 0.01, "{got}");
    }

    #[test]
    fn a_sine_on_a_bin_reads_its_amplitude() {
        // 10 Hz over exactly 1 s lies on a bin; the Hann main lobe is flat enough there.
        let spectrum = amplitude_spectrum(&sine(10.0, 2.5, 1e-3, 1000), 1e-3);
        let peak = spectrum.iter().map(|p| p.1).fold(0.0, f64::max);
        assert!((peak / 2.5 - 1.0).abs() < 0.01, "{peak}");
    }
}
