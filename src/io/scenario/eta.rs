//! The `J_eta` expect: a crack tip's J against the eta estimate from the scene's own
//! load-displacement record (see [`crate::fracture::eta`]).

use super::check::{material_named, positive};
use super::cracks::expect_tip;
use super::schema::ExpectSpec;
use super::source::Source;
use crate::base::error::ScenarioError;
use crate::fracture::eta::EtaEstimate;
use crate::fracture::plan::e_prime;
use crate::physics::material::{Material, Plane};
use crate::record::expect::Measure;

type R<T> = Result<T, ScenarioError>;

/// The measure of a `J_eta` expect, whose probes `ids` are the load's and the
/// displacement's; E' from the named material in the scene's `plane`, B its `thickness`.
pub(super) fn eta_measure(
    src: &Source,
    i: usize,
    e: &ExpectSpec,
    ids: &[usize],
    materials: &[Material],
    plane: Plane,
    thickness: f64,
) -> R<Measure> {
    let key = |k: &str| format!("expect[{i}].{k}");
    let (crack, tip) = expect_tip(src, i, e)?;
    let &[load, displacement] = ids else {
        return Err(src.error(
            &key("probes"),
            "`J_eta` takes two probes: the load (e.g. a support's reaction) and the \
             displacement it works through",
        ));
    };
    if e.at.is_some() {
        return Err(src.error(&key("at"), "`J_eta` is read at the end of the run"));
    }
    let Some(spec) = &e.eta else {
        return Err(src.error(
            &key("eta"),
            "give the specimen's estimate: eta = { factor, ligament, K_per_load, material }",
        ));
    };
    let material = material_named(src, &key("eta.material"), materials, &spec.material)?;
    Ok(Measure::JEta {
        crack,
        tip,
        load,
        displacement,
        estimate: EtaEstimate {
            factor: positive(src, &key("eta.factor"), spec.factor, "dimensionless")?,
            ligament: positive(src, &key("eta.ligament"), spec.ligament, "m")?,
            k_per_load: positive(src, &key("eta.K_per_load"), spec.k_per_load, "Pa sqrt(m)/N")?,
            modulus: e_prime(&materials[material], plane),
            thickness,
        },
    })
}
