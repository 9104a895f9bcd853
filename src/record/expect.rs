//! `[[expect]]` evaluation: what each expect measures in the history, and its error
//! against the reference.

use super::history::{
    History, arrival, energy_balance, frequency, last_rows, path_difference, path_tips,
};
use super::probe::Probe;
use crate::fracture::eta::EtaEstimate;
use crate::fracture::plan::TipResult;
use crate::physics::growth::GrowthRow;
use glam::DVec3;
use serde::Serialize;

/// How a reference varies along a front with the angle theta about its centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// cos(theta).
    Cos,
    /// sin(theta).
    Sin,
    /// Irwin's (sin^2 phi + r^2 cos^2 phi)^(1/4) (Irwin 1962) for an ellipse of axis ratio
    /// r = b/a with its major axis along theta = 0, phi the parametric angle:
    /// tan(phi) = tan(theta) / r.
    Ellipse(f64),
}

/// A reference that varies along a front with the angle about its centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Along {
    /// The variation.
    pub shape: Shape,
    /// Unit direction of theta = 0.
    pub zero: [f64; 3],
    /// Unit direction of theta = 90 degrees (normal x zero).
    pub quarter: [f64; 3],
}

impl Along {
    /// The reference's factor at each of `points`: cos or sin of the angle about their mean.
    pub fn factors(&self, points: &[[f64; 3]]) -> Vec<f64> {
        let n = points.len().max(1) as f64;
        let c: [f64; 3] = [0, 1, 2].map(|a| points.iter().map(|p| p[a]).sum::<f64>() / n);
        let dot = |u: [f64; 3], p: &[f64; 3]| (0..3).map(|a| u[a] * (p[a] - c[a])).sum::<f64>();
        points
            .iter()
            .map(|p| {
                let (v, u) = (dot(self.quarter, p), dot(self.zero, p));
                let t = v.atan2(u);
                match self.shape {
                    Shape::Cos => t.cos(),
                    Shape::Sin => t.sin(),
                    Shape::Ellipse(r) => {
                        let phi = v.atan2(u * r);
                        (phi.sin().powi(2) + r * r * phi.cos().powi(2)).powf(0.25)
                    }
                }
            })
            .collect()
    }
}

/// What an expect measures.
#[derive(Clone, Debug)]
pub enum Measure {
    /// Last sample of a probe, or its last sample at or before time `at` (s).
    Final {
        /// The probe.
        probe: usize,
        /// The time, if not the end.
        at: Option<f64>,
    },
    /// Largest sample of a probe.
    Max(usize),
    /// Smallest sample of a probe.
    Min(usize),
    /// Frequency of a probe's oscillation about its mean (Hz), from upward mean crossings.
    Frequency(usize),
    /// Distance between two probes over the difference of their arrival times (m/s); a
    /// probe's arrival is when its change first reaches half its plateau (the mean change
    /// over the last tenth of the run), which is insensitive to the overshoot at a front.
    WaveSpeed(usize, usize),
    /// The change of one probe over the change of another, from time `from` to the end
    /// (e.g. an unloading modulus: the change of stress over that of strain).
    Slope {
        /// The probe in the numerator.
        rise: usize,
        /// The probe in the denominator.
        run: usize,
        /// Start of the window (s).
        from: f64,
    },
    /// Largest |P(t) - P(0)| over the largest sum |m v| (relative).
    MomentumDrift,
    /// The energy balance: [`energy_balance`].
    EnergyDrift,
    /// |L(end) - L(0)| / |L(0)| about the initial centre of mass (relative).
    AngularMomentumDrift,
    /// The largest kinetic energy over the strain energy from time `from` on: whether a
    /// damped run has come to rest.
    KineticFraction {
        /// Start of the window (s).
        from: f64,
    },
    /// A value at a crack tip, the last one or at a time: `qty` 0..4 = K_I, K_II, J_x, J_y
    /// (Pa sqrt(m), J/m^2).
    Tip {
        /// Crack index.
        crack: u32,
        /// 0 start, 1 end.
        tip: u32,
        /// Which value.
        qty: usize,
        /// Time (s): interpolated linearly between the rows around it; None for the last row.
        at: Option<f64>,
    },
    /// A value along a 3D crack front at the last measurement (`qty` 0..4 = K_I, K_II,
    /// K_III, J_1): over the front's vertices (or at the one `near` a point), the one
    /// farthest from the reference there, given as `reference` plus that difference (so
    /// that the error is the difference over |reference|, the amplitude when the reference
    /// varies `along` the front).
    Front {
        /// Crack index.
        crack: u32,
        /// Which value.
        qty: usize,
        /// The reference the values are compared with.
        reference: f64,
        /// How the reference varies along the front, if it does.
        along: Option<Along>,
        /// Only the vertex nearest this point (m), if given.
        near: Option<[f64; 3]>,
    },
    /// How far K at a crack tip moves once settled: the largest |K(t) - K(end)| over the
    /// rows from `from` on, relative to |K(end)| (K as the vector (K_I, K_II)).
    KDrift {
        /// Crack index.
        crack: u32,
        /// 0 start, 1 end.
        tip: u32,
        /// Start of the window (s).
        from: f64,
    },
    /// The interaction integral's energy release rate against J at a 2D tip at rest: the
    /// largest |G_int(t) - J(t).t| over the largest |J(t).t| from `from` on, with G_int =
    /// (K_I^2 + K_II^2) / E' (Irwin 1957) and t the tip's unit direction (its end segment as
    /// given). The two are independent estimates of one G: their gap shows their
    /// discretisation errors together.
    GInteraction {
        /// Crack index.
        crack: u32,
        /// 0 start, 1 end.
        tip: u32,
        /// Start of the window (s).
        from: f64,
        /// E' of the material at the tip (Pa).
        modulus: f64,
        /// The tip's unit direction.
        direction: [f64; 2],
    },
    /// |J| at a 2D crack tip (last row) against the eta estimate from a load and a
    /// displacement probe: (|J| - J_eta) / J_eta.
    JEta {
        /// Crack index.
        crack: u32,
        /// 0 start, 1 end.
        tip: u32,
        /// The load probe (N).
        load: usize,
        /// The displacement probe (m), the load's work-conjugate.
        displacement: usize,
        /// The specimen's estimate.
        estimate: EtaEstimate,
    },
    /// A growing tip's path or fatigue life, from its growth rows.
    Growth {
        /// Crack index.
        crack: u32,
        /// 0 start, 1 end.
        tip: u32,
        /// What is read.
        qty: GrowthQty,
    },
    /// Path dependence of J with the area (3D: volume) term at a crack tip: the largest
    /// [`path_difference`] of the compared contours against the main one; along a 3D front
    /// the largest over its vertices, or at the one `near` a point.
    PathDifference {
        /// Crack index.
        crack: u32,
        /// 2D: 0 start, 1 end; None along a 3D front.
        tip: Option<u32>,
        /// 3D: only the front vertex nearest this point (m), if given.
        near: Option<[f64; 3]>,
        /// Main contour size (cells).
        main: u32,
        /// Compared contour sizes (cells).
        compare: Vec<u32>,
        /// Start of the window (s).
        from: f64,
    },
}

/// What a growth expect reads from a tip's growth rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GrowthQty {
    /// The first new segment's turn from the crack's last segment (degrees); along a 3D
    /// front, its largest turn at the first check.
    Kink,
    /// The path's line over the last quarter of the length grown (the chord between the
    /// tip positions there, smoother than one segment), as an angle to x in (-90, 90]
    /// degrees.
    PathAngle,
    /// The chord from where the tip started to its last new vertex, as a turn from the
    /// crack's direction there (degrees, counterclockwise, in (-180, 180]).
    Turn,
    /// Fatigue: load cycles to grow by this length (m), interpolated linearly between rows.
    Cycles(f64),
}

/// A checked expectation.
#[derive(Clone, Debug)]
pub struct Expect {
    /// Quantity keyword from the scenario.
    pub quantity: String,
    /// Probes named.
    pub probes: Vec<String>,
    /// Measurement.
    pub measure: Measure,
    /// Reference value.
    pub reference: f64,
    /// Source of the reference.
    pub source: String,
    /// Tolerance (relative, or absolute for a zero reference).
    pub tolerance: f64,
}

/// Outcome of one expect, as written to summary.json.
#[derive(Clone, Debug, Serialize)]
pub struct ExpectResult {
    /// Quantity keyword.
    pub quantity: String,
    /// Probes named.
    pub probes: Vec<String>,
    /// Reference value.
    pub reference: f64,
    /// Measured value (null when it could not be measured).
    pub value: Option<f64>,
    /// Error: relative, or absolute for a zero reference.
    pub error: Option<f64>,
    /// Tolerance.
    pub tolerance: f64,
    /// Whether the error is within tolerance.
    pub pass: bool,
    /// Source of the reference.
    pub source: String,
}

impl Expect {
    /// Measures and compares.
    pub fn evaluate(&self, h: &History, probes: &[Probe]) -> ExpectResult {
        let value = measure(&self.measure, h, probes);
        let error = value.map(|v| {
            if self.reference == 0.0 {
                (v - self.reference).abs()
            } else {
                ((v - self.reference) / self.reference).abs()
            }
        });
        ExpectResult {
            quantity: self.quantity.clone(),
            probes: self.probes.clone(),
            reference: self.reference,
            value,
            error,
            tolerance: self.tolerance,
            pass: error.is_some_and(|e| e <= self.tolerance),
            source: self.source.clone(),
        }
    }
}

/// The value an expect measures in the history, None where it has none (or a non-finite
/// one).
fn measure(m: &Measure, h: &History, probes: &[Probe]) -> Option<f64> {
    match *m {
        Measure::Final { probe, at } => {
            let samples = &h.probes[probe];
            let k = at.map_or(samples.len(), |t| h.time.partition_point(|&s| s <= t));
            samples[..k].last().copied().and_then(finite)
        }
        Measure::Tip {
            crack,
            tip,
            qty,
            at,
        } => tip_value(h, crack, tip, qty, at),
        Measure::Front {
            crack,
            qty,
            reference,
            along,
            near,
        } => front_value(h, crack, qty, reference, along, near),
        Measure::JEta {
            crack,
            tip,
            load,
            displacement,
            estimate,
        } => {
            let last = (h.fracture.iter()).rfind(|r| r.crack == crack && r.tip == tip)?;
            let j = last.j[0].hypot(last.j[1]);
            let eta = estimate.j(&h.probes[load], &h.probes[displacement])?;
            finite((j - eta) / eta)
        }
        Measure::KDrift { crack, tip, from } => {
            let rows: Vec<&TipResult> = h
                .fracture
                .iter()
                .filter(|r| r.crack == crack && r.tip == tip && r.time >= from)
                .collect();
            let last = rows.last()?.k;
            let worst = rows
                .iter()
                .map(|r| (r.k[0] - last[0]).hypot(r.k[1] - last[1]))
                .fold(0.0, f64::max);
            finite(worst / last[0].hypot(last[1]))
        }
        Measure::GInteraction {
            crack,
            tip,
            from,
            modulus,
            direction,
        } => g_interaction(h, crack, tip, from, modulus, direction),
        Measure::PathDifference {
            crack,
            tip,
            near,
            main,
            ref compare,
            from,
        } => path_value(h, crack, tip, near, main, compare, from),
        Measure::Growth { crack, tip, qty } => growth_value(h, crack, tip, qty),
        Measure::Max(p) => h.probes[p].iter().copied().reduce(f64::max),
        Measure::Min(p) => h.probes[p].iter().copied().reduce(f64::min),
        Measure::Frequency(p) => frequency(&h.time, &h.probes[p]),
        Measure::WaveSpeed(a, b) => {
            let ta = arrival(&h.time, &h.probes[a])?;
            let tb = arrival(&h.time, &h.probes[b])?;
            let (ca, cb) = (probes[a].centre, probes[b].centre);
            let d = (0..3).map(|k| (cb[k] - ca[k]).powi(2)).sum::<f64>().sqrt();
            finite(d / (tb - ta))
        }
        Measure::Slope { rise, run, from } => {
            let k = h.time.iter().position(|&t| t >= from)?;
            let change = |p: usize| Some(h.probes[p].last()? - h.probes[p][k]);
            finite(change(rise)? / change(run)?)
        }
        Measure::MomentumDrift => {
            let first = h.rows.first()?;
            let scale = h.rows.iter().map(|r| r.momentum_scale).fold(0.0, f64::max);
            let worst = h
                .rows
                .iter()
                .map(|r| (DVec3::from(r.momentum) - DVec3::from(first.momentum)).length())
                .fold(0.0, f64::max);
            finite(worst / scale)
        }
        Measure::EnergyDrift => energy_balance(h).and_then(finite),
        Measure::KineticFraction { from } => h
            .rows
            .iter()
            .filter(|r| r.time >= from)
            .map(|r| r.energies.kinetic / r.energies.strain)
            .reduce(f64::max)
            .and_then(finite),
        Measure::AngularMomentumDrift => {
            let (first, last) = (h.rows.first()?, h.rows.last()?);
            let (l0, l1) = (DVec3::from(first.angular), DVec3::from(last.angular));
            finite((l1 - l0).length() / l0.length())
        }
    }
}

/// `v` if finite.
fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// [`Measure::GInteraction`]: the worst gap between the interaction integral's G and J
/// along the tip over the rows from `from` on, relative to J's largest; None without rows
/// or where a K is missing (no interaction domain fitted).
fn g_interaction(
    h: &History,
    crack: u32,
    tip: u32,
    from: f64,
    modulus: f64,
    t: [f64; 2],
) -> Option<f64> {
    let rows = (h.fracture.iter()).filter(|r| r.crack == crack && r.tip == tip && r.time >= from);
    let (mut worst, mut scale) = (0.0_f64, 0.0_f64);
    for r in rows {
        let [k1, k2, _] = r.k_interaction;
        let g = (k1 * k1 + k2 * k2) / modulus;
        let j = r.j[0] * t[0] + r.j[1] * t[1];
        worst = worst.max(finite((g - j).abs())?);
        scale = scale.max(j.abs());
    }
    finite(worst / scale)
}

/// K_I, K_II, J_x or J_y (`qty` 0..4) at a 2D tip: the last value, or at time `at`
/// (interpolated between the rows around it).
fn tip_value(h: &History, crack: u32, tip: u32, qty: usize, at: Option<f64>) -> Option<f64> {
    let value = |r: &TipResult| [r.k[0], r.k[1], r.j[0], r.j[1]][qty];
    let mut rows = h
        .fracture
        .iter()
        .filter(|r| r.crack == crack && r.tip == tip);
    let Some(t) = at else {
        return finite(value(rows.next_back()?));
    };
    let rows: Vec<&TipResult> = rows.collect();
    let k = rows.iter().position(|r| r.time >= t)?;
    if k == 0 {
        return (rows[0].time == t).then(|| value(rows[0])).and_then(finite);
    }
    let (a, b) = (rows[k - 1], rows[k]);
    let w = (t - a.time) / (b.time - a.time);
    finite(value(a) + w * (value(b) - value(a)))
}

/// K_I, K_II, K_III or J (`qty` 0..4) along a 3D front at the last measurement: the value
/// farthest from its reference (`reference` times the `along` shape) over the vertices, or
/// at the vertex nearest `near`.
fn front_value(
    h: &History,
    crack: u32,
    qty: usize,
    reference: f64,
    along: Option<Along>,
    near: Option<[f64; 3]>,
) -> Option<f64> {
    let rows = last_rows(h, crack)?;
    let factors = match along {
        Some(a) => a.factors(&rows.iter().map(|r| r.x).collect::<Vec<_>>()),
        None => vec![1.0; rows.len()],
    };
    let nearest = near.map(|p| nearest_row(&rows, p));
    rows.iter()
        .zip(factors)
        .enumerate()
        .filter(|(k, _)| nearest.is_none_or(|n| n == Some(*k)))
        .map(|(_, rf)| rf)
        .map(|(r, f)| [r.k[0], r.k[1], r.k[2], r.j[0]][qty] - reference * f)
        .try_fold(0.0, |worst: f64, d| {
            let d = finite(d)?;
            Some(if d.abs() > worst.abs() { d } else { worst })
        })
        .map(|d| reference + d)
}

/// The largest path difference of J between the main contour and the compared ones, at
/// a tip, at the front vertex nearest `near`, or over every tip.
fn path_value(
    h: &History,
    crack: u32,
    tip: Option<u32>,
    near: Option<[f64; 3]>,
    main: u32,
    compare: &[u32],
    from: f64,
) -> Option<f64> {
    let tips: Vec<u32> = match (tip, near) {
        (Some(t), _) => vec![t],
        (None, Some(p)) => {
            let rows = last_rows(h, crack)?;
            vec![rows[nearest_row(&rows, p)?].tip]
        }
        (None, None) => path_tips(h, crack),
    };
    (tips.iter())
        .flat_map(|&t| compare.iter().map(move |&n| (t, n)))
        .map(|(t, n)| path_difference(h, crack, t, main, n, from, true))
        .try_fold(None, |worst: Option<f64>, d| {
            d.map(|d| Some(worst.map_or(d, |w| w.max(d))))
        })
        .flatten()
        .and_then(finite)
}

/// A growing tip's kink, path angle, turn or cycles to a length (degrees, cycles).
fn growth_value(h: &History, crack: u32, tip: u32, qty: GrowthQty) -> Option<f64> {
    let rows: Vec<&GrowthRow> = (h.growth.iter())
        .filter(|g| g.crack == crack && g.tip == tip)
        .collect();
    match qty {
        GrowthQty::Kink => finite(rows.first()?.kink.to_degrees()),
        GrowthQty::PathAngle => {
            let last = rows.last()?;
            let from = rows.iter().find(|g| g.grown >= 0.75 * last.grown)?;
            let (dx, dy) = (last.x[0] - from.x[0], last.x[1] - from.x[1]);
            let a = if from.step == last.step {
                last.heading.to_degrees()
            } else {
                dy.atan2(dx).to_degrees()
            };
            finite(a - 180.0 * ((a + 90.0) / 180.0).ceil() + 180.0)
        }
        GrowthQty::Turn => {
            let (first, last) = (rows.first()?, rows.last()?);
            let chord = (last.x[1] - first.x[1]).atan2(last.x[0] - first.x[0]);
            let turn = (chord - (first.heading - first.kink)).to_degrees();
            finite(turn - 360.0 * ((turn + 180.0) / 360.0).ceil() + 360.0)
        }
        GrowthQty::Cycles(length) => {
            // The lengths are sums of extensions: allow for their rounding.
            let k = rows.iter().position(|g| g.grown >= length * (1.0 - 1e-9))?;
            let (a, b) = (rows[k.checked_sub(1)?], rows[k]);
            let w = (length - a.grown) / (b.grown - a.grown);
            finite(a.fatigue[1] + w * (b.fatigue[1] - a.fatigue[1]))
        }
    }
}

/// The index of the row nearest point `p` (the first of equals); None without rows.
fn nearest_row(rows: &[&TipResult], p: [f64; 3]) -> Option<usize> {
    let d2 = |k: usize| (0..3).map(|a| (rows[k].x[a] - p[a]).powi(2)).sum::<f64>();
    (0..rows.len()).min_by(|&a, &b| d2(a).total_cmp(&d2(b)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fracture::plan::PathResult;

    /// `final` at a time reads the last sample at or before it; before the first sample
    /// there is none.
    #[test]
    fn final_at_a_time_reads_the_sample_then() {
        let h = History {
            time: vec![0.0, 1.0, 2.0, 3.0],
            probes: vec![vec![10.0, 11.0, 12.0, 13.0]],
            ..History::default()
        };
        let at = |at| measure(&Measure::Final { probe: 0, at }, &h, &[]);
        assert_eq!(at(None), Some(13.0));
        assert_eq!(at(Some(2.0)), Some(12.0));
        assert_eq!(at(Some(2.5)), Some(12.0));
        assert_eq!(at(Some(-1.0)), None);
    }

    /// `G_interaction` at a tip pointing 30 degrees up: the J vector has G along the tip and
    /// an arbitrary part across it; K whose (K_I^2 + K_II^2)/E' is G except one row 2 %
    /// high reads that gap over the largest G. A row before `from` (50 % off) does not
    /// count; a row without interaction K leaves no value.
    #[test]
    fn g_interaction_reads_the_worst_gap_along_the_tip() {
        let (modulus, t) = (2.0e11, [0.75f64.sqrt(), 0.5]);
        let mut h = History::default();
        let mut g_at = Vec::new();
        for step in 0..5u64 {
            let g = 40.0 * (step + 1) as f64;
            let off = [1.5, 1.0, 1.0, 1.02, 1.0][step as usize];
            let k2 = -4.0e5_f64;
            let k1 = (off * g * modulus - k2 * k2).sqrt();
            let across = 0.7 * g;
            h.fracture.push(TipResult {
                step,
                time: step as f64,
                j: [g * t[0] - across * t[1], g * t[1] + across * t[0]],
                k_interaction: [k1, k2, 0.0],
                tip: 1,
                ..TipResult::default()
            });
            g_at.push(g);
        }
        let m = Measure::GInteraction {
            crack: 0,
            tip: 1,
            from: 0.5,
            modulus,
            direction: t,
        };
        let got = measure(&m, &h, &[]).unwrap();
        let want = 0.02 * g_at[3] / g_at[4];
        assert!((got - want).abs() < 1e-9, "{got} against {want}");
        h.fracture[2].k_interaction = [f64::NAN, f64::NAN, 0.0];
        assert_eq!(measure(&m, &h, &[]), None);
    }

    /// J_path at a mixed-mode tip compares G = J . t: two contours with the same G and
    /// different J across the tip (which a contour leaves path dependent) read 0, a G 3 %
    /// off reads 3 %; along a 3D front (direction (1, 0), J2 NaN) J1 alone is compared.
    #[test]
    fn j_path_compares_j_along_the_tip() {
        let t = [0.6, -0.8];
        let row = |contour, g: f64, across: f64, direction: [f64; 2]| PathResult {
            step: 1,
            time: 1.0,
            crack: 0,
            tip: 1,
            contour,
            line: [g * t[0] - across * t[1], g * t[1] + across * t[0]],
            area: [0.0; 2],
            direction,
        };
        let m = Measure::PathDifference {
            crack: 0,
            tip: Some(1),
            near: None,
            main: 2,
            compare: vec![4],
            from: 0.0,
        };
        let h = |a: PathResult, b: PathResult| History {
            paths: vec![a, b],
            ..History::default()
        };
        let same = h(row(2, 100.0, 50.0, t), row(4, 100.0, -80.0, t));
        assert!(measure(&m, &same, &[]).unwrap().abs() < 1e-12);
        let off = h(row(2, 100.0, 50.0, t), row(4, 103.0, 50.0, t));
        assert!((measure(&m, &off, &[]).unwrap() - 0.03).abs() < 1e-12);
        let (mut a, mut b) = (row(2, 0.0, 0.0, [1.0, 0.0]), row(4, 0.0, 0.0, [1.0, 0.0]));
        (a.line, b.line) = ([10.0, f64::NAN], [10.5, f64::NAN]);
        assert!((measure(&m, &h(a, b), &[]).unwrap() - 0.05).abs() < 1e-12);
    }

    /// A front expect with a reference varying as cos(theta) about a ring's centre reads
    /// the reference plus the largest departure from it, at whichever vertex that is, or at
    /// the vertex nearest a point, and only the last measurement counts.
    #[test]
    fn front_measure_takes_the_worst_vertex_against_the_curve() {
        use std::f64::consts::PI;
        let along = Along {
            shape: Shape::Cos,
            zero: [0.0, 0.0, 1.0],
            quarter: [1.0, 0.0, 0.0],
        };
        let (amp, centre) = (2.0e6, [0.3, -0.1, 0.2]);
        let mut h = History::default();
        for (step, dev) in [(1, 5.0e5), (2, 3.0e4)] {
            for k in 0..12u32 {
                let t = f64::from(k) * PI / 6.0;
                let x = [
                    centre[0] + 0.01 * t.sin(),
                    centre[1],
                    centre[2] + 0.01 * t.cos(),
                ];
                let off = if k == 7 { -dev } else { 0.1 * dev };
                h.fracture.push(TipResult {
                    step,
                    crack: 0,
                    tip: k,
                    x,
                    k: [0.0, amp * t.cos() + off, 0.0],
                    ..TipResult::default()
                });
            }
        }
        let mut m = Measure::Front {
            crack: 0,
            qty: 1,
            reference: amp,
            along: Some(along),
            near: None,
        };
        let got = measure(&m, &h, &[]).unwrap();
        assert!((got - (amp - 3.0e4)).abs() < 1e-6, "{got}");
        let Measure::Front { near, .. } = &mut m else {
            unreachable!()
        };
        *near = Some([centre[0] + 0.011, centre[1], centre[2] + 0.001]);
        let got = measure(&m, &h, &[]).unwrap();
        assert!((got - (amp + 3.0e3)).abs() < 1e-6, "vertex 3 alone: {got}");
        let factors = along.factors(&h.fracture[..12].iter().map(|r| r.x).collect::<Vec<_>>());
        assert!((factors[2] - 0.5).abs() < 1e-12 && (factors[6] + 1.0).abs() < 1e-12);
    }

    /// On an ellipse of semi-axes a (along `zero`) and b, the ellipse shape at the point of
    /// parametric angle phi is Irwin's (sin^2 phi + (b/a)^2 cos^2 phi)^(1/4).
    #[test]
    fn ellipse_shape_is_irwins() {
        let (a, b) = (0.035, 0.02);
        let along = Along {
            shape: Shape::Ellipse(b / a),
            zero: [1.0, 0.0, 0.0],
            quarter: [0.0, 0.0, 1.0],
        };
        let phis: Vec<f64> = (0..24)
            .map(|k| f64::from(k) * std::f64::consts::PI / 12.0)
            .collect();
        let pts: Vec<[f64; 3]> = phis
            .iter()
            .map(|p| [a * p.cos(), 0.1, b * p.sin()])
            .collect();
        for (f, p) in along.factors(&pts).iter().zip(&phis) {
            let want = (p.sin().powi(2) + (b / a).powi(2) * p.cos().powi(2)).powf(0.25);
            assert!((f - want).abs() < 1e-12, "phi {p}: {f} vs {want}");
        }
    }

    #[test]
    fn frequency_of_a_sampled_sine() {
        let t: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-4).collect();
        let s: Vec<f64> = t
            .iter()
            .map(|t| (2.0 * std::f64::consts::PI * 37.0 * t).sin() + 3.0)
            .collect();
        let f = frequency(&t, &s).unwrap();
        assert!((f - 37.0).abs() < 0.05, "{f}");
    }

    #[test]
    fn arrival_of_a_ramp_front() {
        let t: Vec<f64> = (0..100).map(|i| i as f64).collect();
        let s: Vec<f64> = t
            .iter()
            .map(|&t: &f64| ((t - 40.0) / 10.0).clamp(0.0, 1.0))
            .collect();
        assert!((arrival(&t, &s).unwrap() - 45.0).abs() < 1e-12);
    }
}
