//! The checks every table's builder shares: vectors of the scene's dimension, positive
//! numbers with units, axis names, and names that become folders or CSV columns. A leaf of
//! the scenario module: each builder imports it, it imports none of them.

use super::schema::BoxSpec;
use super::source::Source;
use crate::base::dim::Dim;
use crate::base::error::ScenarioError;
use crate::physics::material::Material;

/// A builder's result: the built part, or the error naming the file, line and key.
pub(super) type R<T> = Result<T, ScenarioError>;

/// A D-vector from a scenario list, padded to 3 (checked length and finiteness).
pub(super) fn vec3<D: Dim>(src: &Source, key: &str, v: &[f64]) -> R<[f64; 3]> {
    if v.len() != D::D {
        return Err(src.error(
            key,
            format!(
                "expected {} components in {}D, found {}",
                D::D,
                D::D,
                v.len()
            ),
        ));
    }
    if v.iter().any(|c| !c.is_finite()) {
        return Err(src.error(key, "components must be finite numbers"));
    }
    let mut out = [0.0; 3];
    out[..D::D].copy_from_slice(v);
    Ok(out)
}

/// The dimension's vector of a padded triple.
pub(super) fn to_vec<D: Dim>(a: [f64; 3]) -> D::Vec {
    D::from_slice(&a[..D::D])
}

/// The index of axis `name` (x, y or z), refused when the scene's dimension lacks it.
pub(super) fn axis_index<D: Dim>(src: &Source, key: &str, name: &str) -> R<usize> {
    let a = match name {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        _ => return Err(src.error(key, format!("unknown axis `{name}` (use x, y or z)"))),
    };
    if a >= D::D {
        return Err(src.error(key, format!("axis `{name}` does not exist in {}D", D::D)));
    }
    Ok(a)
}

/// `v` if it is a finite positive number, else an error giving its unit.
pub(super) fn positive(src: &Source, key: &str, v: f64, unit: &str) -> R<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(src.error(key, format!("must be a positive number ({unit}), got {v}")))
    }
}

/// A box's corners, padded to 3, refused when max lies below min on some axis.
pub(super) fn box_corners<D: Dim>(src: &Source, key: &str, b: &BoxSpec) -> R<([f64; 3], [f64; 3])> {
    let lo = vec3::<D>(src, &format!("{key}.min"), &b.min)?;
    let hi = vec3::<D>(src, &format!("{key}.max"), &b.max)?;
    if (0..D::D).any(|a| hi[a] < lo[a]) {
        return Err(src.error(&format!("{key}.max"), "max must not be below min"));
    }
    Ok((lo, hi))
}

/// Longest scenario name (bytes): the output folder's name, with room for a sweep's
/// `-sweep` under the 255 bytes a file name may have.
const MAX_NAME: usize = 200;

/// Why `name` cannot name an output folder under the output directory (empty, too long,
/// a path separator, `.` or `..`, control characters), or None when it can.
pub fn folder_name_problem(name: &str) -> Option<String> {
    if name.is_empty() {
        Some("must not be empty".into())
    } else if name.len() > MAX_NAME {
        Some(format!("must be at most {MAX_NAME} bytes long"))
    } else if name.contains(['/', '\\']) {
        Some("must not contain a path separator".into())
    } else if name == "." || name == ".." {
        Some("must not be `.` or `..`".into())
    } else if name.chars().any(char::is_control) {
        Some("must not contain control characters".into())
    } else {
        None
    }
}

/// A scenario name (its `name`, else its file's stem) becomes the output folder's name: it
/// must be one plain path component.
pub(super) fn check_name(src: &Source) -> R<()> {
    let name = src.name();
    let bad = folder_name_problem(&name);
    let what = match src.scenario.name {
        Some(_) => "the name".to_string(),
        None => format!(
            "without a `name`, the file's stem `{}`",
            name.escape_debug()
        ),
    };
    match bad {
        Some(why) => Err(src.error(
            "name",
            format!("{what} names the output folder under the output directory: it {why}"),
        )),
        None => Ok(()),
    }
}

/// Refuses a probe's or crack's name that would break the CSV files it heads or fills: an
/// empty one, or one with a comma, a double quote or a control character.
pub(super) fn csv_name(src: &Source, key: &str, name: &str) -> R<()> {
    if name.is_empty() || name.contains([',', '"']) || name.chars().any(char::is_control) {
        return Err(src.error(
            key,
            format!(
                "`{}` names a column or rows of the CSV outputs: give a non-empty name without \
                 commas, double quotes or control characters",
                name.escape_debug()
            ),
        ));
    }
    Ok(())
}

/// The index of the material called `name`, refused under `key` if there is none.
pub(super) fn material_named(
    src: &Source,
    key: &str,
    materials: &[Material],
    name: &str,
) -> R<usize> {
    (materials.iter().position(|m| m.name == name))
        .ok_or_else(|| src.error(key, format!("no [[material]] named `{name}`")))
}

/// Smallest angle (degrees) between two segments of a 2D crack at their shared point, or
/// between two triangles of a 3D crack along their shared edge: a sharper fold lays the
/// crack's faces over each other.
pub(super) const MIN_FOLD_ANGLE: f64 = 30.0;
