//! The eta estimate of a cracked specimen's J from its load-displacement record, J = J_el +
//! J_pl: J_el = K^2 / E' from a handbook K, J_pl = eta A_pl / (B b) with A_pl the plastic
//! part of the area under the record (Rice, Paris & Merkle 1973, the deep-crack J = 2 A /
//! (B b) of a bend bar; ASTM E1820, Annex A1, eta = 1.9 for its load-line displacement). It
//! checks an elastic-plastic J without looking near the tip.

/// The part of the largest load over which the elastic compliance is fitted: above a tenth,
/// clear of the start's ringing, and below 0.4, before the ligament yields.
const FIT: (f64, f64) = (0.1, 0.4);

/// A specimen's eta estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EtaEstimate {
    /// The plastic eta factor of the specimen and the displacement measured.
    pub factor: f64,
    /// The uncracked ligament b (m).
    pub ligament: f64,
    /// The handbook's K_I per unit load (Pa sqrt(m) / N).
    pub k_per_load: f64,
    /// E' of the material at the tip (Pa).
    pub modulus: f64,
    /// The specimen's thickness B (m).
    pub thickness: f64,
}

impl EtaEstimate {
    /// J (J/m^2) at the end of a record of `load` (N) and `displacement` (m) sampled at the
    /// same times from the unloaded start. A_pl is the work (trapezoidal rule) less the
    /// elastic P^2 C / 2 at the last load, C the least-squares compliance through the
    /// origin of the samples between 0.1 and 0.4 of the largest load; the displacement's
    /// sign is taken so that the work is positive. None without work or fitted samples.
    pub fn j(&self, load: &[f64], displacement: &[f64]) -> Option<f64> {
        let work: f64 = (load.windows(2).zip(displacement.windows(2)))
            .map(|(p, d)| 0.5 * (p[0] + p[1]) * (d[1] - d[0]))
            .sum();
        let largest = load.iter().fold(0.0, |m: f64, p| m.max(p.abs()));
        let window = FIT.0 * largest..=FIT.1 * largest;
        let (mut count, mut pd, mut pp) = (0, 0.0, 0.0);
        for (p, d) in load.iter().zip(displacement) {
            if window.contains(&p.abs()) {
                (count, pd, pp) = (count + 1, pd + p * d, pp + p * p);
            }
        }
        if count < 2 || work == 0.0 || !work.is_finite() {
            return None;
        }
        let compliance = pd / pp;
        let p = *load.last()?;
        let plastic = (work - 0.5 * p * p * compliance) * work.signum();
        let k = self.k_per_load * p;
        Some(k * k / self.modulus + self.factor * plastic / (self.thickness * self.ligament))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record that is elastic, d = C P, up to half the final load P_f and then gains a
    /// plastic displacement a (P - P_f/2)^2, then holds P_f while creeping by `hold`:
    /// A_pl = 2a [P^3/3 - P_1 P^2/2] from P_1 to P_f, plus P_f hold.
    fn record(sign: f64) -> (Vec<f64>, Vec<f64>, f64) {
        let (c, a, pf, hold) = (2e-10, 3e-16, 1.2e6, 1e-5);
        let p1 = 0.5 * pf;
        let n = 20_000;
        let mut load: Vec<f64> = (0..=n).map(|k| pf * k as f64 / n as f64).collect();
        load.extend([pf; 100]);
        let plastic = |p: f64| if p > p1 { a * (p - p1).powi(2) } else { 0.0 };
        let mut disp: Vec<f64> = load[..=n].iter().map(|&p| c * p + plastic(p)).collect();
        let end = disp[n];
        disp.extend((1..=100).map(|k| end + hold * k as f64 / 100.0));
        let cube = |p: f64| 2.0 * a * (p * p * p / 3.0 - p1 * p * p / 2.0);
        let area = cube(pf) - cube(p1) + pf * hold;
        (load, disp.iter().map(|d| sign * d).collect(), area)
    }

    #[test]
    fn plastic_area_matches_the_closed_form() {
        let e = EtaEstimate {
            factor: 1.9,
            ligament: 0.025,
            k_per_load: 47.6,
            modulus: 200e9 / 0.91,
            thickness: 1.0,
        };
        for sign in [1.0, -1.0] {
            let (load, disp, area) = record(sign);
            let elastic = (e.k_per_load * 1.2e6).powi(2) / e.modulus;
            let expected = elastic + 1.9 * area / 0.025;
            let j = e.j(&load, &disp).expect("a record with work");
            assert!((j - expected).abs() <= 1e-6 * expected, "{j} vs {expected}");
        }
        assert_eq!(e.j(&[0.0; 10], &[0.0; 10]), None);
    }
}
