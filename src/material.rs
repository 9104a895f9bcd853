//! Constitutive models: small-strain isotropic linear elasticity.

use crate::sym::Sym3;
use serde::Serialize;

/// How a 2D scene treats the out-of-plane direction (3D scenes use [`Plane::None`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Plane {
    /// Three-dimensional: no constraint.
    None,
    /// 2D plane strain: eps_zz = 0.
    Strain,
    /// 2D plane stress: sigma_zz = 0.
    Stress,
}

/// Isotropic linear elastic material (SI: Pa, kg/m^3).
#[derive(Clone, Debug, Serialize)]
pub struct Elastic {
    /// Name from the scenario.
    pub name: String,
    /// Young's modulus (Pa).
    pub youngs: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Mass density (kg/m^3).
    pub density: f64,
    /// Lame's first parameter (Pa).
    pub lambda: f64,
    /// Shear modulus (Pa).
    pub mu: f64,
}

impl Elastic {
    /// Builds the material; the caller has checked E > 0, rho > 0, -1 < nu < 0.5.
    pub fn new(name: &str, youngs: f64, poisson: f64, density: f64) -> Self {
        let mu = youngs / (2.0 * (1.0 + poisson));
        let lambda = youngs * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
        Elastic {
            name: name.to_string(),
            youngs,
            poisson,
            density,
            lambda,
            mu,
        }
    }

    /// Fastest elastic wave speed for the scene's kinematics (m/s): dilatational
    /// c^2 = (lambda + 2 mu)/rho in 3D and plane strain, c^2 = E/(rho (1 - nu^2)) in plane stress.
    pub fn wave_speed(&self, plane: Plane) -> f64 {
        let modulus = match plane {
            Plane::Stress => self.youngs / (1.0 - self.poisson * self.poisson),
            Plane::None | Plane::Strain => self.lambda + 2.0 * self.mu,
        };
        (modulus / self.density).sqrt()
    }

    /// Stress after a strain increment `de` (3D tensor; in 2D the zz entry is filled in
    /// here: zero for plane strain, the value that keeps sigma_zz = 0 for plane stress).
    #[inline(always)]
    pub fn update(&self, plane: Plane, mut de: Sym3, stress: &mut Sym3) {
        if plane == Plane::Stress {
            de.zz = -self.lambda / (self.lambda + 2.0 * self.mu) * (de.xx + de.yy);
        }
        let lt = self.lambda * de.trace();
        let m2 = 2.0 * self.mu;
        stress.xx += lt + m2 * de.xx;
        stress.yy += lt + m2 * de.yy;
        stress.zz += lt + m2 * de.zz;
        stress.yz += m2 * de.yz;
        stress.xz += m2 * de.xz;
        stress.xy += m2 * de.xy;
    }

    /// Strain from stress through the 3D compliance, eps = ((1 + nu) sigma - nu tr(sigma) I)/E.
    /// Linear elasticity starting unstressed keeps sigma = C : eps, so strain is not stored.
    #[inline(always)]
    pub fn strain(&self, s: &Sym3) -> Sym3 {
        let (e, nu) = (self.youngs, self.poisson);
        let t = nu * s.trace();
        Sym3 {
            xx: ((1.0 + nu) * s.xx - t) / e,
            yy: ((1.0 + nu) * s.yy - t) / e,
            zz: ((1.0 + nu) * s.zz - t) / e,
            yz: (1.0 + nu) * s.yz / e,
            xz: (1.0 + nu) * s.xz / e,
            xy: (1.0 + nu) * s.xy / e,
        }
    }

    /// Strain energy density W = sigma : eps / 2 (J/m^3).
    #[inline(always)]
    pub fn energy_density(&self, stress: &Sym3) -> f64 {
        0.5 * stress.ddot(&self.strain(stress))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniaxial stress in plane stress gives sigma_xx = E eps_xx and sigma_zz = 0.
    #[test]
    fn plane_stress_uniaxial_recovers_youngs_modulus() {
        let m = Elastic::new("m", 100e9, 0.3, 1000.0);
        let mut s = Sym3::default();
        let nu_eff = m.poisson; // lateral contraction of a free plate: eps_yy = -nu eps_xx
        let de = Sym3 {
            xx: 1e-4,
            yy: -nu_eff * 1e-4,
            ..Sym3::default()
        };
        m.update(Plane::Stress, de, &mut s);
        assert!((s.xx - 100e9 * 1e-4).abs() < 1e-6 * 1e7);
        assert!(s.yy.abs() < 1e-6 * 1e7 && s.zz.abs() < 1e-6);
        let e = m.strain(&s);
        assert!((e.xx - 1e-4).abs() < 1e-15 && (e.yy + 0.3e-4).abs() < 1e-15);
    }
}
