//! `[[probe]]` and `[[section]]`: what `probes.csv` and `sections.csv` follow.

use serde::{Deserialize, Serialize};

scene_table! {
    /// `[[probe]]`: what `probes.csv` follows. On a `[[body]]` (or `[ballast]`, `[bonded]`): the
    /// particle nearest `point`, its displacement, velocity and acceleration. On the `[granular]`
    /// sample (`body` names it): one stone, the one whose centre of mass is nearest `point` or
    /// the `stone`-th, followed at its centre of mass; or the stones whose centre of mass lies in
    /// `box` at each sample time, their mean velocity, kinetic energy and count.
    ///
    /// ```toml
    /// [[probe]]
    /// name = "ball"
    /// body = "grains"     # the [granular] name
    /// stone = 1           # or point = [x, y, z], or box = [[x0, y0, z0], [x1, y1, z1]]
    /// ```
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Probe in "[[probe]]" {
        name: String => "string", required,
            "Unique name (the CSV column prefix).";
        body: String => "string", required,
            "Name of the `[[body]]`, `[ballast]`, `[bonded]` body or `[granular]` sample.";
        #[serde(default)]
        point: Option<[f64; 3]> => "[x, y, z]", optional,
            "The particle of the body nearest to this point (in the reference configuration), or \
             the stone whose centre of mass is nearest to it, is sampled.";
        #[serde(default)]
        stone: Option<usize> => "integer", optional,
            "`[granular]` only: the stone sampled, counted from 1 in the sample's order (the \
             `stone` of `stones.csv`, `NAME stone K` in messages).";
        #[serde(default)]
        region as "box": Option<[[f64; 3]; 2]> => "[[x, y, z], [x, y, z]]", optional,
            "`[granular]` only: a box (lower and upper corner, m): the stones whose centre of mass \
             lies inside are averaged (columns `vx, vy, vz, ke, count`).";
    }
}

scene_table! {
    /// `[[section]]`: a plane x[axis] = `at` across which the average magnitude of the contact
    /// forces of touching sphere pairs is written to `sections.csv` at every probe time (the
    /// force through a cell face of a box test, paper 003 §5; in a periodic cell the plane
    /// repeats every period).
    ///
    /// ```toml
    /// [[section]]
    /// name = "left"
    /// axis = "y"
    /// at = 0.7
    /// ```
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Section in "[[section]]" {
        name: String => "string", required,
            "Unique name (the CSV column).";
        axis: String => "string", required,
            "The axis the plane is normal to: \"x\", \"y\" or \"z\".";
        at: f64 => "number", required,
            "The plane's coordinate along `axis` (m).";
        #[serde(default)]
        area: Option<f64> => "number", optional,
            "The section's area, m²: `sections.csv` also gives `NAME.stress`, the normal stress \
             through the plane (Pa, tension positive).";
    }
}
