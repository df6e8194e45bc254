//! A one-line progress display on stderr (simulated time, steps/s, ETA), shown only when
//! stderr is a terminal and the `CI` variable is unset.

use qdem_io::runner::Progress;
use std::io::{IsTerminal, Write};

/// Whether progress should be drawn.
pub fn enabled() -> bool {
    std::io::stderr().is_terminal() && std::env::var_os("CI").is_none()
}

/// Redraws the progress line.
pub fn draw(p: &Progress, t_end: f64) {
    let percent = 100.0 * p.step as f64 / p.steps.max(1) as f64;
    let mut err = std::io::stderr().lock();
    let _ = write!(
        err,
        "\r  t = {:.4} / {:.4} s  {:5.1}%  {:.3e} steps/s  ETA {}   ",
        p.time,
        t_end,
        percent,
        p.steps_per_second,
        clock(p.eta_seconds)
    );
    let _ = err.flush();
}

/// Ends the progress line.
pub fn finish() {
    eprintln!();
}

/// Seconds as h:mm:ss.
pub fn clock(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    format!("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
}
