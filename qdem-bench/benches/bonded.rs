//! Criterion benchmark of paper 001's bonded beam (`fixtures/bbm`, 7,898 particles: the scene
//! with the paper's 7,676-element count) before it cracks:
//!
//! - one explicit Newmark step (β = 0, adaptive, the scene's ∆t), in particle-steps/s
//!   (criterion's "elements"), the paper's Table 1 t_b;
//! - one implicit Newmark step (β = ¼, ∆t = 5 ms) on the kept factorisation, Table 2's t_b;
//! - one refactorisation of the implicit step's matrix M + γ∆tC + β∆t²K
//!   ([`Newmark::refactorize`]: tangent, damping rows, assembly into the kept pattern, numeric
//!   Cholesky), what every step that breaks a bond or changes a contact repeats while the beam
//!   cracks.
//!
//! On one thread, inside its pool as `qdem run --threads 1` runs (a parallel loop started from
//! outside the pool waits for a worker at every call). The whole runs to the failure, with
//! their totals, are in `docs/bbm.md`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use qdem_bench::throughput::on_threads;
use qdem_core::{solvers::Newmark, step::Scheme, step::Stepper};
use qdem_io::build::Simulation;
use qdem_io::scene::Scene;
use std::path::Path;
use std::time::Instant;

/// A time (s) by which no bond has come near its strength (the first breaks at 0.23 s).
const UNCRACKED: f64 = 0.15;

/// The benchmark scene `beam_{kind}_n7676.toml`, built.
fn beam(kind: &str) -> Simulation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fixtures/bbm")
        .join(format!("beam_{kind}_n7676.toml"));
    Simulation::build(Scene::load(&path).expect("scene")).expect("built")
}

fn newmark_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("bonded_beam_step");
    group.sample_size(20);
    for kind in ["explicit", "implicit"] {
        let mut sim = beam(kind);
        let start = sim.world.state.clone();
        group.throughput(Throughput::Elements(sim.world.state.len() as u64));
        group.bench_function(BenchmarkId::new(kind, sim.world.state.len()), |b| {
            b.iter_custom(|iterations| {
                on_threads(1, || {
                    let world = &mut sim.world;
                    world.initialize().expect("initialised");
                    let begin = Instant::now();
                    for _ in 0..iterations {
                        // Back to the start before the ramped load brings the first crack.
                        if world.state.time > UNCRACKED {
                            world.state.copy_motion_from(&start);
                        }
                        world.step().expect("step");
                    }
                    begin.elapsed()
                })
            })
        });
    }
    group.finish();
}

fn implicit_refactorisation(c: &mut Criterion) {
    let mut sim = beam("implicit");
    let Scheme::Newmark { beta, gamma } = sim.world.settings().request.scheme else {
        panic!("the implicit beam steps by Newmark")
    };
    let mut stepper = Newmark::new(beta, gamma, sim.world.dt()).expect("implicit Newmark");
    let world = &mut sim.world;
    stepper
        .initialize(&mut world.state, &mut world.models)
        .expect("initialised");
    let mut group = c.benchmark_group("bonded_beam_refactorisation");
    group.sample_size(20);
    group.bench_function(BenchmarkId::new("implicit", world.state.len()), |b| {
        b.iter_custom(|iterations| {
            on_threads(1, || {
                let begin = Instant::now();
                for _ in 0..iterations {
                    stepper
                        .refactorize(&world.state, &world.models)
                        .expect("factorised");
                }
                begin.elapsed()
            })
        })
    });
    group.finish();
}

criterion_group!(benches, newmark_step, implicit_refactorisation);
criterion_main!(benches);
