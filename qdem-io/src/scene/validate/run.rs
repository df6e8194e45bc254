//! `[run]`: a positive end time, time step (a normal number: a subnormal one cannot advance the
//! time) and probe interval, finite gravity, `dt_safety` in
//! (0, 1], and Newmark's β and γ finite and in range (given with another integrator they are
//! refused: they would do nothing), γ ≥ ½ (below it the scheme's numerical damping is
//! negative: paper 001 Eq. 16's amplification exceeds one) (with a `dt` an implicit step can
//! use); and
//! `[output]`: non-negative intervals.

use super::super::schema::{Integrator, RawScene, TimeStep};
use super::checker::Checker;

/// `[run]`: the time keys, gravity, and the integrator's parameters.
pub(super) fn run_table(c: &mut Checker<'_>, raw: &RawScene) {
    let run = &raw.run;
    c.positive(&["run", "t_end"], "[run]", "t_end", run.t_end, "seconds");
    if let TimeStep::Fixed(dt) = run.dt {
        c.positive(&["run", "dt"], "[run]", "dt", dt, "seconds, or \"auto\"");
        subnormal_step(c, dt);
    }
    c.finite(&["run", "gravity"], "[run]", "gravity", &run.gravity);
    if let Some(every) = run.probe_every {
        c.positive(
            &["run", "probe_every"],
            "[run]",
            "probe_every",
            every,
            "seconds",
        );
    }
    let safety = run.dt_safety;
    if c.finite(&["run", "dt_safety"], "[run]", "dt_safety", &[safety])
        && !(safety > 0.0 && safety <= 1.0)
    {
        c.error(
            &["run", "dt_safety"],
            format!(
                "[run]: dt_safety = {safety}: must be in (0, 1], the fraction of the stable time \
                 step used by dt = \"auto\"; e.g. 0.9"
            ),
        );
    }
    if run.integrator == Integrator::Newmark {
        newmark(c, raw);
    } else {
        newmark_keys_unused(c, raw);
    }
}

/// A `dt` above 0 but below the smallest normal double (2.2e-308 s, e.g. `dt = 1e-320`): a
/// step far too small to advance the time (`t_end / dt` steps, above 10^299 for any `t_end`
/// of a nanosecond or more).
fn subnormal_step(c: &mut Checker<'_>, dt: f64) {
    if dt > 0.0 && dt < f64::MIN_POSITIVE {
        c.error(
            &["run", "dt"],
            format!(
                "[run]: dt = {dt:e} s is subnormal (below {:.4e} s, the smallest normal \
                 double), far too small a step to advance the time; fix: give dt = \"auto\" \
                 (the stable step, which `qdem check` prints) or a dt of that order",
                f64::MIN_POSITIVE
            ),
        );
    }
}

/// `beta` and `gamma` written in a scene whose integrator is not Newmark's: they would do
/// nothing, and the scene is most likely meant to be a Newmark run.
fn newmark_keys_unused(c: &mut Checker<'_>, raw: &RawScene) {
    let integrator = raw.run.integrator.name();
    let default = match raw.run.integrator {
        Integrator::Verlet => " (the default)",
        _ => "",
    };
    for key in ["beta", "gamma"] {
        if c.given(&["run", key]) {
            c.error(
                &["run", key],
                format!(
                    "[run]: {key} is a parameter of integrator = \"newmark\" only; with \
                     integrator = \"{integrator}\"{default} it does nothing; fix: add \
                     integrator = \"newmark\" to [run] to step with Newmark, or remove {key}"
                ),
            );
        }
    }
}

/// `[run]` with `integrator = "newmark"`: β and γ finite (each named by itself) and in range,
/// and a `dt` when the step is implicit (a `[bonded]` body's `critical_fraction` gives one too).
fn newmark(c: &mut Checker<'_>, raw: &RawScene) {
    let run = &raw.run;
    let (beta, gamma) = (run.beta, run.gamma);
    // `&`, not `&&`: both are checked, each named by itself.
    let finite = c.finite(&["run", "beta"], "[run]", "beta", &[beta])
        & c.finite(&["run", "gamma"], "[run]", "gamma", &[gamma]);
    if finite && !((0.0..=1.0).contains(&gamma) && (0.0..=0.5).contains(&beta)) {
        c.error(
            &["run", "beta"],
            format!(
                "[run]: beta = {beta}, gamma = {gamma}: Newmark needs 0 <= gamma <= 1 and \
                 0 <= 2 beta <= 1 (paper 001 Eq. 16); e.g. beta = 0.25, gamma = 0.5"
            ),
        );
    } else if finite && gamma < 0.5 {
        c.error(
            &["run", "gamma"],
            format!(
                "[run]: gamma = {gamma} is below 1/2: Newmark's numerical damping is then \
                 negative, so every step amplifies the motion and the run diverges at any dt \
                 (an inverted tetrahedron or runaway energy, blamed on the step); fix: use \
                 gamma = 0.5 (no numerical damping), or gamma > 0.5 to damp the highest modes \
                 with beta >= (gamma + 0.5)^2 / 4"
            ),
        );
    }
    let fraction = raw.bonded.as_ref().and_then(|b| b.critical_fraction);
    if beta > 0.0 && run.dt == TimeStep::Auto && fraction.is_none() {
        c.error(
            &["run", "dt"],
            "[run]: implicit Newmark (beta > 0) has no stable-step bound to choose dt from: \
             give dt in seconds"
                .to_owned(),
        );
    }
}

/// `[output]`: non-negative VTU and checkpoint intervals.
pub(super) fn output_table(c: &mut Checker<'_>, raw: &RawScene) {
    c.non_negative(
        &["output", "vtu_every"],
        "[output]",
        "vtu_every",
        raw.output.vtu_every,
        "seconds",
    );
    c.non_negative(
        &["output", "checkpoint_every"],
        "[output]",
        "checkpoint_every",
        raw.output.checkpoint_every,
        "seconds",
    );
}
