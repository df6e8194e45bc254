//! Mass, centre of mass and inertia tensor of a stone: a rigid clump of spheres (paper 003 §3),
//! with a rigorous bound on their error.
//!
//! # One sphere
//! Exact: m = 4/3 π r³ ρ, the centre at the sphere's, I = 2/5 m r² times the identity.
//!
//! # Several spheres
//! The union of the spheres (overlaps counted once) is integrated with the midpoint rule on a
//! regular grid of spacing h = r_max/20, r_max the largest radius, anchored half a spacing off
//! the first sphere's centre: each grid point inside the union stands for a cube of side h
//! (its own inertia m·h²/6 included); a point belongs to the first sphere that contains it.
//!
//! **Error bound.** [`grid_error_bound`] bounds how far these values can be from the exact
//! mass properties of the union, rigorously: every grid cube that the spheres' surfaces may
//! cross (its centre within half its diagonal of a surface) is split into eight, again and
//! again to `depth` levels, each piece classed as wholly inside a sphere, wholly outside all,
//! or still uncertain. The exact moments of the pieces inside and the extent of the uncertain
//! ones bound the union's mass, first and second moments within the grid's cube; every other
//! cube the grid counts exactly. Mass: |Δm| ≤ max(|D_m|, |D_m − U_m|) with D the grid's minus
//! the certain pieces' moments and U the uncertain pieces' mass; centre: |Δc| ≤ |ΔS| / (m − |Δm|),
//! |ΔS| ≤ |D_S| + Σ_u m_u (|q − c| + s_u) about the computed centre c; inertia, entry by entry:
//! |D_I| + Σ_u m_u (|q − c| + s_u)² + (m + |Δm|) |Δc|² (the last the parallel-axis shift to the
//! true centre). The bound's width is the uncertain volume, which halves with every level; at
//! `depth` 4 it is 0.8% of the mass and 4% of the largest inertia entry for a three-sphere
//! ballast clump (0.75% of a two-sphere lens's mass), while the grid's actual errors there are
//! 0.06%, 0.1% and 0.02%, checked against a fine grid and the lens's closed form (the cubes
//! along the surface err both ways). It costs a hundred times the integration, so the build
//! does not compute it: the tests do.

use crate::samples::clump_sample::{SampleError, Stone};
use qdem_core::{Mat3, Vec3};
use std::f64::consts::PI;

/// Grid points per largest sphere radius in the integration of a clump of several spheres.
const GRID_PER_RADIUS: f64 = 20.0;

/// Mass (kg), centre of mass, inertia tensor about the centre of mass (kg m², world axes).
#[derive(Clone, Copy, Debug)]
pub struct MassProperties {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass (m).
    pub center: Vec3,
    /// Inertia tensor about the centre of mass (kg m², world axes).
    pub inertia: Mat3,
}

/// Largest errors of a [`clump_mass_properties`] result ([`grid_error_bound`], module docs):
/// its values are within these of the exact mass properties of the union of the spheres.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MassError {
    /// On the mass (kg).
    pub mass: f64,
    /// On the centre of mass, as a distance (m).
    pub center: f64,
    /// On every entry of the inertia tensor (kg m²).
    pub inertia: f64,
}

/// Mass properties of the union of the stone's spheres at `density`: exact for one sphere, by
/// a grid of 20 points per largest radius for several, within [`grid_error_bound`] (module
/// docs). Deterministic.
///
/// ```
/// use qdem_contact::samples::clump_mass::clump_mass_properties;
/// use qdem_contact::samples::clump_sample::Stone;
/// use qdem_core::Vec3;
/// let ball = Stone { centers: vec![Vec3::zeros()], radii: vec![0.5] };
/// let props = clump_mass_properties(&ball, 1000.0).unwrap();
/// let m = 4.0 / 3.0 * std::f64::consts::PI * 0.125 * 1000.0;
/// assert_eq!(props.mass, m);
/// assert_eq!(props.inertia[(0, 0)], 0.4 * m * 0.25);
/// ```
pub fn clump_mass_properties(stone: &Stone, density: f64) -> Result<MassProperties, SampleError> {
    if !(density.is_finite() && density > 0.0) {
        return Err(SampleError::Density { density });
    }
    check_stone(stone)?;
    if let ([center], [r]) = (stone.centers.as_slice(), stone.radii.as_slice()) {
        return Ok(sphere_mass_properties(*center, *r, density));
    }
    let r_max = stone.radii.iter().copied().fold(0.0, f64::max);
    Ok(grid_mass_properties(
        stone,
        density,
        r_max / GRID_PER_RADIUS,
    ))
}

/// The closed form of one sphere: m = 4/3 π r³ ρ, I = 2/5 m r².
fn sphere_mass_properties(center: Vec3, r: f64, density: f64) -> MassProperties {
    let mass = 4.0 / 3.0 * PI * r.powi(3) * density;
    MassProperties {
        mass,
        center,
        inertia: Mat3::identity() * (0.4 * mass * r * r),
    }
}

/// The stone has spheres, as many radii as centres, all finite and the radii positive.
fn check_stone(stone: &Stone) -> Result<(), SampleError> {
    let reason = if stone.centers.is_empty() {
        "it has no spheres".to_string()
    } else if stone.centers.len() != stone.radii.len() {
        format!(
            "{} centres but {} radii",
            stone.centers.len(),
            stone.radii.len()
        )
    } else if let Some(i) = stone
        .centers
        .iter()
        .position(|c| !c.iter().all(|v| v.is_finite()))
    {
        format!("centre {i} is {:?}", stone.centers[i].as_slice())
    } else if let Some(i) = stone
        .radii
        .iter()
        .position(|r| !(r.is_finite() && *r > 0.0))
    {
        format!("radius {i} is {}", stone.radii[i])
    } else {
        return Ok(());
    };
    Err(SampleError::Stone { reason })
}

/// The spheres of `stone` relative to its first centre, the anchor of the grid.
fn anchored(stone: &Stone) -> Vec<(Vec3, f64)> {
    let anchor = stone.centers[0];
    stone
        .centers
        .iter()
        .zip(&stone.radii)
        .map(|(c, &r)| (c - anchor, r))
        .collect()
}

/// The midpoint rule on the grid of spacing `h` over the union of the spheres.
fn grid_mass_properties(stone: &Stone, density: f64, h: f64) -> MassProperties {
    // Centres relative to the anchor: the grid points are (n + 1/2)·h, n integer.
    let spheres = anchored(stone);
    let mut moments = GridMoments::default();
    for (i, &(center, r)) in spheres.iter().enumerate() {
        let earlier = &spheres[..i];
        sum_sphere(center, r, h, |p| {
            if !earlier
                .iter()
                .any(|&(c, q)| (p - c).norm_squared() <= q * q)
            {
                moments.add(p);
            }
        });
    }
    moments.mass_properties(density, h, stone.centers[0])
}

/// A rigorous bound on the error of [`clump_mass_properties`] for `stone` at `density`, the
/// cubes the surfaces may cross split `depth` times (module docs); zero for one sphere.
pub fn grid_error_bound(stone: &Stone, density: f64, depth: u32) -> Result<MassError, SampleError> {
    let props = clump_mass_properties(stone, density)?;
    if stone.centers.len() == 1 {
        return Ok(MassError::default());
    }
    let r_max = stone.radii.iter().copied().fold(0.0, f64::max);
    Ok(bound_grid(
        stone,
        density,
        r_max / GRID_PER_RADIUS,
        depth,
        &props,
    ))
}

/// [`grid_error_bound`] of the grid of spacing `h` whose result is `props`.
fn bound_grid(
    stone: &Stone,
    density: f64,
    h: f64,
    depth: u32,
    props: &MassProperties,
) -> MassError {
    let spheres = anchored(stone);
    let c = props.center - stone.centers[0];
    let mut split = Split {
        spheres: &spheres,
        center: c,
        depth,
        ..Split::default()
    };
    let s = 3f64.sqrt() / 2.0 * h;
    for (i, &(center, r)) in spheres.iter().enumerate() {
        let earlier = &spheres[..i];
        sum_sphere(center, r + s, h, |p| {
            // Each cube once: by the first sphere whose reach holds its centre.
            if earlier
                .iter()
                .any(|&(q, t)| (p - q).norm_squared() <= (t + s) * (t + s))
            {
                return;
            }
            if split.class(p, s) == Class::Uncertain {
                let counted = spheres
                    .iter()
                    .any(|&(q, t)| (p - q).norm_squared() <= t * t);
                if counted {
                    split.grid.add_cube(p - c, h, 1.0);
                }
                split.cube(p, h, 0);
            }
        });
    }
    split.bound(density, props.mass)
}

/// Where a cube lies against the union of the spheres.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Class {
    Inside,
    Outside,
    Uncertain,
}

/// Volume, first moment and second moment tensor of a set of cubes (about a fixed point).
#[derive(Default)]
struct CubeMoments {
    volume: f64,
    first: Vec3,
    second: Mat3,
}

impl CubeMoments {
    /// Adds `sign` times the cube of side `h` centred at `q` (relative to the fixed point).
    fn add_cube(&mut self, q: Vec3, h: f64, sign: f64) {
        let v = sign * h.powi(3);
        self.volume += v;
        self.first += v * q;
        self.second += v * (q * q.transpose() + Mat3::identity() * (h * h / 12.0));
    }
}

/// The recursive split of the uncertain cubes of [`bound_grid`].
#[derive(Default)]
struct Split<'a> {
    spheres: &'a [(Vec3, f64)],
    /// The computed centre of mass (relative to the anchor).
    center: Vec3,
    depth: u32,
    /// The grid's cubes among the uncertain ones, and the pieces certainly inside.
    grid: CubeMoments,
    inside: CubeMoments,
    /// The uncertain pieces at the last level: volume, Σ v (|q − c| + s), Σ v (|q − c| + s)².
    uncertain: [f64; 3],
}

impl Split<'_> {
    /// The class of the cube centred at `q` with half-diagonal `s`.
    fn class(&self, q: Vec3, s: f64) -> Class {
        let mut outside = true;
        for &(c, r) in self.spheres {
            let d = (q - c).norm();
            if d + s <= r {
                return Class::Inside;
            }
            outside &= d - s >= r;
        }
        match outside {
            true => Class::Outside,
            false => Class::Uncertain,
        }
    }

    /// Splits the uncertain cube of side `h` at `q` (level `level`) into eight.
    fn cube(&mut self, q: Vec3, h: f64, level: u32) {
        let s = 3f64.sqrt() / 2.0 * h;
        if level == self.depth {
            let v = h.powi(3);
            let reach = (q - self.center).norm() + s;
            self.uncertain[0] += v;
            self.uncertain[1] += v * reach;
            self.uncertain[2] += v * reach * reach;
            return;
        }
        let quarter = h / 4.0;
        for k in 0..8 {
            let offset = |bit: usize| if k & bit == 0 { -quarter } else { quarter };
            let child = q + Vec3::new(offset(1), offset(2), offset(4));
            match self.class(child, s / 2.0) {
                Class::Inside => self.inside.add_cube(child - self.center, h / 2.0, 1.0),
                Class::Outside => {}
                Class::Uncertain => self.cube(child, h / 2.0, level + 1),
            }
        }
    }

    /// The bound of the module docs at `density`, `mass` the computed mass.
    fn bound(&self, density: f64, mass: f64) -> MassError {
        let d_mass = density * (self.grid.volume - self.inside.volume);
        let unsure = density * self.uncertain[0];
        let mass_error = d_mass.abs().max((d_mass - unsure).abs());
        let first =
            density * (self.grid.first - self.inside.first).norm() + density * self.uncertain[1];
        let center_error = first / (mass - mass_error);
        let d_second = (self.grid.second - self.inside.second) * density;
        let d_inertia = Mat3::identity() * d_second.trace() - d_second;
        let inertia = d_inertia.amax()
            + density * self.uncertain[2]
            + (mass + mass_error) * center_error * center_error;
        MassError {
            mass: mass_error,
            center: center_error,
            inertia,
        }
    }
}

/// Calls `visit` with every grid point (n + 1/2)·h inside the sphere (`center`, `r`), in
/// lexicographic (x, y, z) order.
fn sum_sphere(center: Vec3, r: f64, h: f64, mut visit: impl FnMut(Vec3)) {
    // Index range whose points lie within [c − reach, c + reach], one wider each way than
    // needed; the exact test below decides.
    let range = |c: f64, reach: f64| {
        let lo = ((c - reach) / h - 0.5).floor() as i64;
        let hi = ((c + reach) / h - 0.5).ceil() as i64;
        lo..=hi
    };
    let point = |n: i64| (n as f64 + 0.5) * h;
    let r2 = r * r;
    for ix in range(center.x, r) {
        let x = point(ix);
        let left_x = r2 - (x - center.x).powi(2);
        if left_x < 0.0 {
            continue;
        }
        for iy in range(center.y, left_x.sqrt()) {
            let y = point(iy);
            let left_y = left_x - (y - center.y).powi(2);
            if left_y < 0.0 {
                continue;
            }
            for iz in range(center.z, left_y.sqrt()) {
                let p = Vec3::new(x, y, point(iz));
                if (p - center).norm_squared() <= r2 {
                    visit(p);
                }
            }
        }
    }
}

/// Zeroth, first and second moments of the grid points counted.
#[derive(Default)]
struct GridMoments {
    /// Points counted.
    count: u64,
    /// Sum of the points.
    first: Vec3,
    /// Sum of the points' outer products.
    second: Mat3,
}

impl GridMoments {
    /// Counts point `p`.
    fn add(&mut self, p: Vec3) {
        self.count += 1;
        self.first += p;
        self.second += p * p.transpose();
    }

    /// Mass, centre and inertia about the centre, each point a cube of side `h` at `density`,
    /// the points relative to `anchor`; the error is left zero.
    fn mass_properties(&self, density: f64, h: f64, anchor: Vec3) -> MassProperties {
        let n = self.count as f64;
        let cube = density * h.powi(3);
        let mean = self.first / n;
        // Second moment of mass about the centre of mass.
        let spread = (self.second - n * mean * mean.transpose()) * cube;
        let mass = cube * n;
        let inertia = Mat3::identity() * (spread.trace() + mass * h * h / 6.0) - spread;
        MassProperties {
            mass,
            center: anchor + mean,
            inertia,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere_volume(r: f64) -> f64 {
        4.0 / 3.0 * PI * r.powi(3)
    }

    /// `a` is within `bound` of `b`, entry by entry.
    fn within(a: &Mat3, b: &Mat3, bound: f64) -> bool {
        (a - b).amax() <= bound
    }

    #[test]
    fn a_one_sphere_stone_has_the_closed_form_mass_and_inertia() {
        let (r, rho) = (0.03, 2650.0);
        let center = Vec3::new(1.0, -2.0, 0.5);
        let stone = Stone {
            centers: vec![center],
            radii: vec![r],
        };
        let props = clump_mass_properties(&stone, rho).unwrap();
        let mass = rho * sphere_volume(r);
        assert!((props.mass / mass - 1.0).abs() < 1e-14, "{}", props.mass);
        let j = 0.4 * mass * r * r;
        assert!(
            within(&props.inertia, &(Mat3::identity() * j), 1e-14 * j),
            "{}",
            props.inertia
        );
        assert_eq!(props.center, center);
        assert_eq!(
            grid_error_bound(&stone, rho, 4).unwrap(),
            MassError::default()
        );
    }

    #[test]
    fn two_overlapping_spheres_are_within_the_bound_of_the_exact_lens_union() {
        let (r, d, rho) = (0.03, 0.04, 2000.0);
        let c1 = Vec3::new(0.3, 0.2, 0.1);
        let axis = Vec3::new(1.0, 1.0, 1.0).normalize();
        let stone = Stone {
            centers: vec![c1, c1 + axis * d],
            radii: vec![r, r],
        };
        let props = clump_mass_properties(&stone, rho).unwrap();
        let bound = grid_error_bound(&stone, rho, 4).unwrap();
        let volume = 2.0 * sphere_volume(r) - PI * (4.0 * r + d) * (2.0 * r - d).powi(2) / 12.0;
        let exact = rho * volume;
        let error = (props.mass - exact).abs();
        eprintln!(
            "lens: mass error {:.2e} of the mass, bound {:.2e}",
            error / exact,
            bound.mass / exact
        );
        assert!(error <= bound.mass, "{error} > {bound:?}");
        // The union is symmetric about the midpoint of the centres.
        let middle = c1 + axis * (d / 2.0);
        assert!((props.center - middle).norm() <= bound.center);
        // Not vacuous: the bound is some per cent, the actual error several times less.
        assert!(bound.mass < 0.03 * exact, "{bound:?}");
        assert!(error < 0.005 * exact, "{error}");
    }

    #[test]
    fn a_ballast_clump_is_within_its_bound_of_a_fine_reference() {
        // Three overlapping spheres of different radii off any grid symmetry, as the generated
        // stones are; the reference is the same integration at 80 points per radius, whose
        // own bound is added.
        let stone = Stone {
            centers: vec![
                Vec3::new(0.013, -0.002, 0.004),
                Vec3::new(-0.011, 0.006, 0.001),
                Vec3::new(0.031, 0.011, -0.003),
            ],
            radii: vec![0.021, 0.019, 0.0175],
        };
        let rho = 2600.0;
        let props = clump_mass_properties(&stone, rho).unwrap();
        let e = grid_error_bound(&stone, rho, 4).unwrap();
        let h = 0.021 / 80.0;
        let fine = grid_mass_properties(&stone, rho, h);
        let f = bound_grid(&stone, rho, h, 2, &fine);
        eprintln!(
            "clump: mass {:.3e} off the fine grid, bounds {:.2e} + {:.2e}; inertia {:.2e} off, \
             bounds {:.2e} + {:.2e} (relative to the largest entry)",
            (props.mass - fine.mass).abs() / fine.mass,
            e.mass / fine.mass,
            f.mass / fine.mass,
            (props.inertia - fine.inertia).amax() / fine.inertia.amax(),
            e.inertia / fine.inertia.amax(),
            f.inertia / fine.inertia.amax(),
        );
        assert!((props.mass - fine.mass).abs() <= e.mass + f.mass);
        assert!((props.center - fine.center).norm() <= e.center + f.center);
        assert!(within(&props.inertia, &fine.inertia, e.inertia + f.inertia));
        // Not vacuous: the bound at 20 points per radius, relative to the values.
        assert!(e.mass < 0.03 * props.mass, "{e:?}");
        assert!(e.center < 0.03 * 0.021, "{e:?}");
        assert!(e.inertia < 0.06 * props.inertia.amax(), "{e:?}");
    }

    #[test]
    fn two_far_spheres_follow_the_parallel_axis_theorem_within_the_bound() {
        let (r, rho) = (0.03, 2650.0);
        let (c1, c2) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.2, 0.1, -0.05));
        let stone = Stone {
            centers: vec![c1, c2],
            radii: vec![r, r],
        };
        let props = clump_mass_properties(&stone, rho).unwrap();
        let bound = grid_error_bound(&stone, rho, 3).unwrap();
        let m = rho * sphere_volume(r);
        assert!((props.mass - 2.0 * m).abs() <= bound.mass);
        let middle = 0.5 * (c1 + c2);
        assert!((props.center - middle).norm() <= bound.center);
        let s = 0.5 * (c2 - c1);
        let exact = Mat3::identity() * (2.0 * 0.4 * m * r * r)
            + (Mat3::identity() * s.norm_squared() - s * s.transpose()) * (2.0 * m);
        assert!(
            within(&props.inertia, &exact, bound.inertia),
            "inertia {} vs {exact}: {bound:?}",
            props.inertia
        );
    }
}
