//! The front of a crack surface read from a file without one: its boundary edges whose
//! midpoints lie in a body, joined into one walk. The rest of the boundary (edges in the
//! air, past a free surface) is no front.

use glam::DVec3;
use std::collections::{BTreeMap, HashSet};

/// The front of the surface of `vertices` and `triangles` (checked manifold and oriented
/// one way): its boundary edges inside a body by `inside`, in order, walked against the
/// way the triangles run them (for a crack whose triangles face +z, clockwise seen from
/// +z). Empty when no boundary edge is inside; an error naming the vertices when the edges
/// inside make more than one walk or branch.
pub(super) fn found_front(
    vertices: &[DVec3],
    triangles: &[[u32; 3]],
    inside: &dyn Fn(DVec3) -> bool,
) -> Result<Vec<u32>, String> {
    let directed: HashSet<(u32, u32)> = (triangles.iter())
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .collect();
    // Each front edge, from -> to, with the boundary edge's direction reversed.
    let mut next: BTreeMap<u32, u32> = BTreeMap::new();
    let mut has_prev: HashSet<u32> = HashSet::new();
    let mut edges: Vec<(u32, u32)> = (directed.iter())
        .filter(|&&(p, q)| !directed.contains(&(q, p)))
        .map(|&(p, q)| (q, p))
        .collect();
    edges.sort_unstable();
    for (from, to) in edges {
        let mid = 0.5 * (vertices[from as usize] + vertices[to as usize]);
        if !inside(mid) {
            continue;
        }
        if next.insert(from, to).is_some() || !has_prev.insert(to) {
            return Err(format!(
                "the crack's boundary inside the bodies branches at vertex {}: give `front`",
                if has_prev.contains(&to) { to } else { from }
            ));
        }
    }
    let Some(&first) = next.keys().next() else {
        return Ok(Vec::new());
    };
    let starts: Vec<u32> = next
        .keys()
        .copied()
        .filter(|v| !has_prev.contains(v))
        .collect();
    let start = match starts[..] {
        [] => first,
        [s] => s,
        _ => {
            return Err(format!(
                "the crack's boundary inside the bodies is {} separate pieces (starting at \
                 vertices {}): a crack has one front; give `front`",
                starts.len(),
                starts
                    .iter()
                    .map(u32::to_string)
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    };
    let mut front = vec![start];
    let mut at = start;
    while let Some(&to) = next.get(&at) {
        if to == start {
            break;
        }
        front.push(to);
        at = to;
    }
    // A loop walks as many edges as vertices; a chain one fewer.
    let walked = front.len() - usize::from(!starts.is_empty());
    if walked != next.len() {
        return Err(format!(
            "the crack's boundary inside the bodies is more than one piece (the walk from \
             vertex {start} covers {walked} of its {} edges): a crack has one front; give \
             `front`",
            next.len()
        ));
    }
    Ok(front)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 x 2 grid of squares in z = 0 (vertices j * 5 + i at (i, j)), split into
    /// triangles counterclockwise seen from +z.
    fn sheet() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let v = (0..3)
            .flat_map(|j| (0..5).map(move |i| DVec3::new(i as f64, j as f64, 0.0)))
            .collect();
        let mut t = Vec::new();
        for j in 0..2 {
            for i in 0..4 {
                let a = j * 5 + i;
                t.push([a, a + 1, a + 6]);
                t.push([a, a + 6, a + 5]);
            }
        }
        (v, t)
    }

    /// A body over x > 3.5 takes the sheet's right edge, walked from +y to -y (clockwise
    /// seen from +z); a body holding the whole sheet takes its boundary as one loop; one
    /// holding both short edges finds two pieces and asks for `front`; none, no front.
    #[test]
    fn the_front_is_the_boundary_inside_the_bodies() {
        let (v, t) = sheet();
        let right = found_front(&v, &t, &|x| x.x > 3.5).unwrap();
        assert_eq!(right, vec![14, 9, 4]);
        let all = found_front(&v, &t, &|_| true).unwrap();
        assert_eq!(all.len(), 12);
        assert_eq!(all[..3], [0, 5, 10]);
        let e = found_front(&v, &t, &|x| x.x < 0.5 || x.x > 3.5).unwrap_err();
        assert!(
            e.contains("2 separate pieces") && e.contains("give `front`"),
            "{e}"
        );
        assert!(found_front(&v, &t, &|_| false).unwrap().is_empty());
    }
}
