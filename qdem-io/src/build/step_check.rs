//! The time step a built run will take, checked before its first step (by `qdem check` and
//! `qdem run` alike): a step that is not a positive normal number cannot advance the time
//! (`dt = "auto"` gives one when the stable bound h·√(ρ/E) underflows, e.g. density 1e-295 or
//! young 1e308), and a run of more than 2⁵³ steps cannot count its time: from t ≈ 2·dt/ε on,
//! t + dt rounds back to t and the run would loop at one time.

use super::{BuildError, Simulation};
use crate::scene::TimeStep;

/// The most steps a run may take: 2⁵³, the last step count whose times `n·dt` are distinct
/// doubles.
pub const MAX_STEPS: f64 = 9_007_199_254_740_992.0;

/// Refuses `sim`'s step when it is zero, subnormal or not finite, or when it takes more than
/// [`MAX_STEPS`] to reach `t_end`, naming the step, where it came from and the fix.
pub(crate) fn check_step(sim: &Simulation) -> Result<(), BuildError> {
    let dt = sim.world.dt();
    let t_end = sim.scene.run.t_end;
    let refuse = |message: String| {
        Err(BuildError::Step {
            scene: sim.scene.path.clone(),
            message,
        })
    };
    if !(dt.is_finite() && dt >= f64::MIN_POSITIVE) {
        let (source, fix) = source_and_fix(sim);
        return refuse(format!(
            "the time step dt = {dt:e} s ({source}) is zero, subnormal or not finite, so the \
             run cannot advance its time; fix: {fix}"
        ));
    }
    let steps = t_end / dt;
    // An infinite count (t_end / dt overflowed) is above the limit too.
    if steps > MAX_STEPS {
        let stall = 2.0 * dt / f64::EPSILON;
        let (source, _) = source_and_fix(sim);
        return refuse(format!(
            "t_end = {t_end:e} s at dt = {dt:.4e} s ({source}) is {steps:.3e} steps, more than \
             2^53 = {MAX_STEPS:.4e}: from t = {stall:.3e} s on, t + dt == t and the run would \
             stop advancing; fix: give a shorter t_end or a larger dt (at least {:.3e} s)",
            t_end / MAX_STEPS
        ));
    }
    Ok(())
}

/// Where `sim`'s step came from (the key that sets it), and what to change when it vanishes.
fn source_and_fix(sim: &Simulation) -> (String, String) {
    let run = &sim.scene.run;
    if let Some(f) = sim.scene.bonded.as_ref().and_then(|b| b.critical_fraction) {
        return (
            format!("from [bonded] critical_fraction = {f} times the bonds' critical step"),
            "check the [bonded] material's density and young, or give a larger \
             critical_fraction"
                .to_string(),
        );
    }
    if let TimeStep::Fixed(_) = run.dt {
        return (
            "as given in [run] dt".to_string(),
            "give [run] dt = \"auto\" or a step near the stable one `qdem check` prints"
                .to_string(),
        );
    }
    let (bound, limiter) = &sim.world.settings().stable_dt;
    let source = format!(
        "from dt = \"auto\": dt_safety {} times the stable bound {bound:.4e} s set by \
         `{limiter}`{}",
        run.dt_safety,
        limiter_material(sim, limiter)
    );
    let fix = "check the materials' density and young (the stable step is the mesh size times \
               sqrt(density / young): a density of 1e-295 kg/m^3 or a young of 1e308 Pa makes \
               it vanish), or give dt in seconds"
        .to_string();
    (source, fix)
}

/// `, whose material … has density … and young …` for the body `limiter`, if it is one.
fn limiter_material(sim: &Simulation, limiter: &str) -> String {
    let material = sim
        .scene
        .bodies
        .iter()
        .position(|b| b.name == limiter)
        .and_then(|i| sim.scene.refs().body_materials.get(i))
        .map(|&m| &sim.scene.materials[m]);
    match material {
        Some(m) => format!(
            ", whose material `{}` has density {:e} kg/m^3 and young {:e} Pa",
            m.name, m.density, m.young
        ),
        None => String::new(),
    }
}
