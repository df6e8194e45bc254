//! Throughput of the QDEM kernel (one Verlet step: tetrahedron forces, gather, integration) on
//! structured meshes (or many small stones as one body, [`stones_mesh`]), elastic and
//! viscoelastic, for several thread counts, in tetrahedron-steps per second. A STREAM-like triad measured in the same process gives the
//! machine's memory bandwidth, the peer against which the kernel's compulsory memory traffic
//! per tet-step is judged; the vector peak ([`crate::vector_peak`]) is the peer of its
//! floating-point operations per tet-step. [`run_and_print`] is `qdem bench`: the measurements as a table or as
//! one JSON document.

use crate::vector_peak::vector_peak_flops;
use qdem_core::continuum::averaged_pressure_lanes::{
    FLOPS_AVERAGED_ELASTIC, FLOPS_AVERAGED_VISCOELASTIC,
};
use qdem_core::continuum::prefetch;
use qdem_core::continuum::tet_blocks::block_node_order;
use qdem_core::continuum::tet_lanes::{LaneSet, FLOPS_ELASTIC, FLOPS_VISCOELASTIC};
use qdem_core::{
    continuum::Formulation, continuum::Material, continuum::TetBody, solvers::Verlet, step::Model,
    step::State, step::Stepper, Vec3,
};
use qdem_io::build::memory;
use qdem_mesh::{parse_msh, structured_box, GridError, TetMesh};
use serde_json::json;
use std::path::Path;
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
    /// The tetrahedron measured.
    pub formulation: Formulation,
    /// Instead of the cubes of `tets`: this many stones as one body ([`stones_mesh`]) and a
    /// cube of about their total.
    pub stones: Option<usize>,
}

impl BenchPlan {
    /// The plan from the command line, defaulting to 10⁴, 10⁵, 10⁶ tets on 1 and 2 threads.
    pub fn new(
        tets: Option<Vec<usize>>,
        threads: Option<Vec<usize>>,
        steps: Option<usize>,
        formulation: Formulation,
    ) -> BenchPlan {
        BenchPlan {
            tets: tets.unwrap_or_else(|| vec![10_000, 100_000, 1_000_000]),
            threads: threads.unwrap_or_else(|| vec![1, 2]),
            steps,
            formulation,
            stones: None,
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
    /// Entries of the block sums (`qdem_core::continuum::tet_blocks::BlockLayout::block_nodes`).
    pub block_nodes: usize,
    /// Whether the viscous path ran.
    pub viscous: bool,
    /// The tetrahedron measured.
    pub formulation: Formulation,
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

    /// Compulsory memory traffic of one step divided by the tetrahedra (bytes), for the blocked
    /// kernel of `qdem_core::continuum::tet_blocks`:
    /// - per tetrahedron its hot record, dX⁻¹ and four local corners (80 B);
    /// - per block node (a particle counted once per block that touches it): its index (4 B),
    ///   its position copied in (24 B, 48 B with velocities), its block sum written and read
    ///   back by the gather (48 B) and the gather's entry index (4 B);
    /// - per particle: the gather's range (4 B); the force zeroed, added to and read by the
    ///   accelerations (96 B); the drift and first half kick reading x, v, a and writing x, v
    ///   (120 B); a = f/m with mass and fixity (33 B); the second half kick (72 B).
    ///
    /// The averaged-pressure tetrahedron
    /// ([`qdem_core::continuum::averaged_pressure_tet`]) adds its strain pass and average:
    /// per tetrahedron the pack's corners read again (8 B) and its strain weights (56 B, 64 B
    /// with the viscous weight V_e/4); per block node its index
    /// and position copied in again (28 B, 52 B with velocities), its slot sum written and
    /// read back (48 B), the average's entry index (4 B) and the average copied into the force
    /// pass (24 B); per particle the average's range, inverse volume and average written
    /// (36 B).
    pub fn bytes_per_tet_step(&self) -> f64 {
        let visco = if self.viscous { 24.0 } else { 0.0 };
        let (per_tet, mut per_block_node, mut per_particle) =
            (80.0, 80.0 + visco, 4.0 + 96.0 + 120.0 + 33.0 + 72.0);
        let per_tet = match self.formulation {
            Formulation::Standard => per_tet,
            Formulation::AveragedPressure => {
                per_block_node += 28.0 + visco + 48.0 + 4.0 + 24.0;
                per_particle += 36.0;
                per_tet + 8.0 + if self.viscous { 64.0 } else { 56.0 }
            }
        };
        (per_tet * self.tets as f64
            + per_block_node * self.block_nodes as f64
            + per_particle * self.particles as f64)
            / self.tets as f64
    }

    /// Floating-point operations of one tet-step in the kernel (a multiply-add counted as two;
    /// `qdem_core::continuum::tet_lanes::FLOPS_ELASTIC`): what the vector peak is set against.
    pub fn flops_per_tet_step(&self) -> usize {
        match (self.formulation, self.viscous) {
            (Formulation::Standard, false) => FLOPS_ELASTIC,
            (Formulation::Standard, true) => FLOPS_VISCOELASTIC,
            (Formulation::AveragedPressure, false) => FLOPS_AVERAGED_ELASTIC,
            (Formulation::AveragedPressure, true) => FLOPS_AVERAGED_VISCOELASTIC,
        }
    }
}

/// The ordering of a benchmark mesh's nodes and tetrahedra.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ordering {
    /// The generator's lexicographic order.
    Structured,
    /// Nodes and tetrahedra in a random (seeded) order: what an unsorted mesh file may give.
    Shuffled,
    /// Shuffled, then [`TetMesh::reorder_for_locality`] (reverse Cuthill–McKee).
    Reordered,
    /// The generator's order, then renumbered in the order the kernel's blocks read the nodes
    /// ([`block_node_order`]: each block's nodes one run, shared ones with their first block).
    Blocked,
}

impl std::str::FromStr for Ordering {
    type Err = String;

    /// The ordering by its lower-case name (`structured`, `shuffled`, `reordered`, `blocked`).
    fn from_str(name: &str) -> Result<Ordering, String> {
        let all = [
            Ordering::Structured,
            Ordering::Shuffled,
            Ordering::Reordered,
            Ordering::Blocked,
        ];
        all.into_iter()
            .find(|o| format!("{o:?}").to_lowercase() == name)
            .ok_or_else(|| format!("`{name}`: structured, shuffled, reordered or blocked"))
    }
}

/// The cells along each edge of the block of about `tets` tetrahedra (6 per cell).
fn block_cells(tets: usize) -> usize {
    ((tets as f64 / 6.0).cbrt().round() as usize).max(1)
}

/// Nonzeros of the Cholesky factor of the implicit block at 95,232 unknowns, and the power of
/// the unknowns by which they grow (docs/BENCHMARKS.md: nested dissection of a 3D mesh).
const FACTOR_NONZEROS: (f64, f64, f64) = (154_157_454.0, 95_232.0, 1.5);

/// A block size `qdem bench` cannot build: too large for the memory this process may use
/// (or for a mesh's 32-bit node ids), refused before anything is allocated.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct BlockTooLarge {
    /// The refusal: the size asked for, the memory it needs, the limit and the fix.
    pub message: String,
}

/// Refuses a block of about `tets` tetrahedra that needs more memory than this process may
/// use ([`qdem_io::build::memory`]: the estimate `qdem check` prints for its particles and
/// tetrahedra, and with `implicit` 8 bytes per value of its Cholesky factor, from the growth
/// measured in docs/BENCHMARKS.md), or more nodes than a mesh can number.
///
/// # Errors
/// [`BlockTooLarge`] naming the size, the memory and the fix.
pub fn check_block(tets: usize, implicit: bool) -> Result<(), BlockTooLarge> {
    let n = block_cells(tets) as f64;
    let (nodes, block_tets) = ((n + 1.0).powi(3), 6.0 * n.powi(3));
    let what =
        format!("--tets {tets}: a block of {block_tets:.3e} tetrahedra and {nodes:.3e} nodes");
    let mut bytes = memory::estimate(nodes, block_tets);
    let what = match implicit {
        true => {
            let (nonzeros, unknowns, power) = FACTOR_NONZEROS;
            let factor = 8.0 * nonzeros * (3.0 * nodes / unknowns).powf(power);
            bytes += factor;
            format!(
                "{what} with its Cholesky factor ({})",
                memory::human(factor)
            )
        }
        false => what,
    };
    let refusal = memory::refusal(&what, bytes, "give a smaller --tets");
    if let Some(message) = refusal {
        return Err(BlockTooLarge { message });
    }
    if nodes > f64::from(u32::MAX) {
        let too_many = GridError::TooManyNodes {
            cells: [n as usize; 3],
            nodes: nodes as u128,
        };
        return Err(BlockTooLarge {
            message: format!("--tets {tets}: {too_many}"),
        });
    }
    Ok(())
}

/// A structured unit cube of about `tets` tetrahedra (6 per cell) in the given ordering.
///
/// # Panics
/// For a size [`check_block`] refuses, as the allocation would.
pub fn block_mesh(tets: usize, ordering: Ordering) -> TetMesh {
    let n = block_cells(tets);
    let mut mesh =
        structured_box([0.0; 3], [1.0, 1.0, 1.0], [n, n, n]).expect("a size check_block takes");
    if ordering == Ordering::Blocked {
        let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
        mesh.renumber_nodes(&block_node_order(&reference, &mesh.tets));
        return mesh;
    }
    if ordering != Ordering::Structured {
        let mut seed = 12345u64;
        let nodes = shuffled(mesh.nodes.len(), &mut seed);
        mesh.renumber_nodes(&nodes);
        let order = shuffled(mesh.tets.len(), &mut seed);
        let mut tets = mesh.tets.clone();
        for (old, &new) in order.iter().enumerate() {
            tets[new as usize] = mesh.tets[old];
        }
        mesh.tets = tets;
    }
    if ordering == Ordering::Reordered {
        mesh.reorder_for_locality();
    }
    mesh
}

/// A seeded random permutation of 0..n (new index of each old index).
fn shuffled(n: usize, seed: &mut u64) -> Vec<u32> {
    let mut p: Vec<u32> = (0..n as u32).collect();
    for i in (1..n).rev() {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        p.swap(i, (*seed >> 33) as usize % (i + 1));
    }
    p
}

/// The fine stone meshes of `fixtures/ballast/stones/fine` (about 100 tetrahedra each, as
/// paper 000's ballast, at a mean edge of 19.5 mm, twice the paper's), built into the binary so that `qdem bench --stones` runs
/// from anywhere.
const FINE_STONES: [&[u8]; 16] = [
    include_bytes!("../../fixtures/ballast/stones/fine/stone_00.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_01.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_02.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_03.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_04.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_05.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_06.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_07.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_08.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_09.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_10.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_11.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_12.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_13.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_14.msh"),
    include_bytes!("../../fixtures/ballast/stones/fine/stone_15.msh"),
];

/// The side of the cubic cell each stone of [`stones_mesh`] gets (m): the fine stones' longest
/// bounding-box edge is under 0.1 m.
const STONE_CELL: f64 = 0.12;

/// The fine stones, each read and reordered for locality as `[ballast]` reads its meshes.
fn fine_stones() -> Vec<TetMesh> {
    FINE_STONES
        .iter()
        .enumerate()
        .map(|(k, bytes)| {
            let name = format!("fixtures/ballast/stones/fine/stone_{k:02}.msh");
            let (mut mesh, _) = parse_msh(bytes, Path::new(&name)).expect("a fixture stone");
            mesh.reorder_for_locality();
            mesh
        })
        .collect()
}

/// Nodes and tetrahedra of [`stones_mesh`]`(count)`, counted without building it (as
/// floats: a count too large to build still has a size to refuse).
pub fn stones_size(count: usize) -> (f64, f64) {
    let shapes = fine_stones();
    let (cycles, rest) = (count / shapes.len(), count % shapes.len());
    let (mut nodes, mut tets) = (0.0, 0.0);
    for (k, stone) in shapes.iter().enumerate() {
        let copies = cycles as f64 + f64::from(u8::from(k < rest));
        nodes += copies * stone.nodes.len() as f64;
        tets += copies * stone.tets.len() as f64;
    }
    (nodes, tets)
}

/// Refuses `count` stones ([`stones_mesh`]) that, with the cube of as many tetrahedra timed
/// beside them, need more memory than this process may use, or more nodes than a mesh can
/// number.
///
/// # Errors
/// [`BlockTooLarge`] naming the count, the memory and the fix.
pub fn check_stones(count: usize) -> Result<(), BlockTooLarge> {
    let (nodes, tets) = stones_size(count);
    let what = format!("--stones {count}: {tets:.3e} tetrahedra and {nodes:.3e} nodes");
    if let Some(message) = memory::refusal(
        &what,
        memory::estimate(nodes, tets),
        "give a smaller --stones",
    ) {
        return Err(BlockTooLarge { message });
    }
    if nodes > f64::from(u32::MAX) {
        return Err(BlockTooLarge {
            message: format!("{what}: more nodes than a mesh can number; give a smaller --stones"),
        });
    }
    check_block(tets as usize, false)
}

/// `count` stones as one mesh, as `[ballast]` builds its stones into one body: stone `k` is
/// fine stone `k mod 16` (`fixtures/ballast/stones/fine`), moved into cell `k` of a cubic
/// lattice of [`STONE_CELL`], stone after stone in the node and tetrahedron order. 5,700 of
/// them are paper 000's ballast (about 100 tetrahedra each).
pub fn stones_mesh(count: usize) -> TetMesh {
    let shapes = fine_stones();
    let side = (count as f64).cbrt().ceil().max(1.0) as usize;
    let mut mesh = TetMesh::default();
    for k in 0..count {
        let stone = &shapes[k % shapes.len()];
        let cell = [k % side, (k / side) % side, k / (side * side)];
        let shift = cell.map(|c| STONE_CELL * c as f64);
        let first = mesh.nodes.len() as u32;
        let moved = stone
            .nodes
            .iter()
            .map(|p| std::array::from_fn(|c| p[c] + shift[c]));
        mesh.nodes.extend(moved);
        mesh.tets
            .extend(stone.tets.iter().map(|t| t.map(|n| n + first)));
    }
    mesh
}

/// A body over `mesh` with the cantilever's material (viscous: μ_D = 10⁴, κ_D = 10³ Pa s) and
/// its state with a small smooth velocity, so that the kernel works on a deformed state.
pub fn body_on(mesh: TetMesh, viscous: bool) -> (TetBody, State) {
    let reference: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let mut material = Material::elastic(2350.0, 45e9, 0.167);
    if viscous {
        material.shear_viscosity = 1e4;
        material.bulk_viscosity = 1e3;
    }
    let body = TetBody::new("block", &reference, mesh.tets, material).expect("valid block");
    let mut state = State::at_rest(reference);
    body.lump_mass(&mut state.mass);
    for (v, x) in state.velocity.iter_mut().zip(&state.reference) {
        *v = Vec3::new((3.0 * x.y).sin(), (2.0 * x.z).cos(), (x.x * 5.0).sin()) * 1e-3;
    }
    (body, state)
}

/// A structured block of about `tets` tetrahedra in generator order (see [`body_on`]).
pub fn block(tets: usize, viscous: bool) -> (TetBody, State) {
    body_on(block_mesh(tets, Ordering::Structured), viscous)
}

/// Times Verlet steps of `block(tets, viscous)` on `threads` threads.
pub fn measure(tets: usize, viscous: bool, threads: usize, steps: Option<usize>) -> BenchResult {
    measure_ordered(tets, Ordering::Structured, viscous, threads, steps)
}

/// Times Verlet steps of `block(tets, viscous)` in `formulation` on `threads` threads.
pub fn measure_formulation(
    tets: usize,
    viscous: bool,
    formulation: Formulation,
    threads: usize,
    steps: Option<usize>,
) -> BenchResult {
    let mesh = block_mesh(tets, Ordering::Structured);
    measure_body(mesh, viscous, formulation, threads, steps)
}

/// A body `qdem bench` times.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BenchBody {
    /// A structured cube of about this many tetrahedra ([`block_mesh`]).
    Cube(usize),
    /// This many stones as one body ([`stones_mesh`]).
    Stones(usize),
}

impl BenchBody {
    /// Its mesh.
    pub fn mesh(self) -> TetMesh {
        match self {
            BenchBody::Cube(tets) => block_mesh(tets, Ordering::Structured),
            BenchBody::Stones(count) => stones_mesh(count),
        }
    }

    /// `cube` or `stones`.
    pub fn label(self) -> &'static str {
        match self {
            BenchBody::Cube(_) => "cube",
            BenchBody::Stones(_) => "stones",
        }
    }

    /// The bodies of `plan`: its cubes, or its stones and a cube of about their total.
    pub fn of(plan: &BenchPlan) -> Vec<BenchBody> {
        match plan.stones {
            Some(count) => vec![
                BenchBody::Stones(count),
                BenchBody::Cube(stones_size(count).1 as usize),
            ],
            None => plan.tets.iter().map(|&t| BenchBody::Cube(t)).collect(),
        }
    }
}

/// Times Verlet steps of a block in the given node ordering on `threads` threads.
pub fn measure_ordered(
    tets: usize,
    ordering: Ordering,
    viscous: bool,
    threads: usize,
    steps: Option<usize>,
) -> BenchResult {
    let mesh = block_mesh(tets, ordering);
    measure_body(mesh, viscous, Formulation::Standard, threads, steps)
}

/// Times Verlet steps of the body of [`body_on`] over `mesh` in `formulation` on `threads`
/// threads.
pub fn measure_body(
    mesh: TetMesh,
    viscous: bool,
    formulation: Formulation,
    threads: usize,
    steps: Option<usize>,
) -> BenchResult {
    on_threads(threads, || {
        let (body, mut state) = body_on(mesh, viscous);
        let body = body.with_formulation(formulation);
        let tets = body.tets().len();
        let block_nodes = body.block_layout().block_nodes;
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
            block_nodes,
            viscous,
            formulation,
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
    on_threads(threads, || {
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

/// Runs `work` inside a pool of `threads` threads, 0 for rayon's default (as `qdem run` runs a
/// scene: a parallel loop started from outside a pool waits for a worker at every call).
pub fn on_threads<T: Send>(threads: usize, work: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(work)
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

/// Runs the plan and prints a table or one JSON document.
pub fn run_and_print(plan: &BenchPlan, as_json: bool) {
    let mut results = Vec::new();
    let bandwidth: Vec<(usize, f64)> = plan
        .threads
        .iter()
        .map(|&t| (t, triad_bandwidth(t)))
        .collect();
    let peak: Vec<(usize, f64)> = plan
        .threads
        .iter()
        .map(|&t| (t, vector_peak_flops(t)))
        .collect();
    if !as_json {
        println!(
            "machine: {} ({} cores available)",
            cpu_model(),
            std::thread::available_parallelism().map_or(0, |n| n.get())
        );
        println!("tetrahedron: {}", plan.formulation.name());
        for (t, bw) in &bandwidth {
            println!("triad bandwidth, {t} threads: {:.2} GB/s", bw / 1e9);
        }
        for (t, p) in &peak {
            println!(
                "vector peak ({:?}), {t} threads: {:.1} Gflop/s",
                LaneSet::detected(),
                p / 1e9
            );
        }
        println!(
            "{:>7} {:>9} {:>9} {:>8} {:>7} {:>6} {:>14} {:>10} {:>10} {:>10}",
            "body",
            "tets",
            "particles",
            "material",
            "threads",
            "steps",
            "tet-steps/s",
            "B/tet-step",
            "% of triad",
            "% of peak"
        );
    }
    for body in BenchBody::of(plan) {
        for viscous in [false, true] {
            for &threads in &plan.threads {
                let r = measure_body(body.mesh(), viscous, plan.formulation, threads, plan.steps);
                let bw = bandwidth
                    .iter()
                    .find(|b| b.0 == threads)
                    .map_or(f64::NAN, |b| b.1);
                let fraction = r.tet_steps_per_second() * r.bytes_per_tet_step() / bw;
                let peak = peak
                    .iter()
                    .find(|p| p.0 == threads)
                    .map_or(f64::NAN, |p| p.1);
                let of_peak = r.tet_steps_per_second() * r.flops_per_tet_step() as f64 / peak;
                if !as_json {
                    println!(
                        "{:>7} {:>9} {:>9} {:>8} {:>7} {:>6} {:>14.4e} {:>10.0} {:>9.0}% {:>9.0}%",
                        body.label(),
                        r.tets,
                        r.particles,
                        if viscous { "visco" } else { "elastic" },
                        threads,
                        r.steps,
                        r.tet_steps_per_second(),
                        r.bytes_per_tet_step(),
                        100.0 * fraction,
                        100.0 * of_peak
                    );
                }
                results.push(json!({
                    "body": body.label(),
                    "tets": r.tets, "particles": r.particles, "block_nodes": r.block_nodes,
                    "material": if viscous { "viscoelastic" } else { "elastic" },
                    "formulation": r.formulation.name(),
                    "threads": r.threads, "steps": r.steps, "seconds": r.seconds,
                    "tet_steps_per_second": r.tet_steps_per_second(),
                    "particle_steps_per_second": (r.particles * r.steps) as f64 / r.seconds,
                    "bytes_per_tet_step": r.bytes_per_tet_step(),
                    "fraction_of_triad_bandwidth": fraction,
                    "flops_per_tet_step": r.flops_per_tet_step(),
                    "fraction_of_vector_peak": of_peak,
                }));
            }
        }
    }
    let locality = locality_rows(plan, as_json);
    if as_json {
        let doc = json!({
            "locality": locality,
            "machine": { "cpu": cpu_model(), "cores": std::thread::available_parallelism().map_or(0, |n| n.get()) },
            "kernel_lanes": format!("{:?}", LaneSet::detected()).to_lowercase(),
            "prefetch": prefetch::enabled(),
            "vector_peak_flops_per_second": peak.iter().map(|(t, p)| json!({"threads": t, "value": p})).collect::<Vec<_>>(),
            "triad_bandwidth_bytes_per_second": bandwidth.iter().map(|(t, b)| json!({"threads": t, "value": b})).collect::<Vec<_>>(),
            "results": results,
        });
        println!("{}", serde_json::to_string_pretty(&doc).expect("json"));
    }
}

/// Effect of node ordering: the largest planned block, elastic, on the most threads, in
/// generator order, shuffled, shuffled then reordered (reverse Cuthill–McKee), and in the
/// order the blocks read the nodes; none for a plan of stones.
fn locality_rows(plan: &BenchPlan, as_json: bool) -> Vec<serde_json::Value> {
    let (Some(&tets), Some(&threads)) = (plan.tets.iter().max(), plan.threads.iter().max()) else {
        return Vec::new();
    };
    if plan.stones.is_some() {
        return Vec::new();
    }
    if !as_json {
        println!("node ordering, {tets} tets, elastic, {threads} threads:");
    }
    let orderings = [
        Ordering::Structured,
        Ordering::Shuffled,
        Ordering::Reordered,
        Ordering::Blocked,
    ];
    orderings
        .into_iter()
        .map(|ordering| {
            let r = measure_ordered(tets, ordering, false, threads, plan.steps);
            if !as_json {
                println!("{:>12?} {:>14.4e} tet-steps/s", ordering, r.tet_steps_per_second());
            }
            json!({"ordering": format!("{ordering:?}").to_lowercase(), "tets": r.tets, "threads": threads, "tet_steps_per_second": r.tet_steps_per_second()})
        })
        .collect()
}
