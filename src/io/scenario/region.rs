//! Regions that boundaries, loads and probes select nodes or particles with: axis-aligned
//! boxes, polygons (2D), oriented boxes, discs or balls and half-spaces, so that a specimen rotated in the
//! grid is as easy to describe as an aligned one.

use super::check::{R, vec3};
use super::schema::RegionSpec;
use super::source::Source;
use crate::base::dim::Dim;
use crate::base::geometry::{Aabb, meeting_pairs};
use crate::ranks::domain::Domain;
use crate::store::particles::Particles;
use bytemuck::{Pod, Zeroable};
use glam::{DVec2, DVec3};

/// Most vertices a region polygon may have (its self-crossing check is quadratic).
const MAX_POLYGON: usize = 1000;

/// A checked region, in 3D coordinates (z = 0 in 2D).
#[derive(Clone, Debug)]
pub(super) enum Region {
    /// Axis-aligned box, inclusive.
    Box { lo: [f64; 3], hi: [f64; 3] },
    /// Simple polygon in the plane (2D).
    Polygon(Vec<[f64; 2]>),
    /// Box of half-sizes `half` along the orthonormal `axes` about `center`.
    Oriented {
        center: DVec3,
        axes: [DVec3; 3],
        half: [f64; 3],
    },
    /// The points within `radius` of `center` (a disc in 2D, a ball in 3D).
    Round { center: DVec3, radius: f64 },
    /// The points on the side of the plane through `point` that the unit `normal` points to.
    HalfSpace { point: DVec3, normal: DVec3 },
}

/// `v` scaled to unit length; None for a zero or non-finite one.
fn unit(v: [f64; 3]) -> Option<DVec3> {
    let v = DVec3::from(v);
    let n = v.length();
    (n > 0.0 && n.is_finite()).then(|| v / n)
}

impl Region {
    /// Whether `x` lies in the region or within `tol` (m) of it.
    pub fn contains(&self, x: [f64; 3], dims: usize, tol: f64) -> bool {
        match self {
            Region::Box { lo, hi } => (0..dims).all(|a| x[a] >= lo[a] - tol && x[a] <= hi[a] + tol),
            Region::Polygon(p) => {
                in_polygon(p, [x[0], x[1]]) || edge_distance(p, [x[0], x[1]]) <= tol
            }
            Region::Oriented { center, axes, half } => {
                let d = DVec3::from(x) - *center;
                (0..dims).all(|a| d.dot(axes[a]).abs() <= half[a] + tol)
            }
            Region::Round { center, radius } => (DVec3::from(x) - *center).length() <= radius + tol,
            Region::HalfSpace { point, normal } => (DVec3::from(x) - *point).dot(*normal) >= -tol,
        }
    }
}

/// Even-odd rule.
fn in_polygon(p: &[[f64; 2]], x: [f64; 2]) -> bool {
    let mut inside = false;
    for k in 0..p.len() {
        let (a, b) = (p[k], p[(k + 1) % p.len()]);
        if (a[1] > x[1]) != (b[1] > x[1]) {
            let at = a[0] + (x[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if x[0] < at {
                inside = !inside;
            }
        }
    }
    inside
}

/// Distance from `x` to the polygon's boundary.
fn edge_distance(p: &[[f64; 2]], x: [f64; 2]) -> f64 {
    (0..p.len())
        .map(|k| {
            let (a, b) = (p[k], p[(k + 1) % p.len()]);
            let ab = [b[0] - a[0], b[1] - a[1]];
            let t = (((x[0] - a[0]) * ab[0] + (x[1] - a[1]) * ab[1])
                / (ab[0] * ab[0] + ab[1] * ab[1]))
                .clamp(0.0, 1.0);
            (x[0] - a[0] - t * ab[0]).hypot(x[1] - a[1] - t * ab[1])
        })
        .fold(f64::INFINITY, f64::min)
}

/// Whether segments a-b and c-d cross or touch.
fn segments_meet(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let o = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        robust::orient2d(
            robust::Coord { x: p[0], y: p[1] },
            robust::Coord { x: q[0], y: q[1] },
            robust::Coord { x: r[0], y: r[1] },
        )
    };
    let (d1, d2, d3, d4) = (o(c, d, a), o(c, d, b), o(a, b, c), o(a, b, d));
    let on = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    (d1 * d2 < 0.0 && d3 * d4 < 0.0)
        || (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}

/// A particle a region picked: its number in the whole scene, its position (m), volume
/// (m^3) and its body's particles per cell per direction.
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
#[repr(C)]
pub(super) struct Picked {
    pub id: u64,
    pub x: [f64; 3],
    pub volume: f64,
    pub ppc: f64,
}

/// The particles inside the region a `region` table describes, on every rank, in the whole
/// scene's order (each rank picks among its own); refused when it holds none.
pub(super) fn particles_in<D: Dim>(
    src: &Source,
    key: &str,
    r: &RegionSpec,
    particles: &Particles<D>,
    ppc: &[f64],
    domain: &Domain,
) -> R<Vec<Picked>> {
    let r = region::<D>(src, key, r)?;
    let mine: Vec<Picked> = (0..particles.len())
        .filter(|&p| r.contains(D::to_xyz(particles.x[p]), D::D, 0.0))
        .map(|p| Picked {
            id: particles.id.get(p).copied().unwrap_or(p as u64),
            x: D::to_xyz(particles.x[p]),
            volume: particles.volume[p],
            ppc: ppc[p],
        })
        .collect();
    let sel = domain.in_order(mine, |q| q.id);
    if sel.is_empty() {
        return Err(src.error(key, "the region contains no particle"));
    }
    Ok(sel)
}

/// The region a scenario's `region` table describes, checked (errors name `key`).
pub(super) fn region<D: Dim>(src: &Source, key: &str, r: &RegionSpec) -> R<Region> {
    let k = |s: &str| format!("{key}.{s}");
    let given = [
        r.min.is_some() || r.max.is_some(),
        r.polygon.is_some(),
        r.center.is_some(),
        r.point.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err(src.error(
            key,
            "give exactly one shape: `min` and `max` (a box), `polygon` (2D), `center` with \
             `half` and `angle` (2D) or `axes` (3D) (an oriented box), `center` with `radius` \
             (a disc or ball), or `point` with `normal` (a half-space)",
        ));
    }
    if r.radius.is_some() && r.center.is_none() {
        return Err(src.error(&k("radius"), "a disc or ball needs its `center` too"));
    }
    if let (Some(min), Some(max)) = (&r.min, &r.max) {
        let lo = vec3::<D>(src, &k("min"), min)?;
        let hi = vec3::<D>(src, &k("max"), max)?;
        if (0..D::D).any(|a| hi[a] < lo[a]) {
            return Err(src.error(&k("max"), "max must not be below min"));
        }
        return Ok(Region::Box { lo, hi });
    }
    if r.min.is_some() || r.max.is_some() {
        return Err(src.error(key, "a box needs both `min` and `max`"));
    }
    if let Some(points) = &r.polygon {
        return polygon::<D>(src, &k("polygon"), points);
    }
    if let Some(c) = &r.center {
        let center = DVec3::from(vec3::<D>(src, &k("center"), c)?);
        if let Some(radius) = r.radius {
            if r.half.is_some() || r.angle.is_some() || r.axes.is_some() {
                return Err(src.error(
                    key,
                    "give `radius` (a disc or ball) or `half` with `angle` or `axes` (an \
                     oriented box), not both",
                ));
            }
            if !(radius.is_finite() && radius > 0.0) {
                return Err(src.error(&k("radius"), "the radius must be positive (m)"));
            }
            return Ok(Region::Round { center, radius });
        }
        let half = vec3::<D>(
            src,
            &k("half"),
            r.half.as_deref().ok_or_else(|| {
                src.error(
                    &k("half"),
                    "an oriented box needs `half`, its half-sizes (m)",
                )
            })?,
        )?;
        if (0..D::D).any(|a| half[a].is_nan() || half[a] <= 0.0) {
            return Err(src.error(&k("half"), "half-sizes must be positive (m)"));
        }
        let axes = match (D::D, r.angle, &r.axes) {
            (2, Some(angle), None) if angle.is_finite() => {
                let (s, c) = angle.to_radians().sin_cos();
                [DVec3::new(c, s, 0.0), DVec3::new(-s, c, 0.0), DVec3::Z]
            }
            (2, _, _) => {
                return Err(src.error(
                    &k("angle"),
                    "a 2D oriented box needs a finite `angle` (degrees from +x)",
                ));
            }
            (_, None, Some(axes)) if axes.len() == 2 => {
                let a = unit(vec3::<D>(src, &k("axes[0]"), &axes[0])?);
                let b = unit(vec3::<D>(src, &k("axes[1]"), &axes[1])?);
                let (Some(a), Some(b)) = (a, b) else {
                    return Err(src.error(&k("axes"), "the axes must have non-zero length"));
                };
                if a.dot(b).abs() > 1e-9 {
                    return Err(src.error(&k("axes"), "the two axes must be perpendicular"));
                }
                [a, b, a.cross(b)]
            }
            _ => {
                return Err(src.error(
                    &k("axes"),
                    "a 3D oriented box needs `axes`: its first two axis directions",
                ));
            }
        };
        return Ok(Region::Oriented { center, axes, half });
    }
    let point = DVec3::from(vec3::<D>(
        src,
        &k("point"),
        r.point.as_deref().unwrap_or_default(),
    )?);
    let n = r.normal.as_deref().ok_or_else(|| {
        src.error(
            &k("normal"),
            "a half-space needs `normal`, pointing into it",
        )
    })?;
    let normal = unit(vec3::<D>(src, &k("normal"), n)?)
        .ok_or_else(|| src.error(&k("normal"), "the normal must have non-zero length"))?;
    Ok(Region::HalfSpace { point, normal })
}

/// A checked simple polygon.
fn polygon<D: Dim>(src: &Source, key: &str, points: &[Vec<f64>]) -> R<Region> {
    if D::D != 2 {
        return Err(src.error(key, "polygon regions are 2D (use an oriented box in 3D)"));
    }
    if points.len() < 3 || points.len() > MAX_POLYGON {
        return Err(src.error(key, format!("give 3 to {MAX_POLYGON} vertices [x, y] (m)")));
    }
    let mut p = Vec::with_capacity(points.len());
    for (i, v) in points.iter().enumerate() {
        let c = vec3::<D>(src, &format!("{key}[{i}]"), v)?;
        p.push([c[0], c[1]]);
    }
    simple_polygon(src, key, &p)?;
    Ok(Region::Polygon(p))
}

/// Refuses a polygon (region or body outline) of zero area or whose edges meet other than
/// neighbours at their shared vertex; only edges whose boxes meet are tried
/// ([`meeting_pairs`]).
pub(super) fn simple_polygon(src: &Source, key: &str, p: &[[f64; 2]]) -> R<()> {
    let n = p.len();
    let area: f64 = (0..n)
        .map(|k| {
            let (a, b) = (p[k], p[(k + 1) % n]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum();
    if area == 0.0 || !area.is_finite() {
        return Err(src.error(key, "the polygon is degenerate (zero area)"));
    }
    let boxes: Vec<Aabb<DVec2>> = (0..n)
        .map(|i| Aabb::span(DVec2::from(p[i]), DVec2::from(p[(i + 1) % n])))
        .collect();
    let mut first: Option<(usize, usize)> = None;
    meeting_pairs(&boxes, |i, j| {
        // Neighbouring edges share a vertex; every other pair must not meet.
        let neighbours = j == i + 1 || (i == 0 && j == n - 1);
        if !neighbours
            && first.is_none_or(|f| (i, j) < f)
            && segments_meet(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])
        {
            first = Some((i, j));
        }
    });
    match first {
        Some((i, j)) => Err(src.error(
            key,
            format!("the polygon crosses itself: edges {i} and {j} meet"),
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points inside, outside and on the edge of a rotated square, as polygon and as
    /// oriented box; a half-space.
    #[test]
    fn membership() {
        let (s, c) = 30f64.to_radians().sin_cos();
        let corner = |u: f64, v: f64| [c * u - s * v, s * u + c * v];
        let poly = Region::Polygon(vec![
            corner(-1.0, -1.0),
            corner(1.0, -1.0),
            corner(1.0, 1.0),
            corner(-1.0, 1.0),
        ]);
        let boxed = Region::Oriented {
            center: DVec3::ZERO,
            axes: [DVec3::new(c, s, 0.0), DVec3::new(-s, c, 0.0), DVec3::Z],
            half: [1.0, 1.0, 1.0],
        };
        for (u, v, want) in [
            (0.9, 0.9, true),
            (1.1, 0.0, false),
            (0.0, -1.05, false),
            (-0.99, 0.5, true),
        ] {
            let p = corner(u, v);
            let x = [p[0], p[1], 0.0];
            assert_eq!(poly.contains(x, 2, 0.0), want, "polygon ({u}, {v})");
            assert_eq!(boxed.contains(x, 2, 0.0), want, "box ({u}, {v})");
        }
        let edge = corner(1.0, 0.3);
        assert!(poly.contains([edge[0] + 1e-9, edge[1], 0.0], 2, 1e-6));
        let half = Region::HalfSpace {
            point: DVec3::X,
            normal: DVec3::X,
        };
        assert!(half.contains([1.5, -3.0, 0.0], 2, 0.0) && !half.contains([0.5, 3.0, 0.0], 2, 0.0));
    }

    #[test]
    fn crossing_segments() {
        assert!(segments_meet(
            [0.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [1.0, 0.0]
        ));
        assert!(!segments_meet(
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 1.0],
            [1.0, 1.0]
        ));
        assert!(segments_meet(
            [0.0, 0.0],
            [1.0, 0.0],
            [0.5, 0.0],
            [0.5, 1.0]
        ));
    }
}
