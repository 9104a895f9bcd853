//! `grow`: advances the growing tips of 2D cracks. A tip starts when its criterion holds
//! (the maximum hoop stress reaching K_Ic, Erdogan & Sih 1963; J reaching G_c; or a set
//! time), turns to the direction of the largest hoop stress or runs straight on, and then
//! either runs at a set speed or extends by one segment at every check at which the
//! criterion still holds; under a Paris law each extension adds the load cycles it costs
//! (Belytschko et al. 1995, Eqs. 38-41). A tip that reaches the body's free surface is
//! carried a cell past it and stops; one that reaches another crack stops just short of
//! it. Runs after the step and its fracture measurement; the moved tip is classified, in
//! contact and measured from the next step on.

use crate::base::dim::{D2, Dim};
use crate::base::error::Unstable;
use crate::base::geometry::Element;
use crate::fracture::interaction::near;
use crate::fracture::plan::FracturePlan;
use crate::physics::growth::{
    Direction, GrowthRow, Initiation, Paris, Stopped, TipState, hoop_angle, hoop_k,
};
use crate::physics::shape::ShapeKind;
use crate::store::crack::Cracks;
use crate::store::world::World;
use crate::systems::fracture;
use glam::DVec2;

/// Whether some growing tip or front reads K or J at the end of step `step` (so that step
/// must keep its particles' stencils for the measurement).
pub fn needs_k<D: Dim>(world: &World<D>, step: u64) -> bool {
    let Some(cracks) = &world.cracks else {
        return false;
    };
    let topo = &cracks.topology;
    (topo.fronts().iter().zip(&cracks.tips)).any(|(f, st)| {
        topo.cracks()[f.crack as usize].growth.is_some_and(|g| {
            let t = step as f64 * world.settings.dt;
            step.is_multiple_of(g.check) && g.reads_k(st, t)
        })
    })
}

/// Advances every growing tip by what this step allows, and returns a row for each new
/// segment. `plan` is the scene's fracture plan (present whenever a criterion or direction
/// reads K). A tip leaving the grid makes the run unstable.
pub fn run(world: &mut World<D2>, plan: Option<&FracturePlan>) -> Result<Vec<GrowthRow>, Unstable> {
    let fronts = world
        .cracks
        .as_ref()
        .map_or(0, |c| c.topology.fronts().len());
    // K_I, K_II and G along each tip's direction where this check reads them, all before
    // any tip moves.
    let readings: Vec<_> = (0..fronts).map(|f| reading(world, plan, f)).collect();
    // Fatigue: every tip sees the same load cycles, so the fastest tip checked now grows one
    // extension and the others the share their rates give them.
    let fastest = (0..fronts)
        .filter_map(|f| {
            let cracks = world.cracks.as_ref()?;
            let front = &cracks.topology.fronts()[f];
            let paris = cracks.topology.cracks()[front.crack as usize]
                .growth?
                .paris?;
            let (k1, k2, _) = readings[f]?;
            (cracks.tips[f].stopped == 0).then(|| paris.rate(k1, k2).0)
        })
        .filter(|r| r.is_finite())
        .fold(0.0, f64::max);
    let mut rows = Vec::new();
    for (f, &measured) in readings.iter().enumerate() {
        let Some(cracks) = &world.cracks else {
            return Ok(rows);
        };
        let front = &cracks.topology.fronts()[f];
        let Some(g) = cracks.topology.cracks()[front.crack as usize].growth else {
            continue;
        };
        let (crack, end) = (front.crack, front.end);
        let mut st = cracks.tips[f];
        if st.stopped != 0 {
            continue;
        }
        let (tip, behind) = tip_and_behind(cracks, f);
        let dir = (tip - behind).normalize();
        let check = world.step.is_multiple_of(g.check);
        let holds = match g.initiation {
            Initiation::Time { at } => world.time >= at,
            Initiation::Hoop { k_ic } => {
                measured.is_some_and(|(k1, k2, _)| hoop_k(k1, k2, hoop_angle(k1, k2)) >= k_ic)
            }
            Initiation::Energy { g_c } => measured.is_some_and(|(_, _, g)| g >= g_c),
        };
        if st.started.is_nan() {
            // A tip that turns by the hoop stress starts at a check, where it reads K.
            if !holds || (g.direction == Direction::Hoop && measured.is_none()) {
                continue;
            }
            st.started = world.time;
            st.heading = dir.to_array();
        }
        // The direction the next new segment takes: the hoop stress's at the last check
        // that read K, or straight on. A tip running at a set speed keeps the heading it
        // took when it started: the K it reads while running comes from the faces behind
        // it, which next to a kink still slide as the crack it left did.
        let heading = match (g.direction, measured) {
            (Direction::Hoop, Some((k1, k2, _))) if k1.is_finite() && k2.is_finite() => {
                DVec2::from_angle(hoop_angle(k1, k2)).rotate(dir)
            }
            (Direction::Hoop, _) => DVec2::from(st.heading),
            (Direction::Straight, _) => dir,
        };
        st.heading = heading.to_array();
        let dt = world.settings.dt;
        let (mut ds, over) = match g.speed {
            Some(v) => (v * dt, dt),
            None if check && holds => {
                let share = match (g.paris, measured) {
                    (Some(p), Some((k1, k2, _))) if fastest > 0.0 => p.rate(k1, k2).0 / fastest,
                    _ => 1.0,
                };
                (g.extension * share, g.check as f64 * dt)
            }
            None => (0.0, dt),
        };
        let fatigue = match (g.paris, measured) {
            (Some(p), Some((k1, k2, _))) if ds > 0.0 => {
                let dk = fatigue(&p, &mut st, k1, k2);
                if !dk.is_finite() {
                    st.stopped = Stopped::Unmeasured as u8;
                    ds = 0.0;
                } else if st.rate <= 0.0 {
                    st.stopped = Stopped::Arrested as u8;
                    ds = 0.0;
                }
                [dk, st.cycles]
            }
            _ => [f64::NAN; 2],
        };
        let grown = if ds > 0.0 {
            // A new segment when the last one would pass the extension length; under fatigue
            // at every check, unless the share is below a hundredth of a cell.
            let h = world.grid.geom.h[0].max(world.grid.geom.h[1]);
            let turn = (tip - behind).length() + ds > g.extension
                || (fatigue[0].is_finite() && ds >= 0.01 * h);
            let (grown, stop, fresh) = advance(world, f, tip, dir, heading, ds, turn)?;
            let taken = if turn { heading } else { dir };
            if let Some(s) = stop {
                st.stopped = s as u8;
            }
            if fresh {
                let k = measured.map_or([f64::NAN; 2], |(k1, k2, _)| [k1, k2]);
                rows.push(GrowthRow {
                    step: world.step,
                    time: world.time,
                    crack: u32::from(crack),
                    tip: end,
                    grown: st.grown,
                    x: tip.to_array(),
                    k,
                    kink: dir.perp_dot(taken).atan2(dir.dot(taken)),
                    heading: taken.y.atan2(taken.x),
                    fatigue,
                });
            }
            grown
        } else {
            0.0
        };
        st.grown += grown;
        // A tip that stopped runs no more (its last move may carry it a cell past a surface).
        st.speed = if st.stopped == 0 { grown / over } else { 0.0 };
        if let Some(c) = world.cracks.as_mut() {
            c.tips[f] = st;
        }
    }
    Ok(rows)
}

/// K_I, K_II and G along the direction of front `f`'s tip, where this step is a check of
/// its crack's growth and the tip reads them.
fn reading(world: &World<D2>, plan: Option<&FracturePlan>, f: usize) -> Option<(f64, f64, f64)> {
    let cracks = world.cracks.as_ref()?;
    let front = &cracks.topology.fronts()[f];
    let g = cracks.topology.cracks()[front.crack as usize].growth?;
    let st = &cracks.tips[f];
    if st.stopped != 0 || !world.step.is_multiple_of(g.check) || !g.reads_k(st, world.time) {
        return None;
    }
    let (tip, behind) = tip_and_behind(cracks, f);
    let dir = (tip - behind).normalize();
    let r = fracture::tip(world, cracks, front, plan?, Some(st)).0;
    Some((r.k[0], r.k[1], r.j[0] * dir.x + r.j[1] * dir.y))
}

/// Fatigue at a check: the growth rate from K_I and K_II at the largest load, and the
/// cycles to the tip's length (see [`TipState::count_cycles`]). Returns Delta K_eq.
fn fatigue(p: &Paris, st: &mut TipState, k1: f64, k2: f64) -> f64 {
    let (rate, _, dk) = p.rate(k1, k2);
    st.count_cycles(rate);
    dk
}

/// The tip of front `f` and the vertex just behind it.
fn tip_and_behind(cracks: &Cracks<D2>, f: usize) -> (DVec2, DVec2) {
    let topo = &cracks.topology;
    let front = &topo.fronts()[f];
    let path = &topo.cracks()[front.crack as usize].vertices;
    let (t, p) = if front.end == 1 {
        (path[path.len() - 1], path[path.len() - 2])
    } else {
        (path[0], path[1])
    };
    let x = &cracks.geometry.x;
    (x[t as usize], x[p as usize])
}

/// Moves the tip of front `f` (at `tip`, its last segment along `dir`) by `ds`: when
/// `fresh`, a new vertex is left at the tip and a new segment starts along `heading`;
/// otherwise the tip slides on along `dir`. Returns the length grown, why the tip stopped
/// (if it did) and whether a new segment started.
fn advance(
    world: &mut World<D2>,
    f: usize,
    tip: DVec2,
    dir: DVec2,
    heading: DVec2,
    ds: f64,
    fresh: bool,
) -> Result<(f64, Option<Stopped>, bool), Unstable> {
    let geom = &world.grid.geom;
    let h = geom.h[0].max(geom.h[1]);
    let cracks = world.cracks.as_ref().expect("a growing crack");
    let front = &cracks.topology.fronts()[f];
    let name = &cracks.topology.cracks()[front.crack as usize].name;
    let heading = if fresh { heading } else { dir };
    let mut to = tip + heading * ds;
    let mut stop = None;
    if let Some(t) = first_crossing(cracks, f, tip, to) {
        // Stop a hundredth of a cell short of the crack met, never behind the tip.
        to = tip + heading * (t * ds - 0.01 * h).max(0.0);
        stop = Some(Stopped::Crack);
    } else if !inside(world, to) {
        // Carry the tip a cell past the surface, so that the crack cuts the body through.
        let step = 0.25 * h;
        let mut s = 0.0;
        while s < ds && inside(world, tip + heading * s) {
            s += step;
        }
        to = tip + heading * (s + h);
        stop = Some(Stopped::Surface);
    }
    if !world.grid.geom.fits(ShapeKind::Linear, to, DVec2::ZERO) {
        return Err(Unstable {
            step: world.step,
            time: world.time,
            what: format!(
                "crack `{name}` grew out of the grid: its {} tip reached ({:.6e}, {:.6e}) m",
                ["start", "end"][front.end as usize],
                to.x,
                to.y
            ),
        });
    }
    let grown = (to - tip).length();
    let cracks = world.cracks.as_mut().expect("a growing crack");
    if fresh || stop.is_some() {
        cracks.extend_tip(f, to);
    } else {
        let t = cracks.topology.fronts()[f].vertices[0] as usize;
        let g = &mut cracks.geometry;
        (g.x[t], g.top[t], g.bottom[t]) = (to, to, to);
    }
    Ok((grown, stop, fresh || stop.is_some()))
}

/// Where the move from `a` to `b` of front `f`'s tip first meets a crack segment other
/// than the tip's own: the fraction of the move, if it does.
fn first_crossing(cracks: &Cracks<D2>, f: usize, a: DVec2, b: DVec2) -> Option<f64> {
    let topo = &cracks.topology;
    let tip = topo.fronts()[f].vertices[0];
    let x = &cracks.geometry.x;
    let r = b - a;
    (topo.elems().iter())
        .filter(|e| !e.vertices().contains(&tip))
        .filter_map(|e| {
            let v = e.vertices();
            let (c, d) = (x[v[0] as usize], x[v[1] as usize]);
            let s = d - c;
            let den = r.perp_dot(s);
            if den == 0.0 {
                return None;
            }
            let t = (c - a).perp_dot(s) / den;
            let u = (c - a).perp_dot(r) / den;
            ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then_some(t)
        })
        .min_by(f64::total_cmp)
}

/// Whether `x` lies in the body: within three quarters of a particle spacing (from its
/// area or volume) of some particle near it, along every axis. A crack runs half a spacing
/// from the particle layers on either side of it, so half a spacing would leave it outside.
/// Split over ranks, each looks among its own particles and every rank takes the answer of
/// all (every rank calls it at the same point, as growth is decided alike on all).
pub(crate) fn inside<D: Dim>(world: &World<D>, x: D::Vec) -> bool {
    let p = &world.particles;
    let thickness = world.settings.thickness;
    let h = (0..D::D).map(|a| world.grid.geom.h[a]).fold(0.0, f64::max);
    let mine = near(world, x, h).into_iter().any(|i| {
        let spacing = if D::D == 2 {
            (p.volume[i] / thickness).sqrt()
        } else {
            p.volume[i].cbrt()
        };
        (0..D::D).all(|a| (x[a] - p.x[i][a]).abs() <= 0.75 * spacing)
    });
    world.domain.any(mine)
}
