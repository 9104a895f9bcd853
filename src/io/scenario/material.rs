//! The `[[material]]` tables: elastic constants, and the J2 parameters of plastic ones.

use super::check::positive;
use super::schema::{MaterialSpec, ModelKind};
use super::source::Source;
use crate::base::error::ScenarioError;
use crate::physics::material::{Material, Plane};
use crate::physics::plastic::Hardening;

type R<T> = Result<T, ScenarioError>;

/// Largest yield strain sigma_y / E: small-strain plasticity is meant for metals, whose
/// yield strain is below 1 %; beyond 10 % the small-strain assumption fails before yield.
const MAX_YIELD_STRAIN: f64 = 0.1;

/// Largest Ramberg-Osgood exponent; above it the law is perfect plasticity for any strain
/// a small-strain model reaches (use `H = 0`).
const MAX_EXPONENT: f64 = 100.0;

/// The scene's materials, each checked: positive E and rho, -1 < nu < 0.5, finite derived
/// moduli, and for `model = "j2"` a yield stress with one hardening law.
pub(super) fn materials(src: &Source, specs: &[MaterialSpec]) -> R<Vec<Material>> {
    // The count is checked first and names through a set, so that a scenario with tens of
    // thousands of tables is refused at once.
    if specs.len() > u16::MAX as usize {
        return Err(src.error(
            "material",
            format!("{} materials: at most {} per scene", specs.len(), u16::MAX),
        ));
    }
    let mut names = std::collections::HashSet::new();
    specs
        .iter()
        .enumerate()
        .map(|(i, m)| {
            if !names.insert(m.name.as_str()) {
                let key = format!("material[{i}].name");
                return Err(src.error(&key, format!("duplicate material `{}`", m.name)));
            }
            material(src, i, m)
        })
        .collect()
}

fn material(src: &Source, i: usize, m: &MaterialSpec) -> R<Material> {
    let key = |k: &str| format!("material[{i}].{k}");
    positive(src, &key("E"), m.youngs, "Pa")?;
    positive(src, &key("rho"), m.rho, "kg/m^3")?;
    if !(m.nu > -1.0 && m.nu < 0.5) {
        return Err(src.error(
            &key("nu"),
            format!("Poisson's ratio must satisfy -1 < nu < 0.5, got {}", m.nu),
        ));
    }
    let e = Material::new(&m.name, m.youngs, m.nu, m.rho);
    let c = e.wave_speed(Plane::Strain).max(e.wave_speed(Plane::Stress));
    if !(c.is_finite() && c > 0.0 && e.lambda.is_finite() && e.mu.is_finite()) {
        return Err(src.error(
            &key("E"),
            format!(
                "E = {:e} Pa with rho = {:e} kg/m^3 and nu = {} overflow the derived \
                 moduli or wave speed",
                m.youngs, m.rho, m.nu
            ),
        ));
    }
    if m.model == ModelKind::Elastic {
        for (name, given) in [
            ("sigma_y", m.sigma_y.is_some()),
            ("H", m.hardening.is_some()),
            ("n", m.n.is_some()),
            ("alpha", m.alpha.is_some()),
        ] {
            if given {
                return Err(src.error(
                    &key(name),
                    format!("`{name}` is a plasticity parameter; set model = \"j2\" to use it"),
                ));
            }
        }
        return Ok(e);
    }
    let Some(sigma_y) = m.sigma_y else {
        return Err(src.error(
            &key("model"),
            "model = \"j2\" needs the initial yield stress `sigma_y` (Pa)",
        ));
    };
    positive(src, &key("sigma_y"), sigma_y, "Pa")?;
    if sigma_y > MAX_YIELD_STRAIN * m.youngs {
        return Err(src.error(
            &key("sigma_y"),
            format!(
                "the yield strain sigma_y/E = {:.3e} is above {MAX_YIELD_STRAIN}: small-strain \
                 plasticity does not hold there",
                sigma_y / m.youngs
            ),
        ));
    }
    let hardening = match (m.hardening, m.n) {
        (Some(_), Some(_)) => {
            return Err(src.error(
                &key("n"),
                "give one hardening law: `H` (linear) or `n` (Ramberg-Osgood), not both",
            ));
        }
        (h, None) => {
            let modulus = h.unwrap_or(0.0);
            if !(modulus.is_finite() && modulus >= 0.0) {
                return Err(src.error(
                    &key("H"),
                    format!("the hardening modulus must be zero or positive (Pa), got {modulus}"),
                ));
            }
            Hardening::Linear { modulus }
        }
        (None, Some(n)) => {
            if !(n > 1.0 && n <= MAX_EXPONENT) {
                return Err(src.error(
                    &key("n"),
                    format!(
                        "the Ramberg-Osgood exponent must satisfy 1 < n <= {MAX_EXPONENT}, got {n}"
                    ),
                ));
            }
            match m.alpha {
                None => Hardening::RambergOsgood { exponent: n },
                Some(alpha) if alpha.is_finite() && alpha > 0.0 => {
                    Hardening::Handbook { alpha, exponent: n }
                }
                Some(alpha) => {
                    return Err(src.error(
                        &key("alpha"),
                        format!("the Ramberg-Osgood alpha must be positive, got {alpha}"),
                    ));
                }
            }
        }
    };
    if m.alpha.is_some() && m.n.is_none() {
        return Err(src.error(
            &key("alpha"),
            "`alpha` belongs to the Ramberg-Osgood law: give its exponent `n` too",
        ));
    }
    Ok(e.with_j2(sigma_y, hardening))
}
