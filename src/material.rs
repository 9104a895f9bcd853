//! Constitutive models: small-strain isotropic linear elasticity, and J2 plasticity
//! ([`crate::plastic`]) on top of it for the materials that ask for it.

use crate::plastic::{Hardened, Hardening, J2};
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
        let start = *stress;
        self.update(plane, de, stress);
        self.correct_plastic(plane, de, &start, stress, plastic, h);
    }

    /// Corrects the elastic trial `stress` (the update of `start` by `de`) of a plastic
    /// material to the yield surface. In plane stress the zz strain is then found so that
    /// the returned sigma_zz vanishes (it is monotone in that strain): a tangent's
    /// prediction, a Newton step, then the secant method.
    pub(crate) fn correct_plastic(
        &self,
        plane: Plane,
        mut de: Sym3,
        start: &Sym3,
        stress: &mut Sym3,
        plastic: &mut Sym3,
        h: &mut Hardened,
    ) {
        let Some(j2) = &self.j2 else {
            return;
        };
        if plane != Plane::Stress {
            j2.radial_return(stress, plastic, h);
            return;
        }
        let returned = |trial: Sym3| {
            let (mut s, mut p, mut hh) = (trial, *plastic, *h);
            j2.radial_return(&mut s, &mut p, &mut hh);
            (s, p, hh)
        };
        let trial = |de: &Sym3| {
            let mut s = *start;
            self.add_elastic(de, &mut s);
            returned(s)
        };
        // The first zz strain: the elastic one, or, from a start on the yield surface, the
        // one the elastic-plastic tangent predicts (one return fewer in steady flow).
        let mut now = match self.plastic_zz(j2, &de, start, h) {
            Some(zz) => {
                de.zz = zz;
                trial(&de)
            }
            None => {
                de.zz = self.plane_stress_zz(&de);
                returned(*stress)
            }
        };
        let tol = 1e-12 * j2.flow_stress(&now.2);
        if now.0.zz.abs() > tol {
            // The first correction is Newton's, with the zz-zz entry of the radial return's
            // consistent tangent (Simo & Hughes 1998, Box 3.2): K + 4/3 mu theta - 2 mu
            // theta_bar u_zz^2, theta = y / q_trial = y / (y + 3 mu dl), theta_bar =
            // 3 mu / (3 mu + H) - (1 - theta); the secant method takes it from there.
            let (mut z0, mut f0) = (de.zz, now.0.zz);
            let y = j2.flow_stress(&now.2);
            let theta = y / (y + 3.0 * self.mu * (now.2.equivalent - h.equivalent));
            let (beta, u, _) = self.tangent(j2, &now.0.deviator(), y);
            let theta_bar = beta / (2.0 * self.mu) - (1.0 - theta);
            let slope = self.lambda + 2.0 * self.mu * (1.0 / 3.0 + 2.0 / 3.0 * theta)
                - 2.0 * self.mu * theta_bar * u.zz * u.zz;
            de.zz -= f0 / slope;
            now = trial(&de);
            for _ in 0..crate::plastic::MAX_ITERATIONS {
                let f1 = now.0.zz;
                if f1.abs() <= tol || f1 == f0 {
                    break;
                }
                let z1 = de.zz;
                de.zz = z1 - f1 * (z1 - z0) / (f1 - f0);
                (z0, f0) = (z1, f1);
                now = trial(&de);
            }
        }
        (*stress, *plastic, *h) = now;
    }

    /// The continuum elastic-plastic tangent at a stress with deviator `dev` on the yield
    /// surface `y`: C_ep = C - beta u (x) u with beta = 6 mu^2/(3 mu + H) and the unit
    /// normal u = sqrt(3/2) S / y (Mashayekhi et al. 2011, Eq. 60). Returns beta, u and
    /// the zz-zz entry.
    fn tangent(&self, j2: &J2, dev: &Sym3, y: f64) -> (f64, Sym3, f64) {
        let beta = 6.0 * self.mu * self.mu / (3.0 * self.mu + j2.hardening_slope(y));
        let u = *dev * (1.5f64.sqrt() / y);
        (beta, u, self.lambda + 2.0 * self.mu - beta * u.zz * u.zz)
    }

    /// The zz strain increment that keeps sigma_zz = 0 under the elastic-plastic tangent at
    /// `start`, when `start` lies on the yield surface of state `h` (None otherwise): the
    /// zz row of C_ep : de = 0, lambda tr(de) + 2 mu de_zz - beta u_zz (u : de) = 0,
    /// solved for de_zz.
    fn plastic_zz(&self, j2: &J2, de: &Sym3, start: &Sym3, h: &Hardened) -> Option<f64> {
        let y = j2.flow_stress(h);
        let dev = start.deviator();
        if h.equivalent == 0.0 || 1.5 * dev.ddot(&dev) < (y * (1.0 - 1e-6)).powi(2) {
            return None;
        }
        let (beta, u, czz) = self.tangent(j2, &dev, y);
        let u_de = Sym3 { zz: 0.0, ..*de }.ddot(&u);
        Some((beta * u.zz * u_de - self.lambda * (de.xx + de.yy)) / czz)
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
