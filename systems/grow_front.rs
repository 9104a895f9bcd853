//! `grow` in 3D: advances growing crack fronts. At a check each front vertex reads K_I,
//! K_II and J from the front measurement, and its criterion (the hoop stress reaching K_Ic,
//! J reaching G_c, or a set time) says whether it advances; under a Paris law every vertex
//! advances by its share of the fastest rate (Belytschko et al. 1995, Eqs. 38-40, vertex by
//! vertex), the shares smoothed along the front so that the scatter of K between
//! neighbours does not roughen it. A vertex advances along its frame's x1 axis (normal to
//! the front, in the crack surface) or, under the hoop direction, turned from it towards
//! x2 by the angle of the largest hoop stress of its K_I and K_II (Erdogan & Sih 1963;
//! K_III does not turn it), smoothed along the front the same way; the band it leaves
//! behind becomes a strip of new triangles. A front stops as a whole where a vertex would
//! leave the body or come within a quarter cell of another crack.

use crate::base::dim::D3;
use crate::base::error::Unstable;
use crate::fracture::front::front_line;
use crate::fracture::plan::{FracturePlan, TipResult};
use crate::physics::growth::{
    Direction, Growth, GrowthRow, Initiation, Stopped, hoop_angle, hoop_k,
};
use crate::physics::shape::ShapeKind;
use crate::store::world::World;
use crate::systems::{fracture_front, grow::inside};
use glam::DVec3;

/// Advances every growing front by what this step's check allows, and returns a row for
/// each front that moved. `plan` is the scene's fracture plan (present whenever a criterion
/// reads K). A front leaving the grid makes the run unstable.
pub fn run(world: &mut World<D3>, plan: Option<&FracturePlan>) -> Result<Vec<GrowthRow>, Unstable> {
    let Some(cracks) = &world.cracks else {
        return Ok(Vec::new());
    };
    let due: Vec<Option<Growth>> = (cracks.topology.fronts().iter().zip(&cracks.tips))
        .map(|(f, st)| {
            let g = cracks.topology.cracks()[f.crack as usize].growth?;
            (st.stopped == 0 && world.step.is_multiple_of(g.check)).then_some(g)
        })
        .collect();
    if due.iter().all(Option::is_none) {
        return Ok(Vec::new());
    }
    // K and J at every front vertex, read once for all fronts before any of them moves.
    let reads =
        (due.iter().zip(&cracks.tips)).any(|(g, st)| g.is_some_and(|g| g.reads_k(st, world.time)));
    let measured = match plan {
        Some(p) if reads => fracture_front::measure(world, p).tips,
        _ => Vec::new(),
    };
    let mut first = 0;
    let mut grown = Vec::new();
    for (f, g) in due.into_iter().enumerate() {
        let cracks = world.cracks.as_ref().expect("a growing crack");
        let n = cracks.topology.fronts()[f].vertices.len();
        let rows = measured.get(first..first + n);
        first += n;
        if let Some(g) = g {
            grown.extend(advance(world, f, &g, rows)?);
        }
    }
    Ok(grown)
}

/// One check of front `f` under growth law `g`, with its vertices' readings `rows` (None
/// when this check reads none): the front's growth row if it moved.
fn advance(
    world: &mut World<D3>,
    f: usize,
    g: &Growth,
    rows: Option<&[TipResult]>,
) -> Result<Option<GrowthRow>, Unstable> {
    let cracks = world.cracks.as_ref().expect("a growing crack");
    let front = &cracks.topology.fronts()[f];
    let line = front_line(cracks, front);
    let mut st = cracks.tips[f];
    let n = line.frames.len();
    let reading = |i: usize| rows.map_or([f64::NAN; 3], |r| [r[i].k[0], r[i].k[1], r[i].j[0]]);
    let holds: Vec<bool> = (0..n)
        .map(|i| {
            let [k1, k2, j] = reading(i);
            match g.initiation {
                Initiation::Time { at } => world.time >= at,
                Initiation::Hoop { k_ic } => hoop_k(k1, k2, hoop_angle(k1, k2)) >= k_ic,
                Initiation::Energy { g_c } => j >= g_c,
            }
        })
        .collect();
    if st.started.is_nan() {
        if !holds.contains(&true) {
            return Ok(None);
        }
        st.started = world.time;
    }
    // Each vertex's share of the extension and, under fatigue, the front's mean rate and
    // Delta K_eq.
    let (share, fatigue) = match g.paris {
        Some(p) => {
            let rated: Vec<(f64, f64)> = (0..n)
                .map(|i| {
                    let [k1, k2, _] = reading(i);
                    let (rate, _, dk) = p.rate(k1, k2);
                    (rate, dk)
                })
                .collect();
            let rate = smooth(&rated.iter().map(|r| r.0).collect::<Vec<_>>(), line.closed);
            let fastest = rate.iter().copied().fold(0.0, f64::max);
            if rate.iter().any(|r| !r.is_finite()) {
                st.stopped = Stopped::Unmeasured as u8;
            } else if fastest <= 0.0 {
                st.stopped = Stopped::Arrested as u8;
            }
            if st.stopped != 0 {
                world.cracks.as_mut().expect("a growing crack").tips[f] = st;
                return Ok(None);
            }
            st.count_cycles(mean(&rate));
            let dk = mean(&rated.iter().map(|r| r.1).collect::<Vec<_>>());
            (rate.iter().map(|r| r / fastest).collect(), [dk, st.cycles])
        }
        None => {
            let on: Vec<f64> = holds.iter().map(|&h| f64::from(u8::from(h))).collect();
            (smooth(&on, line.closed), [f64::NAN; 2])
        }
    };
    let turn = turns(g.direction, (0..n).map(reading), line.closed);
    let h = (0..3).map(|a| world.grid.geom.h[a]).fold(0.0, f64::max);
    let ds: Vec<f64> = share.iter().map(|s| s * g.extension).collect();
    let to: Vec<Option<DVec3>> = (line.frames.iter().zip(&ds).zip(&turn))
        .map(|((fr, &d), &t)| {
            (d >= 0.01 * h).then(|| fr.x + (fr.e[0] * t.cos() + fr.e[1] * t.sin()) * d)
        })
        .collect();
    let c = front.crack as usize;
    if let Some(why) = stop_at(world, c, &to, h)? {
        st.stopped = why as u8;
    }
    // The front's mean advance, counting a vertex held for a share under a hundredth of a
    // cell as not moving.
    let moved: Vec<f64> = (to.iter().zip(&ds))
        .map(|(t, &d)| if t.is_some() { d } else { 0.0 })
        .collect();
    let grown = mean(&moved);
    let moves = st.stopped == 0 && to.iter().any(Option::is_some);
    let mut grew = None;
    if moves {
        let k = rows.map_or([f64::NAN; 2], |r| {
            [0, 1].map(|m| mean(&r.iter().map(|t| t.k[m]).collect::<Vec<_>>()))
        });
        let centre = line.frames.iter().map(|fr| fr.x).sum::<DVec3>() / n as f64;
        // The front's largest turn among the vertices that moved, as a magnitude (a front
        // under mode II turns both ways, where K_II changes sign along it).
        let kink = (to.iter().zip(&turn))
            .filter(|(t, _)| t.is_some())
            .fold(0.0, |m: f64, (_, a)| m.max(a.abs()));
        let row = GrowthRow {
            step: world.step,
            time: world.time,
            crack: c as u32,
            tip: front.end,
            grown: st.grown,
            x: [centre.x, centre.y],
            k,
            kink,
            heading: f64::NAN,
            fatigue,
        };
        let closed = line.closed;
        let cracks = world.cracks.as_mut().expect("a growing crack");
        grew = Some(row);
        cracks.advance_front(f, &to, closed).map_err(|e| Unstable {
            step: world.step,
            time: world.time,
            what: format!(
                "crack `{}` cannot grow: {}",
                cracks.topology.cracks()[c].name,
                e.0
            ),
        })?;
        st.grown += grown;
    }
    st.speed = if moves {
        grown / (g.check as f64 * world.settings.dt)
    } else {
        0.0
    };
    world.cracks.as_mut().expect("a growing crack").tips[f] = st;
    Ok(grew)
}

/// Each vertex's turn from x1 towards x2 under `direction`: the hoop angle of its K_I and
/// K_II (none where K was not read), smoothed along the front.
fn turns(direction: Direction, readings: impl Iterator<Item = [f64; 3]>, closed: bool) -> Vec<f64> {
    let raw: Vec<f64> = readings
        .map(|[k1, k2, _]| {
            let t = hoop_angle(k1, k2);
            if t.is_finite() { t } else { 0.0 }
        })
        .collect();
    match direction {
        Direction::Hoop => smooth(&raw, closed),
        Direction::Straight => vec![0.0; raw.len()],
    }
}

/// Why the front of crack `c` stops before reaching the targets `to` (the last reason met
/// along the front: a target not finite, within a quarter cell of another crack, or outside
/// the body), or an error when a target leaves the grid. `h` is the largest cell side (m).
fn stop_at(
    world: &World<D3>,
    c: usize,
    to: &[Option<DVec3>],
    h: f64,
) -> Result<Option<Stopped>, Unstable> {
    let cracks = world.cracks.as_ref().expect("a growing crack");
    let name = &cracks.topology.cracks()[c].name;
    let mut stopped = None;
    for t in to.iter().flatten() {
        if !t.is_finite() {
            stopped = Some(Stopped::Unmeasured);
        } else if !world.grid.geom.fits(ShapeKind::Linear, *t, DVec3::ZERO) {
            return Err(Unstable {
                step: world.step,
                time: world.time,
                what: format!(
                    "crack `{name}` grew out of the grid: a front vertex reached \
                     ({:.6e}, {:.6e}, {:.6e}) m",
                    t.x, t.y, t.z
                ),
            });
        } else if fracture_front::room(cracks, c, *t, 0.25 * h) < 0.25 * h {
            stopped = Some(Stopped::Crack);
        } else if !inside(world, *t) {
            stopped = Some(Stopped::Surface);
        }
    }
    Ok(stopped)
}

/// `v` smoothed along a front by the weights 1/4, 1/2, 1/4 of each vertex and its two
/// neighbours (around a closed front; at the ends of an open one 2/3, 1/3 of the end and
/// its neighbour).
fn smooth(v: &[f64], closed: bool) -> Vec<f64> {
    let n = v.len();
    if n < 3 {
        return v.to_vec();
    }
    (0..n)
        .map(|i| match (i, closed) {
            (0, false) => (2.0 * v[0] + v[1]) / 3.0,
            (_, false) if i == n - 1 => (2.0 * v[i] + v[i - 1]) / 3.0,
            _ => 0.25 * v[(i + n - 1) % n] + 0.5 * v[i] + 0.25 * v[(i + 1) % n],
        })
        .collect()
}

/// The mean of `v` (NaN for none).
fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothing_keeps_a_uniform_front_and_its_mean_around_a_loop() {
        assert_eq!(smooth(&[2.0; 5], true), vec![2.0; 5]);
        assert_eq!(smooth(&[2.0; 5], false), vec![2.0; 5]);
        let v = [1.0, 4.0, 2.0, 8.0, 5.0];
        let s = smooth(&v, true);
        assert!((mean(&s) - mean(&v)).abs() < 1e-12);
        assert_eq!(s[1], 0.25 * 1.0 + 0.5 * 4.0 + 0.25 * 2.0);
    }
}
