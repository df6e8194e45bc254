//! Rigid or deformable, per stone set: a `[ballast]` judged by one representative per stone
//! shape, a `[granular]` sample by its heaviest stone.
//!
//! - **`[ballast]`**: the representative of a shape is its largest stone (its first mode is
//!   the shape's lowest, the frequency going as one over the scale), alone and free
//!   ([`super::body_modes::of_part`]); its dynamic share comes from the scene's loads and its
//!   contacts ([`super::excitation::of_stone`]). The set is judged by its most excited
//!   representative as a `[[body]]` is ([`super::rigidity`]): rigid at most
//!   [`NEGLIGIBLE_DYNAMICS`], deformable from [`DYNAMIC`], the scene's choice between. The
//!   step each way is the run's bound with the set of each kind, the scene built again with
//!   `rigid` turned: rigid stones' contacts act on whole stones, deformable ones' on vertex
//!   particles, and the stones' tetrahedra leave the step. The predicted speed-up is the ratio
//!   of the two steps: a rigid step skips the stones' kernel but carries their rigid-body
//!   passes, and measured 0.3 to 1.8 times a deformable one's cost on the reduced track
//!   (docs/speed-vs-error.md, "Modelling advice against runs"), so the speed-up is told
//!   within a factor of two. The steps are estimated from the contacts at the scene's start
//!   (a pour's lattice, or the bed a `start_from` continues).
//! - A rigid stone loses its Kelvin–Voigt damping, ζ = π f₁ τ at its first mode (τ = μ_D/G).
//!   Where ζ exceeds 1% and the contacts have no dashpots, rigid stones are advised with
//!   `[contact] damping_ratio` = ζ (rounded up to 0.01) in its place, and their step is the
//!   one with those dashpots: the 5 cm bed of docs/ballast.md failed from its second axle
//!   with undamped rigid stones and held with deformable ones and with rigid ones on
//!   ζ = 0.1 dashpots.
//! - `[contact] local_damping` acts on each particle's net force: on every node of a
//!   deformable stone, on the whole of a rigid one, so the two kinds dissipate differently
//!   and the advice says so (docs/ballast.md: the reduced track's bed formed rigid was half
//!   as embedded as the one formed deformable).
//! - **`[granular]`**: a clump of spheres has no mesh and is rigid. Its heaviest stone is
//!   taken as a sphere of its mass and radius a, whose lowest free mode is the torsional
//!   ℓ = 2 one, ω a/c_s = 2.5011 for any ν (Lamb 1882; the spheroidal ℓ = 2 mode is at
//!   2.62–2.66 for ν from 0.1 to 0.45), c_s = √(G/ρ). From [`DYNAMIC`] the stones' vibration
//!   matters and the advice is deformable stones: a `[ballast]` of meshes.

use super::body_modes::{self, BodyModes};
use super::excitation::{self, Excitation};
use super::{Advice, Topic, NEGLIGIBLE_DYNAMICS};
use crate::build::ballast::BallastInfo;
use crate::build::granular::GranularInfo;
use crate::build::Simulation;
use crate::scene::{Material, Scene};
use qdem_core::Vec3;
use std::f64::consts::PI;

/// The dynamic share from which a stone's vibration matters (as a `[[body]]`'s).
const DYNAMIC: f64 = 0.1;

/// ω a/c_s of a free elastic sphere's lowest mode, the torsional ℓ = 2 one: the root of
/// j₂(η) = η j₃(η) (Lamb 1882).
const SPHERE_LOWEST_MODE: f64 = 2.5011;

/// The advice for `sim`'s stone sets: its `[ballast]`, then its `[granular]`.
pub(super) fn advise(sim: &Simulation) -> Vec<Advice> {
    let mut advice = Vec::new();
    if let (Some(info), Some(i)) = (&sim.ballast, sim.scene.refs().ballast_material) {
        advice.push(ballast(sim, info, &sim.scene.materials[i]));
    }
    if let (Some(info), Some(i)) = (&sim.granular, sim.scene.refs().granular_material) {
        advice.extend(granular(sim, info, &sim.scene.materials[i]));
    }
    advice
}

/// One representative stone: its modes alone, its mass and size, and what excites it.
struct Representative {
    shape: usize,
    modes: BodyModes,
    excitation: Excitation,
}

/// The advice for the `[ballast]` set `info` of `material`.
fn ballast(sim: &Simulation, info: &BallastInfo, material: &Material) -> Advice {
    let rigid = sim.scene.ballast.as_ref().is_some_and(|b| b.rigid);
    let now = if rigid { "rigid" } else { "deformable" };
    let mut advice = Advice {
        subject: format!("[ballast] `{}`", info.name),
        topic: Topic::Rigidity,
        now: now.to_string(),
        advised: now.to_string(),
        reasoning: String::new(),
        figures: Vec::new(),
    };
    let worst = match representatives(sim, info, material) {
        Ok(r) => r.into_iter().max_by(|a, b| {
            let share = |r: &Representative| r.excitation.dynamic_share;
            share(a).total_cmp(&share(b))
        }),
        Err(why) => {
            advice.reasoning = format!("no advice: a stone alone has no modal solution ({why})");
            return advice;
        }
    };
    let Some(worst) = worst else {
        advice.reasoning = "no advice: the set has no stone".to_string();
        return advice;
    };
    let shapes = info
        .shapes
        .iter()
        .collect::<std::collections::BTreeSet<_>>();
    let (m, d, zeta) = (
        &worst.modes,
        worst.excitation.dynamic_share,
        worst.modes.damping_ratio,
    );
    let damped = sim
        .scene
        .contact
        .as_ref()
        .is_some_and(|c| c.damping() > 0.0);
    let replace = (zeta > 0.01 && !damped).then(|| (zeta * 100.0).ceil() / 100.0);
    let step = |rigid: bool, damping: Option<f64>| run_step(sim, rigid, damping);
    let (deformable_dt, rigid_dt) = (step(false, None), step(true, None));
    let rigid_advised_dt = match replace {
        Some(z) => step(true, Some(z)),
        None => rigid_dt,
    };
    let speed_up = rigid_advised_dt / deformable_dt;
    advice.figures = vec![
        ("shapes".into(), shapes.len() as f64),
        ("lowest_frequency_hz".into(), m.lowest_hz),
        ("dynamic_share".into(), d),
        ("predicted_error".into(), d),
        ("deformable_dt".into(), deformable_dt),
        ("rigid_dt".into(), rigid_dt),
        ("rigid_advised_dt".into(), rigid_advised_dt),
        ("rigid_speed_up".into(), speed_up),
        ("kelvin_voigt_damping_ratio".into(), zeta),
        ("advised_damping_ratio".into(), replace.unwrap_or(0.0)),
    ];
    let modes = format!(
        "of its {} shapes, the largest stone of shape {} ({} tets) is the most excited: first \
         free mode {:.4e} Hz; {} excites it to {d:.2e} of its quasi-static deflection",
        shapes.len(),
        worst.shape,
        m.tets,
        m.lowest_hz,
        worst.excitation.source
    );
    let steps = format!(
        "the run's step {deformable_dt:.3e} s with deformable stones, {rigid_advised_dt:.3e} s \
         with rigid ones{}: {speed_up:.2}x the steps' length (a rigid step skips the \
         stones' kernel but carries their rigid-body passes: measured 0.3 to 1.8x a \
         deformable one's cost)",
        match replace {
            Some(z) => format!(" on dashpots of damping_ratio = {z}"),
            None => String::new(),
        }
    );
    (advice.advised, advice.reasoning) = if d <= NEGLIGIBLE_DYNAMICS {
        let mut text = format!(
            "{modes} (at most {NEGLIGIBLE_DYNAMICS}): rigid, each stone misses that much; {steps}"
        );
        let advised = match replace {
            Some(z) => {
                text += &format!(
                    "; rigid, a stone loses its Kelvin-Voigt damping (zeta = {zeta:.3} at its \
                     first mode): give [contact] damping_ratio = {z} in its place"
                );
                format!("rigid, [contact] damping_ratio = {z}")
            }
            None => "rigid".to_string(),
        };
        (advised, text)
    } else if d >= DYNAMIC {
        let text = format!("{modes} (at least {DYNAMIC}): its vibration matters; {steps}");
        ("deformable".to_string(), text)
    } else {
        let text = format!(
            "{modes}: either kind; rigid, a stone would miss about {d:.2e} of its response; {steps}"
        );
        (now.to_string(), text)
    };
    if sim
        .scene
        .contact
        .as_ref()
        .is_some_and(|c| c.local_damping > 0.0)
    {
        advice.reasoning += "; local_damping acts on each node of a deformable stone but on the \
                             whole of a rigid one: the two kinds dissipate differently and may \
                             settle into different beds";
    }
    advice
}

/// The largest stone of each shape of `info`, alone and free, with what excites it.
fn representatives(
    sim: &Simulation,
    info: &BallastInfo,
    material: &Material,
) -> Result<Vec<Representative>, String> {
    let Some(body) = sim.bodies.iter().find(|b| b.name == info.name) else {
        return Ok(Vec::new());
    };
    let tets = sim.body_tets(body);
    let state = &sim.world.state;
    let ballast = sim.scene.ballast.as_ref().expect("a [ballast] set");
    let mut largest: Vec<Option<usize>> = Vec::new();
    for (k, &shape) in info.shapes.iter().enumerate() {
        if largest.len() <= shape {
            largest.resize(shape + 1, None);
        }
        if largest[shape].is_none_or(|j| info.sizes[k] > info.sizes[j]) {
            largest[shape] = Some(k);
        }
    }
    let mut out = Vec::new();
    for (shape, k) in largest.iter().enumerate() {
        let Some(k) = *k else { continue };
        let range = info.stones[k].clone();
        let start = range.start as u32;
        let own: Vec<[u32; 4]> = tets
            .iter()
            .filter(|t| range.contains(&(t[0] as usize)))
            .map(|t| t.map(|n| n - start))
            .collect();
        let reference = &state.reference[range];
        let mass = material.density * own.iter().map(|t| volume(reference, t)).sum::<f64>();
        let name = format!("{} stone {k}", info.name);
        let modes = body_modes::of_part(&name, reference, own, material, &[])?;
        let speed = fall_speed(&sim.scene, ballast.velocity, info.sizes[k]);
        let excitation = excitation::of_stone(
            &sim.scene,
            material,
            (mass, ballast.contact_radius),
            speed,
            (modes.lowest_hz, modes.damping_ratio),
        );
        out.push(Representative {
            shape,
            modes,
            excitation,
        });
    }
    Ok(out)
}

/// The speed a stone of size `size` strikes at: its set's starting `velocity`, or a fall as
/// high as itself under the scene's gravity, whichever is faster.
fn fall_speed(scene: &Scene, velocity: [f64; 3], size: f64) -> f64 {
    let g = Vec3::from(scene.run.gravity).norm();
    Vec3::from(velocity).norm().max((2.0 * g * size).sqrt())
}

/// The volume of the tetrahedron `t` of `nodes`.
fn volume(nodes: &[Vec3], t: &[u32; 4]) -> f64 {
    let [a, b, c, d] = t.map(|n| nodes[n as usize]);
    (b - a).cross(&(c - a)).dot(&(d - a)).abs() / 6.0
}

/// The run's explicit stable bound with the `[ballast]` rigid or not and, where `damping` is
/// given, with contact dashpots of that ratio ([`super::changed_step`]).
fn run_step(sim: &Simulation, rigid: bool, damping: Option<f64>) -> f64 {
    let now = sim.scene.ballast.as_ref().is_some_and(|b| b.rigid);
    if rigid == now && damping.is_none() {
        return sim.world.settings().stable_dt.0;
    }
    super::changed_step(sim, |scene| {
        if let Some(b) = scene.ballast.as_mut() {
            b.rigid = rigid;
        }
        if let (Some(c), Some(z)) = (scene.contact.as_mut(), damping) {
            c.damping_ratio = z;
            c.restitution = None;
        }
    })
}

/// The advice for the `[granular]` set `info` of `material`; none without a stone.
fn granular(sim: &Simulation, info: &GranularInfo, material: &Material) -> Option<Advice> {
    let state = &sim.world.state;
    let mass = info
        .stones
        .iter()
        .map(|(c, _)| state.mass[*c])
        .fold(0.0, f64::max);
    if mass <= 0.0 {
        return None;
    }
    let radius = (3.0 * mass / (4.0 * PI * material.density)).cbrt();
    let shear = material.young / (2.0 * (1.0 + material.poisson));
    let f1 = SPHERE_LOWEST_MODE * (shear / material.density).sqrt() / (2.0 * PI * radius);
    let zeta = PI * f1 * body_modes::relaxation_time(material);
    let velocity = sim.scene.granular.as_ref().map_or([0.0; 3], |g| g.velocity);
    let speed = fall_speed(&sim.scene, velocity, 2.0 * radius);
    let exc = excitation::of_stone(&sim.scene, material, (mass, radius), speed, (f1, zeta));
    let d = exc.dynamic_share;
    let modes = format!(
        "its heaviest stone, as a sphere of its mass (radius {radius:.3e} m), has its first \
         free mode at {f1:.4e} Hz; {} excites it to {d:.2e} of its quasi-static deflection",
        exc.source
    );
    let (advised, reasoning) = match d >= DYNAMIC {
        true => (
            "deformable",
            format!(
                "{modes} (at least {DYNAMIC}): its vibration matters; clumps are rigid only: \
                 deformable stones are a [ballast] of meshes"
            ),
        ),
        false => (
            "rigid",
            format!("{modes}: rigid, a stone misses about that much of its response"),
        ),
    };
    Some(Advice {
        subject: format!("[granular] `{}`", info.name),
        topic: Topic::Rigidity,
        now: "rigid".to_string(),
        advised: advised.to_string(),
        reasoning,
        figures: vec![
            ("lowest_frequency_hz".into(), f1),
            ("dynamic_share".into(), d),
            ("predicted_error".into(), d),
            ("radius".into(), radius),
        ],
    })
}
