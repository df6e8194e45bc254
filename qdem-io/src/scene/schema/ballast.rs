//! `[ballast]`: deformable ballast stones.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

scene_table! {
    /// `[ballast]`: deformable ballast stones (paper 000 §4): copies of gmsh stone meshes, each a
    /// QDEM body with contact spheres at its surface vertices, scaled to a grading curve, turned at
    /// random and laid on a loose lattice in `region` to be deposited under gravity. Together the
    /// stones are one body called `name` (for probes, fixes, loads and output); in contact each
    /// stone is its own body.
    ///
    /// ```toml
    /// [ballast]
    /// name = "ballast"
    /// material = "granite"
    /// meshes = ["stones/coarse/stone_00.msh", "stones/coarse/stone_01.msh"]
    /// contact_radius = 0.012
    /// count = 300
    /// region = [[-2.3, 0.0, 0.0], [2.3, 0.6, 1.0]]
    /// exclude = [[-1.1, 0.15, 0.25], [1.1, 0.45, 1.0]]   # optional: keep clear (a sleeper)
    /// grading = [[0.04, 0.0], [0.05, 0.5], [0.063, 1.0]]  # optional (sieve size m, passing)
    /// seed = 1
    /// velocity = [0.0, 0.0, -2.0]                           # optional (m/s)
    /// rigid = false                                         # optional: rigid stones
    /// ```
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Ballast in "[ballast]" {
        name: String => "string", required,
            "Name of the ballast body (stones are `NAME stone K` in messages).";
        material: String => "string", required,
            "A `[[material]]`.";
        meshes: Vec<PathBuf> => "[path, …]", required,
            "Stone shapes: tetrahedral gmsh meshes, relative to the scene file.";
        contact_radius: f64 => "number", required,
            "Radius of the contact spheres at the stones' surface vertices, m (after scaling).";
        count: usize => "integer", required,
            "Number of stones.";
        region: [[f64; 3]; 2] => "[[x, y, z], [x, y, z]]", required,
            "The box filled with stones, bottom layer first (m).";
        #[serde(default)]
        exclude: Option<[[f64; 3]; 2]> => "[[x, y, z], [x, y, z]]", optional,
            "A box no stone may reach into (m).";
        #[serde(default)]
        grading: Option<Vec<[f64; 2]>> => "[[size, passing], …]", optional,
            "Grading curve, (sieve size m, fraction passing) points; a stone's sieve size is the \
             middle extent of its bounding box. Without one the meshes keep their size.";
        #[serde(default = "super::default_seed")]
        seed: u64 => "integer", optional = "1",
            "Seed of the shapes, sizes, turns and lattice jitter; default 1.";
        #[serde(default)]
        velocity: [f64; 3] => "[x, y, z]", optional = "[0.0, 0.0, 0.0]",
            "Initial velocity of every stone (m/s), e.g. downward to shorten the fall; default 0.";
        #[serde(default)]
        angular_velocity: [f64; 3] => "[x, y, z]", optional = "[0.0, 0.0, 0.0]",
            "Initial angular velocity of every stone about its own centre of mass (rad/s, world \
             axes): its particles get v + ω × (x − x_c); default 0.";
        #[serde(default)]
        rigid: bool => "bool", optional = "false",
            "Each stone a rigid body of its contact spheres (mass, centre and inertia from its \
             tetrahedra) instead of a deformable one; default `false`. A scene that `start_from`s \
             a checkpoint may change it: stones become deformable at their pose, unstressed, or \
             rigid at their centre of mass and best-fit rotation.";
    }
}
