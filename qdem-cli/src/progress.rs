//! A one-line progress display on stderr (simulated time, steps/s, ETA), shown only when
//! stderr is a terminal and the `CI` variable is unset; and, on the same terminals, the
//! seconds a set-up (a scene's build: a sample generated, meshes read) has taken once it takes
//! more than [`QUIET_SETUP`], so that a long one is not mistaken for a hang.

use qdem_io::runner::Progress;
use std::io::{IsTerminal, Write};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// How long a set-up runs before [`while_busy`] shows its seconds.
pub const QUIET_SETUP: Duration = Duration::from_secs(2);

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

/// Runs `work`, showing on a terminal (see [`enabled`]) `what` and the seconds it has taken,
/// redrawn every second, once it has taken more than [`QUIET_SETUP`]; the line is cleared when
/// it ends.
pub fn while_busy<T>(what: &str, work: impl FnOnce() -> T) -> T {
    if !enabled() {
        return work();
    }
    let (done, wait) = mpsc::channel::<()>();
    std::thread::scope(|s| {
        s.spawn(move || {
            let start = Instant::now();
            let mut shown = false;
            let mut timeout = QUIET_SETUP;
            while let Err(mpsc::RecvTimeoutError::Timeout) = wait.recv_timeout(timeout) {
                shown = true;
                timeout = Duration::from_secs(1);
                let seconds = start.elapsed().as_secs();
                let mut err = std::io::stderr().lock();
                let _ = write!(err, "\r  {what}: {}   ", clock(seconds as f64));
                let _ = err.flush();
            }
            if shown {
                eprint!("\r{:width$}\r", "", width = what.len() + 16);
            }
        });
        let result = work();
        drop(done);
        result
    })
}
