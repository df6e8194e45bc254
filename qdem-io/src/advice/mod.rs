//! What a scene needs modelled, told by the program (issue 58): `qdem check` advises each
//! `[[body]]`'s kind (rigid or deformable) and formulation, a `[ballast]` or `[granular]`
//! stone set's kind, the integrator, and the contacts' stiffness, each with its reasoning and
//! the figures behind it.
//!
//! Advice is advice: nothing in the scene changes; [`Advice::now`] says what the scene does,
//! [`Advice::advised`] what the figures point to. The figures come from the bodies' own
//! natural modes with their fixes ([`body_modes`], Lanczos as `qdem modes`), the loads' time
//! functions and the impacts' contact times ([`excitation`]), and measured costs cited where
//! they are used. One file per kind of advice: [`rigidity`], [`stones`], [`formulation`],
//! [`integrator`] (a `[bonded]` body's: [`bonded_integrator`]), [`contact_stiffness`].

mod body_modes;
mod bonded_integrator;
mod contact_stiffness;
mod excitation;
mod formulation;
mod integrator;
mod rigidity;
mod stones;

pub use bonded_integrator::{EXPLICIT_FRACTION, IMPLICIT_BBM_STEP_COST};

use crate::build::{BodyKind, Simulation};
use crate::scene::Scene;
use serde::Serialize;

/// The largest dynamic share ([`excitation::Excitation::dynamic_share`]) at which a body's
/// vibration is negligible: its first mode answers the loads with at most 1% of their
/// quasi-static response on top.
pub const NEGLIGIBLE_DYNAMICS: f64 = 0.01;

/// What a piece of advice is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Topic {
    /// A body rigid or deformable ([`rigidity`]).
    Rigidity,
    /// A deformable body's tetrahedron ([`formulation`]).
    Formulation,
    /// The run's integrator and step ([`integrator`]).
    Integrator,
    /// The contacts' stiffness against the step it sets ([`contact_stiffness`]).
    ContactStiffness,
}

/// One piece of advice: about what, what the scene does now, what is advised and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Advice {
    /// What it is about: `body \`beam\``, `run`, `contacts`.
    pub subject: String,
    /// The kind of advice.
    pub topic: Topic,
    /// What the scene does now (`deformable`, `standard`, `verlet dt = 1e-6 s`).
    pub now: String,
    /// What the figures point to; equal to `now` when the scene's choice stands.
    pub advised: String,
    /// The reasoning, in a sentence or two, with its numbers.
    pub reasoning: String,
    /// The figures behind it, by name (SI units; named with their unit where not obvious).
    pub figures: Vec<(String, f64)>,
}

impl Advice {
    /// Whether the advice asks for a change of the scene.
    pub fn changes(&self) -> bool {
        self.now != self.advised
    }

    /// The figure named `name`, if the advice has one.
    pub fn figure(&self, name: &str) -> Option<f64> {
        self.figures.iter().find(|(n, _)| n == name).map(|f| f.1)
    }

    /// One line for `qdem check`: `advice body \`beam\` (rigidity): keep deformable: ...`.
    pub fn line(&self) -> String {
        let verdict = match self.changes() {
            true => format!("{} -> {}", self.now, self.advised),
            false => format!("keep {}", self.now),
        };
        format!(
            "advice {} ({}): {verdict}: {}",
            self.subject,
            self.topic_name(),
            self.reasoning
        )
    }

    fn topic_name(&self) -> &'static str {
        match self.topic {
            Topic::Rigidity => "rigid or deformable",
            Topic::Formulation => "formulation",
            Topic::Integrator => "integrator",
            Topic::ContactStiffness => "contact stiffness",
        }
    }
}

/// Every piece of advice for `sim`'s scene, in the order: each `[[body]]` (rigidity, then
/// formulation), the stone sets (`[ballast]`, `[granular]`), the integrator (of the
/// `[[body]]`s, or of a `[bonded]` body), the contacts.
///
/// ```
/// # let dir = std::env::temp_dir().join(format!("qdem-advice-doc-{}", std::process::id()));
/// # std::fs::create_dir_all(&dir).unwrap();
/// # let mesh = concat!(env!("CARGO_MANIFEST_DIR"), "/../fixtures/cantilever/cantilever_lc100.msh");
/// # let scene = format!(r#"
/// # [run]
/// # t_end = 1.0
/// # integrator = "static"
/// # [[material]]
/// # name = "rubber"
/// # density = 1100.0
/// # young = 5e6
/// # poisson = 0.49
/// # [[body]]
/// # name = "beam"
/// # mesh = "{mesh}"
/// # material = "rubber"
/// # [[fix]]
/// # body = "beam"
/// # group = "clamp"
/// # "#);
/// # std::fs::write(dir.join("scene.toml"), scene).unwrap();
/// # let path = dir.join("scene.toml");
/// use qdem_io::{advice, build::Simulation, scene::Scene};
/// let sim = Simulation::build(Scene::load(&path)?)?;
/// let all = advice::advise(&sim);
/// let formulation = all.iter().find(|a| a.topic == advice::Topic::Formulation).unwrap();
/// assert_eq!(formulation.advised, "averaged-pressure");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn advise(sim: &Simulation) -> Vec<Advice> {
    let mut advice = Vec::new();
    let mut lowest = Vec::new();
    for body in &sim.bodies {
        // The `[ballast]` stones are in `sim.bodies` but no `[[body]]` of the scene.
        let Some(i) = sim.scene.bodies.iter().position(|b| b.name == body.name) else {
            continue;
        };
        if matches!(body.kind, BodyKind::Stones { .. }) {
            continue;
        }
        let material = &sim.scene.materials[sim.scene.refs().body_materials[i]];
        let modes = body_modes::of_body(sim, body, material);
        if let Ok(m) = &modes {
            lowest.push((body.name.clone(), m.clone()));
        }
        advice.push(rigidity::advise(sim, body, &modes));
        if !sim.scene.bodies[i].rigid {
            advice.push(formulation::advise(&body.name, material));
        }
    }
    advice.extend(stones::advise(sim));
    advice.extend(integrator::advise(sim, &lowest));
    advice.extend(bonded_integrator::advise(sim));
    advice.extend(contact_stiffness::advise(sim));
    advice
}

/// The run's explicit stable bound (s) of `sim`'s scene changed by `change`, the scene built
/// again (a body or stone set turned rigid or deformable, contact dashpots added): the step a
/// change gives, with every model's bound, not a guess at the one it relieves. NaN where the
/// changed scene does not build.
fn changed_step(sim: &Simulation, change: impl FnOnce(&mut Scene)) -> f64 {
    let mut scene = sim.scene.clone();
    change(&mut scene);
    Simulation::build(scene).map_or(f64::NAN, |s| s.world.settings().stable_dt.0)
}

/// The advice as JSON for scripts (`qdem check --advice json`): an array of objects with
/// `subject`, `topic`, `now`, `advised`, `changes`, `reasoning` and `figures` (an object of
/// named numbers).
pub fn to_json(advice: &[Advice]) -> serde_json::Value {
    let items = advice
        .iter()
        .map(|a| {
            let figures: serde_json::Map<String, serde_json::Value> = a
                .figures
                .iter()
                .map(|(name, value)| (name.clone(), serde_json::json!(value)))
                .collect();
            serde_json::json!({
                "subject": a.subject,
                "topic": a.topic,
                "now": a.now,
                "advised": a.advised,
                "changes": a.changes(),
                "reasoning": a.reasoning,
                "figures": figures,
            })
        })
        .collect();
    serde_json::Value::Array(items)
}
