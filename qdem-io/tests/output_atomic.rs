//! Atomic writes: failures keep the previous content and leave no temporary file;
//! streamed files appear only on commit; the summary JSON goes through the same path.

mod common;
use common::*;
use std::io::{self, Write};
use std::path::Path;

use qdem_io::output::{write_atomic, write_summary, AtomicFile, IoStage, OutputError};

#[test]
fn failing_writer_keeps_previous_content_and_no_temp_file() {
    let dir = test_dir("atomic-fail");
    let path = dir.join("out.txt");
    write_atomic(&path, |w| w.write_all(b"first\n")).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "first\n");
    assert_eq!(entries(&dir), ["out.txt"]);

    // Fails after writing more than the buffer holds, so part of it reached the disk.
    let err = write_atomic(&path, |w| {
        w.write_all(&vec![b'x'; 1 << 20])?;
        Err(io::Error::other("simulated failure"))
    })
    .unwrap_err();
    match &err {
        OutputError::Io {
            path: p,
            stage,
            source,
            temp,
            ..
        } => {
            assert_eq!(p, &path);
            assert_eq!(*stage, IoStage::Write);
            assert_eq!(source.to_string(), "simulated failure");
            assert_eq!(
                temp.file_name().unwrap().to_string_lossy(),
                format!(".out.txt.tmp-{}", std::process::id())
            );
        }
        other => panic!("expected an Io error, got {other:?}"),
    }
    let msg = err.to_string();
    assert!(
        msg.contains(&path.display().to_string()) && msg.contains("simulated failure"),
        "{msg}"
    );
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "first\n");
    assert_eq!(entries(&dir), ["out.txt"]);

    // A failure on a file that did not exist yet creates nothing.
    let fresh = dir.join("fresh.txt");
    write_atomic(&fresh, |_| Err(io::Error::other("nope"))).unwrap_err();
    assert_eq!(entries(&dir), ["out.txt"]);

    // And a successful write replaces the content.
    write_atomic(&path, |w| w.write_all(b"second\n")).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "second\n");
    assert_eq!(entries(&dir), ["out.txt"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn missing_directory_is_an_error_naming_the_path() {
    let dir = test_dir("atomic-missing");
    let path = dir.join("no").join("such").join("file.txt");
    let err = write_atomic(&path, |w| w.write_all(b"x")).unwrap_err();
    assert!(
        matches!(
            &err,
            OutputError::Io {
                stage: IoStage::CreateTemp,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(
        err.to_string().contains(&path.display().to_string()),
        "{err}"
    );
    assert!(entries(&dir).is_empty());

    let err = AtomicFile::create(&path).unwrap_err();
    assert!(
        err.to_string().contains(&path.display().to_string()),
        "{err}"
    );
    let err = write_atomic(Path::new("/"), |_| Ok(())).unwrap_err();
    assert!(matches!(err, OutputError::NoFileName { .. }), "{err:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn atomic_file_appears_only_on_commit() {
    let dir = test_dir("atomic-file");
    let path = dir.join("stream.csv");
    std::fs::write(&path, "old\n").unwrap();

    let mut file = AtomicFile::create(&path).unwrap();
    assert_eq!(file.path(), path);
    for i in 0..1000 {
        writeln!(file.writer(), "{i}").unwrap();
    }
    file.writer().flush().unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "old\n");
    assert!(file.temp_path().exists());
    let temp = file.temp_path().to_path_buf();
    drop(file);
    assert!(
        !temp.exists(),
        "dropping without commit removes the temp file"
    );
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "old\n");
    assert_eq!(entries(&dir), ["stream.csv"]);

    let mut file = AtomicFile::create(&path).unwrap();
    for i in 0..1000 {
        writeln!(file.writer(), "{i}").unwrap();
    }
    file.commit().unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.lines().count(), 1000);
    assert_eq!(text.lines().last(), Some("999"));
    assert_eq!(entries(&dir), ["stream.csv"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn summary_is_pretty_json() {
    let dir = test_dir("summary");
    let path = dir.join("summary.json");
    let summary = serde_json::json!({
        "steps": 12345,
        "dt": 1.0e-7 / 3.0,
        "wall_time_s": 2.5,
        "energy": { "kinetic": 0.1, "strain": [1.0, 2.0] },
        "name": "cantilever \"A\"",
    });
    write_summary(&path, &summary).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.starts_with("{\n  \""), "{text}");
    assert!(text.ends_with("}\n"), "{text}");
    let back: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(back, summary);
    assert_eq!(
        back["dt"].as_f64().unwrap().to_bits(),
        (1.0e-7f64 / 3.0).to_bits()
    );
    assert_eq!(entries(&dir), ["summary.json"]);

    let err = write_summary(&dir.join("missing/summary.json"), &summary).unwrap_err();
    assert!(err.to_string().contains("summary JSON"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
