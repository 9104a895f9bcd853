//! Time functions that scale loads and prescribed velocities.

use serde::{Deserialize, Serialize};

/// A dimensionless multiplier f(t) applied to a load or a prescribed velocity.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum TimeFn {
    /// f = 1 at all times (a struct variant, so that a stray key beside it is refused as
    /// in the other kinds).
    Constant {},
    /// Heaviside step: f = 0 before `start` (s), 1 after.
    Step {
        /// Switch-on time (s).
        #[serde(default)]
        start: f64,
    },
    /// Linear rise from 0 at `start` to 1 at `start + rise` (s), then 1.
    Ramp {
        /// Start time (s).
        #[serde(default)]
        start: f64,
        /// Rise time (s), > 0.
        rise: f64,
    },
    /// Rectangular pulse: f = 1 for `start <= t < start + width` (s), else 0.
    Pulse {
        /// Start time (s).
        #[serde(default)]
        start: f64,
        /// Duration (s), > 0.
        width: f64,
    },
    /// Piecewise linear through `points` = [[t, f], ...] (s, -), times increasing; f is
    /// held at the first value before the first time and at the last after the last.
    /// Loading and unloading cycles are tables.
    Table {
        /// The (time, value) corners.
        points: Vec<[f64; 2]>,
    },
}

impl Default for TimeFn {
    fn default() -> Self {
        TimeFn::Constant {}
    }
}

impl TimeFn {
    /// Value at time `t` (s).
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            TimeFn::Constant {} => 1.0,
            TimeFn::Step { start } => (t >= start) as u8 as f64,
            TimeFn::Ramp { start, rise } => ((t - start) / rise).clamp(0.0, 1.0),
            TimeFn::Pulse { start, width } => (t >= start && t < start + width) as u8 as f64,
            TimeFn::Table { ref points } => {
                let k = points.partition_point(|p| p[0] <= t);
                match (k.checked_sub(1).map(|j| points[j]), points.get(k)) {
                    (Some(a), Some(b)) => a[1] + (b[1] - a[1]) * (t - a[0]) / (b[0] - a[0]),
                    (Some(a), None) => a[1],
                    (None, Some(b)) => b[1],
                    (None, None) => 0.0,
                }
            }
        }
    }

    /// The integral of f from 0 to `t` (s): the displacement per unit of velocity that a
    /// velocity scaled by f prescribes by time `t` (a static scene's grips).
    pub fn integral(&self, t: f64) -> f64 {
        self.antiderivative(t) - self.antiderivative(0.0)
    }

    /// An antiderivative of f, exact for each kind (f is piecewise constant or linear).
    fn antiderivative(&self, t: f64) -> f64 {
        match *self {
            TimeFn::Constant {} => t,
            TimeFn::Step { start } => (t - start).max(0.0),
            TimeFn::Ramp { start, rise } => {
                let s = (t - start).max(0.0);
                if s < rise {
                    s * s / (2.0 * rise)
                } else {
                    s - 0.5 * rise
                }
            }
            TimeFn::Pulse { start, width } => (t - start).clamp(0.0, width),
            TimeFn::Table { ref points } => {
                let Some(&[t0, f0]) = points.first() else {
                    return 0.0;
                };
                if t <= t0 {
                    return f0 * (t - t0);
                }
                let mut area = 0.0;
                for w in points.windows(2) {
                    let ([a, fa], [b, fb]) = (w[0], w[1]);
                    if t <= b {
                        return area + 0.5 * (t - a) * (fa + self.at(t));
                    }
                    area += 0.5 * (b - a) * (fa + fb);
                }
                let [tn, fn_] = points[points.len() - 1];
                area + fn_ * (t - tn)
            }
        }
    }

    /// A problem with the parameters, if any.
    pub fn check(&self) -> Option<&'static str> {
        match *self {
            TimeFn::Step { start } | TimeFn::Ramp { start, .. } | TimeFn::Pulse { start, .. }
                if !start.is_finite() =>
            {
                Some("the start time must be a finite number (s)")
            }
            TimeFn::Ramp { rise, .. } if !rise.is_finite() || rise <= 0.0 => {
                Some("ramp rise time must be > 0 s")
            }
            TimeFn::Pulse { width, .. } if !width.is_finite() || width <= 0.0 => {
                Some("pulse width must be > 0 s")
            }
            TimeFn::Table { ref points } if points.is_empty() => {
                Some("a table needs at least one [time, value] point")
            }
            TimeFn::Table { ref points }
                if points.iter().flatten().any(|v| !v.is_finite())
                    || points.windows(2).any(|w| w[1][0] <= w[0][0]) =>
            {
                Some("table points must be finite with strictly increasing times")
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::TimeFn;

    /// Each kind's integral from 0 matches a fine midpoint sum of its values, before,
    /// inside and after its features, to the sum's own error: at most the sum's step h
    /// (under 7e-6 here) per unit jump.
    #[test]
    fn integrals_match_midpoint_sums() {
        let kinds = [
            TimeFn::Constant {},
            TimeFn::Step { start: 0.3 },
            TimeFn::Ramp {
                start: 0.2,
                rise: 0.5,
            },
            TimeFn::Pulse {
                start: 0.1,
                width: 0.4,
            },
            TimeFn::Table {
                points: vec![[0.2, 0.5], [0.6, 2.0], [0.9, -1.0]],
            },
            TimeFn::Table {
                points: vec![[-1.0, 0.0], [1.0, 2.0]],
            },
        ];
        for f in &kinds {
            for t in [0.0, 0.15, 0.45, 0.75, 1.3] {
                let n = 200_000;
                let h = t / n as f64;
                let sum: f64 = (0..n).map(|k| f.at((k as f64 + 0.5) * h) * h).sum();
                let got = f.integral(t);
                assert!((got - sum).abs() <= 2.0 * h, "{f:?} at {t}: {got} vs {sum}");
            }
        }
    }

    /// A table interpolates linearly between its corners and holds its end values.
    #[test]
    fn table_interpolates_and_holds() {
        let f = TimeFn::Table {
            points: vec![[1.0, 0.0], [3.0, 2.0], [4.0, -1.0]],
        };
        assert_eq!(f.check(), None);
        for (t, v) in [
            (0.0, 0.0),
            (1.0, 0.0),
            (2.0, 1.0),
            (3.0, 2.0),
            (3.5, 0.5),
            (9.0, -1.0),
        ] {
            assert!((f.at(t) - v).abs() < 1e-15, "f({t}) = {} not {v}", f.at(t));
        }
        let back = TimeFn::Table {
            points: vec![[1.0, 0.0], [1.0, 2.0]],
        };
        assert!(back.check().is_some());
        assert!(TimeFn::Table { points: vec![] }.check().is_some());
    }
}
