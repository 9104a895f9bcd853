//! Crack topology as snapshot columns and back, so that a crack whose vertices, elements
//! or fronts changed during the run (a grown crack) resumes as it was. Names and contact
//! laws come from the stored scenario.

use super::format::{ColumnSet, Reader, SnapshotError};
use crate::base::dim::Dim;
use crate::base::geometry::Element;
use crate::store::crack::{Crack, Front, Topology};

/// A topology flattened into integer columns.
pub struct Encoded {
    /// Vertex count and version.
    counts: [u64; 2],
    /// Element vertices, `Element::VERTICES` per element.
    elems: Vec<u64>,
    /// Crack of each element.
    elem_crack: Vec<u16>,
    /// Per crack: its vertex count, then its vertices.
    paths: Vec<u64>,
    /// Per front: crack, end, vertex count, then its vertices.
    fronts: Vec<u64>,
}

impl Encoded {
    /// Flattens `t`.
    pub fn new<D: Dim>(t: &Topology<D>) -> Self {
        Encoded {
            counts: [t.vertex_count() as u64, t.version()],
            elems: (t.elems().iter())
                .flat_map(|e| e.vertices().iter().map(|&v| v as u64))
                .collect(),
            elem_crack: t.elem_crack().to_vec(),
            paths: t.cracks().iter().flat_map(|c| list(&c.vertices)).collect(),
            fronts: (t.fronts().iter())
                .flat_map(|f| {
                    [f.crack as u64, f.end as u64]
                        .into_iter()
                        .chain(list(&f.vertices))
                })
                .collect(),
        }
    }

    /// Adds the columns to `c`.
    pub fn add<'a>(&'a self, c: &mut ColumnSet<'a>) {
        c.add("cracks.topology.counts", &self.counts[..]);
        c.add("cracks.topology.elems", &self.elems);
        c.add("cracks.topology.elem_crack", &self.elem_crack);
        c.add("cracks.topology.paths", &self.paths);
        c.add("cracks.topology.fronts", &self.fronts);
    }
}

/// A length-prefixed list.
fn list(v: &[u32]) -> impl Iterator<Item = u64> + '_ {
    std::iter::once(v.len() as u64).chain(v.iter().map(|&k| k as u64))
}

/// Reads the stored topology of the cracks that `built` (the scene rebuilt from the stored
/// scenario) names; every index is checked.
pub fn read<D: Dim>(r: &mut Reader, built: &Topology<D>) -> Result<Topology<D>, SnapshotError> {
    let counts: Vec<u64> = r.column("cracks.topology.counts", 2)?;
    let elems: Vec<u64> = r.column_any("cracks.topology.elems")?;
    let elem_crack: Vec<u16> = r.column_any("cracks.topology.elem_crack")?;
    let paths: Vec<u64> = r.column_any("cracks.topology.paths")?;
    let fronts: Vec<u64> = r.column_any("cracks.topology.fronts")?;
    let per = <D::Elem as Element>::VERTICES;
    if !elems.len().is_multiple_of(per) {
        return Err(r.invalid("crack elements: not a whole number of elements"));
    }
    let index = |v: u64| u32::try_from(v).ok();
    let mut elem_list = Vec::with_capacity(elems.len() / per);
    for e in elems.chunks_exact(per) {
        let v: Option<Vec<u32>> = e.iter().map(|&k| index(k)).collect();
        let v = v.ok_or_else(|| r.invalid("crack elements: a vertex index out of range"))?;
        elem_list.push(D::Elem::from_vertices(&v));
    }
    let mut cursor = Cursor {
        data: &paths,
        at: 0,
    };
    let mut cracks = Vec::new();
    for c in built.cracks() {
        let vertices = cursor
            .list()
            .ok_or_else(|| r.invalid(format!("crack paths: `{}` is cut short", c.name)))?;
        cracks.push(Crack {
            name: c.name.clone(),
            contact: c.contact,
            growth: c.growth,
            split: c.split,
            vertices,
        });
    }
    if !cursor.done() {
        return Err(r.invalid("crack paths: more cracks stored than the scenario has"));
    }
    let mut cursor = Cursor {
        data: &fronts,
        at: 0,
    };
    let mut front_list = Vec::new();
    while !cursor.done() {
        let front = (|| {
            let crack = u16::try_from(cursor.next()?).ok()?;
            let end = index(cursor.next()?)?;
            let vertices = cursor.list()?;
            Some(Front {
                crack,
                end,
                vertices,
            })
        })();
        front_list.push(front.ok_or_else(|| r.invalid("crack fronts: an entry is cut short"))?);
    }
    let vertex_count =
        usize::try_from(counts[0]).map_err(|_| r.invalid("crack vertex count out of range"))?;
    Topology::from_parts(
        cracks,
        elem_list,
        elem_crack,
        front_list,
        vertex_count,
        counts[1],
    )
    .map_err(|e| r.invalid(format!("crack topology: {}", e.0)))
}

/// Reads integers and length-prefixed lists off a column.
struct Cursor<'a> {
    data: &'a [u64],
    at: usize,
}

impl Cursor<'_> {
    fn next(&mut self) -> Option<u64> {
        let v = self.data.get(self.at).copied();
        self.at += 1;
        v
    }

    fn list(&mut self) -> Option<Vec<u32>> {
        let n = usize::try_from(self.next()?).ok()?;
        let end = self.at.checked_add(n)?;
        let items = self.data.get(self.at..end)?;
        self.at = end;
        items.iter().map(|&k| u32::try_from(k).ok()).collect()
    }

    fn done(&self) -> bool {
        self.at >= self.data.len()
    }
}
