//! Crack growth: when a tip starts to grow, which way and how fast, and the state a growing
//! tip carries from step to step. The growth system (`systems/grow.rs`) applies it.

/// When a tip starts to grow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Initiation {
    /// Maximum hoop stress (Erdogan & Sih 1963): the hoop-stress intensity in the direction
    /// of its maximum, [`hoop_k`], reaches the toughness K_Ic (Pa sqrt(m)).
    Hoop {
        /// K_Ic (Pa sqrt(m)).
        k_ic: f64,
    },
    /// Griffith: the energy release rate G = J reaches G_c (J/m^2).
    Energy {
        /// G_c (J/m^2).
        g_c: f64,
    },
    /// At a set time (s), whatever the load (e.g. Freund's crack set running).
    Time {
        /// Start (s).
        at: f64,
    },
}

/// Which way a growing tip extends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Direction {
    /// On along its last segment.
    Straight,
    /// Where the hoop stress is largest (Erdogan & Sih 1963), [`hoop_angle`].
    Hoop,
}

/// A crack's growth law, from its `growth` table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Growth {
    /// When a tip starts.
    pub initiation: Initiation,
    /// Which way it goes.
    pub direction: Direction,
    /// Once started, a tip runs at this speed (m/s) whatever K does, on the heading it took
    /// at the start; None: it extends by `extension` at every check at which the
    /// criterion holds.
    pub speed: Option<f64>,
    /// Length of a new crack segment (m).
    pub extension: f64,
    /// Steps between evaluations of the criterion and the direction.
    pub check: u64,
    /// Fatigue: the Paris-Erdogan law that turns each extension into load cycles.
    pub paris: Option<Paris>,
}

impl Growth {
    /// Whether a tip or front in state `st` reads K or J at a check at time `t`: to start
    /// on a criterion, to turn by the hoop stress (at its start time on, for one started by
    /// the clock), to keep extending while its criterion holds, or (fatigue) for the growth
    /// rate.
    pub fn reads_k(&self, st: &TipState, t: f64) -> bool {
        let (criterion, due) = match self.initiation {
            Initiation::Time { at } => (false, t >= at),
            _ => (true, true),
        };
        match (st.stopped, st.started.is_nan()) {
            (0, _) if self.paris.is_some() => true,
            (0, true) => criterion || (due && self.direction == Direction::Hoop),
            (0, false) => self.speed.is_none() && (self.direction == Direction::Hoop || criterion),
            _ => false,
        }
    }
}

/// The Paris-Erdogan law da/dN = C (Delta K_eq)^m (Belytschko et al. 1995, Eq. 38), with the
/// equivalent mode I range of Eq. 40 ([`delta_k_eq`]). The run holds the cycle's largest
/// load, so K_min = R K_max (linear elasticity, proportional load).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Paris {
    /// C (m per cycle per (Pa sqrt(m))^m).
    pub c: f64,
    /// The exponent m (n in the paper).
    pub m: f64,
    /// The load ratio R = K_min / K_max, in [0, 1).
    pub r: f64,
}

impl Paris {
    /// Crack growth per cycle (m) at a tip where the largest load gives K_I and K_II, the
    /// kink angle of the growth there (maximum hoop stress, Eq. 41 of Belytschko et al.
    /// 1995, on the ranges) and Delta K_eq (Pa sqrt(m)); zero growth where Delta K_eq is
    /// not positive.
    pub fn rate(&self, k1: f64, k2: f64) -> (f64, f64, f64) {
        let (dk1, dk2) = ((1.0 - self.r) * k1, (1.0 - self.r) * k2);
        let theta = hoop_angle(dk1, dk2);
        let dk = delta_k_eq(dk1, dk2, theta);
        let rate = if dk > 0.0 {
            self.c * dk.powf(self.m)
        } else {
            0.0
        };
        (rate, theta, dk)
    }
}

/// What a tip has done so far (one per front, kept in snapshots).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TipState {
    /// Time it started to grow (s); NaN while it has not.
    pub started: f64,
    /// Length grown (m).
    pub grown: f64,
    /// Speed over the last step (m/s).
    pub speed: f64,
    /// Unit direction it runs in (2D: x, y), set when it starts and at each check.
    pub heading: [f64; 2],
    /// Why it stopped growing for good (0: it has not; see [`Stopped`]).
    pub stopped: u8,
    /// Fatigue: load cycles to the length at the last check.
    pub cycles: f64,
    /// Fatigue: da/dN at the last check (m per cycle); NaN before the first.
    pub rate: f64,
    /// Fatigue: length grown at the last check (m).
    pub checked: f64,
}

impl TipState {
    /// Numbers per tip in a snapshot.
    pub const VALUES: usize = 9;

    /// The state as numbers for a snapshot.
    pub fn values(&self) -> [f64; Self::VALUES] {
        [
            self.started,
            self.grown,
            self.speed,
            self.heading[0],
            self.heading[1],
            f64::from(self.stopped),
            self.cycles,
            self.rate,
            self.checked,
        ]
    }

    /// The state from a snapshot's numbers; None when they cannot be one.
    pub fn from_values(v: &[f64]) -> Option<TipState> {
        let stopped = v[5];
        let code = (stopped == stopped.trunc() && (0.0..=255.0).contains(&stopped))
            .then_some(stopped as u8)
            .filter(|&c| c == 0 || Stopped::from_code(c).is_some())?;
        Some(TipState {
            started: v[0],
            grown: v[1],
            speed: v[2],
            heading: [v[3], v[4]],
            stopped: code,
            cycles: v[6],
            rate: v[7],
            checked: v[8],
        })
    }
}

impl TipState {
    /// Fatigue at a check whose growth rate (m per cycle) is `rate`: the cycles from the
    /// last check's length to this one by the trapezoidal rule in the length (second order
    /// in the extension, where the forward rule would be first).
    pub fn count_cycles(&mut self, rate: f64) {
        if !self.rate.is_nan() && rate > 0.0 {
            self.cycles += (self.grown - self.checked) * 0.5 * (1.0 / self.rate + 1.0 / rate);
        }
        self.rate = rate;
        self.checked = self.grown;
    }
}

impl Default for TipState {
    fn default() -> Self {
        TipState {
            started: f64::NAN,
            grown: 0.0,
            speed: 0.0,
            heading: [0.0; 2],
            stopped: 0,
            cycles: 0.0,
            rate: f64::NAN,
            checked: 0.0,
        }
    }
}

/// Why a tip stopped growing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Stopped {
    /// It reached the body's free surface.
    Surface = 1,
    /// It reached another crack (or another part of its own).
    Crack = 2,
    /// Fatigue: Delta K_eq is not positive, so it grows no more under this load.
    Arrested = 3,
    /// Fatigue: K could not be measured at the tip (no J contour fits), so its rate is
    /// unknown.
    Unmeasured = 4,
}

impl Stopped {
    /// What happened, for summary.json and the launcher.
    pub fn describe(self) -> &'static str {
        match self {
            Stopped::Surface => "reached the free surface",
            Stopped::Crack => "reached another crack",
            Stopped::Arrested => "arrested: Delta K_eq is not positive",
            Stopped::Unmeasured => {
                "stopped: K could not be measured at the tip (no J contour fits there)"
            }
        }
    }

    /// From the stored code; None for 0 or an unknown code.
    pub fn from_code(c: u8) -> Option<Stopped> {
        match c {
            1 => Some(Stopped::Surface),
            2 => Some(Stopped::Crack),
            3 => Some(Stopped::Arrested),
            4 => Some(Stopped::Unmeasured),
            _ => None,
        }
    }
}

/// The angle (rad, from the tip's direction, counterclockwise) of the largest hoop stress
/// at a tip with K_I >= 0 and K_II (Erdogan & Sih 1963): the root of
/// K_I sin(theta) + K_II (3 cos(theta) - 1) = 0 in (-pi, pi) that maximises it,
/// theta = 2 atan((K_I - sqrt(K_I^2 + 8 K_II^2)) / (4 K_II)); 0 in pure mode I.
pub fn hoop_angle(k1: f64, k2: f64) -> f64 {
    if k2 == 0.0 {
        return 0.0;
    }
    let k1 = k1.max(0.0);
    2.0 * ((k1 - (k1 * k1 + 8.0 * k2 * k2).sqrt()) / (4.0 * k2)).atan()
}

/// The equivalent mode I range Delta K_eq = Delta K_I cos^3(theta/2) - 3 Delta K_II
/// cos^2(theta/2) sin(theta/2) at the kink angle theta (Belytschko et al. 1995, Eq. 40,
/// after Broek 1982): the hoop-stress intensity of the ranges, [`hoop_k`].
pub fn delta_k_eq(dk1: f64, dk2: f64, theta: f64) -> f64 {
    hoop_k(dk1, dk2, theta)
}

/// A growing tip's record at a check that extended it (growth.csv): where it was, what it
/// read, and, under fatigue, the cycles it took to get there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrowthRow {
    /// Step.
    pub step: u64,
    /// Time (s).
    pub time: f64,
    /// Crack index.
    pub crack: u32,
    /// 0 start, 1 end.
    pub tip: u32,
    /// Length grown before this extension (m).
    pub grown: f64,
    /// The tip before this extension (m).
    pub x: [f64; 2],
    /// K_I and K_II read at this check (NaN when the check read none).
    pub k: [f64; 2],
    /// The new segment's turn from the last one (rad, counterclockwise); for a 3D front,
    /// the largest turn of its vertices (rad, a magnitude).
    pub kink: f64,
    /// The new segment's direction (rad from x, counterclockwise).
    pub heading: f64,
    /// Fatigue: Delta K_eq (Pa sqrt(m)) and the cycles to reach `grown`; NaN otherwise.
    pub fatigue: [f64; 2],
}

impl GrowthRow {
    /// Numbers per row in a snapshot (after step, crack and tip).
    pub const VALUES: usize = 10;

    /// The row's numbers for a snapshot, in growth.csv's column order.
    pub fn values(&self) -> [f64; Self::VALUES] {
        [
            self.time,
            self.grown,
            self.x[0],
            self.x[1],
            self.k[0],
            self.k[1],
            self.kink,
            self.heading,
            self.fatigue[0],
            self.fatigue[1],
        ]
    }

    /// A row from a snapshot's numbers.
    pub fn from_values(step: u64, crack: u32, tip: u32, v: &[f64]) -> GrowthRow {
        GrowthRow {
            step,
            time: v[0],
            crack,
            tip,
            grown: v[1],
            x: [v[2], v[3]],
            k: [v[4], v[5]],
            kink: v[6],
            heading: v[7],
            fatigue: [v[8], v[9]],
        }
    }
}

/// The hoop-stress intensity sigma_theta sqrt(2 pi r) at angle `theta` from the tip
/// (Erdogan & Sih 1963): cos(theta/2) (K_I cos^2(theta/2) - 3/2 K_II sin(theta)).
pub fn hoop_k(k1: f64, k2: f64, theta: f64) -> f64 {
    let c = (0.5 * theta).cos();
    c * (k1 * c * c - 1.5 * k2 * theta.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pure mode I grows straight on at K_I; pure mode II kinks by -70.53 degrees
    /// (cos(theta) = 1/3) with a hoop intensity of 2/sqrt(3) K_II (Erdogan & Sih 1963);
    /// the angle is where the hoop stress's derivative vanishes and it is a maximum.
    #[test]
    fn hoop_angle_and_intensity() {
        assert_eq!(hoop_angle(2.0e6, 0.0), 0.0);
        assert_eq!(hoop_k(2.0e6, 0.0, 0.0), 2.0e6);
        let t = hoop_angle(0.0, 1.0e6);
        assert!(
            (t + (1.0f64 / 3.0).acos()).abs() < 1e-12,
            "{}",
            t.to_degrees()
        );
        let k = hoop_k(0.0, 1.0e6, t);
        assert!((k - 2.0 / 3f64.sqrt() * 1.0e6).abs() < 1e-6, "{k}");
        for (k1, k2) in [(1.0e6, 0.4e6), (1.0e6, -0.7e6), (0.2e6, 1.0e6)] {
            let t = hoop_angle(k1, k2);
            let d = k1 * t.sin() + k2 * (3.0 * t.cos() - 1.0);
            assert!(d.abs() < 1e-9 * k1.hypot(k2), "stationary: {d}");
            let h = 1e-4;
            assert!(hoop_k(k1, k2, t) > hoop_k(k1, k2, t + h).max(hoop_k(k1, k2, t - h)));
            assert!(t * k2 < 0.0, "the kink turns away from the sliding");
        }
    }

    /// The Paris rate is C ((1 - R) K_I)^m straight ahead in mode I; in mixed mode the kink
    /// is the hoop angle and Delta K_eq is Eq. 40 of Belytschko et al. (1995) written out;
    /// a closed crack does not grow.
    #[test]
    fn paris_rate_in_mode_one_and_mixed_mode() {
        let p = Paris {
            c: 1e-29,
            m: 3.0,
            r: 0.2,
        };
        let (rate, theta, _) = p.rate(10e6, 0.0);
        assert_eq!(theta, 0.0);
        assert!(
            (rate - 1e-29 * 8e6f64.powi(3)).abs() < 1e-12 * rate,
            "{rate}"
        );
        let (k1, k2) = (8e6, 3e6);
        let (rate, theta, _) = p.rate(k1, k2);
        assert!((theta - hoop_angle(k1, k2)).abs() < 1e-12);
        let (c, s) = ((0.5 * theta).cos(), (0.5 * theta).sin());
        let eq = 0.8 * k1 * c.powi(3) - 3.0 * 0.8 * k2 * c * c * s;
        assert!((rate - 1e-29 * eq.powi(3)).abs() < 1e-9 * rate, "{rate}");
        assert_eq!(p.rate(-5e6, 0.0).0, 0.0);
    }
}
