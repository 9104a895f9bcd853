//! The `[[probe]]` tables: particle averages (or a boundary's reaction) recorded every
//! history row.

use super::check::{R, axis_index, csv_name};
use super::region::{Region, particles_in, region};
use super::schema::{ProbeSpec, RegionSpec};
use super::source::Source;
use crate::base::dim::Dim;
use crate::physics::loads::VelocityBc;
use crate::physics::material::Material;
use crate::ranks::domain::Domain;
use crate::record::probe::{Probe, ProbeQty};
use crate::store::grid::GridGeom;
use crate::store::particles::Particles;

/// Every `[[probe]]`: its quantity and component, and the particles it averages (by their
/// numbers in the whole scene, on every rank; the boundary nodes it sums for a reaction),
/// with their centroid.
pub(super) fn probes<D: Dim>(
    src: &Source,
    geom: &GridGeom<D>,
    particles: &Particles<D>,
    ppc: &[f64],
    domain: &Domain,
    bcs: &[VelocityBc<D>],
    materials: &[Material],
) -> R<Vec<Probe>> {
    let sc = &src.scenario;
    let mut probes: Vec<Probe> = Vec::new();
    for (i, p) in sc.probes.iter().enumerate() {
        let key = |k: &str| format!("probe[{i}].{k}");
        csv_name(src, &key("name"), &p.name)?;
        if probes.iter().any(|q| q.name == p.name) {
            return Err(src.error(&key("name"), format!("duplicate probe `{}`", p.name)));
        }
        let (qty, comp, component) = quantity::<D>(src, &key, p)?;
        if qty == ProbeQty::Reaction {
            let (supports, centre) = supports::<D>(src, &key, &p.region, bcs, geom, comp)?;
            probes.push(Probe {
                name: p.name.clone(),
                particles: Vec::new(),
                ids: Vec::new(),
                supports,
                qty,
                comp,
                centre,
            });
            continue;
        }
        let sel = particles_in(src, &key("region"), &p.region, particles, ppc, domain)?;
        let mut centre = [0.0; 3];
        for q in &sel {
            let x = q.x;
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
                Region::Round { center, .. } => centre = center.to_array(),
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
            let beyond = (sel.iter()).filter(|q| q.x[comp] > centre[comp]).count();
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
            particles: sel.iter().map(|q| q.id as u32).collect(),
            ids: Vec::new(),
            supports: Vec::new(),
            qty,
            comp,
            centre,
        });
    }
    Ok(probes)
}

/// A probe's quantity, its component's index (an axis, or a tensor component in Voigt
/// order xx, yy, zz, yz, xz, xy) and the component's name as given.
fn quantity<'a, D: Dim>(
    src: &Source,
    key: &dyn Fn(&str) -> String,
    p: &'a ProbeSpec,
) -> R<(ProbeQty, usize, Option<&'a str>)> {
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
    Ok((qty, comp, component))
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
