//! Rigid bodies held at points ([`qdem_core::step::rigid_constraints`]) under velocity Verlet:
//! a bar held at one end swings as a compound pendulum, with its pivot where it started to
//! round-off; a bar held in one direction at its members keeps them in that plane and moves
//! freely otherwise; a block resting on held members carries its weight on them; and a run is
//! the same bits on one and two threads, on one process and two or three ranks, and resumed
//! from a checkpoint.

use qdem_core::checkpoint::{Decoder, Encoder};
use qdem_core::parallel::thread_ranks::on_thread_ranks;
use qdem_core::step::{Scheme, StepRequest, StepSettings};
use qdem_core::world::World;
use qdem_core::{
    loads::Gravity, solvers::Verlet, step::Dofs, step::MemberHold, step::Model, step::State,
    step::Stepper, Mat3, Vec3,
};
use std::f64::consts::PI;

const G: f64 = 9.81;

/// A bar of mass `mass` along its own axis: centre particle 0 at `centre`, members 1 and 2 at
/// −`half` and +`half` along `axis` (a unit vector), principal moments `across` (about axes across the
/// bar) and `along` (about its axis).
fn bar(centre: Vec3, axis: Vec3, half: f64, mass: f64, (across, along): (f64, f64)) -> State {
    let mut s = State::at_rest(vec![centre, centre - half * axis, centre + half * axis]);
    s.mass[0] = mass;
    let inertia = Mat3::identity() * across + (along - across) * axis * axis.transpose();
    s.add_rigid_body("bar", 0, &[1, 2], inertia).unwrap();
    s
}

/// The angle from the downward vertical of the pivot-to-centre line, in the x–z plane.
fn swing(s: &State, pivot: Vec3) -> f64 {
    let r = s.position[0] - pivot;
    r.x.atan2(-r.z)
}

/// A bar of 2 kg, centre 0.5 m below its upper end, I_c = 0.5 kg m² across it: held at its
/// upper end (member 1) in x, y and z, let go at 0.05 rad, it swings with the compound
/// pendulum's period T₀ = 2π √(I_pivot / (m g d)), I_pivot = I_c + m d² = 1 kg m², times the
/// finite amplitude's 1 + θ₀²/16 + 11θ₀⁴/3072 (the series of 2K(sin θ₀/2)/π, its next term
/// 3·10⁻¹⁰ here). Verlet's period error at ∆t = 10⁻³ s (ω∆t = 3·10⁻³) is (ω∆t)²/24 ≈ 4·10⁻⁷
/// (measured: 4.1·10⁻⁷), the zero crossings' linear interpolation far below it: the period
/// within 2·10⁻⁶. The pivot stays where it started to round-off (measured 5·10⁻¹⁶ m over
/// 20,000 steps, bound 10⁻¹⁴) and the energy within Verlet's O((ω∆t)²) oscillation
/// (measured 2.5·10⁻⁶ of the swing's, bound 10⁻⁵).
#[test]
fn a_bar_held_at_one_end_swings_with_the_compound_pendulum_period() {
    let (mass, d, across) = (2.0, 0.5, 0.5);
    let theta0: f64 = 0.05;
    let axis = Vec3::new(theta0.sin(), 0.0, -theta0.cos());
    let pivot = Vec3::new(0.0, 0.0, 1.0);
    let mut s = bar(pivot + d * axis, axis, d, mass, (across, 0.01));
    s.hold_members(&[MemberHold {
        particle: 1,
        dofs: Dofs::ALL,
        fix: 1,
    }]);
    assert!(
        !s.rigid.spin_fixed[0],
        "a point hold leaves the body free to turn"
    );
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(Gravity::new(Vec3::new(0.0, 0.0, -G)))];
    let dt = 1e-3;
    let mut verlet = Verlet::new(dt);
    verlet.initialize(&mut s, &mut models).unwrap();
    let energy = |s: &State| s.kinetic_energy() + mass * G * s.position[0].z;
    let e0 = energy(&s);
    let (mut crossings, mut previous, mut drift, mut worst) =
        (Vec::new(), swing(&s, pivot), 0.0f64, 0.0f64);
    for _ in 0..20_000 {
        verlet.step(&mut s, &mut models).unwrap();
        let now = swing(&s, pivot);
        if previous > 0.0 && now <= 0.0 {
            crossings.push(s.time - dt * now / (now - previous));
        }
        previous = now;
        drift = drift.max((s.position[1] - pivot).norm());
        worst = worst.max((energy(&s) - e0).abs() / (mass * G * d * (1.0 - theta0.cos())));
    }
    let i_pivot = across + mass * d * d;
    let t0 = 2.0 * PI * (i_pivot / (mass * G * d)).sqrt();
    let expected = t0 * (1.0 + theta0.powi(2) / 16.0 + 11.0 * theta0.powi(4) / 3072.0);
    let periods: Vec<f64> = crossings.windows(2).map(|w| w[1] - w[0]).collect();
    assert!(periods.len() >= 8, "{crossings:?}");
    let off = periods
        .iter()
        .map(|t| (t / expected - 1.0).abs())
        .fold(0.0, f64::max);
    eprintln!("pendulum: period {off:.1e} off, pivot moved {drift:.1e} m, energy {worst:.1e}");
    for t in &periods {
        assert!(
            (t / expected - 1.0).abs() < 2e-6,
            "period {t} s against {expected} s"
        );
    }
    assert!(drift < 1e-14, "the pivot moved {drift:e} m");
    assert!(worst < 1e-5, "energy off by {worst:e} of the swing's");
}

/// The same bar lying along x, held at both members in y only, thrown along x and y and
/// spun about x, y and z: the holds take v_y and ω_z (which move the members in y) and leave
/// v_x, ω_x (about the bar's own axis, which moves no member) and ω_y. The members then keep
/// y = 0 while the bar slides in x, falls in z and tumbles; the holds' forces are along y
/// only, so the centre slides and falls freely, x = v_x t and z = −g t²/2.
#[test]
fn members_held_in_y_keep_their_y_and_move_freely_otherwise() {
    let mut s = bar(Vec3::zeros(), Vec3::x(), 0.5, 2.0, (0.5, 0.01));
    s.velocity[0] = Vec3::new(0.3, 0.7, 0.0);
    s.rigid.set_angular_velocity(0, Vec3::new(0.4, 1.5, 0.9));
    let y = Dofs::parse("y").unwrap();
    s.hold_members(&[
        MemberHold {
            particle: 1,
            dofs: y,
            fix: 1,
        },
        MemberHold {
            particle: 2,
            dofs: y,
            fix: 2,
        },
    ]);
    // The projection keeps what the holds allow.
    assert!((s.velocity[0] - Vec3::new(0.3, 0.0, 0.0)).norm() < 1e-15);
    assert!((s.rigid.angular_velocity[0] - Vec3::new(0.4, 1.5, 0.0)).norm() < 1e-15);
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(Gravity::new(Vec3::new(0.0, 0.0, -G)))];
    let mut verlet = Verlet::new(1e-3);
    verlet.initialize(&mut s, &mut models).unwrap();
    let mut worst = 0.0f64;
    for _ in 0..5000 {
        verlet.step(&mut s, &mut models).unwrap();
        worst = worst.max(s.position[1].y.abs()).max(s.position[2].y.abs());
    }
    let t = s.time;
    assert!(worst < 1e-14, "held members left y = 0 by {worst:e} m");
    assert!(
        (s.position[0].x - 0.3 * t).abs() < 1e-12,
        "{}",
        s.position[0]
    );
    assert!(
        (s.position[0].z + 0.5 * G * t * t).abs() < 1e-9,
        "{}",
        s.position[0]
    );
    assert!(s.position[0].y.abs() < 1e-14, "{}", s.position[0]);
    // It turned about y: its members left the x axis in z.
    assert!((s.position[1] - s.position[0]).z.abs() > 0.1);
}

/// A block of 3 kg resting on four members held in x, y and z (the corners of its base) under
/// gravity: the holds leave it no motion, so it is held whole, and the forces on the members
/// (the reactions, −f in the force buffer) sum to its weight, shared equally by the
/// symmetric corners (the least-norm forces), with no sideways part.
#[test]
fn a_block_resting_on_held_members_carries_its_weight_on_them() {
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let mut points = vec![Vec3::zeros()];
    points.extend(
        corners
            .iter()
            .map(|&(x, y)| Vec3::new(0.2 * x, 0.1 * y, -0.05)),
    );
    let mut s = State::at_rest(points);
    s.mass[0] = 3.0;
    s.add_rigid_body(
        "block",
        0,
        &[1, 2, 3, 4],
        Mat3::from_diagonal(&Vec3::new(0.01, 0.02, 0.03)),
    )
    .unwrap();
    let holds: Vec<MemberHold> = (1..=4)
        .map(|particle| MemberHold {
            particle,
            dofs: Dofs::ALL,
            fix: 1,
        })
        .collect();
    s.hold_members(&holds);
    assert!(
        s.rigid.spin_fixed[0],
        "four corners leave no motion: held whole"
    );
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(Gravity::new(Vec3::new(0.0, 0.0, -G)))];
    let mut verlet = Verlet::new(1e-3);
    verlet.initialize(&mut s, &mut models).unwrap();
    for _ in 0..10 {
        verlet.step(&mut s, &mut models).unwrap();
    }
    let weight = 3.0 * G;
    let reaction: Vec3 = (1..=4).map(|m| -verlet.forces()[m]).sum();
    assert!(
        (reaction - Vec3::new(0.0, 0.0, weight)).norm() < 1e-12 * weight,
        "{reaction}"
    );
    for m in 1..=4 {
        let share = -verlet.forces()[m];
        assert!(
            (share - Vec3::new(0.0, 0.0, weight / 4.0)).norm() < 1e-12 * weight,
            "{share}"
        );
    }
    assert_eq!(s.position[0], Vec3::zeros());
}

/// The pendulum's state after 3,000 steps on `threads` threads.
fn pendulum_on(threads: usize) -> State {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let axis = Vec3::new(0.3, 0.2, -1.0).normalize();
        let mut s = bar(axis * 0.5, axis, 0.5, 2.0, (0.5, 0.02));
        s.rigid.set_angular_velocity(0, Vec3::new(0.1, 2.0, 0.3));
        s.hold_members(&[MemberHold {
            particle: 1,
            dofs: Dofs::ALL,
            fix: 1,
        }]);
        let mut models: Vec<Box<dyn Model>> = vec![Box::new(Gravity::new(Vec3::new(0.0, 0.0, -G)))];
        let mut verlet = Verlet::new(1e-3);
        verlet.initialize(&mut s, &mut models).unwrap();
        for _ in 0..3000 {
            verlet.step(&mut s, &mut models).unwrap();
        }
        s
    })
}

/// A held body's run is the same bits on one and two threads (its constraints are solved
/// body by body, in a fixed order).
#[test]
fn a_held_body_gives_the_same_bits_on_one_and_two_threads() {
    let one = pendulum_on(1);
    assert!(one.rigid.angular_velocity[0].norm() > 0.1);
    assert!(one == pendulum_on(2));
}

/// Four bars held at one end each, swinging in different planes, as a world stepped by
/// Verlet at ∆t = 10⁻³ s under gravity.
fn pendulums() -> World {
    let mut points = Vec::new();
    let mut bars = Vec::new();
    for k in 0..4 {
        let pivot = Vec3::new(k as f64, 0.0, 1.0);
        let axis = Vec3::new(0.2 * (k as f64 - 1.5), 0.1 * k as f64, -1.0).normalize();
        let centre = pivot + 0.5 * axis;
        let first = points.len();
        points.extend([centre, pivot, centre + 0.5 * axis]);
        bars.push((first, axis));
    }
    let mut s = State::at_rest(points);
    let mut holds = Vec::new();
    for (k, &(c, axis)) in bars.iter().enumerate() {
        s.mass[c] = 2.0;
        let inertia = Mat3::identity() * 0.5 - 0.48 * axis * axis.transpose();
        s.add_rigid_body("bar", c, &[c + 1, c + 2], inertia)
            .unwrap();
        s.rigid
            .set_angular_velocity(k, Vec3::new(0.3, 1.0 + k as f64, 0.2));
        holds.push(MemberHold {
            particle: c + 1,
            dofs: Dofs::ALL,
            fix: k + 1,
        });
    }
    s.hold_members(&holds);
    let models: Vec<Box<dyn Model>> = vec![Box::new(Gravity::new(Vec3::new(0.0, 0.0, -G)))];
    let request = StepRequest {
        scheme: Scheme::Verlet,
        dt: Some(1e-3),
        safety: 0.9,
        local_damping: 0.0,
        adaptive: false,
        event_solve: Default::default(),
        implicit_default: None,
        fit_to: None,
    };
    let settings = StepSettings::resolve(&request, &s, &models).unwrap();
    World::new(s, models, settings).unwrap()
}

/// The pendulums' state and the stepper's forces (the holds' reactions at the pivots) after
/// 500 steps.
fn pendulums_stepped(world: &mut World) -> (State, Vec<Vec3>) {
    world.initialize().unwrap();
    for _ in 0..500 {
        world.step().unwrap();
    }
    world.gather();
    (world.state.clone(), world.stepper().forces().to_vec())
}

/// Over two and three ranks (each body owned whole by one rank), the held bodies' motion and
/// their reactions are one process's bits.
#[test]
fn held_bodies_over_ranks_give_one_processs_bits() {
    let (one, forces) = pendulums_stepped(&mut pendulums());
    assert!(forces[1].norm() > 1.0, "the pivot carries the bar");
    for size in [2, 3] {
        let runs = on_thread_ranks(size, |comm| {
            let mut world = pendulums();
            world.decompose(comm).unwrap();
            pendulums_stepped(&mut world)
        });
        for (rank, (state, f)) in runs.iter().enumerate() {
            assert!(*state == one, "{size} ranks, rank {rank}: the state");
            assert!(*f == forces, "{size} ranks, rank {rank}: the reactions");
        }
    }
}

/// A checkpoint of held bodies resumes bit for bit: the holds come from the scene (built
/// again), the pose, momenta and the torques with the holds' part from the checkpoint.
#[test]
fn held_bodies_resume_from_a_checkpoint_bit_for_bit() {
    let mut straight = pendulums();
    straight.initialize().unwrap();
    let mut saved = Vec::new();
    for step in 1..=400 {
        straight.step().unwrap();
        if step == 150 {
            let mut out = Encoder::new();
            straight.save(&mut out).unwrap();
            saved = out.into_bytes();
        }
    }
    let mut resumed = pendulums();
    resumed.restore(&mut Decoder::new(&saved), 150).unwrap();
    for _ in 150..400 {
        resumed.step().unwrap();
    }
    assert!(resumed.state == straight.state);
}
