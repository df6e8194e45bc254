//! The reader never panics: truncations at every 97th byte, and deterministic random byte
//! corruption, of valid ASCII and binary files of both versions.

mod common;

use common::fixture;
use qdem_mesh::parse_msh;

const FILES: [&str; 6] = [
    "box_gmsh22_ascii.msh",
    "box_gmsh22_binary.msh",
    "box_gmsh41_ascii.msh",
    "box_gmsh41_binary.msh",
    "box_meshio41_binary.msh",
    "box_meshio22_binary.msh",
];

#[test]
fn truncation_at_every_97th_byte_is_an_error() {
    for name in FILES {
        let path = fixture(&format!("msh/{name}"));
        let bytes = std::fs::read(&path).unwrap();
        assert!(parse_msh(&bytes, &path).is_ok());
        for cut in (0..bytes.len()).step_by(97) {
            if bytes[cut..].iter().all(u8::is_ascii_whitespace) {
                continue; // only the final newline cut: still a complete file
            }
            let r = parse_msh(&bytes[..cut], &path);
            assert!(r.is_err(), "{name} cut at {cut} parsed");
        }
    }
}

/// A small deterministic generator (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

/// Iterations per file; `QDEM_FUZZ_ITERS` raises it for a longer local run.
fn iterations() -> usize {
    std::env::var("QDEM_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300)
}

#[test]
fn corrupted_bytes_never_panic() {
    let mut rng = Rng(42);
    let iters = iterations();
    for name in FILES {
        let path = fixture(&format!("msh/{name}"));
        let bytes = std::fs::read(&path).unwrap();
        for _ in 0..iters {
            let mut b = bytes.clone();
            for _ in 0..1 + rng.next() % 4 {
                let at = (rng.next() % b.len() as u64) as usize;
                b[at] = match rng.next() % 4 {
                    0 => 0xff,
                    1 => 0,
                    2 => b"0123456789-$ \n"[(rng.next() % 14) as usize],
                    _ => rng.next() as u8,
                };
            }
            // Ok or Err are both fine; a panic fails the test.
            let _ = parse_msh(&b, &path);
        }
    }
}

#[test]
fn hostile_words_in_binary_files_never_panic() {
    // Overwrite an 8-byte window at every 7th offset with huge, negative or zero values: this
    // hits every count, size_t, tag and type field of the binary sections.
    let words: [[u8; 8]; 4] = [
        [0xff; 8],
        [0xff, 0xff, 0xff, 0x7f, 0xff, 0xff, 0xff, 0x7f],
        [0; 8],
        [0x00, 0x00, 0x00, 0x80, 0x00, 0x00, 0x00, 0x80],
    ];
    for name in ["box_gmsh41_binary.msh", "box_gmsh22_binary.msh"] {
        let path = fixture(&format!("msh/{name}"));
        let bytes = std::fs::read(&path).unwrap();
        for at in (0..bytes.len().saturating_sub(8)).step_by(7) {
            for w in &words {
                let mut b = bytes.clone();
                b[at..at + 8].copy_from_slice(w);
                let _ = parse_msh(&b, &path);
            }
        }
    }
}
