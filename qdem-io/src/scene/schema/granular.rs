//! `[granular]`: a sample of rigid stones, each a clump of spheres.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

scene_table! {
    /// `[granular]`: a sample of rigid stones, each a clump of spheres (paper 003 §3), read from a
    /// `sample` file (the `stones.csv` a run writes; `crop` keeps its stones lying wholly inside a
    /// box) and/or generated loosely in `region` to be deposited under gravity.
    ///
    /// ```toml
    /// [granular]
    /// name = "ballast"
    /// material = "granite"
    /// region = [[0, 0, 0.05], [0.3, 0.7, 1.2]]
    /// count = 400
    /// grading = [[0.0224, 0.0], [0.04, 0.5], [0.0625, 1.0]]  # (size m, fraction passing)
    /// grading_basis = "mass"               # optional: fractions of mass; default "number"
    /// spheres_per_stone = [3, 5]
    /// shape = "angular"                    # optional: a stone with corners; default "elongated"
    /// seed = 1
    /// velocity = [0.0, 0.0, -1.0]          # optional, m/s: every stone
    /// angular_velocity = [0.0, 20.0, 0.0]  # optional, rad/s: every stone about its centre
    /// # region_velocity, region_angular_velocity: the generated stones' instead (a pour onto a
    /// # sample at rest)
    /// # or: sample = "stones.csv", crop = [[0, 0.7, 0], [0.3, 1.4, 0.45]]
    /// # a periodic cell's sample repeated along y:
    /// # sample = "stones.csv", copies = [[0, -0.7, 0], [0, 0, 0], [0, 0.7, 0]]
    /// # a periodic cell's whole sample between walls at y = 0.7 and 1.4, to pour back:
    /// # sample = "stones.csv", refill = [[0, 0.7, 0.5], [0.3, 1.4, 2.0]]
    /// ```
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Granular in "[granular]" {
        name: String => "string", required,
            "Name (stones are called `NAME stone K` in messages).";
        material: String => "string", required,
            "A `[[material]]` (density and contact elasticity).";
        #[serde(default)]
        sample: Option<PathBuf> => "path", optional,
            "A stones file (CSV `stone,x,y,z,radius`), relative to the scene file.";
        #[serde(default = "default_copies")]
        copies: Vec<[f64; 3]> => "[[x, y, z], …]", optional = "[[0.0, 0.0, 0.0]]",
            "The sample's stones placed once per translation (m), before `crop`: a sample \
             deposited in a periodic cell, repeated by whole periods, fills a box several cells \
             long with the cell's packing; default `[[0.0, 0.0, 0.0]]`, one copy where the file \
             puts it.";
        #[serde(default)]
        crop: Option<[[f64; 3]; 2]> => "[[x, y, z], [x, y, z]]", optional,
            "Keep only the sample's stones whose spheres all lie inside this box (m), up to \
             `CROP_TOLERANCE` of a radius (a stone resting on a wall of the box stays).";
        #[serde(default)]
        refill: Option<[[f64; 3]; 2]> => "[[x, y, z], [x, y, z]]", optional,
            "A walled box's whole sample, to be poured back in a deposition run: after `copies` \
             and `crop`, the sample's stones not wholly inside this box along x and y (those \
             astride a wall a crop would drop) are moved inside it by their overhang and \
             stacked from its lower z up, clear of each other (m; the other stones must lie \
             below its lower z, the stack below its upper z). The box keeps every stone, so the \
             same count and mass as the sample.";
        #[serde(default)]
        region: Option<[[f64; 3]; 2]> => "[[x, y, z], [x, y, z]]", optional,
            "Generation: the box filled with stones on a loose lattice (m).";
        #[serde(default)]
        count: Option<usize> => "integer", optional,
            "Generation: number of stones, at least 1.";
        #[serde(default)]
        grading: Option<Vec<[f64; 2]>> => "[[size, passing], …]", optional,
            "Generation: the grading curve, (sieve size m, fraction passing) points.";
        #[serde(default)]
        grading_basis: GradingBasisName => "\"number\" or \"mass\"", optional = "\"number\"",
            "Generation: what `grading`'s fractions passing count: `\"number\"` (default) the \
             fraction of stones finer than a size (the sample is coarser by mass than the curve), \
             `\"mass\"` the fraction of mass, as sieve analyses and ballast standards give it \
             (within a segment the mass is spread uniformly in size, a stone weighing ∝ d³).";
        #[serde(default = "default_spheres_per_stone")]
        spheres_per_stone: [usize; 2] => "[integer, integer]", optional = "[3, 5]",
            "Generation: smallest and largest number of spheres per stone; default [3, 5].";
        #[serde(default)]
        shape: ClumpShapeName => "\"elongated\" or \"angular\"", optional = "\"elongated\"",
            "Generation: the stones' shape: `\"elongated\"` (default) a row of spheres along a \
             long axis, a flaky stone; `\"angular\"` a core sphere with the other spheres as \
             corners out towards an ellipsoid, like crushed ballast. Either is scaled so that \
             its sieve size as `grading.csv` measures it (the middle extent of its spheres' \
             union) is the size drawn from `grading`: a stone's longest extent is then 1.4–2.0 \
             times its sieve size if elongated, 1.1–1.6 if angular (10th to 90th percentile); \
             one sphere is a plain sphere of diameter d.";
        #[serde(default = "super::default_seed")]
        seed: u64 => "integer", optional = "1",
            "Generation: seed; default 1.";
        #[serde(default)]
        velocity: [f64; 3] => "[x, y, z]", optional = "[0.0, 0.0, 0.0]",
            "Initial velocity of every stone (m/s); default zero.";
        #[serde(default)]
        angular_velocity: [f64; 3] => "[x, y, z]", optional = "[0.0, 0.0, 0.0]",
            "Initial angular velocity of every stone about its centre of mass (rad/s, world axes); \
             default zero.";
        #[serde(default)]
        region_velocity: Option<[f64; 3]> => "[x, y, z]", optional,
            "Initial velocity of the generated (`region`) stones instead of `velocity` (m/s): \
             grains poured onto a sample at rest; default `velocity`.";
        #[serde(default)]
        region_angular_velocity: Option<[f64; 3]> => "[x, y, z]", optional,
            "Initial angular velocity of the generated stones instead of `angular_velocity` \
             (rad/s); default `angular_velocity`.";
    }
}

impl Granular {
    /// The initial velocity and angular velocity of a stone, generated or from the sample.
    pub fn motion(&self, generated: bool) -> ([f64; 3], [f64; 3]) {
        match generated {
            true => (
                self.region_velocity.unwrap_or(self.velocity),
                self.region_angular_velocity
                    .unwrap_or(self.angular_velocity),
            ),
            false => (self.velocity, self.angular_velocity),
        }
    }
}

fn default_copies() -> Vec<[f64; 3]> {
    vec![[0.0; 3]]
}

fn default_spheres_per_stone() -> [usize; 2] {
    [3, 5]
}

/// `[granular] grading_basis`: what the grading's fractions passing count
/// (`qdem_contact::samples::clump_sample::GradingBasis`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GradingBasisName {
    /// The fraction of stones finer than a size: the curve is sampled by number.
    #[default]
    Number,
    /// The fraction of mass finer than a size.
    Mass,
}

/// `[granular] shape`: how a generated stone's spheres are arranged
/// (`qdem_contact::samples::clump_shape::ClumpShape`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ClumpShapeName {
    /// A row of spheres along the long axis: an elongated, flaky stone.
    #[default]
    Elongated,
    /// A core sphere with corner spheres out towards an ellipsoid: a stone with corners.
    Angular,
}
