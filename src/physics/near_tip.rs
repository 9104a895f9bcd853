//! The leading (Williams) term of the elastic near-tip field of a straight crack, in tip
//! axes: x along the crack's extension, the faces on theta = +-pi (Williams 1957; Irwin
//! 1957). Used as the imposed field of traction loads and as the auxiliary fields of the
//! interaction integral. The formulas are written out in `scenarios/reference/README.md`.

use std::f64::consts::PI;

/// The sines and cosines of theta/2, 3 theta/2 and theta the fields are made of.
#[derive(Clone, Copy, Debug)]
struct Angle {
    s: f64,
    c: f64,
    s3: f64,
    c3: f64,
    st: f64,
    ct: f64,
}

impl Angle {
    fn new(theta: f64) -> Angle {
        let (s, c) = (0.5 * theta).sin_cos();
        let (s3, c3) = (1.5 * theta).sin_cos();
        let (st, ct) = theta.sin_cos();
        Angle {
            s,
            c,
            s3,
            c3,
            st,
            ct,
        }
    }
}

/// Stress (xx, yy, xy) of the leading near-tip term at polar position (r, theta) about the
/// tip. Independent of the material and of plane strain or stress.
pub fn stress(k1: f64, k2: f64, r: f64, theta: f64) -> [f64; 3] {
    stress_at(k1, k2, r, &Angle::new(theta))
}

fn stress_at(k1: f64, k2: f64, r: f64, t: &Angle) -> [f64; 3] {
    let a = 1.0 / (2.0 * PI * r).sqrt();
    let Angle { s, c, s3, c3, .. } = *t;
    [
        a * (k1 * c * (1.0 - s * s3) - k2 * s * (2.0 + c * c3)),
        a * (k1 * c * (1.0 + s * s3) + k2 * s * c * c3),
        a * (k1 * s * c * c3 + k2 * c * (1.0 - s * s3)),
    ]
}

/// The angular functions of the displacement, u_i = sqrt(r) / (2 mu sqrt(2 pi)) f_i(theta),
/// and their derivatives f_i'(theta), for K_I = k1 and K_II = k2.
fn angular(k1: f64, k2: f64, t: &Angle, kappa: f64) -> ([f64; 2], [f64; 2]) {
    let Angle { s, c, .. } = *t;
    let f = [
        k1 * c * (kappa - 1.0 + 2.0 * s * s) + k2 * s * (kappa + 1.0 + 2.0 * c * c),
        k1 * s * (kappa + 1.0 - 2.0 * c * c) - k2 * c * (kappa - 1.0 - 2.0 * s * s),
    ];
    // d(s)/dtheta = c/2, d(c)/dtheta = -s/2.
    let df = [
        k1 * (-0.5 * s * (kappa - 1.0 + 2.0 * s * s) + 2.0 * s * c * c)
            + k2 * (0.5 * c * (kappa + 1.0 + 2.0 * c * c) - 2.0 * s * s * c),
        k1 * (0.5 * c * (kappa + 1.0 - 2.0 * c * c) + 2.0 * s * s * c)
            + k2 * (0.5 * s * (kappa - 1.0 - 2.0 * s * s) + 2.0 * s * c * c),
    ];
    (f, df)
}

/// Displacement (x, y) of the leading near-tip term, for shear modulus `mu` and
/// kappa = 3 - 4 nu (plane strain) or (3 - nu)/(1 + nu) (plane stress).
pub fn displacement(k1: f64, k2: f64, r: f64, theta: f64, kappa: f64, mu: f64) -> [f64; 2] {
    let (f, _) = angular(k1, k2, &Angle::new(theta), kappa);
    let a = r.sqrt() / (2.0 * mu * (2.0 * PI).sqrt());
    [a * f[0], a * f[1]]
}

/// Displacement gradient `g[i][j]` = du_i/dx_j of the leading near-tip term, from
/// d/dx = cos t d/dr - (sin t / r) d/dt and d/dy = sin t d/dr + (cos t / r) d/dt with
/// du/dr = u / (2 r).
pub fn displacement_gradient(
    k1: f64,
    k2: f64,
    r: f64,
    theta: f64,
    kappa: f64,
    mu: f64,
) -> [[f64; 2]; 2] {
    gradient_at(k1, k2, r, &Angle::new(theta), kappa, mu)
}

fn gradient_at(k1: f64, k2: f64, r: f64, t: &Angle, kappa: f64, mu: f64) -> [[f64; 2]; 2] {
    let (f, df) = angular(k1, k2, t, kappa);
    let a = 1.0 / (2.0 * mu * (2.0 * PI * r).sqrt());
    let (st, ct) = (t.st, t.ct);
    [0, 1].map(|i| {
        [
            a * (0.5 * ct * f[i] - st * df[i]),
            a * (0.5 * st * f[i] + ct * df[i]),
        ]
    })
}

/// Stress and displacement gradient of unit K_I (index 0) and unit K_II (index 1) at
/// (r, theta): the interaction integral's auxiliary fields, from one evaluation of the
/// angle's sines and cosines.
pub fn unit_fields(r: f64, theta: f64, kappa: f64, mu: f64) -> ([[f64; 3]; 2], [[[f64; 2]; 2]; 2]) {
    let t = Angle::new(theta);
    let modes = [[1.0, 0.0], [0.0, 1.0]];
    (
        modes.map(|k| stress_at(k[0], k[1], r, &t)),
        modes.map(|k| gradient_at(k[0], k[1], r, &t, kappa, mu)),
    )
}

/// Anti-plane (mode III) field of K_III = `k3` at (r, theta): the displacement along the
/// front u_3 = (2 K_III / mu) sqrt(r / 2 pi) sin(theta/2), its gradient [du_3/dx, du_3/dy]
/// and the stress [s_13, s_23] = mu times that gradient (Irwin 1957).
pub fn antiplane(k3: f64, r: f64, theta: f64, mu: f64) -> (f64, [f64; 2], [f64; 2]) {
    let (s, c) = (0.5 * theta).sin_cos();
    let a = k3 / (2.0 * PI * r).sqrt();
    let g = [-a * s / mu, a * c / mu];
    (2.0 * r * a * s / mu, g, [mu * g[0], mu * g[1]])
}

#[cfg(test)]
mod tests {
    use super::*;

    const MU: f64 = 80e9;

    /// The anti-plane faces are free (s_23 = 0 at theta = +-pi), the ligament carries
    /// s_23 = K_III / sqrt(2 pi r), the tearing between the faces is 4 K_III / mu
    /// sqrt(r / 2 pi), and the gradient is the derivative of the displacement.
    #[test]
    fn antiplane_field() {
        let (k3, r) = (0.8e6, 1.5e-3);
        let a = k3 / (2.0 * PI * r).sqrt();
        assert!((antiplane(k3, r, 0.0, MU).2[1] - a).abs() < 1e-12 * a);
        assert!(antiplane(k3, r, PI, MU).2[1].abs() < 1e-9 * a);
        let tear = antiplane(k3, r, PI, MU).0 - antiplane(k3, r, -PI, MU).0;
        let want = 4.0 * k3 / MU * (r / (2.0 * PI)).sqrt();
        assert!((tear - want).abs() < 1e-12 * want);
        let u = |x: f64, y: f64| antiplane(k3, x.hypot(y), y.atan2(x), MU).0;
        let (x, y, d): (f64, f64, f64) = (-4e-4, 7e-4, 1e-9);
        let g = antiplane(k3, x.hypot(y), y.atan2(x), MU).1;
        let fd = [
            (u(x + d, y) - u(x - d, y)) / (2.0 * d),
            (u(x, y + d) - u(x, y - d)) / (2.0 * d),
        ];
        for k in 0..2 {
            assert!((g[k] - fd[k]).abs() < 1e-6 * g[k].abs(), "{g:?} vs {fd:?}");
        }
    }

    /// The faces theta = +-pi carry no traction (s_yy = s_xy = 0) and, ahead of the tip,
    /// s_yy = K_I / sqrt(2 pi r) and s_xy = K_II / sqrt(2 pi r).
    #[test]
    fn faces_are_free_and_ligament_carries_k() {
        let (k1, k2, r) = (2.0e6, -0.7e6, 1e-3);
        let a = 1.0 / (2.0 * PI * r).sqrt();
        let ahead = stress(k1, k2, r, 0.0);
        assert!((ahead[1] - k1 * a).abs() < 1e-9 * k1 * a);
        assert!((ahead[2] - k2 * a).abs() < 1e-9 * k1 * a);
        for t in [PI, -PI] {
            let face = stress(k1, k2, r, t);
            assert!(face[1].abs() < 1e-9 * k1 * a && face[2].abs() < 1e-9 * k1 * a);
        }
    }

    /// The gradient matches central differences of the displacement.
    #[test]
    fn gradient_is_the_derivative_of_the_displacement() {
        let (k1, k2, kappa) = (1.3e6, -0.4e6, 1.8);
        for (x, y) in [(1e-3, 2e-4), (-7e-4, 5e-4), (-7e-4, -5e-4), (2e-4, -9e-4)] {
            let at = |x: f64, y: f64| {
                displacement(k1, k2, f64::hypot(x, y), f64::atan2(y, x), kappa, MU)
            };
            let g = displacement_gradient(k1, k2, f64::hypot(x, y), f64::atan2(y, x), kappa, MU);
            let d = 1e-9;
            let (px, mx, py, my) = (at(x + d, y), at(x - d, y), at(x, y + d), at(x, y - d));
            for i in 0..2 {
                let fd = [(px[i] - mx[i]) / (2.0 * d), (py[i] - my[i]) / (2.0 * d)];
                for j in 0..2 {
                    assert!(
                        (g[i][j] - fd[j]).abs() < 1e-6 * g[i][j].abs().max(1e-6),
                        "({x}, {y}) du{i}/dx{j}: {} vs {}",
                        g[i][j],
                        fd[j]
                    );
                }
            }
        }
    }

    /// Hooke's law on the gradient's strain gives the stress, in plane strain and in plane
    /// stress (each with its kappa): the displacement and the stress are one field.
    #[test]
    fn strain_of_the_displacement_gives_the_stress() {
        let (k1, k2, nu) = (0.9e6, 1.7e6, 0.3);
        let e = 2.0 * MU * (1.0 + nu);
        for (kappa, lam_eff) in [
            (3.0 - 4.0 * nu, e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))),
            ((3.0 - nu) / (1.0 + nu), e * nu / (1.0 - nu * nu)),
        ] {
            for t in [-2.9, -1.2, 0.0, 0.7, 2.2, 3.1] {
                let r = 3e-4;
                let g = displacement_gradient(k1, k2, r, t, kappa, MU);
                let tr = g[0][0] + g[1][1];
                let hooke = [
                    lam_eff * tr + 2.0 * MU * g[0][0],
                    lam_eff * tr + 2.0 * MU * g[1][1],
                    MU * (g[0][1] + g[1][0]),
                ];
                let s = stress(k1, k2, r, t);
                let scale = k1.hypot(k2) / (2.0 * PI * r).sqrt();
                for (h, s) in hooke.iter().zip(s) {
                    assert!(
                        (h - s).abs() < 1e-9 * scale,
                        "theta {t}: {hooke:?} vs {s:?}"
                    );
                }
            }
        }
    }

    /// The opening between the faces is (kappa + 1) K_I / mu sqrt(r / 2 pi), i.e.
    /// 8 K_I / E' sqrt(r / 2 pi), and the sliding (kappa + 1) K_II / mu sqrt(r / 2 pi).
    #[test]
    fn face_opening_and_sliding() {
        let (k1, k2, kappa, r) = (1.1e6, 0.6e6, 1.9, 2e-3);
        let up = displacement(k1, k2, r, PI, kappa, MU);
        let down = displacement(k1, k2, r, -PI, kappa, MU);
        let scale = (kappa + 1.0) / MU * (r / (2.0 * PI)).sqrt();
        assert!((up[1] - down[1] - scale * k1).abs() < 1e-12 * scale * k1);
        assert!((up[0] - down[0] - scale * k2).abs() < 1e-12 * scale * k1);
    }
}
