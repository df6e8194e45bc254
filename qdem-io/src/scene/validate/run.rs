//! `[run]`: a positive end time, time step and probe interval, finite gravity, `dt_safety` in
//! (0, 1], and Newmark's β and γ in range, γ ≥ ½ (below it the scheme's numerical damping is
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
    }
}

/// `[run]` with `integrator = "newmark"`: β and γ in range, and a `dt` when the step is implicit
/// (a `[bonded]` body's `critical_fraction` gives one too).
fn newmark(c: &mut Checker<'_>, raw: &RawScene) {
    let run = &raw.run;
    let (beta, gamma) = (run.beta, run.gamma);
    if c.finite(&["run", "beta"], "[run]", "beta", &[beta, gamma])
        && !((0.0..=1.0).contains(&gamma) && (0.0..=0.5).contains(&beta))
    {
        c.error(
            &["run", "beta"],
            format!(
                "[run]: beta = {beta}, gamma = {gamma}: Newmark needs 0 <= gamma <= 1 and \
                 0 <= 2 beta <= 1 (paper 001 Eq. 16); e.g. beta = 0.25, gamma = 0.5"
            ),
        );
    } else if gamma < 0.5 {
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
