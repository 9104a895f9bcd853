//! The `[[load]]` tables: forces and tractions on the particles of a region.

use super::check::{R, to_vec, vec3};
use super::region::particles_in;
use super::source::Source;
use super::traction::{Face, StressField, tractions};
use crate::base::dim::Dim;
use crate::physics::loads::Load;
use crate::ranks::domain::Domain;
use crate::store::grid::GridGeom;
use crate::store::particles::Particles;

/// Every `[[load]]`: a total force shared equally by its region's particles, or a
/// traction (pressure or a closed-form field) over the face they make. Each load lists
/// its particles by their numbers in the whole scene, on every rank.
pub(super) fn loads<D: Dim>(
    src: &Source,
    geom: &GridGeom<D>,
    particles: &Particles<D>,
    ppc: &[f64],
    domain: &Domain,
) -> R<Vec<Load<D>>> {
    let sc = &src.scenario;
    let mut loads = Vec::new();
    for (i, l) in sc.loads.iter().enumerate() {
        let key = |k: &str| format!("load[{i}].{k}");
        let sel = particles_in(src, &key("region"), &l.region, particles, ppc, domain)?;
        if let Some(msg) = l.time.check() {
            return Err(src.error(&key("time"), msg));
        }
        let forces = match (&l.force, StressField::of::<D>(src, &key, l)?) {
            (Some(f), None) => {
                if l.normal.is_some() {
                    return Err(src.error(&key("normal"), "`normal` goes with a traction"));
                }
                let f = vec3::<D>(src, &key("force"), f)?;
                vec![to_vec::<D>(f.map(|c| c / sel.len() as f64)); sel.len()]
            }
            (None, Some(field)) => {
                let face = Face::new::<D>(src, &key, l, geom.h)?;
                tractions::<D>(src, &face, &field, &sel)?
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
            particles: sel.iter().map(|q| q.id as u32).collect(),
            ids: Vec::new(),
            time: l.time.clone(),
        });
    }
    Ok(loads)
}
