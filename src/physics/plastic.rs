//! J2 (von Mises) plasticity at small strain: an elastic predictor and a radial return
//! (Simo & Hughes 1998, Box 3.2; Mashayekhi, Shodja & Namakian 2011, Eqs. 46-56), with
//! linear isotropic hardening or the modified Ramberg-Osgood law (Mashayekhi et al. 2011,
//! Eqs. 62-63); in plane stress the projected return of Simo & Taylor (Simo & Hughes 1998,
//! Section 3.4.3).

use crate::base::columnar::{Columnar, Scalar};
use crate::base::sym::Sym3;
use bytemuck::{Pod, Zeroable};
use serde::Serialize;

/// How the yield stress grows with the equivalent plastic strain.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Hardening {
    /// sigma_y = sigma_0 + H eps_p, with H >= 0 (Pa); H = 0 is perfectly plastic.
    Linear {
        /// Hardening modulus H (Pa).
        modulus: f64,
    },
    /// The modified Ramberg-Osgood law: linear up to sigma_0, then eps / eps_0 =
    /// (sigma / sigma_0)^n in uniaxial tension, so eps_p / eps_0 = (sigma_y/sigma_0)^n -
    /// sigma_y/sigma_0 with eps_0 = sigma_0 / E (Mashayekhi et al. 2011, Eqs. 62-63).
    RambergOsgood {
        /// Hardening exponent n (> 1).
        exponent: f64,
    },
    /// The Ramberg-Osgood law in the form of the EPRI handbook (Kumar, German & Shih
    /// 1981): eps / eps_0 = sigma / sigma_0 + alpha (sigma / sigma_0)^n in uniaxial
    /// tension, so eps_p = alpha eps_0 (sigma_y / sigma_0)^n from the first load (no
    /// elastic limit: sigma_0 is a reference stress, not a yield stress).
    Handbook {
        /// The coefficient alpha (> 0).
        alpha: f64,
        /// Hardening exponent n (> 1).
        exponent: f64,
    },
}

/// A von Mises material's plastic parameters (the elastic ones are the material's).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct J2 {
    /// Initial yield stress sigma_0 (Pa).
    pub yield_stress: f64,
    /// Hardening law.
    pub hardening: Hardening,
    /// Young's modulus (Pa), which fixes the Ramberg-Osgood eps_0.
    pub youngs: f64,
    /// Shear modulus (Pa).
    pub mu: f64,
}

/// A particle's hardening state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct Hardened {
    /// Equivalent plastic strain eps_p = sum of the plastic multipliers (Eq. 44).
    pub equivalent: f64,
    /// Current yield stress (Pa); meaningful once `equivalent` > 0.
    pub flow_stress: f64,
    /// Plastic work per unit volume, the integral of sigma_y d(eps_p) (J/m^3).
    pub work: f64,
}

impl Columnar for Hardened {
    const SCALAR: Scalar = Scalar::F64;
}

/// Most iterations of a scalar solve (the Ramberg-Osgood return, the plane-stress return);
/// both converge in a handful.
const MAX_ITERATIONS: usize = 60;

/// Relative tolerance of the scalar solves.
const TOLERANCE: f64 = 1e-13;

/// A stress lies on the yield surface when its effective stress is within this fraction
/// of the yield stress: far above the returns' round-off, far below an elastic unloading
/// step's departure.
const ON_SURFACE: f64 = 1e-9;

/// r^e, by squaring when e is a small whole number (the usual Ramberg-Osgood exponents):
/// a few multiplications inline, where `powf` (or `powi`'s library call) costs several
/// times more in the return map's Newton iterations.
#[inline(always)]
fn power(r: f64, e: f64) -> f64 {
    // `e as u32` saturates, so the round trip holds only for whole e in 0..=64 (and,
    // unlike `fract`, it needs no library call).
    let k = e as u32;
    if k <= 64 && k as f64 == e {
        let (mut k, mut base, mut acc) = (k, r, 1.0);
        while k > 0 {
            if k & 1 == 1 {
                acc *= base;
            }
            base *= base;
            k >>= 1;
        }
        acc
    } else {
        r.powf(e)
    }
}

impl J2 {
    /// The yield stress of a particle in state `h`.
    #[inline(always)]
    pub fn flow_stress(&self, h: &Hardened) -> f64 {
        if h.equivalent > 0.0 {
            h.flow_stress
        } else if let Hardening::Handbook { .. } = self.hardening {
            0.0
        } else {
            self.yield_stress
        }
    }

    /// The handbook law's equivalent plastic strain at yield stress `y`, and its
    /// derivative d(eps_p)/dy.
    #[inline]
    fn handbook_strain(&self, alpha: f64, n: f64, y: f64) -> (f64, f64) {
        let s0 = self.yield_stress;
        let scale = alpha * s0 / self.youngs;
        let r = y / s0;
        let p = power(r, n - 1.0);
        (scale * p * r, scale * n * p / s0)
    }

    /// Solves the consistency condition q - 3 G dl - sigma_y(eps_p + dl) = 0 (Eq. 55) for
    /// the plastic multiplier dl and the new yield stress, given the trial effective stress
    /// `q` above the current yield stress `y0`.
    fn consistency(&self, q: f64, y0: f64, h: &Hardened) -> (f64, f64) {
        let g3 = 3.0 * self.mu;
        match self.hardening {
            Hardening::Linear { modulus } => {
                let dl = (q - y0) / (g3 + modulus);
                (dl, y0 + modulus * dl)
            }
            Hardening::RambergOsgood { exponent: n } => {
                // In the new yield stress y: f(y) = q - y - 3G (eps_p(y) - eps_p) is concave
                // and decreasing on [y0, q]. Newton's first step from y0 (the linearised
                // return) lands just past the root, and from there Newton falls monotonically
                // onto it. After a step s the error left is at most K s^2 with K = |f''| /
                // (2 |f'(y0)|) (|f'| is least at y0, |f''| largest at the iterate); the
                // iteration stops once the plastic strain that error makes is below the
                // tolerance: two evaluations of the law for an explicit step's increment.
                // The new eps_p(y) is the last evaluation's, carried to y along its slope
                // (an error of the same order).
                let (s0, eps0) = (self.yield_stress, self.yield_stress / self.youngs);
                // Reciprocals off the chain of dependent operations a return is.
                let inv_s0 = 1.0 / s0;
                let c = g3 * eps0 * inv_s0;
                let df0 = 1.0 + c * (n * power(y0 * inv_s0, n - 1.0) - 1.0);
                let mut y = (y0 + (q - y0) / df0).min(q);
                let mut strain = h.equivalent;
                for _ in 0..MAX_ITERATIONS {
                    let r = y * inv_s0;
                    let p = power(r, n - 1.0);
                    let e = eps0 * (p * r - r);
                    let df = 1.0 + c * (n * p - 1.0);
                    let step = (q - y - g3 * (e - h.equivalent)) / df;
                    let next = (y + step).clamp(y0, q);
                    strain = e + (next - y) * eps0 * inv_s0 * (n * p - 1.0);
                    y = next;
                    // K s^2 times 2 |f'(y0)| r, with |f''(y)| r = c n (n - 1) r^(n-1) / s0; the
                    // strain error is that over the hardening slope, eps0/s0 (n r^(n-1) - 1).
                    let bound = c * n * (n - 1.0) * p * inv_s0 * step * step;
                    if bound * eps0 * inv_s0 * (n * p - 1.0) <= 2.0 * df0 * TOLERANCE * strain * r {
                        break;
                    }
                }
                ((strain - h.equivalent).max(0.0), y)
            }
            Hardening::Handbook { alpha, exponent: n } => {
                // f(y) = q - y - 3G (eps_p(y) - eps_p) is concave and decreasing on [y0, q]
                // (eps_p is convex in y): Newton from y0 lands right of the root and falls
                // monotonically onto it.
                let mut y = y0;
                for _ in 0..MAX_ITERATIONS {
                    let (e, de) = self.handbook_strain(alpha, n, y);
                    let step = (q - y - g3 * (e - h.equivalent)) / (1.0 + g3 * de);
                    y = (y + step).clamp(y0, q);
                    if step.abs() <= TOLERANCE * y {
                        break;
                    }
                }
                let strain = self.handbook_strain(alpha, n, y).0;
                ((strain - h.equivalent).max(0.0), y)
            }
        }
    }

    /// Whether the stress `trial` lies outside the yield surface of state `h`: its
    /// effective stress sqrt(3 J_2) = sqrt(3/2 S : S) above the yield stress.
    #[inline(always)]
    pub fn yields(&self, trial: &Sym3, h: &Hardened) -> bool {
        let s = trial.deviator();
        1.5 * s.ddot(&s) > self.flow_stress(h).powi(2)
    }

    /// Returns `trial` (an elastic predictor) to the yield surface if it lies outside,
    /// updating the plastic strain and hardening state; a trial inside is kept.
    #[inline]
    pub fn radial_return(&self, trial: &mut Sym3, plastic: &mut Sym3, h: &mut Hardened) {
        let s = trial.deviator();
        let q2 = 1.5 * s.ddot(&s);
        let y0 = self.flow_stress(h);
        if q2 <= y0 * y0 {
            return;
        }
        let p = trial.trace() / 3.0;
        let q = q2.sqrt();
        let (dl, y) = self.consistency(q, y0, h);
        // Eq. 56: S = (1 - 3 G dl / q) S_trial = (y / q) S_trial; the flow direction is
        // S_trial / q.
        let inv_q = 1.0 / q;
        *trial = s * (y * inv_q) + Sym3::identity() * p;
        *plastic += s * (1.5 * dl * inv_q);
        // The dissipation sigma_y d(eps_p) by the trapezoidal rule (exact for linear hardening).
        h.work += 0.5 * (y0 + y) * dl;
        h.equivalent += dl;
        h.flow_stress = y;
    }

    /// The radial return of [`Self::radial_return`] with its algorithmic tangent, for a
    /// Newton solve: None when the trial lies inside the yield surface (the tangent is then
    /// the elastic one).
    pub fn radial_return_tangent(
        &self,
        trial: &mut Sym3,
        plastic: &mut Sym3,
        h: &mut Hardened,
    ) -> Option<Tangent> {
        if !self.yields(trial, h) {
            return None;
        }
        let s = trial.deviator();
        let norm = s.ddot(&s).sqrt();
        // q = sqrt(3/2) |s|.
        let q = 1.5f64.sqrt() * norm;
        self.radial_return(trial, plastic, h);
        let theta = h.flow_stress / q;
        Some(Tangent::Radial(RadialTangent {
            theta,
            theta_bar: theta - self.hardening_share(h.flow_stress),
            normal: s * (1.0 / norm),
        }))
    }

    /// The continuum elastoplastic tangent at a stress on the yield surface of state `h`
    /// (the algorithmic one's limit for a vanishing increment: theta = 1, theta_bar = 3 mu
    /// / (3 mu + H'); Simo & Hughes 1998, Eq. 3.3.12): None inside the surface or before
    /// first yield. A Newton step's first solve starts from it, on the state alone.
    pub fn continuum_tangent(&self, stress: &Sym3, h: &Hardened) -> Option<Tangent> {
        let y = self.flow_stress(h);
        let s = stress.deviator();
        let norm = s.ddot(&s).sqrt();
        let on_surface = 1.5f64.sqrt() * norm >= (1.0 - ON_SURFACE) * y;
        if h.equivalent <= 0.0 || !on_surface {
            return None;
        }
        Some(Tangent::Radial(RadialTangent {
            theta: 1.0,
            theta_bar: 1.0 - self.hardening_share(y),
            normal: s * (1.0 / norm),
        }))
    }

    /// H' / (3 mu + H') at yield stress `y`, H' = d(sigma_y)/d(eps_p) the hardening slope,
    /// written as 1 / (1 + 3 mu d(eps_p)/d(sigma_y)) for the Ramberg-Osgood laws (Eq. 63
    /// of Mashayekhi et al. 2011 differentiated, and the handbook form's), whose slope is
    /// unbounded where their plastic compliance vanishes.
    pub fn hardening_share(&self, y: f64) -> f64 {
        let s0 = self.yield_stress;
        let compliance = match self.hardening {
            Hardening::Linear { modulus } => return modulus / (3.0 * self.mu + modulus),
            Hardening::RambergOsgood { exponent: n } => {
                s0 / self.youngs * (n * power(y / s0, n - 1.0) - 1.0) / s0
            }
            Hardening::Handbook { alpha, exponent: n } => self.handbook_strain(alpha, n, y).1,
        };
        1.0 / (1.0 + 3.0 * self.mu * compliance)
    }

    /// Returns the plane-stress elastic trial `trial` (sigma_zz = 0) to the yield surface in
    /// plane stress, keeping sigma_zz = 0: Simo & Taylor's projected return (Simo & Hughes
    /// 1998, Section 3.4.3). In the eigenbasis of the J2 projection P the returned stress
    /// is the trial's scaled by 1 / (1 + E dg / (3 (1 - nu))) along (1, 1, 0) and by
    /// 1 / (1 + 2 mu dg) along (-1, 1, 0) and the shear, dg the plastic multiplier; one
    /// scalar equation gives the new yield stress y, q(dg(y)) = y, with dg(y) = 3 dl /
    /// (2 y) from the hardening law's plastic strain dl (for no hardening, q(dg) = y in
    /// dg). Safeguarded Newton: each iterate stays inside the bracket the signs give.
    pub fn plane_stress_return(&self, trial: &mut Sym3, plastic: &mut Sym3, h: &mut Hardened) {
        let dev = trial.deviator();
        let y0 = self.flow_stress(h);
        let q_trial = (1.5 * dev.ddot(&dev)).sqrt();
        if q_trial <= y0 {
            return;
        }
        let nu = self.youngs / (2.0 * self.mu) - 1.0;
        let (k1, k2) = (self.youngs / (3.0 * (1.0 - nu)), 2.0 * self.mu);
        let a1 = (trial.xx + trial.yy) * std::f64::consts::FRAC_1_SQRT_2;
        let a2 = (trial.yy - trial.xx) * std::f64::consts::FRAC_1_SQRT_2;
        let (p1, p2) = (a1 * a1 / 3.0, a2 * a2 + 2.0 * trial.xy * trial.xy);
        // q after a return of multiplier dg, and dq/d(dg).
        let q_of = |dg: f64| {
            let (f1, f2) = (1.0 / (1.0 + k1 * dg), 1.0 / (1.0 + k2 * dg));
            let q = (1.5 * (p1 * f1 * f1 + p2 * f2 * f2)).sqrt();
            let dxi = -2.0 * (k1 * p1 * f1 * f1 * f1 + k2 * p2 * f2 * f2 * f2);
            (q, 0.75 * dxi / q)
        };
        let tol = TOLERANCE * y0;
        let (dg, y, dl) = match self.hardening {
            Hardening::Linear { modulus: 0.0 } => {
                // q(dg) is convex and decreasing: Newton from dg = 0 rises onto the root.
                let mut dg = 0.0;
                for _ in 0..MAX_ITERATIONS {
                    let (q, dq) = q_of(dg);
                    let step = (q - y0) / dq;
                    dg -= step;
                    if step.abs() * k2 <= TOLERANCE {
                        break;
                    }
                }
                (dg, y0, 2.0 / 3.0 * dg * y0)
            }
            _ => {
                // dg(y) and d(dg)/dy from the plastic strain the hardening law gives at y.
                let (s0, eps0) = (self.yield_stress, self.yield_stress / self.youngs);
                let strain = |y: f64| -> (f64, f64) {
                    match self.hardening {
                        Hardening::Linear { modulus } => ((y - y0) / modulus, 1.0 / modulus),
                        Hardening::RambergOsgood { exponent: n } => {
                            let r = y / s0;
                            let p = power(r, n - 1.0);
                            (eps0 * (p * r - r) - h.equivalent, eps0 / s0 * (n * p - 1.0))
                        }
                        Hardening::Handbook { alpha, exponent: n } => {
                            let (e, de) = self.handbook_strain(alpha, n, y);
                            (e - h.equivalent, de)
                        }
                    }
                };
                // The handbook law starts from y0 = 0, where dg(y) = 3 eps_p / (2 y) is 0/0:
                // it starts mid-bracket instead.
                let start = if y0 > 0.0 { y0 } else { 0.5 * q_trial };
                let (mut lo, mut hi, mut y) = (y0, q_trial, start);
                let mut last = f64::NAN;
                for _ in 0..MAX_ITERATIONS {
                    let (e, de) = strain(y);
                    let dg = 1.5 * e.max(0.0) / y;
                    let (q, dq) = q_of(dg);
                    let g = q - y;
                    if g > 0.0 {
                        lo = y;
                    } else {
                        hi = y;
                    }
                    let slope = dq * (1.5 * de / y - dg / y) - 1.0;
                    let step = g / slope;
                    // Newton's error after this step is about M step^2, with M estimated
                    // from the last two steps (step ~ M last^2): stop once that is below
                    // the tolerance, sparing the step that would only confirm it.
                    if step.abs() <= tol || step * step * step.abs() <= tol * last * last {
                        y -= step;
                        break;
                    }
                    // Newton, or the bracket's midpoint where Newton would leave it (which
                    // leaves no estimate of M).
                    (y, last) = if y - step > lo && y - step < hi {
                        (y - step, step)
                    } else {
                        (0.5 * (lo + hi), f64::NAN)
                    };
                }
                let dl = strain(y).0.max(0.0);
                (1.5 * dl / y, y, dl)
            }
        };
        let (f1, f2) = (1.0 / (1.0 + k1 * dg), 1.0 / (1.0 + k2 * dg));
        let (b1, b2) = (
            a1 * f1 * std::f64::consts::FRAC_1_SQRT_2,
            a2 * f2 * std::f64::consts::FRAC_1_SQRT_2,
        );
        *trial = Sym3 {
            xx: b1 - b2,
            yy: b1 + b2,
            xy: trial.xy * f2,
            ..Sym3::default()
        };
        // Plastic flow along the returned deviator: d(eps_p) = dg S.
        *plastic += trial.deviator() * dg;
        h.work += 0.5 * (y0 + y) * dl;
        h.equivalent += dl;
        h.flow_stress = y;
    }
}

/// The algorithmic (consistent) tangent of a radial return, d(sigma)/d(eps) of the
/// discrete update rather than of the rate equations, which keeps Newton's iterations
/// quadratic (Simo & Taylor 1985; Simo & Hughes 1998, Box 3.2): C = K 1 (x) 1 + 2 mu theta
/// I_dev - 2 mu theta_bar N (x) N, with theta = sigma_y / q_trial, theta_bar = theta -
/// H' / (3 mu + H'), N the unit trial deviator and H' the hardening slope at the returned
/// state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadialTangent {
    /// sigma_y / q_trial: how much of the trial deviator the return keeps.
    pub theta: f64,
    /// theta - H' / (3 mu + H'): the stiffness lost along the flow direction.
    pub theta_bar: f64,
    /// The unit trial deviator N (N : N = 1).
    pub normal: Sym3,
}

impl RadialTangent {
    /// C : `de` for a material of Lame moduli `lambda` and `mu`.
    #[inline(always)]
    pub fn apply(&self, lambda: f64, mu: f64, de: &Sym3) -> Sym3 {
        let bulk = lambda + 2.0 / 3.0 * mu;
        let m2 = 2.0 * mu;
        de.deviator() * (m2 * self.theta)
            + Sym3::identity() * (bulk * de.trace())
            + self.normal * (-m2 * self.theta_bar * self.normal.ddot(de))
    }
}

/// A yielded particle's algorithmic tangent, for a Newton solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tangent {
    /// The radial return's, in closed form (3D and plane strain).
    Radial(RadialTangent),
    /// The plane-stress return's: d(sigma_xx, sigma_yy, sigma_xy) / d(eps_xx, eps_yy,
    /// eps_xy) (tensor shear), by central differences of the return (Miehe 1996).
    InPlane([[f64; 3]; 3]),
}

impl Tangent {
    /// C : `de` for a material of Lame moduli `lambda` and `mu` (in plane stress, of the
    /// in-plane components; sigma_zz stays 0).
    #[inline(always)]
    pub fn apply(&self, lambda: f64, mu: f64, de: &Sym3) -> Sym3 {
        match self {
            Tangent::Radial(r) => r.apply(lambda, mu, de),
            Tangent::InPlane(c) => {
                let d = [de.xx, de.yy, de.xy];
                let row = |r: &[f64; 3]| r[0] * d[0] + r[1] * d[1] + r[2] * d[2];
                Sym3 {
                    xx: row(&c[0]),
                    yy: row(&c[1]),
                    xy: row(&c[2]),
                    ..Sym3::default()
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::material::{Material, Plane};

    fn steel(hardening: Hardening) -> Material {
        Material::new("steel", 200e9, 0.3, 7800.0).with_j2(250e6, hardening)
    }

    /// A stress update of `m` by `de` with plastic state, returning the new stress.
    fn step(m: &Material, plane: Plane, de: Sym3, st: &mut (Sym3, Sym3, Hardened)) {
        m.update_plastic(plane, de, &mut st.0, &mut st.1, &mut st.2);
    }

    /// The equivalent plastic strain at yield stress `y` on the Ramberg-Osgood curve.
    fn ramberg_osgood_strain(j2: &J2, n: f64, y: f64) -> f64 {
        let r = y / j2.yield_stress;
        j2.yield_stress / j2.youngs * (r.powf(n) - r)
    }

    fn effective(s: &Sym3) -> f64 {
        let d = s.deviator();
        (1.5 * d.ddot(&d)).sqrt()
    }

    /// After a return, the effective stress equals the yield stress to round-off and the
    /// Ramberg-Osgood state lies on its hardening curve (the consistency condition), in 3D
    /// and in plane stress (whose return also keeps sigma_zz = 0).
    #[test]
    fn return_satisfies_consistency() {
        for hardening in [
            Hardening::Linear { modulus: 0.0 },
            Hardening::Linear { modulus: 2e9 },
            Hardening::RambergOsgood { exponent: 10.0 },
            Hardening::RambergOsgood { exponent: 3.0 },
        ] {
            // In plane stress the increment is in-plane (its zz is the update's to choose).
            // Increments of a third of the yield strain and of forty times it.
            for (plane, out, big) in [
                (Plane::None, 1.0, 1.0),
                (Plane::Stress, 0.0, 1.0),
                (Plane::None, 1.0, 125.0),
                (Plane::Stress, 0.0, 125.0),
            ] {
                let m = steel(hardening);
                let mut st = (Sym3::default(), Sym3::default(), Hardened::default());
                let de = Sym3 {
                    xx: 4e-4,
                    yy: -1e-4,
                    zz: 0.5e-4 * out,
                    yz: 2e-4 * out,
                    xz: -1e-4 * out,
                    xy: 3e-4,
                } * big;
                for _ in 0..20 {
                    step(&m, plane, de, &mut st);
                    // The elastic update leaves round-off in sigma_zz, a return none.
                    let zz = if plane == Plane::Stress { st.0.zz } else { 0.0 };
                    assert!(zz.abs() <= 1e-12 * 250e6, "{hardening:?}: sigma_zz {zz}");
                    let j2 = m.j2.expect("plastic");
                    let y = j2.flow_stress(&st.2);
                    let q = effective(&st.0);
                    if st.2.equivalent > 0.0 {
                        assert!((q - y).abs() <= 1e-12 * y, "{hardening:?}: {q} vs {y}");
                    } else {
                        assert!(q <= y, "{hardening:?}: elastic above yield");
                    }
                    if let Hardening::RambergOsgood { exponent } = hardening {
                        let e = ramberg_osgood_strain(&j2, exponent, y);
                        assert!(
                            (e - st.2.equivalent).abs() <= 1e-12 * e,
                            "{hardening:?} {}",
                            (e - st.2.equivalent) / e
                        );
                    }
                    // Plastic flow is deviatoric.
                    assert!(st.1.trace().abs() <= 1e-15 * st.2.equivalent.max(1e-30));
                }
            }
        }
    }

    /// Steel with `hardening` after the 3D strain `pre` from rest: its material, J2
    /// parameters and state (stress, plastic strain, hardening).
    fn yielded(hardening: Hardening, pre: Sym3) -> (Material, J2, (Sym3, Sym3, Hardened)) {
        let m = steel(hardening);
        let j2 = m.j2.expect("plastic");
        let mut st = (Sym3::default(), Sym3::default(), Hardened::default());
        step(&m, Plane::None, pre, &mut st);
        (m, j2, st)
    }

    /// The algorithmic tangent is the derivative of the return map: against central
    /// differences of the update from a yielded state (truncation ~h^2, round-off of the
    /// 1e-13 scalar solves over h ~ 1e-7 of the increment: 1e-6 of the stress change is
    /// far above both and far below a wrong term, which moves it by percent).
    #[test]
    fn tangent_is_the_derivative_of_the_return() {
        for hardening in [
            Hardening::Linear { modulus: 0.0 },
            Hardening::Linear { modulus: 2e9 },
            Hardening::RambergOsgood { exponent: 10.0 },
            Hardening::RambergOsgood { exponent: 3.0 },
            Hardening::Handbook {
                alpha: 1.0,
                exponent: 10.0,
            },
        ] {
            let pre = Sym3 {
                xx: 2e-3,
                yy: -5e-4,
                zz: -4e-4,
                xy: 6e-4,
                ..Sym3::default()
            };
            let (m, j2, st) = yielded(hardening, pre);
            let de = Sym3 {
                xx: 1e-3,
                yy: 2e-4,
                zz: -3e-4,
                yz: 1e-4,
                xz: -2e-4,
                xy: 5e-4,
            };
            let returned = |d: Sym3| {
                let mut s = st;
                m.update(Plane::None, d, &mut s.0);
                let t = j2.radial_return_tangent(&mut s.0, &mut s.1, &mut s.2);
                (s.0, t)
            };
            let (_, t) = returned(de);
            let t = t.expect("the increment yields");
            for dir in [
                Sym3 {
                    xx: 1.0,
                    ..Sym3::default()
                },
                Sym3 {
                    yy: 1.0,
                    zz: -0.5,
                    ..Sym3::default()
                },
                Sym3 {
                    xy: 1.0,
                    ..Sym3::default()
                },
                Sym3 {
                    yz: 0.7,
                    xx: 0.2,
                    ..Sym3::default()
                },
            ] {
                let h = 1e-7 * 1e-3;
                let (plus, _) = returned(de + dir * h);
                let (minus, _) = returned(de + dir * -h);
                let fd = (plus + minus * -1.0) * (0.5 / h);
                let exact = t.apply(m.lambda, m.mu, &dir);
                let err = (fd + exact * -1.0).max_abs();
                assert!(
                    err <= 1e-6 * exact.max_abs(),
                    "{hardening:?} along {dir:?}: {err:e} of {:e}",
                    exact.max_abs()
                );
            }
        }
    }

    /// The continuum tangent at a yielded state is the algorithmic tangent's limit for an
    /// increment that vanishes along the flow: the two agree to the increment's relative
    /// size (1e-9 here), and an unloaded state has none.
    #[test]
    fn continuum_tangent_is_the_small_increment_limit() {
        for hardening in [
            Hardening::Linear { modulus: 0.0 },
            Hardening::Linear { modulus: 2e9 },
            Hardening::RambergOsgood { exponent: 5.0 },
            Hardening::Handbook {
                alpha: 0.5,
                exponent: 5.0,
            },
        ] {
            let pre = Sym3 {
                xx: 3e-3,
                yy: -1e-3,
                zz: -5e-4,
                xy: 1e-3,
                ..Sym3::default()
            };
            let (m, j2, st) = yielded(hardening, pre);
            let c = j2.continuum_tangent(&st.0, &st.2).expect("on the surface");
            let mut next = st;
            m.update(Plane::None, pre * 1e-9, &mut next.0);
            let a = (j2.radial_return_tangent(&mut next.0, &mut next.1, &mut next.2))
                .expect("still yielding");
            let (Tangent::Radial(c), Tangent::Radial(a)) = (c, a) else {
                panic!("a radial return's tangents");
            };
            for (x, y) in [(c.theta, a.theta), (c.theta_bar, a.theta_bar)] {
                assert!((x - y).abs() <= 1e-6 * x.abs(), "{hardening:?}: {x} vs {y}");
            }
            assert!((c.normal + a.normal * -1.0).max_abs() <= 1e-6);
            let mut unloaded = st;
            m.update(Plane::None, pre * -0.1, &mut unloaded.0);
            assert!(j2.continuum_tangent(&unloaded.0, &unloaded.2).is_none());
        }
    }

    /// Uniaxial stress by iterating the lateral strain (3D: yy = zz; plane stress: yy) until
    /// the lateral stress vanishes; returns sigma_xx.
    fn uniaxial(m: &Material, plane: Plane, dx: f64, st: &mut (Sym3, Sym3, Hardened)) -> f64 {
        let lateral = |e: f64| Sym3 {
            xx: dx,
            yy: e,
            zz: if plane == Plane::None { e } else { 0.0 },
            ..Sym3::default()
        };
        let try_e = |e: f64| {
            let mut s = *st;
            step(m, plane, lateral(e), &mut s);
            (s.0.yy, s)
        };
        let (mut e0, mut e1) = (-0.3 * dx, -0.5 * dx);
        let (mut f0, mut f1) = (try_e(e0).0, try_e(e1).0);
        for _ in 0..100 {
            if f1 == f0 {
                break;
            }
            let e2 = e1 - f1 * (e1 - e0) / (f1 - f0);
            (e0, f0) = (e1, f1);
            e1 = e2;
            f1 = try_e(e1).0;
            if f1.abs() < 1e-15 * m.youngs {
                break;
            }
        }
        *st = try_e(e1).1;
        st.0.xx
    }

    /// Loading past yield follows the uniaxial hardening law in 3D and in plane stress, and
    /// unloading follows the elastic slope E: for linear hardening sigma = sigma_0 +
    /// E H/(E + H) (eps - eps_0); for Ramberg-Osgood eps/eps_0 = (sigma/sigma_0)^n; for the
    /// handbook's form eps/eps_0 = sigma/sigma_0 + alpha (sigma/sigma_0)^n from the start.
    #[test]
    fn uniaxial_cycle_follows_the_hardening_law() {
        let (e, s0) = (200e9, 250e6);
        let eps0 = s0 / e;
        for plane in [Plane::None, Plane::Stress] {
            for hardening in [
                Hardening::Linear { modulus: 0.0 },
                Hardening::Linear { modulus: 10e9 },
                Hardening::RambergOsgood { exponent: 10.0 },
                Hardening::Handbook {
                    alpha: 1.0,
                    exponent: 5.0,
                },
            ] {
                let m = steel(hardening);
                let mut st = (Sym3::default(), Sym3::default(), Hardened::default());
                let (steps, peak) = (400, 8.0 * eps0);
                let mut sigma = 0.0;
                for k in 1..=steps {
                    sigma = uniaxial(&m, plane, peak / steps as f64, &mut st);
                    let eps = peak * k as f64 / steps as f64;
                    let expect = match hardening {
                        Hardening::Handbook { alpha, exponent: n } => {
                            // Invert eps/eps0 = r + alpha r^n by Newton in r, from above
                            // (the right side is convex).
                            let mut r: f64 = eps / eps0;
                            for _ in 0..50 {
                                r -= (r + alpha * r.powf(n) - eps / eps0)
                                    / (1.0 + alpha * n * r.powf(n - 1.0));
                            }
                            s0 * r
                        }
                        _ if eps <= eps0 => e * eps,
                        Hardening::Linear { modulus: h } => s0 + e * h / (e + h) * (eps - eps0),
                        Hardening::RambergOsgood { exponent: n } => {
                            // Invert eps/eps0 = r^n by Newton in r = sigma/sigma0.
                            let mut r: f64 = (eps / eps0).powf(1.0 / n);
                            for _ in 0..5 {
                                r -= (r.powf(n) - eps / eps0) / (n * r.powf(n - 1.0));
                            }
                            s0 * r
                        }
                    };
                    assert!(
                        (sigma - expect).abs() <= 1e-9 * s0,
                        "{plane:?} {hardening:?} at eps = {eps}: {sigma} vs {expect}"
                    );
                    assert!(st.0.yy.abs() < 1e-11 * s0 && st.0.zz.abs() < 1e-11 * s0);
                }
                let top = sigma;
                let back = 0.5 * eps0;
                let unloaded = uniaxial(&m, plane, -back, &mut st);
                assert!(
                    (top - unloaded - e * back).abs() <= 1e-9 * s0,
                    "{plane:?} {hardening:?}: unloading slope"
                );
            }
        }
    }
}
