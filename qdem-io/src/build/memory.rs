//! The memory a scene needs, estimated before its particles are allocated, so that a count
//! far beyond the machine (`[granular] count = 1e12`, a `[bonded]` rectangle of 10³⁰⁰
//! elements) is refused with the figure instead of aborting the process when the allocation
//! fails.
//!
//! The estimate counts per particle what a run keeps: the state's vectors (reference and
//! current position, velocity, acceleration, force, mass, fixes: about 200 bytes), a contact
//! sphere's arrays (about 100 bytes) and its share of the candidate lists (about six pairs of
//! about 110 bytes each), rounded up to [`BYTES_PER_PARTICLE`]; and per tetrahedron its
//! nodes, reference shape and stress scratch ([`BYTES_PER_TET`]). It is an order of
//! magnitude, which is what the refusal needs: the counts it stops are thousands of times
//! over the limit. The limit is the memory this process may use ([`memory_limit`]): the
//! machine's (`MemTotal` of `/proc/meminfo`), or less where its control group
//! (`memory.max`) or its address-space limit (`ulimit -v`) allows less; where none of them
//! can be read only a count whose bytes do not fit in the address space is refused.

use super::BuildError;
use std::path::Path;

/// Bytes a run keeps per particle with a contact sphere (see the module docs).
pub const BYTES_PER_PARTICLE: f64 = 1024.0;

/// Bytes a run keeps per tetrahedron (see the module docs).
pub const BYTES_PER_TET: f64 = 512.0;

/// The machine's memory in bytes (`MemTotal` of `/proc/meminfo`), `None` where it cannot be
/// read.
pub fn machine_memory() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// The bytes a run of `particles` particles and `tets` tetrahedra keeps (see the module
/// docs).
#[must_use]
pub fn estimate(particles: f64, tets: f64) -> f64 {
    particles * BYTES_PER_PARTICLE + tets * BYTES_PER_TET
}

/// `bytes` as a number with its binary unit (`5.6e4 TiB`, `12.3 MiB`).
#[must_use]
pub fn human(bytes: f64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut value = bytes;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if value >= 1e4 {
        format!("{value:.2e} {}", UNITS[unit])
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

/// The memory this process may use, in bytes, and what sets it (see the module docs): the
/// least of the machine's memory, its control group's `memory.max` and its address-space
/// limit; the address space where none can be read.
#[must_use]
pub fn memory_limit() -> (f64, String) {
    let mut limits: Vec<(f64, String)> = Vec::new();
    if let Some(bytes) = machine_memory() {
        limits.push((bytes, format!("this machine's {}", human(bytes))));
    }
    if let Some(bytes) = cgroup_limit() {
        limits.push((
            bytes,
            format!("the {} its control group allows", human(bytes)),
        ));
    }
    if let Some(bytes) = address_space_limit() {
        limits.push((
            bytes,
            format!("the {} address space allowed (ulimit -v)", human(bytes)),
        ));
    }
    limits
        .into_iter()
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap_or_else(|| (isize::MAX as f64, "the address space".to_string()))
}

/// The memory limit of this process's control group (cgroup v2 `memory.max`), `None` where
/// there is none or it cannot be read.
fn cgroup_limit() -> Option<f64> {
    let groups = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let path = groups.lines().find_map(|l| l.strip_prefix("0::"))?;
    let file = Path::new("/sys/fs/cgroup")
        .join(path.trim_start_matches('/'))
        .join("memory.max");
    std::fs::read_to_string(file).ok()?.trim().parse().ok()
}

/// The address-space limit of this process (`Max address space` of `/proc/self/limits`,
/// `ulimit -v`), `None` where it is unlimited or cannot be read.
fn address_space_limit() -> Option<f64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    line.split_whitespace().nth(3)?.parse().ok()
}

/// Why `what`, which needs `bytes`, cannot be held, when that is more than the memory this
/// process may use ([`memory_limit`]) or than the address space; `fix`: what to change.
#[must_use]
pub fn refusal(what: &str, bytes: f64, fix: &str) -> Option<String> {
    let (limit, which) = memory_limit();
    if bytes.is_finite() && bytes <= limit {
        return None;
    }
    Some(format!(
        "{what} would need about {} of memory, more than {which}; fix: {fix}",
        human(bytes)
    ))
}

/// Refuses `what` (e.g. "`[granular]` count = 1000000000000 stones of up to 4 spheres")
/// when its `particles` and `tets` need more memory than this process may use ([`refusal`]);
/// `fix` says what to change.
pub(crate) fn check(
    scene: &Path,
    what: String,
    (particles, tets): (f64, f64),
    fix: &'static str,
) -> Result<(), BuildError> {
    let what = format!("{what}: {particles:.3e} particles");
    match refusal(&what, estimate(particles, tets), fix) {
        None => Ok(()),
        Some(message) => Err(BuildError::Memory {
            scene: scene.to_path_buf(),
            message,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_are_shown_in_binary_units() {
        assert_eq!(human(512.0), "512.0 B");
        assert_eq!(human(3.0 * 1024.0 * 1024.0), "3.0 MiB");
        assert_eq!(human(5.6e16), "5.09e4 TiB");
    }

    #[test]
    fn a_count_beyond_the_address_space_is_refused_whatever_the_machine() {
        let refused = check(Path::new("s.toml"), "x".into(), (1e300, 0.0), "fix it");
        assert!(matches!(refused, Err(BuildError::Memory { .. })));
        assert!(check(Path::new("s.toml"), "x".into(), (1e3, 1e3), "fix it").is_ok());
    }
}
