//! The `[[body]]` tables: each body's geometry filled with particles (less the points of
//! the bodies before it, its holes and its clip), then all particles stored tile by tile.

use super::check::{R, axis_index, box_corners, material_named, positive, to_vec, vec3};
use super::claim::Claim;
use super::grid::GridPlan;
use super::schema::{BodySpec, RoundSpec};
use super::source::Source;
use crate::base::dim::Dim;
use crate::physics::bodies::{Solid, fill, first_outside};
use crate::physics::material::Material;
use crate::physics::shape::ShapeKind;
use crate::store::grid::GridGeom;
use crate::store::particles::Particles;
use crate::store::tiles::Tiles;

/// Largest particle count one body may ask for.
const MAX_PARTICLES: f64 = 2.0e8;

/// The particles of every body, stored tile by tile, with what the later tables need.
pub(super) struct Filled<D: Dim> {
    /// The particle store, in tile order.
    pub particles: Particles<D>,
    /// Particles per cell per direction of each particle's body (for face tractions).
    pub ppc: Vec<f64>,
    /// Which materials some body is made of.
    pub used: Vec<bool>,
    /// The tiles the particles are ordered by.
    pub tiles: Tiles,
    /// Each body's region, in the order listed (where a crack's front may lie).
    pub claims: Vec<Claim>,
}

/// Fills every `[[body]]` in order (the first listed keeps a point two bodies share),
/// after refusing a scene whose bodies' bounding boxes would hold more particles than the
/// machine's memory; then orders the particles by tile, so the tile-ordered scatter streams
/// through memory.
pub(super) fn bodies<D: Dim>(
    src: &Source,
    grid: &GridPlan<D>,
    materials: &[Material],
    thickness: f64,
    tile: usize,
) -> R<Filled<D>> {
    let sc = &src.scenario;
    let geom = &grid.geom;
    if sc.bodies.is_empty() {
        return Err(src.missing(
            "body",
            "the scenario has no [[body]]: add one after the last line (a `material` and a \
             geometry such as `box = { min, max }`)",
        ));
    }
    let h = D::to_xyz(geom.h);
    let mut most = 0.0;
    for (b, body) in sc.bodies.iter().enumerate() {
        let (lo, hi) = geometry::<D>(src, b, body)?.bounds();
        let mut n = 1.0;
        for a in 0..D::D {
            let span = (hi[a].min(grid.max[a]) - lo[a].max(grid.min[a])).max(0.0);
            n *= (span / h[a] + 2.0) * body.ppc.clamp(1, 16) as f64;
        }
        most += n;
    }
    super::memory::check(src, D::D, most, grid.nodes, super::memory::available())?;
    let mut particles = Particles::<D>::default();
    let shape = sc.simulation.shape;
    let mut used = vec![false; materials.len()];
    let mut ppc = Vec::new();
    let mut claims = Vec::new();
    for (b, body) in sc.bodies.iter().enumerate() {
        add_body::<D>(
            src,
            b,
            body,
            geom,
            materials,
            &mut used,
            shape,
            thickness,
            &mut particles,
            &mut claims,
        )?;
        ppc.resize(particles.len(), body.ppc as f64);
    }

    let tiles = Tiles::new::<D>(tile, geom.cells);
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
    Ok(Filled {
        particles,
        ppc,
        used,
        tiles,
        claims,
    })
}

/// The geometry of body `b`, from exactly one geometry key.
fn geometry<D: Dim>(src: &Source, b: usize, body: &BodySpec) -> R<Solid> {
    let key = |k: &str| format!("body[{b}].{k}");
    let given = [
        body.box_.is_some(),
        body.disc.is_some(),
        body.sphere.is_some(),
        body.cylinder.is_some(),
        body.polygon.is_some(),
        body.mesh.is_some(),
    ];
    if given.iter().filter(|g| **g).count() != 1 {
        return Err(src.error(
            &format!("body[{b}]"),
            "give exactly one geometry: box, disc (2D), sphere (3D), cylinder (3D), polygon or \
             mesh (3D)",
        ));
    }
    if let Some(m) = &body.mesh {
        if D::D != 3 {
            return Err(src.error(&key("mesh"), "a mesh body is 3D; use polygon in 2D"));
        }
        return super::mesh_body::solid(src, &key("mesh"), m);
    }
    if let Some(bx) = &body.box_ {
        let (min, max) = box_corners::<D>(src, &key("box"), bx)?;
        return Ok(Solid::Box { min, max });
    }
    if let Some(d) = &body.disc {
        if D::D != 2 {
            return Err(src.error(&key("disc"), "disc is 2D; use sphere or cylinder in 3D"));
        }
        return Ok(Solid::Round {
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
        return Ok(Solid::Round {
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
        return Ok(Solid::Cylinder {
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
    Ok(Solid::Polygon { points, z })
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

/// The round holes of body `b`: centre and radius (m).
fn holes<D: Dim>(src: &Source, b: usize, body: &BodySpec) -> R<Vec<([f64; 3], f64)>> {
    let mut holes = Vec::new();
    for (k, hole) in body.holes.iter().enumerate() {
        let key = format!("body[{b}].holes[{k}]");
        let center = vec3::<D>(src, &format!("{key}.center"), &hole.center)?;
        let r = positive(src, &format!("{key}.radius"), hole.radius, "m")?;
        if hole.inner_radius != 0.0 {
            return Err(src.error(
                &format!("{key}.inner_radius"),
                "`inner_radius` does not apply to a hole",
            ));
        }
        holes.push((center, r));
    }
    Ok(holes)
}

/// Refuses body `b` (shape `g`, what `kept` accepts of it) when the grid would cut it,
/// naming both boxes and a point of the body outside the grid.
fn inside_grid<D: Dim>(
    src: &Source,
    b: usize,
    g: &Solid,
    geom: &GridGeom<D>,
    ppc: usize,
    kept: impl Fn([f64; 3]) -> bool,
) -> R<()> {
    let (origin, h, cells) = (D::to_xyz(geom.origin), D::to_xyz(geom.h), geom.cells);
    let Some(x) = first_outside(g, D::D, origin, h, cells, ppc, kept) else {
        return Ok(());
    };
    let (lo, hi) = g.bounds();
    let grid_hi = [0, 1, 2].map(|a| origin[a] + cells[a] as f64 * h[a]);
    let at = |p: [f64; 3]| {
        let c: Vec<String> = p[..D::D].iter().map(|c| format!("{c:.4e}")).collect();
        format!("({})", c.join(", "))
    };
    Err(src.error(
        &format!("body[{b}]"),
        format!(
            "the body reaches beyond the grid, which would cut it: the body spans {} to {} m, \
             the grid {} to {} m (the body's point {} m lies outside); enlarge the grid or \
             clip the body with `clip`",
            at(lo),
            at(hi),
            at(origin),
            at(grid_hi),
            at(x)
        ),
    ))
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
    let clip = match &body.clip {
        Some(clip) => Some(super::region::region::<D>(src, &key("clip"), clip)?),
        None => None,
    };
    let holes = holes::<D>(src, b, body)?;
    // What the clip and the holes leave of the body's shape.
    let kept = |x: &[f64; 3]| {
        clip.as_ref().is_none_or(|c| c.contains(*x, D::D, 0.0))
            && (holes.iter())
                .all(|(c, r)| (0..D::D).map(|a| (x[a] - c[a]).powi(2)).sum::<f64>() >= r * r)
    };
    let cells = geom.cells;
    inside_grid::<D>(src, b, &g, geom, body.ppc, |x| kept(&x))?;
    let mut pts = fill(&g, D::D, origin, h, cells, body.ppc);
    pts.retain(kept);
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
        Some(w) if w.iter().any(|c| !c.is_finite()) => {
            return Err(src.error(
                &key("angular_velocity"),
                "components must be finite numbers (rad/s)",
            ));
        }
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
