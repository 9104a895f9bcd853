//! Time functions that scale loads and prescribed velocities.

use serde::{Deserialize, Serialize};

/// A dimensionless multiplier f(t) applied to a load or a prescribed velocity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum TimeFn {
    /// f = 1 at all times.
    #[default]
    Constant,
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
}

impl TimeFn {
    /// Value at time `t` (s).
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            TimeFn::Constant => 1.0,
            TimeFn::Step { start } => (t >= start) as u8 as f64,
            TimeFn::Ramp { start, rise } => ((t - start) / rise).clamp(0.0, 1.0),
            TimeFn::Pulse { start, width } => (t >= start && t < start + width) as u8 as f64,
        }
    }

    /// A problem with the parameters, if any.
    pub fn check(&self) -> Option<&'static str> {
        match *self {
            TimeFn::Ramp { rise, .. } if !rise.is_finite() || rise <= 0.0 => {
                Some("ramp rise time must be > 0 s")
            }
            TimeFn::Pulse { width, .. } if !width.is_finite() || width <= 0.0 => {
                Some("pulse width must be > 0 s")
            }
            _ => None,
        }
    }
}
