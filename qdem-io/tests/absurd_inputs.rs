//! Inputs that are valid but hardly meant are warned of, naming the value and the likely
//! intent (issue 40, item 8); a cyclic load with min above max is refused. The paper's short
//! cantilever (2.4 m, concrete, `common::short_cantilever`) as it is gets no warning.

mod common;

use common::{short_cantilever, test_dir};
use qdem_io::build::Simulation;
use qdem_io::scene::Scene;

/// The warnings of the short cantilever with `edits`.
fn warnings(name: &str, edits: &[(&str, &str)]) -> Vec<String> {
    let dir = test_dir(name);
    let sim = Simulation::build(Scene::load(&short_cantilever(&dir, edits)).unwrap()).unwrap();
    sim.warnings
}

/// The one warning there is, which contains every one of `parts`.
fn assert_one_warning(warnings: &[String], parts: &[&str]) {
    assert_eq!(warnings.len(), 1, "{warnings:#?}");
    for part in parts {
        assert!(
            warnings[0].contains(part),
            "{part:?} not in {:?}",
            warnings[0]
        );
    }
}

#[test]
fn the_cantilever_as_it_is_gets_no_warning() {
    assert_eq!(warnings("absurd-none", &[]), Vec::<String>::new());
}

/// dt = 1e-12 s against a stable step of some 10⁻⁵ s: 2·10¹⁰ steps for 0.02 s.
#[test]
fn a_tiny_step_is_warned_of_with_its_step_count() {
    let w = warnings("absurd-dt", &[("dt = \"auto\"", "dt = 1e-12")]);
    assert_one_warning(
        &w,
        &[
            "[run] dt = 1e-12 s",
            "2.00e10 steps",
            "did you mean dt = \"auto\"",
        ],
    );
}

/// A probe 8 m beyond the beam's tip (the beam is 2.4 m long).
#[test]
fn a_probe_far_from_every_particle_is_warned_of() {
    let w = warnings(
        "absurd-probe",
        &[("point = [2.4, 0.125, 0.11]", "point = [10.4, 0.125, 0.11]")],
    );
    assert_one_warning(&w, &["[[probe]] \"tip\"", "8.000 m away", "in metres"]);
}

/// young = 1 Pa for concrete's 2350 kg/m³: a wave speed of 0.02 m/s.
#[test]
fn a_stone_with_young_of_one_pascal_is_warned_of() {
    let w = warnings("absurd-young", &[("young = 45e9", "young = 1")]);
    assert_one_warning(
        &w,
        &[
            "young = 1e0 Pa",
            "density = 2.35e3",
            "2.06e-2 m/s",
            "did you mean 1e9 Pa (GPa)",
        ],
    );
}

/// A cyclic load whose min is above its max is refused, naming both and the fix.
#[test]
fn a_cyclic_load_with_min_above_max_is_refused() {
    let dir = test_dir("absurd-cyclic");
    let path = short_cantilever(
        &dir,
        &[(
            "ramp = [[0.0, 0.0], [0.01, 1.0], [2.0, 1.0], [2.0, 0.0]]",
            "cyclic = { min = 1.0, max = 0.075, frequency = 3.0 }",
        )],
    );
    let message = Scene::load(&path).unwrap_err().to_string();
    for part in [
        "[[load]] #1",
        "cyclic min = 1 is above max = 0.075",
        "swap them",
    ] {
        assert!(message.contains(part), "{part:?} not in {message:?}");
    }
}

/// The poured grains of `fixtures/contact/grains.toml` at dt = 2e-4 s, above the 5.9e-5 s the
/// contacts estimate: no grain touches at the start, so no contact alone is shown unstable
/// there, and the step is accepted with a warning of what the run does if one comes to need
/// a shorter step (the fixed worst case refused it).
#[test]
fn a_step_above_the_contacts_estimate_is_accepted_and_warned_of() {
    let dir = test_dir("absurd-contact-step");
    let fixture = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../fixtures/contact/grains.toml"
    );
    let text = std::fs::read_to_string(fixture).unwrap();
    let path = dir.join("grains.toml");
    std::fs::write(&path, text.replace("dt = 2e-5", "dt = 2e-4")).unwrap();
    let sim = Simulation::build(Scene::load(&path).unwrap()).expect("accepted");
    assert_one_warning(
        &sim.warnings,
        &[
            "[run] dt = 2e-4 s",
            "estimates from the contacts present",
            "the run stops, naming the contact",
        ],
    );
}
