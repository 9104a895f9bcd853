//! Fracture measurement results and the conversion of the energy release rate into stress
//! intensity factors from the crack opening (Guo & Nairn 2D (2004) Eqs. 10, 14-22).

use crate::physics::material::{Material, Plane};

/// What to measure at crack tips, from the scenario's `[fracture]` table.
#[derive(Clone, Debug)]
pub struct FracturePlan {
    /// The main path J is measured on, in cells: in 2D the half-size n of the n x n square
    /// contour; in 3D the tube's radius and half-length `domain` (when that is whole).
    pub contour: usize,
    /// Add the area integral of Guo & Nairn 2D (2004) Eq. 8 (path independence in dynamics).
    pub area_term: bool,
    /// End of the window behind the tip, in cells, over which the crack opening that splits
    /// G into K_I and K_II (and K_III in 3D) is fitted (it starts one cell behind the tip).
    pub opening: f64,
    /// Further contour sizes (cells; in 3D tube radii, each with its half-length) on which
    /// J is also measured, for paths.csv.
    pub compare: Vec<usize>,
    /// Start of the window over which the contours are compared (s).
    pub compare_from: f64,
    /// K that fracture.png divides by (Pa sqrt(m)), e.g. s0 sqrt(pi a).
    pub k0: Option<f64>,
    /// Which K_I, K_II are reported (both are measured and written).
    pub k_method: KMethod,
    /// Radius of the interaction integral's domain, in cells (of the larger cell size); in
    /// 3D the radius and half-length of the tube around the front.
    pub domain: f64,
}

/// How the reported K_I and K_II are obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KMethod {
    /// Of [`KMethod::Interaction`] and [`KMethod::Mixity`] (the same mode ratio), the one
    /// with the lower G ([`lower_g`]): the default.
    LowerG,
    /// sqrt(E' G) with G from J, split in the ratio K_II / K_I of the interaction integral
    /// ([`k_from_mixity`]).
    Mixity,
    /// The interaction integral alone (`crate::fracture::interaction`).
    Interaction,
    /// G split by the crack opening and sliding behind the tip (Guo & Nairn 2D (2004) Eqs.
    /// 14-22, with the fit of `FracturePlan::opening`).
    Opening,
}

/// What a step measured at its cracks, for the run to write: J and K at every tip (or
/// front vertex), J on the compared contours, and the growth rows of the tips that moved.
#[derive(Clone, Debug, Default)]
pub struct Measured {
    /// One result per crack tip.
    pub tips: Vec<TipResult>,
    /// One result per tip and compared contour.
    pub paths: Vec<PathResult>,
    /// The growth system's records of new segments.
    pub growth: Vec<crate::physics::growth::GrowthRow>,
}

/// J on one contour at one tip and time, its line and area parts apart (J/m^2): the
/// path-independence record (paths.csv).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PathResult {
    /// Step.
    pub step: u64,
    /// Time (s).
    pub time: f64,
    /// Crack index.
    pub crack: u32,
    /// 0 for the crack's start vertex, 1 for its end vertex.
    pub tip: u32,
    /// Contour size n (cells) of the n x n contour.
    pub contour: u32,
    /// Line integral (Eq. 7), global x and y.
    pub line: [f64; 2],
    /// Area term (Eq. 8), global x and y.
    pub area: [f64; 2],
    /// The tip's unit direction in global x and y, G = J . direction (Eq. 10); along a 3D
    /// front (1, 0), J1 being J along the front's normal already.
    pub direction: [f64; 2],
}

impl PathResult {
    /// J along the tip's direction, the energy release rate G (Eq. 10), with or without
    /// the area term; a zero component is skipped (along a 3D front J2 is NaN).
    pub fn along_tip(&self, area: bool) -> f64 {
        let a = if area { self.area } else { [0.0; 2] };
        (0..2)
            .filter(|&k| self.direction[k] != 0.0)
            .map(|k| (self.line[k] + a[k]) * self.direction[k])
            .sum()
    }
}

/// J and K at one crack tip (2D) or front vertex (3D) at one time (SI: J/m^2, Pa sqrt(m)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TipResult {
    /// Step.
    pub step: u64,
    /// Time (s).
    pub time: f64,
    /// Crack index.
    pub crack: u32,
    /// In 2D 0 for the crack's start vertex, 1 for its end vertex; in 3D the front vertex's
    /// ordinal along the crack's fronts.
    pub tip: u32,
    /// Tip position (m).
    pub x: [f64; 3],
    /// J components in global x and y (Eq. 7 or 8); in 3D J along the front's normal x1
    /// (the energy release rate) and NaN (J_2 would need the crack-face term of Eq. 33).
    pub j: [f64; 2],
    /// Mode I, II and III stress intensity factors as reported (KIII = 0 in 2D): those of
    /// `FracturePlan::k_method`.
    pub k: [f64; 3],
    /// K_I, K_II, K_III from the interaction integral (K_III = 0 in 2D).
    pub k_interaction: [f64; 3],
    /// K_I, K_II, K_III from G and the crack opening (K_III = 0 in 2D).
    pub k_opening: [f64; 3],
    /// Radius of the interaction integral's domain (m); 0 when none fitted.
    pub domain: f64,
    /// The crack's length along its polyline (m; 2D; NaN in 3D): it grows with the crack.
    pub length: f64,
    /// The tip's speed (m/s): 0 unless the crack grows at a set speed.
    pub speed: f64,
}

impl TipResult {
    /// Number of [`TipResult::values`].
    pub const VALUES: usize = 17;

    /// Position, J, the reported K, the interaction integral's and the opening split's K,
    /// the domain radius, the crack length and the tip speed, in fracture.csv's column order.
    pub fn values(&self) -> [f64; Self::VALUES] {
        [
            self.x[0],
            self.x[1],
            self.x[2],
            self.j[0],
            self.j[1],
            self.k[0],
            self.k[1],
            self.k[2],
            self.k_interaction[0],
            self.k_interaction[1],
            self.k_interaction[2],
            self.k_opening[0],
            self.k_opening[1],
            self.k_opening[2],
            self.domain,
            self.length,
            self.speed,
        ]
    }

    /// The result whose [`TipResult::values`] are `v`.
    pub fn from_values(
        step: u64,
        time: f64,
        crack: u32,
        tip: u32,
        v: &[f64; Self::VALUES],
    ) -> Self {
        TipResult {
            step,
            time,
            crack,
            tip,
            x: [v[0], v[1], v[2]],
            j: [v[3], v[4]],
            k: [v[5], v[6], v[7]],
            k_interaction: [v[8], v[9], v[10]],
            k_opening: [v[11], v[12], v[13]],
            domain: v[14],
            length: v[15],
            speed: v[16],
        }
    }
}

/// Crack-speed factors (A_I, A_II) of a tip running at speed `c` (Nishioka 1995, as quoted
/// in Guo & Nairn 2D (2004) Eqs. 16-18): A_I = beta_d (1 - beta_s^2) / D and A_II =
/// beta_s (1 - beta_s^2) / D, with beta_d = sqrt(1 - c^2/cd^2), beta_s = sqrt(1 - c^2/cs^2)
/// and D = 4 beta_d beta_s - (1 + beta_s^2)^2. At c = 0 both take their limit
/// (kappa + 1)/4 (Eq. 20).
pub fn speed_factors(c: f64, cs: f64, cd: f64, kappa: f64) -> [f64; 2] {
    if c == 0.0 {
        return [(kappa + 1.0) / 4.0; 2];
    }
    let bd = (1.0 - (c / cd).powi(2)).sqrt();
    let bs = (1.0 - (c / cs).powi(2)).sqrt();
    let d = 4.0 * bd * bs - (1.0 + bs * bs).powi(2);
    [bd * (1.0 - bs * bs) / d, bs * (1.0 - bs * bs) / d]
}

/// kappa: 3 - 4 nu in plane strain (and 3D), (3 - nu)/(1 + nu) in plane stress.
pub fn kappa(m: &Material, plane: Plane) -> f64 {
    match plane {
        Plane::Stress => (3.0 - m.poisson) / (1.0 + m.poisson),
        Plane::Strain | Plane::None => 3.0 - 4.0 * m.poisson,
    }
}

/// E' = E in plane stress, E / (1 - nu^2) in plane strain: G = (K_I^2 + K_II^2) / E'.
pub fn e_prime(m: &Material, plane: Plane) -> f64 {
    match plane {
        Plane::Stress => m.youngs,
        Plane::Strain | Plane::None => m.youngs / (1.0 - m.poisson * m.poisson),
    }
}

/// K_I and K_II of magnitude sqrt(E' g) in the ratio of `k` (a stationary tip: G = (K_I^2 +
/// K_II^2) / E', Irwin 1957). The energy release rate `g` comes from the path-independent J
/// and the mode mixity from the interaction integral, which is the more sensitive of the
/// two to where the discrete crack's tip lies. NaN when `k` is NaN or zero.
pub fn k_from_mixity(m: &Material, plane: Plane, g: f64, k: [f64; 2]) -> [f64; 2] {
    let norm = k[0].hypot(k[1]);
    if norm.is_nan() || norm == 0.0 {
        return [f64::NAN; 2];
    }
    let scale = (e_prime(m, plane) * g.max(0.0)).sqrt() / norm;
    [k[0] * scale, k[1] * scale]
}

/// Of two K estimates in the same mode ratio, the one of lower energy release rate (the
/// smaller norm); `a` where `b` is NaN. On the discrete crack each estimate errs high
/// where it fails: the interaction integral in slender arms (its auxiliary field centred
/// on the last crack vertex, not where the discrete crack acts as if it ends), J where the
/// crack cuts the cells obliquely (docs/fracture.md, "Which K").
pub fn lower_g<const N: usize>(a: [f64; N], b: [f64; N]) -> [f64; N] {
    let norm = |k: &[f64; N]| k.iter().map(|v| v * v).sum::<f64>();
    if norm(&b) < norm(&a) { b } else { a }
}

/// K_I and K_II from the energy release rate `g` of a tip at rest and the opening `d_i` and
/// sliding `d_ii` displacements behind it: K = (delta / |delta|) sqrt(E' G) (Guo & Nairn
/// 2D (2004) Eqs. 21-22, their Eqs. 14-15 at c = 0). NaN when the crack is closed (no
/// opening to split by).
pub fn k_from_g(m: &Material, plane: Plane, g: f64, d_i: f64, d_ii: f64) -> [f64; 2] {
    let den = d_i * d_i + d_ii * d_ii;
    if den == 0.0 {
        return [f64::NAN; 2];
    }
    let k = (e_prime(m, plane) * g.max(0.0) / den).sqrt();
    [d_i * k, d_ii * k]
}

/// K_I and K_II of a tip running at speed `c` from the amplitudes of its opening `d_i` and
/// sliding `d_ii` behind it, delta = d sqrt(r) (m^0.5). The faces of a tip running steadily
/// part as delta = (2 A(c) K / mu) sqrt(2 r / pi), with A the speed factors A_I, A_II
/// (Freund 1990, the moving tip's asymptotic field; Nishioka 1995), which at rest is the
/// static (kappa + 1) K / mu sqrt(r / (2 pi)). A running tip takes its K from here rather
/// than from G: the tip of an explicit crack absorbs no energy as it moves (the energy the
/// continuum's tip takes leaves as waves), so J round it reads low, while the faces behind
/// it open as the moving field's K says.
pub fn k_from_opening(m: &Material, plane: Plane, d_i: f64, d_ii: f64, c: f64) -> [f64; 2] {
    let kap = kappa(m, plane);
    let cs = (m.mu / m.density).sqrt();
    let cd = cs * ((kap + 1.0) / (kap - 1.0)).sqrt();
    let [a1, a2] = speed_factors(c, cs, cd, kap);
    let scale = 0.5 * m.mu * (0.5 * std::f64::consts::PI).sqrt();
    [scale * d_i / a1, scale * d_ii / a2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lower of two proportional estimates is kept, in any order; a NaN estimate (no J)
    /// never replaces a measured one.
    #[test]
    fn lower_g_keeps_the_smaller_and_ignores_nan() {
        let (a, b) = ([3.0e6, -1.0e6, 0.5e6], [2.7e6, -0.9e6, 0.45e6]);
        assert_eq!(lower_g(a, b), b);
        assert_eq!(lower_g(b, a), b);
        assert_eq!(lower_g(a, [f64::NAN; 3]), a);
    }

    /// Eqs. 21-22: K = (delta/|delta|) sqrt(G E'), so K_I^2 + K_II^2 = E' G.
    #[test]
    fn stationary_limit_is_sqrt_g_e() {
        let m = Material::new("m", 2.3e9, 0.33, 1500.0);
        let g = 10.0;
        for (plane, e) in [
            (Plane::Stress, 2.3e9),
            (Plane::Strain, 2.3e9 / (1.0 - 0.33 * 0.33)),
        ] {
            let [k1, k2] = k_from_g(&m, plane, g, 3.0, 4.0);
            let k = (g * e).sqrt();
            assert!(
                (k1 - 0.6 * k).abs() < 1e-12 * k,
                "{plane:?}: {k1} vs {}",
                0.6 * k
            );
            assert!((k2 - 0.8 * k).abs() < 1e-12 * k);
        }
    }

    /// The speed factors tend to their c = 0 limit (kappa + 1)/4 (Eq. 20) and grow as the
    /// speed approaches the Rayleigh speed, where D = 0.
    #[test]
    fn speed_factors_are_continuous_at_rest() {
        let (cs, nu): (f64, f64) = (1000.0, 0.3);
        let kap: f64 = 3.0 - 4.0 * nu;
        let cd = cs * ((kap + 1.0) / (kap - 1.0)).sqrt();
        let [a1, a2] = speed_factors(1e-3 * cs, cs, cd, kap);
        let limit = (kap + 1.0) / 4.0;
        assert!(
            (a1 - limit).abs() < 1e-5 && (a2 - limit).abs() < 1e-5,
            "{a1} {a2}"
        );
        let [fast, _] = speed_factors(0.5 * cs, cs, cd, kap);
        assert!(fast > 1.1 * limit);
    }

    /// At rest, the opening of a K_I field is (kappa + 1) K / mu sqrt(r / (2 pi)) (the
    /// Williams field). Running at 0.4 c_s, the opening for K taken with the stress ahead of
    /// the tip, K / sqrt(2 pi x), in Irwin's crack-closure integral gives the energy release
    /// rate of Belytschko et al. (1995) Eqs. 45-47, G = (1 - nu^2)/E A(v) K^2 with
    /// A(v) = v^2 alpha_d / ((1 - nu) c_s^2 D): the closure integral over a length a is
    /// K^2 d sqrt(pi / 2) / 4 for an opening d K sqrt(r).
    #[test]
    fn running_opening_closes_to_the_running_energy_release_rate() {
        let (e, nu, rho) = (211.0e9, 0.3, 7800.0);
        let m = Material::new("steel", e, nu, rho);
        let k = 10.0e6;
        let kap = 3.0 - 4.0 * nu;
        let static_amplitude = (kap + 1.0) * k / (m.mu * (2.0 * std::f64::consts::PI).sqrt());
        let [k1, k2] = k_from_opening(&m, Plane::Strain, static_amplitude, 0.0, 0.0);
        assert!((k1 - k).abs() < 1e-9 * k && k2 == 0.0, "{k1}");

        let cs = (m.mu / rho).sqrt();
        let cd = cs * ((kap + 1.0) / (kap - 1.0)).sqrt();
        let v = 0.4 * cs;
        let d = 1.0 / k_from_opening(&m, Plane::Strain, 1.0, 1.0, v)[0];
        let closure = k * k * d * (0.5 * std::f64::consts::PI).sqrt() / 4.0;
        let (ad, as_) = (
            (1.0 - (v / cd).powi(2)).sqrt(),
            (1.0 - (v / cs).powi(2)).sqrt(),
        );
        let dd = 4.0 * ad * as_ - (1.0 + as_ * as_).powi(2);
        let a = v * v * ad / ((1.0 - nu) * cs * cs * dd);
        let g = (1.0 - nu * nu) / e * a * k * k;
        assert!((closure - g).abs() < 1e-9 * g, "{closure} vs {g}");
        assert!(
            a > 1.1,
            "the running tip releases more per K^2 than at rest: {a}"
        );
    }
}
