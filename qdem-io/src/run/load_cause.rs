//! The load behind an instability: when a run becomes unstable, a load that no step can
//! resolve is named instead of the step. A deformable body of density ρ, Young's modulus E and
//! extent L can give its mass an acceleration of about E / (ρ L) at a strain of 1 (the stress
//! E over the mass ρ L per unit area of its cross-section); a load that asks for more inverts
//! its tetrahedra at any dt, and a smaller step only reaches the same state in more steps.
//! Three loads are compared with it, each a ratio that is a strain:
//!
//! - `[run] gravity` g: ρ g L / E, the strain of the body's own weight over its extent;
//! - a body's `angular_velocity` ω: ρ ω² L² / (8 E), the stress at the centre of a rod of
//!   length L spinning about it (ρ ω² L² / 8) over E;
//! - a body's `velocity` v: v / √(E / ρ), the strain an impact at v sends through it.
//!
//! Each is a lower bound of the strain the load causes where it is largest (a bending or a
//! held end strains more), so a ratio above [`CRUSHING_STRAIN`] names the load as the cause
//! with certainty; below it the step's advice stands. Gravity 1e7 m/s² on the paper's
//! cantilever (2.4 m of concrete) gives 1.25 and inverts a tetrahedron at step 137.

use crate::build::{BodyKind, Simulation};
use crate::scene::Material;
use qdem_core::Vec3;

/// A load whose strain ratio is above this inverts a tetrahedron at any step.
pub const CRUSHING_STRAIN: f64 = 1.0;

/// A load of one body, the key that sets it and its strain ratio.
struct Overload {
    /// The key and the load's size, e.g. `[run] gravity (1.000e12 m/s^2)`.
    key: String,
    /// The body.
    body: String,
    /// The strain ratio (module docs).
    strain: f64,
    /// How the ratio is made, with the body's numbers.
    how: String,
    /// What the user should check.
    fix: &'static str,
}

/// The advice for an instability of `sim` caused by a load that no step resolves (the
/// largest ratio above [`CRUSHING_STRAIN`] over the deformable `[[body]]`s), or `None`.
pub(crate) fn load_cause(sim: &Simulation) -> Option<String> {
    let worst = overloads(sim)
        .filter(|o| o.strain > CRUSHING_STRAIN)
        .max_by(|a, b| a.strain.total_cmp(&b.strain))?;
    Some(format!(
        "the load, not the step, is the cause: {} gives body `{}` a strain of {:.3e} ({}), \
         more than its tetrahedra can carry (a strain of {CRUSHING_STRAIN} inverts one) at any \
         dt, so a smaller step does not help; fix: {}",
        worst.key, worst.body, worst.strain, worst.how, worst.fix
    ))
}

/// The loads of every deformable `[[body]]`.
fn overloads(sim: &Simulation) -> impl Iterator<Item = Overload> + '_ {
    let scene = &sim.scene;
    let gravity = Vec3::from(scene.run.gravity).norm();
    sim.bodies
        .iter()
        .zip(&scene.bodies)
        .zip(&scene.refs().body_materials)
        .filter(|((info, _), _)| matches!(info.kind, BodyKind::Deformable { .. }))
        .flat_map(move |((info, body), &m)| {
            let material = &scene.materials[m];
            let extent = extent(sim, info.particles.clone());
            let (spin, speed) = (
                Vec3::from(body.angular_velocity).norm(),
                Vec3::from(body.velocity).norm(),
            );
            let name = &body.name;
            [
                weight(material, extent, gravity),
                spin_load(material, extent, spin, name),
                impact(material, speed, name),
            ]
            .into_iter()
            .map(move |(key, strain, how, fix)| Overload {
                key,
                body: name.clone(),
                strain,
                how,
                fix,
            })
        })
}

/// A load's key, strain ratio, how it is made and what to check.
type Load = (String, f64, String, &'static str);

/// Gravity's strain ratio ρ g L / E.
fn weight(m: &Material, extent: f64, g: f64) -> Load {
    (
        format!("[run] gravity ({g:.3e} m/s^2)"),
        m.density * g * extent / m.young,
        format!(
            "density x |gravity| x extent / young = {:e} kg/m^3 x {g:.3e} m/s^2 x {extent:.3e} \
             m / {:e} Pa",
            m.density, m.young
        ),
        "check [run] gravity, in m/s^2 (9.81 on Earth)",
    )
}

/// A spin's strain ratio ρ ω² L² / (8 E).
fn spin_load(m: &Material, extent: f64, spin: f64, body: &str) -> Load {
    (
        format!("[[body]] {body:?} angular_velocity ({spin:.3e} rad/s)"),
        m.density * spin * spin * extent * extent / (8.0 * m.young),
        format!(
            "density x angular_velocity^2 x extent^2 / (8 young) = {:e} kg/m^3 x ({spin:.3e} \
             rad/s)^2 x ({extent:.3e} m)^2 / (8 x {:e} Pa)",
            m.density, m.young
        ),
        "check the body's angular_velocity, in rad/s (1 turn/s is 6.28 rad/s)",
    )
}

/// An initial speed's strain ratio v / √(E / ρ).
fn impact(m: &Material, speed: f64, body: &str) -> Load {
    let wave = (m.young / m.density).sqrt();
    (
        format!("[[body]] {body:?} velocity ({speed:.3e} m/s)"),
        speed / wave,
        format!("speed / wave speed sqrt(young / density) = {speed:.3e} / {wave:.3e} m/s"),
        "check the body's velocity, in m/s",
    )
}

/// The largest side of the box around the reference positions of `particles` (m).
fn extent(sim: &Simulation, particles: std::ops::Range<usize>) -> f64 {
    let positions = &sim.world.state.reference[particles];
    let Some(first) = positions.first() else {
        return 0.0;
    };
    let (lo, hi) = positions
        .iter()
        .fold((*first, *first), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    (hi - lo).max()
}
