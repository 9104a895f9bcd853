//! Axis-aligned boxes and the sweep that finds the pairs of them that meet.

/// An axis-aligned box (min, max) in x, y, z (m); a 2D box has z = 0 at both ends.
pub type Bounds = ([f64; 3], [f64; 3]);

/// Whether two boxes meet (touching counts).
pub fn overlap(a: &Bounds, b: &Bounds) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

/// Calls `pair(i, j)`, i < j, for every two of `boxes` that meet, found by a sweep along x
/// (boxes sorted by their low x, each tried only against those starting before it ends),
/// so boxes that keep apart cost about their number rather than its square.
pub fn meeting_pairs(boxes: &[Bounds], mut pair: impl FnMut(usize, usize)) {
    let mut by_x: Vec<usize> = (0..boxes.len()).collect();
    by_x.sort_by(|&a, &b| boxes[a].0[0].total_cmp(&boxes[b].0[0]).then(a.cmp(&b)));
    for (k, &a) in by_x.iter().enumerate() {
        for &b in by_x[k + 1..]
            .iter()
            .take_while(|&&b| boxes[b].0[0] <= boxes[a].1[0])
        {
            if overlap(&boxes[a], &boxes[b]) {
                pair(a.min(b), a.max(b));
            }
        }
    }
}
