//! 3D crack surfaces: triangle meshes from vertex and triangle lists or OBJ and STL files, or
//! generated from rectangles, ellipses (whole or half) and pennies, with the checks a crack
//! surface needs (indices in range, no degenerate triangle, a manifold surface oriented one
//! way).

use super::check::{MIN_FOLD_ANGLE, positive, vec3};
use super::crack_front::found_front;
use super::mesh_body::{file, placement, read};
use super::schema::{CrackFileSpec, CrackSpec, EllipseSpec, MeshSpec, PennySpec, PlanarSpec};
use super::source::Source;
use crate::base::dim::D3;
use crate::base::error::ScenarioError;
use crate::base::geometry::Element;
use glam::DVec3;
use std::collections::{HashMap, HashSet};
use std::f64::consts::PI;

type R<T> = Result<T, ScenarioError>;

/// How far (cells) a half ellipse's straight edge is carried past the surface it lies on.
const OVERHANG_CELLS: f64 = 1.5;

/// Most triangles a generated crack surface may have: counted before it is generated, so a
/// spacing of a nanometre is refused at once rather than meshed for minutes.
const MAX_TRIANGLES: f64 = 200_000.0;

/// A crack surface: vertices, counterclockwise triangles (seen from above) and its front.
#[derive(Debug, Clone)]
pub(super) struct Surface {
    /// Vertex positions (m).
    pub vertices: Vec<DVec3>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// Front vertices in order (empty: no front).
    pub front: Vec<u32>,
}

/// The surface of 3D crack `c`, generated or read, and checked; `cell` is the smallest
/// cell size (m), the default spacing. A surface read from a file without a `front` takes
/// the boundary edges that lie `inside` a body.
pub(super) fn surface(
    src: &Source,
    c: usize,
    spec: &CrackSpec,
    cell: f64,
    inside: &dyn Fn(DVec3) -> bool,
) -> R<Surface> {
    let key = |k: &str| format!("crack[{c}].{k}");
    if spec.points.is_some() || spec.line.is_some() || spec.tips.is_some() {
        let k = if spec.points.is_some() {
            "points"
        } else if spec.line.is_some() {
            "line"
        } else {
            "tips"
        };
        return Err(src.error(
            &key(k),
            "a 3D crack is a surface: give `mesh`, `mesh_file`, `rectangle`, `ellipse` or \
             `penny`",
        ));
    }
    let spacing = |s: Option<f64>, k: &str| match s {
        Some(s) => positive(src, &key(k), s, "m"),
        None => Ok(0.5 * cell),
    };
    let given = [spec.mesh.is_some(), spec.mesh_file.is_some()];
    let (surface, what) = match (&spec.mesh_file, &spec.rectangle, &spec.ellipse, &spec.penny) {
        (Some(f), None, None, None) if given == [false, true] => {
            (crack_mesh(src, &key("mesh_file"), f)?, "mesh_file")
        }
        (None, None, None, None) if given == [true, false] => {
            (mesh(src, c, spec.mesh.as_ref().expect("given"))?, "mesh")
        }
        (None, Some(r), None, None) if given == [false, false] => {
            let h = spacing(r.spacing, "rectangle.spacing")?;
            let k = key("rectangle.spacing");
            (rectangle(src, c, r, h, &k)?, "rectangle")
        }
        (None, None, Some(e), None) if given == [false, false] => {
            let h = spacing(e.spacing, "ellipse.spacing")?;
            let k = key("ellipse.spacing");
            (ellipse(src, c, e, h, OVERHANG_CELLS * cell, &k)?, "ellipse")
        }
        (None, None, None, Some(p)) if given == [false, false] => {
            let h = spacing(p.spacing, "penny.spacing")?;
            (penny(src, c, p, h, &key("penny.spacing"))?, "penny")
        }
        _ => {
            return Err(src.error(
                &format!("crack[{c}]"),
                "give exactly one of `mesh`, `mesh_file`, `rectangle`, `ellipse` and `penny`",
            ));
        }
    };
    let named = |mut e: ScenarioError| {
        // A surface read from a file is named in what its checks find.
        if let Some(f) = &spec.mesh_file {
            e.message = format!("{}: {}", f.file, e.message);
        }
        e
    };
    check(src, &key(what), &surface).map_err(named)?;
    let mut surface = surface;
    if spec.mesh_file.as_ref().is_some_and(|f| f.front.is_none()) {
        let front = found_front(&surface.vertices, &surface.triangles, inside)
            .map_err(|m| named(src.error(&key("mesh_file"), m)))?;
        surface.front = front;
    }
    Ok(surface)
}

/// Refuses the spacing `h` (under `key`; by default half the cell) when it would cut a
/// surface into more than [`MAX_TRIANGLES`] triangles, `triangles` being that count.
fn not_too_fine(src: &Source, key: &str, h: f64, triangles: f64) -> R<()> {
    if triangles <= MAX_TRIANGLES {
        return Ok(());
    }
    // The count goes as 1 / h^2.
    let least = h * (triangles / MAX_TRIANGLES).sqrt();
    Err(src.error(
        key,
        format!(
            "a spacing of {h:e} m (half the cell when not given) cuts this surface into \
             {triangles:.3e} triangles, more than {MAX_TRIANGLES}: give a spacing of at \
             least about {least:.3e} m"
        ),
    ))
}

fn point(src: &Source, key: &str, v: &[f64]) -> R<DVec3> {
    vec3::<D3>(src, key, v).map(DVec3::from)
}

/// Two in-plane axis vectors, not parallel.
fn axes(src: &Source, key: &str, a: &[Vec<f64>]) -> R<(DVec3, DVec3)> {
    if a.len() != 2 {
        return Err(src.error(key, "give two axis vectors [[x, y, z], [x, y, z]]"));
    }
    let u = point(src, key, &a[0])?;
    let v = point(src, key, &a[1])?;
    if u.cross(v).length() <= 1e-12 * u.length() * v.length() || u.length() == 0.0 {
        return Err(src.error(key, "the two axes must be non-zero and not parallel"));
    }
    Ok((u, v))
}

fn mesh(src: &Source, c: usize, m: &MeshSpec) -> R<Surface> {
    let key = |k: &str| format!("crack[{c}].mesh.{k}");
    let vertices = (m.vertices.iter().enumerate())
        .map(|(j, v)| point(src, &format!("crack[{c}].mesh.vertices[{j}]"), v))
        .collect::<R<Vec<_>>>()?;
    let n = vertices.len() as i64;
    let index = |k: &str, i: i64| {
        if (0..n).contains(&i) {
            Ok(i as u32)
        } else {
            Err(src.error(&key(k), format!("vertex {i} does not exist ({n} vertices)")))
        }
    };
    let mut triangles = Vec::with_capacity(m.triangles.len());
    for t in &m.triangles {
        if t.len() != 3 {
            return Err(src.error(&key("triangles"), "each triangle has three vertex indices"));
        }
        triangles.push([
            index("triangles", t[0])?,
            index("triangles", t[1])?,
            index("triangles", t[2])?,
        ]);
    }
    if triangles.is_empty() {
        return Err(src.error(&key("triangles"), "a crack surface needs a triangle"));
    }
    let front = (m.front.iter().flatten())
        .map(|&i| index("front", i))
        .collect::<R<Vec<_>>>()?;
    Ok(Surface {
        vertices,
        triangles,
        front,
    })
}

/// The crack surface in the file `spec` names (vertices placed), for the crack surface's
/// own checks; the front's positions are matched to the file's vertices.
fn crack_mesh(src: &Source, key: &str, spec: &CrackFileSpec) -> R<Surface> {
    let place = placement(src, key, spec.scale, spec.rotate.as_ref(), &spec.translate)?;
    let (path, refuse) = file(src, key, &spec.file)?;
    let (unique, triangles) = read(&path).map_err(&refuse)?;
    // Positions typed in the scenario match the file's to round-off of its own size.
    let (lo, hi) = unique.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), v| (lo.min(DVec3::from_array(*v)), hi.max(DVec3::from_array(*v))),
    );
    let tol = 1e-9 * (hi - lo).length();
    let mut front = Vec::new();
    for (k, p) in spec.front.iter().flatten().enumerate() {
        let at = format!("{key}.front[{k}]");
        let p = match p.as_slice() {
            [x, y, z] if p.iter().all(|c| c.is_finite()) => DVec3::new(*x, *y, *z),
            _ => return Err(src.error(&at, "give [x, y, z] in the file's units, finite")),
        };
        let nearest = (0..unique.len())
            .min_by(|&a, &b| {
                let d = |i: usize| DVec3::from_array(unique[i]).distance(p);
                d(a).total_cmp(&d(b))
            })
            .filter(|&i| DVec3::from_array(unique[i]).distance(p) <= tol);
        match nearest {
            Some(i) if !front.contains(&(i as u32)) => front.push(i as u32),
            Some(_) => return Err(src.error(&at, "this front vertex is listed twice")),
            None => {
                return Err(src.error(
                    &at,
                    format!("no vertex of the file lies at ({}, {}, {})", p.x, p.y, p.z),
                ));
            }
        }
    }
    Ok(Surface {
        vertices: unique.into_iter().map(place).collect(),
        triangles,
        front,
    })
}

fn rectangle(src: &Source, c: usize, r: &PlanarSpec, h: f64, spacing: &str) -> R<Surface> {
    let centre = point(src, &format!("crack[{c}].rectangle.center"), &r.center)?;
    let (u, v) = axes(src, &format!("crack[{c}].rectangle.axes"), &r.axes)?;
    let n = |a: DVec3| (2.0 * a.length() / h).ceil().max(1.0);
    not_too_fine(src, spacing, h, 2.0 * n(u) * n(v))?;
    let (nu, nv) = (n(u) as u32, n(v) as u32);
    let mut vertices = Vec::new();
    for j in 0..=nv {
        for i in 0..=nu {
            let (s, t) = (
                2.0 * i as f64 / nu as f64 - 1.0,
                2.0 * j as f64 / nv as f64 - 1.0,
            );
            vertices.push(centre + u * s + v * t);
        }
    }
    let at = |i: u32, j: u32| j * (nu + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, cc, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            triangles.push([a, b, cc]);
            triangles.push([a, cc, d]);
        }
    }
    Ok(Surface {
        vertices,
        triangles,
        front: Vec::new(),
    })
}

fn penny(src: &Source, c: usize, p: &PennySpec, h: f64, spacing: &str) -> R<Surface> {
    let key = |k: &str| format!("crack[{c}].penny.{k}");
    let centre = point(src, &key("center"), &p.center)?;
    let n = point(src, &key("normal"), &p.normal)?;
    if n.length() == 0.0 {
        return Err(src.error(&key("normal"), "the normal must not be zero"));
    }
    let r = positive(src, &key("radius"), p.radius, "m")?;
    let (u, v) = n.normalize().any_orthonormal_pair();
    not_too_fine(src, spacing, h, disc_triangles(r, h, false))?;
    Ok(disc(centre, u * r, v * r, h, None))
}

fn ellipse(
    src: &Source,
    c: usize,
    e: &EllipseSpec,
    h: f64,
    overhang: f64,
    spacing: &str,
) -> R<Surface> {
    let centre = point(src, &format!("crack[{c}].ellipse.center"), &e.center)?;
    let (a, b) = axes(src, &format!("crack[{c}].ellipse.axes"), &e.axes)?;
    let size = a.length().max(b.length());
    not_too_fine(src, spacing, h, disc_triangles(size, h, e.half))?;
    Ok(disc(centre, a, b, h, e.half.then_some(overhang)))
}

/// How many triangles [`disc`] makes of an ellipse of larger semi-axis `size` at spacing
/// `h`: 6 n^2 for n rings, 3 n^2 for a half (a bound).
fn disc_triangles(size: f64, h: f64, half: bool) -> f64 {
    let rings = (size / h).ceil().max(1.0);
    let per = if half { 3.0 } else { 6.0 };
    per * rings * rings
}

/// The ellipse `centre + a cos(t) + b sin(t)` meshed in rings of about `h` spacing (ring k
/// of the unit disc at radius k/n with 6k points), its front the outer ring. With
/// `half = Some(overhang)` only the half with a positive `b` component, its straight edge
/// carried `overhang` (m) past the centre line, the front the outer half ring.
fn disc(centre: DVec3, a: DVec3, b: DVec3, h: f64, half: Option<f64>) -> Surface {
    let rings = ((a.length().max(b.length()) / h).ceil() as usize).max(1);
    let span = if half.is_some() { PI } else { 2.0 * PI };
    let at = |r: f64, t: f64| centre + a * (r * t.cos()) + b * (r * t.sin());
    let mut vertices = vec![centre];
    let mut ring_of: Vec<Vec<u32>> = vec![vec![0]];
    for k in 1..=rings {
        let count = if half.is_some() { 3 * k + 1 } else { 6 * k };
        let r = k as f64 / rings as f64;
        let first = vertices.len() as u32;
        let step = if half.is_some() {
            span / (count - 1) as f64
        } else {
            span / count as f64
        };
        vertices.extend((0..count).map(|i| at(r, i as f64 * step)));
        ring_of.push((first..first + count as u32).collect());
    }
    // Fraction of the span at point i of ring k >= 1.
    let angle = |k: usize, i: usize| {
        let count = ring_of[k].len();
        if half.is_some() {
            i as f64 / (count - 1) as f64
        } else {
            i as f64 / count as f64
        }
    };
    let mut triangles = Vec::new();
    for k in 0..rings {
        let (inner, outer) = (&ring_of[k], &ring_of[k + 1]);
        if k == 0 {
            let m = outer.len();
            let last = if half.is_some() { m - 1 } else { m };
            for i in 0..last {
                triangles.push([inner[0], outer[i], outer[(i + 1) % m]]);
            }
            continue;
        }
        // Walk both rings by angle, always advancing the one whose next point comes first.
        let (ni, no) = (inner.len(), outer.len());
        let (ei, eo) = if half.is_some() {
            (ni - 1, no - 1)
        } else {
            (ni, no)
        };
        let (mut i, mut o) = (0, 0);
        while i < ei || o < eo {
            let next_i = if i < ei {
                angle(k, i + 1)
            } else {
                f64::INFINITY
            };
            let next_o = if o < eo {
                angle(k + 1, o + 1)
            } else {
                f64::INFINITY
            };
            if next_o <= next_i {
                triangles.push([inner[i % ni], outer[o % no], outer[(o + 1) % no]]);
                o += 1;
            } else {
                triangles.push([inner[i % ni], outer[o % no], inner[(i + 1) % ni]]);
                i += 1;
            }
        }
    }
    let front = ring_of[rings].clone();
    if let Some(overhang) = half {
        // A strip from the straight edge outwards: the edge's points are each ring's two
        // ends (and the centre), mirrored `overhang` along -b.
        let out = -b.normalize() * overhang;
        let mut edge: Vec<u32> = (1..=rings)
            .rev()
            .map(|k| *ring_of[k].last().unwrap())
            .collect();
        edge.push(0);
        edge.extend((1..=rings).map(|k| ring_of[k][0]));
        let first = vertices.len() as u32;
        let shifted: Vec<DVec3> = edge.iter().map(|&e| vertices[e as usize] + out).collect();
        vertices.extend(shifted);
        for (j, w) in edge.windows(2).enumerate() {
            let (p, q) = (first + j as u32, first + j as u32 + 1);
            triangles.push([w[0], p, q]);
            triangles.push([w[0], q, w[1]]);
        }
    }
    Surface {
        vertices,
        triangles,
        front,
    }
}

/// Degenerate triangles, edges shared by more than two triangles or by two of opposite
/// orientation, and a front that is not a walk along the surface's boundary (a vertex off
/// it, listed twice, or two in a row that no boundary edge joins) are errors.
fn check(src: &Source, key: &str, s: &Surface) -> R<()> {
    let scale = s
        .triangles
        .iter()
        .flat_map(|t| t.map(|k| s.vertices[k as usize]))
        .fold(0.0f64, |m, v| m.max(v.abs().max_element()))
        .max(f64::MIN_POSITIVE);
    let mut edges: HashMap<[u32; 2], Vec<(usize, bool)>> = HashMap::new();
    for (k, t) in s.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|i| s.vertices[i as usize]);
        let longest = (b - a).length().max((c - b).length()).max((a - c).length());
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] || longest == 0.0 {
            return Err(src.error(
                key,
                format!("triangle {k} is degenerate (repeated vertices)"),
            ));
        }
        // Twice the area against the longest edge squared: a sliver flatter than 1e-9 of
        // its size, or one lost in round-off at the surface's scale.
        let area2 = (b - a).cross(c - a).length();
        if area2 <= 1e-9 * longest * longest || longest <= 1e-12 * scale {
            return Err(src.error(key, format!("triangle {k} is degenerate (no area)")));
        }
        for i in 0..3 {
            let (p, q) = (t[i], t[(i + 1) % 3]);
            edges
                .entry([p.min(q), p.max(q)])
                .or_default()
                .push((k, p < q));
        }
    }
    let mut boundary = vec![false; s.vertices.len()];
    let mut boundary_edges = HashSet::new();
    let mut sorted: Vec<_> = edges.into_iter().collect();
    sorted.sort_unstable_by_key(|e| e.0);
    for (e, uses) in sorted {
        match uses[..] {
            [_] => {
                boundary[e[0] as usize] = true;
                boundary[e[1] as usize] = true;
                boundary_edges.insert(e);
            }
            [(t1, d1), (t2, d2)] if d1 == d2 => {
                return Err(src.error(
                    key,
                    format!(
                        "triangles {t1} and {t2} are oriented oppositely (they run their shared \
                         edge {}-{} the same way); list every triangle counterclockwise seen \
                         from the same side",
                        e[0], e[1]
                    ),
                ));
            }
            [(t1, _), (t2, _)] => {
                // Consistently oriented, the two normals point to one side: opposite normals
                // are a surface folded flat over itself along this edge.
                let normal = |t: usize| s.triangles[t].normal(&s.vertices);
                let cos = normal(t1).dot(normal(t2));
                if cos < -MIN_FOLD_ANGLE.to_radians().cos() {
                    return Err(src.error(
                        key,
                        format!(
                            "triangles {t1} and {t2} fold over each other along edge {}-{}: \
                             they meet at {:.1} degrees (less than {MIN_FOLD_ANGLE})",
                            e[0],
                            e[1],
                            180.0 - cos.clamp(-1.0, 1.0).acos().to_degrees()
                        ),
                    ));
                }
            }
            _ => {
                return Err(src.error(
                    key,
                    format!(
                        "edge {}-{} is shared by {} triangles: the surface is not a manifold",
                        e[0],
                        e[1],
                        uses.len()
                    ),
                ));
            }
        }
    }
    if let Some(&v) = s.front.iter().find(|&&v| !boundary[v as usize]) {
        return Err(src.error(
            key,
            format!("front vertex {v} is not on the surface's boundary"),
        ));
    }
    check_front_walk(src, key, &s.front, &boundary_edges)
}

/// The front must walk the boundary: each vertex once, each one joined to the next by a
/// boundary edge (a repeated or skipped vertex gave a front frame of NaN).
fn check_front_walk(
    src: &Source,
    key: &str,
    front: &[u32],
    boundary_edges: &HashSet<[u32; 2]>,
) -> R<()> {
    let mut seen = HashSet::new();
    if let Some(&v) = front.iter().find(|&&v| !seen.insert(v)) {
        return Err(src.error(key, format!("front vertex {v} is listed twice")));
    }
    for w in front.windows(2) {
        let (p, q) = (w[0], w[1]);
        if !boundary_edges.contains(&[p.min(q), p.max(q)]) {
            return Err(src.error(
                key,
                format!(
                    "front vertices {p} and {q} follow each other but no boundary edge joins \
                     them: list the front in order along the surface's boundary"
                ),
            ));
        }
    }
    Ok(())
}
