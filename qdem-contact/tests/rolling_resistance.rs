//! Rolling resistance (`[contact] rolling_friction`, Ai et al. 2011 model C as LIGGGHTS
//! `epsd2`) against closed forms for a sphere of radius R, mass m and I = 2/5 m R² on a plane
//! (R* = R against a wall), rolling without slip:
//!
//! - on a level plane the rolling torque at its cap, μ_r R m g, decelerates it: m dv/dt = −F_t,
//!   I dω/dt = F_t R − μ_r R m g and v = ωR give a = (5/7) μ_r g, so from v₀ it stops after
//!   v₀²/(2a), and the spring (below its cap) then holds it where model A would chatter;
//! - on a plane inclined at θ it stays at rest while the rolling torque can balance the
//!   friction's moment, F_t R ≤ μ_r R F_n with F_t = m g sin θ and F_n = m g cos θ, that is
//!   tan θ ≤ μ_r (with μ ≥ tan θ against sliding); steeper, it rolls down with
//!   a = (5/7) g (sin θ − μ_r cos θ).
//!
//! The contact model's friction acts at the middle of the overlap, a lever R − δ/2 against
//! R* = R in the cap: here δ/R ≈ 10⁻⁴, so the closed forms hold to about 10⁻⁴.

mod common;

use common::{contacts, rigid_spheres, stepper};
use qdem_contact::{
    ContactLaw, ContactSettings, DemContacts, LinearSpring, PlaneWall, Wall, WallShape,
};
use qdem_core::{loads::Gravity, step::Model, step::State, step::Stepper, Vec3};

const G: f64 = 9.81;
const RADIUS: f64 = 0.01;
const DENSITY: f64 = 2500.0;
const MU: f64 = 0.5;
const MU_R: f64 = 0.1;
/// Normal and tangential stiffness (N/m): a static overlap m g / k ≈ 1 µm, δ/R ≈ 10⁻⁴.
const K: f64 = 1e5;

fn settings() -> ContactSettings {
    ContactSettings {
        law: ContactLaw::Linear(LinearSpring {
            normal_stiffness: K,
            tangential_stiffness: K,
            damping_ratio: 0.3,
        }),
        friction: MU,
        skin: 0.1 * RADIUS,
    }
}

/// A sphere resting on a plane through the origin inclined at `theta` about y, rolling down
/// it (towards +x for θ = 0) at `v0` without slip, with rolling friction `mu_r`: the state,
/// the models (contacts, gravity) and the step, and the downhill direction.
fn on_a_slope(theta: f64, v0: f64, mu_r: f64) -> (State, Vec<Box<dyn Model>>, f64, Vec3) {
    let normal = Vec3::new(-theta.sin(), 0.0, theta.cos());
    let downhill = match theta > 0.0 {
        true => -Vec3::new(theta.cos(), 0.0, theta.sin()),
        false => Vec3::x(),
    };
    let (mut state, spheres) = rigid_spheres(&[Vec3::zeros()], RADIUS, DENSITY);
    let m = state.mass[0];
    let static_overlap = m * G * theta.cos() / K;
    state.position[0] = (RADIUS - static_overlap) * normal;
    state.velocity[0] = v0 * downhill;
    // Rolling: the contact point v + ω × (−R n) at rest.
    state
        .rigid
        .set_angular_velocity(0, normal.cross(&downhill) * (v0 / RADIUS));
    let wall = Wall {
        shape: WallShape::Plane(PlaneWall::new(Vec3::zeros(), normal, Vec3::zeros())),
        friction: MU,
    };
    let model = contacts(&state, &spheres, (1e9, 0.25), settings(), vec![wall])
        .with_rolling_friction(mu_r)
        .unwrap();
    let dt = 0.2 * model.stable_dt(&state).unwrap();
    let models: Vec<Box<dyn Model>> = vec![
        Box::new(model),
        Box::new(Gravity::new(Vec3::new(0.0, 0.0, -G))),
    ];
    (state, models, dt, downhill)
}

#[test]
fn a_rolling_sphere_decelerates_at_five_sevenths_mu_r_g_and_stops_where_the_closed_form_says() {
    let v0 = 0.5;
    let (mut state, mut models, dt, downhill) = on_a_slope(0.0, v0, MU_R);
    let mut s = stepper(dt, &mut state, &mut models);
    let speed = |st: &State| st.velocity[0].dot(&downhill);
    let a = 5.0 / 7.0 * MU_R * G;
    // The mean deceleration over the middle of the roll.
    while state.time < 0.1 {
        s.step(&mut state, &mut models).unwrap();
    }
    let (t0, u0) = (state.time, speed(&state));
    while state.time < 0.5 {
        s.step(&mut state, &mut models).unwrap();
    }
    let measured = (u0 - speed(&state)) / (state.time - t0);
    eprintln!("a = {measured:.6} m/s² vs (5/7) μ_r g = {a:.6}");
    assert!((measured / a - 1.0).abs() < 1e-3, "a = {measured} vs {a}");
    // Still rolling without slip: ω R = v.
    let w = state.rigid.angular_velocity[0].y;
    assert!(
        (w * RADIUS / speed(&state) - 1.0).abs() < 1e-3,
        "ω R = {}",
        w * RADIUS
    );
    while speed(&state) > 0.0 {
        s.step(&mut state, &mut models).unwrap();
    }
    let (stop, at) = (state.position[0].x, state.time);
    let expected = v0 * v0 / (2.0 * a);
    eprintln!(
        "stopped after {stop:.6} m at {at:.4} s vs v0²/(2a) = {expected:.6} m, v0/a = {:.4} s",
        v0 / a
    );
    assert!(
        (stop / expected - 1.0).abs() < 1e-3,
        "{stop} m vs {expected} m"
    );
    // Held by the rolling spring: its swing, 2 M/k_r = 2 μ_r m g / (k_t R) ≈ 2e-5 rad, moves
    // the centre by about R · 2e-5 = 0.2 µm; model A's constant torque would flip the spin by
    // μ_r R m g ∆t / I at every step and the sphere would creep.
    let mut farthest = 0.0f64;
    while state.time < at + 0.2 {
        s.step(&mut state, &mut models).unwrap();
        farthest = farthest.max((state.position[0].x - stop).abs());
    }
    let spin = state.rigid.angular_velocity[0].norm();
    eprintln!("after stopping: moved at most {farthest:.3e} m, spin {spin:.3e} rad/s at the end");
    assert!(farthest < 1e-6, "moved {farthest} m after stopping");
    assert!(spin < 1e-3, "spin {spin} rad/s after stopping");
}

/// The sphere released at rest on a slope of tan θ = `ratio` μ_r: its mean acceleration down
/// the slope from 0.05 s (after the springs have taken the load) to `t_end`, and the distance
/// it went by `t_end`.
fn release(ratio: f64, t_end: f64) -> (f64, f64) {
    let theta = (ratio * MU_R).atan();
    let (mut state, mut models, dt, downhill) = on_a_slope(theta, 0.0, MU_R);
    let start = state.position[0];
    let mut s = stepper(dt, &mut state, &mut models);
    let speed = |st: &State| st.velocity[0].dot(&downhill);
    while state.time < 0.05 {
        s.step(&mut state, &mut models).unwrap();
    }
    let (t0, u0) = (state.time, speed(&state));
    while state.time < t_end {
        s.step(&mut state, &mut models).unwrap();
    }
    (
        (speed(&state) - u0) / (state.time - t0),
        (state.position[0] - start).dot(&downhill),
    )
}

#[test]
fn a_sphere_stays_on_a_slope_flatter_than_tan_theta_mu_r_and_rolls_down_a_steeper_one() {
    let t_end = 0.2;
    let (a, moved) = release(0.8, t_end);
    eprintln!("tan θ = 0.8 μ_r: a = {a:.3e} m/s², moved {moved:.3e} m");
    // Free, it would roll (5/7) g sin θ t²/2 ≈ 11 mm; the springs settle within 1 µm.
    assert!(moved.abs() < 1e-6, "moved {moved} m");
    assert!(a.abs() < 1e-4, "a = {a} m/s²");
    let (a, moved) = release(1.25, t_end);
    let theta = (1.25 * MU_R).atan();
    let expected = 5.0 / 7.0 * G * (theta.sin() - MU_R * theta.cos());
    eprintln!("tan θ = 1.25 μ_r: a = {a:.6} m/s² vs {expected:.6}, moved {moved:.6e} m");
    assert!((a / expected - 1.0).abs() < 1e-3, "a = {a} vs {expected}");
}

/// Two spheres pressed together, one spinning about x, after one evaluation with and
/// without rolling friction: the torques and forces on each.
fn pair_loads(mu_r: f64) -> (Vec<Vec3>, Vec<Vec3>) {
    let centers = [Vec3::zeros(), Vec3::new(0.0, 0.0, 2.0 * RADIUS - 1e-5)];
    let (mut state, spheres) = rigid_spheres(&centers, RADIUS, DENSITY);
    state
        .rigid
        .set_angular_velocity(0, Vec3::new(3.0, 0.0, 1.0));
    state
        .rigid
        .set_angular_velocity(1, Vec3::new(-1.0, 2.0, 0.0));
    let mut model: DemContacts = contacts(&state, &spheres, (1e9, 0.25), settings(), vec![])
        .with_rolling_friction(mu_r)
        .unwrap();
    let (mut force, mut torque) = (vec![Vec3::zeros(); 2], vec![Vec3::zeros(); 2]);
    model.add_forces(&state, &mut force, &mut torque);
    state.time = 1e-6;
    force.fill(Vec3::zeros());
    torque.fill(Vec3::zeros());
    model.add_forces(&state, &mut force, &mut torque);
    (force, torque)
}

#[test]
fn a_pairs_rolling_torques_are_equal_and_opposite_against_the_relative_rolling() {
    let (f0, t0) = pair_loads(0.0);
    let (f1, t1) = pair_loads(MU_R);
    assert_eq!(f0, f1, "rolling resistance adds no force");
    let (on_a, on_b) = (t1[0] - t0[0], t1[1] - t0[1]);
    // ω_a − ω_b = (4, −2, 1), its rolling part (4, −2, 0); over 1 µs of rolling spring
    // growth k_r = k_t R*² = 1e5 · 0.005² = 2.5 N m/rad: M_r = 2.5 · 1e-6 · (4, −2, 0), below
    // the cap μ_r R* F_n = 0.1 · 0.005 · 1 N.
    let expected = 2.5 * 1e-6 * Vec3::new(4.0, -2.0, 0.0);
    assert!(
        (on_a + expected).norm() < 1e-12 * expected.norm(),
        "{on_a:?}"
    );
    assert!(
        (on_a + on_b).norm() < 1e-12 * expected.norm(),
        "the pair adds a moment"
    );
}

/// Three spheres stacked and pressed together, each spinning its own way, listed bottom up
/// or (`reverse`) top down, their rolling springs grown over three evaluations, the second
/// model restored from a checkpoint taken after two when `resume`: the torque on each sphere,
/// bottom up, at the third.
fn stack_torques(reverse: bool, resume: bool) -> Vec<Vec3> {
    use qdem_core::checkpoint::{Decoder, Encoder};
    use qdem_core::step::Persistent;
    let gap = 2.0 * RADIUS - 1e-5;
    let mut centers: Vec<Vec3> = (0..3)
        .map(|k| Vec3::new(0.0, 0.0, k as f64 * gap))
        .collect();
    let mut spins = [
        Vec3::new(3.0, 0.0, 1.0),
        Vec3::new(-1.0, 2.0, 0.0),
        Vec3::new(0.5, -4.0, 2.0),
    ];
    if reverse {
        centers.reverse();
        spins.reverse();
    }
    let (mut state, spheres) = rigid_spheres(&centers, RADIUS, DENSITY);
    for (b, w) in spins.iter().enumerate() {
        state.rigid.set_angular_velocity(b, *w);
    }
    let model = |state: &State| -> DemContacts {
        contacts(state, &spheres, (1e9, 0.25), settings(), vec![])
            .with_rolling_friction(MU_R)
            .unwrap()
    };
    let mut torque = vec![Vec3::zeros(); 3];
    let mut evaluate = |m: &mut DemContacts, state: &mut State, t: f64| {
        state.time = t;
        let mut force = vec![Vec3::zeros(); 3];
        torque.fill(Vec3::zeros());
        m.add_forces(state, &mut force, &mut torque);
        torque.clone()
    };
    let mut last = model(&state);
    evaluate(&mut last, &mut state, 0.0);
    evaluate(&mut last, &mut state, 1e-6);
    if resume {
        let mut out = Encoder::new();
        last.save(&mut out);
        last = model(&state);
        last.restore(&mut Decoder::new(out.bytes())).unwrap();
    }
    let mut t = evaluate(&mut last, &mut state, 2e-6);
    if reverse {
        t.reverse();
    }
    t
}

/// The engine keeps its spheres in spatial order, each pair with its lower slot first, and a
/// checkpoint writes its lists by the spheres' stable ids, sorted again when read: whichever
/// way the stack is listed, and across a checkpoint, each sphere's rolling torque is the same
/// (each spring moved with its record).
#[test]
fn rolling_springs_follow_their_contacts_whichever_way_the_spheres_are_listed_and_across_a_checkpoint(
) {
    let reference = stack_torques(false, false);
    let largest = reference.iter().map(|t| t.norm()).fold(0.0, f64::max);
    assert!(largest > 0.0);
    for (reverse, resume) in [(true, false), (false, true), (true, true)] {
        let t = stack_torques(reverse, resume);
        for (a, b) in reference.iter().zip(&t) {
            assert!(
                (a - b).norm() <= 1e-12 * largest,
                "reverse {reverse}, resume {resume}: {t:?} against {reference:?}"
            );
        }
    }
}
