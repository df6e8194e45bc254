//! The command line (clap's derive API: [`Cli`]) and the six commands. Values are checked as
//! they are parsed, so that a bad argument is refused before any work, naming its flag. Errors
//! from the libraries are rendered once, by `main`, through [`CliError`]'s `Display`.

use crate::{check, progress, run_length};
use clap::{Args, Parser, Subcommand, ValueEnum};
use qdem_bench::throughput::BenchPlan;
use qdem_bench::{implicit, throughput, verify};
use qdem_core::continuum::Formulation;
use qdem_core::step::team::Team;
use qdem_core::{error::CoreError, parallel::Communicator, step::Halt, step::Scheme};
use qdem_io::analyze::AnalyzeOptions;
use qdem_io::build::{BuildError, Simulation};
use qdem_io::mode_marks::ReferenceMark;
use qdem_io::modes::Shapes;
use qdem_io::runner::{run_with, RunError, RunOptions};
use qdem_io::scene::{Scene, SceneError};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use thiserror::Error;

/// Everything the command line reports as an error.
#[derive(Debug, Error)]
pub enum CliError {
    /// Bad command-line usage: clap's message (which names the argument), the usage line and
    /// where to find help, without clap's own `error: ` prefix (`main` adds it).
    #[error("{}", usage_message(.0))]
    Usage(#[from] clap::Error),
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
    /// A modal analysis that could not be made.
    #[error(transparent)]
    Modes(#[from] qdem_io::modes::ModesError),
    /// An analysis that could not be made.
    #[error(transparent)]
    Analyze(#[from] qdem_io::analyze::AnalyzeError),
    /// A run that cannot be decomposed over the processes of `mpirun`.
    #[error("{}: {source}", scene.display())]
    Decompose {
        /// The scene file.
        scene: PathBuf,
        /// Why.
        source: CoreError,
    },
    /// A command other than `run` and `check` started by `mpirun` on several processes.
    #[error(
        "`qdem {command}` runs as one process; only `qdem run` and `qdem check` are \
         decomposed over the processes of mpirun: start it without mpirun"
    )]
    NotDecomposed {
        /// The command.
        command: &'static str,
    },
    /// A run modelled to take more than a day, started without `--yes`.
    #[error(transparent)]
    TooLong(#[from] Box<run_length::TooLong>),
    /// A `qdem bench` block too large for this process's memory.
    #[error(transparent)]
    Block(#[from] throughput::BlockTooLarge),
    /// The thread pool could not be set up.
    #[error("cannot start {threads} threads: {message}")]
    Threads {
        /// Requested threads.
        threads: usize,
        /// Why.
        message: String,
    },
    /// A value of the environment variable `QDEM_TEAM` other than 0 and 1.
    #[error(
        "QDEM_TEAM={value:?} in the environment: give 1 to run a step's parallel regions on \
         a persistent team of threads, or 0 (or leave it unset) for the default"
    )]
    Team {
        /// The value given.
        value: String,
    },
}

/// Clap's rendering of a usage error, plain text, without its leading `error: ` and trailing
/// newline; `qdem` alone is told that a command is missing, above the help that lists them.
fn usage_message(error: &clap::Error) -> String {
    let text = error.to_string();
    if error.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
        return format!(
            "no command given; give one of the commands below\n\n{}",
            text.trim_end()
        );
    }
    text.strip_prefix("error: ")
        .unwrap_or(&text)
        .trim_end()
        .to_string()
}

/// Simulation of deformable and granular bodies with the quadruple discrete element method
/// (QDEM).
#[derive(Debug, Parser)]
#[command(name = "qdem", version, propagate_version = true)]
pub struct Cli {
    /// The command to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scene (or continue one from its checkpoint)
    ///
    /// Outputs go to DIR (default: the scene's [output] dir, relative to the scene file).
    /// Ctrl-C or SIGTERM stops the run after its current step with DIR/checkpoint.qdc (exit
    /// status 130), which --resume continues bit for bit.
    Run(RunArgs),
    /// Validate a scene; print mesh statistics, mass, stable dt, measured cost per step,
    /// estimated run time
    ///
    /// Also times each model's force evaluation at the scene's start, so it shows where a step
    /// goes (continuum kernel, contacts, loads, integration), and says whether the scene can be
    /// checkpointed.
    Check(CheckArgs),
    /// Analytical fixtures: fixture, analytical, computed, error, tolerance, CPU s
    ///
    /// Exits non-zero if a fixture misses its tolerance. --full adds the paper's cantilever on
    /// every fixture mesh (about 16 min), keeping their outputs and plots in DIR.
    Verify(VerifyArgs),
    /// Kernel throughput in tet-steps/s on structured meshes
    ///
    /// Elastic and viscoelastic blocks of about each --tets size on each --threads count, the
    /// machine's triad bandwidth and vector peak (the kernel's share of each) and the effect of
    /// node ordering. --implicit measures the
    /// sparse Cholesky path instead: assembly, factorisation, solve and implicit step against
    /// the number of unknowns.
    Bench(BenchArgs),
    /// A finished run's sensors: Parzen-smoothed linear spectra and mobility, CSV + SVG
    ///
    /// Reads the run's probes.csv and writes DIR/analysis (default: the scene's [output] dir):
    /// spectra smoothed by the Parzen window (20 Hz bandwidth by default) and the mobility over
    /// the scene's series loads.
    Analyze(AnalyzeArgs),
    /// Natural frequencies and mode shapes of the scene's deformable and rigid bodies
    ///
    /// The N lowest modes about the starting state (the tetrahedra's linear stiffness, the
    /// touching contacts as springs, the lumped masses, the scene's fixes; a rigid body's six
    /// DOFs) by shift-invert Lanczos: DIR/modes.csv (frequency, dominant direction, effective
    /// mass fractions), DIR/modes.pvd and DIR/vtu/mode_NNNN.vtu. A body with no fix and
    /// nothing touching it reports its six rigid-body modes first.
    Modes(ModesArgs),
}

/// `qdem modes`.
#[derive(Debug, Args)]
pub struct ModesArgs {
    /// The scene file (TOML)
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Number of modes, rigid-body modes included
    #[arg(long, value_name = "N", value_parser = positive_whole, allow_negative_numbers = true,
          default_value_t = 10)]
    pub count: usize,
    /// Output directory [default: the scene's [output] dir, then modes/]
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Worker threads [default: one per core]
    #[arg(long, value_name = "N", value_parser = thread_count, allow_negative_numbers = true)]
    pub threads: Option<usize>,
    /// Write modes.csv only, no mode shapes (a bed's hundreds of modes would write a mesh
    /// each)
    #[arg(long)]
    pub no_shapes: bool,
}

/// `qdem run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// The scene file (TOML)
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Output directory [default: the scene's [output] dir]
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Worker threads [default: one per core]
    #[arg(long, value_name = "N", value_parser = thread_count, allow_negative_numbers = true)]
    pub threads: Option<usize>,
    /// Continue the run from this checkpoint (DIR/checkpoint.qdc of a stopped run)
    #[arg(long, value_name = "CHECKPOINT")]
    pub resume: Option<PathBuf>,
    /// Stop after step N as Ctrl-C does: with DIR/checkpoint.qdc, exit status 130 (a batch
    /// slot's last step)
    #[arg(long, value_name = "N", value_parser = step_number, allow_negative_numbers = true)]
    pub stop_after: Option<u64>,
    /// Start the run even if it is modelled to take more than a day of wall time (without it,
    /// such a run is refused, with the estimate and how to shorten it)
    #[arg(long)]
    pub yes: bool,
}

/// `qdem check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The scene file (TOML)
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Worker threads for the cost measurement [default: one per core]
    #[arg(long, value_name = "N", value_parser = thread_count, allow_negative_numbers = true)]
    pub threads: Option<usize>,
    /// Print only the modelling advice, as one JSON array (`json`), for scripts; without it
    /// the advice is part of the report
    #[arg(long, value_name = "FORMAT")]
    pub advice: Option<AdviceFormat>,
}

/// How `qdem check --advice` prints the advice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AdviceFormat {
    /// One JSON array of the advice (`qdem_io::advice::to_json`).
    Json,
}

/// `qdem verify`.
#[derive(Debug, Args)]
pub struct VerifyArgs {
    /// Print one JSON document instead of the table
    #[arg(long)]
    pub json: bool,
    /// Add the cantilever meshes (about 16 min)
    #[arg(long)]
    pub full: bool,
    /// Where --full keeps the cantilever outputs and plots [default: out/verify]
    #[arg(long, value_name = "DIR", requires = "full")]
    pub out: Option<PathBuf>,
}

/// `qdem bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    /// Print one JSON document instead of the table
    #[arg(long)]
    pub json: bool,
    /// Approximate tetrahedron counts, comma-separated [default: 10000,100000,1000000; with
    /// --implicit 16000,180000,550000]
    #[arg(long, value_name = "N,..", value_delimiter = ',', value_parser = positive_whole,
          allow_negative_numbers = true)]
    pub tets: Option<Vec<usize>>,
    /// Thread counts, comma-separated [default: 1,2; with --implicit the last one, default 2]
    #[arg(long, value_name = "N,..", value_delimiter = ',', value_parser = threads_within_cores,
          allow_negative_numbers = true)]
    pub threads: Option<Vec<usize>>,
    /// Steps per measurement [default: about one second's worth, at least 3]
    #[arg(long, value_name = "N", value_parser = positive_whole, allow_negative_numbers = true)]
    pub steps: Option<usize>,
    /// Measure the implicit path (sparse Cholesky) against the number of unknowns instead
    #[arg(long)]
    pub implicit: bool,
    /// The tetrahedron measured: `standard` or `averaged-pressure` (the `[[material]]`
    /// formulation)
    #[arg(long, value_name = "NAME", default_value = "standard")]
    pub formulation: BenchFormulation,
    /// Instead of the cubes of --tets: N stones of about 100 tetrahedra (the fine stones of
    /// fixtures/ballast/stones) as one body, as [ballast] builds them, beside one cube of
    /// about the same total
    #[arg(long, value_name = "N", value_parser = positive_whole, allow_negative_numbers = true,
          conflicts_with_all = ["tets", "implicit"])]
    pub stones: Option<usize>,
}

/// The tetrahedron `qdem bench` measures (`[[material]] formulation`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BenchFormulation {
    /// The standard QDEM tetrahedron.
    Standard,
    /// The average nodal pressure tetrahedron.
    AveragedPressure,
}

impl BenchFormulation {
    /// The core's formulation.
    fn core(self) -> Formulation {
        match self {
            BenchFormulation::Standard => Formulation::Standard,
            BenchFormulation::AveragedPressure => Formulation::AveragedPressure,
        }
    }
}

/// `qdem analyze`.
#[derive(Debug, Args)]
pub struct AnalyzeArgs {
    /// The scene file (TOML) of the finished run
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// The run's output directory [default: the scene's [output] dir]
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Start of the analysed window (s) [default: the first row]
    #[arg(long, value_name = "T", value_parser = non_negative,
          allow_negative_numbers = true)]
    pub from: Option<f64>,
    /// End of the analysed window (s) [default: the last row]
    #[arg(long, value_name = "T", value_parser = non_negative,
          allow_negative_numbers = true)]
    pub to: Option<f64>,
    /// Bandwidth of the Parzen window (Hz)
    #[arg(long, value_name = "HZ", value_parser = non_negative,
          allow_negative_numbers = true, default_value_t = AnalyzeOptions::default().bandwidth)]
    pub bandwidth: f64,
    /// Highest frequency written and plotted (Hz)
    #[arg(long, value_name = "HZ", value_parser = non_negative,
          allow_negative_numbers = true, default_value_t = AnalyzeOptions::default().max_frequency)]
    pub fmax: f64,
    /// A modes.csv of `qdem modes`: its modes moving at least 5% of the mass are marked on
    /// the spectra and mobility plots
    #[arg(long, value_name = "MODES_CSV")]
    pub modes: Option<PathBuf>,
    /// A frequency to mark on the spectra and mobility plots in red, HZ=LABEL (a paper's
    /// peak: `--mark 100=paper:rigid --mark 200=paper:bending`); repeat for more
    #[arg(long = "mark", value_name = "HZ=LABEL")]
    pub marks: Vec<ReferenceMark>,
}

/// A count (tetrahedra, threads or steps of `bench`): a whole number of at least 1.
fn positive_whole(value: &str) -> Result<usize, String> {
    value
        .trim()
        .parse::<usize>()
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| "give a positive whole number (1 or more)".to_string())
}

/// How many threads a core may be given: more only slow a run down (a pool of 100,000
/// threads took over a minute to start, saying nothing), while a few more than the cores are
/// asked for on purpose (a run on more threads than cores checks that its results do not
/// depend on the count).
const THREADS_PER_CORE: usize = 8;

/// The cores this process may run on (1 where that cannot be told).
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// A thread count (of `run`, `check`, `modes` or `bench`): a positive whole number, at most
/// [`THREADS_PER_CORE`] per core.
fn threads_within_cores(value: &str) -> Result<usize, String> {
    let threads = positive_whole(value)?;
    let (cores, most) = (cores(), THREADS_PER_CORE * cores());
    match threads <= most {
        true => Ok(threads),
        false => Err(format!(
            "{threads} threads is more than {THREADS_PER_CORE} per core of the {cores} cores \
             this process may use: they would only share them, slower; give at most {most} \
             (leave --threads out for one per core)"
        )),
    }
}

/// The step of `--stop-after`: a whole number of at least 1 (the first step is step 1, so a 0
/// would never stop the run).
fn step_number(value: &str) -> Result<u64, String> {
    value
        .trim()
        .parse::<u64>()
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| "give a positive whole number of steps (1 or more)".to_string())
}

/// The one thread count of `run`, `check` and `modes`.
fn thread_count(value: &str) -> Result<usize, String> {
    threads_within_cores(value).map_err(|e| {
        if value.contains(',') {
            "give one positive whole number here (lists N,.. are for `qdem bench`)".to_string()
        } else {
            e
        }
    })
}

/// Says that `threads` share fewer cores (a run is then slower; its results are the same).
fn note_shared_cores(threads: Option<usize>) {
    let cores = cores();
    if let Some(threads) = threads.filter(|&t| t > cores) {
        eprintln!(
            "note: {threads} threads on the {cores} cores this process may use: they share \
             them (the results are the same, the run is slower)"
        );
    }
}

/// A finite non-negative number of seconds or hertz.
fn non_negative(value: &str) -> Result<f64, String> {
    value
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| "give a finite number >= 0".to_string())
}

/// The thread pool of `--threads N` (rayon's default without it, and for `verify`). Commands
/// run inside it ([`rayon::ThreadPool::install`]) rather than on the main thread: a parallel
/// loop started outside the pool is handed to a worker and waited for, a sleep and a wake-up
/// per loop, which cost an explicit bonded-beam step (ten loops of a few microseconds each)
/// about a fifth of its time.
fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, CliError> {
    note_shared_cores(threads);
    let count = threads.unwrap_or(0);
    rayon::ThreadPoolBuilder::new()
        .num_threads(count)
        .build()
        .map_err(|e| CliError::Threads {
            threads: count,
            message: e.to_string(),
        })
}

/// Runs `f` with a persistent team of the pool's threads installed on this thread
/// ([`qdem_core::step::team`]) when the environment sets `QDEM_TEAM=1`: each step's parallel
/// regions are then phases of the team, which wake its workers at most once a step.
fn with_team<R>(f: impl FnOnce() -> Result<R, CliError>) -> Result<R, CliError> {
    let value = std::env::var("QDEM_TEAM").unwrap_or_default();
    match value.trim() {
        "" | "0" => f(),
        "1" => Team::new(rayon::current_num_threads()).install(f),
        _ => Err(CliError::Team { value }),
    }
}

/// Runs the parsed command; `ranks`: the processes of an `mpirun` (of more than one), over
/// which `qdem run` decomposes its run.
pub fn dispatch(cli: Cli, ranks: Option<Arc<dyn Communicator>>) -> Result<(), CliError> {
    if let Some(command) = ranks.as_ref().and_then(|_| cli.command.single_process()) {
        return Err(CliError::NotDecomposed { command });
    }
    match cli.command {
        Command::Run(a) => thread_pool(a.threads)?.install(|| with_team(|| run_scene(&a, ranks))),
        Command::Modes(a) => {
            let shapes = if a.no_shapes {
                Shapes::None
            } else {
                Shapes::Vtu
            };
            thread_pool(a.threads)?
                .install(|| modes_of(&a.scene, a.count, a.out.as_deref(), shapes))
        }
        Command::Check(a) => thread_pool(a.threads)?.install(|| match a.advice {
            Some(AdviceFormat::Json) => check::print_advice_json(&a.scene),
            None => with_team(|| check::check_scene(&a.scene, ranks)),
        }),
        Command::Analyze(a) => {
            let options = AnalyzeOptions {
                from: a.from,
                to: a.to,
                bandwidth: a.bandwidth,
                max_frequency: a.fmax,
                modes: a.modes,
                references: a.marks,
            };
            analyze_run(&a.scene, a.out.as_deref(), &options)
        }
        Command::Verify(a) => {
            let out = a.out.unwrap_or_else(|| PathBuf::from("out/verify"));
            thread_pool(None)?
                .install(|| verify::run_and_print(a.json, a.full.then_some(out.as_path())))
                .map_err(CliError::from)
        }
        Command::Bench(a) => {
            if a.implicit {
                let threads = a
                    .threads
                    .as_deref()
                    .and_then(|t| t.last().copied())
                    .unwrap_or(2);
                let sizes = a.tets.clone().unwrap_or(implicit::DEFAULT_TETS.to_vec());
                for &tets in &sizes {
                    throughput::check_block(tets, true)?;
                }
                return Ok(implicit::run_and_print(Some(sizes), threads, a.json)?);
            }
            let mut plan = BenchPlan::new(a.tets, a.threads, a.steps, a.formulation.core());
            plan.stones = a.stones;
            match a.stones {
                Some(count) => throughput::check_stones(count)?,
                None => {
                    for &tets in &plan.tets {
                        throughput::check_block(tets, false)?;
                    }
                }
            }
            throughput::run_and_print(&plan, a.json);
            Ok(())
        }
    }
}

fn analyze_run(path: &Path, out: Option<&Path>, options: &AnalyzeOptions) -> Result<(), CliError> {
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

/// `qdem modes`: builds the scene, computes and writes the modes, prints the table.
fn modes_of(path: &Path, count: usize, out: Option<&Path>, shapes: Shapes) -> Result<(), CliError> {
    let scene = Scene::load(path)?;
    let out_dir = match out {
        Some(dir) => dir.to_path_buf(),
        None => scene.base_dir().join(&scene.output.dir).join("modes"),
    };
    let mut sim = progress::while_busy("building the scene", || Simulation::build(scene))?;
    for w in &sim.warnings {
        eprintln!("warning: {w}");
    }
    let report = qdem_io::modes::compute_and_write_as(&mut sim, count, &out_dir, shapes)?;
    if report.loose_stone_modes > 0 {
        eprintln!(
            "warning: gravity or a load does work along {} rigid-body modes of [ballast] \
             stones that touch nothing (stones in flight above the bed): kept as rigid, the \
             elastic modes are the bed's without those stones",
            report.loose_stone_modes
        );
    }
    for name in &report.ignored {
        eprintln!("note: model `{name}` gives no stiffness and is left out of the modes");
    }
    let m = &report.modes;
    if m.mechanisms > 0 {
        eprintln!(
            "note: {} rigid motions of single pieces that nothing resists (stones resting on \
             fewer than three contacts, or on none) are left out of the modes",
            m.mechanisms
        );
    }
    eprintln!(
        "qdem modes {}: {} free DOFs, K factorised in {:.2} s, {} Lanczos steps",
        path.display(),
        m.dofs,
        m.factor_seconds,
        m.steps
    );
    let mut table = Vec::new();
    qdem_io::modes::write_table(&mut table, m).expect("writing to memory");
    print!("{}", String::from_utf8_lossy(&table));
    match &report.pvd {
        Some(pvd) => eprintln!("{} and {} written", report.csv.display(), pvd.display()),
        None => eprintln!("{} written (no mode shapes)", report.csv.display()),
    }
    Ok(())
}

/// The line `qdem run` prints of a decomposed run: per rank, the tetrahedra it computes, the
/// particles it owns and the block sums it receives per step.
fn decomposition_line(d: &qdem_core::parallel::RankFigures) -> String {
    let list = |v: &[usize]| {
        v.iter()
            .map(|n| n.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    format!(
        "decomposed over {} ranks: tets per rank [{}], owned particles [{}], block sums received per step \
         [{}], particles received per step [{}], {} bodies cut between ranks",
        d.ranks,
        list(&d.tets),
        list(&d.owned),
        list(&d.halo),
        list(&d.received),
        d.cut_bodies
    )
}

/// Set by the Ctrl-C / SIGTERM handler: the run stops after its current step, checkpointed.
static STOP: AtomicBool = AtomicBool::new(false);

impl Command {
    /// The name of a command that is not decomposed over processes (all but `run` and
    /// `check`).
    fn single_process(&self) -> Option<&'static str> {
        match self {
            Command::Run(_) | Command::Check(_) => None,
            Command::Verify(_) => Some("verify"),
            Command::Bench(_) => Some("bench"),
            Command::Analyze(_) => Some("analyze"),
            Command::Modes(_) => Some("modes"),
        }
    }
}

fn run_scene(args: &RunArgs, ranks: Option<Arc<dyn Communicator>>) -> Result<(), CliError> {
    // Set first, so that a signal while the scene loads and builds stops the run at its first
    // step, checkpointed, as one later does. A second signal while the checkpoint is being
    // written is ignored; the handler can only fail if one is already installed, which this
    // process never does twice.
    let _ = ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed));
    let (path, resume) = (args.scene.as_path(), args.resume.as_deref());
    let scene = Scene::load(path)?;
    let out_dir = match args.out.as_deref() {
        Some(dir) => dir.to_path_buf(),
        None => path
            .parent()
            .unwrap_or(Path::new("."))
            .join(&scene.output.dir),
    };
    let mut sim = progress::while_busy("building the scene", || Simulation::build(scene))?;
    let leader = ranks.as_ref().is_none_or(|r| r.rank() == 0);
    if let Some(ranks) = &ranks {
        let figures = sim
            .world
            .decompose(ranks.clone())
            .map_err(|source| CliError::Decompose {
                scene: path.to_path_buf(),
                source,
            })?;
        if leader {
            eprintln!("{}", decomposition_line(&figures));
        }
    }
    if resume.is_none() && !args.yes {
        let ranks = ranks.as_ref().map_or(1, |r| r.size());
        run_length::refuse_long(&sim, rayon::current_num_threads(), cores(), ranks)?;
    }
    if !leader {
        let options = RunOptions {
            resume,
            stop: Some(&STOP),
            stop_after: args.stop_after,
        };
        run_with(&mut sim, &out_dir, options, &mut |_| {})?;
        return Ok(());
    }
    for w in &sim.warnings {
        eprintln!("warning: {w}");
    }
    eprintln!(
        "qdem run {}: {} particles, {} tets, {}, {} threads",
        path.display(),
        sim.world.state.len(),
        sim.tets(),
        stepping_words(&sim),
        rayon::current_num_threads()
    );
    let t_end = sim.scene.run.t_end;
    let show = progress::enabled();
    let mut on_progress = |p: &qdem_io::runner::Progress| {
        if show {
            progress::draw(p, t_end)
        }
    };
    let options = RunOptions {
        resume,
        stop: Some(&STOP),
        stop_after: args.stop_after,
    };
    if let Some(checkpoint) = resume {
        eprintln!("resuming from {}", checkpoint.display());
    }
    let report = run_with(&mut sim, &out_dir, options, &mut on_progress);
    if show {
        progress::finish();
    }
    let report = report?;
    if let Some(Halt {
        time,
        particle,
        value: u,
        ..
    }) = report.halt
    {
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
    let steps = match sim.world.settings().request.scheme {
        Scheme::Static => {
            let solves = sim.world.stepper().report().counts.solves;
            format!("{} steps (linear solves: {solves})", report.steps)
        }
        _ => format!("{} steps", report.steps),
    };
    eprintln!(
        "done: {steps} in {:.2} s ({rate}); outputs in {}",
        report.wall_seconds,
        out_dir.display()
    );
    Ok(())
}

/// How the run steps, for its first line: an explicit step against the stable bound, an
/// implicit one or a static run's load levels without it (no stable bound applies to them).
fn stepping_words(sim: &Simulation) -> String {
    let (dt, steps) = (sim.world.dt(), sim.steps());
    let name = sim.scene.run.integrator.name();
    match sim.world.settings().request.scheme {
        Scheme::Static => format!("static with load levels every {dt:.4e} s, {steps} steps"),
        scheme if scheme.is_implicit() => format!("{name} with dt = {dt:.4e} s, {steps} steps"),
        _ => format!(
            "{name} with dt = {dt:.4e} s ({:.3}x the explicit stable bound), {steps} steps",
            dt / sim.world.settings().stable_dt.0
        ),
    }
}
