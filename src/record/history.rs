//! What a run records (probe samples, energy rows, J and K, paths, growth) and the
//! analyses of it the expects and reports share: the energy balance, frequencies,
//! arrival times, path differences of J.

use crate::fracture::plan::{PathResult, TipResult};
use crate::physics::growth::GrowthRow;
use crate::record::solve_log::SolveRow;
use crate::store::world::Energies;
use std::collections::HashMap;

/// A history row taken at the energy cadence.
#[derive(Clone, Copy, Debug)]
pub struct Row {
    /// Step.
    pub step: u64,
    /// Time (s).
    pub time: f64,
    /// Energies (J).
    pub energies: Energies,
    /// Total momentum (kg m/s).
    pub momentum: [f64; 3],
    /// Sum of |m v| (kg m/s), the scale of momentum errors.
    pub momentum_scale: f64,
    /// Angular momentum about the initial centre of mass (kg m^2/s).
    pub angular: [f64; 3],
}

/// Everything recorded over a run that expects are measured on.
#[derive(Clone, Debug, Default)]
pub struct History {
    /// Time of every step's probe sample (s).
    pub time: Vec<f64>,
    /// Probe samples, one series per probe.
    pub probes: Vec<Vec<f64>>,
    /// Rows at the energy cadence.
    pub rows: Vec<Row>,
    /// J and K at every crack tip, at the energy cadence.
    pub fracture: Vec<TipResult>,
    /// J on the compared contours, at the energy cadence.
    pub paths: Vec<PathResult>,
    /// The growing tips' new segments.
    pub growth: Vec<GrowthRow>,
    /// A static scene's load steps: what each one's solves took.
    pub solves: Vec<SolveRow>,
}

/// How far the energy balance E = K + W + W_p - W_ext + W_damp + W_f strays from its start:
/// the largest |E(t) - E(0)| over the largest of K + W + W_p, |W_ext|, W_damp and W_f in the
/// run.
pub fn energy_balance(h: &History) -> Option<f64> {
    let drift = balance_drift(h)?;
    // NaN (a run with no energy at all) stays NaN, as a failed measurement.
    Some(drift.iter().map(|(_, d)| d.abs()).fold(0.0, |m: f64, d| {
        if m.is_nan() || d.is_nan() {
            f64::NAN
        } else {
            m.max(d)
        }
    }))
}

/// The energy balance's drift over time: (t, (E(t) - E(0)) / scale), with the scale of
/// [`energy_balance`]; None without rows.
pub fn balance_drift(h: &History) -> Option<Vec<(f64, f64)>> {
    let e0 = h.rows.first()?.energies.balance();
    let scale = (h.rows.iter())
        .map(|r| {
            let e = &r.energies;
            (e.internal())
                .max(e.external_work.abs())
                .max(e.damping_work)
                .max(e.friction_work)
        })
        .fold(0.0, f64::max);
    Some(
        (h.rows.iter())
            .map(|r| (r.time, (r.energies.balance() - e0) / scale))
            .collect(),
    )
}

/// Mean frequency from upward crossings of the series' mean (linear interpolation).
pub fn frequency(t: &[f64], s: &[f64]) -> Option<f64> {
    let mean = s.iter().sum::<f64>() / s.len() as f64;
    let crossings: Vec<f64> = (1..s.len())
        .filter(|&i| s[i - 1] < mean && s[i] >= mean)
        .map(|i| {
            let f = (mean - s[i - 1]) / (s[i] - s[i - 1]);
            t[i - 1] + f * (t[i] - t[i - 1])
        })
        .collect();
    if crossings.len() < 2 {
        return None;
    }
    Some((crossings.len() - 1) as f64 / (crossings[crossings.len() - 1] - crossings[0]))
}

/// The tips (3D: front vertices) of a crack that J was compared at, in order.
pub fn path_tips(h: &History, crack: u32) -> Vec<u32> {
    let mut t: Vec<u32> = (h.paths.iter())
        .filter(|p| p.crack == crack)
        .map(|p| p.tip)
        .collect();
    t.sort_unstable();
    t.dedup();
    t
}

/// A crack's rows of the last fracture measurement (one per tip or front vertex); None
/// without any.
pub fn last_rows(h: &History, crack: u32) -> Option<Vec<&TipResult>> {
    let rows = h.fracture.iter().filter(|r| r.crack == crack);
    let last = rows.clone().map(|r| r.step).max()?;
    Some(rows.filter(|r| r.step == last).collect())
}

/// First time the change from the initial value reaches half of its plateau, the mean
/// change over the last tenth of the samples (linear interpolation between samples).
pub fn arrival(t: &[f64], s: &[f64]) -> Option<f64> {
    let s0 = *s.first()?;
    let tail = &s[s.len() - (s.len() / 10).max(1)..];
    let plateau = tail.iter().map(|v| v - s0).sum::<f64>() / tail.len() as f64;
    if plateau == 0.0 || !plateau.is_finite() {
        return None;
    }
    let half = 0.5 * plateau.abs();
    let rise = |v: f64| (v - s0) * plateau.signum();
    let i = s.iter().position(|&v| rise(v) >= half)?;
    if i == 0 {
        return Some(t[0]);
    }
    let (a, b) = (rise(s[i - 1]), rise(s[i]));
    Some(t[i - 1] + (half - a) / (b - a) * (t[i] - t[i - 1]))
}

/// How far J on contour `n` is from J on contour `main` at a crack tip, over the rows from
/// time `from` on: max |J_n - J_main| / max |J_main|, with or without the area term. In 2D
/// J is compared along the tip's direction at each row (G = J . t, path independent; J_2
/// is not in mixed mode, where it needs the integral along the crack faces that a contour
/// leaves out); along a 3D front J1 alone (J2 is not measured). None without rows for both
/// contours, or where J1 is NaN (a tube that does not fit).
pub fn path_difference(
    h: &History,
    crack: u32,
    tip: u32,
    main: u32,
    n: u32,
    from: f64,
    area: bool,
) -> Option<f64> {
    let j = |p: &PathResult| p.along_tip(area);
    let rows = || {
        h.paths
            .iter()
            .filter(move |p| p.crack == crack && p.tip == tip && p.time >= from)
    };
    let other: HashMap<u64, &PathResult> = rows()
        .filter(|p| p.contour == n)
        .map(|p| (p.step, p))
        .collect();
    let (mut diff, mut size, mut pairs) = (0.0f64, 0.0f64, 0);
    for m in rows().filter(|p| p.contour == main) {
        let Some(o) = other.get(&m.step) else {
            continue;
        };
        let (a, b) = (j(m), j(o));
        if a.is_nan() || b.is_nan() {
            return None;
        }
        diff = diff.max((b - a).abs());
        size = size.max(a.abs());
        pairs += 1;
    }
    (pairs > 0 && size > 0.0).then(|| diff / size)
}
