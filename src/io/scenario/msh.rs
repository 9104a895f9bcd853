//! Gmsh MSH 4.1 files (ASCII or binary, parsed with `mshio`): the triangles of a surface
//! mesh (quadrangles split in two), or the boundary of a volume mesh (the faces of its
//! tetrahedra, hexahedra, prisms and pyramids that no second element shares), each face
//! turned to point out of its element. Higher-order elements are read by their corners.

use crate::base::geometry::TriangleList;
use mshio::mshfile::{ElementType, MshFile};
use std::collections::HashMap;
use std::path::Path;

/// The faces of a volume element as corner indices, each counterclockwise seen from
/// outside a positively oriented element (Gmsh's corner numbering).
const TET: &[&[usize]] = &[&[0, 2, 1], &[0, 1, 3], &[0, 3, 2], &[1, 2, 3]];
const HEX: &[&[usize]] = &[
    &[0, 3, 2, 1],
    &[4, 5, 6, 7],
    &[0, 1, 5, 4],
    &[1, 2, 6, 5],
    &[2, 3, 7, 6],
    &[3, 0, 4, 7],
];
const PRISM: &[&[usize]] = &[
    &[0, 2, 1],
    &[3, 4, 5],
    &[0, 1, 4, 3],
    &[1, 2, 5, 4],
    &[2, 0, 3, 5],
];
const PYRAMID: &[&[usize]] = &[
    &[0, 3, 2, 1],
    &[0, 1, 4],
    &[1, 2, 4],
    &[2, 3, 4],
    &[3, 0, 4],
];

/// What an element type contributes to a surface.
enum Kind {
    /// Points and lines: nothing.
    Skip,
    /// A surface element with this many corners (3 or 4).
    Face(usize),
    /// A volume element with these faces.
    Solid(&'static [&'static [usize]]),
}

fn kind(t: ElementType) -> Option<Kind> {
    use ElementType::*;
    Some(match t {
        Pnt | Lin2 | Lin3 | Lin4 | Lin5 | Lin6 => Kind::Skip,
        Tri3 | Tri6 | Tri9 | Tri10 | Tri12 | Tri15 | Tri15i | Tri21 => Kind::Face(3),
        Qua4 | Qua8 | Qua9 | Qua16 => Kind::Face(4),
        Tet4 | Tet10 | Tet20 => Kind::Solid(TET),
        Hex8 | Hex20 | Hex27 => Kind::Solid(HEX),
        Pri6 | Pri15 => Kind::Solid(PRISM),
        Pyr5 | Pyr13 | Pyr14 => Kind::Solid(PYRAMID),
        _ => return None,
    })
}

/// The surface in the MSH file at `path`: all its nodes, and triangles indexing them.
pub(super) fn read_msh(path: &Path) -> Result<TriangleList, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read it: {e}"))?;
    let binary = header(&bytes)?;
    for section in ["$Nodes", "$Elements"] {
        counts(&bytes, section, binary)?;
    }
    let msh: MshFile<u64, i32, f64> = mshio::parse_msh_bytes(&bytes).map_err(|e| {
        let at = e.begin_msh_errors().next().map(|(rest, _)| rest.len());
        let offset = bytes.len() - at.unwrap_or(bytes.len());
        let what: Vec<String> = (e.filtered_backtrace().iter().rev())
            .map(|(_, k)| k.context().map_or_else(|| k.to_string(), str::to_string))
            .collect();
        let line = bytes[..offset].iter().filter(|&&b| b == b'\n').count() + 1;
        format!(
            "not a readable MSH 4.1 file: {} (byte {offset}, line {line})",
            what.join(": ")
        )
    })?;
    let nodes = (msh.data.nodes.as_ref()).ok_or("the file has no $Nodes section")?;
    let mut positions = Vec::new();
    let mut index: HashMap<u64, u32> = HashMap::new();
    for block in &nodes.node_blocks {
        // Dense tags are numbered in the order the blocks list them, as Gmsh writes them.
        let mut tags = vec![0u64; block.nodes.len()];
        match &block.node_tags {
            Some(map) => map.iter().for_each(|(&tag, &k)| tags[k] = tag),
            None => {
                let first = nodes.min_node_tag + positions.len() as u64;
                (0..tags.len()).for_each(|k| tags[k] = first + k as u64);
            }
        }
        for (node, tag) in block.nodes.iter().zip(tags) {
            index.insert(tag, positions.len() as u32);
            positions.push([node.x, node.y, node.z]);
        }
    }
    let elements = (msh.data.elements.as_ref()).ok_or("the file has no $Elements section")?;
    let (mut faces, mut solids) = (Vec::new(), Vec::new());
    for block in &elements.element_blocks {
        let kind = kind(block.element_type).ok_or_else(|| {
            format!(
                "elements of type {:?} (entity {}) are not read: give triangles, \
                 quadrangles, tetrahedra, hexahedra, prisms or pyramids (linear or \
                 quadratic)",
                block.element_type, block.entity_tag
            )
        })?;
        for element in &block.elements {
            let corners = |n: usize| -> Result<Vec<u32>, String> {
                (element.nodes[..n].iter())
                    .map(|tag| {
                        index.get(tag).copied().ok_or_else(|| {
                            format!(
                                "element {}: node {tag} is not in $Nodes",
                                element.element_tag
                            )
                        })
                    })
                    .collect()
            };
            match kind {
                Kind::Skip => {}
                Kind::Face(n) => faces.push(corners(n)?),
                Kind::Solid(sides) => {
                    let n = 1 + sides.iter().flat_map(|f| f.iter()).max().expect("faces");
                    let c = corners(n)?;
                    solids.extend(outward(&positions, &c, sides));
                }
            }
        }
    }
    let faces = if solids.is_empty() {
        faces
    } else {
        boundary(solids)
    };
    if faces.is_empty() {
        return Err("the file has no triangles, quadrangles or volume elements".into());
    }
    let triangles = (faces.iter())
        .flat_map(|f| match f[..] {
            [a, b, c] => vec![[a, b, c]],
            [a, b, c, d] => vec![[a, b, c], [a, c, d]],
            _ => unreachable!("faces have 3 or 4 corners"),
        })
        .collect();
    Ok((positions, triangles))
}

/// The faces of the element with `corners`, each turned to face away from its centre (an
/// element listed inside out is turned as a whole).
fn outward(positions: &[[f64; 3]], corners: &[u32], sides: &[&[usize]]) -> Vec<Vec<u32>> {
    let at = |i: u32| glam::DVec3::from_array(positions[i as usize]);
    let centre = corners.iter().map(|&i| at(i)).sum::<glam::DVec3>() / corners.len() as f64;
    let first = sides[0];
    let (a, b, c) = (
        at(corners[first[0]]),
        at(corners[first[1]]),
        at(corners[first[2]]),
    );
    let inside_out = (b - a).cross(c - a).dot(a - centre) < 0.0;
    (sides.iter())
        .map(|side| {
            let mut face: Vec<u32> = side.iter().map(|&k| corners[k]).collect();
            if inside_out {
                face.reverse();
            }
            face
        })
        .collect()
}

/// The faces listed once (by their set of corners): the outside of a volume mesh, in the
/// order of the elements.
fn boundary(faces: Vec<Vec<u32>>) -> Vec<Vec<u32>> {
    let key = |f: &Vec<u32>| {
        let mut k = f.clone();
        k.sort_unstable();
        k
    };
    let mut seen: HashMap<Vec<u32>, usize> = HashMap::with_capacity(faces.len());
    for f in &faces {
        *seen.entry(key(f)).or_default() += 1;
    }
    faces.into_iter().filter(|f| seen[&key(f)] == 1).collect()
}

/// Checks the `$MeshFormat` line the parser relies on: version 4.1 with 8-byte sizes.
/// Returns whether the file is binary.
fn header(bytes: &[u8]) -> Result<bool, String> {
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(256)]);
    let mut lines = text.lines().map(str::trim);
    if lines.next() != Some("$MeshFormat") {
        return Err("not a Gmsh MSH file: it does not begin with $MeshFormat".into());
    }
    let fields: Vec<&str> = lines.next().unwrap_or("").split_whitespace().collect();
    match fields[..] {
        [version, _, _] if version.parse::<f64>() != Ok(4.1) => Err(format!(
            "MSH format version {version}: only 4.1 is read (Gmsh: -format msh41)"
        )),
        [_, "0", "8"] => Ok(false),
        [_, "1", "8"] => Ok(true),
        _ => Err(format!(
            "the $MeshFormat line `{}` is not `4.1 <0 or 1> 8`",
            fields.join(" ")
        )),
    }
}

/// Refuses a `section` whose header declares no entries or a largest tag below its
/// smallest (the parser's arithmetic assumes neither).
fn counts(bytes: &[u8], section: &str, binary: bool) -> Result<(), String> {
    let tag = format!("{section}\n");
    let Some(at) = bytes.windows(tag.len()).position(|w| w == tag.as_bytes()) else {
        return Ok(());
    };
    let body = &bytes[at + tag.len()..];
    let values: Vec<u64> = if binary {
        let endian_one = header_end(bytes).and_then(|k| bytes.get(k..k + 4));
        let little = endian_one == Some(&1i32.to_le_bytes()[..]);
        (body.chunks_exact(8).take(4))
            .map(|c| {
                let c: [u8; 8] = c.try_into().expect("8 bytes");
                if little {
                    u64::from_le_bytes(c)
                } else {
                    u64::from_be_bytes(c)
                }
            })
            .collect()
    } else {
        let line = body.split(|&b| b == b'\n').next().unwrap_or(&[]);
        (String::from_utf8_lossy(line).split_whitespace())
            .map_while(|w| w.parse().ok())
            .collect()
    };
    match values[..] {
        [_, n, lo, hi] if n >= 1 && hi >= lo => Ok(()),
        _ => Err(format!(
            "the {section} section's first line must give its blocks, its count (at least \
             1) and its smallest and largest tags"
        )),
    }
}

/// Where the binary endianness check (the int 1) follows the `$MeshFormat` line.
fn header_end(bytes: &[u8]) -> Option<usize> {
    let first = bytes.iter().position(|&b| b == b'\n')?;
    let second = bytes[first + 1..].iter().position(|&b| b == b'\n')?;
    Some(first + 1 + second + 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A tetrahedron as an MSH 4.1 ASCII file.
    const TET_FILE: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n\
        1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 4 1\n\
        1 1 2 3 4\n$EndElements\n";

    /// The file read: its four faces, turned outward.
    #[test]
    fn a_tetrahedron_is_its_four_faces() {
        let path = std::env::temp_dir().join(format!("fissure-tet-{}.msh", std::process::id()));
        std::fs::write(&path, TET_FILE).unwrap();
        let (v, t) = read_msh(&path).unwrap();
        std::fs::remove_file(&path).ok();
        assert_eq!(v.len(), 4);
        assert_eq!(t, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]
        /// Bytes overwritten anywhere in a valid file, or the file cut short: an error or a
        /// surface, never a panic.
        #[test]
        fn damaged_files_never_panic(
            edits in prop::collection::vec((0usize..TET_FILE.len(), any::<u8>()), 0..4),
            cut in 0usize..=TET_FILE.len(),
        ) {
            let mut bytes = TET_FILE.as_bytes().to_vec();
            for (at, b) in edits {
                bytes[at] = b;
            }
            bytes.truncate(cut);
            let path = std::env::temp_dir()
                .join(format!("fissure-fuzz-{}-{cut}.msh", std::process::id()));
            std::fs::write(&path, &bytes).unwrap();
            let _ = read_msh(&path);
            std::fs::remove_file(&path).ok();
        }
    }
}
