//! `kernel_steps [--tets N | --stones N] [--viscous] [--separate-passes] [--steps S]`: the
//! Verlet steps of one `qdem bench` body (a cube of about N tetrahedra, or N stones of 108 as
//! one body; `qdem_bench::throughput`) on a pool of one thread (so that every pass runs on the
//! thread that calls `steps`), untimed, for counting what a step costs with a tool that does
//! not depend on the machine's load:
//!
//! ```sh
//! valgrind --tool=callgrind --cache-sim=yes --toggle-collect='kernel_steps::steps' \
//!     target/release/kernel_steps --tets 100000 --steps 5
//! ```
//!
//! counts the instructions, data reads and writes and cache misses of the S steps alone (the
//! body is built and initialised outside `steps`). `--separate-passes` integrates in the
//! stepper's sweeps (the traffic before the fused step). Prints one JSON line: the body and a
//! checksum of its final positions (the same for both ways of integrating).

use qdem_bench::throughput::{block, on_threads, stones_body};
use qdem_core::{solvers::Verlet, step::Model, step::State, step::Stepper};
use serde_json::json;

/// The command line: `(tets, stones, viscous, separate, steps)`.
fn arguments() -> Result<(usize, Option<usize>, bool, bool, usize), String> {
    let (mut tets, mut stones, mut viscous, mut separate, mut steps) =
        (100_000, None, false, false, 5);
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        let mut count = || -> Result<usize, String> {
            let value = args.next().ok_or(format!("{flag} needs a count"))?;
            value
                .parse::<usize>()
                .ok()
                .filter(|&n| n > 0)
                .ok_or(format!("{flag} {value}: give a whole number of at least 1"))
        };
        match flag.as_str() {
            "--tets" => tets = count()?,
            "--stones" => stones = Some(count()?),
            "--steps" => steps = count()?,
            "--viscous" => viscous = true,
            "--separate-passes" => separate = true,
            _ => {
                return Err(format!(
                    "unknown argument {flag}: see the file's first lines"
                ))
            }
        }
    }
    Ok((tets, stones, viscous, separate, steps))
}

/// The steps counted.
#[inline(never)]
fn steps(stepper: &mut Verlet, state: &mut State, models: &mut [Box<dyn Model>], count: usize) {
    for _ in 0..count {
        stepper.step(state, models).expect("a stable step");
    }
}

fn main() {
    let (tets, stones, viscous, separate, count) = match arguments() {
        Ok(a) => a,
        Err(message) => {
            eprintln!("kernel_steps: {message}");
            std::process::exit(2);
        }
    };
    on_threads(1, || run(tets, stones, viscous, separate, count));
}

/// Builds the body, steps it `count` times and prints the line.
fn run(tets: usize, stones: Option<usize>, viscous: bool, separate: bool, count: usize) {
    let (body, mut state) = match stones {
        Some(n) => stones_body(n, viscous),
        None => block(tets, viscous),
    };
    let (tets, layout) = (body.tets().len(), body.block_layout());
    let dt = 0.9 * body.stable_dt(&state).expect("a body bounds the step");
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(body)];
    let mut stepper = match separate {
        true => Verlet::new(dt).with_separate_passes(),
        false => Verlet::new(dt),
    };
    stepper
        .initialize(&mut state, &mut models)
        .expect("a stable start");
    steps(&mut stepper, &mut state, &mut models, count);
    let checksum: f64 = state.position.iter().map(|x| x.sum()).sum();
    let line = json!({
        "tets": tets, "particles": state.len(), "block_nodes": layout.block_nodes,
        "interior_particles": layout.interior, "stones": stones, "viscous": viscous,
        "separate_passes": separate, "steps": count, "position_checksum": checksum,
    });
    println!("{line}");
}
