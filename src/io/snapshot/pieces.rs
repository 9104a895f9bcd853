//! A split run's snapshot: every rank writes its particles, with their whole-scene ids,
//! into a piece file, then the first rank writes the manifest (`step_N.fsnap`: everything
//! else, and the table of pieces with their checksums). The manifest is renamed into place
//! last, so a set is whole once its manifest exists; a piece's name carries its checksum,
//! so a new set never overwrites a piece an older manifest names.

use super::columns;
use super::format::{ColumnSet, Reader, SnapshotError};
use crate::base::dim::Dim;
use crate::io::scenario::Source;
use crate::ranks::partition::{Partition, TileGrid};
use crate::store::grid::GridGeom;
use crate::store::particles::Particles;
use crate::store::tiles::Tiles;
use crate::store::world::{Solver, World};
use bitvec::vec::BitVec;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// File extension of a piece.
pub const EXTENSION: &str = "fpiece";
/// Manifest column: per piece, its particle count and its header checksum.
const TABLE: &str = "ranks.pieces";
/// Manifest column: the pieces' file names, one per line, in rank order.
const NAMES: &str = "ranks.piece_names";

/// One rank's piece of a snapshot, as the manifest lists it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Piece {
    /// File name, in the manifest's folder.
    pub name: String,
    /// Particles in the piece.
    pub particles: u64,
    /// The piece's header checksum (which covers every column's checksum).
    pub checksum: u64,
    /// Bytes of its columns.
    pub bytes: u64,
}

/// Writes this rank's piece of the snapshot `stem` (`step_000000000100`) into `dir`.
pub fn write<D: Dim>(
    dir: &Path,
    stem: &str,
    rank: usize,
    src: &Source,
    world: &World<D>,
) -> std::io::Result<Piece> {
    let p = &world.particles;
    let mut c = ColumnSet::default();
    columns::add_particles(&mut c, p);
    c.add("particles.id", &p.id);
    let sealed = c.seal(columns::header(src, world, p.len() as u64))?;
    let piece = Piece {
        name: format!("{stem}.r{rank:05}.{:016x}.{EXTENSION}", sealed.checksum),
        particles: p.len() as u64,
        checksum: sealed.checksum,
        bytes: sealed.bytes(),
    };
    sealed.write(&dir.join(&piece.name))?;
    Ok(piece)
}

/// Whether `name` is a piece's file name.
pub fn is_piece(name: &str) -> bool {
    name.strip_suffix(EXTENSION)
        .is_some_and(|s| s.ends_with('.'))
}

/// The manifest's table of pieces, as columns.
pub(super) struct Table {
    names: String,
    data: Vec<u64>,
}

impl Table {
    pub(super) fn new(pieces: &[Piece]) -> Self {
        let names: Vec<&str> = pieces.iter().map(|p| p.name.as_str()).collect();
        Table {
            names: names.join("\n"),
            data: pieces
                .iter()
                .flat_map(|p| [p.particles, p.checksum])
                .collect(),
        }
    }

    /// Particles over all pieces.
    pub(super) fn particles(&self) -> u64 {
        self.data.iter().step_by(2).sum()
    }

    pub(super) fn add<'a>(&'a self, c: &mut ColumnSet<'a>) {
        c.add(NAMES, self.names.as_bytes());
        c.add(TABLE, &self.data);
    }
}

/// Whether the snapshot `r` is a split run's manifest.
pub(super) fn listed(r: &Reader) -> bool {
    r.offset_of(TABLE).is_some()
}

/// The pieces a manifest names, with their particle counts and checksums (none for a
/// whole snapshot). A name that is not a plain piece file name is refused, so a damaged
/// manifest cannot lead the reader out of its folder.
pub fn listing(r: &mut Reader) -> Result<Vec<Piece>, SnapshotError> {
    if !listed(r) {
        return Ok(Vec::new());
    }
    let bytes: Vec<u8> = r.column_any(NAMES)?;
    let text = String::from_utf8(bytes)
        .map_err(|_| r.invalid(format!("column `{NAMES}` is not UTF-8 text")))?;
    let names: Vec<&str> = text.split('\n').collect();
    let data: Vec<u64> = r.column(TABLE, names.len() * 2)?;
    let mut pieces = Vec::with_capacity(names.len());
    for (name, d) in names.iter().zip(data.chunks_exact(2)) {
        let plain = Path::new(name).file_name() == Some(name.as_ref());
        if !(plain && is_piece(name)) {
            return Err(r.invalid(format!(
                "`{}` in the table of pieces is not a piece's file name (corrupt)",
                name.escape_debug()
            )));
        }
        pieces.push(Piece {
            name: name.to_string(),
            particles: d[0],
            checksum: d[1],
            bytes: 0,
        });
    }
    Ok(pieces)
}

/// Puts the stored particles (a whole snapshot's, or those of the pieces its manifest
/// names: every particle from exactly one) into `w` in whole-scene order. Split across
/// ranks, each rank keeps its share: those in the tiles a partition of the stored places
/// gives it (a static scene's initial places, where its solves use them), the partition
/// replacing the one the scene was built with; every rank reads every piece's ids and
/// places twice, one piece at a time (to count the tiles, then to pick its own), and
/// keeps only its own particles' columns: the same share as the whole store split.
pub(super) fn read<D: Dim>(r: &mut Reader, w: &mut World<D>) -> Result<(), SnapshotError> {
    // Which optional columns the scene keeps (split, a rank's share of the built scene may
    // hold no particle to say), then the built particles make way for the stored ones.
    let b = &w.particles;
    let kept = |col_empty: bool| w.domain.any(!col_empty);
    let kept = columns::Kept {
        half: kept(b.half.is_empty()),
        gradients: kept(b.grad_u.is_empty()),
        plastic: kept(b.hardened.is_empty()),
    };
    w.particles = Particles::default();
    let n = r.header.particles as usize;
    let rows = Rows::of(r)?;
    let mut seen = bitvec::bitvec![0; n];
    let split = w.domain.comm.is_split();
    let (partition, total) = if split {
        let (part, own) = divide(r, w, &rows, &mut seen)?;
        (Some(part), own)
    } else {
        (None, n)
    };
    let (place, me) = (place_column(w), w.domain.comm.rank());
    let tile = tile_of(&w.grid.geom, &w.tiles);
    let mut p = Particles::<D>::default();
    seen.fill(false);
    // One process reading one file takes its rows as they stand, in id order.
    let in_order = partition.is_none() && !listed(r);
    rows.each(r, &mut seen, |mut f, ids| {
        let Some(part) = &partition else {
            columns::append_rows(&mut f, &mut p, (None, ids.len(), total), kept)?;
            if !in_order {
                p.id.extend_from_slice(&ids);
            }
            return Ok(());
        };
        let x: Vec<D::Vec> = f.column(place, ids.len())?;
        let mut mine = Vec::new();
        for (k, (&id, &x)) in ids.iter().zip(&x).enumerate() {
            if part.owns_tile(tile(&f, id, x)?, me) {
                mine.push(k);
            }
        }
        columns::append_rows(&mut f, &mut p, (Some(&mine), ids.len(), total), kept)?;
        p.id.extend(mine.iter().map(|&k| ids[k]));
        Ok(())
    })?;
    // The tiles' borrow ends here: `w` is written below.
    drop(tile);
    Rows::all_seen(r, &seen)?;
    // Rows from several pieces interleave in id; a whole snapshot's are in order.
    if !p.id.is_sorted() {
        let mut order: Vec<u32> = (0..p.len() as u32).collect();
        order.sort_unstable_by_key(|&k| p.id[k as usize]);
        p.permute(&order);
    }
    if !split {
        p.id = Vec::new();
    }
    w.particles = p;
    if partition.is_some() {
        w.domain.partition = partition;
    }
    w.tiles.tile_of.clear();
    w.tiles.fresh = false;
    Ok(())
}

/// The column of the places a run bins its particles by: where they are, or, in a static
/// scene, where they started.
fn place_column<D: Dim>(w: &World<D>) -> &'static str {
    if w.settings.solver == Solver::Static {
        "particles.x0"
    } else {
        "particles.x"
    }
}

/// The tile holding the place `x` of particle `id` read from `f`, refused when outside the
/// grid.
fn tile_of<'a, D: Dim>(
    geom: &'a GridGeom<D>,
    tiles: &'a Tiles,
) -> impl Fn(&Reader, u64, D::Vec) -> Result<u32, SnapshotError> + 'a {
    move |f: &Reader, id: u64, x: D::Vec| {
        (tiles.tile_at(geom, x))
            .ok_or_else(|| f.invalid(format!("particle {id} lies outside the grid (corrupt)")))
    }
}

/// The partition of the tiles by the stored particles' places, for the ranks `w` runs on,
/// and the particles it gives this rank: every piece's ids and places read one piece at a
/// time, each tile's particles counted.
fn divide<D: Dim>(
    r: &Reader,
    w: &World<D>,
    rows: &Rows,
    seen: &mut BitVec,
) -> Result<(Partition, usize), SnapshotError> {
    let (place, tile) = (place_column(w), tile_of(&w.grid.geom, &w.tiles));
    let mut counts = vec![0u32; w.tiles.len()];
    rows.each(r, seen, |mut f, ids| {
        let x: Vec<D::Vec> = f.column(place, ids.len())?;
        for (&id, &x) in ids.iter().zip(&x) {
            counts[tile(&f, id, x)? as usize] += 1;
        }
        Ok(())
    })?;
    Rows::all_seen(r, seen)?;
    let grid = TileGrid {
        counts: w.tiles.counts,
        size: w.tiles.size,
        cells: w.grid.geom.cells,
        dims: D::D,
    };
    let comm = &w.domain.comm;
    let me = comm.rank();
    let part =
        Partition::new(grid, &counts, comm.size(), me).map_err(|e| r.invalid(e.to_string()))?;
    let own = (counts.iter().enumerate())
        .filter(|&(t, _)| part.owns_tile(t as u32, me))
        .map(|(_, &c)| c as usize)
        .sum();
    Ok((part, own))
}

/// Where a snapshot's particle rows are: its own columns (a whole snapshot, ids 0..n) or
/// the pieces its manifest names.
struct Rows {
    pieces: Option<Vec<Piece>>,
}

impl Rows {
    fn of(r: &mut Reader) -> Result<Self, SnapshotError> {
        Ok(Rows {
            pieces: listed(r).then(|| listing(r)).transpose()?,
        })
    }

    /// Hands `visit` each file holding rows, opened, one at a time, with its rows'
    /// whole-scene ids, marked in `seen` (refused when outside the scene or already seen).
    fn each(
        &self,
        r: &Reader,
        seen: &mut BitVec,
        mut visit: impl FnMut(Reader, Vec<u64>) -> Result<(), SnapshotError>,
    ) -> Result<(), SnapshotError> {
        let n = seen.len();
        let Some(pieces) = &self.pieces else {
            seen.fill(true);
            return visit(Reader::open(r.path())?, (0..n as u64).collect());
        };
        let dir = r.path().parent().unwrap_or(Path::new(".")).to_path_buf();
        for (rank, piece) in pieces.iter().enumerate() {
            let path = dir.join(&piece.name);
            if !path.exists() {
                return Err(r.invalid(format!(
                    "piece {} (rank {rank}) is missing: the snapshot set is incomplete",
                    piece.name
                )));
            }
            let mut f = Reader::open(&path)?;
            if f.checksum != piece.checksum || f.header.particles != piece.particles {
                return Err(f.invalid(format!(
                    "not the piece the manifest {} names (checksum {:016x}, expected \
                     {:016x}): from another run or damaged",
                    r.path().display(),
                    f.checksum,
                    piece.checksum
                )));
            }
            let ids: Vec<u64> = f.column("particles.id", piece.particles as usize)?;
            for &id in &ids {
                if id as usize >= n || seen.replace(id as usize, true) {
                    return Err(f.invalid(format!(
                        "particle id {id} is outside the scene's {n} particles or in two pieces"
                    )));
                }
            }
            visit(f, ids)?;
        }
        Ok(())
    }

    /// Refuses a set in which no piece holds some particle.
    fn all_seen(r: &Reader, seen: &BitVec) -> Result<(), SnapshotError> {
        match seen.first_zero() {
            Some(missing) => Err(r.invalid(format!(
                "no piece holds particle {missing}: the snapshot set is incomplete"
            ))),
            None => Ok(()),
        }
    }
}

/// Checks every piece the manifest `r` names: present, the one named (checksum, count),
/// every column intact. Per piece, None when sound, else what is wrong.
pub fn verify(r: &mut Reader) -> Result<Vec<(Piece, Option<String>)>, SnapshotError> {
    let dir = r.path().parent().unwrap_or(Path::new(".")).to_path_buf();
    let mut out = Vec::new();
    for piece in listing(r)? {
        let problem = match Reader::open(&dir.join(&piece.name)) {
            Err(e) => Some(e.to_string()),
            Ok(f) if f.checksum != piece.checksum || f.header.particles != piece.particles => {
                Some("not the piece the manifest names (from another run or damaged)".into())
            }
            Ok(mut f) => {
                let bad = f.verify()?.iter().filter(|(_, ok)| !ok).count();
                (bad > 0).then(|| format!("{bad} column(s) fail their checksum"))
            }
        };
        out.push((piece, problem));
    }
    Ok(out)
}
