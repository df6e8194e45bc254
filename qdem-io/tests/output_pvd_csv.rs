//! PVD collection and probe CSV: exact text layout, and numbers that parse back to the
//! same `f64`.

mod common;
use common::*;

use nalgebra::Vector3;
use qdem_io::output::{OutputError, ProbeCsv, PvdIndex};

#[test]
fn pvd_is_complete_after_each_write() {
    let dir = test_dir("pvd");
    let path = dir.join("run.pvd");
    let times = [0.0, 1e-7 / 3.0, 0.1, 2.5];
    let mut index = PvdIndex::new();
    for (i, &t) in times.iter().enumerate() {
        index.push(t, format!("frames/run_{i:04}.vtu"));
        index.write(&path).unwrap();

        let text = std::fs::read_to_string(&path).unwrap();
        let mut expected = String::from(
            "<?xml version=\"1.0\"?>\n\
             <VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  \
             <Collection>\n",
        );
        for (j, &tj) in times[..=i].iter().enumerate() {
            let ts = match j {
                0 => "0",
                1 => "3.3333333333333334e-8",
                2 => "0.1",
                _ => "2.5",
            };
            assert_eq!(ts.parse::<f64>().unwrap().to_bits(), tj.to_bits());
            expected.push_str(&format!(
                "    <DataSet timestep=\"{ts}\" group=\"\" part=\"0\" file=\"frames/run_{j:04}.vtu\"/>\n"
            ));
        }
        expected.push_str("  </Collection>\n</VTKFile>\n");
        assert_eq!(text, expected);
        assert_eq!(entries(&dir), ["run.pvd"]);
    }
    assert_eq!(index.len(), 4);
    assert_eq!(index.entries()[1].1, "frames/run_0001.vtu");

    // Special characters are escaped; non-finite times are rejected.
    let mut index = PvdIndex::new();
    index.push(1.0, "a&b \"c\".vtu");
    index.write(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("file=\"a&amp;b &quot;c&quot;.vtu\""),
        "{text}"
    );
    index.push(f64::NAN, "x.vtu");
    let err = index.write(&path).unwrap_err();
    assert!(matches!(err, OutputError::NonFinite { .. }), "{err:?}");
    assert!(err.to_string().contains("run.pvd"), "{err}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text, "unchanged");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn probe_csv_header_and_exact_values() {
    let dir = test_dir("probes");
    let path = dir.join("probes.csv");
    let names = vec!["tip".to_string(), "mid span".to_string()];
    let mut csv = ProbeCsv::create(&path, &names).unwrap();
    assert_eq!(csv.num_probes(), 2);
    assert!(!path.exists(), "the file appears only on finish");

    let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
    let nan = Vector3::repeat(f64::NAN);
    let rows: Vec<(f64, Vec<[Vector3<f64>; 4]>)> = vec![
        (
            0.0,
            vec![
                [Vector3::zeros(); 4],
                [v(-0.0, 0.0, 1.0), Vector3::zeros(), v(0.0, 0.0, -9.81), nan],
            ],
        ),
        (
            1e-7 / 3.0,
            vec![
                [
                    v(1.0 / 3.0, -2.5e-7, 5e-324),
                    v(1e300, -1e-300, 0.1),
                    v(f64::MAX, f64::MIN_POSITIVE, 123456.789),
                    v(0.0, -40.0, 1.0 / 7.0),
                ],
                [
                    v(std::f64::consts::PI, 1e16, 9.999999999999999e-6),
                    v(1e-5, -7.0, 2.0 / 3.0),
                    v(0.2, 0.3, 0.7),
                    nan,
                ],
            ],
        ),
        (
            2.0,
            vec![
                [
                    v(f64::NAN, f64::INFINITY, f64::NEG_INFINITY),
                    Vector3::zeros(),
                    Vector3::zeros(),
                    Vector3::zeros(),
                ],
                [Vector3::zeros(); 4],
            ],
        ),
    ];
    for (t, samples) in &rows {
        csv.row(*t, samples).unwrap();
    }
    assert_eq!(csv.num_rows(), 3);

    // Wrong sample count and non-finite time are rejected without writing anything.
    let err = csv.row(3.0, &rows[0].1[..1]).unwrap_err();
    assert!(
        matches!(&err, OutputError::Length { expected: 2, found: 1, path: p, .. } if p == &path),
        "{err:?}"
    );
    let err = csv.row(f64::INFINITY, &rows[0].1).unwrap_err();
    assert!(matches!(err, OutputError::NonFinite { .. }), "{err:?}");
    csv.finish().unwrap();
    assert_eq!(entries(&dir), ["probes.csv"]);

    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "time,tip.ux,tip.uy,tip.uz,tip.vx,tip.vy,tip.vz,tip.ax,tip.ay,tip.az,\
         tip.wx,tip.wy,tip.wz,\
         mid span.ux,mid span.uy,mid span.uz,mid span.vx,mid span.vy,mid span.vz,\
         mid span.ax,mid span.ay,mid span.az,mid span.wx,mid span.wy,mid span.wz"
    );
    for (t, samples) in &rows {
        let line = lines.next().expect("a row per call");
        let got: Vec<u64> = line
            .split(',')
            .map(|s| {
                s.parse::<f64>()
                    .unwrap_or_else(|e| panic!("{s:?}: {e}"))
                    .to_bits()
            })
            .collect();
        let mut want = vec![t.to_bits()];
        for sample in samples {
            for x in sample.iter().flat_map(|v| v.iter()) {
                want.push(x.to_bits());
            }
        }
        assert_eq!(got.len(), 25);
        // NaN compares by bits too: the standard NaN is written and read back.
        assert_eq!(got, want, "{line}");
    }
    assert_eq!(lines.next(), None);
    assert!(text.ends_with('\n'));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn probe_csv_rejects_bad_names_and_drop_leaves_nothing() {
    let dir = test_dir("probes-names");
    let path = dir.join("probes.csv");
    for bad in [
        &["a,b"][..],
        &["a\"b"],
        &[""],
        &["x", "x"],
        &["line\nbreak"],
    ] {
        let names: Vec<String> = bad.iter().map(|s| s.to_string()).collect();
        let err = ProbeCsv::create(&path, &names).unwrap_err();
        assert!(
            matches!(err, OutputError::InvalidName { .. }),
            "{bad:?}: {err:?}"
        );
    }
    assert!(entries(&dir).is_empty());

    // No probes: a header-only file with the time column.
    let mut csv = ProbeCsv::create(&path, &[]).unwrap();
    csv.row(0.5, &[]).unwrap();
    drop(csv);
    assert!(entries(&dir).is_empty(), "dropped without finish");
    let mut csv = ProbeCsv::create(&path, &[]).unwrap();
    csv.row(0.5, &[]).unwrap();
    csv.finish().unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "time\n0.5\n");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_probe_csv_of_output_format_one_is_not_resumed() {
    let dir = test_dir("probes-format-one");
    let path = dir.join("probes.csv");
    let old =
        "t,tip.ux,tip.uy,tip.uz,tip.vx,tip.vy,tip.vz,tip.ax,tip.ay,tip.az\n0,0,0,0,0,0,0,0,0,0\n";
    std::fs::write(&path, old).unwrap();
    let err = ProbeCsv::resume(&path, &["tip".to_string()], 1).unwrap_err();
    let message = err.to_string();
    assert!(matches!(err, OutputError::Resume { .. }), "{err:?}");
    assert!(
        message.contains("output format 1 (time column `t`"),
        "{message}"
    );
    assert!(message.contains("without --resume"), "{message}");
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        old,
        "left as it was"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
