//! Crack topology: which vertices make up each crack, its elements and its fronts. It
//! changes only when a crack grows; a version number tells the systems that keep
//! something built from it (element neighbours, the classification record) to rebuild.

use super::law::Contact;
use super::split::Split;
use crate::base::dim::Dim;
use crate::base::geometry::Element;
use crate::physics::growth::Growth;
use std::collections::{HashMap, HashSet};

/// One crack of the store.
#[derive(Clone, Debug, PartialEq)]
pub struct Crack {
    /// Name from the scenario.
    pub name: String,
    /// How the crack faces interact where they touch.
    pub contact: Contact,
    /// How its tips grow (None: they do not).
    pub growth: Option<Growth>,
    /// Which particle-node pairs it splits between its sides' fields.
    pub split: Split,
    /// Its vertices; in 2D the polyline in order from start to end.
    pub vertices: Vec<u32>,
}

/// A crack front: where the crack may grow and where J and K are measured. In 2D one tip
/// vertex at an end of the polyline; in 3D an ordered polyline of front vertices.
#[derive(Clone, Debug, PartialEq)]
pub struct Front {
    /// The crack it belongs to.
    pub crack: u16,
    /// In 2D the polyline end it sits at (0 start, 1 end), the tip's name in outputs.
    pub end: u32,
    /// Front vertices in order. A vertex keeps its index for the life of the run, so a
    /// front keeps its vertices when others are inserted.
    pub vertices: Vec<u32>,
}

/// Vertex lists, elements and fronts of every crack, with a version that changes whenever
/// any of them does.
#[derive(Clone, Debug)]
pub struct Topology<D: Dim> {
    elems: Vec<D::Elem>,
    elem_crack: Vec<u16>,
    cracks: Vec<Crack>,
    fronts: Vec<Front>,
    vertex_count: usize,
    version: u64,
}

impl<D: Dim> Default for Topology<D> {
    fn default() -> Self {
        Topology {
            elems: Vec::new(),
            elem_crack: Vec::new(),
            cracks: Vec::new(),
            fronts: Vec::new(),
            vertex_count: 0,
            version: 0,
        }
    }
}

/// Why stored topology cannot be used (a corrupt or foreign snapshot).
#[derive(Debug, Clone, PartialEq)]
pub struct TopologyError(pub String);

impl<D: Dim> Topology<D> {
    /// Elements as vertex indices.
    pub fn elems(&self) -> &[D::Elem] {
        &self.elems
    }

    /// Crack of each element.
    pub fn elem_crack(&self) -> &[u16] {
        &self.elem_crack
    }

    /// The cracks.
    pub fn cracks(&self) -> &[Crack] {
        &self.cracks
    }

    /// The fronts of every crack.
    pub fn fronts(&self) -> &[Front] {
        &self.fronts
    }

    /// Number of vertices the elements and fronts index into.
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Changes whenever elements, vertices or fronts do.
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Whether `front` is a loop: its two ends lie on one element of its crack (in 3D, a
    /// triangle edge joins them).
    pub fn is_closed(&self, front: &Front) -> bool {
        let fv = &front.vertices;
        let (first, last) = (fv[0], fv[fv.len() - 1]);
        fv.len() > 2
            && (self.elems.iter().zip(&self.elem_crack)).any(|(e, &k)| {
                k == front.crack && e.vertices().contains(&first) && e.vertices().contains(&last)
            })
    }

    /// Adds a crack of `vertices` new vertices (numbered after the existing ones), with
    /// `elems` and `fronts` given in the crack's own numbering (0 = its first vertex).
    /// Returns the index of its first vertex.
    pub fn add_crack(
        &mut self,
        name: String,
        contact: Contact,
        growth: Option<Growth>,
        vertices: usize,
        elems: &[D::Elem],
        fronts: &[(u32, Vec<u32>)],
    ) -> u32 {
        let first = self.vertex_count as u32;
        let c = self.cracks.len() as u16;
        let shift = |e: &D::Elem| {
            let v: Vec<u32> = e.vertices().iter().map(|&k| k + first).collect();
            D::Elem::from_vertices(&v)
        };
        self.elems.extend(elems.iter().map(shift));
        self.elem_crack.extend(std::iter::repeat_n(c, elems.len()));
        self.fronts.extend(fronts.iter().map(|(end, v)| Front {
            crack: c,
            end: *end,
            vertices: v.iter().map(|&k| k + first).collect(),
        }));
        self.cracks.push(Crack {
            name,
            contact,
            growth,
            split: Split::Crossing,
            vertices: (first..first + vertices as u32).collect(),
        });
        self.vertex_count += vertices;
        self.version += 1;
        first
    }

    /// Sets crack `c`'s rule for splitting particle-node pairs (added as `Crossing`).
    pub fn set_split(&mut self, c: usize, split: Split) {
        if self.cracks[c].split != split {
            self.cracks[c].split = split;
            self.version += 1;
        }
    }

    /// Inserts vertex `new` (the next free index) into crack `c`'s 2D polyline just behind
    /// its tip vertex `tip` at end `end`: the tip's segment now ends at `new`, and a new
    /// segment joins `new` to the tip, both keeping the polyline's direction. The tip keeps
    /// its index, and so does every other vertex.
    pub fn insert_behind_tip(&mut self, c: usize, end: u32, tip: u32) -> u32
    where
        D: Dim<Elem = crate::base::geometry::Segment>,
    {
        let new = self.vertex_count as u32;
        let e = self
            .elems
            .iter()
            .zip(&self.elem_crack)
            .position(|(el, &k)| k as usize == c && el.contains(&tip))
            .expect("a tip vertex ends one segment of its crack");
        let path = &mut self.cracks[c].vertices;
        if end == 1 {
            self.elems[e][1] = new;
            self.elems.push([new, tip]);
            path.insert(path.len() - 1, new);
        } else {
            self.elems[e][0] = new;
            self.elems.push([tip, new]);
            path.insert(1, new);
        }
        self.elem_crack.push(c as u16);
        self.vertex_count += 1;
        self.version += 1;
        new
    }

    /// Inserts a strip of triangles behind front `front` of a 3D crack, for a front whose
    /// vertices flagged in `moves` are about to advance: each of them leaves a new vertex
    /// (the next free indices, in front order) in its place, which takes it over in the
    /// crack's triangles, and each front edge gains the triangles that join the vertices
    /// behind it to the front, oriented as the triangle the edge was on. A front vertex
    /// keeps its index and its place in the front. Returns the vertex behind each front
    /// vertex (itself where it does not move), or the first front edge that lies on no
    /// triangle of the crack (so the strip's orientation is unknown).
    pub fn insert_behind_front(
        &mut self,
        front: usize,
        moves: &[bool],
        closed: bool,
    ) -> Result<Vec<u32>, TopologyError>
    where
        D: Dim<Elem = crate::base::geometry::Triangle>,
    {
        let c = self.fronts[front].crack;
        let fv = self.fronts[front].vertices.clone();
        // The crack's triangle edges, each in the direction its triangle runs it: how each
        // front edge is oriented, found before anything changes.
        let runs: HashSet<(u32, u32)> = (self.elems.iter().zip(&self.elem_crack))
            .filter(|(_, k)| **k == c)
            .flat_map(|(e, _)| (0..3).map(move |k| (e[k], e[(k + 1) % 3])))
            .collect();
        let edges = if closed { fv.len() } else { fv.len() - 1 };
        let forward = (0..edges)
            .map(|i| {
                let (a, b) = (fv[i], fv[(i + 1) % fv.len()]);
                match (runs.contains(&(a, b)), runs.contains(&(b, a))) {
                    (true, _) => Ok(true),
                    (_, true) => Ok(false),
                    _ => Err(TopologyError(format!(
                        "front edge {i} of crack `{}` lies on none of its triangles",
                        self.cracks[c as usize].name
                    ))),
                }
            })
            .collect::<Result<Vec<bool>, _>>()?;
        let mut next = self.vertex_count as u32;
        let behind: Vec<u32> = (fv.iter().zip(moves))
            .map(|(&v, &m)| {
                if !m {
                    return v;
                }
                next += 1;
                next - 1
            })
            .collect();
        let taken: HashMap<u32, u32> = (fv.iter().zip(&behind))
            .filter(|(v, b)| v != b)
            .map(|(&v, &b)| (v, b))
            .collect();
        for (e, _) in (self.elems.iter_mut().zip(&self.elem_crack)).filter(|(_, k)| **k == c) {
            for v in e.iter_mut() {
                if let Some(&b) = taken.get(v) {
                    *v = b;
                }
            }
        }
        let mut strip = Vec::with_capacity(2 * edges);
        for (i, &forward) in forward.iter().enumerate() {
            let j = (i + 1) % fv.len();
            let (p, q) = (behind[i], behind[j]);
            // The quadrilateral behind the edge, run against the edge's own triangle,
            // fanned from its first corner (a corner that did not move closes it to one;
            // an edge neither of whose ends moved has none).
            let quad = if forward {
                [q, p, fv[i], fv[j]]
            } else {
                [p, q, fv[j], fv[i]]
            };
            for t in [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]] {
                if t[0] != t[1] && t[1] != t[2] && t[2] != t[0] {
                    strip.push(t);
                }
            }
        }
        self.elem_crack.extend(std::iter::repeat_n(c, strip.len()));
        self.elems.extend(strip);
        let first = self.vertex_count as u32;
        self.cracks[c as usize].vertices.extend(first..next);
        self.vertex_count = next as usize;
        self.version += 1;
        Ok(behind)
    }

    /// Topology read back from stored parts, checked: every index in range, every front
    /// vertex on its crack.
    pub fn from_parts(
        cracks: Vec<Crack>,
        elems: Vec<D::Elem>,
        elem_crack: Vec<u16>,
        fronts: Vec<Front>,
        vertex_count: usize,
        version: u64,
    ) -> Result<Self, TopologyError> {
        let err = |m: String| Err(TopologyError(m));
        if elems.len() != elem_crack.len() {
            return err(format!(
                "{} elements but {} element cracks",
                elems.len(),
                elem_crack.len()
            ));
        }
        if let Some(e) = elems
            .iter()
            .position(|e| e.vertices().iter().any(|&v| v as usize >= vertex_count))
        {
            return err(format!("element {e} names a vertex past {vertex_count}"));
        }
        if let Some(e) = elem_crack.iter().position(|&c| c as usize >= cracks.len()) {
            return err(format!("element {e} names a crack past {}", cracks.len()));
        }
        for (k, c) in cracks.iter().enumerate() {
            if c.vertices.iter().any(|&v| v as usize >= vertex_count) {
                return err(format!("crack {k} names a vertex past {vertex_count}"));
            }
        }
        for (k, f) in fronts.iter().enumerate() {
            let Some(c) = cracks.get(f.crack as usize) else {
                return err(format!("front {k} names a crack past {}", cracks.len()));
            };
            if f.vertices.is_empty() || f.vertices.iter().any(|v| !c.vertices.contains(v)) {
                return err(format!("front {k} has a vertex off its crack `{}`", c.name));
            }
        }
        Ok(Topology {
            elems,
            elem_crack,
            cracks,
            fronts,
            vertex_count,
            version,
        })
    }
}
