//! Reads gmsh MSH files and prints their statistics, groups, warnings and timings.
//!
//! ```sh
//! cargo run --release -p qdem-mesh --example msh_info -- fixtures/cantilever/*.msh
//! ```

use std::path::Path;
use std::time::Instant;

fn main() {
    let mut failed = false;
    for arg in std::env::args().skip(1) {
        let path = Path::new(&arg);
        let t0 = Instant::now();
        match qdem_mesh::read_msh(path) {
            Ok((mut mesh, warnings)) => {
                let read = t0.elapsed();
                println!(
                    "{}: read in {:.1} ms",
                    path.display(),
                    read.as_secs_f64() * 1e3
                );
                for w in &warnings {
                    println!("  warning: {w}");
                }
                println!("  {:?}", mesh.stats());
                for g in &mesh.groups {
                    println!(
                        "  group \"{}\" (dim {}, tag {}): {} nodes",
                        g.name,
                        g.dim,
                        g.tag,
                        g.nodes.len()
                    );
                }
                let bw = mesh.bandwidth();
                let t1 = Instant::now();
                mesh.reorder_for_locality();
                println!(
                    "  reorder_for_locality: {:.1} ms, bandwidth {} -> {}",
                    t1.elapsed().as_secs_f64() * 1e3,
                    bw,
                    mesh.bandwidth()
                );
                let t2 = Instant::now();
                let surf = mesh.surface_triangles();
                println!(
                    "  {} surface triangles in {:.1} ms",
                    surf.len(),
                    t2.elapsed().as_secs_f64() * 1e3
                );
            }
            Err(e) => {
                eprintln!("error: {e}");
                failed = true;
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
}
