//! `qdem check` of a `[run] start_from` stage estimates its contacts' step from the contacts
//! of the state it starts from: the incline's rigid block (`fixtures/contact/incline.toml`,
//! k_n = k_t = 1e7 N/m, starting 1 mm above the slope; its contacts damped at ζ = 0.9 here,
//! so that it lands without bouncing) is run until it slides on the slope, and a second
//! stage starts from its checkpoint. The lists of such a stage were built
//! only at its first step, so the check named "the 0 contacts present" and no one-contact
//! bound; now it counts the block's contacts with the slope, and the step above which one of
//! them alone is unstable is 2/ω of the block on one spring, ω² = k_n/m (a wall does not
//! move; the block's own turn is left out of that lower bound): 2 √(m/k_n).

mod common;

use common::{variant, TempDir};
use std::ffi::OsStr;
use std::path::Path;
use std::process::Command;

/// The slope's springs (N/m), normal and tangential alike (the fixture's).
const STIFFNESS: f64 = 1e7;

/// `qdem check SCENE`'s standard output; it must succeed.
fn check(scene: &Path) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_qdem"))
        .args([OsStr::new("check"), scene.as_os_str()])
        .env("CI", "1")
        .output()
        .expect("start the qdem binary");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "qdem check {} failed:\n{}\n{stdout}",
        scene.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// The number in `text` right after the first `before` (up to a space, comma or semicolon).
fn number_after(text: &str, before: &str) -> f64 {
    let at = text
        .find(before)
        .unwrap_or_else(|| panic!("no {before:?} in:\n{text}"));
    let rest = &text[at + before.len()..];
    let end = rest.find([' ', ',', ';']).unwrap_or(rest.len());
    rest[..end]
        .parse()
        .unwrap_or_else(|e| panic!("{:?} after {before:?}: {e}", &rest[..end]))
}

/// The contacts' step line of a check.
fn contact_line(stdout: &str) -> &str {
    stdout
        .lines()
        .find(|l| l.starts_with("step limit of the contacts:"))
        .unwrap_or_else(|| panic!("no contacts' step in:\n{stdout}"))
}

#[test]
fn a_start_from_stage_estimates_its_contact_step_from_the_contacts_it_starts_with() {
    let tmp = TempDir::new("start-from-check");
    // 40 ms: the block falls its 1 mm in 15 ms and then slides on the slope.
    let first = variant(
        "contact/incline.toml",
        &[
            ("t_end = 0.4", "t_end = 0.04"),
            ("damping_ratio = 0.05", "damping_ratio = 0.9"),
            ("vtu_every = 0.05", "checkpoint_every = 0.01"),
        ],
        &tmp,
    );
    let out = tmp.path().join("rested");
    common::run(&first, &out, 1);
    let checkpoint = out.join("checkpoint.qdc");
    assert!(checkpoint.exists(), "the first stage wrote no checkpoint");
    let start = format!(
        "probe_every = 1e-3\nstart_from = \"{}\"",
        checkpoint.display()
    );
    let stage_dir = TempDir::new("start-from-stage");
    let stage = variant(
        "contact/incline.toml",
        &[
            ("probe_every = 1e-3", &start),
            ("damping_ratio = 0.05", "damping_ratio = 0.9"),
        ],
        &stage_dir,
    );
    let stdout = check(&stage);
    let line = contact_line(&stdout);
    let present = number_after(line, "estimated from the ");
    assert!(
        present >= 3.0,
        "a block resting on a plane touches it with at least 3 spheres: {line}"
    );
    let body = stdout
        .lines()
        .find(|l| l.starts_with("body `block`"))
        .expect("the block's line");
    let mass = number_after(body, "mass ");
    let alone = 2.0 * (mass / STIFFNESS).sqrt();
    let refused = number_after(line, "a step above ");
    assert!(
        (refused - alone).abs() <= 1e-3 * alone,
        "one contact alone is unstable above 2 sqrt(m/k) = {alone:.4e} s (m = {mass} kg), \
         the check says {refused:.4e} s: {line}"
    );
}
