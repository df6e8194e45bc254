//! Regressions from the fuzzing campaign (`docs/fuzzing.md`).
//!
//! The 10-minute libFuzzer run of the `scene` target found no crash in scenes of up to 4 KB
//! (libFuzzer's length limit for these seeds). One resource bug lay beyond that size, found by
//! reviewing the checks for work that grows faster than the file and confirmed with the crafted
//! scene below (on which the fuzz target timed out after 120 s): a 968 KB scene with 8000
//! bodies and 8000 probes that name undefined bodies. Every problem
//! - found its line and column by scanning the text from its start,
//! - listed every defined body in its message (8000 names, in each of 8000 messages),
//! - ran the "did you mean" edit distance against every body name;
//!
//! and every `[[fix]]` looked for its body in the whole body list. The test took 102 s before
//! the fix (in the test profile), 1.4 s after. Now positions are resolved in one pass, messages
//! list at most 20 names, suggestions have a total budget, and the rigid-body lookup is a set.
//!
//! The scenes are generated here rather than committed (they are large). Speed is not asserted
//! here (no timed tests): a return of the quadratic behaviour shows as a test that takes
//! minutes.

use std::path::Path;

use qdem_io::scene::{Scene, SceneError};

const HEAD: &str = "[run]\nt_end = 1.0\n\n[[material]]\nname = \"m\"\ndensity = 1.0\n\
                    young = 1.0\npoisson = 0.2\n\n";

fn invalid(text: &str) -> Vec<qdem_io::scene::Diagnostic> {
    match Scene::parse(text, Path::new("big.toml")) {
        Err(SceneError::Invalid(ds)) => ds,
        Err(other) => panic!("expected SceneError::Invalid, got {other}"),
        Ok(_) => panic!("expected SceneError::Invalid, the scene parsed"),
    }
}

#[test]
fn thousands_of_undefined_bodies_are_checked_in_linear_time() {
    let n = 8000;
    let mut text = HEAD.to_owned();
    for k in 0..n {
        text.push_str(&format!(
            "[[body]]\nname = \"body{k:05}\"\nmesh = \"a.msh\"\nmaterial = \"m\"\nrigid = true\n\n"
        ));
    }
    // Line of the first [[probe]]'s `body` key: HEAD has 9 lines, each body 6.
    let first_probe_body = 9 + 6 * n + 3;
    for k in 0..n {
        text.push_str(&format!(
            "[[probe]]\nname = \"p\"\nbody = \"x{k:05}\"\npoint = [0.0, 0.0, 0.0]\n\n"
        ));
    }
    for k in 0..n {
        text.push_str(&format!(
            "[[fix]]\nbody = \"body{k:05}\"\ngroup = \"g\"\nrotation = true\n\n"
        ));
    }
    let ds = invalid(&text);
    // Per probe: its body is undefined and (but for the first) its name is a duplicate; the
    // fixes hold rigid bodies, so rotation = true is fine.
    assert_eq!(ds.len(), 2 * n - 1);
    let d = &ds[0];
    assert_eq!((d.line, d.column), (Some(first_probe_body), Some(8)));
    assert!(
        d.message
            .starts_with("[[probe]] \"p\": body \"x00000\" is not defined"),
        "{}",
        d.message
    );
    assert!(
        d.message
            .ends_with("\"body00018\", \"body00019\", … and 7980 more)"),
        "{}",
        d.message
    );
    // The duplicate name of the second probe, with the line of the first.
    let d = &ds[1];
    assert_eq!(d.line, Some(first_probe_body + 4));
    assert!(
        d.message
            .contains(&format!("already used at line {}", first_probe_body - 1)),
        "{}",
        d.message
    );
    // The last problem: the last probe's body.
    let d = ds.last().unwrap();
    assert_eq!(d.line, Some(first_probe_body + 5 * (n - 1)));
    assert!(d.message.contains("body \"x07999\""), "{}", d.message);
}

#[test]
fn thousands_of_problems_on_one_line_get_their_columns() {
    // The same probes as an array of inline tables on one line: the one-pass positions must
    // still give every column (in characters, past multi-byte ones).
    let n = 8000;
    let mut line = String::from("probe = [");
    let mut columns = Vec::new();
    for k in 0..n {
        if k > 0 {
            line.push_str(", ");
        }
        line.push_str(&format!("{{ name = \"p{k:05}\", body = "));
        columns.push(line.chars().count() + 1);
        line.push_str(&format!("\"bé{k:05}\", point = [0.0, 0.0, 0.0] }}"));
    }
    line.push(']');
    // A top-level key: before the first table.
    let mut text = format!("{line}\n\n{HEAD}");
    text.push_str("[[body]]\nname = \"beam\"\nmesh = \"a.msh\"\nmaterial = \"m\"\n");
    let ds = invalid(&text);
    assert_eq!(ds.len(), n);
    for (k, (d, &column)) in ds.iter().zip(&columns).enumerate() {
        assert_eq!((d.line, d.column), (Some(1), Some(column)), "probe {k}");
    }
    // A small scene still gets its suggestion.
    assert!(ds[0].message.contains("body \"bé00000\" is not defined"));
    let ds = invalid(&text.replace("\"bé00000\"", "\"bean\""));
    assert!(
        ds[0].message.contains("did you mean \"beam\"?"),
        "{}",
        ds[0].message
    );
}
