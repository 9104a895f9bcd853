//! A crack's `[crack.growth]` table, checked: the criterion with the value it needs, the
//! direction, and the speed, extension and check cadence within their ranges.

use super::schema::{CrackSpec, ExpectSpec, GrowthSpec, ParisSpec};
use super::source::Source;
use crate::base::dim::Dim;
use crate::base::error::ScenarioError;
use crate::physics::growth::{Direction, Growth, Initiation, Paris};
use crate::physics::material::Material;
use crate::record::expect::{GrowthQty, Measure};

type R<T> = Result<T, ScenarioError>;

/// Steps between checks when `interval` is not given: reading K at a tip costs about a
/// third of a DCB-sized step, so a check every tenth step keeps a waiting tip's cost near
/// 3 %.
const DEFAULT_CHECK: u64 = 10;

/// The growth law of crack `c`, if it has one. `cell` is the smallest cell size (m) and
/// `dt` the time step (s); `measured` says whether the scene has a `[fracture]` table,
/// which criteria on K or J need; `tips` whether the crack has a tip to grow.
#[allow(clippy::too_many_arguments)]
pub(super) fn growth<D: Dim>(
    src: &Source,
    c: usize,
    spec: &CrackSpec,
    materials: &[Material],
    cell: f64,
    dt: f64,
    measured: bool,
    tips: bool,
) -> R<Option<Growth>> {
    let Some(g) = &spec.growth else {
        return Ok(None);
    };
    let key = |k: &str| format!("crack[{c}].growth.{k}");
    if !tips {
        let why = if D::D == 2 {
            "the crack has no tip to grow (see `tips`)"
        } else {
            "the crack has no front to grow (a rectangle cuts through the body and has none)"
        };
        return Err(src.error(&format!("crack[{c}].growth"), why));
    }
    let initiation = initiation(src, c, g)?;
    // A 3D front grows in its own plane unless told; a 2D tip turns by the hoop stress
    // unless told.
    let planar = D::D == 3;
    let direction = match g.direction.as_deref() {
        Some("hoop") => Direction::Hoop,
        Some("straight") => Direction::Straight,
        None if planar => Direction::Straight,
        None => Direction::Hoop,
        Some(other) => {
            return Err(src.error(
                &key("direction"),
                format!("unknown direction `{other}` (hoop, straight)"),
            ));
        }
    };
    if planar && g.speed.is_some() {
        return Err(src.error(
            &key("speed"),
            "a 3D front does not run at a set speed: it grows by its criterion or a Paris law",
        ));
    }
    let paris = match &g.paris {
        Some(p) => Some(paris(src, c, p, &initiation, g.speed.is_some())?),
        None => None,
    };
    let needs_k = direction == Direction::Hoop
        || paris.is_some()
        || !matches!(initiation, Initiation::Time { .. });
    if needs_k && !measured {
        return Err(src.error(
            &format!("crack[{c}].growth"),
            "this criterion or direction reads K or J at the tip: add a [fracture] table",
        ));
    }
    let speed = match g.speed {
        None => None,
        Some(v) => {
            let rayleigh = materials
                .iter()
                .map(rayleigh_speed)
                .fold(f64::INFINITY, f64::min);
            if !(v > 0.0 && v < rayleigh) {
                return Err(src.error(
                    &key("speed"),
                    format!(
                        "a crack runs at a speed above 0 and below the Rayleigh wave speed \
                         (about {rayleigh:.4e} m/s here)"
                    ),
                ));
            }
            Some(v)
        }
    };
    let extension = g.extension.unwrap_or(0.5 * cell);
    if !(extension >= 0.01 * cell && extension <= 2.0 * cell) {
        return Err(src.error(
            &key("extension"),
            format!(
                "a new segment is 0.01 to 2 cells long ({:.4e} to {:.4e} m)",
                0.01 * cell,
                2.0 * cell
            ),
        ));
    }
    let check = match g.interval {
        None => DEFAULT_CHECK,
        Some(t) if t.is_finite() && t >= dt => (t / dt).round() as u64,
        Some(_) => {
            return Err(src.error(
                &key("interval"),
                format!("checks are at least one time step apart (dt = {dt:.4e} s)"),
            ));
        }
    };
    Ok(Some(Growth {
        initiation,
        direction,
        speed,
        extension,
        check,
        paris,
    }))
}

/// The checked Paris law: C and m positive, R in [0, 1), growth from a set time (after
/// the first static solve) by fixed extensions, not at a set speed.
fn paris(src: &Source, c: usize, p: &ParisSpec, initiation: &Initiation, speed: bool) -> R<Paris> {
    let key = |k: &str| format!("crack[{c}].growth.paris.{k}");
    if !matches!(initiation, Initiation::Time { .. }) {
        return Err(src.error(
            &format!("crack[{c}].growth.initiation"),
            "fatigue growth starts at a set time, once the first static solve has settled: \
             give initiation = \"time\" and `at`",
        ));
    }
    if speed {
        return Err(src.error(
            &format!("crack[{c}].growth.speed"),
            "a fatigue crack grows by the Paris law, not at a set speed",
        ));
    }
    if !(p.c > 0.0 && p.c.is_finite()) {
        return Err(src.error(&key("C"), "the Paris coefficient must be positive"));
    }
    if !(p.m > 0.0 && p.m.is_finite()) {
        return Err(src.error(&key("m"), "the Paris exponent must be positive"));
    }
    let r = p.r.unwrap_or(0.0);
    if !(0.0..1.0).contains(&r) {
        return Err(src.error(&key("R"), "the load ratio K_min/K_max must be in [0, 1)"));
    }
    Ok(Paris { c: p.c, m: p.m, r })
}

/// The initiation criterion with its one value, which must be positive.
fn initiation(src: &Source, c: usize, g: &GrowthSpec) -> R<Initiation> {
    let key = |k: &str| format!("crack[{c}].growth.{k}");
    let values = [("KIc", g.k_ic), ("Gc", g.g_c), ("at", g.at)];
    let wanted = match g.initiation.as_str() {
        "hoop" => "KIc",
        "energy" => "Gc",
        "time" => "at",
        other => {
            return Err(src.error(
                &key("initiation"),
                format!("unknown criterion `{other}` (hoop, energy, time)"),
            ));
        }
    };
    for (name, v) in values {
        if name != wanted && v.is_some() {
            return Err(src.error(
                &key(name),
                format!(
                    "`{name}` does not apply to initiation = \"{}\"",
                    g.initiation
                ),
            ));
        }
    }
    let v = values
        .iter()
        .find(|(n, _)| *n == wanted)
        .and_then(|(_, v)| *v)
        .ok_or_else(|| {
            src.error(
                &key("initiation"),
                format!("initiation = \"{}\" needs `{wanted}`", g.initiation),
            )
        })?;
    let ok = if wanted == "at" { v >= 0.0 } else { v > 0.0 };
    if !(ok && v.is_finite()) {
        return Err(src.error(
            &key(wanted),
            match wanted {
                "KIc" => "the toughness must be positive (Pa sqrt(m))",
                "Gc" => "the critical energy release rate must be positive (J/m^2)",
                _ => "the start time must be >= 0 (s)",
            },
        ));
    }
    Ok(match wanted {
        "KIc" => Initiation::Hoop { k_ic: v },
        "Gc" => Initiation::Energy { g_c: v },
        _ => Initiation::Time { at: v },
    })
}

/// Rayleigh wave speed (m/s), Viktorov's approximation c_s (0.862 + 1.14 nu) / (1 + nu).
fn rayleigh_speed(m: &Material) -> f64 {
    (m.mu / m.density).sqrt() * (0.862 + 1.14 * m.poisson) / (1.0 + m.poisson)
}

/// The measure of a growth expect (`kink`, `path_angle`, `turn`, `cycles`) on expect `i`: a named
/// crack with a growth table, one of its tips (in 3D, with a `front`, its one front), and
/// for `cycles` a Paris law and the `length` grown (m; in 3D the front's mean advance).
pub(super) fn growth_measure(src: &Source, i: usize, e: &ExpectSpec, front: bool) -> R<Measure> {
    let key = |k: &str| format!("expect[{i}].{k}");
    let sc = &src.scenario;
    let name = e
        .crack
        .as_deref()
        .ok_or_else(|| src.error(&key("quantity"), "name the crack with `crack = ...`"))?;
    let (c, spec) = (sc.cracks.iter().enumerate())
        .find(|(k, c)| c.name.clone().unwrap_or_else(|| format!("crack{k}")) == name)
        .ok_or_else(|| src.error(&key("crack"), format!("no crack named `{name}`")))?;
    let Some(g) = &spec.growth else {
        return Err(src.error(
            &key("crack"),
            format!("crack `{name}` does not grow (it has no [crack.growth] table)"),
        ));
    };
    let tip = match e.tip.as_deref() {
        Some(_) if front => {
            return Err(src.error(
                &key("tip"),
                "a 3D crack grows along its front, not at a tip",
            ));
        }
        None if front => 0,
        Some("start") => 0,
        Some("end") | None => 1,
        Some(other) => {
            return Err(src.error(&key("tip"), format!("unknown tip `{other}` (start, end)")));
        }
    };
    let tips = spec.tips.clone().unwrap_or_else(|| vec!["end".into()]);
    if !front && !tips.iter().any(|t| t == ["start", "end"][tip]) {
        return Err(src.error(
            &key("tip"),
            format!("the {} of `{name}` is not a tip", ["start", "end"][tip]),
        ));
    }
    if e.at.is_some() {
        return Err(src.error(&key("at"), "`at` applies to KI, KII, J1 and J2"));
    }
    let qty = match (e.quantity.as_str(), e.length) {
        ("kink", None) => GrowthQty::Kink,
        ("path_angle", None) => GrowthQty::PathAngle,
        ("turn", None) => GrowthQty::Turn,
        ("cycles", Some(l)) if g.paris.is_some() && l > 0.0 && l.is_finite() => {
            GrowthQty::Cycles(l)
        }
        ("cycles", _) if g.paris.is_none() => {
            return Err(src.error(
                &key("quantity"),
                format!("`cycles` needs a fatigue law: crack `{name}` has no `paris`"),
            ));
        }
        ("cycles", _) => {
            return Err(src.error(&key("length"), "give the length grown (m, > 0)"));
        }
        (_, _) => return Err(src.error(&key("length"), "`length` applies to cycles")),
    };
    Ok(Measure::Growth {
        crack: c as u32,
        tip: tip as u32,
        qty,
    })
}
