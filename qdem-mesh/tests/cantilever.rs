//! The cantilever fixtures of the QDEM paper (2.4 × 0.25 × 0.22 m box).

mod common;

use common::{fixture, rel};
use qdem_mesh::read_msh;

#[test]
fn cantilever_fixtures() {
    for (name, nodes, tets) in [
        ("cantilever_lc100.msh", 352, 915),
        ("cantilever_lc070.msh", 738, 2301),
        ("cantilever_lc050.msh", 1555, 5681),
    ] {
        let path = fixture(&format!("cantilever/{name}"));
        let (mut mesh, warnings) = read_msh(&path).unwrap();
        assert!(warnings.is_empty(), "{name}: {warnings:?}");
        assert_eq!((mesh.nodes.len(), mesh.tets.len()), (nodes, tets), "{name}");
        assert!(rel(mesh.volume(), 2.4 * 0.25 * 0.22) < 1e-10, "{name}");
        let centre = [2.4, 0.125, 0.11];
        let k = mesh.nearest_node(centre).unwrap();
        assert_eq!(mesh.nodes[k as usize], centre, "{name}");
        assert_eq!(mesh.require_group("tip_centre", &path).unwrap().nodes, [k]);
        let clamp = mesh.require_group("clamp", &path).unwrap();
        assert!(clamp
            .nodes
            .iter()
            .all(|&n| mesh.nodes[n as usize][0] == 0.0));
        assert_eq!(clamp.nodes, mesh.nodes_in_box([-1.0; 3], [0.0, 1.0, 1.0]));
        let tip = mesh.require_group("tip", &path).unwrap();
        assert!(tip.nodes.contains(&k));
        assert!(tip.nodes.iter().all(|&n| mesh.nodes[n as usize][0] == 2.4));
        assert_eq!(mesh.group("beam").unwrap().nodes.len(), nodes);
        let s = mesh.stats();
        assert!(
            s.worst_quality > 0.05 && s.worst_quality <= 1.0,
            "{name}: {s:?}"
        );
        let bw = mesh.bandwidth();
        mesh.reorder_for_locality();
        assert!(mesh.bandwidth() < bw, "{name}");
        assert!(rel(mesh.volume(), 2.4 * 0.25 * 0.22) < 1e-10);
        let k = mesh.nearest_node(centre).unwrap();
        assert_eq!(mesh.nodes[k as usize], centre);
        assert_eq!(mesh.group("tip_centre").unwrap().nodes, [k]);
    }
}
