//! `study speed-vs-error [--docs DIR] [--work DIR] [--meshes 100,070,050] [--dts 1e-3,3e-4,1e-4]`:
//! regenerates `docs/speed-vs-error.md` and its plots (about 25 minutes on 2 cores, dominated by
//! the explicit run on the finest mesh).

use qdem_bench::cantilever::fixtures_dir;
use qdem_bench::speed_vs_error::{run_study, write_report};
use qdem_bench::throughput::cpu_model;
use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) != Some("speed-vs-error") {
        eprintln!("usage: study speed-vs-error [--docs DIR] [--work DIR] [--meshes 100,070,050] [--dts 1e-3,3e-4,1e-4]");
        return ExitCode::FAILURE;
    }
    let option = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
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
    let machine = format!("{}, {} threads", cpu_model(), rayon::current_num_threads());
    match run_study(&meshes, &dts, &work).and_then(|rows| write_report(&rows, &machine, &docs)) {
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
