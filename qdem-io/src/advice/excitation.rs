//! What excites a body: its loads' time functions and the impacts it starts with, each turned
//! into the **dynamic share** d of its first mode, the amplitude of the body's vibration in
//! that mode over its quasi-static deflection under the same load (an undamped oscillator of
//! frequency f₁; Clough & Penzien, *Dynamics of Structures*, §4 and §6):
//!
//! - a cyclic load of frequency f, oscillating part w of its peak: d = w r²/|1 − r²|, r = f/f₁
//!   (the dynamic amplification 1/|1 − r²| less its quasi-static 1);
//! - a ramp or series segment changing by w of the peak over Δt: d = w min(1, 1/(π f₁ Δt)),
//!   the envelope of the residual vibration |sin(π f₁ Δt)|/(π f₁ Δt) a linear ramp leaves;
//!   a jump (Δt = 0) leaves d = w;
//! - an impact of contact time t_c (the Hertz or linear-spring time at the body's starting
//!   speed against a rigid wall): a pulse rising over t_c/2, d = min(1, 2/(π f₁ t_c)).
//!
//! A stone of a `[ballast]` or `[granular]` set ([`of_stone`]) is excited by every load of the
//! scene, which reaches it through the bed, and by its contacts, which strike it however it
//! starts. A `[bonded]` body by its top load's ramp ([`of_ramp`]).
//!
//! The body's Kelvin–Voigt damping ratio ζ at f₁ lowers these: the cyclic share becomes
//! w |1/√((1 − r²)² + (2ζr)²) − 1|, and the transient ones are scaled by the step response's
//! overshoot e^(−ζπ/√(1 − ζ²)), zero for an overdamped mode (ζ ≥ 1: a creep test).
//!
//! The body's own weight is left out: it is not an excitation a rigid body would miss.

use crate::build::load_series::read_series;
use crate::scene::{Body, ContactLawName, Load, Material, Scene};
use std::f64::consts::PI;

/// What a body's loads and impacts do to its first mode.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Excitation {
    /// The largest dynamic share of its sources.
    pub dynamic_share: f64,
    /// The source of that share, in words.
    pub source: String,
}

/// The excitation of `body` (of `material`, of mass `mass`) in `scene`, for a first mode at
/// `f1` Hz with damping ratio `zeta`: its own loads and its impact at its starting speed.
pub(super) fn of_body(
    scene: &Scene,
    body: &Body,
    material: &Material,
    mass: f64,
    (f1, zeta): (f64, f64),
) -> Excitation {
    let mut worst = loads(scene, Some(&body.name), (f1, zeta));
    let speed = nalgebra::Vector3::from(body.velocity).norm();
    if speed > 0.0 {
        let radius = body.contact_radius.unwrap_or(0.0);
        worst.consider(impact(scene, material, (mass, radius), speed, (f1, zeta)));
    }
    worst
}

/// The excitation of one stone of a `[ballast]` or `[granular]` set (of `material`, of mass
/// `mass`, its contact spheres of radius `radius`) in `scene`, for a first mode at `f1` Hz
/// with damping ratio `zeta`. A stone has no load of its own: every `[[load]]` of the scene
/// reaches it through the bed, at the load's own rate. Its contacts strike it: a linear
/// spring over π√(m/k_n) whatever the speed (the contact's half period, the shortest a
/// stone's contact force can change over), a Hertz contact at `speed` (the set's starting
/// speed, or a fall as high as the stone, the least a pour or a rearranging stone strikes at).
pub(super) fn of_stone(
    scene: &Scene,
    material: &Material,
    (mass, radius): (f64, f64),
    speed: f64,
    (f1, zeta): (f64, f64),
) -> Excitation {
    let mut worst = loads(scene, None, (f1, zeta));
    worst.consider(impact(scene, material, (mass, radius), speed, (f1, zeta)));
    worst
}

/// The excitation of a `[bonded]` body's first mode at `f1` Hz (damping ratio `zeta`) by its
/// top load rising linearly over `rise` seconds (at once where zero), then held.
pub(super) fn of_ramp(rise: f64, (f1, zeta): (f64, f64)) -> Excitation {
    let (share, _) = segments(&[(0.0, 0.0), (rise, 1.0)], f1);
    Excitation {
        dynamic_share: overshoot(zeta) * share,
        source: match rise > 0.0 {
            true => format!("its top load, ramped on over {rise:.4e} s,"),
            false => "its top load, applied at once,".to_string(),
        },
    }
}

impl Excitation {
    /// Keeps `other` where it excites more.
    fn consider(&mut self, other: Option<Excitation>) {
        if let Some(other) = other.filter(|o| o.dynamic_share > self.dynamic_share) {
            *self = other;
        }
    }
}

/// The largest dynamic share of the `[[load]]`s on `body` (every load where `None`).
fn loads(scene: &Scene, body: Option<&str>, (f1, zeta): (f64, f64)) -> Excitation {
    let overshoot = overshoot(zeta);
    let mut worst = Excitation {
        dynamic_share: 0.0,
        source: "nothing time-varying (no cyclic, ramped or series load, no impact)".to_string(),
    };
    let mut consider = |share: f64, source: String| {
        worst.consider(Some(Excitation {
            dynamic_share: share,
            source,
        }))
    };
    for (k, load) in scene.loads.iter().enumerate() {
        if body.is_some_and(|b| load.body != b) {
            continue;
        }
        let name = format!("[[load]] #{}", k + 1);
        if let Some(c) = &load.cyclic {
            let peak = c.max.abs().max(c.min.abs());
            let w = if peak > 0.0 {
                (c.max - c.min).abs() / peak
            } else {
                0.0
            };
            let r = c.frequency / f1;
            let gain = 1.0 / ((1.0 - r * r).powi(2) + (2.0 * zeta * r).powi(2)).sqrt();
            let share = w * (gain.min(1e3) - 1.0).abs();
            consider(share, format!("{name} cycles at {:.4} Hz", c.frequency));
        } else if let Some(s) = &load.series {
            if let Ok(points) = read_series(&scene.resolve(&s.file), &s.column) {
                let (share, at) = segments(&points, f1);
                consider(
                    overshoot * share,
                    format!("{name}'s series changes fastest at t = {at:.4e} s"),
                );
            }
        } else {
            let points: Vec<(f64, f64)> = load.ramp.points.iter().map(|p| (p[0], p[1])).collect();
            let (share, at) = segments(&points, f1);
            consider(
                overshoot * share,
                format!("{name}'s ramp changes fastest at t = {at:.4e} s"),
            );
        }
    }
    worst
}

/// The dynamic share of an impact at `speed` of a carrier of mass `mass` on spheres of
/// `radius` under `scene`'s contact law; none without `[contact]` or a contact time.
fn impact(
    scene: &Scene,
    material: &Material,
    (mass, radius): (f64, f64),
    speed: f64,
    (f1, zeta): (f64, f64),
) -> Option<Excitation> {
    let contact = scene.contact.as_ref()?;
    let t_c = match contact.law {
        ContactLawName::HertzMindlin if speed > 0.0 => {
            hertz_contact_time(mass, radius, material.young, material.poisson, speed)
        }
        ContactLawName::HertzMindlin => f64::INFINITY,
        ContactLawName::Linear => contact
            .normal_stiffness
            .map_or(f64::INFINITY, |k| PI * (mass / k).sqrt()),
    };
    (t_c.is_finite() && t_c > 0.0).then(|| Excitation {
        dynamic_share: overshoot(zeta) * (2.0 / (PI * f1 * t_c)).min(1.0),
        source: match speed > 0.0 {
            true => format!("an impact at {speed:.3} m/s lasting about {t_c:.3e} s"),
            false => format!("its contacts, each lasting about {t_c:.3e} s"),
        },
    })
}

/// The loads' shortest ramp segment that changes their value, shortest cycle period, or the
/// shortest time a series takes to change by its peak at its fastest rate (s); the run's
/// length if there is none.
pub(super) fn shortest_load_segment(scene: &Scene) -> f64 {
    let mut shortest = scene.run.t_end;
    for load in &scene.loads {
        if let Some(c) = &load.cyclic {
            shortest = shortest.min(1.0 / c.frequency);
        } else if let Some(s) = &load.series {
            if let Ok(points) = read_series(&scene.resolve(&s.file), &s.column) {
                shortest = shortest.min(time_to_peak(&points));
            }
        }
        for w in load.ramp.points.windows(2) {
            let dt = w[1][0] - w[0][0];
            if dt > 0.0 && w[1][1] != w[0][1] {
                shortest = shortest.min(dt);
            }
        }
    }
    shortest
}

/// The largest magnitude of `load`'s time factor: the peak of its ramp (1 without one), of
/// its cycle or of its series (1 where the series cannot be read: the build refuses it).
pub(super) fn peak_factor(scene: &Scene, load: &Load) -> f64 {
    let peak = |points: &mut dyn Iterator<Item = f64>| points.map(f64::abs).fold(0.0, f64::max);
    if let Some(c) = &load.cyclic {
        c.max.abs().max(c.min.abs())
    } else if let Some(s) = &load.series {
        read_series(&scene.resolve(&s.file), &s.column)
            .map_or(1.0, |points| peak(&mut points.iter().map(|p| p.1)))
    } else if load.ramp.points.is_empty() {
        1.0
    } else {
        peak(&mut load.ramp.points.iter().map(|p| p[1]))
    }
}

/// The time a piecewise-linear function takes to change by its peak at its fastest rate
/// (infinite for a constant one).
fn time_to_peak(points: &[(f64, f64)]) -> f64 {
    let peak = points.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
    let rate = points
        .windows(2)
        .filter(|w| w[1].0 > w[0].0)
        .map(|w| (w[1].1 - w[0].1).abs() / (w[1].0 - w[0].0))
        .fold(0.0, f64::max);
    peak / rate
}

/// The overshoot e^(−ζπ/√(1 − ζ²)) of a mode's step response over its static deflection; zero
/// when overdamped.
fn overshoot(zeta: f64) -> f64 {
    match zeta < 1.0 {
        true => (-zeta * PI / (1.0 - zeta * zeta).sqrt()).exp(),
        false => 0.0,
    }
}

/// The largest dynamic share of the segments of a piecewise-linear function, and the time
/// it starts at.
fn segments(points: &[(f64, f64)], f1: f64) -> (f64, f64) {
    let peak = points.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
    if peak == 0.0 {
        return (0.0, 0.0);
    }
    points
        .windows(2)
        .map(|w| {
            let (dt, dv) = (w[1].0 - w[0].0, (w[1].1 - w[0].1).abs() / peak);
            let share = match dt > 0.0 {
                true => dv * (1.0 / (PI * f1 * dt)).min(1.0),
                false => dv,
            };
            (share, w[0].0)
        })
        .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
}

/// Hertz's contact time 2.87 (m²/(R E*² v))^(1/5) of a sphere of radius `radius` carrying
/// mass `mass` against a rigid wall at speed `v`, E* = E/(1 − ν²) (Johnson, *Contact
/// Mechanics*, §11.4).
fn hertz_contact_time(mass: f64, radius: f64, young: f64, poisson: f64, v: f64) -> f64 {
    let e_star = young / (1.0 - poisson * poisson);
    2.87 * (mass * mass / (radius * e_star * e_star * v)).powf(0.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ramp ten periods long leaves about 1/(10π) of the static deflection ringing; a jump
    /// all of it.
    #[test]
    fn a_slow_ramp_barely_rings_a_jump_rings_fully() {
        let slow = segments(&[(0.0, 0.0), (10.0, 1.0)], 1.0).0;
        assert!((slow - 1.0 / (10.0 * PI)).abs() < 1e-12, "{slow}");
        let jump = segments(&[(0.0, 1.0), (1.0, 1.0), (1.0, 0.0)], 1.0);
        assert_eq!(jump, (1.0, 1.0));
    }

    /// The closed form against Hertz's law integrated step by step: m δ'' = −(4/3) E* √R δ^(3/2)
    /// from δ = 0 at speed v until δ returns to 0.
    #[test]
    fn the_hertz_contact_time_is_that_of_the_hertz_law_integrated() {
        let (m, r, e, nu, v): (f64, f64, f64, f64, f64) = (0.01, 0.005, 5e7, 0.25, 1.5);
        let k = 4.0 / 3.0 * e / (1.0 - nu * nu) * r.sqrt();
        let (mut delta, mut rate, mut t, dt) = (0.0f64, v, 0.0, 1e-9);
        loop {
            let a = -k * delta.max(0.0).powf(1.5) / m;
            rate += a * dt;
            delta += rate * dt;
            t += dt;
            if delta < 0.0 {
                break;
            }
        }
        let closed = hertz_contact_time(m, r, e, nu, v);
        // 2.87 is 2.868 rounded: 0.1% and the integration's 1e-9 s of 1e-4 s.
        assert!((t / closed - 1.0).abs() < 2e-3, "{t} against {closed}");
    }
}
