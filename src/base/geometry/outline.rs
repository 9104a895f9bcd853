//! A 2D region bounded by closed outlines (any number of loops, holes among them): the
//! boundary edges of a flat triangle mesh. Inside by the even-odd rule along +x, each query
//! trying only the edges of its horizontal band.

/// The boundary of a 2D region as undirected edges, binned by horizontal bands.
#[derive(Clone, Debug)]
pub struct Outline {
    /// Edges (m): their two ends in x-y.
    edges: Vec<[[f64; 2]; 2]>,
    /// Lower corner of the edges' box (m).
    lo: [f64; 2],
    /// Upper corner of the edges' box (m).
    hi: [f64; 2],
    /// Band height (m).
    band: f64,
    /// Per band, the edges whose y-range meets it (start of band k at `start[k]`).
    start: Vec<u32>,
    /// The edges of each band, band by band.
    members: Vec<u32>,
}

impl Outline {
    /// The region bounded by `edges`, at least three of them, every coordinate finite.
    pub fn new(edges: Vec<[[f64; 2]; 2]>) -> Self {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for e in &edges {
            for p in e {
                for a in 0..2 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
        }
        let bands = edges.len().max(1);
        let band = ((hi[1] - lo[1]) / bands as f64).max(f64::MIN_POSITIVE);
        let index = |y: f64| (((y - lo[1]) / band) as usize).min(bands - 1);
        let span = |e: &[[f64; 2]; 2]| {
            let (y0, y1) = (e[0][1].min(e[1][1]), e[0][1].max(e[1][1]));
            index(y0)..=index(y1)
        };
        let mut start = vec![0u32; bands + 1];
        for e in &edges {
            span(e).for_each(|k| start[k + 1] += 1);
        }
        for k in 0..bands {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut members = vec![0u32; start[bands] as usize];
        for (i, e) in edges.iter().enumerate() {
            for k in span(e) {
                members[fill[k] as usize] = i as u32;
                fill[k] += 1;
            }
        }
        Outline {
            edges,
            lo,
            hi,
            band,
            start,
            members,
        }
    }

    /// Whether `p` lies inside: an odd number of edges cross the ray from it along +x (an
    /// edge counts for y in [min, max) of its ends, so a vertex on the ray counts once).
    pub fn contains(&self, p: [f64; 2]) -> bool {
        if (0..2).any(|a| !(p[a] >= self.lo[a] && p[a] <= self.hi[a])) {
            return false;
        }
        let bands = self.start.len() - 1;
        let k = (((p[1] - self.lo[1]) / self.band) as usize).min(bands - 1);
        let mut inside = false;
        for &i in &self.members[self.start[k] as usize..self.start[k + 1] as usize] {
            let [a, b] = self.edges[i as usize];
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if p[0] < x {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// The edges' box (lower, upper), m.
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        (self.lo, self.hi)
    }
}

#[cfg(test)]
mod tests {
    use super::Outline;

    /// A unit square with a square hole: inside between the loops, outside in the hole and
    /// beyond, whatever the edges' directions.
    #[test]
    fn a_square_with_a_hole_holds_the_ring_only() {
        let square = |lo: f64, hi: f64| {
            let c = [[lo, lo], [hi, lo], [hi, hi], [lo, hi]];
            (0..4).map(move |k| [c[k], c[(k + 1) % 4]])
        };
        let edges: Vec<_> = square(0.0, 1.0).chain(square(0.4, 0.6)).collect();
        let o = Outline::new(edges);
        assert!(o.contains([0.2, 0.5]));
        assert!(o.contains([0.5, 0.8]));
        assert!(!o.contains([0.5, 0.5]));
        assert!(!o.contains([1.2, 0.5]));
        assert!(!o.contains([0.5, -0.1]));
        // On the ray through a vertex of both loops.
        assert!(o.contains([0.1, 0.4]));
        assert!(!o.contains([0.45, 0.4 + 1e-12]));
    }
}
