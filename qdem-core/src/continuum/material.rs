//! Isotropic Kelvin–Voigt viscoelastic material (paper 000 Eqs. 2, 7, 8).
//!
//! The elastic part is Hooke's law with Lamé constants λ_E, μ_E from Young's modulus and
//! Poisson's ratio; the viscous part has shear viscosity μ_D and bulk viscosity
//! κ_D = λ_D + ⅔ μ_D, the two scalars a user can measure. A material with zero viscosities is
//! elastic and the tetrahedron kernel skips its viscous path.

use crate::error::MaterialError;

/// Material constants of a Kelvin–Voigt solid.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Mass density ρ (kg/m³).
    pub density: f64,
    /// Young's modulus E (Pa).
    pub young: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Shear viscosity μ_D (Pa s).
    pub shear_viscosity: f64,
    /// Bulk viscosity κ_D = λ_D + ⅔ μ_D (Pa s).
    pub bulk_viscosity: f64,
}

/// Lamé-type pair (λ, μ) of either the elastic (Pa) or the viscous (Pa s) part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lame {
    /// First parameter λ.
    pub lambda: f64,
    /// Second parameter μ.
    pub mu: f64,
}

impl Material {
    /// An elastic material (zero viscosities).
    pub fn elastic(density: f64, young: f64, poisson: f64) -> Material {
        Material {
            density,
            young,
            poisson,
            shear_viscosity: 0.0,
            bulk_viscosity: 0.0,
        }
    }

    /// Checks every constant against its physical range.
    pub fn validate(&self) -> Result<(), MaterialError> {
        if !(self.density.is_finite() && self.density > 0.0) {
            return Err(MaterialError::Density(self.density));
        }
        if !(self.young.is_finite() && self.young > 0.0) {
            return Err(MaterialError::Young(self.young));
        }
        if !(self.poisson > -1.0 && self.poisson < 0.5) {
            return Err(MaterialError::Poisson(self.poisson));
        }
        for (name, value) in [
            ("shear_viscosity", self.shear_viscosity),
            ("bulk_viscosity", self.bulk_viscosity),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(MaterialError::Viscosity { name, value });
            }
        }
        Ok(())
    }

    /// Elastic Lamé constants λ_E = Eν/((1+ν)(1−2ν)), μ_E = E/(2(1+ν)) of Eq. 2.
    pub fn elastic_lame(&self) -> Lame {
        let (e, nu) = (self.young, self.poisson);
        Lame {
            lambda: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            mu: e / (2.0 * (1.0 + nu)),
        }
    }

    /// Viscous Lamé parameters λ_D = κ_D − ⅔ μ_D, μ_D of Eq. 7.
    pub fn viscous_lame(&self) -> Lame {
        Lame {
            lambda: self.bulk_viscosity - 2.0 / 3.0 * self.shear_viscosity,
            mu: self.shear_viscosity,
        }
    }

    /// Whether both viscosities are zero, so the viscous stress of Eq. 7 vanishes identically.
    pub fn is_elastic(&self) -> bool {
        self.shear_viscosity == 0.0 && self.bulk_viscosity == 0.0
    }

    /// Thin-bar wave speed √(E/ρ) (m/s).
    pub fn bar_wave_speed(&self) -> f64 {
        (self.young / self.density).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lame_constants_recover_young_and_poisson() {
        let m = Material::elastic(2350.0, 45e9, 0.167);
        let Lame { lambda, mu } = m.elastic_lame();
        let young = mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu);
        let poisson = lambda / (2.0 * (lambda + mu));
        assert!((young / 45e9 - 1.0).abs() < 1e-14);
        assert!((poisson / 0.167 - 1.0).abs() < 1e-14);
    }

    #[test]
    fn out_of_range_constants_are_refused() {
        let ok = Material::elastic(1.0, 1.0, 0.3);
        assert!(ok.validate().is_ok());
        let bad = |f: fn(&mut Material)| {
            let mut m = ok.clone();
            f(&mut m);
            m.validate().unwrap_err()
        };
        assert_eq!(bad(|m| m.density = -1.0), MaterialError::Density(-1.0));
        assert_eq!(bad(|m| m.young = 0.0), MaterialError::Young(0.0));
        assert_eq!(bad(|m| m.poisson = 0.5), MaterialError::Poisson(0.5));
        assert!(matches!(
            bad(|m| m.bulk_viscosity = f64::NAN),
            MaterialError::Viscosity { .. }
        ));
    }
}
