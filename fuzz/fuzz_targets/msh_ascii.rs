//! The gmsh MSH reader on arbitrary bytes, seeded with ASCII files (`fuzz/seeds/msh_ascii`);
//! the checks are shared with the other MSH target (`msh_checks.rs`), which exists so that
//! each kind of file keeps a corpus of its own.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "msh_checks.rs"]
mod msh_checks;

fuzz_target!(|data: &[u8]| msh_checks::check(data));
