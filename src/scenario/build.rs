//! Building a World from a parsed scenario, validating every value on the way.

use super::claim::Claim;
use super::region::{Region, region};
use super::schema::{AnchorSpec, BodySpec, BoxSpec, RegionSpec, RoundSpec};
use super::source::Source;
use super::traction::{Face, Field, tractions};
use crate::bodies::{Geometry, fill};
use crate::dim::Dim;
use crate::error::ScenarioError;
use crate::fracture::FracturePlan;
use crate::grid::{Grid, GridGeom};
use crate::loads::{Load, VelocityBc};
use crate::material::{Material, Plane};
use crate::measure::{Expect, Measure, Probe, ProbeQty};
use crate::particles::Particles;
use crate::shape::ShapeKind;
use crate::tiles::{MIN_TILE, Tiles};
use crate::world::{Settings, Work, World};

/// Largest grid (nodes) and particle count a scenario may ask for.
const MAX_NODES: f64 = 2.0e8;
const MAX_PARTICLES: f64 = 2.0e8;

/// Output cadence of a run.
#[derive(Clone, Debug)]
pub struct OutputPlan {
    /// Simulated time between VTK frames (s).
    pub interval: f64,
    /// Simulated time between history rows (s).
    pub history_interval: f64,
    /// Write VTK files.
    pub vtk: bool,
    /// Write PNG plots.
    pub plot: bool,
}

/// When a run writes snapshots.
#[derive(Clone, Debug)]
pub struct CheckpointPlan {
    /// Every this many steps.
    pub every_steps: Option<u64>,
    /// Every this much simulated time (s).
    pub every_time: Option<f64>,
    /// Every this much wall-clock time.
    pub every_wall: Option<std::time::Duration>,
    /// Newest snapshots kept.
    pub keep: usize,
}

/// A World ready to run, with what the run records and checks.
#[derive(Clone, Debug)]
pub struct Scene<D: Dim> {
    /// Scenario name.
    pub name: String,
    /// Initial state.
    pub world: World<D>,
    /// Probes.
    pub probes: Vec<Probe>,
    /// Expectations.
    pub expects: Vec<Expect>,
    /// Simulated duration (s).
    pub duration: f64,
    /// Output cadence.
    pub output: OutputPlan,
    /// Stability limit h_min / c_max (s).
    pub dt_limit: f64,
    /// Snapshot cadence.
    pub checkpoint: CheckpointPlan,
    /// J and K measurement, when the scenario asks for it.
    pub fracture: Option<FracturePlan>,
}

type R<T> = Result<T, ScenarioError>;

/// A D-vector from a scenario list, padded to 3 (checked length and finiteness).
pub(super) fn vec3<D: Dim>(src: &Source, key: &str, v: &[f64]) -> R<[f64; 3]> {
    if v.len() != D::D {
        return Err(src.error(
            key,
            format!(
                "expected {} components in {}D, found {}",
                D::D,
                D::D,
                v.len()
            ),
        ));
    }
    if v.iter().any(|c| !c.is_finite()) {
        return Err(src.error(key, "components must be finite numbers"));
    }
    let mut out = [0.0; 3];
    out[..D::D].copy_from_slice(v);
    Ok(out)
}

pub(super) fn to_vec<D: Dim>(a: [f64; 3]) -> D::Vec {
    D::from_slice(&a[..D::D])
}

fn axis_index<D: Dim>(src: &Source, key: &str, name: &str) -> R<usize> {
    let a = match name {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        _ => return Err(src.error(key, format!("unknown axis `{name}` (use x, y or z)"))),
    };
    if a >= D::D {
        return Err(src.error(key, format!("axis `{name}` does not exist in {}D", D::D)));
    }
    Ok(a)
}

/// Most time steps a run may take (a duration or `--until` needing more is refused).
pub const MAX_STEPS: f64 = 1e10;

/// The CFL factor when neither `cfl` nor `dt` is given.
const DEFAULT_CFL: f64 = 0.5;

/// A scenario name becomes the output folder's name: it must be one plain path component.
fn check_name(src: &Source, name: &str) -> R<()> {
    let bad = if name.is_empty() {
        Some("must not be empty")
    } else if name.contains(['/', '\\']) {
        Some("must not contain a path separator")
    } else if name == "." || name == ".." {
        Some("must not be `.` or `..`")
    } else if name.chars().any(char::is_control) {
        Some("must not contain control characters")
    } else {
        None
    };
    match bad {
        Some(why) => Err(src.error(
            "name",
            format!("the name names the output folder under the output directory: it {why}"),
        )),
        None => Ok(()),
    }
}

/// Refuses a probe's or crack's name that would break the CSV files it heads or fills: an
/// empty one, or one with a comma, a double quote or a control character.
pub(super) fn csv_name(src: &Source, key: &str, name: &str) -> R<()> {
    if name.is_empty() || name.contains([',', '"']) || name.chars().any(char::is_control) {
        return Err(src.error(
            key,
            format!(
                "`{}` names a column or rows of the CSV outputs: give a non-empty name without \
                 commas, double quotes or control characters",
                name.escape_debug()
            ),
        ));
    }
    Ok(())
}

/// The index of the material called `name`, refused under `key` if there is none.
pub(super) fn material_named(
    src: &Source,
    key: &str,
    materials: &[Material],
    name: &str,
) -> R<usize> {
    (materials.iter().position(|m| m.name == name))
        .ok_or_else(|| src.error(key, format!("no [[material]] named `{name}`")))
}

pub(super) fn positive(src: &Source, key: &str, v: f64, unit: &str) -> R<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(src.error(key, format!("must be a positive number ({unit}), got {v}")))
    }
}

fn bounds<D: Dim>(src: &Source, key: &str, b: &BoxSpec) -> R<([f64; 3], [f64; 3])> {
    let lo = vec3::<D>(src, &format!("{key}.min"), &b.min)?;
    let hi = vec3::<D>(src, &format!("{key}.max"), &b.max)?;
    if (0..D::D).any(|a| hi[a] < lo[a]) {
        return Err(src.error(&format!("{key}.max"), "max must not be below min"));
    }
    Ok((lo, hi))
}

/// Builds the scene described by `src` in dimension `D`.
pub fn build<D: Dim>(src: &Source) -> R<Scene<D>> {
    let sc = &src.scenario;
    let sim = &sc.simulation;
    if let Some(name) = &sc.name {
        check_name(src, name)?;
    }
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

    // Grid.
    let mut gmin = vec3::<D>(src, "grid.min", &sc.grid.min)?;
    let mut gmax = vec3::<D>(src, "grid.max", &sc.grid.max)?;
    let cell = vec3::<D>(src, "grid.cell", &sc.grid.cell)?;
    let mut cells = [1usize; 3];
    let mut h = [1.0; 3];
    let mut node_count = 1.0;
    for a in 0..D::D {
        h[a] = positive(src, "grid.cell", cell[a], "m")?;
        if gmax[a] <= gmin[a] {
            return Err(src.error("grid.max", "grid max must exceed grid min on every axis"));
        }
    }
    if let Some(anchor) = &sc.grid.anchor {
        (gmin, gmax) = anchored::<D>(src, anchor, gmin, gmax, h)?;
    }
    for a in 0..D::D {
        let n = (gmax[a] - gmin[a]) / h[a];
        if (n - n.round()).abs() > 1e-6 * n.max(1.0) {
            return Err(src.error(
                "grid.cell",
                format!("the grid extent on axis {a} is {n:.6} cells; it must be a whole number"),
            ));
        }
        node_count *= n.round() + 1.0;
        if node_count > MAX_NODES {
            return Err(src.error("grid.cell", "grid too large (more than 2e8 nodes)"));
        }
        cells[a] = n.round() as usize;
        if cells[a] < 2 {
            return Err(src.error("grid.cell", "the grid needs at least 2 cells per axis"));
        }
    }
    let geom = GridGeom::<D>::new(to_vec::<D>(gmin), to_vec::<D>(h), cells);

    let materials = super::material::materials(src, &sc.materials)?;

    // Bodies.
    if sc.bodies.is_empty() {
        return Err(src.error("body", "the scenario has no [[body]]"));
    }
    // The particles the bodies can hold at most (their bounding boxes filled), before any
    // is made, so that a scene too large for the machine is refused at once.
    let mut most = 0.0;
    for (b, body) in sc.bodies.iter().enumerate() {
        let (lo, hi) = geometry::<D>(src, b, body)?.bounds();
        let mut n = 1.0;
        for a in 0..D::D {
            let span = (hi[a].min(gmax[a]) - lo[a].max(gmin[a])).max(0.0);
            n *= (span / h[a] + 2.0) * body.ppc.clamp(1, 16) as f64;
        }
        most += n;
    }
    super::memory::check(src, D::D, most, node_count, super::memory::available())?;
    let mut particles = Particles::<D>::default();
    let shape = sim.shape;
    let mut used = vec![false; materials.len()];
    // Particles per cell per direction of each particle's body (for face tractions).
    let mut ppc = Vec::new();
    let mut claims = Vec::new();
    for (b, body) in sc.bodies.iter().enumerate() {
        add_body::<D>(
            src,
            b,
            body,
            &geom,
            &materials,
            &mut used,
            shape,
            thickness,
            &mut particles,
            &mut claims,
        )?;
        ppc.resize(particles.len(), body.ppc as f64);
    }

    // Store particles tile by tile, so the tile-ordered scatter streams through memory.
    let tiles = Tiles::new::<D>(tile, cells);
    let mut keyed: Vec<(u32, u32)> = (0..particles.len())
        .map(|i| {
            let x = particles.x[i];
            let mut cell = [0; 3];
            for a in 0..D::D {
                cell[a] = ((x[a] - geom.origin[a]) * geom.inv_h[a]) as usize;
            }
            (tiles.tile_of_cell(cell), i as u32)
        })
        .collect();
    keyed.sort_unstable();
    particles.permute(&keyed.iter().map(|k| k.1).collect::<Vec<_>>());
    let ppc: Vec<f64> = keyed.iter().map(|k| ppc[k.1 as usize]).collect();

    // Time step.
    let c_max = materials
        .iter()
        .zip(&used)
        .filter(|(_, u)| **u)
        .map(|(m, _)| m.wave_speed(plane))
        .fold(0.0, f64::max);
    let dt_limit = geom.min_cell() / c_max;
    let dt = match sim.dt {
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
        None => cfl * dt_limit,
    };
    if duration / dt > MAX_STEPS {
        return Err(src.error(
            "simulation.duration",
            format!("more than {MAX_STEPS:e} time steps"),
        ));
    }

    // Boundary conditions.
    let mut bcs = Vec::new();
    for (i, bc) in sc.boundaries.iter().enumerate() {
        let key = |k: &str| format!("boundary[{i}].{k}");
        let (nodes, normal) = match (&bc.region, &bc.plane) {
            (Some(r), None) => {
                let r = region::<D>(src, &key("region"), r)?;
                let tol = 1e-6 * (0..D::D).map(|a| h[a]).fold(f64::INFINITY, f64::min);
                let nodes: Vec<u32> = (0..geom.node_count())
                    .filter(|&n| r.contains(D::to_xyz(geom.node_position(n)), D::D, tol))
                    .map(|n| n as u32)
                    .collect();
                (nodes, None)
            }
            (None, Some(p)) => {
                let a = axis_index::<D>(src, &key("plane.axis"), &p.axis)?;
                let nodes: Vec<u32> = (0..geom.node_count())
                    .filter(|&n| (geom.node_position(n)[a] - p.at).abs() <= 1e-6 * h[a])
                    .map(|n| n as u32)
                    .collect();
                (nodes, Some(a))
            }
            _ => {
                return Err(src.error(
                    &format!("boundary[{i}]"),
                    "give exactly one of `region` or `plane`",
                ));
            }
        };
        if nodes.is_empty() {
            return Err(src.error(
                &format!("boundary[{i}]"),
                "selects no grid node (a plane must lie on a grid line)",
            ));
        }
        let mut axes = [false; 3];
        match (&bc.fix, normal) {
            (Some(list), _) => {
                for (k, c) in list.iter().enumerate() {
                    axes[axis_index::<D>(src, &format!("boundary[{i}].fix[{k}]"), c)?] = true;
                }
            }
            (None, Some(a)) => axes[a] = true,
            (None, None) => axes[..D::D].iter_mut().for_each(|x| *x = true),
        }
        let velocity = match &bc.velocity {
            Some(v) => vec3::<D>(src, &key("velocity"), v)?,
            None => [0.0; 3],
        };
        if let Some(msg) = bc.time.check() {
            return Err(src.error(&key("time"), msg));
        }
        bcs.push(VelocityBc {
            reaction: vec![D::zero(); nodes.len()],
            nodes,
            axes,
            velocity: to_vec::<D>(velocity),
            time: bc.time.clone(),
        });
    }

    // Loads.
    let select = |key: &str, r: &RegionSpec| -> R<Vec<u32>> {
        let r = region::<D>(src, key, r)?;
        let sel: Vec<u32> = (0..particles.len())
            .filter(|&p| r.contains(D::to_xyz(particles.x[p]), D::D, 0.0))
            .map(|p| p as u32)
            .collect();
        if sel.is_empty() {
            return Err(src.error(key, "the region contains no particle"));
        }
        Ok(sel)
    };
    let mut loads = Vec::new();
    for (i, l) in sc.loads.iter().enumerate() {
        let key = |k: &str| format!("load[{i}].{k}");
        let sel = select(&key("region"), &l.region)?;
        if let Some(msg) = l.time.check() {
            return Err(src.error(&key("time"), msg));
        }
        let forces = match (&l.force, Field::of::<D>(src, &key, l)?) {
            (Some(f), None) => {
                if l.normal.is_some() {
                    return Err(src.error(&key("normal"), "`normal` goes with a traction"));
                }
                let f = vec3::<D>(src, &key("force"), f)?;
                vec![to_vec::<D>(f.map(|c| c / sel.len() as f64)); sel.len()]
            }
            (None, Some(field)) => {
                let face = Face::new::<D>(src, &key, l, geom.h)?;
                tractions(src, &face, &field, &sel, &particles, &ppc)?
            }
            (Some(_), Some(_)) => {
                return Err(src.error(&key("force"), "give a force or a traction, not both"));
            }
            (None, None) => {
                return Err(src.error(
                    &format!("load[{i}]"),
                    "give `force` (total N), or a traction: `pressure`, `williams` or \
                     `centre_crack`",
                ));
            }
        };
        loads.push(Load {
            forces,
            particles: sel,
            time: l.time.clone(),
        });
    }

    // Probes.
    let mut probes: Vec<Probe> = Vec::new();
    for (i, p) in sc.probes.iter().enumerate() {
        let key = |k: &str| format!("probe[{i}].{k}");
        csv_name(src, &key("name"), &p.name)?;
        if probes.iter().any(|q| q.name == p.name) {
            return Err(src.error(&key("name"), format!("duplicate probe `{}`", p.name)));
        }
        let qty = match p.quantity.as_str() {
            "displacement" => ProbeQty::Displacement,
            "velocity" => ProbeQty::Velocity,
            "position" => ProbeQty::Position,
            "stress" => ProbeQty::Stress,
            "strain" => ProbeQty::Strain,
            "opening" => ProbeQty::Opening,
            "plastic_radius" => ProbeQty::PlasticRadius,
            "reaction" => ProbeQty::Reaction,
            other => {
                return Err(src.error(
                    &key("quantity"),
                    format!(
                        "unknown quantity `{other}` (displacement, velocity, position, stress, \
                         strain, opening, plastic_radius, reaction)"
                    ),
                ));
            }
        };
        let component = match (&p.component, qty) {
            (None, ProbeQty::PlasticRadius) => None,
            (Some(_), ProbeQty::PlasticRadius) => {
                return Err(src.error(&key("component"), "a plastic radius has no component"));
            }
            (Some(c), _) => Some(c.as_str()),
            (None, _) => {
                return Err(src.error(&key("component"), "give the probed component"));
            }
        };
        let comp = match (component, qty) {
            (None, _) => 0,
            (Some(c), ProbeQty::Stress | ProbeQty::Strain) => ["xx", "yy", "zz", "yz", "xz", "xy"]
                .iter()
                .position(|t| *t == c)
                .ok_or_else(|| {
                    src.error(
                        &key("component"),
                        "tensor component must be xx, yy, zz, yz, xz or xy",
                    )
                })?,
            (Some(c), _) => axis_index::<D>(src, &key("component"), c)?,
        };
        if qty == ProbeQty::Reaction {
            let (supports, centre) = supports::<D>(src, &key, &p.region, &bcs, &geom, comp)?;
            probes.push(Probe {
                name: p.name.clone(),
                particles: Vec::new(),
                supports,
                qty,
                comp,
                centre,
            });
            continue;
        }
        let sel = select(&key("region"), &p.region)?;
        let mut centre = [0.0; 3];
        for &q in &sel {
            let x = D::to_xyz(particles.x[q as usize]);
            for a in 0..3 {
                centre[a] += x[a] / sel.len() as f64;
            }
        }
        if qty == ProbeQty::PlasticRadius {
            if !materials.iter().any(|m| m.j2.is_some()) {
                return Err(src.error(
                    &key("quantity"),
                    "a plastic radius needs a plastic material (model = \"j2\")",
                ));
            }
            match region::<D>(src, &key("region"), &p.region)? {
                Region::Round { center, .. } => centre = center,
                _ => {
                    return Err(src.error(
                        &key("region"),
                        "a plastic radius is measured from the centre of a disc or ball \
                         region: give `center` and `radius`",
                    ));
                }
            }
        }
        if qty == ProbeQty::Opening {
            let beyond = (sel.iter())
                .filter(|&&q| D::to_xyz(particles.x[q as usize])[comp] > centre[comp])
                .count();
            if beyond == 0 || beyond == sel.len() {
                return Err(src.error(
                    &key("region"),
                    format!(
                        "an opening probe needs particles on both sides of its region's \
                         centroid along {}: this region has them on one side",
                        component.unwrap_or_default()
                    ),
                ));
            }
        }
        probes.push(Probe {
            name: p.name.clone(),
            particles: sel,
            supports: Vec::new(),
            qty,
            comp,
            centre,
        });
    }

    // Expectations.
    let mut expects = Vec::new();
    for (i, e) in sc.expects.iter().enumerate() {
        let key = |k: &str| format!("expect[{i}].{k}");
        let mut ids = Vec::new();
        for name in &e.probes {
            let id = probes
                .iter()
                .position(|p| &p.name == name)
                .ok_or_else(|| src.error(&key("probes"), format!("no probe named `{name}`")))?;
            ids.push(id);
        }
        // Crack-tip quantities name a crack and a tip instead of probes.
        let tip_qty = ["KI", "KII", "J1", "J2"]
            .iter()
            .position(|q| *q == e.quantity);
        if e.from.is_some()
            && !["K_drift", "kinetic_fraction", "slope"].contains(&e.quantity.as_str())
        {
            return Err(src.error(
                &key("from"),
                "`from` applies to K_drift, kinetic_fraction and slope",
            ));
        }
        let front_qty = ["KI_front", "KII_front", "KIII_front", "J1_front"]
            .iter()
            .position(|q| *q == e.quantity);
        let tip_like = tip_qty.is_some() || ["K_drift", "J_eta"].contains(&e.quantity.as_str());
        if e.eta.is_some() && e.quantity != "J_eta" {
            return Err(src.error(&key("eta"), "`eta` applies to J_eta"));
        }
        if D::D == 3 && tip_like {
            return Err(src.error(
                &key("quantity"),
                format!(
                    "`{}` is measured at a 2D crack tip; along a 3D front use KI_front, \
                     KII_front, KIII_front or J1_front",
                    e.quantity
                ),
            ));
        }
        let path_3d = D::D == 3 && e.quantity == "J_path";
        for (k, given, also) in [
            ("along", e.along.is_some(), ""),
            ("near", e.near.is_some() && !path_3d, " (and J_path in 3D)"),
        ] {
            if given && front_qty.is_none() {
                return Err(src.error(
                    &key(k),
                    format!("`{k}` applies to KI_front, KII_front, KIII_front and J1_front{also}"),
                ));
            }
        }
        if D::D == 2 && front_qty.is_some() {
            return Err(src.error(
                &key("quantity"),
                format!(
                    "`{}` runs along a 3D crack front; at a 2D tip use KI, KII, J1 or J2",
                    e.quantity
                ),
            ));
        }
        let crack_measure = match (tip_qty, front_qty) {
            (Some(qty), _) => Some(super::cracks::tip_measure(src, i, e, qty)?),
            (_, Some(qty)) => Some(super::cracks::front_measure(src, i, e, qty)?),
            _ if e.quantity == "J_path" => {
                Some(super::cracks::path_measure::<D>(src, i, e, &geom)?)
            }
            _ if e.quantity == "K_drift" => Some(super::cracks::drift_measure(src, i, e)?),
            _ if e.quantity == "J_eta" => Some(super::eta::eta_measure(
                src, i, e, &ids, &materials, plane, thickness,
            )?),
            _ if ["kink", "path_angle", "turn", "cycles"].contains(&e.quantity.as_str()) => {
                if D::D == 3 && !["cycles", "kink"].contains(&e.quantity.as_str()) {
                    return Err(src.error(
                        &key("quantity"),
                        format!("`{}` follows a growing 2D tip", e.quantity),
                    ));
                }
                Some(super::growth::growth_measure(src, i, e, D::D == 3)?)
            }
            _ => None,
        };
        if let Some(measure) = crack_measure {
            positive(src, &key("tolerance"), e.tolerance, "relative")?;
            if !ids.is_empty() && e.quantity != "J_eta" {
                return Err(src.error(
                    &key("probes"),
                    format!("`{}` is read at a crack: it takes no probes", e.quantity),
                ));
            }
            expects.push(Expect {
                quantity: e.quantity.clone(),
                probes: e
                    .crack
                    .iter()
                    .cloned()
                    .chain([e.tip.clone().unwrap_or_else(|| match &e.near {
                        Some(p) if D::D == 3 => format!("near {p:?}"),
                        _ if D::D == 3 => "front".into(),
                        _ => "end".into(),
                    })])
                    .chain(e.at.map(|t| format!("t={t:.3e}")))
                    .chain(e.probes.iter().cloned())
                    .collect(),
                measure,
                reference: e.reference,
                source: e.source.clone(),
                tolerance: e.tolerance,
            });
            continue;
        }
        if let Some(at) = e.at {
            let end = src.scenario.simulation.duration;
            if e.quantity != "final" {
                return Err(src.error(&key("at"), "`at` applies to final, KI, KII, J1 and J2"));
            }
            if !(0.0..=end).contains(&at) {
                return Err(src.error(
                    &key("at"),
                    format!("the time must lie in the run, 0 to {end:.4e} s"),
                ));
            }
        }
        if e.length.is_some() {
            return Err(src.error(&key("length"), "`length` applies to cycles"));
        }
        let need = match e.quantity.as_str() {
            "wave_speed" | "slope" => 2,
            "final" | "max" | "min" | "frequency" => 1,
            "momentum_drift" | "energy_drift" | "angular_momentum_drift" | "kinetic_fraction" => 0,
            other => {
                return Err(src.error(
                    &key("quantity"),
                    format!(
                        "unknown quantity `{other}` (final, max, min, frequency, wave_speed, \
                         slope, momentum_drift, energy_drift, angular_momentum_drift, KI, KII, J1, J2, \
                         J_path, K_drift, J_eta, kinetic_fraction, KI_front, KII_front, \
                         KIII_front, J1_front, kink, path_angle, turn, cycles)"
                    ),
                ));
            }
        };
        if ids.len() != need {
            return Err(src.error(
                &key("probes"),
                format!(
                    "`{}` takes {need} probe name(s), got {}",
                    e.quantity,
                    ids.len()
                ),
            ));
        }
        let measure = match e.quantity.as_str() {
            "final" => Measure::Final {
                probe: ids[0],
                at: e.at,
            },
            "max" => Measure::Max(ids[0]),
            "min" => Measure::Min(ids[0]),
            "frequency" => Measure::Frequency(ids[0]),
            "wave_speed" => Measure::WaveSpeed(ids[0], ids[1]),
            "slope" => {
                let end = src.scenario.simulation.duration;
                match e.from {
                    Some(from) if (0.0..end).contains(&from) => Measure::Slope {
                        rise: ids[0],
                        run: ids[1],
                        from,
                    },
                    _ => {
                        return Err(src.error(
                            &key("from"),
                            format!(
                                "`slope` is the change of its first probe over its second's \
                                 from `from` to the end: give `from`, 0 to {end:.4e} s"
                            ),
                        ));
                    }
                }
            }
            "momentum_drift" => Measure::MomentumDrift,
            "energy_drift" => Measure::EnergyDrift,
            "kinetic_fraction" => {
                let end = src.scenario.simulation.duration;
                match e.from {
                    Some(from) if (0.0..end).contains(&from) => Measure::KineticFraction { from },
                    _ => {
                        return Err(src.error(
                            &key("from"),
                            format!(
                                "`kinetic_fraction` runs over a window: give its start \
                                 `from`, 0 to {end:.4e} s"
                            ),
                        ));
                    }
                }
            }
            _ => Measure::AngularMomentumDrift,
        };
        if !e.reference.is_finite() {
            return Err(src.error(&key("reference"), "must be a finite number"));
        }
        positive(
            src,
            &key("tolerance"),
            e.tolerance,
            "relative, or absolute for reference 0",
        )?;
        expects.push(Expect {
            quantity: e.quantity.clone(),
            probes: e.probes.clone(),
            measure,
            reference: e.reference,
            source: e.source.clone(),
            tolerance: e.tolerance,
        });
    }

    let out = &sc.output;
    let interval = match out.interval {
        Some(v) => positive(src, "output.interval", v, "s")?,
        None => duration / 20.0,
    };
    let history_interval = match out.history_interval {
        Some(v) => positive(src, "output.history_interval", v, "s")?,
        None => duration / 400.0,
    };
    let checkpoint = checkpoint_plan(src)?;
    let cracks = super::cracks::build::<D>(src, &particles, &materials, &geom, dt)?;
    let fracture = super::cracks::fracture_plan(src, cracks.as_ref(), &geom)?;
    super::cracks::check_front_expects(src, &expects, cracks.as_ref(), geom.min_cell())?;
    if fracture.is_some() {
        particles.grad_u = vec![D::mat_zero(); particles.len()];
        particles.grad_v = vec![D::mat_zero(); particles.len()];
    }
    // Plastic state is kept only when a body is made of a plastic material.
    if materials
        .iter()
        .zip(&used)
        .any(|(m, &u)| u && m.j2.is_some())
    {
        particles.make_plastic();
    }
    let min_mass = particles.mass.iter().copied().fold(f64::INFINITY, f64::min);
    let world = World {
        tiles,
        grid: Grid::new(geom),
        particles,
        materials,
        settings: Settings {
            shape,
            update: sim.update,
            plane,
            damping: sim.damping,
            gravity: to_vec::<D>(gravity),
            dt,
            mass_tol: 1e-12 * min_mass,
            sliver_mass: 1e-3 * min_mass,
            thickness,
        },
        loads,
        bcs,
        time: 0.0,
        step: 0,
        work: Work::default(),
        cracks,
    };
    Ok(Scene {
        name: src.name(),
        world,
        probes,
        expects,
        duration,
        output: OutputPlan {
            interval,
            history_interval,
            vtk: out.vtk.unwrap_or(true),
            plot: out.plot.unwrap_or(true),
        },
        dt_limit,
        checkpoint,
        fracture,
    })
}

/// The `[checkpoint]` table, checked.
fn checkpoint_plan(src: &Source) -> R<CheckpointPlan> {
    let c = &src.scenario.checkpoint;
    if c.every_steps == Some(0) {
        return Err(src.error("checkpoint.every_steps", "must be at least 1"));
    }
    let every_time = c
        .every_time
        .map(|t| positive(src, "checkpoint.every_time", t, "s"))
        .transpose()?;
    let every_wall = c
        .every_wall_minutes
        .map(|m| positive(src, "checkpoint.every_wall_minutes", m, "min"))
        .transpose()?
        .map(|m| std::time::Duration::from_secs_f64((m * 60.0).min(1e12)));
    if c.keep == Some(0) {
        return Err(src.error("checkpoint.keep", "must keep at least 1 snapshot"));
    }
    Ok(CheckpointPlan {
        every_steps: c.every_steps,
        every_time,
        every_wall,
        keep: c.keep.unwrap_or(2),
    })
}

/// The grid's extent widened to whole cells of the lattice `anchor` lays: nodes at
/// `point + (k + offset) h` per axis. A bound already on the lattice (to a billionth of a
/// cell) is kept as given, so an anchor that agrees with `min` changes nothing.
fn anchored<D: Dim>(
    src: &Source,
    anchor: &AnchorSpec,
    min: [f64; 3],
    max: [f64; 3],
    h: [f64; 3],
) -> R<([f64; 3], [f64; 3])> {
    let point = vec3::<D>(src, "grid.anchor.point", &anchor.point)?;
    let offset = match &anchor.offset {
        Some(o) => vec3::<D>(src, "grid.anchor.offset", o)?,
        None => [0.0; 3],
    };
    if offset.iter().any(|o| !(0.0..1.0).contains(o)) {
        return Err(src.error(
            "grid.anchor.offset",
            "offsets are fractions of a cell in [0, 1)",
        ));
    }
    let (mut lo, mut hi) = (min, max);
    for a in 0..D::D {
        let origin = point[a] + offset[a] * h[a];
        let node = |k: f64| origin + k * h[a];
        let snap = |x: f64, k: f64| {
            if (node(k) - x).abs() <= 1e-9 * h[a] {
                x
            } else {
                node(k)
            }
        };
        let first = ((min[a] - origin) / h[a] + 1e-9).floor();
        let last = ((max[a] - origin) / h[a] - 1e-9).ceil();
        lo[a] = snap(min[a], first);
        hi[a] = snap(max[a], last);
    }
    Ok((lo, hi))
}

/// The radius of a ring's or a spherical shell's hole: in [0, radius) (m).
fn hole(src: &Source, key: &str, round: &RoundSpec) -> R<f64> {
    if (0.0..round.radius).contains(&round.inner_radius) {
        Ok(round.inner_radius)
    } else {
        Err(src.error(
            key,
            format!(
                "the hole's radius must lie in [0, radius = {:e}) m",
                round.radius
            ),
        ))
    }
}

/// A prescribed-velocity node: (its boundary, its place in that boundary's node list).
type Support = (u32, u32);

/// A reaction probe's nodes, with their centroid: every prescribed-velocity node inside
/// `region` (within a millionth of a cell, as boundaries select them), as (boundary, place
/// in its node list), refused when none of them prescribes component `comp`.
fn supports<D: Dim>(
    src: &Source,
    key: &dyn Fn(&str) -> String,
    spec: &RegionSpec,
    bcs: &[VelocityBc<D>],
    geom: &GridGeom<D>,
    comp: usize,
) -> R<(Vec<Support>, [f64; 3])> {
    let r = region::<D>(src, &key("region"), spec)?;
    let tol = 1e-6 * (0..D::D).map(|a| geom.h[a]).fold(f64::INFINITY, f64::min);
    let mut supports = Vec::new();
    for (b, bc) in bcs.iter().enumerate().filter(|(_, bc)| bc.axes[comp]) {
        for (k, &n) in bc.nodes.iter().enumerate() {
            if r.contains(D::to_xyz(geom.node_position(n as usize)), D::D, tol) {
                supports.push((b as u32, k as u32));
            }
        }
    }
    if supports.is_empty() {
        return Err(src.error(
            &key("region"),
            "a reaction probe's region holds no grid node of a [[boundary]] that prescribes \
             its component",
        ));
    }
    let mut centre = [0.0; 3];
    for &(b, k) in &supports {
        let x = D::to_xyz(geom.node_position(bcs[b as usize].nodes[k as usize] as usize));
        (0..3).for_each(|a| centre[a] += x[a] / supports.len() as f64);
    }
    Ok((supports, centre))
}

/// The geometry of body `b`, from exactly one geometry key.
fn geometry<D: Dim>(src: &Source, b: usize, body: &BodySpec) -> R<Geometry> {
    let key = |k: &str| format!("body[{b}].{k}");
    let given = [
        body.box_.is_some(),
        body.disc.is_some(),
        body.sphere.is_some(),
        body.cylinder.is_some(),
        body.polygon.is_some(),
    ];
    if given.iter().filter(|g| **g).count() != 1 {
        return Err(src.error(
            &format!("body[{b}]"),
            "give exactly one geometry: box, disc (2D), sphere (3D), cylinder (3D) or polygon",
        ));
    }
    if let Some(bx) = &body.box_ {
        let (min, max) = bounds::<D>(src, &key("box"), bx)?;
        return Ok(Geometry::Box { min, max });
    }
    if let Some(d) = &body.disc {
        if D::D != 2 {
            return Err(src.error(&key("disc"), "disc is 2D; use sphere or cylinder in 3D"));
        }
        return Ok(Geometry::Round {
            center: vec3::<D>(src, &key("disc.center"), &d.center)?,
            radius: positive(src, &key("disc.radius"), d.radius, "m")?,
            inner: hole(src, &key("disc.inner_radius"), d)?,
            sphere: false,
        });
    }
    if let Some(s) = &body.sphere {
        if D::D != 3 {
            return Err(src.error(&key("sphere"), "sphere is 3D; use disc in 2D"));
        }
        return Ok(Geometry::Round {
            center: vec3::<D>(src, &key("sphere.center"), &s.center)?,
            radius: positive(src, &key("sphere.radius"), s.radius, "m")?,
            inner: hole(src, &key("sphere.inner_radius"), s)?,
            sphere: true,
        });
    }
    if let Some(c) = &body.cylinder {
        if D::D != 3 {
            return Err(src.error(&key("cylinder"), "cylinder is 3D; use disc in 2D"));
        }
        let radius = positive(src, &key("cylinder.radius"), c.radius, "m")?;
        if !(0.0..radius).contains(&c.inner_radius) {
            return Err(src.error(
                &key("cylinder.inner_radius"),
                format!("the bore's radius must lie in [0, radius = {radius:e}) m"),
            ));
        }
        return Ok(Geometry::Cylinder {
            center: vec3::<D>(src, &key("cylinder.center"), &c.center)?,
            axis: axis_index::<D>(src, &key("cylinder.axis"), &c.axis)?,
            radius,
            inner: c.inner_radius,
            length: positive(src, &key("cylinder.length"), c.length, "m")?,
        });
    }
    let p = body.polygon.as_ref().expect("one geometry is given");
    if p.points.len() < 3 {
        return Err(src.error(&key("polygon.points"), "a polygon needs at least 3 points"));
    }
    let mut points = Vec::new();
    for (k, pt) in p.points.iter().enumerate() {
        if pt.len() != 2 || pt.iter().any(|c| !c.is_finite()) {
            return Err(src.error(
                &key(&format!("polygon.points[{k}]")),
                "polygon points are [x, y] pairs of finite numbers",
            ));
        }
        points.push([pt[0], pt[1]]);
    }
    super::region::simple_polygon(src, &key("polygon.points"), &points)?;
    let z = match (&p.z, D::D) {
        (Some(z), 3) if z.len() == 2 && z[1] > z[0] => Some([z[0], z[1]]),
        (None, 2) => None,
        (None, _) => {
            return Err(src.error(
                &key("polygon"),
                "a 3D polygon needs its extrusion z = [z0, z1]",
            ));
        }
        (Some(_), 2) => return Err(src.error(&key("polygon.z"), "z applies to 3D scenes only")),
        (Some(_), _) => return Err(src.error(&key("polygon.z"), "z must be [z0, z1] with z1 > z0")),
    };
    Ok(Geometry::Polygon { points, z })
}

/// Fills body `b` with particles, less the points of the bodies before it (`claims`, to
/// which it adds its own), and appends them to the store.
#[allow(clippy::too_many_arguments)]
fn add_body<D: Dim>(
    src: &Source,
    b: usize,
    body: &BodySpec,
    geom: &GridGeom<D>,
    materials: &[Material],
    used: &mut [bool],
    shape: ShapeKind,
    thickness: f64,
    particles: &mut Particles<D>,
    claims: &mut Vec<Claim>,
) -> R<()> {
    let key = |k: &str| format!("body[{b}].{k}");
    let mat = material_named(src, &key("material"), materials, &body.material)?;
    used[mat] = true;
    if !(1..=16).contains(&body.ppc) {
        return Err(src.error(
            &key("ppc"),
            "particles per cell per direction must be 1..=16",
        ));
    }
    let g = geometry::<D>(src, b, body)?;
    let (lo, hi) = g.bounds();
    let origin = D::to_xyz(geom.origin);
    let h = D::to_xyz(geom.h);
    let mut estimate = 1.0;
    for a in 0..D::D {
        estimate *= ((hi[a] - lo[a]) / h[a] + 2.0) * body.ppc as f64;
    }
    if estimate > MAX_PARTICLES {
        return Err(src.error(
            &format!("body[{b}]"),
            "body would need more than 2e8 particles",
        ));
    }
    let mut pts = fill(&g, D::D, origin, h, geom.cells, body.ppc);
    let clip = match &body.clip {
        Some(clip) => Some(super::region::region::<D>(src, &key("clip"), clip)?),
        None => None,
    };
    if let Some(clip) = &clip {
        pts.retain(|x| clip.contains(*x, D::D, 0.0));
    }
    let mut holes = Vec::new();
    for (k, hole) in body.holes.iter().enumerate() {
        let key = key(&format!("holes[{k}]"));
        let center = vec3::<D>(src, &format!("{key}.center"), &hole.center)?;
        let r = positive(src, &format!("{key}.radius"), hole.radius, "m")?;
        if hole.inner_radius != 0.0 {
            return Err(src.error(
                &format!("{key}.inner_radius"),
                "`inner_radius` does not apply to a hole",
            ));
        }
        pts.retain(|x| (0..D::D).map(|a| (x[a] - center[a]).powi(2)).sum::<f64>() >= r * r);
        holes.push((center, r));
    }
    let earlier: Vec<&Claim> = (claims.iter())
        .filter(|c| c.reaches((lo, hi), D::D))
        .collect();
    if !earlier.is_empty() {
        pts.retain(|x| !earlier.iter().any(|c| c.contains(*x, D::D)));
    }
    if pts.is_empty() {
        return Err(src.error(
            &format!("body[{b}]"),
            "body contains no particle (is it smaller than a particle spacing, outside the grid, \
             clipped or cut away, or covered by the bodies listed before it?)",
        ));
    }
    let n = body.ppc as f64;
    let mut volume = thickness;
    let mut half = [0.0; 3];
    for a in 0..D::D {
        volume *= h[a] / n;
        half[a] = 0.5 * h[a] / n;
    }
    let v0 = match &body.velocity {
        Some(v) => vec3::<D>(src, &key("velocity"), v)?,
        None => [0.0; 3],
    };
    let omega = match &body.angular_velocity {
        None => [0.0; 3],
        Some(w) if D::D == 2 && w.len() == 1 => [0.0, 0.0, w[0]],
        Some(w) if D::D == 3 && w.len() == 3 => [w[0], w[1], w[2]],
        Some(_) => {
            return Err(src.error(
                &key("angular_velocity"),
                "give one value (rad/s, about z) in 2D or three in 3D",
            ));
        }
    };
    let centre = match &body.spin_center {
        Some(c) => vec3::<D>(src, &key("spin_center"), c)?,
        None => [0, 1, 2].map(|a| 0.5 * (lo[a] + hi[a])),
    };
    let rho = materials[mat].density;
    for x in pts {
        if !geom.fits(shape, to_vec::<D>(x), to_vec::<D>(half)) {
            return Err(src.error(
                &format!("body[{b}]"),
                format!(
                    "body extends beyond the grid: a particle at ({:.4e}, {:.4e}, {:.4e}) m needs \
                     its shape-function support inside the grid; enlarge the grid by a cell",
                    x[0], x[1], x[2]
                ),
            ));
        }
        let r = [0, 1, 2].map(|a| x[a] - centre[a]);
        let spin = [
            omega[1] * r[2] - omega[2] * r[1],
            omega[2] * r[0] - omega[0] * r[2],
            omega[0] * r[1] - omega[1] * r[0],
        ];
        let v = [0, 1, 2].map(|a| v0[a] + spin[a]);
        particles.push(
            to_vec::<D>(x),
            to_vec::<D>(v),
            rho * volume,
            volume,
            mat as u16,
        );
        if shape == ShapeKind::Ugimp {
            particles.half.push(to_vec::<D>(half));
        }
    }
    claims.push(Claim {
        geometry: g,
        clip,
        holes,
        bounds: (lo, hi),
    });
    Ok(())
}
