//! Particle packings of a rectangle for 2D beam-bonded DEM (paper 001 §5), and the bond
//! cross-section that makes a packing represent an elastic continuum.
//!
//! # Packings
//! - **Regular**: a triangular lattice of spacing h (rows h√3/2 apart, every other row shifted
//!   by h/2), bonds between nearest neighbours (six per inner particle). h is the requested
//!   element size, adjusted down so that a whole number of rows fills the height exactly.
//! - **Random**: the same lattice with every particle moved by a uniform random offset of up to
//!   `jitter`·h in x and y (seeded), the bonds kept: bond lengths and directions vary.
//!
//! Each particle is a disc of radius h/2 owning the lattice cell (√3/2)h² of the plane, so its
//! mass is ρ·(√3/2)h²·b for thickness b and its moment of inertia J = m r²/2.
//!
//! # How λ is set
//! A bond's section is a rectangle of width b (the thickness) and height λl, l the bond's
//! length: A = λlb, I = b(λl)³/12, W = b(λl)²/6 (paper 001: "the cross section of contact is
//! evaluated with dependence of coefficient λ"). For a triangular lattice under uniform strain
//! (node rotations equal to the continuum's rotation), bonds with axial stiffness k_n = EA/l
//! and transverse stiffness k_s = 12EI/(l³(1+ϕ)) give the plane-stress continuum
//!
//!   ν = (1 − r)/(3 + r),   E_lattice = 2√3·λ·E·(1 + r)/(3 + r),   r = k_s/k_n = λ²/(1 + ϕ).
//!
//! So for the material's ν, r = (1 − 3ν)/(1 + ν); λ = (3 + r)/(2√3(1 + r)) makes the lattice's
//! Young's modulus E (the bonds then carry the continuum's stress: a bond's N/A equals the
//! stress along it under uniaxial tension); and the shear coefficient ϕ = λ²/r − 1 gives the
//! lattice Poisson's ratio ν. For ν = 0.25: r = 0.2, λ = 0.7698, ϕ = 1.963. Such a lattice
//! represents 0.16 ≲ ν < 1/3 (ϕ ≥ 0); other ratios are refused ([`lattice_section`]).

use crate::bonded::beam_bond::BeamSection;

/// The kind of packing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PackingKind {
    /// A triangular lattice.
    Regular,
    /// A triangular lattice with every particle moved by up to `jitter`·h (0 ≤ jitter < 0.25).
    Random {
        /// Largest offset per direction as a fraction of the spacing.
        jitter: f64,
        /// Seed of the offsets.
        seed: u64,
    },
}

/// Particles filling a rectangle, with the pairs to bond.
#[derive(Clone, Debug, PartialEq)]
pub struct Packing {
    /// Particle centres (x, y), row by row from the bottom, left to right.
    pub centers: Vec<[f64; 2]>,
    /// Lattice spacing h (m).
    pub spacing: f64,
    /// Plane area each particle owns, (√3/2)h² (m²).
    pub cell_area: f64,
    /// Number of rows.
    pub rows: usize,
    /// Bonded pairs (i < j), sorted.
    pub bonds: Vec<(u32, u32)>,
}

impl Packing {
    /// Fills the rectangle with lower-left corner `origin` and `size` (m) at element size
    /// `element_size` (m). `None` if the rectangle is not at least two spacings each way.
    pub fn rectangle(
        origin: [f64; 2],
        size: [f64; 2],
        element_size: f64,
        kind: PackingKind,
    ) -> Option<Packing> {
        let pitch = 3f64.sqrt() / 2.0;
        let rows = (size[1] / (element_size * pitch)).round().max(1.0) as usize;
        let h = size[1] / (rows as f64 * pitch);
        let columns = (size[0] / h).round() as usize;
        if rows < 2 || columns < 2 {
            return None;
        }
        let mut centers = Vec::new();
        let mut row_start = Vec::new();
        for r in 0..rows {
            row_start.push(centers.len());
            let shift = if r % 2 == 0 { 0.5 } else { 1.0 };
            let count = if r % 2 == 0 { columns } else { columns - 1 };
            let y = origin[1] + (r as f64 + 0.5) * h * pitch;
            for c in 0..count {
                centers.push([origin[0] + (c as f64 + shift) * h, y]);
            }
        }
        row_start.push(centers.len());
        let bonds = lattice_bonds(&row_start);
        if let PackingKind::Random { jitter, seed } = kind {
            let mut rng = SplitMix64(seed);
            for p in &mut centers {
                p[0] += jitter * h * (2.0 * rng.uniform() - 1.0);
                p[1] += jitter * h * (2.0 * rng.uniform() - 1.0);
            }
        }
        Some(Packing {
            centers,
            spacing: h,
            cell_area: pitch * h * h,
            rows,
            bonds,
        })
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.centers.len()
    }

    /// Whether there is no particle.
    pub fn is_empty(&self) -> bool {
        self.centers.is_empty()
    }

    /// Radius of every particle, h/2 (m).
    pub fn radius(&self) -> f64 {
        0.5 * self.spacing
    }
}

/// Nearest-neighbour pairs of the lattice whose rows start at `row_start` (even rows have one
/// particle more than odd rows, odd rows sit half a spacing to the right).
fn lattice_bonds(row_start: &[usize]) -> Vec<(u32, u32)> {
    let mut bonds = Vec::new();
    let rows = row_start.len() - 1;
    for r in 0..rows {
        let (start, end) = (row_start[r], row_start[r + 1]);
        for i in start..end.saturating_sub(1) {
            bonds.push((i as u32, i as u32 + 1));
        }
        if r + 1 == rows {
            continue;
        }
        let (up, up_end) = (row_start[r + 1], row_start[r + 2]);
        for (c, i) in (start..end).enumerate() {
            // Even row: particle c touches c − 1 and c above; odd row: c and c + 1.
            let (left, right) = if r % 2 == 0 {
                (c.checked_sub(1), c)
            } else {
                (Some(c), c + 1)
            };
            for k in left.into_iter().chain(Some(right)) {
                if up + k < up_end {
                    bonds.push((i as u32, (up + k) as u32));
                }
            }
        }
    }
    bonds.sort_unstable();
    bonds
}

/// The bond section coefficients of a triangular lattice representing Poisson's ratio ν.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LatticeSection {
    /// Section height over bond length.
    pub lambda: f64,
    /// Timoshenko shear coefficient ϕ of every bond.
    pub shear_factor: f64,
}

/// λ and ϕ for Poisson's ratio `poisson` (see the module docs); `None` outside the range a
/// beam lattice can represent.
pub fn lattice_section(poisson: f64) -> Option<LatticeSection> {
    let r = (1.0 - 3.0 * poisson) / (1.0 + poisson);
    if r <= 0.0 {
        return None;
    }
    let lambda = (3.0 + r) / (2.0 * 3f64.sqrt() * (1.0 + r));
    let shear_factor = lambda * lambda / r - 1.0;
    (shear_factor >= 0.0).then_some(LatticeSection {
        lambda,
        shear_factor,
    })
}

impl LatticeSection {
    /// The section of a bond of `length` in a body of `thickness` (m).
    pub fn section(&self, length: f64, thickness: f64) -> BeamSection {
        let height = self.lambda * length;
        BeamSection {
            area: height * thickness,
            inertia: thickness * height.powi(3) / 12.0,
            modulus: thickness * height * height / 6.0,
            shear_factor: self.shear_factor,
        }
    }
}

/// A small seeded generator (SplitMix64) for reproducible packings and strengths.
#[derive(Clone, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u = 1.0 - self.uniform();
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_lattice_fills_the_rectangle_with_six_neighbours_inside() {
        let p = Packing::rectangle([0.0, 0.0], [3.0, 0.5], 0.05, PackingKind::Regular).unwrap();
        let h = p.spacing;
        assert!((p.rows as f64 * h * 3f64.sqrt() / 2.0 - 0.5).abs() < 1e-12);
        let mut degree = vec![0; p.len()];
        for &(i, j) in &p.bonds {
            let (a, b) = (p.centers[i as usize], p.centers[j as usize]);
            let d = (a[0] - b[0]).hypot(a[1] - b[1]);
            assert!((d - h).abs() < 1e-12 * h, "bond {i}-{j} has length {d}");
            degree[i as usize] += 1;
            degree[j as usize] += 1;
        }
        assert_eq!(*degree.iter().max().unwrap(), 6);
        // Every pair closer than 1.5 h is bonded (brute force).
        let mut close = 0;
        for i in 0..p.len() {
            for j in i + 1..p.len() {
                let (a, b) = (p.centers[i], p.centers[j]);
                if (a[0] - b[0]).hypot(a[1] - b[1]) < 1.5 * h {
                    close += 1;
                }
            }
        }
        assert_eq!(close, p.bonds.len());
        let area: f64 = p.len() as f64 * p.cell_area;
        assert!((area / 1.5 - 1.0).abs() < 0.02, "cells cover {area} m²");
    }

    #[test]
    fn random_packing_is_seeded_and_keeps_the_bonds() {
        let kind = PackingKind::Random {
            jitter: 0.1,
            seed: 7,
        };
        let a = Packing::rectangle([0.0, 0.0], [1.0, 0.3], 0.05, kind).unwrap();
        let b = Packing::rectangle([0.0, 0.0], [1.0, 0.3], 0.05, kind).unwrap();
        let regular =
            Packing::rectangle([0.0, 0.0], [1.0, 0.3], 0.05, PackingKind::Regular).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.bonds, regular.bonds);
        assert_ne!(a.centers, regular.centers);
    }

    #[test]
    fn section_matches_the_closed_form_for_nu_one_quarter() {
        let s = lattice_section(0.25).unwrap();
        assert!((s.lambda - 3.2 / (2.0 * 3f64.sqrt() * 1.2)).abs() < 1e-15);
        assert!((s.lambda * s.lambda / (1.0 + s.shear_factor) - 0.2).abs() < 1e-15);
        assert!(lattice_section(0.35).is_none());
        assert!(lattice_section(0.0).is_none());
    }
}
