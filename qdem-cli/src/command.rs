//! Command-line parsing and the four commands. Errors from the libraries are rendered once,
//! by `main`, through [`CliError`]'s `Display`.

use crate::{check, progress};
use qdem_bench::throughput::BenchPlan;
use qdem_bench::{implicit, throughput, verify};
use qdem_core::CoreError;
use qdem_io::build::{BuildError, Simulation};
use qdem_io::runner::{run_with, RunError, RunOptions};
use qdem_io::scene::{Scene, SceneError};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use thiserror::Error;

/// Usage text.
pub const USAGE: &str = "\
usage:
  qdem run SCENE [--out DIR] [--threads N] [--resume CHECKPOINT]
                                             run a scene; outputs go to DIR (default: the scene's [output] dir);
                                             Ctrl-C or SIGTERM stops it with DIR/checkpoint.qdc, which --resume continues
  qdem check SCENE [--threads N]             validate a scene; print meshes, mass, stable dt, cost estimate
  qdem analyze SCENE [--out DIR] [--from T] [--to T] [--bandwidth HZ] [--fmax HZ]
                                             spectra (Parzen window, default 20 Hz) and mobility of a finished
                                             run's probes into DIR/analysis (default: the scene's [output] dir)
  qdem verify [--json] [--full [--out DIR]]  run the analytical fixtures (--full adds the cantilever meshes,
                                             keeping their outputs and plots in DIR, default out/verify)
  qdem bench [--json] [--tets N,N,..] [--threads N,N,..] [--steps N]
                                             kernel throughput on structured meshes, tet-steps/s
  qdem bench --implicit [--json] [--tets N,..] [--threads N]
                                             sparse Cholesky: factorisation, solve and implicit step vs unknowns";

/// Everything the command line reports as an error.
#[derive(Debug, Error)]
pub enum CliError {
    /// Bad command-line usage.
    #[error("{0}\n{USAGE}")]
    Usage(String),
    /// A scene that does not parse or validate.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A scene that cannot be built.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// A run that failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A verification fixture that failed to run or missed its tolerance.
    #[error(transparent)]
    Verify(#[from] verify::VerifyError),
    /// A measurement of `qdem bench --implicit` failed.
    #[error(transparent)]
    Bench(#[from] CoreError),
    /// An analysis that could not be made.
    #[error(transparent)]
    Analyze(#[from] qdem_io::analyze::AnalyzeError),
    /// The thread pool could not be set up.
    #[error("cannot start {threads} threads: {message}")]
    Threads {
        /// Requested threads.
        threads: usize,
        /// Why.
        message: String,
    },
}

/// Parsed options common to the commands.
#[derive(Debug, Default)]
struct Options {
    positional: Vec<String>,
    out: Option<PathBuf>,
    threads: Option<Vec<usize>>,
    json: bool,
    full: bool,
    implicit: bool,
    tets: Option<Vec<usize>>,
    steps: Option<usize>,
    resume: Option<PathBuf>,
    analyze: qdem_io::analyze::AnalyzeOptions,
}

/// A finite non-negative number of seconds or hertz.
fn parse_number(flag: &str, value: &str) -> Result<f64, CliError> {
    value
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| CliError::Usage(format!("{flag} takes a number >= 0, got `{value}`")))
}

fn parse_list(flag: &str, value: &str) -> Result<Vec<usize>, CliError> {
    value
        .split(',')
        .map(|v| {
            v.trim()
                .parse::<usize>()
                .ok()
                .filter(|&n| n > 0)
                .ok_or_else(|| {
                    CliError::Usage(format!(
                        "{flag} takes positive whole numbers, got `{value}`"
                    ))
                })
        })
        .collect()
}

fn parse(args: &[String], allowed: &[&str]) -> Result<Options, CliError> {
    let mut o = Options::default();
    let mut it = args.iter();
    while let Some(arg) = it.next() {
        if !arg.starts_with("--") {
            o.positional.push(arg.clone());
            continue;
        }
        if !allowed.contains(&arg.as_str()) {
            return Err(CliError::Usage(format!("unknown option `{arg}`")));
        }
        let mut value = || {
            it.next()
                .cloned()
                .ok_or_else(|| CliError::Usage(format!("`{arg}` needs a value")))
        };
        match arg.as_str() {
            "--out" => o.out = Some(PathBuf::from(value()?)),
            "--resume" => o.resume = Some(PathBuf::from(value()?)),
            "--json" => o.json = true,
            "--full" => o.full = true,
            "--implicit" => o.implicit = true,
            "--steps" => o.steps = Some(parse_list(arg, &value()?)?[0]),
            "--tets" => o.tets = Some(parse_list(arg, &value()?)?),
            "--threads" => o.threads = Some(parse_list(arg, &value()?)?),
            "--from" => o.analyze.from = Some(parse_number(arg, &value()?)?),
            "--to" => o.analyze.to = Some(parse_number(arg, &value()?)?),
            "--bandwidth" => o.analyze.bandwidth = parse_number(arg, &value()?)?,
            "--fmax" => o.analyze.max_frequency = parse_number(arg, &value()?)?,
            _ => unreachable!("every allowed option is matched"),
        }
    }
    Ok(o)
}

fn one_scene(o: &Options, command: &str) -> Result<PathBuf, CliError> {
    match o.positional.as_slice() {
        [scene] => Ok(PathBuf::from(scene)),
        [] => Err(CliError::Usage(format!(
            "`qdem {command}` needs a scene file"
        ))),
        more => Err(CliError::Usage(format!(
            "`qdem {command}` takes one scene file, got {}",
            more.len()
        ))),
    }
}

fn no_positional(o: &Options, command: &str) -> Result<(), CliError> {
    match o.positional.first() {
        Some(extra) => Err(CliError::Usage(format!(
            "`qdem {command}` takes no argument `{extra}`"
        ))),
        None => Ok(()),
    }
}

/// The thread pool of `--threads N` (one number for `run` and `check`; rayon's default
/// without it, and for `verify`). Commands run inside it ([`rayon::ThreadPool::install`])
/// rather than on the main thread: a parallel loop started outside the pool is handed to a
/// worker and waited for, a sleep and a wake-up per loop, which cost an explicit bonded-beam
/// step (ten loops of a few microseconds each) about a fifth of its time.
fn thread_pool(threads: Option<&[usize]>) -> Result<rayon::ThreadPool, CliError> {
    let count = match threads {
        Some(&[threads]) => threads,
        Some(_) => return Err(CliError::Usage("--threads takes one number here".into())),
        None => 0,
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(count)
        .build()
        .map_err(|e| CliError::Threads {
            threads: count,
            message: e.to_string(),
        })
}

/// Runs the command named by the first argument.
pub fn dispatch(args: &[String]) -> Result<(), CliError> {
    let Some((command, rest)) = args.split_first() else {
        return Err(CliError::Usage("no command given".into()));
    };
    match command.as_str() {
        "run" => {
            let o = parse(rest, &["--out", "--threads", "--resume"])?;
            let scene = one_scene(&o, "run")?;
            thread_pool(o.threads.as_deref())?
                .install(|| run_scene(&scene, o.out.as_deref(), o.resume.as_deref()))
        }
        "check" => {
            let o = parse(rest, &["--threads"])?;
            let scene = one_scene(&o, "check")?;
            thread_pool(o.threads.as_deref())?.install(|| check::check_scene(&scene))
        }
        "analyze" => {
            let o = parse(rest, &["--out", "--from", "--to", "--bandwidth", "--fmax"])?;
            analyze_run(&one_scene(&o, "analyze")?, o.out.as_deref(), &o.analyze)
        }
        "verify" => {
            let o = parse(rest, &["--json", "--full", "--out"])?;
            no_positional(&o, "verify")?;
            if o.out.is_some() && !o.full {
                return Err(CliError::Usage(
                    "`qdem verify --out DIR` goes with `--full`".into(),
                ));
            }
            let out = o.out.unwrap_or_else(|| PathBuf::from("out/verify"));
            thread_pool(None)?
                .install(|| verify::run_and_print(o.json, o.full.then_some(out.as_path())))
                .map_err(CliError::from)
        }
        "bench" => {
            let o = parse(
                rest,
                &["--json", "--tets", "--threads", "--steps", "--implicit"],
            )?;
            no_positional(&o, "bench")?;
            if o.implicit {
                let threads = o
                    .threads
                    .as_deref()
                    .and_then(|t| t.last().copied())
                    .unwrap_or(2);
                return Ok(implicit::run_and_print(o.tets, threads, o.json)?);
            }
            throughput::run_and_print(&BenchPlan::new(o.tets, o.threads, o.steps), o.json);
            Ok(())
        }
        "help" | "--help" | "-h" => {
            println!("{USAGE}");
            Ok(())
        }
        other => Err(CliError::Usage(format!("unknown command `{other}`"))),
    }
}

fn analyze_run(
    path: &Path,
    out: Option<&Path>,
    options: &qdem_io::analyze::AnalyzeOptions,
) -> Result<(), CliError> {
    let scene = Scene::load(path)?;
    let out_dir = match out {
        Some(dir) => dir.to_path_buf(),
        None => scene.base_dir().join(&scene.output.dir),
    };
    let a = qdem_io::analyze::analyze(&scene, &out_dir, options)?;
    println!(
        "analysed {} rows every {:.4e} s ({:.4} s, frequency step {:.3} Hz), Parzen bandwidth {} Hz",
        a.rows,
        a.dt,
        a.dt * (a.rows - 1) as f64,
        1.0 / (a.dt * a.rows as f64),
        options.bandwidth
    );
    for p in &a.peaks {
        println!(
            "probe `{}`: largest smoothed vertical-acceleration amplitude above 20 Hz at {:.1} Hz ({:.3e} m/s)",
            p.probe, p.frequency, p.amplitude
        );
    }
    if !a.mobility {
        println!("no `series` load in the scene: mobility not computed");
    }
    println!("spectra, mobility and plots in {}", a.dir.display());
    Ok(())
}

/// Set by the Ctrl-C / SIGTERM handler: the run stops after its current step, checkpointed.
static STOP: AtomicBool = AtomicBool::new(false);

fn run_scene(path: &Path, out: Option<&Path>, resume: Option<&Path>) -> Result<(), CliError> {
    let scene = Scene::load(path)?;
    let out_dir = match out {
        Some(dir) => dir.to_path_buf(),
        None => path
            .parent()
            .unwrap_or(Path::new("."))
            .join(&scene.output.dir),
    };
    let mut sim = Simulation::build(scene)?;
    for w in &sim.warnings {
        eprintln!("warning: {w}");
    }
    eprintln!(
        "qdem run {}: {} particles, {} tets, {} with dt = {:.4e} s ({:.3}x the explicit stable bound), {} steps, {} threads",
        path.display(),
        sim.state.len(),
        sim.tets(),
        sim.scene.run.integrator.name(),
        sim.dt,
        sim.dt / sim.stable_dt.0,
        sim.steps(),
        rayon::current_num_threads()
    );
    let t_end = sim.scene.run.t_end;
    let show = progress::enabled();
    let mut on_progress = |p: &qdem_io::runner::Progress| {
        if show {
            progress::draw(p, t_end)
        }
    };
    // A second signal while the checkpoint is being written is ignored; the handler can
    // only fail if one is already installed, which this process never does twice.
    let _ = ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed));
    let options = RunOptions {
        resume,
        stop: Some(&STOP),
        stop_after: None,
    };
    if let Some(checkpoint) = resume {
        eprintln!("resuming from {}", checkpoint.display());
    }
    let report = run_with(&mut sim, &out_dir, options, &mut on_progress);
    if show {
        progress::finish();
    }
    let report = report?;
    if let Some((time, particle, u)) = report.crack_timing.collapse {
        eprintln!(
            "stopped at t = {time:.5} s: particle {particle} of the bonded body moved {u:.3e} m, \
             beyond the small-displacement range of its bonds (the body failed); \
             {} bonds broken",
            sim.bonded().map_or(0, |b| b.broken())
        );
    }
    // Particles are what a bonded or a stone run steps; its tetrahedra, if any, are few.
    let rate = if sim.bonded().is_some() || sim.granular.is_some() {
        format!("{:.3e} particle-steps/s", report.particle_steps_per_second)
    } else {
        format!("{:.3e} tet-steps/s", report.tet_steps_per_second)
    };
    eprintln!(
        "done: {} steps in {:.2} s ({rate}); outputs in {}",
        report.steps,
        report.wall_seconds,
        out_dir.display()
    );
    Ok(())
}
