//! `qdem verify --json`: the quick analytical fixtures all pass, and the JSON is well formed.

use std::process::Command;
use std::time::Instant;

#[test]
fn verify_json_passes_every_row() {
    let start = Instant::now();
    let output = Command::new(env!("CARGO_BIN_EXE_qdem"))
        .args(["verify", "--json"])
        .env("CI", "1")
        .output()
        .expect("start the qdem binary");
    let seconds = start.elapsed().as_secs_f64();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "qdem verify --json failed ({}):\n{stderr}\n{stdout}",
        output.status
    );
    let rows: serde_json::Value = serde_json::from_str(&stdout)
        .unwrap_or_else(|e| panic!("stdout is not JSON ({e}):\n{stdout}"));
    let rows = rows.as_array().expect("a JSON array of rows");
    assert!(
        rows.len() >= 4,
        "expected the 4 quick fixtures, got {}",
        rows.len()
    );
    for row in rows {
        for key in [
            "fixture",
            "analytical",
            "computed",
            "relative_error",
            "tolerance",
            "cpu_seconds",
        ] {
            assert!(row.get(key).is_some(), "row without `{key}`: {row}");
        }
        assert_eq!(row["passed"], true, "fixture did not pass: {row:#}");
    }
    eprintln!("qdem verify --json: {} rows in {seconds:.1} s", rows.len());
}
