//! `[[measure]]`: a region of the `[granular]` sample in which a run measures what a DEM user
//! reads off a packing (`measure_NAME.csv`, `measure_NAME.svg`; see
//! `qdem_io::post::contact_stress` for the definitions).

use serde::{Deserialize, Serialize};

scene_table! {
    /// `[[measure]]`: a box, or a sphere, over the `[granular]` sample; every `every` seconds the
    /// run writes a row of `measure_NAME.csv`: the contact stress tensor (Love–Weber), the solid
    /// fraction and porosity, the coordination number and the kinetic energy of the stones whose
    /// centre of mass lies inside.
    ///
    /// ```toml
    /// [[measure]]
    /// name = "bed"
    /// box = [[0.0, 0.0, 0.05], [0.3, 0.7, 0.15]]   # or center = [x, y, z] and radius = r
    /// every = 1e-3                                  # s; default as probes.csv's rows
    /// follow_wall = 2                               # optional: moves with the 2nd [[wall]]
    /// ```
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Measure in "[[measure]]" {
        name: String => "string", required,
            "Unique name: the files `measure_NAME.csv`, `measure_NAME.svg`, \
             `measure_NAME_energy.svg`.";
        #[serde(default)]
        region as "box": Option<[[f64; 3]; 2]> => "[[x, y, z], [x, y, z]]", optional,
            "The region as a box (lower and upper corner, m); or `center` and `radius`. Needs \
             `[granular]` and `[contact]`.";
        #[serde(default)]
        center: Option<[f64; 3]> => "[x, y, z]", optional,
            "Instead of `box`: the centre of a spherical region (m), with `radius`.";
        #[serde(default)]
        radius: Option<f64> => "number", optional,
            "With `center`: the spherical region's radius (m).";
        #[serde(default)]
        every: Option<f64> => "number", optional,
            "Simulated time between two rows of `measure_NAME.csv`, s; default `probe_every`.";
        #[serde(default)]
        follow_wall: Option<usize> => "integer", optional,
            "The K-th `[[wall]]` (from 1, `walls.csv`'s `wallK`) the region moves with: at each \
             row it is `box` or `center` translated by that wall's displacement since t = 0 \
             (`wallK.ux,uy,uz`), its volume unchanged (a layer under a servo lid).";
    }
}

/// The region of a validated `[[measure]]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MeasureRegion {
    /// Lower and upper corner (m).
    Box([[f64; 3]; 2]),
    /// Centre and radius (m).
    Sphere([f64; 3], f64),
}

impl Measure {
    /// Its region (a validated measure has exactly one).
    pub fn shape(&self) -> MeasureRegion {
        match (self.region, self.center, self.radius) {
            (Some(b), _, _) => MeasureRegion::Box(b),
            (None, Some(c), Some(r)) => MeasureRegion::Sphere(c, r),
            _ => MeasureRegion::Box([[0.0; 3]; 2]),
        }
    }
}

impl MeasureRegion {
    /// The region translated by `d` (m).
    pub fn shifted(&self, d: [f64; 3]) -> MeasureRegion {
        let add = |x: [f64; 3]| std::array::from_fn(|k| x[k] + d[k]);
        match *self {
            MeasureRegion::Box([lo, hi]) => MeasureRegion::Box([add(lo), add(hi)]),
            MeasureRegion::Sphere(c, r) => MeasureRegion::Sphere(add(c), r),
        }
    }

    /// Its volume (m³).
    pub fn volume(&self) -> f64 {
        match self {
            MeasureRegion::Box([lo, hi]) => (0..3).map(|k| hi[k] - lo[k]).product(),
            MeasureRegion::Sphere(_, r) => 4.0 / 3.0 * std::f64::consts::PI * r.powi(3),
        }
    }

    /// Whether the point `x` lies inside (boundary included).
    pub fn contains(&self, x: [f64; 3]) -> bool {
        match self {
            MeasureRegion::Box([lo, hi]) => (0..3).all(|k| x[k] >= lo[k] && x[k] <= hi[k]),
            MeasureRegion::Sphere(c, r) => {
                (0..3).map(|k| (x[k] - c[k]).powi(2)).sum::<f64>() <= r * r
            }
        }
    }
}
