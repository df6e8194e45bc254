//! Criterion benchmark of one explicit Verlet step of the QDEM kernel on structured blocks of
//! about 10⁴ and 10⁵ tetrahedra, elastic and viscoelastic, in tet-steps/s (criterion's
//! "elements" throughput). The 10⁶ case runs in `qdem bench`, which needs no statistics to be
//! steady at that size.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use qdem_bench::throughput::block;
use qdem_core::{solvers::Verlet, step::Model, step::Stepper};

fn verlet_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("verlet_step");
    group.sample_size(20);
    for tets in [10_000, 100_000] {
        for viscous in [false, true] {
            let (body, mut state) = block(tets, viscous);
            let n = body.tets().len();
            let dt = 0.9 * body.stable_dt(&state).expect("bound");
            let mut models: Vec<Box<dyn Model>> = vec![Box::new(body)];
            let mut stepper = Verlet::new(dt);
            stepper.initialize(&mut state, &mut models).expect("stable");
            group.throughput(Throughput::Elements(n as u64));
            let label = if viscous { "viscoelastic" } else { "elastic" };
            group.bench_function(BenchmarkId::new(label, n), |b| {
                b.iter(|| stepper.step(&mut state, &mut models).expect("stable"))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, verlet_step);
criterion_main!(benches);
