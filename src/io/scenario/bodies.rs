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
use crate::ranks::domain::Domain;
use crate::ranks::partition::{Partition, TileGrid};
use crate::store::grid::GridGeom;
use crate::store::particles::Particles;
use crate::store::tiles::Tiles;

/// Largest particle count one body may ask for.
const MAX_PARTICLES: f64 = 2.0e8;

/// The particles of every body (split across ranks, this rank's share), stored tile by
/// tile, with what the later tables need.
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
    /// Split across ranks, this rank's tiles (None on one rank).
    pub partition: Option<Partition>,
}

/// Fills every `[[body]]` in order (the first listed keeps a point two bodies share),
/// after refusing a scene whose bodies' bounding boxes would hold more particles than the
/// machine's memory; then orders the particles by tile, so the tile-ordered scatter streams
/// through memory. Split across ranks, each rank first counts every tile's particles
/// without storing them, divides the tiles, and then stores only its own tiles' particles,
/// each numbered by its place in the whole scene's tile order: no rank ever holds the
/// whole scene.
pub(super) fn bodies<D: Dim>(
    src: &Source,
    grid: &GridPlan<D>,
    materials: &[Material],
    thickness: f64,
    tile: usize,
    domain: &Domain,
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
    let ranks = domain.comm.size();
    // The least any rank has free (every rank takes part, whatever it could read).
    let free = domain.min(super::memory::available().unwrap_or(f64::INFINITY));
    let free = free.is_finite().then_some(free);
    super::memory::check(src, D::D, (most, ranks), grid.nodes, free)?;
    let mut used = vec![false; materials.len()];
    let mut plans = Vec::new();
    let mut claims = Vec::new();
    for (b, body) in sc.bodies.iter().enumerate() {
        let (plan, claim) = plan_body::<D>(src, b, body, geom, materials, &mut used, thickness)?;
        plans.push(plan);
        claims.push(claim);
    }
    let tiles = Tiles::new::<D>(tile, geom.cells);
    let shape = sc.simulation.shape;
    let bodies = Bodies {
        plans: &plans,
        claims: &claims,
        geom,
        shape,
        tiles: &tiles,
    };
    let partition = if domain.comm.is_split() {
        let counts = bodies.place(src, |_| false)?.counts;
        let grid = TileGrid {
            counts: tiles.counts,
            size: tiles.size,
            cells: geom.cells,
            dims: D::D,
        };
        let p = Partition::new(grid, &counts, ranks, domain.comm.rank())
            .map_err(|e| src.error("simulation.tile", e.to_string()))?;
        Some(p)
    } else {
        None
    };
    let me = domain.comm.rank();
    let placed = bodies.place(src, |t| {
        partition.as_ref().is_none_or(|p| p.owns_tile(t, me))
    })?;
    let (particles, ppc) = placed.in_scene_order(partition.is_some());
    Ok(Filled {
        particles,
        ppc,
        used,
        tiles,
        claims,
        partition,
    })
}

/// What every body puts on the lattice points it claims, and where they fall.
struct Bodies<'a, D: Dim> {
    plans: &'a [BodyPlan],
    claims: &'a [Claim],
    geom: &'a GridGeom<D>,
    shape: ShapeKind,
    tiles: &'a Tiles,
}

/// The particles of the tiles a pass kept, in fill order, with every tile's count of all
/// the bodies' particles.
struct Placed<D: Dim> {
    particles: Particles<D>,
    ppc: Vec<f64>,
    /// Particles per tile, kept or not.
    counts: Vec<u32>,
    /// Each kept particle's tile and its place among that tile's particles.
    keys: Vec<(u32, u32)>,
}

impl<D: Dim> Placed<D> {
    /// The kept particles and their particles per cell, ordered by their number in the
    /// whole scene: the particles of the tiles before their own, then their place among
    /// their tile's in fill order (one process's tile order). With `numbered`, each
    /// particle's `id` is that number.
    fn in_scene_order(self, numbered: bool) -> (Particles<D>, Vec<f64>) {
        let mut before = 0;
        let first: Vec<u64> = (self.counts.iter())
            .map(|&n| {
                let f = before;
                before += u64::from(n);
                f
            })
            .collect();
        let id: Vec<u64> = (self.keys.iter())
            .map(|&(t, k)| first[t as usize] + u64::from(k))
            .collect();
        let mut order: Vec<u32> = (0..id.len() as u32).collect();
        order.sort_unstable_by_key(|&i| id[i as usize]);
        let mut particles = self.particles;
        particles.permute(&order);
        if numbered {
            particles.id = order.iter().map(|&i| id[i as usize]).collect();
        }
        let ppc = order.iter().map(|&i| self.ppc[i as usize]).collect();
        (particles, ppc)
    }
}

impl<D: Dim> Bodies<'_, D> {
    /// Fills every body in turn, storing the particles of the tiles `keep` accepts, and
    /// refuses a body with no particle or one whose stencil would leave the grid.
    fn place(&self, src: &Source, keep: impl Fn(u32) -> bool) -> R<Placed<D>> {
        let geom = self.geom;
        let (origin, h) = (D::to_xyz(geom.origin), D::to_xyz(geom.h));
        let mut out = Placed {
            particles: Particles::default(),
            ppc: Vec::new(),
            counts: vec![0; self.tiles.len()],
            keys: Vec::new(),
        };
        for (b, (plan, claim)) in self.plans.iter().zip(self.claims).enumerate() {
            let earlier: Vec<&Claim> = (self.claims[..b].iter())
                .filter(|c| c.reaches(claim.bounds, D::D))
                .collect();
            let (mut found, mut outside) = (false, None);
            let g = &claim.geometry;
            fill(g, D::D, origin, h, geom.cells, plan.ppc, |x| {
                if outside.is_some()
                    || !claim.keeps(x, D::D)
                    || earlier.iter().any(|c| c.contains(x, D::D))
                {
                    return;
                }
                if !geom.fits(self.shape, to_vec::<D>(x), to_vec::<D>(plan.half)) {
                    outside = Some(x);
                    return;
                }
                found = true;
                let t = (self.tiles.tile_at(geom, to_vec::<D>(x)))
                    .expect("a particle whose stencil fits lies in the grid");
                if keep(t) {
                    out.keys.push((t, out.counts[t as usize]));
                    plan.push(x, self.shape, &mut out.particles);
                    out.ppc.push(plan.ppc as f64);
                }
                out.counts[t as usize] += 1;
            });
            if let Some(x) = outside {
                return Err(src.error(
                    &format!("body[{b}]"),
                    format!(
                        "body extends beyond the grid: a particle at ({:.4e}, {:.4e}, {:.4e}) m \
                         needs its shape-function support inside the grid; enlarge the grid by \
                         a cell",
                        x[0], x[1], x[2]
                    ),
                ));
            }
            if !found {
                return Err(src.error(
                    &format!("body[{b}]"),
                    "body contains no particle (is it smaller than a particle spacing, outside \
                     the grid, clipped or cut away, or covered by the bodies listed before it?)",
                ));
            }
        }
        Ok(out)
    }
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
             mesh",
        ));
    }
    if let Some(m) = &body.mesh {
        return match D::D {
            2 => super::mesh_outline::outline(src, &key("mesh"), m),
            _ => super::mesh_body::solid(src, &key("mesh"), m),
        };
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

/// What body `b` puts on each of its points but the position: material, mass, volume,
/// size and velocity.
struct BodyPlan {
    material: u16,
    ppc: usize,
    mass: f64,
    volume: f64,
    /// Half the particle's size on each axis (m).
    half: [f64; 3],
    velocity: [f64; 3],
    /// Angular velocity (rad/s) about `centre`.
    omega: [f64; 3],
    centre: [f64; 3],
}

impl BodyPlan {
    /// Appends the particle at `x`.
    fn push<D: Dim>(&self, x: [f64; 3], shape: ShapeKind, particles: &mut Particles<D>) {
        let (w, r) = (self.omega, [0, 1, 2].map(|a| x[a] - self.centre[a]));
        let spin = [
            w[1] * r[2] - w[2] * r[1],
            w[2] * r[0] - w[0] * r[2],
            w[0] * r[1] - w[1] * r[0],
        ];
        let v = [0, 1, 2].map(|a| self.velocity[a] + spin[a]);
        particles.push(
            to_vec::<D>(x),
            to_vec::<D>(v),
            self.mass,
            self.volume,
            self.material,
        );
        if shape == ShapeKind::Ugimp {
            particles.half.push(to_vec::<D>(self.half));
        }
    }
}

/// Body `b`'s particle plan and its region, checked (its material, particles per cell,
/// size, clip, holes, velocities, and that the grid does not cut it).
fn plan_body<D: Dim>(
    src: &Source,
    b: usize,
    body: &BodySpec,
    geom: &GridGeom<D>,
    materials: &[Material],
    used: &mut [bool],
    thickness: f64,
) -> R<(BodyPlan, Claim)> {
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
    let claim = Claim {
        geometry: g,
        clip,
        holes: holes::<D>(src, b, body)?,
        bounds: (lo, hi),
    };
    inside_grid::<D>(src, b, &claim.geometry, geom, body.ppc, |x| {
        claim.keeps(x, D::D)
    })?;
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
    let plan = BodyPlan {
        material: mat as u16,
        ppc: body.ppc,
        mass: materials[mat].density * volume,
        volume,
        half,
        velocity: v0,
        omega,
        centre,
    };
    Ok((plan, claim))
}
