//! The granular benchmark of issue 4: a dense, settled packing of rigid spheres (Hertz–Mindlin,
//! friction, damping, gravity) in a box of plane walls, and the throughput of qdem on it in
//! sphere-steps per second. `study packing` writes the packing for both qdem and LIGGGHTS
//! (`qdem-bench/scripts/liggghts_compare.py` runs the two side by side on the same file and
//! time step); `study dem-throughput` times qdem on it, and with `--clumps` the same packing
//! with every sphere replaced by a rigid clump of 2, 3 or 4 smaller spheres inside it
//! ([`Packing::build_clumps`]).
//!
//! Material: E = 50 MPa (soft, as DEM benchmarks use to afford a long step), ν = 0.25,
//! ρ = 2700 kg/m³, μ = 0.5, restitution 0.5 (damping ratio ζ = −ln e/√(π² + ln² e)),
//! radius 5 mm, skin 1 mm; the step is 20% of the Rayleigh time, LIGGGHTS's recommended limit,
//! or 90% of qdem's own bound if that is smaller.

use qdem_contact::{
    ContactLaw, ContactSettings, ContactSphere, DemContacts, HertzMindlin, PlaneWall, Wall,
    WallShape,
};
use qdem_core::step::rigid_body::point_inertia;
use qdem_core::{
    loads::Gravity, solvers::Verlet, step::Model, step::State, step::Stepper, Mat3, Vec3,
};
use serde_json::{json, Value};
use std::path::Path;
use std::time::Instant;
use thiserror::Error;

/// Sphere radius (m).
pub const RADIUS: f64 = 0.005;
const DENSITY: f64 = 2700.0;
const YOUNG: f64 = 5e7;
const POISSON: f64 = 0.25;
const FRICTION: f64 = 0.5;
const RESTITUTION: f64 = 0.5;
const SKIN: f64 = 0.001;
const GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// Why the granular study failed.
#[derive(Debug, Error)]
pub enum GranularError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The error.
        source: std::io::Error,
    },
    /// A packing file is malformed.
    #[error("{path}: {reason}")]
    Format {
        /// The file.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// The run failed.
    #[error("the granular run failed: {0}")]
    Core(#[from] qdem_core::error::CoreError),
}

/// A packing: sphere centres in a box with an open top.
#[derive(Clone, Debug)]
pub struct Packing {
    /// Sphere centres (m).
    pub centers: Vec<Vec3>,
    /// Box corners (m); the floor is z = lower.z.
    pub lower: Vec3,
    /// Upper corner (the top is open).
    pub upper: Vec3,
}

/// ζ from the restitution coefficient e.
pub fn damping_ratio(restitution: f64) -> f64 {
    let l = restitution.ln();
    -l / (std::f64::consts::PI.powi(2) + l * l).sqrt()
}

/// The Rayleigh time π r √(ρ/G)/(0.1631ν + 0.8766) (s).
pub fn rayleigh_time() -> f64 {
    let shear = YOUNG / (2.0 * (1.0 + POISSON));
    std::f64::consts::PI * RADIUS * (DENSITY / shear).sqrt() / (0.1631 * POISSON + 0.8766)
}

/// The step of both codes: 20% of the Rayleigh time (LIGGGHTS's recommended limit) or 90% of
/// qdem's stable bound for the packing's models, whichever is smaller.
pub fn time_step(state: &State, models: &[Box<dyn Model>]) -> f64 {
    let bound = qdem_core::step::stepper::stable_step(state, models).map_or(f64::INFINITY, |b| b.0);
    (0.2 * rayleigh_time()).min(0.9 * bound)
}

impl Packing {
    /// `n` spheres on a loose lattice (spacing 2.2 r, a deterministic jitter) over a square
    /// base of about ∛n spheres a side.
    pub fn lattice(n: usize) -> Packing {
        let side = (n as f64).cbrt().ceil() as usize;
        let pitch = 2.2 * RADIUS;
        let centers = (0..n)
            .map(|m| {
                let (i, j, k) = (m % side, (m / side) % side, m / (side * side));
                let jitter = ((i * 7 + j * 13 + k * 29) % 17) as f64 / 17.0 - 0.5;
                Vec3::new(
                    (i as f64 + 0.5) * pitch + 0.1 * RADIUS * jitter,
                    (j as f64 + 0.5) * pitch - 0.1 * RADIUS * jitter,
                    (k as f64 + 0.5) * pitch,
                )
            })
            .collect();
        let width = side as f64 * pitch;
        Packing {
            centers,
            lower: Vec3::zeros(),
            upper: Vec3::new(width, width, (n.div_ceil(side * side)) as f64 * pitch),
        }
    }

    /// The floor and four side walls, normals inwards.
    pub fn walls(&self) -> Vec<(Vec3, Vec3)> {
        vec![
            (self.lower, Vec3::z()),
            (self.lower, Vec3::x()),
            (self.lower, Vec3::y()),
            (self.upper, -Vec3::x()),
            (self.upper, -Vec3::y()),
        ]
    }

    /// The state (one rotating particle per sphere) and the models: contacts, gravity.
    pub fn build(&self) -> (State, Vec<Box<dyn Model>>) {
        self.build_with(damping_ratio(RESTITUTION), FRICTION)
    }

    /// The same without contact damping and without friction: an elastic packing whose
    /// equations conserve the energy (kinetic, the contacts' elastic energy and gravity's
    /// potential), which the speed-versus-error study's energy drift measures.
    pub fn build_elastic(&self) -> (State, Vec<Box<dyn Model>>) {
        self.build_with(0.0, 0.0)
    }

    /// The same with contact damping ratio `zeta` and Coulomb friction `friction`.
    fn build_with(&self, zeta: f64, friction: f64) -> (State, Vec<Box<dyn Model>>) {
        let mut state = State::at_rest(self.centers.clone());
        let mass = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3);
        for i in 0..self.centers.len() {
            state.mass[i] = mass;
            state.let_turn(i, 0.4 * mass * RADIUS * RADIUS);
        }
        let spheres: Vec<ContactSphere> = (0..self.centers.len())
            .map(|i| ContactSphere {
                particle: i,
                radius: RADIUS,
                body: i,
                material: 0,
            })
            .collect();
        let names = vec!["sphere".to_string(); self.centers.len()];
        let models = self.models(&state, &spheres, names, zeta, friction);
        (state, models)
    }

    /// The contacts of `spheres` (of bodies `names`) with each other and the walls, and
    /// gravity.
    fn models(
        &self,
        state: &State,
        spheres: &[ContactSphere],
        names: Vec<String>,
        zeta: f64,
        friction: f64,
    ) -> Vec<Box<dyn Model>> {
        let walls = self
            .walls()
            .into_iter()
            .map(|(p, n)| Wall {
                shape: WallShape::Plane(PlaneWall::new(p, n, Vec3::zeros())),
                friction,
            })
            .collect();
        let settings = ContactSettings {
            law: ContactLaw::HertzMindlin(HertzMindlin {
                damping_ratio: zeta,
            }),
            friction,
            skin: SKIN,
        };
        let contacts =
            DemContacts::new(state, spheres, names, &[(YOUNG, POISSON)], settings, walls);
        vec![
            Box::new(contacts),
            Box::new(Gravity::new(Vec3::from(GRAVITY))),
        ]
    }

    /// The state and models of the packing with sphere i replaced by a rigid clump of k = 2, 3,
    /// 4 (in turn) spheres inside it, on the vertices of a segment, triangle or tetrahedron of
    /// circumradius a about the sphere's centre, turned by a fixed rotation per clump, with
    /// radius r − a so that the clump reaches the sphere's surface: a = r/2, 2r/(2 + √3),
    /// 2r/(2 + √(8/3)), the smallest for which the clump's spheres do not overlap, so that its
    /// mass properties are the sum of its spheres' (2/5 m r² plus the parallel-axis term each).
    /// Returns the number of contact spheres too.
    pub fn build_clumps(&self) -> (State, Vec<Box<dyn Model>>, usize) {
        let shapes: [(&[[f64; 3]], f64); 3] = [
            (&[[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]], 0.5),
            (
                &[
                    [1.0, 0.0, 0.0],
                    [-0.5, 0.866_025_403_784_438_6, 0.0],
                    [-0.5, -0.866_025_403_784_438_6, 0.0],
                ],
                2.0 / (2.0 + 3f64.sqrt()),
            ),
            (
                &[
                    [1.0, 1.0, 1.0],
                    [1.0, -1.0, -1.0],
                    [-1.0, 1.0, -1.0],
                    [-1.0, -1.0, 1.0],
                ],
                2.0 / (2.0 + (8.0f64 / 3.0).sqrt()),
            ),
        ];
        let mut members = Vec::new();
        for (i, c) in self.centers.iter().enumerate() {
            let (vertices, arm) = shapes[i % 3];
            let turn = nalgebra::UnitQuaternion::from_euler_angles(
                0.7 * i as f64,
                1.3 * i as f64,
                2.1 * i as f64,
            );
            let r = (1.0 - arm) * RADIUS;
            let at = vertices
                .iter()
                .map(|v| c + turn * (arm * RADIUS * Vec3::from(*v).normalize()))
                .collect::<Vec<_>>();
            members.push((at, r));
        }
        let positions = members.iter().flat_map(|(at, _)| at.iter().copied());
        let mut state = State::at_rest(positions.collect());
        let mut spheres = Vec::new();
        for (b, (at, r)) in members.iter().enumerate() {
            let m = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
            let first = spheres.len();
            let ids: Vec<usize> = (first..first + at.len()).collect();
            let center = state.push_particle(self.centers[b], Vec3::zeros(), m * at.len() as f64);
            let own = Mat3::identity() * (0.4 * m * r * r * at.len() as f64);
            let inertia = own + point_inertia(self.centers[b], at, &vec![m; at.len()]);
            state
                .add_rigid_body("clump", center, &ids, inertia)
                .expect("a clump has positive mass and inertia");
            spheres.extend(ids.iter().map(|&p| ContactSphere {
                particle: p,
                radius: *r,
                body: b,
                material: 0,
            }));
        }
        let count = spheres.len();
        let names = vec!["clump".to_string(); self.centers.len()];
        let models = self.models(
            &state,
            &spheres,
            names,
            damping_ratio(RESTITUTION),
            FRICTION,
        );
        (state, models, count)
    }

    /// Pours the lattice under gravity for `seconds` of simulated time and keeps the settled
    /// centres. The pouring dissipates by local damping 0.7 instead of contact dashpots, whose
    /// step bound is three times shorter, so that it takes a third of the steps.
    pub fn settle(&mut self, seconds: f64) -> Result<(), GranularError> {
        let (mut state, mut models) = self.build_with(0.0, FRICTION);
        let mut stepper = Verlet::new(time_step(&state, &models)).with_local_damping(0.7);
        stepper.initialize(&mut state, &mut models)?;
        while state.time < seconds {
            stepper.step(&mut state, &mut models)?;
        }
        eprintln!(
            "settled {} spheres for {seconds} s: kinetic energy {:.3e} J",
            state.len(),
            state.kinetic_energy()
        );
        self.centers = state.position;
        Ok(())
    }

    /// Writes `packing.csv` and `packing.json` into `dir`.
    pub fn write(&self, dir: &Path) -> Result<(), GranularError> {
        let dt = {
            let (state, models) = self.build();
            time_step(&state, &models)
        };
        let io = |path: &Path| {
            let path = path.display().to_string();
            move |source| GranularError::Io { path, source }
        };
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let mut csv = String::from("x,y,z,radius\n");
        for c in &self.centers {
            csv.push_str(&format!(
                "{:.17e},{:.17e},{:.17e},{RADIUS:e}\n",
                c.x, c.y, c.z
            ));
        }
        let csv_path = dir.join("packing.csv");
        std::fs::write(&csv_path, csv).map_err(io(&csv_path))?;
        let top = self.centers.iter().map(|c| c.z).fold(0.0, f64::max) + RADIUS;
        let walls: Vec<Value> = self
            .walls()
            .iter()
            .map(|(p, n)| json!({"point": [p.x, p.y, p.z], "normal": [n.x, n.y, n.z]}))
            .collect();
        let meta = json!({
            "spheres": self.centers.len(),
            "box_min": [self.lower.x, self.lower.y, self.lower.z],
            "box_max": [self.upper.x, self.upper.y, self.upper.z.max(top)],
            "radius": RADIUS,
            "density": DENSITY,
            "youngs_modulus": YOUNG,
            "poisson_ratio": POISSON,
            "friction": FRICTION,
            "restitution": RESTITUTION,
            "damping_ratio": damping_ratio(RESTITUTION),
            "gravity": GRAVITY,
            "dt": dt,
            "skin": SKIN,
            "walls": walls,
        });
        let json_path = dir.join("packing.json");
        let text = serde_json::to_string_pretty(&meta).expect("plain JSON");
        std::fs::write(&json_path, text).map_err(io(&json_path))
    }

    /// Reads the centres of `dir/packing.csv` (box from `packing.json`).
    pub fn read(dir: &Path) -> Result<Packing, GranularError> {
        let csv_path = dir.join("packing.csv");
        let text = std::fs::read_to_string(&csv_path).map_err(|source| GranularError::Io {
            path: csv_path.display().to_string(),
            source,
        })?;
        let bad = |line: usize, reason: &str| GranularError::Format {
            path: format!("{}:{line}", csv_path.display()),
            reason: reason.to_string(),
        };
        let mut centers = Vec::new();
        for (n, line) in text.lines().enumerate().skip(1) {
            let v: Vec<f64> = line
                .split(',')
                .map(|f| f.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| bad(n + 1, "expected four numbers x,y,z,radius"))?;
            if v.len() != 4 || v[3] != RADIUS {
                return Err(bad(n + 1, "expected x,y,z,radius with radius 0.005"));
            }
            centers.push(Vec3::new(v[0], v[1], v[2]));
        }
        let json_path = dir.join("packing.json");
        let meta: Value = std::fs::read_to_string(&json_path)
            .map_err(|source| GranularError::Io {
                path: json_path.display().to_string(),
                source,
            })
            .and_then(|t| {
                serde_json::from_str(&t).map_err(|e| GranularError::Format {
                    path: json_path.display().to_string(),
                    reason: e.to_string(),
                })
            })?;
        let corner = |key: &str| -> Result<Vec3, GranularError> {
            let v: Option<Vec<f64>> = meta[key]
                .as_array()
                .map(|a| a.iter().filter_map(Value::as_f64).collect());
            match v {
                Some(v) if v.len() == 3 => Ok(Vec3::new(v[0], v[1], v[2])),
                _ => Err(GranularError::Format {
                    path: json_path.display().to_string(),
                    reason: format!("`{key}` must be [x, y, z]"),
                }),
            }
        };
        Ok(Packing {
            centers,
            lower: corner("box_min")?,
            upper: corner("box_max")?,
        })
    }
}

/// The bytes a Verlet step of a sphere packing moves per sphere, with `candidates` candidate
/// contacts (pairs and wall contacts) per sphere, each array read or written once per pass:
/// the kick and drift of x, v, a and θ, ω, θ̈ (240 B), the sphere read (x, v, ω and the
/// build position in, a 96-byte sphere record out: 192 B), zeroing the forces and moments
/// (48 B), per candidate its 64-byte record read and written by the fused pass of narrow
/// phase, law and sums, with the slot of its second sphere (132 B; the partners' records and
/// the per-sphere sums stay in cache within a run), the sums out and into the particle forces
/// and moments (48 + 144 B), gravity (56 B), and a = f/m, θ̈ = M/J with the second half kick
/// (210 B). Before the fused pass (issue 37) each 112-byte record was also read twice by a
/// gather, with two incidence entries: 456 B per candidate; with the fused pass and that
/// record, 228 B.
pub fn bytes_per_sphere_step(candidates: f64) -> f64 {
    240.0 + 192.0 + 48.0 + 132.0 * candidates + 192.0 + 56.0 + 210.0
}

/// Initialises a Verlet stepper of step `dt` and times `steps` steps (the initial force
/// evaluation excluded); returns the stepper and the wall seconds.
fn timed_steps(
    state: &mut State,
    models: &mut [Box<dyn Model>],
    dt: f64,
    steps: usize,
) -> Result<(Verlet, f64), GranularError> {
    let mut stepper = Verlet::new(dt);
    stepper.initialize(state, models)?;
    let start = Instant::now();
    for _ in 0..steps {
        stepper.step(state, models)?;
    }
    Ok((stepper, start.elapsed().as_secs_f64()))
}

/// The packing's contact model, which its builders put first.
fn first_contacts(models: &[Box<dyn Model>]) -> &DemContacts {
    let model: &dyn std::any::Any = models[0].as_ref();
    model.downcast_ref::<DemContacts>().expect("contacts first")
}

/// Times `steps` Verlet steps of the packing with its spheres replaced by clumps
/// ([`Packing::build_clumps`]), with the packing's own step, and returns the JSON record:
/// particle-steps/s counts the contact spheres, clump-steps/s the clumps.
pub fn clump_throughput(packing: &Packing, steps: usize) -> Result<Value, GranularError> {
    let (mut state, mut models, spheres) = packing.build_clumps();
    let dt = {
        let (state, models) = packing.build();
        time_step(&state, &models)
    };
    let bound =
        qdem_core::step::stepper::stable_step(&state, &models).map_or(f64::INFINITY, |b| b.0);
    let (stepper, seconds) = timed_steps(&mut state, &mut models, dt.min(0.9 * bound), steps)?;
    let contacts = first_contacts(&models);
    let clumps = packing.centers.len();
    Ok(json!({
        "code": "qdem",
        "clumps": clumps,
        "spheres": spheres,
        "steps": steps,
        "dt": stepper.dt(),
        "stable_bound": bound,
        "wall_s": seconds,
        "particle_steps_per_s": (spheres * steps) as f64 / seconds,
        "clump_steps_per_s": (clumps * steps) as f64 / seconds,
        "threads": rayon::current_num_threads(),
        "contacts": contacts.contacts(),
        "rebuilds": contacts.rebuilds(),
        "kinetic_energy": state.kinetic_energy(),
    }))
}

/// Times `steps` Verlet steps of the packing (after the initial force evaluation, as
/// LIGGGHTS's "Loop time" excludes its set-up) and returns the JSON record.
pub fn throughput(packing: &Packing, steps: usize) -> Result<Value, GranularError> {
    let (mut state, mut models) = packing.build();
    let dt = time_step(&state, &models);
    let bound =
        qdem_core::step::stepper::stable_step(&state, &models).map_or(f64::INFINITY, |b| b.0);
    let (_, seconds) = timed_steps(&mut state, &mut models, dt, steps)?;
    let contacts = first_contacts(&models);
    let n = packing.centers.len();
    let candidates = contacts.candidates() as f64 / n as f64;
    Ok(json!({
        "code": "qdem",
        "spheres": n,
        "candidates_per_sphere": candidates,
        "bytes_per_particle_step": bytes_per_sphere_step(candidates),
        "triad_bytes_per_s": crate::throughput::triad_bandwidth(rayon::current_num_threads()),
        "steps": steps,
        "dt": dt,
        "stable_bound": bound,
        "wall_s": seconds,
        "particle_steps_per_s": (n * steps) as f64 / seconds,
        "threads": rayon::current_num_threads(),
        "contacts": contacts.contacts(),
        "rebuilds": contacts.rebuilds(),
        "kinetic_energy": state.kinetic_energy(),
    }))
}
