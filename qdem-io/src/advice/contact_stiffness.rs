//! The linear contact's stiffness against the step it sets: the overlap it allows under the
//! scene's largest force against the sphere radius, and the step a softer spring would give.
//!
//! The reference force is the largest of the heaviest `[[body]]`'s weight, the weight of a
//! column of the heaviest stone (of `[granular]` or `[ballast]`) as many layers high as the
//! sample (its height along gravity over the smallest sphere's diameter), and the largest
//! `[[load]]` force (its `total_force` times its time factor's peak), carried by one contact
//! (the worst case of a body resting on one sphere, of a stone at the bottom of a column):
//! δ = F/k_n. A softer spring k_n/s lets δ grow s-fold and the step √s-fold (the contact's
//! frequency √(k/m)), and lengthens a contact's duration π√(m/k) √s-fold:
//! - δ/R below 0.5% and the contacts setting the step: softer, to δ/R = 1% (s = 0.01 R/δ),
//!   unless that would make the contact time longer than a tenth of the loads' shortest
//!   segment (where the scene has `[[load]]`s; a series' segment is the time it takes to
//!   change by its peak at its fastest rate);
//! - δ/R above 5%: stiffer, back to 1%: overlaps that large distort the geometry the law
//!   assumes (the fixed 5% of the radius the contacts' step bound was first taken at);
//! - otherwise the stiffness stands.
//!
//! Hertz–Mindlin takes its stiffness from the bodies' materials, so only its overlap is told.

use super::{Advice, Topic};
use crate::build::Simulation;
use crate::scene::ContactLawName;
use qdem_core::step::Model as _;

/// Overlap over radius advised for a softened or stiffened spring.
const TARGET_OVERLAP: f64 = 0.01;

/// The advice for `sim`'s contacts; none without `[contact]` or without a sphere.
pub(super) fn advise(sim: &Simulation) -> Option<Advice> {
    let contact = sim.scene.contact.as_ref()?;
    let contacts = sim.contacts()?;
    let radius = contacts.smallest_radius()?;
    let g = nalgebra::Vector3::from(sim.scene.run.gravity).norm();
    let (heaviest, mass) = heaviest_carrier(sim, radius);
    let load = sim
        .scene
        .loads
        .iter()
        .map(|l| {
            nalgebra::Vector3::from(l.total_force).norm()
                * super::excitation::peak_factor(&sim.scene, l)
        })
        .fold(0.0, f64::max);
    let force = (mass * g).max(load);
    let (bound, limiter) = &sim.world.settings().stable_dt;
    let contact_dt = contacts
        .stable_dt(&sim.world.state)
        .unwrap_or(f64::INFINITY);
    let limits = limiter == contacts.name();
    let mut advice = Advice {
        subject: "contacts".to_string(),
        topic: Topic::ContactStiffness,
        now: String::new(),
        advised: String::new(),
        reasoning: String::new(),
        figures: vec![
            ("contact_dt".into(), contact_dt),
            ("step_bound".into(), *bound),
        ],
    };
    let Some(k) = contact
        .normal_stiffness
        .filter(|_| contact.law == ContactLawName::Linear)
    else {
        advice.now = "hertz-mindlin".into();
        advice.advised = advice.now.clone();
        advice.reasoning = format!(
            "the stiffness follows the bodies' materials; the contacts' step is {contact_dt:.3e} s \
             ({})",
            if limits { "it sets the run's step" } else { "not the run's limit" }
        );
        return Some(advice);
    };
    let overlap = force / k / radius;
    let contact_time = std::f64::consts::PI * (mass / k).sqrt();
    let segment = super::excitation::shortest_load_segment(&sim.scene);
    advice.now = format!("normal_stiffness = {k:.4e}");
    advice.figures.extend([
        ("overlap_over_radius".into(), overlap),
        ("contact_time".into(), contact_time),
        ("reference_force".into(), force),
        ("radius".into(), radius),
    ]);
    let told = format!(
        "the largest force, {force:.4e} N ({}), on one contact overlaps it by {:.3}% of the \
         {radius:.3e} m radius; the contacts' step is {contact_dt:.3e} s",
        if mass * g >= load {
            heaviest
        } else {
            "a [[load]]".into()
        },
        overlap * 100.0
    );
    let (factor, why) = if overlap < 0.005 && limits {
        let limit = match sim.scene.loads.is_empty() {
            true => f64::INFINITY,
            false => (0.1 * segment / contact_time).powi(2),
        };
        let s = (TARGET_OVERLAP / overlap).min(limit).max(1.0);
        let why = match s > 1.0 {
            true => format!("it sets the run's step: a spring {s:.3e}x softer overlaps {:.2}% and steps {:.2}x longer", overlap * s * 100.0, s.sqrt()),
            false => format!("it sets the run's step, but a softer spring's contact, {contact_time:.3e} s now, would last longer than a tenth of the loads' fastest change ({segment:.3e} s): the stiffness stands"),
        };
        (s, why)
    } else if overlap > 0.05 {
        let s = TARGET_OVERLAP / overlap;
        (s, format!("more than 5% of the radius distorts the contact geometry: a spring {:.2}x stiffer overlaps 1% and steps {:.2}x shorter", 1.0 / s, 1.0 / s.sqrt()))
    } else {
        (1.0, "the stiffness stands".to_string())
    };
    advice.advised = match !(0.95..=1.05).contains(&factor) {
        true => format!("normal_stiffness = {:.4e}", k / factor),
        false => advice.now.clone(),
    };
    advice.figures.push(("softening".into(), factor));
    advice.reasoning = format!("{told}; {why}");
    Some(advice)
}

/// What weighs most on one contact, in words, and its mass (kg): the heaviest `[[body]]`, or
/// a column of the heaviest stone as many layers high as the stones' sample.
fn heaviest_carrier(sim: &Simulation, radius: f64) -> (String, f64) {
    let state = &sim.world.state;
    let mut stones: Vec<(f64, Vec<usize>)> = Vec::new();
    if let Some(g) = &sim.granular {
        stones.extend(g.stones.iter().map(|(c, _)| (state.mass[*c], vec![*c])));
    }
    if let Some(b) = &sim.ballast {
        stones.extend(
            b.stones
                .iter()
                .map(|r| (state.mass[r.clone()].iter().sum(), r.clone().collect())),
        );
    }
    let down = nalgebra::Vector3::from(sim.scene.run.gravity)
        .try_normalize(0.0)
        .unwrap_or_else(qdem_core::Vec3::z);
    let heights = stones
        .iter()
        .flat_map(|s| &s.1)
        .map(|&p| state.position[p].dot(&down));
    let (low, high) = heights.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), z| {
        (l.min(z), h.max(z))
    });
    let stone = stones.iter().map(|s| s.0).fold(0.0, f64::max);
    let layers = match high > low {
        true => ((high - low) / (2.0 * radius)).floor() + 1.0,
        false => 1.0,
    };
    let mut heaviest = (
        format!("a column of the heaviest stone, {layers} stones high"),
        stone * layers,
    );
    for b in &sim.bodies {
        if matches!(b.kind, crate::build::BodyKind::Stones { .. }) {
            continue;
        }
        let mass = sim.body_mass(b);
        if mass > heaviest.1 {
            heaviest = (format!("the weight of body `{}`", b.name), mass);
        }
    }
    heaviest
}
