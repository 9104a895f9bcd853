//! Traction loads: a pressure, or the stress of a closed-form 2D field, applied on a body
//! face (planar, or a circle or sphere about a centre) as a force on each face particle.

use super::check::{to_vec, vec3};
use super::region::Picked;
use super::schema::{LoadSpec, PressureSpec};
use super::source::Source;
use crate::base::dim::Dim;
use crate::base::error::ScenarioError;
use crate::physics::loads::{centre_crack_stress, rotate_stress};
use crate::physics::near_tip;

type R<T> = Result<T, ScenarioError>;

/// A stress field on a face, in global axes.
pub(super) enum StressField {
    /// A uniform pressure (Pa): the stress -p I, so the traction is -p n.
    Pressure(f64),
    /// Williams near-tip field: K_I, K_II (Pa sqrt(m)), tip (m), crack direction (rad).
    Williams {
        k: [f64; 2],
        tip: [f64; 3],
        angle: f64,
    },
    /// Centre crack in an infinite plate: remote stress in crack axes (Pa), centre (m),
    /// half-length (m), crack angle (rad).
    CentreCrack {
        remote: [f64; 3],
        center: [f64; 3],
        a: f64,
        angle: f64,
    },
}

impl StressField {
    /// The field a `[[load]]` names, if any (at most one).
    pub fn of<D: Dim>(
        src: &Source,
        key: &dyn Fn(&str) -> String,
        l: &LoadSpec,
    ) -> R<Option<StressField>> {
        let named = [
            l.pressure.is_some(),
            l.williams.is_some(),
            l.centre_crack.is_some(),
        ];
        if named.iter().filter(|&&n| n).count() > 1 {
            return Err(src.error(
                &key("pressure"),
                "give one traction: `pressure`, `williams` or `centre_crack`",
            ));
        }
        if let Some(p) = &l.pressure {
            if !p.value.is_finite() {
                return Err(src.error(&key("pressure.value"), "the pressure must be finite (Pa)"));
            }
            return Ok(Some(StressField::Pressure(p.value)));
        }
        if D::D != 2 && (l.williams.is_some() || l.centre_crack.is_some()) {
            return Err(src.error(
                &key(if l.williams.is_some() {
                    "williams"
                } else {
                    "centre_crack"
                }),
                "the williams and centre_crack fields are 2D only",
            ));
        }
        match (&l.williams, &l.centre_crack) {
            (Some(_), Some(_)) => unreachable!("checked above"),
            (Some(w), None) => {
                if !(w.k1.is_finite() && w.k2.is_finite() && w.direction.is_finite()) {
                    return Err(src.error(
                        &key("williams"),
                        "KI, KII (Pa sqrt(m)) and direction (degrees) must be finite",
                    ));
                }
                Ok(Some(StressField::Williams {
                    k: [w.k1, w.k2],
                    tip: coords(src, &key("williams.tip"), &w.tip)?,
                    angle: w.direction.to_radians(),
                }))
            }
            (None, Some(c)) => {
                if c.stress.len() != 3 || c.stress.iter().any(|v| !v.is_finite()) {
                    return Err(src.error(
                        &key("centre_crack.stress"),
                        "give the remote stress as three finite values [xx, yy, xy] (Pa)",
                    ));
                }
                if !c.angle.is_finite() {
                    return Err(src.error(
                        &key("centre_crack.angle"),
                        "the angle must be finite (degrees)",
                    ));
                }
                if !c.half_length.is_finite() || c.half_length <= 0.0 {
                    return Err(src.error(
                        &key("centre_crack.half_length"),
                        "the half-length must be positive and finite (m)",
                    ));
                }
                let angle = c.angle.to_radians();
                Ok(Some(StressField::CentreCrack {
                    remote: rotate_stress([c.stress[0], c.stress[1], c.stress[2]], -angle),
                    center: coords(src, &key("centre_crack.center"), &c.center)?,
                    a: c.half_length,
                    angle,
                }))
            }
            (None, None) => Ok(None),
        }
    }

    /// Traction on the face with outward unit normal `n` at `x`, or None where the field
    /// is singular (a tip, a crack face).
    fn traction(&self, x: [f64; 3], n: [f64; 3]) -> Option<[f64; 3]> {
        if let StressField::Pressure(p) = self {
            return Some(n.map(|c| -p * c));
        }
        let [sxx, syy, sxy] = self.plane_stress([x[0], x[1]])?;
        Some([sxx * n[0] + sxy * n[1], sxy * n[0] + syy * n[1], 0.0])
    }

    /// Global plane stress (xx, yy, xy) of a 2D field at `x`, or None where it is singular.
    fn plane_stress(&self, x: [f64; 2]) -> Option<[f64; 3]> {
        let local = |origin: &[f64; 3], angle: f64| {
            let (sn, cs) = angle.sin_cos();
            let d = [x[0] - origin[0], x[1] - origin[1]];
            [cs * d[0] + sn * d[1], -sn * d[0] + cs * d[1]]
        };
        match self {
            StressField::Williams { k, tip, angle } => {
                let [xl, yl] = local(tip, *angle);
                let r = xl.hypot(yl);
                (r > 0.0)
                    .then(|| rotate_stress(near_tip::stress(k[0], k[1], r, yl.atan2(xl)), *angle))
            }
            StressField::CentreCrack {
                remote,
                center,
                a,
                angle,
            } => {
                let [xl, yl] = local(center, *angle);
                centre_crack_stress(*remote, *a, xl, yl).map(|s| rotate_stress(s, *angle))
            }
            StressField::Pressure(_) => unreachable!("a pressure has no plane stress"),
        }
    }
}

/// Two coordinates (m) from a 2-vector in the scenario.
fn coords(src: &Source, key: &str, v: &[f64]) -> R<[f64; 3]> {
    if v.len() != 2 || v.iter().any(|c| !c.is_finite()) {
        return Err(src.error(key, "give two finite coordinates (m)"));
    }
    Ok([v[0], v[1], 0.0])
}

/// The shape of a loaded face.
enum Shape {
    /// A plane with this outward unit normal.
    Plane([f64; 3]),
    /// A circle (2D) or sphere (3D) about `center`: the loaded layer's inner side (a bore,
    /// outward normal towards the centre) or its outer side.
    Round { center: [f64; 3], inner: bool },
}

/// The face a traction load acts on.
pub(super) struct Face<'a> {
    /// Scenario key of the load, for errors.
    key: &'a dyn Fn(&str) -> String,
    /// Its shape.
    shape: Shape,
    /// Cell sizes (m).
    h: [f64; 3],
    /// Dimensions used.
    dims: usize,
}

impl<'a> Face<'a> {
    /// The face of load `l`: round when its pressure names a `center`, otherwise planar with
    /// the load's `normal` (present, finite, not zero; it is normalised).
    pub fn new<D: Dim>(
        src: &Source,
        key: &'a dyn Fn(&str) -> String,
        l: &LoadSpec,
        h: D::Vec,
    ) -> R<Face<'a>> {
        let face = |shape| Face {
            key,
            shape,
            h: D::to_xyz(h),
            dims: D::D,
        };
        if let Some(PressureSpec {
            center: Some(c),
            face: side,
            ..
        }) = &l.pressure
        {
            if l.normal.is_some() {
                return Err(src.error(
                    &key("normal"),
                    "a pressure about a `center` acts along the radius: leave out `normal`",
                ));
            }
            let inner = match side.as_deref() {
                Some("inner") => true,
                Some("outer") => false,
                _ => {
                    return Err(src.error(
                        &key("pressure.face"),
                        "a round face is the loaded layer's \"inner\" side (a bore) or its \
                         \"outer\" side",
                    ));
                }
            };
            let center = vec3::<D>(src, &key("pressure.center"), c)?;
            return Ok(face(Shape::Round { center, inner }));
        }
        if let Some(PressureSpec { face: Some(_), .. }) = &l.pressure {
            return Err(src.error(
                &key("pressure.face"),
                "`face` goes with a round face's `center`",
            ));
        }
        let n = l.normal.as_deref().ok_or_else(|| {
            src.error(
                &key("normal"),
                "a traction needs the outward normal of its face, e.g. normal = [1.0, 0.0], \
                 or for a pressure a round face's `center`",
            )
        })?;
        let n = vec3::<D>(src, &key("normal"), n)?;
        let len = n[0].hypot(n[1]).hypot(n[2]);
        if len == 0.0 {
            return Err(src.error(&key("normal"), "the normal must not be zero"));
        }
        Ok(face(Shape::Plane(n.map(|c| c / len))))
    }

    /// Signed distance of `x` along the outward normal (for a round face, the radius, negated
    /// on a bore) and the outward unit normal there; None at a round face's centre.
    fn locate(&self, x: [f64; 3]) -> Option<(f64, [f64; 3])> {
        match self.shape {
            Shape::Plane(n) => Some(((0..3).map(|a| x[a] * n[a]).sum(), n)),
            Shape::Round { center, inner } => {
                let d = [0, 1, 2].map(|a| if a < self.dims { x[a] - center[a] } else { 0.0 });
                let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let s = if inner { -1.0 } else { 1.0 };
                (r > 0.0).then(|| (s * r, d.map(|c| s * c / r)))
            }
        }
    }
}

/// Forces on the face particles `sel`: the traction at each particle's face point times
/// the face area it carries. The selected particles fill a layer under the face; their
/// distances along the outward normal fall on k distinct rows, and the layer is as deep as
/// the rows span plus one mean row spacing (a single row: the particle size along n), so
/// each particle carries its volume over that depth and the areas add up to the face's, on
/// a face along a grid line or turned in the grid or round (where the particles sit on a
/// staircase and the rows are many and close). The face lies half a row spacing beyond the
/// outermost row, and a particle's face point is its projection on it. On a round face of
/// radius R a particle at radius r carries (R / r)^(d-1) of its share, so that the shares of
/// a curved layer add up to the face's area.
pub(super) fn tractions<D: Dim>(
    src: &Source,
    face: &Face,
    field: &StressField,
    sel: &[Picked],
) -> R<Vec<D::Vec>> {
    let mut placed = Vec::with_capacity(sel.len());
    for q in sel {
        let x = q.x;
        let (along, n) = face.locate(x).ok_or_else(|| {
            src.error(
                &(face.key)("region"),
                "a loaded particle sits at the round face's centre, where it has no normal",
            )
        })?;
        placed.push((x, along, n));
    }
    let mut rows: Vec<f64> = placed.iter().map(|q| q.1).collect();
    rows.sort_unstable_by(f64::total_cmp);
    let tol = 1e-9
        * face.h[..face.dims]
            .iter()
            .fold(f64::INFINITY, |a, &b| a.min(b));
    rows.dedup_by(|a, b| (*a - *b).abs() <= tol);
    let (first, last) = (rows[0], rows[rows.len() - 1]);
    let spacing = if rows.len() > 1 {
        (last - first) / (rows.len() - 1) as f64
    } else {
        let n = placed[0].2;
        (0..face.dims).map(|a| face.h[a] * n[a].abs()).sum::<f64>() / sel[0].ppc
    };
    let depth = last - first + spacing;
    let outer = last + 0.5 * spacing;
    let mut forces = Vec::with_capacity(sel.len());
    for (q, &(x, along, n)) in sel.iter().zip(&placed) {
        let to_face = outer - along;
        let at = [0, 1, 2].map(|a| x[a] + to_face * n[a]);
        let t = field.traction(at, n).ok_or_else(|| {
            src.error(
                &(face.key)("region"),
                format!(
                    "the field is singular at the face point ({:.4e}, {:.4e}) m (a crack tip \
                     or face lies on the loaded face)",
                    at[0], at[1]
                ),
            )
        })?;
        let curved = match face.shape {
            Shape::Plane(_) => 1.0,
            Shape::Round { .. } => (outer / along).abs().powi(face.dims as i32 - 1),
        };
        let area = q.volume / depth * curved;
        forces.push(to_vec::<D>(t.map(|c| c * area)));
    }
    Ok(forces)
}
