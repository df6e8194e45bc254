//! - `study speed-vs-error [--docs DIR] [--work DIR] [--meshes 100,070,050] [--dts 1e-3,3e-4,1e-4]`:
//!   regenerates the cantilever's section of `docs/speed-vs-error.md` and its plots (about 25
//!   minutes on 2 cores, dominated by the explicit run on the finest mesh).
//! - `study speed-vs-error --all` (every family) or `--families bbm,packing` (those, keeping
//!   the others' sections), with `--quick` for the tests' small sweeps and `--threads N`
//!   (default: rayon's): regenerates those sections and their SVGs.
//! - `study packing --spheres N --out DIR [--settle SECONDS]`: pours and settles N rigid
//!   spheres and writes `DIR/packing.csv` and `DIR/packing.json` (the granular benchmark).
//! - `study dem-throughput --packing DIR --steps S [--grains spheres|clumps]`: times qdem on
//!   that packing (with `clumps`, every sphere replaced by a rigid clump of 2–4 spheres inside
//!   it) and prints one JSON object.
//! - `study kernel-steps --tets N --steps S [--ordering structured|shuffled|reordered|blocked]
//!   [--threads T] [--viscous]`: `qdem bench`'s measurement of one block in one node ordering
//!   (3 warm steps, then S timed), one JSON object: the run to give a cache simulator
//!   (`valgrind --tool=callgrind --cache-sim=yes`), where the orderings' misses can be counted
//!   on a loaded machine. `--stones N` in place of `--tets`: N fine stones as one body
//!   (`qdem bench --stones`).

use qdem_bench::cantilever::fixtures_dir;
use qdem_bench::granular::{clump_throughput, throughput, Packing};
use qdem_bench::speed_vs_error::{run_family, write_page, Family, Setting, Size};
use qdem_bench::throughput::{
    check_block, check_stones, cpu_model, measure_body, measure_ordered, on_threads, stones_mesh,
    Ordering,
};
use qdem_core::continuum::Formulation;
use std::path::PathBuf;
use std::process::ExitCode;

const USAGE: &str = "usage: study speed-vs-error [--all | --families cantilever,bbm,boxtest,packing,track] [--quick] [--threads N] [--docs DIR] [--work DIR] [--meshes 100,070,050] [--dts 1e-3,3e-4,1e-4]
       study packing --spheres N --out DIR [--settle SECONDS]
       study dem-throughput --packing DIR --steps S [--grains spheres|clumps]
       study kernel-steps (--tets N | --stones N) --steps S [--ordering structured|shuffled|reordered|blocked] [--threads T] [--viscous]";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let option = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let flag = |name: &str| args.iter().any(|a| a == name);
    let threads = match number(&option, "--threads", Some(0)) {
        Ok(n) => n,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    // Inside a pool of rayon's default size unless told, as `qdem run` runs.
    on_threads(threads, || match args.first().map(String::as_str) {
        Some("speed-vs-error") => speed_vs_error(&option, &flag),
        Some("packing") => packing(&option),
        Some("dem-throughput") => dem_throughput(&option),
        Some("kernel-steps") => kernel_steps(&option, args.iter().any(|a| a == "--viscous")),
        _ => {
            eprintln!("{USAGE}");
            ExitCode::FAILURE
        }
    })
}

/// A required numeric option, or a message.
fn number<T: std::str::FromStr>(
    option: &dyn Fn(&str) -> Option<String>,
    name: &str,
    default: Option<T>,
) -> Result<T, String> {
    match (option(name), default) {
        (Some(v), _) => v
            .parse()
            .map_err(|_| format!("{name} takes a number, got `{v}`")),
        (None, Some(d)) => Ok(d),
        (None, None) => Err(format!("{name} is required\n{USAGE}")),
    }
}

fn packing(option: &dyn Fn(&str) -> Option<String>) -> ExitCode {
    let run = || -> Result<PathBuf, String> {
        let n: usize = number(option, "--spheres", None)?;
        let settle: f64 = number(option, "--settle", Some(0.4))?;
        let out = option("--out").ok_or(format!("--out is required\n{USAGE}"))?;
        let mut packing = Packing::lattice(n);
        packing.settle(settle).map_err(|e| e.to_string())?;
        packing.write(out.as_ref()).map_err(|e| e.to_string())?;
        Ok(PathBuf::from(out))
    };
    match run() {
        Ok(dir) => {
            eprintln!("wrote {}/packing.csv and packing.json", dir.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Prints a subcommand's JSON record, or its error on stderr with a failing exit code.
fn print_record(record: Result<String, String>) -> ExitCode {
    match record {
        Ok(json) => {
            println!("{json}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn dem_throughput(option: &dyn Fn(&str) -> Option<String>) -> ExitCode {
    let run = || -> Result<String, String> {
        let steps: usize = number(option, "--steps", None)?;
        let dir = option("--packing").ok_or(format!("--packing is required\n{USAGE}"))?;
        let packing = Packing::read(dir.as_ref()).map_err(|e| e.to_string())?;
        let record = match option("--grains").as_deref() {
            None | Some("spheres") => throughput(&packing, steps),
            Some("clumps") => clump_throughput(&packing, steps),
            Some(other) => return Err(format!("--grains {other}: spheres or clumps\n{USAGE}")),
        };
        let record = record.map_err(|e| e.to_string())?;
        Ok(record.to_string())
    };
    print_record(run())
}

fn kernel_steps(option: &dyn Fn(&str) -> Option<String>, viscous: bool) -> ExitCode {
    let run = || -> Result<String, String> {
        let steps: usize = number(option, "--steps", None)?;
        let threads: usize = number(option, "--threads", Some(1))?;
        let ordering: Ordering = option("--ordering")
            .unwrap_or_else(|| "structured".into())
            .parse()
            .map_err(|e| format!("--ordering {e}\n{USAGE}"))?;
        let r = match option("--stones") {
            Some(_) => {
                if option("--ordering").is_some() || option("--tets").is_some() {
                    return Err(format!(
                        "--stones takes neither --tets nor --ordering\n{USAGE}"
                    ));
                }
                let stones: usize = number(option, "--stones", None)?;
                check_stones(stones).map_err(|e| e.to_string())?;
                let mesh = stones_mesh(stones);
                measure_body(mesh, viscous, Formulation::Standard, threads, Some(steps))
            }
            None => {
                let tets: usize = number(option, "--tets", None)?;
                check_block(tets, false).map_err(|e| e.to_string())?;
                measure_ordered(tets, ordering, viscous, threads, Some(steps))
            }
        };
        let record = serde_json::json!({
            "tets": r.tets, "particles": r.particles, "block_nodes": r.block_nodes,
            "ordering": format!("{ordering:?}").to_lowercase(), "viscous": viscous,
            "threads": threads, "steps": r.steps,
            "tet_steps_per_second": r.tet_steps_per_second(),
            "bytes_per_tet_step": r.bytes_per_tet_step(),
        });
        Ok(record.to_string())
    };
    print_record(run())
}

/// The families to run: `--all`, `--families a,b`, or the cantilever alone.
fn families(
    option: &dyn Fn(&str) -> Option<String>,
    flag: &dyn Fn(&str) -> bool,
) -> Result<Vec<Family>, String> {
    match (flag("--all"), option("--families")) {
        (true, Some(_)) => Err("--all and --families: give one".into()),
        (true, None) => Ok(Family::ALL.to_vec()),
        (false, Some(names)) => names.split(',').map(Family::parse).collect(),
        (false, None) => Ok(vec![Family::Cantilever]),
    }
}

/// The machine line of a section: the CPU, the threads and the load when the family started.
fn machine() -> String {
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "unknown".into());
    let cpus = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!(
        "Machine: {}, {} thread(s) of {cpus} CPUs, load average {load} when the family started",
        cpu_model(),
        rayon::current_num_threads()
    )
}

fn speed_vs_error(
    option: &dyn Fn(&str) -> Option<String>,
    flag: &dyn Fn(&str) -> bool,
) -> ExitCode {
    let docs =
        option("--docs").map_or_else(|| fixtures_dir().join("..").join("docs"), PathBuf::from);
    let work = option("--work").map_or_else(|| PathBuf::from("out/study"), PathBuf::from);
    let meshes = option("--meshes").unwrap_or_else(|| "100,070,050".into());
    let meshes: Vec<&str> = meshes.split(',').collect();
    let dts: Result<Vec<f64>, _> = option("--dts")
        .unwrap_or_else(|| "1e-3,3e-4,1e-4".into())
        .split(',')
        .map(str::parse)
        .collect();
    let Ok(dts) = dts else {
        eprintln!("error: --dts takes numbers of seconds, e.g. 1e-3,3e-4");
        return ExitCode::FAILURE;
    };
    let families = match families(option, flag) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}\n{USAGE}");
            return ExitCode::FAILURE;
        }
    };
    let size = if flag("--quick") {
        Size::Quick
    } else {
        Size::Full
    };
    let figures = docs.join("figures");
    let mut sections = Vec::new();
    for family in families {
        let machine = machine();
        let setting = Setting {
            size,
            work: &work,
            figures: &figures,
            machine: &machine,
            cantilever: (&meshes, &dts),
        };
        eprintln!("{}: running ({machine})", family.name());
        match run_family(family, &setting) {
            Ok(markdown) => sections.push((family, markdown)),
            Err(e) => {
                eprintln!("error: {}: {e}", family.name());
                return ExitCode::FAILURE;
            }
        }
    }
    match write_page(&docs, &sections) {
        Ok(()) => {
            eprintln!("wrote {}", docs.join("speed-vs-error.md").display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
