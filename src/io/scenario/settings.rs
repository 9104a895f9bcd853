//! The `[simulation]` table: plane mode, thickness, duration, time-step choice, damping,
//! gravity and tile size; and the time step itself once the materials are known.

use super::check::{R, positive, vec3};
use super::source::Source;
use crate::base::dim::Dim;
use crate::physics::material::{Material, Plane};
use crate::physics::shape::ShapeKind;
use crate::ranks::domain::Domain;
use crate::store::grid::GridGeom;
use crate::store::tiles::MIN_TILE;
use crate::store::world::{Dilatation, Solver};

/// Most time steps a run may take (a duration or `--until` needing more is refused).
pub const MAX_STEPS: f64 = 1e10;

/// The CFL factor when neither `cfl` nor `dt` is given.
const DEFAULT_CFL: f64 = 0.5;

/// The checked `[simulation]` values the other builders need.
pub(super) struct Simulation {
    /// Plane strain or stress in 2D, none in 3D.
    pub plane: Plane,
    /// Out-of-plane thickness (m; 1 in 3D).
    pub thickness: f64,
    /// Simulated duration (s).
    pub duration: f64,
    /// Fraction of the stability limit taken as the step when `dt` is not given.
    pub cfl: f64,
    /// Gravity, padded to 3 (m/s^2).
    pub gravity: [f64; 3],
    /// Tile width in cells.
    pub tile: usize,
}

/// The `[simulation]` table, checked (the name too, which names the output folder).
pub(super) fn simulation<D: Dim>(src: &Source) -> R<Simulation> {
    let sc = &src.scenario;
    let sim = &sc.simulation;
    super::check::check_name(src)?;
    if sim.dimension as usize != D::D {
        return Err(src.error("simulation.dimension", "must be 2 or 3"));
    }
    let plane = match (D::D, sim.plane.as_deref()) {
        (2, None | Some("strain")) => Plane::Strain,
        (2, Some("stress")) => Plane::Stress,
        (2, Some(other)) => {
            return Err(src.error(
                "simulation.plane",
                format!("unknown plane mode `{other}` (use \"strain\" or \"stress\")"),
            ));
        }
        (_, Some(_)) => return Err(src.error("simulation.plane", "applies to 2D scenes only")),
        _ => Plane::None,
    };
    if sim.dilatation == Dilatation::CellMean && plane == Plane::Stress {
        return Err(src.error(
            "simulation.dilatation",
            "\"cell_mean\" relieves a volume constraint that plane stress does not have \
             (sigma_zz = 0 lets the thickness change): use it in plane strain or 3D",
        ));
    }
    let thickness = match (D::D, sim.thickness) {
        (2, Some(t)) => positive(src, "simulation.thickness", t, "m")?,
        (2, None) => 1.0,
        (_, Some(_)) => {
            return Err(src.error("simulation.thickness", "applies to 2D scenes only"));
        }
        _ => 1.0,
    };
    let duration = positive(src, "simulation.duration", sim.duration, "s")?;
    let cfl = sim.cfl.unwrap_or(DEFAULT_CFL);
    if !(cfl > 0.0 && cfl < 1.0) {
        return Err(src.error(
            "simulation.cfl",
            format!("CFL factor must satisfy 0 < cfl < 1, got {cfl}"),
        ));
    }
    if sim.cfl.is_some() && sim.dt.is_some() {
        return Err(src.error(
            "simulation.dt",
            "give the time step either as `dt` or as a fraction `cfl` of the stability limit, \
             not both",
        ));
    }
    if !(sim.damping >= 0.0 && sim.damping.is_finite()) {
        return Err(src.error("simulation.damping", "damping must be >= 0 (1/s)"));
    }
    let gravity = match &sim.gravity {
        Some(g) => vec3::<D>(src, "simulation.gravity", g)?,
        None => [0.0; 3],
    };
    let tile = sim.tile.unwrap_or(if D::D == 2 { 8 } else { 4 });
    if tile < MIN_TILE {
        return Err(src.error(
            "simulation.tile",
            format!("tiles must be at least {MIN_TILE} cells wide"),
        ));
    }
    Ok(Simulation {
        plane,
        thickness,
        duration,
        cfl,
        gravity,
        tile,
    })
}

/// Most load steps a static scene may take.
const MAX_LOAD_STEPS: u64 = 1_000_000;

/// Load steps of a static scene without `load_steps` or a history interval.
const DEFAULT_LOAD_STEPS: u64 = 10;

/// The time step and the stability limit (smallest cell over the fastest wave speed of the
/// materials some body uses), both in s: `dt` as given (refused above the limit), else the
/// CFL fraction of the limit. A static scene steps by its load step instead, `duration`
/// over `load_steps` (`dt`, `cfl` and `damping` do not apply to it).
pub(super) fn time_step<D: Dim>(
    src: &Source,
    sim: &Simulation,
    materials: &[Material],
    used: &[bool],
    geom: &GridGeom<D>,
) -> R<(f64, f64)> {
    let c_max = materials
        .iter()
        .zip(used)
        .filter(|(_, u)| **u)
        .map(|(m, _)| m.wave_speed(sim.plane))
        .fold(0.0, f64::max);
    let dt_limit = geom.min_cell() / c_max;
    let s = &src.scenario;
    if s.simulation.solver == Solver::Static {
        let steps = match (s.simulation.load_steps, s.output.history_interval) {
            (Some(n), _) => n,
            (None, Some(h)) if h > 0.0 => (sim.duration / h).round().max(1.0) as u64,
            _ => DEFAULT_LOAD_STEPS,
        };
        if !(1..=MAX_LOAD_STEPS).contains(&steps) {
            return Err(src.error(
                "simulation.load_steps",
                format!("give 1 to {MAX_LOAD_STEPS} load steps"),
            ));
        }
        return Ok((sim.duration / steps as f64, dt_limit));
    }
    if s.simulation.load_steps.is_some() {
        return Err(src.error(
            "simulation.load_steps",
            "load steps belong to a static scene (solver = \"static\")",
        ));
    }
    let dt = match src.scenario.simulation.dt {
        Some(dt) => {
            positive(src, "simulation.dt", dt, "s")?;
            if dt > dt_limit {
                return Err(src.error(
                    "simulation.dt",
                    format!(
                        "time step {dt:.4e} s is above the stability limit {dt_limit:.4e} s \
                         (smallest cell / fastest wave speed {c_max:.1} m/s)"
                    ),
                ));
            }
            dt
        }
        None => sim.cfl * dt_limit,
    };
    if sim.duration / dt > MAX_STEPS {
        return Err(src.error(
            "simulation.duration",
            format!("more than {MAX_STEPS:e} time steps"),
        ));
    }
    Ok((dt, dt_limit))
}

/// Cell units within which a particle's domain counts as inside its cell: far below any
/// particle spacing, far above the round-off of a position.
const INSIDE: f64 = 1e-9;

/// The shape functions a run takes: the scenario's, but linear for uGIMP in a static scene
/// whose every particle's domain lies inside one cell. There the two are the same
/// functions: a uGIMP weight is the mean of the node's hat over the particle's domain,
/// which within a cell is the hat's value at the particle's centre (and its gradient the
/// hat's), and zero for the nodes beyond the cell. The linear stencil holds 2^D nodes
/// against uGIMP's 3^D, of which the others carry zeros through every product with K.
pub(super) fn solve_shape<D: Dim>(
    solver: Solver,
    shape: ShapeKind,
    x: &[D::Vec],
    half: &[D::Vec],
    geom: &GridGeom<D>,
    domain: &Domain,
) -> ShapeKind {
    if solver != Solver::Static || shape != ShapeKind::Ugimp {
        return shape;
    }
    let inside = |(x, l): (&D::Vec, &D::Vec)| {
        (0..D::D).all(|a| {
            let xi = (x[a] - geom.origin[a]) * geom.inv_h[a];
            let (l, cell) = (l[a] * geom.inv_h[a], xi.floor());
            xi - l >= cell - INSIDE && xi + l <= cell + 1.0 + INSIDE
        })
    };
    // Every rank's particles inside their cells.
    let mine = half.len() == x.len() && x.iter().zip(half).all(inside);
    if domain.any(!mine) {
        shape
    } else {
        ShapeKind::Linear
    }
}
