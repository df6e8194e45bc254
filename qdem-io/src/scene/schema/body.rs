//! `[[body]]`: the continuum bodies meshed with tetrahedra.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

scene_table! {
    /// `[[body]]`: a continuum body meshed with tetrahedra.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Body in "[[body]]" {
        name: String => "string", required,
            "Unique name that fixes, loads and probes refer to.";
        mesh: PathBuf => "path", required,
            "The gmsh mesh file (MSH 2.2 or 4.1, linear tetrahedra), relative to the scene file.";
        material: String => "string", required,
            "Name of a `[[material]]`.";
        #[serde(default = "default_true")]
        reorder: bool => "bool", optional = "true",
            "Reorder nodes for memory locality after import; default `true`.";
        #[serde(default)]
        merge_nodes: bool => "bool", optional = "false",
            "Merge the mesh's coincident nodes (nodes at one place, within 1e-9 of the mesh's \
             size, that its tetrahedra do not share, as separately meshed volumes leave them) so \
             that the tetrahedra on either side connect; default `false`: they are reported in a \
             warning and the body stays in pieces there.";
        #[serde(default)]
        contact_radius: Option<f64> => "number", optional,
            "Radius (m) of the contact spheres put at the body's surface vertices (paper 000 §4); \
             `None` (the default): the body touches nothing.";
        #[serde(default)]
        rigid: bool => "bool", optional = "false",
            "Integrate the body as a rigid body (6 degrees of freedom, mass and inertia from its \
             tetrahedra) instead of a deformable one; default `false`.";
        #[serde(default)]
        translate: [f64; 3] => "[x, y, z]", optional = "[0.0, 0.0, 0.0]",
            "Translation applied to the mesh after the rotation (m); default zero.";
        #[serde(default)]
        rotate_deg: [f64; 3] => "[x, y, z]", optional = "[0.0, 0.0, 0.0]",
            "Rotation of the mesh about its nodes' centroid, in degrees about x, then y, then z \
             (fixed axes); default zero.";
        #[serde(default)]
        velocity: [f64; 3] => "[x, y, z]", optional = "[0.0, 0.0, 0.0]",
            "Initial velocity of every particle of the body (m/s); default zero.";
        #[serde(default)]
        angular_velocity: [f64; 3] => "[x, y, z]", optional = "[0.0, 0.0, 0.0]",
            "Initial angular velocity of the body about its centre of mass (rad/s, world axes): a \
             rigid body's ω; a deformable body's particles get v + ω × (x − x_c) in addition to \
             `velocity`. Default zero.";
        #[serde(default)]
        rest_on: Option<String> => "string", optional,
            "Name of the `[granular]` sample to lay the body on: after `translate` it is lowered \
             along −z until its contact spheres touch the stones beneath (`rest_on.rs`); default \
             none (the body stays where `translate` puts it).";
        #[serde(default)]
        pose_from: Option<PathBuf> => "path", optional,
            "A `poses.csv` written by an earlier run (relative to the scene file): a rigid body is \
             placed where that run left its body of the same name (`pose_from.rs`); default none.";
        #[serde(default)]
        pose_body: Option<String> => "string", optional,
            "With `pose_from`: take the pose of this body of the poses file instead of the body of \
             the same name (the sleepers of a three-sleeper box placed from the one sleeper of a \
             periodic cell); default the body's own name.";
        #[serde(default)]
        pose_shift: [f64; 3] => "[x, y, z]", optional = "[0.0, 0.0, 0.0]",
            "With `pose_from`: added to the pose's centre of mass (m), e.g. one period along a \
             periodic axis; default zero.";
    }
}

fn default_true() -> bool {
    true
}
