//! What both MSH targets check: any `Err` is fine; a panic, an abort, a hang or an
//! out-of-memory is a bug. A mesh that is read must keep the reader's promises (indices in
//! range, positive tetrahedra, sorted unique group node sets), and every error must display.

use std::path::Path;

/// Reads `data` as an MSH file and checks the result.
pub fn check(data: &[u8]) {
    match qdem_mesh::parse_msh(data, Path::new("fuzz.msh")) {
        Ok((mesh, warnings)) => {
            let n = mesh.nodes.len();
            assert!(!mesh.tets.is_empty());
            for t in &mesh.tets {
                assert!(
                    t.iter().all(|&k| (k as usize) < n),
                    "tet {t:?} out of range"
                );
                let p = t.map(|k| mesh.nodes[k as usize]);
                assert!(
                    qdem_mesh::signed_volume6(&p) > 0.0,
                    "tet {t:?} not positive"
                );
            }
            for g in &mesh.groups {
                assert!(
                    g.nodes.windows(2).all(|w| w[0] < w[1]),
                    "group {} unsorted",
                    g.name
                );
                assert!(
                    g.nodes.iter().all(|&k| (k as usize) < n),
                    "group {} out of range",
                    g.name
                );
            }
            for w in &warnings {
                let _ = w.to_string();
            }
        }
        Err(e) => {
            let _ = e.to_string();
        }
    }
}
