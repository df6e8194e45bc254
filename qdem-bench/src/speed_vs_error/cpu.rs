//! The speed of a study run: the CPU seconds the process spent (user + system, all its
//! threads), read from `/proc/self/stat` before and after the run. CPU time, not wall time,
//! because the study's machine is shared: other jobs lengthen a run's wall time but not the
//! CPU time it takes (beyond what they cost it in caches). Counted in clock ticks
//! (`utime` + `stime`, fields 14 and 15, of 1/100 s on Linux).

use super::StudyError;
use std::path::PathBuf;

const STAT: &str = "/proc/self/stat";
/// Clock ticks per second of `/proc/self/stat` (USER_HZ, 100 on every Linux architecture).
const TICKS_PER_SECOND: f64 = 100.0;

/// CPU seconds (user + system, all threads) this process has used so far.
///
/// ```
/// let before = qdem_bench::speed_vs_error::cpu_seconds().unwrap();
/// let spin: f64 = (0..2_000_000).map(|i| (i as f64).sqrt()).sum();
/// assert!(spin > 0.0);
/// assert!(qdem_bench::speed_vs_error::cpu_seconds().unwrap() >= before);
/// ```
pub fn cpu_seconds() -> Result<f64, StudyError> {
    let problem = |message: String| StudyError::Probes {
        path: PathBuf::from(STAT),
        message,
    };
    let text = std::fs::read_to_string(STAT)
        .map_err(|e| problem(format!("{e}: the CPU time is read from Linux's /proc")))?;
    // The command name (field 2) is in parentheses and may hold spaces: count after it.
    let after = text
        .rfind(')')
        .map(|i| &text[i + 1..])
        .ok_or_else(|| problem("no `)` after the command name".into()))?;
    let fields: Vec<&str> = after.split_whitespace().collect();
    // Fields 14 and 15 of the whole line are the 12th and 13th after the name.
    let tick = |i: usize| -> Result<f64, StudyError> {
        fields
            .get(i)
            .and_then(|v| v.parse::<u64>().ok())
            .map(|v| v as f64 / TICKS_PER_SECOND)
            .ok_or_else(|| problem(format!("field {} is not a tick count", i + 3)))
    };
    Ok(tick(11)? + tick(12)?)
}

/// Runs `work` and returns its result with the CPU seconds it took.
pub fn timed<T>(work: impl FnOnce() -> Result<T, StudyError>) -> Result<(T, f64), StudyError> {
    let start = cpu_seconds()?;
    let value = work()?;
    Ok((value, cpu_seconds()? - start))
}
