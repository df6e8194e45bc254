//! Building a scene's `[bonded]` body (paper 001 §5): the packing of its rectangle, the
//! [`BondedParticles`] model with seeded strengths, the supports and the top-row line load.
//!
//! Supports act on the end lines of the full rows (the particles at the smallest and largest
//! x): held vertically; the one nearest mid-height of the left end (and for `pinned` of the
//! right end too) held horizontally. Holding the staggered particles of the other rows as well
//! would clamp the ends partly. The load is the line load times the body's width, shared
//! equally by the particles of the top row (all equally spaced), rising linearly over
//! `load_ramp` seconds.
//!
//! The step: `critical_fraction` × ∆t_crit of Eq. 28 when given, else `[run] dt` as for any
//! scene; an explicit step is always checked against the rigorous bound
//! ([`qdem_core::step::Model::stable_dt`]), and a `critical_fraction` whose step is above it is
//! refused naming that key (not `[run] dt`, which it replaces). The world watches the body for collapse
//! ([`CollapseWatch`]).

use crate::build::{nearest_particle_in, step_request, BuildError, Simulation};
use crate::scene::{Bonded, Material, PackingName, Scene, Supports, TimeStep};
use qdem_contact::{
    BondSettings, BondedMaterial, BondedParticles, CollapseWatch, ContactError, Packing,
    PackingKind, UnbondedLaw,
};
use qdem_core::{
    error::CoreError, loads::NodalLoad, loads::TimeFunction, step::Dofs, step::Model, step::State,
    step::StepRequest, step::StepSettings, world::World, Vec3,
};

/// A bonded run ends early once a particle has moved this many particle spacings: its linear
/// bonds and contacts are meaningless beyond (the body has collapsed or come apart).
const COLLAPSE_SPACINGS: f64 = 0.5;

/// Builds the simulation of a scene whose body is `[bonded]`, of `material`.
pub(crate) fn build_bonded(
    scene: Scene,
    bonded: &Bonded,
    material: &Material,
) -> Result<Simulation, BuildError> {
    let contact = |source| BuildError::Contact {
        scene: scene.path.clone(),
        source: Box::new(source),
    };
    let kind = match bonded.packing {
        PackingName::Regular => PackingKind::Regular,
        PackingName::Random => PackingKind::Random {
            jitter: bonded.jitter,
            seed: bonded.packing_seed,
        },
    };
    // A hexagonal packing of pitch h holds one particle per (√3/2)·h² of the rectangle.
    let [width, height] = bonded.size;
    let h = bonded.element_size;
    super::memory::check(
        &scene.path,
        format!("[bonded] size = [{width:e}, {height:e}] m with element_size = {h:e} m"),
        (width * height / (h * h * 3f64.sqrt() / 2.0), 0.0),
        "give a smaller size or a larger element_size",
    )?;
    let packing = Packing::rectangle(bonded.origin, bonded.size, bonded.element_size, kind)
        .ok_or_else(|| {
            contact(ContactError::TooCoarse {
                body: bonded.name.clone(),
                size: bonded.size,
                element_size: bonded.element_size,
            })
        })?;
    let (bond_material, settings) = bond_settings(bonded, material);
    let (mut state, model) =
        BondedParticles::from_packing(&bonded.name, &packing, &bond_material, settings)
            .map_err(contact)?;
    hold(&mut state, &packing, bonded.supports);
    let critical = model.initial_critical_step();
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(model)];
    if bonded.top_load > 0.0 {
        models.push(Box::new(top_load(&packing, bonded)));
    }
    let core = |source| BuildError::Core {
        scene: scene.path.clone(),
        source,
    };
    let request = bonded_step(&scene, bonded, critical);
    let settings = StepSettings::resolve(&request, &state, &models).map_err(|source| {
        match (bonded.critical_fraction, source) {
            (Some(fraction), CoreError::StepTooLarge { dt, bound, limiter }) => {
                BuildError::CriticalFraction {
                    scene: scene.path.clone(),
                    fraction,
                    critical,
                    dt,
                    bound,
                    limiter,
                }
            }
            (_, source) => core(source),
        }
    })?;
    let probes = scene
        .probes
        .iter()
        .map(|p| {
            let at = Vec3::from(p.point.expect("validated: a probe on a body has a point"));
            nearest_particle_in(&state, 0..state.len(), at, &p.name)
        })
        .collect();
    let mut world = World::new(state, models, settings).map_err(core)?;
    let body = world.model::<BondedParticles>().expect("built above");
    world.add_hook(Box::new(CollapseWatch::for_body(body, COLLAPSE_SPACINGS)));
    let warnings = super::ineffective_event_solve(&scene).into_iter().collect();
    Ok(Simulation {
        scene,
        world,
        bodies: Vec::new(),
        probes,
        regions: Vec::new(),
        warnings,
        granular: None,
        ballast: None,
        fix_particles: Vec::new(),
        fix_frames: Vec::new(),
    })
}

/// The bonds' material (`material` with the body's thickness, damping and strengths) and the
/// settings of its unbonded contacts.
fn bond_settings(bonded: &Bonded, material: &Material) -> (BondedMaterial, BondSettings) {
    let bond_material = BondedMaterial {
        density: material.density,
        young: material.young,
        poisson: material.poisson,
        thickness: bonded.thickness,
        damping_ratio: bonded.damping_ratio,
        strength_mean: bonded.strength_mean,
        strength_std: bonded.strength_std,
        seed: bonded.strength_seed,
    };
    let settings = BondSettings {
        contact: UnbondedLaw {
            shear_ratio: bonded.contact_shear_ratio,
            friction: bonded.friction,
            damping_ratio: bonded.contact_damping_ratio,
        },
        tolerance: bonded.tolerance,
    };
    (bond_material, settings)
}

/// The end lines of full rows held vertically, a mid-height particle (or two) horizontally.
fn hold(state: &mut State, packing: &Packing, supports: Supports) {
    if supports == Supports::None {
        return;
    }
    let c = &packing.centers;
    let tol = 0.1 * packing.spacing;
    let (x_min, x_max) = c
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p[0]), b.max(p[0])));
    let y_mid = 0.5 * c.iter().fold(f64::MAX, |a, p| a.min(p[1]))
        + 0.5 * c.iter().fold(f64::MIN, |a, p| a.max(p[1]));
    let line = |x: f64| -> Vec<usize> {
        (0..c.len())
            .filter(|&p| (c[p][0] - x).abs() < tol)
            .collect()
    };
    let (left, right) = (line(x_min), line(x_max));
    let y = Dofs::parse("y").expect("valid");
    for &p in left.iter().chain(&right) {
        state.fix(p, y);
    }
    let middle = |ids: &[usize]| {
        *ids.iter()
            .min_by(|&&a, &&b| (c[a][1] - y_mid).abs().total_cmp(&(c[b][1] - y_mid).abs()))
            .expect("a lattice has at least two rows")
    };
    let x = Dofs::parse("x").expect("valid");
    state.fix(middle(&left), x);
    if supports == Supports::Pinned {
        state.fix(middle(&right), x);
    }
}

/// The line load on the top row.
fn top_load(packing: &Packing, bonded: &Bonded) -> NodalLoad {
    let c = &packing.centers;
    let top = c.iter().fold(f64::MIN, |a, p| a.max(p[1]));
    let particles = (0..c.len())
        .filter(|&p| (c[p][1] - top).abs() < 1e-9 * packing.spacing)
        .map(|p| p as u32)
        .collect();
    let total = Vec3::new(0.0, -bonded.top_load * bonded.size[0], 0.0);
    let factor = if bonded.load_ramp > 0.0 {
        TimeFunction::new(vec![(0.0, 0.0), (bonded.load_ramp, 1.0)]).expect("increasing times")
    } else {
        TimeFunction::constant(1.0)
    };
    NodalLoad::new("top_load", particles, total, factor)
}

/// The step: `critical_fraction` × Eq. 28's ∆t_crit (`critical`), or `[run] dt` (explicit
/// steps are refused above the rigorous bound; implicit runs must give one, which validation
/// checks), kept as it is rather than fitted to t_end.
fn bonded_step(scene: &Scene, bonded: &Bonded, critical: f64) -> StepRequest {
    let dt = match (bonded.critical_fraction, scene.run.dt) {
        (Some(f), _) => Some(f * critical),
        (None, TimeStep::Fixed(dt)) => Some(dt),
        (None, TimeStep::Auto) => None,
    };
    StepRequest {
        dt,
        implicit_default: None,
        fit_to: None,
        ..step_request(scene)
    }
}
