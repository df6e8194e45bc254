//! The World adds no physics: stepped through its stages it gives bit for bit what its
//! stepper gives alone; its stage counters cover every model; its failure check stops an
//! unstable step with the bound; a hook can halt a run; the step rule refuses an explicit step
//! above the bound and fits an automatic one to the end time.

mod common;

use qdem_core::{
    continuum::Material, error::CoreError, solvers::Verlet, step::Halt, step::Model,
    step::PostStep, step::Scheme, step::State, step::StepRequest, step::StepSettings,
    step::Stepper, world::World, Vec3,
};
use qdem_mesh::structured_box;

/// A viscoelastic cantilever under gravity and a ramped tip load.
fn cantilever() -> (State, Vec<Box<dyn Model>>) {
    let mesh = structured_box([0.0; 3], [1.2, 0.2, 0.2], [12, 2, 2]).unwrap();
    let material = Material {
        density: 2350.0,
        young: 30e9,
        poisson: 0.2,
        shear_viscosity: 1e3,
        bulk_viscosity: 1e3,
    };
    common::clamped_beam(&mesh, material, Vec3::new(0.0, 0.0, -2e4))
}

fn verlet(dt: Option<f64>, fit_to: Option<f64>) -> StepRequest {
    StepRequest {
        scheme: Scheme::Verlet,
        dt,
        safety: 0.9,
        local_damping: 0.0,
        adaptive: false,
        event_solve: Default::default(),
        implicit_default: None,
        fit_to,
    }
}

fn world(request: &StepRequest) -> World {
    let (state, models) = cantilever();
    let settings = StepSettings::resolve(request, &state, &models).unwrap();
    World::new(state, models, settings).unwrap()
}

fn bits(s: &State) -> Vec<u64> {
    s.position
        .iter()
        .chain(&s.velocity)
        .chain(&s.acceleration)
        .flat_map(|v| v.iter().map(|c| c.to_bits()))
        .collect()
}

#[test]
fn a_world_steps_bit_for_bit_as_its_stepper_alone() {
    let mut w = world(&verlet(None, None));
    w.initialize().unwrap();
    let (mut state, mut models) = cantilever();
    let mut stepper = Verlet::new(w.dt());
    stepper.initialize(&mut state, &mut models).unwrap();
    for _ in 0..300 {
        assert_eq!(w.step().unwrap(), None);
        stepper.step(&mut state, &mut models).unwrap();
    }
    assert!(
        state.displacement(state.len() - 1).norm() > 1e-7,
        "it moves"
    );
    assert_eq!(bits(&w.state), bits(&state));
    assert_eq!(w.steps_done(), 300);
}

#[test]
fn the_stage_counters_name_every_model_and_share_the_whole_step() {
    let mut w = world(&verlet(None, None));
    w.initialize().unwrap();
    for _ in 0..50 {
        w.step().unwrap();
    }
    let report = w.stage_report();
    let names: Vec<&str> = report.iter().map(|s| s.name.as_str()).collect();
    for expected in ["predict", "forces: beam", "integrate", "failure check"] {
        assert!(names.contains(&expected), "{expected} in {names:?}");
    }
    let shares: f64 = report.iter().map(|s| s.share).sum();
    assert!((shares - 1.0).abs() < 1e-12);
    assert_eq!(w.stages().steps(), 50);
}

#[test]
fn a_step_three_times_the_bound_is_stopped_by_the_failure_check_naming_the_bound() {
    let mut w = world(&verlet(None, None));
    let mut settings = w.settings().clone();
    settings.dt *= 3.0 / 0.9;
    w.set_settings(settings).unwrap();
    w.initialize().unwrap();
    let error = (1..=10_000)
        .find_map(|_| w.step().err())
        .expect("an unstable step must be caught");
    let CoreError::Unstable {
        step, dt, bound, ..
    } = &error
    else {
        panic!("expected an instability, got {error}")
    };
    assert!(
        *step > 1 && *dt > 2.9 * bound,
        "step {step}, dt {dt}, bound {bound}"
    );
    assert!(error.to_string().contains("the step is above the bound"));
}

/// Halts once the simulated time passes `at`.
struct Alarm {
    at: f64,
}

impl PostStep for Alarm {
    fn name(&self) -> &str {
        "alarm"
    }

    fn after_step(&mut self, state: &mut State, _models: &[Box<dyn Model>]) -> Option<Halt> {
        (state.time > self.at).then(|| Halt {
            hook: "alarm".into(),
            time: state.time,
            particle: 0,
            value: state.time,
        })
    }
}

#[test]
fn a_hook_halts_the_run_at_the_first_step_past_its_limit() {
    let mut w = world(&verlet(None, None));
    let at = 25.5 * w.dt();
    w.add_hook(Box::new(Alarm { at }));
    w.initialize().unwrap();
    let halted_at = (1..=100).find(|_| w.step().unwrap().is_some());
    assert_eq!(halted_at, Some(26));
    assert!(w.stage_report().iter().any(|s| s.name == "hook: alarm"));
}

#[test]
fn the_step_rule_refuses_an_explicit_step_above_the_bound_and_fits_an_automatic_one() {
    let (state, models) = cantilever();
    let auto = StepSettings::resolve(&verlet(None, Some(1e-3)), &state, &models).unwrap();
    let bound = auto.stable_dt.0;
    assert_eq!(auto.stable_dt.1, "beam");
    let steps = 1e-3 / auto.dt;
    assert!(
        (steps - steps.round()).abs() < 1e-9,
        "{steps} steps to t_end"
    );
    assert!(auto.dt <= 0.9 * bound && auto.dt > 0.85 * bound);
    let refused = StepSettings::resolve(&verlet(Some(1.01 * bound), None), &state, &models);
    assert!(matches!(refused, Err(CoreError::StepTooLarge { .. })));
    let implicit = StepRequest {
        scheme: Scheme::Newmark {
            beta: 0.25,
            gamma: 0.5,
        },
        ..verlet(Some(100.0 * bound), None)
    };
    let big = StepSettings::resolve(&implicit, &state, &models).unwrap();
    assert_eq!(big.dt, 100.0 * bound);
    assert!(big.is_implicit());
}
