//! `[output]`: where and how often to write results.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

scene_table! {
    /// `[output]`: where and how often to write results.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Output in "[output]" {
        #[serde(default = "default_out_dir")]
        dir: PathBuf => "path", optional = "\"out\"",
            "Output directory as written (default `\"out\"`); the command line's `--out` overrides \
             it.";
        #[serde(default)]
        vtu_every: f64 => "number", optional = "0.0",
            "Simulated time between VTU snapshots, s; 0 (the default) writes none, except a static \
             run's final state.";
        #[serde(default)]
        checkpoint_every: f64 => "number", optional = "0.0",
            "Simulated time between checkpoints (`checkpoint.qdc` in the output directory, which \
             `qdem run --resume` continues from), s; 0 (the default) writes one only when the run \
             is interrupted (Ctrl-C, SIGTERM) or becomes unstable.";
        #[serde(default)]
        node_reactions: bool => "bool", optional = "false",
            "Whether to write `node_reactions.csv`: every `probe_every`, the force each `[[fix]]` \
             of a deformable body, or holding a rigid body at points, carries at each of its \
             particles, with the particle's gmsh node id and reference position; default false.";
    }
}

impl Output {
    /// Whether VTU snapshots are requested.
    pub fn writes_vtu(&self) -> bool {
        self.vtu_every > 0.0
    }
}

impl Default for Output {
    fn default() -> Output {
        Output {
            dir: default_out_dir(),
            vtu_every: 0.0,
            checkpoint_every: 0.0,
            node_reactions: false,
        }
    }
}

fn default_out_dir() -> PathBuf {
    PathBuf::from("out")
}
