//! `qdem analyze`: the spectra and mobility of a finished run's sensors (paper 000 §4.2).
//!
//! Reads `probes.csv` from the run's output directory and the input load from the scene's
//! `series` loads (the size of each one's resultant times the series, summed, evaluated at the
//! probe times: the rail-seat loads; a `total_force`'s size, a pressure's p·A on a plane face,
//! a traction's |t|·A: [`crate::build::load_resultant`]), keeps the rows in a time window,
//! and writes to `analysis/`:
//! - `spectra.csv` and `spectra.svg`: the Parzen-smoothed linear spectra
//!   ([`crate::linear_spectrum`]) of every probe's vertical acceleration and of the input load;
//! - `mobility.csv` and `mobility.svg`: every probe's vertical velocity over the input load;
//! - `acceleration.svg`, `displacement.svg` (lateral y and vertical z) and `load.svg`: the time
//!   series.

use crate::build::BuildError;
use crate::linear_spectrum::{linear_spectrum, mobility, parzen_smooth};
use crate::mode_marks::{read_mode_marks, ModeMark, ModeMarksError, ReferenceMark};
use crate::output::{write_atomic, OutputError, OUTPUT_FORMAT, PROBE_COLUMNS, TIME_COLUMN};
use crate::plot::{line_plot_svg, marked_plot_svg, Labels, Mark, Series};
use crate::scene::Scene;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// What to analyse.
#[derive(Clone, Debug)]
pub struct AnalyzeOptions {
    /// Start of the window (s); default the first row.
    pub from: Option<f64>,
    /// End of the window (s); default the last row.
    pub to: Option<f64>,
    /// Parzen bandwidth (Hz); the paper uses 20.
    pub bandwidth: f64,
    /// Highest frequency written and plotted (Hz); the paper trusts up to 1 kHz.
    pub max_frequency: f64,
    /// A `modes.csv` of `qdem modes` whose modes are marked on the spectra and mobility
    /// plots ([`crate::mode_marks`]).
    pub modes: Option<PathBuf>,
    /// Frequencies given by hand to mark beside the modes (a paper's peaks).
    pub references: Vec<ReferenceMark>,
}

impl Default for AnalyzeOptions {
    /// The paper's: the whole record, 20 Hz bandwidth, up to 1 kHz.
    fn default() -> Self {
        AnalyzeOptions {
            from: None,
            to: None,
            bandwidth: 20.0,
            max_frequency: 1000.0,
            modes: None,
            references: Vec::new(),
        }
    }
}

/// Why an analysis could not be made.
#[derive(Debug, Error)]
pub enum AnalyzeError {
    /// The probe file cannot be read.
    #[error("{path}: {source}; run the scene first (`qdem run SCENE`), it writes probes.csv")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The probe file is malformed or too short.
    #[error("{path}:{line}: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// Line (1-based).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A load series, or the mesh a pressure or traction load acts on, cannot be read.
    #[error(transparent)]
    Series(#[from] BuildError),
    /// The modes to mark cannot be read.
    #[error(transparent)]
    Modes(#[from] ModeMarksError),
    /// The output directory cannot be made.
    #[error("cannot create the directory {path}: {source}")]
    Dir {
        /// The directory.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// An output cannot be written.
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// One probe's peak in its smoothed acceleration spectrum.
#[derive(Clone, Debug)]
pub struct Peak {
    /// Probe name.
    pub probe: String,
    /// Frequency of the largest smoothed amplitude above 20 Hz (Hz).
    pub frequency: f64,
    /// That amplitude (m/s² · s).
    pub amplitude: f64,
}

/// What the analysis found.
#[derive(Clone, Debug)]
pub struct Analysis {
    /// Rows analysed and their sampling step (s).
    pub rows: usize,
    /// Sampling step (s).
    pub dt: f64,
    /// Peaks per probe.
    pub peaks: Vec<Peak>,
    /// Whether the scene had a series load (then mobility was written).
    pub mobility: bool,
    /// The directory written.
    pub dir: PathBuf,
}

/// The columns of `probes.csv`.
struct Probes {
    names: Vec<String>,
    time: Vec<f64>,
    /// Per probe, 9 columns: u, v, a in x, y, z.
    columns: Vec<[Vec<f64>; 9]>,
}

/// Lowest frequency for reporting a peak (Hz): below it lies the quasi-static load.
const PEAK_FROM: f64 = 20.0;

/// Analyses the run of `scene` whose outputs are in `out_dir`.
pub fn analyze(
    scene: &Scene,
    out_dir: &Path,
    options: &AnalyzeOptions,
) -> Result<Analysis, AnalyzeError> {
    let marks = match &options.modes {
        Some(path) => read_mode_marks(path)?,
        None => Vec::new(),
    };
    let labels: Vec<String> = marks.iter().map(ModeMark::label).collect();
    let marks: Vec<Mark<'_>> = marks
        .iter()
        .zip(&labels)
        .map(|(m, label)| Mark {
            x: m.frequency_hz,
            label,
            reference: false,
        })
        .chain(options.references.iter().map(|r| Mark {
            x: r.frequency_hz,
            label: &r.label,
            reference: true,
        }))
        .collect();
    let probes = read_probes(&out_dir.join("probes.csv"), options)?;
    let dt = sampling_step(&probes, &out_dir.join("probes.csv"))?;
    let load = input_load(scene, &probes.time)?;
    let dir = out_dir.join("analysis");
    std::fs::create_dir_all(&dir).map_err(|source| AnalyzeError::Dir {
        path: dir.clone(),
        source,
    })?;
    let keep = |s: Vec<(f64, f64)>| -> Vec<(f64, f64)> {
        s.into_iter()
            .filter(|p| p.0 <= options.max_frequency)
            .collect()
    };
    let spectra: Vec<Vec<(f64, f64)>> = probes
        .columns
        .iter()
        .map(|c| {
            keep(parzen_smooth(
                &linear_spectrum(&c[8], dt),
                options.bandwidth,
            ))
        })
        .collect();
    let mut names: Vec<String> = probes.names.iter().map(|n| format!("{n}.az")).collect();
    let mut columns = spectra.clone();
    if let Some(f) = &load {
        names.push("load".to_string());
        columns.push(keep(parzen_smooth(
            &linear_spectrum(f, dt),
            options.bandwidth,
        )));
    }
    write_table(&dir.join("spectra.csv"), &names, &columns)?;
    log_plot(
        &dir.join("spectra.svg"),
        "Linear spectra of vertical acceleration (Parzen)",
        "log10 |A| (m/s)",
        &probes.names,
        &spectra,
        options,
        &marks,
    )?;
    if let Some(f) = &load {
        let mobilities: Vec<Vec<(f64, f64)>> = probes
            .columns
            .iter()
            .map(|c| keep(mobility(&c[5], f, dt, options.bandwidth)))
            .collect();
        let names: Vec<String> = probes.names.iter().map(|n| format!("{n}.vz/F")).collect();
        write_table(&dir.join("mobility.csv"), &names, &mobilities)?;
        log_plot(
            &dir.join("mobility.svg"),
            "Mobility: vertical velocity over input load",
            "log10 mobility (m/s/N)",
            &probes.names,
            &mobilities,
            options,
            &marks,
        )?;
        let series = [Series {
            label: "input load",
            points: &probes
                .time
                .iter()
                .copied()
                .zip(f.iter().copied())
                .collect::<Vec<_>>(),
        }];
        line_plot_svg(
            &dir.join("load.svg"),
            &Labels {
                title: "Input load (sum of series loads)",
                x: "t (s)",
                y: "N",
            },
            &series,
        )?;
    }
    time_plots(&dir, &probes)?;
    let peaks = probes
        .names
        .iter()
        .zip(&spectra)
        .map(|(name, s)| {
            let (frequency, amplitude) = s
                .iter()
                .filter(|p| p.0 >= PEAK_FROM)
                .fold((0.0, 0.0), |best, p| if p.1 > best.1 { *p } else { best });
            Peak {
                probe: name.clone(),
                frequency,
                amplitude,
            }
        })
        .collect();
    Ok(Analysis {
        rows: probes.time.len(),
        dt,
        peaks,
        mobility: load.is_some(),
        dir,
    })
}

/// The probe file's columns, rows in the window only.
fn read_probes(path: &Path, options: &AnalyzeOptions) -> Result<Probes, AnalyzeError> {
    let text = std::fs::read_to_string(path).map_err(|source| AnalyzeError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let bad = |line: usize, message: String| AnalyzeError::Format {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let (names, at) = probe_columns(&header).map_err(|message| bad(1, message))?;
    let mut probes = Probes {
        columns: vec![std::array::from_fn(|_| Vec::new()); names.len()],
        names,
        time: Vec::new(),
    };
    for (i, line) in lines.enumerate() {
        let values: Vec<f64> = line
            .split(',')
            .map(|v| {
                v.parse::<f64>()
                    .map_err(|_| bad(i + 2, format!("`{v}` is not a number")))
            })
            .collect::<Result<_, _>>()?;
        if values.len() != header.len() {
            return Err(bad(
                i + 2,
                format!("{} fields, the header has {}", values.len(), header.len()),
            ));
        }
        let t = values[0];
        if options.from.is_some_and(|f| t < f) || options.to.is_some_and(|e| t > e) {
            continue;
        }
        probes.time.push(t);
        for (columns, at) in probes.columns.iter_mut().zip(&at) {
            for (column, &k) in columns.iter_mut().zip(at) {
                column.push(values[k]);
            }
        }
    }
    if probes.time.len() < 16 {
        return Err(bad(
            1,
            format!(
                "only {} rows in the window: widen --from/--to or sample more often (probe_every)",
                probes.time.len()
            ),
        ));
    }
    Ok(probes)
}

/// The probes of a `probes.csv` header (output format 2): their names and, per probe, where its
/// nine columns u, v, a in x, y, z are; refuses a header that is not a probe file's, naming
/// format 1's `t`.
fn probe_columns(header: &[&str]) -> Result<(Vec<String>, Vec<[usize; 9]>), String> {
    match header.first() {
        Some(&TIME_COLUMN) => {}
        Some(&"t") => {
            return Err(format!(
                "a probes.csv of output format 1 (time column `t`); this qdem reads format \
                 {OUTPUT_FORMAT}, whose time column is `{TIME_COLUMN}`; fix: run the scene again, \
                 or rename the first column to `{TIME_COLUMN}`"
            ))
        }
        _ => {
            return Err(format!(
                "not a probe file: the header must start with `{TIME_COLUMN}`"
            ))
        }
    }
    let mut names = Vec::new();
    let mut at = Vec::new();
    for cell in header.iter().filter_map(|c| c.strip_suffix(".ux")) {
        let mut columns = [0; 9];
        for (k, suffix) in PROBE_COLUMNS[..9].iter().enumerate() {
            let name = format!("{cell}.{suffix}");
            columns[k] = header.iter().position(|&c| c == name).ok_or_else(|| {
                format!("not a probe file: probe `{cell}` has no column `{name}`")
            })?;
        }
        names.push(cell.to_string());
        at.push(columns);
    }
    if names.is_empty() {
        return Err("not a probe file: no probe on a particle (no `NAME.ux` column)".to_string());
    }
    Ok((names, at))
}

/// The rows' common time step; refuses uneven sampling (an FFT needs even steps).
fn sampling_step(probes: &Probes, path: &Path) -> Result<f64, AnalyzeError> {
    let t = &probes.time;
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    match t.windows(2).position(|w| ((w[1] - w[0]) - dt).abs() > 0.01 * dt) {
        Some(i) => Err(AnalyzeError::Format {
            path: path.to_path_buf(),
            line: i + 2,
            message: format!("rows are not evenly spaced ({} s then {} s, mean {dt:.4e} s); the spectra need a constant probe_every", t[i], t[i + 1]),
        }),
        None => Ok(dt),
    }
}

/// The summed series loads at `time`, or `None` when the scene has none.
fn input_load(scene: &Scene, time: &[f64]) -> Result<Option<Vec<f64>>, AnalyzeError> {
    let mut total: Option<Vec<f64>> = None;
    for (k, load) in scene.loads.iter().enumerate() {
        let Some(series) = &load.series else { continue };
        let rows = crate::load_series::read_series(&scene.resolve(&series.file), &series.column)?;
        let f = qdem_core::loads::TimeFunction::new(rows).map_err(|source| BuildError::Core {
            scene: scene.path.clone(),
            source,
        })?;
        let size = crate::build::load_resultant(scene, k)?.norm();
        let sum = total.get_or_insert_with(|| vec![0.0; time.len()]);
        for (s, &t) in sum.iter_mut().zip(time) {
            *s += size * f.value(t);
        }
    }
    Ok(total)
}

/// CSV `f,NAME…` of spectra sharing their frequencies.
fn write_table(
    path: &Path,
    names: &[String],
    columns: &[Vec<(f64, f64)>],
) -> Result<(), OutputError> {
    write_atomic(path, |w| {
        writeln!(w, "f,{}", names.join(","))?;
        let rows = columns.iter().map(Vec::len).min().unwrap_or(0);
        for k in 0..rows {
            write!(w, "{:.6e}", columns[0][k].0)?;
            for c in columns {
                write!(w, ",{:.6e}", c[k].1)?;
            }
            writeln!(w)?;
        }
        Ok(())
    })
}

/// Spectra on a log10 scale (the amplitudes span decades), from the first non-zero frequency,
/// with the natural frequencies `marks`.
fn log_plot(
    path: &Path,
    title: &str,
    y: &str,
    names: &[String],
    columns: &[Vec<(f64, f64)>],
    options: &AnalyzeOptions,
    marks: &[Mark<'_>],
) -> Result<(), OutputError> {
    let logs: Vec<Vec<(f64, f64)>> = columns
        .iter()
        .map(|c| {
            c.iter()
                .filter(|p| p.0 > 0.0 && p.1 > 0.0)
                .map(|p| (p.0, p.1.log10()))
                .collect()
        })
        .collect();
    let series = named_series(names, &logs);
    let title = format!("{title}, bandwidth {} Hz", options.bandwidth);
    marked_plot_svg(
        path,
        &Labels {
            title: &title,
            x: "f (Hz)",
            y,
        },
        &series,
        marks,
    )
}

/// Vertical acceleration, and lateral and vertical displacement, of every probe against time.
fn time_plots(dir: &Path, probes: &Probes) -> Result<(), OutputError> {
    let pairs = |column: usize| -> Vec<Vec<(f64, f64)>> {
        probes
            .columns
            .iter()
            .map(|c| {
                probes
                    .time
                    .iter()
                    .copied()
                    .zip(c[column].iter().copied())
                    .collect()
            })
            .collect()
    };
    let (az, uy, uz) = (pairs(8), pairs(1), pairs(2));
    let labels_y: Vec<String> = probes.names.iter().map(|n| format!("{n} uy")).collect();
    let labels_z: Vec<String> = probes.names.iter().map(|n| format!("{n} uz")).collect();
    let series_a: Vec<Series<'_>> = named_series(&probes.names, &az);
    line_plot_svg(
        &dir.join("acceleration.svg"),
        &Labels {
            title: "Vertical acceleration",
            x: "t (s)",
            y: "m/s^2",
        },
        &series_a,
    )?;
    let mut displacement = named_series(&labels_y, &uy);
    displacement.extend(named_series(&labels_z, &uz));
    line_plot_svg(
        &dir.join("displacement.svg"),
        &Labels {
            title: "Lateral (y) and vertical (z) displacement",
            x: "t (s)",
            y: "m",
        },
        &displacement,
    )
}

/// Plot series from parallel lists of labels and points.
fn named_series<'a>(labels: &'a [String], data: &'a [Vec<(f64, f64)>]) -> Vec<Series<'a>> {
    labels
        .iter()
        .zip(data)
        .map(|(l, d)| Series {
            label: l,
            points: d,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_format_two_header_is_read_by_name_and_format_one_is_refused_by_name() {
        let header = "time,tip.ux,tip.uy,tip.uz,tip.vx,tip.vy,tip.vz,tip.ax,tip.ay,tip.az,\
                      tip.wx,tip.wy,tip.wz,bed.vx,bed.vy,bed.vz,bed.ke,bed.count";
        let cells: Vec<&str> = header.split(',').collect();
        let (names, at) = probe_columns(&cells).unwrap();
        assert_eq!(names, ["tip"]);
        assert_eq!(at, [[1, 2, 3, 4, 5, 6, 7, 8, 9]]);
        let old = "t,tip.ux,tip.uy,tip.uz,tip.vx,tip.vy,tip.vz,tip.ax,tip.ay,tip.az";
        let err = probe_columns(&old.split(',').collect::<Vec<_>>()).unwrap_err();
        assert!(err.contains("output format 1 (time column `t`)"), "{err}");
        assert!(err.contains("rename the first column to `time`"), "{err}");
        let err = probe_columns(&["time", "tip.ux", "tip.uy"]).unwrap_err();
        assert!(err.contains("probe `tip` has no column `tip.uz`"), "{err}");
    }
}
