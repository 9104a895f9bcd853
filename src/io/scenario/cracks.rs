//! Building the crack store from `[[crack]]` tables, with every check a crack needs.

use super::check::{MIN_FOLD_ANGLE, material_named, positive, to_vec, vec3};
use super::claim::Claim;
use super::schema::{AlongSpec, CrackSpec, ExpectSpec, FractureSpec};
use super::source::Source;
use super::surface;
use crate::base::dim::{D3, Dim};
use crate::base::error::ScenarioError;
use crate::base::geometry::Element;
use crate::fracture::plan::{FracturePlan, KMethod, e_prime};
use crate::physics::growth::TipState;
use crate::physics::material::{Material, Plane};
use crate::ranks::domain::Domain;
use crate::record::expect::{Along, Expect, Measure, Shape};
use crate::store::crack::{COLORS, Contact, Cracks, Law, MAX_CRACKS, Split, colors};
use crate::store::grid::GridGeom;
use crate::store::particles::Particles;
use glam::DVec3;
use std::collections::HashMap;

type R<T> = Result<T, ScenarioError>;

/// Most segments one 2D crack may have (a finer crack than a few per cell buys nothing).
const MAX_VERTICES: usize = 100_000;

/// How far (in cells, on every axis) a crack vertex may lie from the nearest particle:
/// cracks that cut through a body must reach past its edge.
const REACH_CELLS: f64 = 2.0;

/// The scene's cracks, or None when it has none (then no crack system is scheduled).
pub(super) fn build<D: Dim>(
    src: &Source,
    particles: &Particles<D>,
    domain: &Domain,
    bodies: &[Claim],
    materials: &[Material],
    geom: &GridGeom<D>,
    dt: f64,
) -> R<Option<Cracks<D>>> {
    let specs = &src.scenario.cracks;
    if specs.is_empty() {
        return Ok(None);
    }
    if specs.len() > MAX_CRACKS {
        return Err(src.error(
            &format!("crack[{MAX_CRACKS}]"),
            format!("at most {MAX_CRACKS} cracks per scene (crack indices are 16-bit)"),
        ));
    }
    let occupied = Occupied::new(particles, geom);
    let mut store = Cracks::<D>::default();
    for (c, spec) in specs.iter().enumerate() {
        let piece = piece::<D>(src, c, spec, geom, bodies)?;
        // The vertices near some particle of any rank.
        let mine: Vec<u32> = (0..piece.points.len() as u32)
            .filter(|&j| occupied.near(piece.points[j as usize]))
            .collect();
        let near = domain.union(mine);
        placed(src, &piece, geom, |j| near.binary_search(&j).is_ok())?;
        apart(src, &store, &piece, geom)?;
        let contact = contact(src, c, spec)?;
        let name = spec.name.clone().unwrap_or_else(|| format!("crack{c}"));
        super::check::csv_name(src, &format!("crack[{c}].name"), &name)?;
        if store.topology.cracks().iter().any(|k| k.name == name) {
            return Err(src.error(
                &format!("crack[{c}].name"),
                format!("two cracks are named `{name}`: expects and outputs name cracks"),
            ));
        }
        let growth = super::growth::growth::<D>(
            src,
            c,
            spec,
            materials,
            geom.min_cell(),
            dt,
            src.scenario.fracture.is_some(),
            !piece.fronts.is_empty(),
        )?;
        store.topology.add_crack(
            name,
            contact,
            growth,
            piece.points.len(),
            &piece.elems,
            &piece.fronts,
        );
        store.topology.set_split(c, split(src, c, spec)?);
        store.geometry.x.extend(&piece.points);
    }
    let h_max = (0..D::D).map(|k| geom.h[k]).fold(0.0, f64::max);
    if let Err(c) = colors::<D>(&store.topology, &store.geometry.x, h_max) {
        let name = |k: usize| &store.topology.cracks()[k].name;
        return Err(src.error(
            &format!("crack[{}]", c.crack),
            format!(
                "crack `{}` lies within reach (3.5 cells) of {COLORS} other cracks (`{}` among \
                 them): a field's mask has room for {COLORS} cracks near one place",
                name(c.crack),
                name(c.near)
            ),
        ));
    }
    let g = &mut store.geometry;
    g.top = g.x.clone();
    g.bottom = g.x.clone();
    store.tips = vec![TipState::default(); store.topology.fronts().len()];
    Ok(Some(store))
}

/// Crack `c` as a piece: a polyline in 2D, a triangulated surface in 3D that does not meet
/// itself (its front, when read from a file and not given, where it lies in `bodies`).
fn piece<D: Dim>(
    src: &Source,
    c: usize,
    spec: &CrackSpec,
    geom: &GridGeom<D>,
    bodies: &[Claim],
) -> R<Piece<D>> {
    if D::D == 2 {
        return polyline::<D>(src, c, spec, geom);
    }
    let inside = |x: DVec3| bodies.iter().any(|b| b.contains(x.to_array(), 3));
    let s = surface::surface(src, c, spec, geom.min_cell(), &inside)?;
    let piece = Piece {
        key: format!("crack[{c}]"),
        points: s
            .vertices
            .iter()
            .map(|v| D::from_slice(&v.to_array()))
            .collect(),
        elems: s
            .triangles
            .iter()
            .map(|t| D::Elem::from_vertices(t))
            .collect(),
        fronts: if s.front.is_empty() {
            Vec::new()
        } else {
            vec![(0, s.front)]
        },
    };
    let tol = 1e-6 * geom.min_cell();
    if let Some((a, b)) = super::crack_meet::self_meets::<D>(&piece.points, &piece.elems, tol) {
        let file = (spec.mesh_file.as_ref()).map_or(String::new(), |f| format!("{}: ", f.file));
        return Err(src.error(
            &piece.key,
            format!(
                "{file}the surface meets itself (triangles {a} and {b}, which share no \
                 vertex, cross or touch)"
            ),
        ));
    }
    Ok(piece)
}

/// Every vertex of `piece` lies in the grid and every front vertex in a body; the rest may
/// overhang a body's edge by any length (a crack that cuts through it), so that a scene
/// keeps its cracks when its cells are refined. Some vertex must lie in a body. `is_near`
/// tells whether vertex j lies within `REACH_CELLS` of a particle (on any rank).
fn placed<D: Dim>(
    src: &Source,
    piece: &Piece<D>,
    geom: &GridGeom<D>,
    is_near: impl Fn(u32) -> bool,
) -> R<()> {
    let front: Vec<u32> = piece.fronts.iter().flat_map(|f| f.1.clone()).collect();
    let mut touches = false;
    for (j, x) in piece.points.iter().enumerate() {
        let at = D::to_xyz(*x);
        let at = at[..D::D]
            .iter()
            .map(|c| format!("{c:e}"))
            .collect::<Vec<_>>();
        if !geom.fits(crate::physics::shape::ShapeKind::Linear, *x, D::zero()) {
            return Err(src.error(
                &piece.key,
                format!("vertex {j} at ({}) m lies outside the grid", at.join(", ")),
            ));
        }
        let near = is_near(j as u32);
        touches |= near;
        if !near && front.contains(&(j as u32)) {
            return Err(src.error(
                &piece.key,
                format!(
                    "front vertex {j} at ({}) m is outside every body (more than \
                     {REACH_CELLS} cells from any particle)",
                    at.join(", ")
                ),
            ));
        }
    }
    if !touches {
        return Err(src.error(
            &piece.key,
            format!(
                "the crack is outside every body (no vertex within {REACH_CELLS} cells of a \
                 particle)"
            ),
        ));
    }
    Ok(())
}

/// `piece` keeps apart from the cracks already in `store`: no crossing or touching.
fn apart<D: Dim>(src: &Source, store: &Cracks<D>, piece: &Piece<D>, geom: &GridGeom<D>) -> R<()> {
    if let Some((k, mine, theirs)) =
        super::crack_meet::meets(store, &piece.points, &piece.elems, 1e-6 * geom.min_cell())
    {
        let what = if D::D == 2 { "segment" } else { "triangle" };
        return Err(src.error(
            &piece.key,
            format!(
                "the crack meets crack `{}` (its {what} {mine} and their {what} {theirs}): \
                 cracks must not cross or touch",
                store.topology.cracks()[k].name
            ),
        ));
    }
    Ok(())
}

/// One crack before it joins the store: the key errors about its vertices name, its
/// vertices, its elements and its fronts (end or index, vertices), in its own numbering.
struct Piece<D: Dim> {
    key: String,
    points: Vec<D::Vec>,
    elems: Vec<D::Elem>,
    fronts: Vec<(u32, Vec<u32>)>,
}

/// A 2D crack: the polyline of `points` or `line`, its tips at the ends named in `tips`.
fn polyline<D: Dim>(src: &Source, c: usize, spec: &CrackSpec, geom: &GridGeom<D>) -> R<Piece<D>> {
    let key = |k: &str| format!("crack[{c}].{k}");
    let surface_key = [
        ("mesh", spec.mesh.is_some()),
        ("mesh_file", spec.mesh_file.is_some()),
        ("rectangle", spec.rectangle.is_some()),
        ("ellipse", spec.ellipse.is_some()),
        ("penny", spec.penny.is_some()),
    ];
    if let Some((k, _)) = surface_key.iter().find(|k| k.1) {
        return Err(src.error(
            &key(k),
            "a 2D crack is a polyline: give `points` or `line` (surfaces are 3D)",
        ));
    }
    let points = vertices::<D>(src, c, spec, geom)?;
    let what = key(if spec.points.is_some() {
        "points"
    } else {
        "line"
    });
    if let Some(j) = fold_back::<D>(&points) {
        return Err(src.error(
            &what,
            format!("the crack folds back onto itself at vertex {j}"),
        ));
    }
    if let Some((a, b)) = self_crossing::<D>(&points) {
        return Err(src.error(
            &what,
            format!("the crack crosses itself (segments {a} and {b})"),
        ));
    }
    let mut ends = vec![1u32];
    if let Some(t) = &spec.tips {
        ends.clear();
        for name in t {
            let end = match name.as_str() {
                "start" => 0,
                "end" => 1,
                other => {
                    return Err(
                        src.error(&key("tips"), format!("unknown tip `{other}` (start, end)"))
                    );
                }
            };
            if !ends.contains(&end) {
                ends.push(end);
            }
        }
        ends.sort_unstable();
    }
    let n = points.len() as u32;
    Ok(Piece {
        key: what,
        elems: (0..n - 1)
            .map(|k| D::Elem::from_vertices(&[k, k + 1]))
            .collect(),
        fronts: ends
            .iter()
            .map(|&end| (end, vec![if end == 0 { 0 } else { n - 1 }]))
            .collect(),
        points,
    })
}

/// Crack `c`'s rule for splitting particle-node pairs (`split`, default "crossing").
fn split(src: &Source, c: usize, spec: &CrackSpec) -> R<Split> {
    let Some(name) = &spec.split else {
        return Ok(Split::Crossing);
    };
    Split::named(name).ok_or_else(|| {
        src.error(
            &format!("crack[{c}].split"),
            format!("unknown split rule `{name}` (crossing, inside)"),
        )
    })
}

/// The contact settings of crack `c`.
fn contact(src: &Source, c: usize, spec: &CrackSpec) -> R<Contact> {
    let key = |k: &str| format!("crack[{c}].contact.{k}");
    let Some(cs) = &spec.contact else {
        return Ok(Contact::OPEN);
    };
    let law = match cs.law.as_str() {
        "none" => Law::None,
        "stick" => Law::Stick,
        "frictionless" => Law::Frictionless,
        "friction" => {
            let mu = cs
                .friction
                .ok_or_else(|| src.error(&key("friction"), "give the friction coefficient"))?;
            if !(mu.is_finite() && mu >= 0.0) {
                return Err(src.error(&key("friction"), "must be a number >= 0"));
            }
            Law::Coulomb(mu)
        }
        other => {
            return Err(src.error(
                &key("law"),
                format!("unknown contact law `{other}` (none, stick, frictionless, friction)"),
            ));
        }
    };
    if cs.friction.is_some() && !matches!(law, Law::Coulomb(_)) {
        return Err(src.error(
            &key("friction"),
            "only the `friction` law takes a coefficient",
        ));
    }
    Ok(Contact {
        law,
        approach_check: cs.approach_check.unwrap_or(false),
    })
}

/// The vertices of crack `c`: its points, or its line cut at the spacing; all inside the
/// grid, at least two, no two consecutive ones equal.
fn vertices<D: Dim>(
    src: &Source,
    c: usize,
    spec: &CrackSpec,
    geom: &GridGeom<D>,
) -> R<Vec<D::Vec>> {
    let key = |k: &str| format!("crack[{c}].{k}");
    let points: Vec<D::Vec> = match (&spec.points, &spec.line) {
        (Some(pts), None) => {
            if pts.len() < 2 {
                return Err(src.error(&key("points"), "a crack needs at least two points"));
            }
            if pts.len() > MAX_VERTICES + 1 {
                return Err(src.error(
                    &key("points"),
                    format!("at most {} points per crack", MAX_VERTICES + 1),
                ));
            }
            pts.iter()
                .enumerate()
                .map(|(j, p)| {
                    vec3::<D>(src, &format!("crack[{c}].points[{j}]"), p).map(to_vec::<D>)
                })
                .collect::<R<_>>()?
        }
        (None, Some(line)) => {
            let a = to_vec::<D>(vec3::<D>(src, &key("line.start"), &line.start)?);
            let b = to_vec::<D>(vec3::<D>(src, &key("line.end"), &line.end)?);
            let len = D::dot(b - a, b - a).sqrt();
            if len == 0.0 {
                return Err(src.error(&key("line.end"), "the line's start and end coincide"));
            }
            let spacing = match line.spacing {
                Some(s) => positive(src, &key("line.spacing"), s, "m")?,
                None => 0.5 * geom.min_cell(),
            };
            let n = (len / spacing).ceil();
            if n > MAX_VERTICES as f64 {
                return Err(src.error(
                    &key("line.spacing"),
                    format!(
                        "{spacing:e} m cuts the {len:e} m line into {n:e} segments, more than \
                         {MAX_VERTICES}: give a spacing of at least {:e} m",
                        len / MAX_VERTICES as f64
                    ),
                ));
            }
            let n = n as usize;
            (0..=n)
                .map(|k| a + (b - a) * (k as f64 / n as f64))
                .collect()
        }
        _ => {
            return Err(src.error(
                &format!("crack[{c}]"),
                "give exactly one of `points` and `line`",
            ));
        }
    };
    for (j, w) in points.windows(2).enumerate() {
        if w[0] == w[1] {
            return Err(src.error(&key("points"), format!("points {j} and {} coincide", j + 1)));
        }
    }
    for (j, w) in points.windows(3).enumerate() {
        let (back, on) = (w[0] - w[1], w[2] - w[1]);
        let cos = D::dot(back, on) / (D::dot(back, back) * D::dot(on, on)).sqrt();
        if cos > MIN_FOLD_ANGLE.to_radians().cos() {
            return Err(src.error(
                &key("points"),
                format!(
                    "the crack folds back on itself at point {}: its segments there meet at \
                     {:.1} degrees (less than {MIN_FOLD_ANGLE}), so its faces would overlap",
                    j + 1,
                    cos.clamp(-1.0, 1.0).acos().to_degrees()
                ),
            ));
        }
    }
    Ok(points)
}

/// The particles of each grid cell that holds some, to tell quickly whether a crack vertex
/// is near the body.
struct Occupied<'a, D: Dim> {
    cells: HashMap<[i64; 3], Vec<u32>>,
    x: &'a [D::Vec],
    geom: &'a GridGeom<D>,
}

impl<'a, D: Dim> Occupied<'a, D> {
    fn new(p: &'a Particles<D>, geom: &'a GridGeom<D>) -> Self {
        let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (i, &x) in p.x.iter().enumerate() {
            cells.entry(Self::cell(geom, x)).or_default().push(i as u32);
        }
        Occupied {
            cells,
            x: &p.x,
            geom,
        }
    }

    fn cell(geom: &GridGeom<D>, x: D::Vec) -> [i64; 3] {
        let mut c = [0i64; 3];
        for (a, ca) in c.iter_mut().enumerate().take(D::D) {
            *ca = ((x[a] - geom.origin[a]) * geom.inv_h[a]).floor() as i64;
        }
        c
    }

    /// Whether some particle lies within `REACH_CELLS` cells of `x` on every axis.
    fn near(&self, x: D::Vec) -> bool {
        let r = REACH_CELLS.ceil() as i64;
        let c = Self::cell(self.geom, x);
        let span = |a: usize| if a < D::D { -r..=r } else { 0..=0 };
        let close = |&i: &u32| {
            let y = self.x[i as usize];
            (0..D::D).all(|a| ((y[a] - x[a]) * self.geom.inv_h[a]).abs() <= REACH_CELLS)
        };
        span(2).any(|k| {
            span(1).any(|j| {
                span(0).any(|i| {
                    (self.cells.get(&[c[0] + i, c[1] + j, c[2] + k]))
                        .is_some_and(|ys| ys.iter().any(close))
                })
            })
        })
    }
}

/// The first vertex at which a polyline turns straight back along its previous segment
/// (the two segments overlap, which the test for non-adjacent crossings cannot see).
fn fold_back<D: Dim>(pts: &[D::Vec]) -> Option<usize> {
    let c = |u: D::Vec| robust::Coord { x: u[0], y: u[1] };
    (1..pts.len() - 1).find(|&j| {
        let (a, b, d) = (pts[j - 1], pts[j], pts[j + 1]);
        robust::orient2d(c(a), c(b), c(d)) == 0.0 && D::dot(b - a, d - b) < 0.0
    })
}

/// The first pair (in index order) of non-adjacent segments of a polyline that intersect,
/// if any. Segments are binned into square buckets about as wide as a segment on average
/// (each in the buckets around points along it, every quarter bucket), so only segments
/// sharing a bucket are tested: about linear in the vertex count, however long a few
/// segments are.
fn self_crossing<D: Dim>(pts: &[D::Vec]) -> Option<(usize, usize)> {
    let e = |k: usize| D::Elem::from_vertices(&[k as u32, k as u32 + 1]);
    let n = pts.len() - 1;
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in pts {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let length = |k: usize| D::dot(pts[k + 1] - pts[k], pts[k + 1] - pts[k]).sqrt();
    let mean = (0..n).map(length).sum::<f64>() / n as f64;
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let size = mean.max(extent / (n as f64).sqrt()).max(f64::MIN_POSITIVE);
    let mut buckets: HashMap<[i64; 2], Vec<usize>> = HashMap::new();
    let mut cells: Vec<[i64; 2]> = Vec::new();
    for k in 0..n {
        let (p, q) = (pts[k], pts[k + 1]);
        // Every point of the segment lies within a quarter bucket of a sample, so in the
        // sample's bucket or a neighbour: a point two segments share is in a bucket of both.
        let samples = (4.0 * length(k) / size).ceil().max(1.0) as usize;
        cells.clear();
        for s in 0..=samples {
            let x = p + (q - p) * (s as f64 / samples as f64);
            let c = [0, 1].map(|a| ((x[a] - lo[a]) / size).floor() as i64);
            for di in -1..=1 {
                for dj in -1..=1 {
                    cells.push([c[0] + di, c[1] + dj]);
                }
            }
        }
        cells.sort_unstable();
        cells.dedup();
        for c in &cells {
            buckets.entry(*c).or_default().push(k);
        }
    }
    let mut first: Option<(usize, usize)> = None;
    for segs in buckets.values() {
        for (i, &a) in segs.iter().enumerate() {
            for &b in &segs[i + 1..] {
                if b < a + 2 || first.is_some_and(|f| f <= (a, b)) {
                    continue;
                }
                let (p, q) = (pts[b], pts[b + 1]);
                // Touching counts as crossing here: a crack must not meet itself at all.
                if (e(a)).crossing(p, q, pts) != 0 || (e(a)).crossing(q, p, pts) != 0 {
                    first = Some((a, b));
                }
            }
        }
    }
    first
}

/// The `[fracture]` sizes in cells: the square contour (2D), the compared contours or
/// tubes, the interaction domain and the opening window, converted from metres when
/// `lengths = "m"` (whole cells for the contours and tubes, by rounding).
pub(super) struct Sizes {
    /// Half-size of the main contour (2D), if given.
    pub contour: Option<usize>,
    /// The compared contours or tubes.
    pub compare: Vec<usize>,
    /// The interaction domain's or tube's radius, if given.
    pub domain: Option<f64>,
    /// The opening fit's window, if given.
    pub opening: Option<f64>,
}

/// Reads [`Sizes`] from `f` on the grid `geom`.
pub(super) fn sizes<D: Dim>(src: &Source, f: &FractureSpec, geom: &GridGeom<D>) -> R<Sizes> {
    let scale = match f.lengths.as_deref() {
        None | Some("cells") => None,
        Some("m") => Some(1.0 / (0..D::D).map(|a| geom.h[a]).fold(0.0, f64::max)),
        Some(other) => {
            return Err(src.error(
                "fracture.lengths",
                format!("unknown unit `{other}`: give \"cells\" or \"m\""),
            ));
        }
    };
    let cells = |v: f64| scale.map_or(v, |s| v * s);
    let whole = |key: &str, v: f64| -> R<usize> {
        let n = cells(v);
        let n = if scale.is_some() { n.round() } else { n };
        if !(n.is_finite() && n >= 0.0 && n.fract() == 0.0 && n <= 1e6) {
            let unit = if scale.is_some() { "m" } else { "cells" };
            return Err(src.error(
                key,
                format!("give a whole number of cells (or a length with lengths = \"m\"), got {v} {unit}"),
            ));
        }
        Ok(n as usize)
    };
    Ok(Sizes {
        contour: f
            .contour
            .map(|v| whole("fracture.contour", v))
            .transpose()?,
        compare: (f.compare.iter().flatten())
            .map(|&v| whole("fracture.compare", v))
            .collect::<R<_>>()?,
        domain: f.domain.map(cells),
        opening: f.opening.map(cells),
    })
}

/// The `[fracture]` table, checked against the cracks: they must exist and have tips, and
/// the contour around each tip must fit inside the grid.
pub(super) fn fracture_plan<D: Dim>(
    src: &Source,
    cracks: Option<&Cracks<D>>,
    geom: &GridGeom<D>,
) -> R<Option<FracturePlan>> {
    let Some(f) = &src.scenario.fracture else {
        return Ok(None);
    };
    let Some(cracks) = cracks else {
        return Err(src.error("fracture", "J and K need at least one [[crack]]"));
    };
    if cracks.topology.fronts().is_empty() {
        return Err(src.error(
            "fracture",
            if D::D == 2 {
                "J and K are measured at crack tips, and no crack has one (see `tips`)"
            } else {
                "J and K are measured along crack fronts, and no crack has one (a rectangle \
                 cuts through)"
            },
        ));
    }
    let fits = |key: &str, n: usize| -> R<()> {
        if n == 0 {
            return Err(src.error(key, "must be at least 1 cell"));
        }
        let topo = &cracks.topology;
        for f in topo.fronts() {
            for &k in &f.vertices {
                let x = cracks.geometry.x[k as usize];
                let inside = (0..D::D).all(|a| {
                    let i = ((x[a] - geom.origin[a]) * geom.inv_h[a]).round();
                    i >= n as f64 && i + n as f64 <= geom.cells[a] as f64
                });
                if !inside {
                    return Err(src.error(
                        key,
                        format!(
                            "a {n} x {n} cell contour around the {} tip of `{}` leaves the grid",
                            ["start", "end"][f.end as usize],
                            topo.cracks()[f.crack as usize].name
                        ),
                    ));
                }
            }
        }
        Ok(())
    };
    let sizes = sizes(src, f, geom)?;
    let n = sizes.contour.unwrap_or(2);
    let compare = sizes.compare;
    if D::D == 2 {
        fits("fracture.contour", n)?;
        for &m in &compare {
            fits("fracture.compare", m)?;
        }
    } else {
        // J along a 3D front comes from the tube's domain integral, which always carries the
        // volume term; the square grid contour is 2D. Compared tubes are sized in cells.
        let grid_keys = [
            ("contour", f.contour.is_some()),
            ("area_term", f.area_term.is_some()),
        ];
        if let Some((key, _)) = grid_keys.iter().find(|k| k.1) {
            return Err(src.error(
                &format!("fracture.{key}"),
                "the square J contour is 2D; along a 3D front J and K come from a tube of \
                 radius `domain` cells",
            ));
        }
        if compare.iter().any(|&m| m < 2) {
            return Err(src.error(
                "fracture.compare",
                "compared tubes around a 3D front are at least 2 cells in radius",
            ));
        }
    }
    let compare_from = f.compare_from.unwrap_or(0.0);
    if compare_from.is_nan() || compare_from < 0.0 {
        return Err(src.error("fracture.compare_from", "give a time >= 0 (s)"));
    }
    let opening = sizes.opening.unwrap_or(8.0);
    if opening.is_nan() || opening < 2.0 {
        return Err(src.error(
            "fracture.opening",
            "the opening is fitted from 1 cell to `opening` behind the tip: give at least 2 cells",
        ));
    }
    let k_method = match f.k_from.as_deref() {
        None | Some("lower_g") => KMethod::LowerG,
        Some("interaction") => KMethod::Interaction,
        Some("mixity") => KMethod::Mixity,
        Some("opening") => KMethod::Opening,
        Some(other) => {
            return Err(src.error(
                "fracture.k_from",
                format!(
                    "unknown method `{other}`: give \"lower_g\", \"interaction\", \"mixity\" or \"opening\""
                ),
            ));
        }
    };
    let domain = sizes.domain.unwrap_or(if D::D == 2 { 6.0 } else { 3.0 });
    if !(domain.is_finite() && domain >= 2.0) {
        return Err(src.error(
            "fracture.domain",
            "the interaction integral's domain radius must be at least 2 cells",
        ));
    }
    // In 3D the compared tubes are set against the main one, of `domain` cells.
    if D::D == 3 && !compare.is_empty() && (domain.fract() != 0.0 || domain > 1e3) {
        return Err(src.error(
            "fracture.domain",
            "tubes compared with `compare` are set against the main one: give `domain` as \
             a whole number of cells",
        ));
    }
    Ok(Some(FracturePlan {
        contour: if D::D == 2 { n } else { domain as usize },
        k_method,
        domain,
        area_term: f.area_term.unwrap_or(true),
        opening,
        compare,
        compare_from,
        k0: match f.k0 {
            Some(k) => Some(positive(src, "fracture.k0", k, "Pa sqrt(m)")?),
            None => None,
        },
    }))
}

/// The index and name of the crack a fracture expect names, checked: the scenario must
/// measure J and K, and the crack must exist.
fn measured_crack<'a>(src: &Source, i: usize, e: &'a ExpectSpec) -> R<(usize, &'a str)> {
    let key = |k: &str| format!("expect[{i}].{k}");
    let sc = &src.scenario;
    if sc.fracture.is_none() {
        return Err(src.error(
            &key("quantity"),
            format!("`{}` needs a [fracture] table", e.quantity),
        ));
    }
    let name = e
        .crack
        .as_deref()
        .ok_or_else(|| src.error(&key("quantity"), "name the crack with `crack = ...`"))?;
    let c = sc
        .cracks
        .iter()
        .enumerate()
        .position(|(k, c)| c.name.clone().unwrap_or_else(|| format!("crack{k}")) == name)
        .ok_or_else(|| src.error(&key("crack"), format!("no crack named `{name}`")))?;
    Ok((c, name))
}

/// The crack and tip (0 start, 1 end) an expect names, checked.
pub(super) fn expect_tip(src: &Source, i: usize, e: &ExpectSpec) -> R<(u32, u32)> {
    let key = |k: &str| format!("expect[{i}].{k}");
    let sc = &src.scenario;
    let (c, name) = measured_crack(src, i, e)?;
    let tip = match e.tip.as_deref().unwrap_or("end") {
        "start" => 0,
        "end" => 1,
        other => return Err(src.error(&key("tip"), format!("unknown tip `{other}` (start, end)"))),
    };
    let tips = sc.cracks[c]
        .tips
        .clone()
        .unwrap_or_else(|| vec!["end".into()]);
    if !tips.iter().any(|t| t == ["start", "end"][tip]) {
        return Err(src.error(
            &key("tip"),
            format!("the {} of `{name}` is not a tip", ["start", "end"][tip]),
        ));
    }
    Ok((c as u32, tip as u32))
}

/// The measure of an expect on a crack tip (`qty` 0..4 = KI, KII, J1, J2).
pub(super) fn tip_measure(src: &Source, i: usize, e: &ExpectSpec, qty: usize) -> R<Measure> {
    let key = |k: &str| format!("expect[{i}].{k}");
    let (crack, tip) = expect_tip(src, i, e)?;
    if let Some(t) = e.at {
        let end = src.scenario.simulation.duration;
        if !(0.0..=end).contains(&t) {
            return Err(src.error(
                &key("at"),
                format!("the time must lie in the run, 0 to {end:.4e} s"),
            ));
        }
    }
    Ok(Measure::Tip {
        crack,
        tip,
        qty,
        at: e.at,
    })
}

/// The measure of an expect along a 3D crack front (`qty` 0..4 = KI, KII, KIII, J1): the
/// value farthest from the reference over the front's vertices, at the last measurement.
pub(super) fn front_measure(src: &Source, i: usize, e: &ExpectSpec, qty: usize) -> R<Measure> {
    let key = |k: &str| format!("expect[{i}].{k}");
    let (crack, _) = measured_crack(src, i, e)?;
    for (k, given) in [("tip", e.tip.is_some()), ("at", e.at.is_some())] {
        if given {
            return Err(src.error(
                &key(k),
                format!(
                    "`{}` covers every front vertex at the last measurement",
                    e.quantity
                ),
            ));
        }
    }
    let along = match &e.along {
        None => None,
        Some(a) => Some(along(src, &key("along"), a)?),
    };
    let near = match &e.near {
        None => None,
        Some(p) => Some(vec3::<D3>(src, &key("near"), p)?),
    };
    Ok(Measure::Front {
        crack: crack as u32,
        qty,
        reference: e.reference,
        along,
        near,
    })
}

/// Checks the expects along 3D fronts against the built cracks: the crack has a front, and
/// a `near` point lies within two cells of one of its vertices.
pub(super) fn check_front_expects<D: Dim>(
    src: &Source,
    expects: &[Expect],
    cracks: Option<&Cracks<D>>,
    cell: f64,
) -> R<()> {
    for (i, e) in expects.iter().enumerate() {
        let (Measure::Front { crack, near, .. }
        | Measure::PathDifference {
            crack,
            near,
            tip: None,
            ..
        }) = e.measure
        else {
            continue;
        };
        let Some(store) = cracks else { continue };
        let topo = &store.topology;
        let c = crack as usize;
        let front: Vec<u32> = topo
            .fronts()
            .iter()
            .filter(|f| f.crack as usize == c)
            .flat_map(|f| f.vertices.iter().copied())
            .collect();
        let name = &topo.cracks()[c].name;
        if front.is_empty() {
            return Err(src.error(
                &format!("expect[{i}].crack"),
                format!("crack `{name}` has no front to measure (a rectangle cuts through)"),
            ));
        }
        let Some(p) = near else { continue };
        let p = DVec3::from(p);
        let nearest = front
            .iter()
            .map(|&v| DVec3::from(D::to_xyz(store.geometry.x[v as usize])).distance(p))
            .fold(f64::INFINITY, f64::min);
        if nearest > 2.0 * cell {
            return Err(src.error(
                &format!("expect[{i}].near"),
                format!(
                    "no front vertex of crack `{name}` lies within two cells of this point; \
                     the nearest is {nearest:.4e} m away"
                ),
            ));
        }
    }
    Ok(())
}

/// The checked `along` of a front expect: a shape of cos or sin, and a `zero` direction
/// with a component off the `normal` axis.
fn along(src: &Source, key: &str, a: &AlongSpec) -> R<Along> {
    let shape = match (a.shape.as_str(), a.ratio) {
        ("cos", None) => Shape::Cos,
        ("sin", None) => Shape::Sin,
        ("ellipse", Some(r)) if r > 0.0 && r <= 1.0 => Shape::Ellipse(r),
        ("ellipse", _) => {
            return Err(src.error(
                &format!("{key}.ratio"),
                "an ellipse needs `ratio` = b/a of its semi-axes, in (0, 1]",
            ));
        }
        ("cos" | "sin", Some(_)) => {
            return Err(src.error(&format!("{key}.ratio"), "`ratio` is for shape \"ellipse\""));
        }
        (other, _) => {
            return Err(src.error(
                &format!("{key}.shape"),
                format!("unknown shape `{other}`: give \"cos\", \"sin\" or \"ellipse\""),
            ));
        }
    };
    let unit = |name: &str, v: &[f64]| -> R<DVec3> {
        let k = format!("{key}.{name}");
        let v: [f64; 3] = v
            .try_into()
            .map_err(|_| src.error(&k, "give three components"))?;
        let v = DVec3::from(v);
        if !(v.is_finite() && v.length() > 0.0) {
            return Err(src.error(&k, "must be a finite, non-zero direction"));
        }
        Ok(v.normalize())
    };
    let n = unit("normal", &a.normal)?;
    let z = unit("zero", &a.zero)?;
    let zero = z - z.dot(n) * n;
    if zero.length() < 1e-6 {
        return Err(src.error(&format!("{key}.zero"), "is parallel to `normal`"));
    }
    let zero = zero.normalize();
    Ok(Along {
        shape,
        zero: zero.to_array(),
        quarter: n.cross(zero).to_array(),
    })
}

/// The measure of a `K_drift` expect: how far K moves at a crack tip from `from` on.
pub(super) fn drift_measure(src: &Source, i: usize, e: &ExpectSpec) -> R<Measure> {
    let (crack, tip) = expect_tip(src, i, e)?;
    if e.at.is_some() {
        return Err(src.error(
            &format!("expect[{i}].at"),
            "`K_drift` runs over a window: give its start `from`",
        ));
    }
    let end = src.scenario.simulation.duration;
    match e.from {
        Some(from) if (0.0..end).contains(&from) => Ok(Measure::KDrift { crack, tip, from }),
        _ => Err(src.error(
            &format!("expect[{i}].from"),
            format!("`K_drift` runs over a window: give its start `from`, 0 to {end:.4e} s"),
        )),
    }
}

/// The measure of a `G_interaction` expect: the interaction integral's G against J at a 2D
/// tip at rest from `from` on, E' that of the `material` at the tip (the scene's only one
/// by default), the tip's direction that of the crack's end segment.
pub(super) fn g_interaction_measure<D: Dim>(
    src: &Source,
    i: usize,
    e: &ExpectSpec,
    geom: &GridGeom<D>,
    materials: &[Material],
    plane: Plane,
) -> R<Measure> {
    let key = |k: &str| format!("expect[{i}].{k}");
    let (crack, tip) = expect_tip(src, i, e)?;
    let spec = &src.scenario.cracks[crack as usize];
    if spec.growth.is_some() {
        return Err(src.error(
            &key("quantity"),
            "`G_interaction` compares G and J at a tip at rest: this crack grows",
        ));
    }
    if e.at.is_some() {
        return Err(src.error(
            &key("at"),
            "`G_interaction` runs over a window: give its start `from`",
        ));
    }
    let end = src.scenario.simulation.duration;
    let from = match e.from {
        Some(from) if (0.0..end).contains(&from) => from,
        _ => {
            return Err(src.error(
                &key("from"),
                format!(
                    "`G_interaction` runs over a window: give its start `from`, 0 to {end:.4e} s"
                ),
            ));
        }
    };
    let material = match (&e.material, materials) {
        (Some(name), _) => material_named(src, &key("material"), materials, name)?,
        (None, [_]) => 0,
        (None, _) => {
            return Err(src.error(
                &key("material"),
                "the scene has several materials: name the one at the tip",
            ));
        }
    };
    Ok(Measure::GInteraction {
        crack,
        tip,
        from,
        modulus: e_prime(&materials[material], plane),
        direction: tip_direction(src, crack, tip, geom)?,
    })
}

/// The unit direction of 2D crack `crack`'s tip `tip` (0 start, 1 end): that of its end
/// segment, pointing out of the crack.
fn tip_direction<D: Dim>(src: &Source, crack: u32, tip: u32, geom: &GridGeom<D>) -> R<[f64; 2]> {
    let spec = &src.scenario.cracks[crack as usize];
    let points = vertices::<D>(src, crack as usize, spec, geom)?;
    let n = points.len();
    let (a, b) = if tip == 0 {
        (points[1], points[0])
    } else {
        (points[n - 2], points[n - 1])
    };
    let (a, b) = (D::to_xyz(a), D::to_xyz(b));
    let d = [b[0] - a[0], b[1] - a[1]];
    let len = d[0].hypot(d[1]);
    Ok([d[0] / len, d[1] / len])
}

/// The measure of a `J_path` expect: J with the area term on the compared contours against
/// the main one at a crack tip (3D: J with the volume term on the compared tubes, at every
/// front vertex or the one `near` a point), from `[fracture] compare_from` on.
pub(super) fn path_measure<D: Dim>(
    src: &Source,
    i: usize,
    e: &ExpectSpec,
    geom: &GridGeom<D>,
) -> R<Measure> {
    let key = |k: &str| format!("expect[{i}].{k}");
    let (crack, tip, near) = if D::D == 2 {
        let (crack, tip) = expect_tip(src, i, e)?;
        (crack, Some(tip), None)
    } else {
        if e.tip.is_some() {
            return Err(src.error(
                &key("tip"),
                "a 3D front has no named tips: `J_path` covers every front vertex, or the \
                 one `near` a point",
            ));
        }
        let near = match &e.near {
            Some(p) => Some(vec3::<D3>(src, &key("near"), p)?),
            None => None,
        };
        (measured_crack(src, i, e)?.0 as u32, None, near)
    };
    if e.at.is_some() {
        return Err(src.error(
            &format!("expect[{i}].at"),
            "`J_path` runs over a window: set its start with `[fracture] compare_from`",
        ));
    }
    let f = src.scenario.fracture.as_ref();
    let sizes = f.map(|f| sizes(src, f, geom)).transpose()?;
    let compare: Vec<u32> = (sizes.iter())
        .flat_map(|s| s.compare.iter().map(|&n| n as u32))
        .collect();
    if compare.is_empty() {
        return Err(src.error(
            &format!("expect[{i}].quantity"),
            "`J_path` compares contours: list them in `[fracture] compare`",
        ));
    }
    let main = if D::D == 2 {
        sizes.as_ref().and_then(|s| s.contour).unwrap_or(2) as u32
    } else {
        sizes.as_ref().and_then(|s| s.domain).unwrap_or(3.0) as u32
    };
    Ok(Measure::PathDifference {
        crack,
        tip,
        near,
        main,
        compare,
        from: f.and_then(|f| f.compare_from).unwrap_or(0.0),
    })
}
