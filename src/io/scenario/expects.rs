//! The `[[expect]]` tables: the checks a run makes of itself, read from its history
//! (probes, energies, momenta) or at its cracks (J, K, paths, growth).

use super::check::{R, positive};
use super::schema::ExpectSpec;
use super::source::Source;
use crate::base::dim::Dim;
use crate::physics::material::{Material, Plane};
use crate::record::expect::{Expect, Measure};
use crate::record::probe::Probe;
use crate::store::grid::GridGeom;

/// Every `[[expect]]`, with the probes it names resolved to their indices.
pub(super) fn expects<D: Dim>(
    src: &Source,
    probes: &[Probe],
    geom: &GridGeom<D>,
    materials: &[Material],
    plane: Plane,
    thickness: f64,
) -> R<Vec<Expect>> {
    let sc = &src.scenario;
    let mut expects = Vec::new();
    for (i, e) in sc.expects.iter().enumerate() {
        let key = |k: &str| format!("expect[{i}].{k}");
        if !e.reference.is_finite() {
            return Err(src.error(&key("reference"), "must be a finite number"));
        }
        let mut ids = Vec::new();
        for name in &e.probes {
            let id = probes
                .iter()
                .position(|p| &p.name == name)
                .ok_or_else(|| src.error(&key("probes"), format!("no probe named `{name}`")))?;
            ids.push(id);
        }
        let at_crack = crack_expect::<D>(src, i, e, &ids, geom, materials, plane, thickness)?;
        expects.push(match at_crack {
            Some(x) => x,
            None => history_expect(src, i, e, &ids)?,
        });
    }
    Ok(expects)
}

/// Checks the keys that belong to particular quantities (`from`, `eta`, `along`, `near`,
/// and which quantities exist in 2D or 3D), then builds the expect if its quantity is read
/// at a crack; None for one read from the history.
#[allow(clippy::too_many_arguments)]
fn crack_expect<D: Dim>(
    src: &Source,
    i: usize,
    e: &ExpectSpec,
    ids: &[usize],
    geom: &GridGeom<D>,
    materials: &[Material],
    plane: Plane,
    thickness: f64,
) -> R<Option<Expect>> {
    let key = |k: &str| format!("expect[{i}].{k}");
    // Crack-tip quantities name a crack and a tip instead of probes.
    let tip_qty = ["KI", "KII", "J1", "J2"]
        .iter()
        .position(|q| *q == e.quantity);
    let windowed = ["K_drift", "G_interaction", "kinetic_fraction", "slope"];
    if e.from.is_some() && !windowed.contains(&e.quantity.as_str()) {
        return Err(src.error(
            &key("from"),
            "`from` applies to K_drift, G_interaction, kinetic_fraction and slope",
        ));
    }
    let front_qty = ["KI_front", "KII_front", "KIII_front", "J1_front"]
        .iter()
        .position(|q| *q == e.quantity);
    let tip_like =
        tip_qty.is_some() || ["K_drift", "J_eta", "G_interaction"].contains(&e.quantity.as_str());
    if e.eta.is_some() && e.quantity != "J_eta" {
        return Err(src.error(&key("eta"), "`eta` applies to J_eta"));
    }
    if e.material.is_some() && e.quantity != "G_interaction" {
        return Err(src.error(&key("material"), "`material` applies to G_interaction"));
    }
    if D::D == 3 && tip_like {
        return Err(src.error(
            &key("quantity"),
            format!(
                "`{}` is measured at a 2D crack tip; along a 3D front use KI_front, \
                 KII_front, KIII_front or J1_front",
                e.quantity
            ),
        ));
    }
    let path_3d = D::D == 3 && e.quantity == "J_path";
    for (k, given, also) in [
        ("along", e.along.is_some(), ""),
        ("near", e.near.is_some() && !path_3d, " (and J_path in 3D)"),
    ] {
        if given && front_qty.is_none() {
            return Err(src.error(
                &key(k),
                format!("`{k}` applies to KI_front, KII_front, KIII_front and J1_front{also}"),
            ));
        }
    }
    if D::D == 2 && front_qty.is_some() {
        return Err(src.error(
            &key("quantity"),
            format!(
                "`{}` runs along a 3D crack front; at a 2D tip use KI, KII, J1 or J2",
                e.quantity
            ),
        ));
    }
    let crack_measure = match (tip_qty, front_qty) {
        (Some(qty), _) => Some(super::cracks::tip_measure(src, i, e, qty)?),
        (_, Some(qty)) => Some(super::cracks::front_measure(src, i, e, qty)?),
        _ if e.quantity == "J_path" => Some(super::cracks::path_measure::<D>(src, i, e, geom)?),
        _ if e.quantity == "K_drift" => Some(super::cracks::drift_measure(src, i, e)?),
        _ if e.quantity == "G_interaction" => Some(super::cracks::g_interaction_measure::<D>(
            src, i, e, geom, materials, plane,
        )?),
        _ if e.quantity == "J_eta" => Some(super::eta::eta_measure(
            src, i, e, ids, materials, plane, thickness,
        )?),
        _ if ["kink", "path_angle", "turn", "cycles"].contains(&e.quantity.as_str()) => {
            if D::D == 3 && !["cycles", "kink"].contains(&e.quantity.as_str()) {
                return Err(src.error(
                    &key("quantity"),
                    format!("`{}` follows a growing 2D tip", e.quantity),
                ));
            }
            Some(super::growth::growth_measure(src, i, e, D::D == 3)?)
        }
        _ => None,
    };
    let Some(measure) = crack_measure else {
        return Ok(None);
    };
    positive(src, &key("tolerance"), e.tolerance, "relative")?;
    if !ids.is_empty() && e.quantity != "J_eta" {
        return Err(src.error(
            &key("probes"),
            format!("`{}` is read at a crack: it takes no probes", e.quantity),
        ));
    }
    Ok(Some(Expect {
        quantity: e.quantity.clone(),
        probes: e
            .crack
            .iter()
            .cloned()
            .chain([e.tip.clone().unwrap_or_else(|| match &e.near {
                Some(p) if D::D == 3 => format!("near {p:?}"),
                _ if D::D == 3 => "front".into(),
                _ => "end".into(),
            })])
            .chain(e.at.map(|t| format!("t={t:.3e}")))
            .chain(e.probes.iter().cloned())
            .collect(),
        measure,
        reference: e.reference,
        source: e.source.clone(),
        tolerance: e.tolerance,
    }))
}

/// An expect read from the history: a probe's final, extreme or rate value, or a drift of
/// energy or momentum, with the probe count each quantity takes.
fn history_expect(src: &Source, i: usize, e: &ExpectSpec, ids: &[usize]) -> R<Expect> {
    let key = |k: &str| format!("expect[{i}].{k}");
    if let Some(at) = e.at {
        let end = src.scenario.simulation.duration;
        if e.quantity != "final" {
            return Err(src.error(&key("at"), "`at` applies to final, KI, KII, J1 and J2"));
        }
        if !(0.0..=end).contains(&at) {
            return Err(src.error(
                &key("at"),
                format!("the time must lie in the run, 0 to {end:.4e} s"),
            ));
        }
    }
    if e.length.is_some() {
        return Err(src.error(&key("length"), "`length` applies to cycles"));
    }
    let need = match e.quantity.as_str() {
        "wave_speed" | "slope" => 2,
        "final" | "max" | "min" | "frequency" => 1,
        "momentum_drift" | "energy_drift" | "angular_momentum_drift" | "kinetic_fraction" => 0,
        other => {
            return Err(src.error(
                &key("quantity"),
                format!(
                    "unknown quantity `{other}` (final, max, min, frequency, wave_speed, \
                     slope, momentum_drift, energy_drift, angular_momentum_drift, KI, KII, J1, J2, \
                     J_path, K_drift, G_interaction, J_eta, kinetic_fraction, KI_front, KII_front, \
                     KIII_front, J1_front, kink, path_angle, turn, cycles)"
                ),
            ));
        }
    };
    if ids.len() != need {
        return Err(src.error(
            &key("probes"),
            format!(
                "`{}` takes {need} probe name(s), got {}",
                e.quantity,
                ids.len()
            ),
        ));
    }
    let measure = match e.quantity.as_str() {
        "final" => Measure::Final {
            probe: ids[0],
            at: e.at,
        },
        "max" => Measure::Max(ids[0]),
        "min" => Measure::Min(ids[0]),
        "frequency" => Measure::Frequency(ids[0]),
        "wave_speed" => Measure::WaveSpeed(ids[0], ids[1]),
        "slope" => {
            let end = src.scenario.simulation.duration;
            match e.from {
                Some(from) if (0.0..end).contains(&from) => Measure::Slope {
                    rise: ids[0],
                    run: ids[1],
                    from,
                },
                _ => {
                    return Err(src.error(
                        &key("from"),
                        format!(
                            "`slope` is the change of its first probe over its second's \
                             from `from` to the end: give `from`, 0 to {end:.4e} s"
                        ),
                    ));
                }
            }
        }
        "momentum_drift" => Measure::MomentumDrift,
        "energy_drift" => Measure::EnergyDrift,
        "kinetic_fraction" => {
            let end = src.scenario.simulation.duration;
            match e.from {
                Some(from) if (0.0..end).contains(&from) => Measure::KineticFraction { from },
                _ => {
                    return Err(src.error(
                        &key("from"),
                        format!(
                            "`kinetic_fraction` runs over a window: give its start \
                             `from`, 0 to {end:.4e} s"
                        ),
                    ));
                }
            }
        }
        _ => Measure::AngularMomentumDrift,
    };
    positive(
        src,
        &key("tolerance"),
        e.tolerance,
        "relative, or absolute for reference 0",
    )?;
    Ok(Expect {
        quantity: e.quantity.clone(),
        probes: e.probes.clone(),
        measure,
        reference: e.reference,
        source: e.source.clone(),
        tolerance: e.tolerance,
    })
}
