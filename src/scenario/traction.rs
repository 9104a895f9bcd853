//! Traction loads: the stress of a closed-form 2D field applied on a body face, as a force
//! on each face particle.

use super::build::{to_vec, vec3};
use super::schema::LoadSpec;
use super::source::Source;
use crate::dim::Dim;
use crate::error::ScenarioError;
use crate::loads::{centre_crack_stress, rotate_stress};
use crate::near_tip;
use crate::particles::Particles;

type R<T> = Result<T, ScenarioError>;

/// A closed-form plane stress field, in global axes.
pub(super) enum Field {
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

impl Field {
    /// The field a `[[load]]` names, if any (at most one).
    pub fn of(src: &Source, key: &dyn Fn(&str) -> String, l: &LoadSpec) -> R<Option<Field>> {
        match (&l.williams, &l.centre_crack) {
            (Some(_), Some(_)) => Err(src.error(
                &key("centre_crack"),
                "give one traction field: `williams` or `centre_crack`",
            )),
            (Some(w), None) => {
                if !(w.k1.is_finite() && w.k2.is_finite() && w.direction.is_finite()) {
                    return Err(src.error(
                        &key("williams"),
                        "KI, KII (Pa sqrt(m)) and direction (degrees) must be finite",
                    ));
                }
                Ok(Some(Field::Williams {
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
                Ok(Some(Field::CentreCrack {
                    remote: rotate_stress([c.stress[0], c.stress[1], c.stress[2]], -angle),
                    center: coords(src, &key("centre_crack.center"), &c.center)?,
                    a: c.half_length,
                    angle,
                }))
            }
            (None, None) => Ok(None),
        }
    }

    /// Global stress at `x`, or None where the field is singular (a tip, a crack face).
    fn stress(&self, x: [f64; 2]) -> Option<[f64; 3]> {
        let local = |origin: &[f64; 3], angle: f64| {
            let (sn, cs) = angle.sin_cos();
            let d = [x[0] - origin[0], x[1] - origin[1]];
            [cs * d[0] + sn * d[1], -sn * d[0] + cs * d[1]]
        };
        match self {
            Field::Williams { k, tip, angle } => {
                let [xl, yl] = local(tip, *angle);
                let r = xl.hypot(yl);
                (r > 0.0)
                    .then(|| rotate_stress(near_tip::stress(k[0], k[1], r, yl.atan2(xl)), *angle))
            }
            Field::CentreCrack {
                remote,
                center,
                a,
                angle,
            } => {
                let [xl, yl] = local(center, *angle);
                centre_crack_stress(*remote, *a, xl, yl).map(|s| rotate_stress(s, *angle))
            }
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

/// The face a traction load acts on.
pub(super) struct Face<'a> {
    /// Scenario key of the load, for errors.
    key: &'a dyn Fn(&str) -> String,
    /// Outward unit normal (any direction in the plane).
    normal: [f64; 3],
    /// Cell sizes (m).
    h: [f64; 3],
}

impl<'a> Face<'a> {
    /// Checks the scenario's `normal`: present, finite and not zero (it is normalised).
    pub fn new<D: Dim>(
        src: &Source,
        key: &'a dyn Fn(&str) -> String,
        normal: Option<&[f64]>,
        h: D::Vec,
    ) -> R<Face<'a>> {
        if D::D != 2 {
            return Err(src.error(&key("normal"), "traction fields are 2D only"));
        }
        let n = normal.ok_or_else(|| {
            src.error(
                &key("normal"),
                "a traction needs the outward normal of its face, e.g. normal = [1.0, 0.0]",
            )
        })?;
        let n = vec3::<D>(src, &key("normal"), n)?;
        let len = n[0].hypot(n[1]);
        if len == 0.0 {
            return Err(src.error(&key("normal"), "the normal must not be zero"));
        }
        Ok(Face {
            key,
            normal: [n[0] / len, n[1] / len, 0.0],
            h: D::to_xyz(h),
        })
    }
}

/// Forces on the face particles `sel`: the traction s . n at each particle's face point
/// times the face area it carries. The selected particles fill a layer under the face;
/// their positions along n fall on k distinct rows, and the layer is as deep as the rows
/// span plus one mean row spacing (a single row: the particle size along n), so each
/// particle carries its volume over that depth and the areas add up to the face's, on a
/// face along a grid line or turned in the grid (where the particles sit on a staircase
/// and the rows are many and close). The face lies half a row spacing beyond the outermost
/// row, and a particle's face point is its projection on it. `ppc` is each particle's
/// particles per cell per direction.
pub(super) fn tractions<D: Dim>(
    src: &Source,
    face: &Face,
    field: &Field,
    sel: &[u32],
    particles: &Particles<D>,
    ppc: &[f64],
) -> R<Vec<D::Vec>> {
    let n = face.normal;
    let along = |p: u32| {
        let x = D::to_xyz(particles.x[p as usize]);
        x[0] * n[0] + x[1] * n[1]
    };
    let mut rows: Vec<f64> = sel.iter().map(|&p| along(p)).collect();
    rows.sort_unstable_by(f64::total_cmp);
    let tol = 1e-9 * face.h[0].min(face.h[1]);
    rows.dedup_by(|a, b| (*a - *b).abs() <= tol);
    let (first, last) = (rows[0], rows[rows.len() - 1]);
    let spacing = if rows.len() > 1 {
        (last - first) / (rows.len() - 1) as f64
    } else {
        let p = sel[0] as usize;
        (face.h[0] * n[0].abs() + face.h[1] * n[1].abs()) / ppc[p]
    };
    let depth = last - first + spacing;
    let outer = last + 0.5 * spacing;
    let mut forces = Vec::with_capacity(sel.len());
    for &p in sel {
        let x = D::to_xyz(particles.x[p as usize]);
        let to_face = outer - along(p);
        let at = [x[0] + to_face * n[0], x[1] + to_face * n[1]];
        let [sxx, syy, sxy] = field.stress(at).ok_or_else(|| {
            src.error(
                &(face.key)("region"),
                format!(
                    "the field is singular at the face point ({:.4e}, {:.4e}) m (a crack tip \
                     or face lies on the loaded face)",
                    at[0], at[1]
                ),
            )
        })?;
        let area = particles.volume[p as usize] / depth;
        let t = [sxx * n[0] + sxy * n[1], sxy * n[0] + syy * n[1], 0.0];
        forces.push(to_vec::<D>(t.map(|c| c * area)));
    }
    Ok(forces)
}
