//! Throughput of the QDEM kernel (one Verlet step: tetrahedron forces, gather, integration) on
//! structured meshes, elastic and viscoelastic, for several thread counts, in
//! tetrahedron-steps per second. A STREAM-like triad measured in the same process gives the
//! machine's memory bandwidth, the peer against which the kernel's compulsory memory traffic
//! per tet-step is judged.

use qdem_core::{Material, Model, State, Stepper, TetBody, Vec3, Verlet};
use qdem_mesh::structured_box;
use std::time::Instant;

/// What to measure.
#[derive(Clone, Debug)]
pub struct BenchPlan {
    /// Approximate tetrahedron counts (each rounded to a cube of 6-tet cells).
    pub tets: Vec<usize>,
    /// Thread counts.
    pub threads: Vec<usize>,
    /// Steps per measurement (default: enough for about one second, at least 3).
    pub steps: Option<usize>,
}

impl BenchPlan {
    /// The plan from the command line, defaulting to 10⁴, 10⁵, 10⁶ tets on 1 and 2 threads.
    pub fn new(
        tets: Option<Vec<usize>>,
        threads: Option<Vec<usize>>,
        steps: Option<usize>,
    ) -> BenchPlan {
        BenchPlan {
            tets: tets.unwrap_or_else(|| vec![10_000, 100_000, 1_000_000]),
            threads: threads.unwrap_or_else(|| vec![1, 2]),
            steps,
        }
    }
}

/// One measurement.
#[derive(Clone, Debug)]
pub struct BenchResult {
    /// Tetrahedra.
    pub tets: usize,
    /// Particles.
    pub particles: usize,
    /// Whether the viscous path ran.
    pub viscous: bool,
    /// Threads.
    pub threads: usize,
    /// Steps timed.
    pub steps: usize,
    /// Wall seconds for those steps.
    pub seconds: f64,
}

impl BenchResult {
    /// Tetrahedron-steps per second.
    pub fn tet_steps_per_second(&self) -> f64 {
        (self.tets * self.steps) as f64 / self.seconds
    }

    /// Compulsory memory traffic of one step divided by the tetrahedra (bytes): per tetrahedron
    /// its 4 indices and dX⁻¹ (88 B), the force buffer written and read back (192 B) and the
    /// incidence entries (16 B); per particle positions, velocities, accelerations read and
    /// written across the two half kicks and the drift (~216 B), force written and read
    /// (48 B), mass and fixity (9 B), gathered positions (24 B, 48 B with velocities).
    pub fn bytes_per_tet_step(&self) -> f64 {
        let per_tet = 88.0 + 192.0 + 16.0;
        let per_particle = 216.0 + 48.0 + 9.0 + if self.viscous { 48.0 } else { 24.0 };
        per_tet + per_particle * self.particles as f64 / self.tets as f64
    }
}

/// A structured block of about `tets` tetrahedra with the cantilever's material.
pub fn block(tets: usize, viscous: bool) -> (TetBody, State) {
    let n = ((tets as f64 / 6.0).cbrt().round() as usize).max(1);
    let mesh = structured_box([0.0; 3], [1.0, 1.0, 1.0], [n, n, n]);
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let mut material = Material::elastic(2350.0, 45e9, 0.167);
    if viscous {
        material.shear_viscosity = 1e4;
        material.bulk_viscosity = 1e3;
    }
    let body = TetBody::new("block", &reference, mesh.tets, material).expect("valid block");
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    // A small smooth initial velocity so that the kernel works on a deformed state.
    for (v, x) in state.velocity.iter_mut().zip(&state.reference) {
        *v = Vec3::new((3.0 * x.y).sin(), (2.0 * x.z).cos(), (x.x * 5.0).sin()) * 1e-3;
    }
    (body, state)
}

/// Times Verlet steps of `block(tets, viscous)` on `threads` threads.
pub fn measure(tets: usize, viscous: bool, threads: usize, steps: Option<usize>) -> BenchResult {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let (body, mut state) = block(tets, viscous);
        let tets = body.tets().len();
        let dt = 0.9 * body.stable_dt(&state).expect("a body bounds the step");
        let mut models: Vec<Box<dyn Model>> = vec![Box::new(body)];
        let mut stepper = Verlet::new(dt);
        stepper.initialize(&mut state, &mut models).expect("stable");
        let warm = Instant::now();
        for _ in 0..3 {
            stepper.step(&mut state, &mut models).expect("stable");
        }
        let per_step = warm.elapsed().as_secs_f64() / 3.0;
        let steps = steps.unwrap_or(((1.0 / per_step) as usize).clamp(3, 2000));
        let start = Instant::now();
        for _ in 0..steps {
            stepper.step(&mut state, &mut models).expect("stable");
        }
        BenchResult {
            tets,
            particles: state.len(),
            viscous,
            threads,
            steps,
            seconds: start.elapsed().as_secs_f64(),
        }
    })
}

/// STREAM-like triad a = b + s·c over 3 × 128 MiB on `threads` threads, in bytes/s (counting
/// two reads and one write per element).
pub fn triad_bandwidth(threads: usize) -> f64 {
    use rayon::prelude::*;
    let n = 16 << 20;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let (b, c) = (vec![1.0f64; n], vec![2.0f64; n]);
        let mut a = vec![0.0f64; n];
        let mut best = f64::INFINITY;
        for _ in 0..5 {
            let start = Instant::now();
            a.par_iter_mut()
                .zip(b.par_iter().zip(c.par_iter()))
                .with_min_len(1 << 16)
                .for_each(|(a, (b, c))| *a = b + 3.0 * c);
            best = best.min(start.elapsed().as_secs_f64());
        }
        assert!(a[n / 2] == 7.0);
        (3 * 8 * n) as f64 / best
    })
}

/// The CPU model from /proc/cpuinfo, or "unknown".
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}
