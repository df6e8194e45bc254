//! Two grains driven through each other: a contact spring holds two spheres apart only while
//! they overlap by less than their radii; past that a centre is inside the other sphere, and
//! once the centres cross the contact pulls them through. The pass-through check at each
//! rebuild of the lists stops the run while the overlap is beyond the smaller radius but the
//! centres have not crossed, naming both bodies, as the run's interpenetration watch does for
//! `[[body]]`s (which does not run with stones or over ranks).

mod common;

use common::{contacts, rigid_spheres, verlet_world};
use qdem_contact::{ContactLaw, ContactSettings, LinearSpring};
use qdem_core::error::CoreError;
use qdem_core::step::Model;
use qdem_core::Vec3;

const R: f64 = 0.005;

/// Two grains of radius `R` 1 mm apart, thrown at each other at `speed` each, on linear
/// springs of stiffness `k`, stepped at 1 µs until 10 ms or the first failure.
fn collide(speed: f64, k: f64) -> Result<[Vec3; 2], CoreError> {
    let centers = [
        Vec3::new(-R - 5e-4, 0.0, 0.0),
        Vec3::new(R + 5e-4, 0.0, 0.0),
    ];
    let (mut state, spheres) = rigid_spheres(&centers, R, 2500.0);
    state.velocity[0] = Vec3::new(speed, 0.0, 0.0);
    state.velocity[1] = Vec3::new(-speed, 0.0, 0.0);
    let settings = ContactSettings {
        law: ContactLaw::Linear(LinearSpring {
            normal_stiffness: k,
            tangential_stiffness: k,
            damping_ratio: 0.0,
        }),
        friction: 0.0,
        skin: 0.2 * R,
    };
    let models: Vec<Box<dyn Model>> = vec![Box::new(contacts(
        &state,
        &spheres,
        (1e9, 0.25),
        settings,
        vec![],
    ))];
    let mut world = verlet_world(state, models, Some(1e-6))?;
    while world.state.time < 0.01 {
        world.step()?;
    }
    Ok([world.state.position[0], world.state.position[1]])
}

/// On 10 N/m springs the grains (1.3 g each, at 2 m/s) would need a 0.8 m overlap to stop:
/// they pass through each other, and the run stops while their centres are still apart. On
/// 1e5 N/m they bounce (the largest overlap m v²/k under a tenth of a millimetre) and the
/// run goes on.
#[test]
fn grains_driven_through_each_other_stop_the_run_naming_both() {
    let error = collide(2.0, 10.0).expect_err("the grains pass through each other");
    let text = error.to_string();
    eprintln!("{text}");
    assert!(
        text.contains("body `body0`")
            && text.contains("overlaps the contact sphere of body `body1`"),
        "{text}"
    );
    assert!(text.contains("more than the smaller radius"), "{text}");
    let [a, b] = collide(2.0, 1e5).expect("the grains bounce");
    assert!(a.x < 0.0 && b.x > 0.0, "they bounced apart: {a:?} {b:?}");
}
