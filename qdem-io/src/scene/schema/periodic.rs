//! `[periodic]` and `[periodic.time_delay]`: periodic and time-delayed boundaries.

use serde::{Deserialize, Serialize};

scene_table! {
    /// `[periodic]`: periodic boundaries (paper 003 §4) along `axes`, over `length` (one period
    /// per listed axis, from `origin`) or over the `box`.
    ///
    /// ```toml
    /// [periodic]
    /// axes = "y"
    /// length = [0.7]            # or box = [[0, 0, 0], [0.3, 0.7, 0.45]]
    /// origin = [0.0, 0.0, 0.0]  # optional
    ///
    /// [periodic.time_delay]     # optional: paper 003 §5
    /// body = "sleeper"          # the body whose cyclic [[load]] gives the phase
    /// lag_deg = 90.0            # or sleeper_spacing and speed (m, m/s)
    /// shared_faces = false      # true: one scale for both sides of a pair (qdem's variant)
    /// ```
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Periodic in "[periodic]" {
        axes: String => "string", required,
            "The periodic axes, e.g. `\"y\"` or `\"xy\"`.";
        #[serde(default)]
        length: Option<Vec<f64>> => "[number, …]", optional,
            "One period per listed axis (m), in the order of `axes`.";
        #[serde(default)]
        origin: Option<[f64; 3]> => "[x, y, z]", optional,
            "The lower corner of the cell (m); default the origin.";
        #[serde(default)]
        bbox as "box": Option<[[f64; 3]; 2]> => "[[x, y, z], [x, y, z]]", optional,
            "The cell as a box (lower and upper corner, m): origin and periods at once.";
        #[serde(default)]
        time_delay: Option<TimeDelay> => "table", optional,
            "A time-delayed boundary.";
    }
}

scene_table! {
    /// `[periodic.time_delay]`: ghost forces scaled by the load phase of the neighbour cells
    /// (paper 003 Eqs. 2–7).
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct TimeDelay in "[periodic.time_delay]" {
        body: String => "string", required,
            "The body (a sleeper) whose `cyclic` [[load]] sets the phase Φ.";
        #[serde(default)]
        axis: Option<String> => "string", optional,
            "The delayed axis; default the only periodic axis.";
        #[serde(default)]
        lag_deg: Option<f64> => "number", optional,
            "Phase lag δ of the neighbour cells (degrees); default 90 (paper 003 Eqs. 4–5).";
        #[serde(default)]
        sleeper_spacing: Option<f64> => "number", optional,
            "With `speed`: the lag δ = 360° f s / v of sleepers `sleeper_spacing` apart (m).";
        #[serde(default)]
        speed: Option<f64> => "number", optional,
            "With `sleeper_spacing`: the speed of the travelling load (m/s).";
        #[serde(default)]
        shared_faces: bool => "bool", optional = "false",
            "Shared faces (qdem's variant, not paper 003's Eqs. 6–7): both spheres of a pair \
             through the boundary scaled alike, by the mean of the two faces' predicted forces, so \
             the pair's action equals its reaction; default false.";
    }
}
