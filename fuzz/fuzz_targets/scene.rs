//! The scene parser (TOML syntax, schema, semantic checks) on arbitrary text, seeded with the
//! scenes under `fixtures/` (`fuzz/seeds/scene`). Touches no file: `Scene::parse` reads and
//! writes nothing, and mesh files are not checked.
//!
//! Any `Err` is fine; a panic, an abort, a hang or an out-of-memory is a bug. A scene that
//! parses must pass `Scene::validate` again (the checks on a scene built in code), and every
//! error must display.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use qdem_io::scene::Scene;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match Scene::parse(text, Path::new("fuzz.toml")) {
        Ok(scene) => {
            if let Err(e) = scene.validate() {
                panic!("a parsed scene fails Scene::validate: {e}");
            }
        }
        Err(e) => {
            let _ = e.to_string();
        }
    }
});
