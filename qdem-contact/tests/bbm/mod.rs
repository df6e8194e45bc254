#![allow(dead_code)]
//! A simply supported bonded beam (paper 001 §5) built in code for the tests.

use qdem_contact::{
    BondSettings, BondedMaterial, BondedParticles, Packing, PackingKind, UnbondedLaw,
};
use qdem_core::{
    loads::NodalLoad, loads::TimeFunction, step::Dofs, step::Model, step::State, Vec3,
};

pub const LENGTH: f64 = 3.0;
pub const HEIGHT: f64 = 0.5;
pub const YOUNG: f64 = 30e9;
pub const POISSON: f64 = 0.25;

/// The beam, its supports and its load.
pub struct Beam {
    pub state: State,
    pub models: Vec<Box<dyn Model>>,
    pub packing: Packing,
    /// Distance between the two support lines (m).
    pub span: f64,
    /// Particles within half a spacing of midspan.
    pub midspan: Vec<usize>,
}

/// The beam at element size `h` under the line load `q` (N/m, downwards) with bond strengths
/// N(`mean`, `std`): the end particles of the full rows (one vertical line at each end) held
/// vertically, the left (and with `pin_both` the right) one nearest mid-height held
/// horizontally too. (Holding both zig-zag end particles of every row would clamp the ends
/// partly.)
pub fn beam(h: f64, q: f64, mean: f64, std: f64, pin_both: bool) -> Beam {
    let packing =
        Packing::rectangle([0.0, 0.0], [LENGTH, HEIGHT], h, PackingKind::Regular).unwrap();
    let (mut state, model) =
        BondedParticles::from_packing("beam", &packing, &material(mean, std), settings()).unwrap();
    let hs = packing.spacing;
    let y_mid = HEIGHT / 2.0;
    let x_max = packing
        .centers
        .iter()
        .map(|c| c[0])
        .fold(f64::MIN, f64::max);
    let mut left = Vec::new();
    let mut right = Vec::new();
    for (p, c) in packing.centers.iter().enumerate() {
        if c[0] < 0.6 * hs {
            left.push(p);
        }
        if c[0] > x_max - 0.1 * hs {
            right.push(p);
        }
    }
    let row_ends = |ids: &[usize], leftmost: bool| -> Vec<usize> {
        let mut by_row = std::collections::BTreeMap::new();
        for &p in ids {
            let key = (packing.centers[p][1] * 1e6).round() as i64;
            let e = by_row.entry(key).or_insert(p);
            let better = if leftmost {
                packing.centers[p][0] < packing.centers[*e][0]
            } else {
                packing.centers[p][0] > packing.centers[*e][0]
            };
            if better {
                *e = p;
            }
        }
        by_row.into_values().collect()
    };
    let (left, right) = (row_ends(&left, true), row_ends(&right, false));
    let y = Dofs::parse("y").unwrap();
    for &p in left.iter().chain(&right) {
        state.fix(p, y);
    }
    let closest = |ids: &[usize]| {
        *ids.iter()
            .min_by(|&&a, &&b| {
                let da = (packing.centers[a][1] - y_mid).abs();
                let db = (packing.centers[b][1] - y_mid).abs();
                da.total_cmp(&db)
            })
            .unwrap()
    };
    state.fix(closest(&left), Dofs::parse("x").unwrap());
    if pin_both {
        state.fix(closest(&right), Dofs::parse("x").unwrap());
    }
    let mean_x =
        |ids: &[usize]| ids.iter().map(|&p| packing.centers[p][0]).sum::<f64>() / ids.len() as f64;
    let span = mean_x(&right) - mean_x(&left);
    let top_y = packing
        .centers
        .iter()
        .map(|c| c[1])
        .fold(f64::MIN, f64::max);
    let top: Vec<u32> = (0..packing.len())
        .filter(|&p| (packing.centers[p][1] - top_y).abs() < 1e-9)
        .map(|p| p as u32)
        .collect();
    let load = NodalLoad::new(
        "line load",
        top,
        Vec3::new(0.0, -q * LENGTH, 0.0),
        TimeFunction::constant(1.0),
    );
    let centre = 0.5 * (mean_x(&left) + mean_x(&right));
    let midspan = (0..packing.len())
        .filter(|&p| (packing.centers[p][0] - centre).abs() < 0.51 * hs)
        .collect();
    Beam {
        state,
        models: vec![Box::new(model), Box::new(load)],
        packing,
        span,
        midspan,
    }
}

/// Undamped concrete (ρ = 2400 kg/m³, E, ν above, 1 m thick) with strengths N(`mean`, `std`).
pub fn material(mean: f64, std: f64) -> BondedMaterial {
    BondedMaterial {
        density: 2400.0,
        young: YOUNG,
        poisson: POISSON,
        thickness: 1.0,
        damping_ratio: 0.0,
        strength_mean: mean,
        strength_std: std,
        seed: 1,
    }
}

/// Undamped unbonded contacts (k_t0/k_n = 0.2, μ = 0.5), ε = 0.05.
pub fn settings() -> BondSettings {
    BondSettings {
        contact: UnbondedLaw {
            shear_ratio: 0.2,
            friction: 0.5,
            damping_ratio: 0.0,
        },
        tolerance: 0.05,
    }
}

impl Beam {
    /// Work of the line load `q` (shared equally by the top row) on the current displacement.
    pub fn load_work(&self, q: f64) -> f64 {
        let s = &self.state;
        let c = &self.packing.centers;
        let top_y = c.iter().map(|c| c[1]).fold(f64::MIN, f64::max);
        let top: Vec<usize> = (0..s.len())
            .filter(|&p| (c[p][1] - top_y).abs() < 1e-9)
            .collect();
        let per = q * LENGTH / top.len() as f64;
        top.iter().map(|&p| -per * s.displacement(p)[1]).sum()
    }

    /// Mean vertical displacement of the midspan section (m).
    pub fn midspan_deflection(&self) -> f64 {
        let s = &self.state;
        self.midspan
            .iter()
            .map(|&p| s.displacement(p)[1])
            .sum::<f64>()
            / self.midspan.len() as f64
    }

    /// The bonded-particle model.
    pub fn bonds(&self) -> &BondedParticles {
        let m: &dyn std::any::Any = self.models[0].as_ref();
        m.downcast_ref().unwrap()
    }

    /// The bonded-particle model, mutable.
    pub fn bonds_mut(&mut self) -> &mut BondedParticles {
        let m: &mut dyn std::any::Any = self.models[0].as_mut();
        m.downcast_mut().unwrap()
    }
}

/// Timoshenko's midspan deflection of a simply supported beam of span `l` under `q`:
/// 5ql⁴/(384EI) + ql²/(8κGA), κ = 5/6, plane stress.
pub fn timoshenko_deflection(q: f64, l: f64) -> f64 {
    let (b, h) = (1.0, HEIGHT);
    let i = b * h.powi(3) / 12.0;
    let g = YOUNG / (2.0 * (1.0 + POISSON));
    5.0 * q * l.powi(4) / (384.0 * YOUNG * i) + q * l * l / (8.0 * 5.0 / 6.0 * g * b * h)
}

/// The line load at which the midspan bending stress qL²/8 / (bH²/6) reaches `strength`.
pub fn cracking_load(strength: f64, l: f64) -> f64 {
    8.0 * strength * (HEIGHT * HEIGHT / 6.0) / (l * l)
}
