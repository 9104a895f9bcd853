//! Constitutive models: small-strain isotropic linear elasticity, and J2 plasticity
//! ([`crate::physics::plastic`]) on top of it for the materials that ask for it.

use crate::base::sym::Sym3;
use crate::physics::plastic::{Hardened, Hardening, J2, Tangent};
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

/// An isotropic material (SI: Pa, kg/m^3): linear elastic, and von Mises plastic when `j2`
/// is set.
#[derive(Clone, Debug, Serialize)]
pub struct Material {
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
    /// J2 plasticity; None for a linear elastic material.
    pub j2: Option<J2>,
}

impl Material {
    /// Builds the material; the caller has checked E > 0, rho > 0, -1 < nu < 0.5.
    pub fn new(name: &str, youngs: f64, poisson: f64, density: f64) -> Self {
        let mu = youngs / (2.0 * (1.0 + poisson));
        let lambda = youngs * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
        Material {
            name: name.to_string(),
            youngs,
            poisson,
            density,
            lambda,
            mu,
            j2: None,
        }
    }

    /// The material made von Mises plastic with initial yield stress `yield_stress` (Pa).
    pub fn with_j2(mut self, yield_stress: f64, hardening: Hardening) -> Self {
        self.j2 = Some(J2 {
            yield_stress,
            hardening,
            youngs: self.youngs,
            mu: self.mu,
        });
        self
    }

    /// The same material with new elastic constants (a plastic one keeps its yield law).
    pub fn with_elastic(&self, youngs: f64, poisson: f64, density: f64) -> Self {
        let m = Material::new(&self.name, youngs, poisson, density);
        match self.j2 {
            Some(j) => m.with_j2(j.yield_stress, j.hardening),
            None => m,
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
            de.zz = self.plane_stress_zz(&de);
        }
        self.add_elastic(&de, stress);
    }

    /// The zz strain that keeps an elastic increment at sigma_zz = 0.
    #[inline(always)]
    fn plane_stress_zz(&self, de: &Sym3) -> f64 {
        -self.lambda / (self.lambda + 2.0 * self.mu) * (de.xx + de.yy)
    }

    /// Adds the elastic stress increment C : `de` to `stress`.
    #[inline(always)]
    fn add_elastic(&self, de: &Sym3, stress: &mut Sym3) {
        let lt = self.lambda * de.trace();
        let m2 = 2.0 * self.mu;
        stress.xx += lt + m2 * de.xx;
        stress.yy += lt + m2 * de.yy;
        stress.zz += lt + m2 * de.zz;
        stress.yz += m2 * de.yz;
        stress.xz += m2 * de.xz;
        stress.xy += m2 * de.xy;
    }

    /// The stress update of a plastic material (`j2` set) by the strain increment `de`, with
    /// the particle's plastic strain and hardening state: an elastic predictor and a radial
    /// return.
    pub fn update_plastic(
        &self,
        plane: Plane,
        de: Sym3,
        stress: &mut Sym3,
        plastic: &mut Sym3,
        h: &mut Hardened,
    ) {
        self.update(plane, de, stress);
        self.correct_plastic(plane, stress, plastic, h);
    }

    /// The stress update of a plastic material by `de` ([`Self::update_plastic`]) with the
    /// update's algorithmic tangent, for a Newton solve (None where the update stays
    /// elastic): the radial return's in closed form; in plane stress, central differences
    /// of the whole update in each in-plane strain component (Miehe 1996), with steps of
    /// 1e-6 of the yield strain: the truncation error (step squared) is far below the
    /// return's own tolerance (1e-13 of the flow stress) over the step.
    pub fn update_plastic_tangent(
        &self,
        plane: Plane,
        de: Sym3,
        stress: &mut Sym3,
        plastic: &mut Sym3,
        h: &mut Hardened,
    ) -> Option<Tangent> {
        let j2 = self.j2.as_ref()?;
        if plane != Plane::Stress {
            self.update(plane, de, stress);
            return j2.radial_return_tangent(stress, plastic, h);
        }
        let start = (*stress, *plastic, *h);
        let step = |de: Sym3| {
            let mut s = start;
            self.update_plastic(plane, de, &mut s.0, &mut s.1, &mut s.2);
            s
        };
        let end = step(de);
        (*stress, *plastic, *h) = end;
        if end.2.equivalent <= start.2.equivalent {
            return None;
        }
        let e = 1e-6 * j2.yield_stress / j2.youngs;
        // Column k: the stresses' change per unit of strain component k (xx, yy, xy).
        let columns = [0, 1, 2].map(|k| {
            let mut d = Sym3::default();
            match k {
                0 => d.xx = e,
                1 => d.yy = e,
                _ => d.xy = e,
            }
            let (plus, minus) = (step(de + d).0, step(de + d * -1.0).0);
            let slope = |a: f64, b: f64| (a - b) / (2.0 * e);
            [
                slope(plus.xx, minus.xx),
                slope(plus.yy, minus.yy),
                slope(plus.xy, minus.xy),
            ]
        });
        Some(Tangent::InPlane([0, 1, 2].map(|r| columns.map(|c| c[r]))))
    }

    /// Corrects the elastic trial `stress` of a plastic material to the yield surface: the
    /// radial return in 3D and plane strain, the projected return in plane stress (which
    /// keeps sigma_zz = 0).
    #[inline]
    pub(crate) fn correct_plastic(
        &self,
        plane: Plane,
        stress: &mut Sym3,
        plastic: &mut Sym3,
        h: &mut Hardened,
    ) {
        let Some(j2) = &self.j2 else {
            return;
        };
        if plane == Plane::Stress {
            j2.plane_stress_return(stress, plastic, h);
        } else {
            j2.radial_return(stress, plastic, h);
        }
    }

    /// Elastic strain from stress through the 3D compliance, eps = ((1 + nu) sigma - nu
    /// tr(sigma) I)/E. Linear elasticity starting unstressed keeps sigma = C : eps, so strain
    /// is not stored; a plastic particle adds its plastic strain column.
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

    /// Elastic strain energy density W = sigma : eps_e / 2 (J/m^3).
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
        let m = Material::new("m", 100e9, 0.3, 1000.0);
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
