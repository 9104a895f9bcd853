//! Files a run appends to as it goes (energy.csv, probes.csv, VTK frames), so a run that
//! stops early keeps what it wrote. A resumed run rewrites the rows its snapshot recorded
//! and continues, so the files match an uninterrupted run's byte for byte.

use crate::base::dim::Dim;
use crate::fracture::plan::{PathResult, TipResult};
use crate::io::output::vtk;
use crate::physics::growth::GrowthRow;
use crate::record::history::{History, Row};
use crate::record::solve_log::SolveRow;
use crate::record::state::RunState;
use crate::store::world::World;
use anyhow::Context;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A buffered output file whose write errors name it (a full disk says which file).
struct Named {
    path: PathBuf,
    w: BufWriter<File>,
}

impl Named {
    fn named(&self, e: std::io::Error) -> std::io::Error {
        std::io::Error::new(
            e.kind(),
            format!("cannot write {}: {e}", self.path.display()),
        )
    }
}

impl Write for Named {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.w.write(buf).map_err(|e| self.named(e))
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.w.flush().map_err(|e| self.named(e))
    }
}

/// Which files beyond energy.csv and probes.csv a run writes.
pub struct Contents<'a> {
    /// The cracks' names when J and K are measured (fracture.csv).
    pub cracks: Option<&'a [String]>,
    /// J on compared contours (paths.csv).
    pub paths: bool,
    /// Whether the tips are 3D front vertices rather than 2D crack ends.
    pub front_vertices: bool,
    /// The cracks' names when some crack grows (growth.csv), and whether one grows under
    /// fatigue (cycles.csv).
    pub growing: Option<(&'a [String], bool)>,
    /// A static scene's load steps (solver.csv).
    pub solves: bool,
}

/// Open output files of a run.
pub struct Writers {
    /// Output folder.
    pub dir: PathBuf,
    energy: Named,
    probes: Named,
    fracture: Option<(Named, Vec<String>)>,
    paths: Option<Named>,
    growth: Option<(Named, Vec<String>)>,
    /// cycles.csv, when some crack grows under fatigue.
    cycles: Option<Named>,
    /// solver.csv, in a static scene.
    solver: Option<Named>,
    /// Whether a tip is a 3D front vertex (named by its ordinal along the crack's front)
    /// rather than a 2D crack end (named start or end).
    front_vertices: bool,
    /// After a resume into another folder: the frames written before it (their count) and
    /// the folder they are in, relative to this one, which the collection files point to.
    earlier: Option<(usize, String)>,
}

impl Writers {
    /// Creates the output folder and the CSV files `contents` asks for, holding the header
    /// and every row already recorded in `history` (none for a fresh run).
    pub fn open(
        dir: &Path,
        probe_names: &[String],
        contents: Contents,
        history: &History,
    ) -> anyhow::Result<Self> {
        let Contents {
            cracks,
            paths,
            front_vertices,
            growing,
            solves,
        } = contents;
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create output folder {}", dir.display()))?;
        let create = |name: &str| -> anyhow::Result<_> {
            let path = dir.join(name);
            let file =
                File::create(&path).with_context(|| format!("cannot create {}", path.display()))?;
            Ok(Named {
                w: BufWriter::new(file),
                path,
            })
        };
        let mut energy = create("energy.csv")?;
        writeln!(
            energy,
            "step,time,kinetic,strain,external_work,damping_work,plastic_work,friction_work"
        )?;
        let mut probes = create("probes.csv")?;
        let names: String = probe_names.iter().map(|n| format!(",{n}")).collect();
        writeln!(probes, "step,time{names}")?;
        let fracture = match cracks {
            Some(names) => {
                let mut f = create("fracture.csv")?;
                writeln!(
                    f,
                    "step,time,crack,tip,x,y,z,J1,J2,KI,KII,KIII,\
                     KI_interaction,KII_interaction,KIII_interaction,\
                     KI_opening,KII_opening,KIII_opening,domain,length,speed"
                )?;
                Some((f, names.to_vec()))
            }
            None => None,
        };
        let paths = match (paths, &fracture) {
            (true, Some(_)) => {
                let mut f = create("paths.csv")?;
                let part = if front_vertices { "volume" } else { "area" };
                writeln!(f, "step,time,crack,tip,contour,J1,J2,J1_{part},J2_{part},G")?;
                Some(f)
            }
            _ => None,
        };
        let cycles = match growing {
            Some((_, true)) => {
                let mut f = create("cycles.csv")?;
                writeln!(f, "step,time,crack,tip,grown,dKeq,cycles")?;
                Some(f)
            }
            _ => None,
        };
        let growth = match growing {
            Some((names, _)) => {
                let mut f = create("growth.csv")?;
                writeln!(
                    f,
                    "step,time,crack,tip,grown,x,y,KI,KII,kink_deg,heading_deg,dKeq,cycles"
                )?;
                Some((f, names.to_vec()))
            }
            None => None,
        };
        let solver = match solves {
            true => {
                let mut f = create("solver.csv")?;
                writeln!(
                    f,
                    "step,time,newton,iterations,factorizations,residual,contact_rounds,\
                     closed_faces,free_motions,imbalance,factor_entries,too_large"
                )?;
                Some(f)
            }
            false => None,
        };
        let mut w = Writers {
            dir: dir.to_path_buf(),
            energy,
            probes,
            fracture,
            paths,
            growth,
            cycles,
            solver,
            front_vertices,
            earlier: None,
        };
        for row in &history.rows {
            w.row(row, history)?;
        }
        w.fracture(&history.fracture, &history.paths)?;
        w.growth(&history.growth)?;
        for row in &history.solves {
            w.solve(row)?;
        }
        Ok(w)
    }

    /// Appends a load step's solve to solver.csv: its Newton iterations (0 for a linear
    /// step), conjugate-gradient iterations, factorizations, final residual over the
    /// external force, contact rounds and closed face pairs, free rigid motions and the
    /// load's share along them, the largest factor's entries, and 1 where the direct
    /// solve was too large for memory.
    pub fn solve(&mut self, row: &SolveRow) -> anyhow::Result<()> {
        let Some(f) = &mut self.solver else {
            return Ok(());
        };
        let s = &row.solved;
        writeln!(
            f,
            "{},{:.9e},{},{},{},{:.6e},{},{},{},{:.6e},{},{}",
            row.step,
            row.time,
            s.newton,
            s.iterations,
            s.factorizations,
            s.residual,
            s.contact_rounds,
            s.closed_faces,
            s.free_motions,
            s.imbalance,
            s.factor_entries,
            s.too_large as u8
        )?;
        Ok(())
    }

    /// Appends `row` to energy.csv and the probes' samples at its step to probes.csv.
    pub fn row(&mut self, row: &Row, history: &History) -> anyhow::Result<()> {
        let e = &row.energies;
        writeln!(
            self.energy,
            "{},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e}",
            row.step,
            row.time,
            e.kinetic,
            e.strain,
            e.external_work,
            e.damping_work,
            e.plastic_work,
            e.friction_work
        )?;
        // Probes are sampled once per step from step 0, so the sample index is the step.
        let k = row.step as usize;
        write!(self.probes, "{},{:.9e}", row.step, row.time)?;
        for s in &history.probes {
            write!(self.probes, ",{:.9e}", s[k])?;
        }
        writeln!(self.probes)?;
        Ok(())
    }

    /// Appends J and K at crack tips to fracture.csv, and J on the compared contours (with
    /// the area term, and the area term alone; in 3D tubes, with the volume term and it
    /// alone, J2 not measured; then G, J along the tip) to paths.csv (SI: J/m^2, Pa
    /// sqrt(m)).
    pub fn fracture(&mut self, tips: &[TipResult], paths: &[PathResult]) -> anyhow::Result<()> {
        let Some((f, names)) = &mut self.fracture else {
            return Ok(());
        };
        let tip = |t: u32| -> String {
            if self.front_vertices {
                t.to_string()
            } else {
                ["start", "end"][t as usize].into()
            }
        };
        if let Some(pf) = &mut self.paths {
            for p in paths {
                writeln!(
                    pf,
                    "{},{:.9e},{},{},{},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e}",
                    p.step,
                    p.time,
                    names[p.crack as usize],
                    tip(p.tip),
                    p.contour,
                    p.line[0] + p.area[0],
                    p.line[1] + p.area[1],
                    p.area[0],
                    p.area[1],
                    p.along_tip(true)
                )?;
            }
        }
        for t in tips {
            write!(
                f,
                "{},{:.9e},{},{}",
                t.step,
                t.time,
                names[t.crack as usize],
                tip(t.tip)
            )?;
            for v in t.values() {
                write!(f, ",{v:.9e}")?;
            }
            writeln!(f)?;
        }
        Ok(())
    }

    /// Appends the growing tips' new segments to growth.csv: the length grown and tip
    /// before the segment (m), K read there (Pa sqrt(m)), the segment's turn and direction
    /// (degrees), and under fatigue Delta K_eq (Pa sqrt(m)) and the cycles to that length.
    /// A 3D front's row (tip `front`) holds its mean advance, the mean of its vertices (x,
    /// y), and the means of K and Delta K_eq along it.
    pub fn growth(&mut self, rows: &[GrowthRow]) -> anyhow::Result<()> {
        let Some((f, names)) = &mut self.growth else {
            return Ok(());
        };
        let front = self.front_vertices;
        let tip = |t: u32| {
            if front {
                "front"
            } else {
                ["start", "end"][t as usize]
            }
        };
        for g in rows {
            writeln!(
                f,
                "{},{:.9e},{},{},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.6},{:.6},{:.9e},{:.9e}",
                g.step,
                g.time,
                names[g.crack as usize],
                tip(g.tip),
                g.grown,
                g.x[0],
                g.x[1],
                g.k[0],
                g.k[1],
                g.kink.to_degrees(),
                g.heading.to_degrees(),
                g.fatigue[0],
                g.fatigue[1]
            )?;
            if let Some(c) = self.cycles.as_mut().filter(|_| g.fatigue[1].is_finite()) {
                writeln!(
                    c,
                    "{},{:.9e},{},{},{:.9e},{:.9e},{:.9e}",
                    g.step,
                    g.time,
                    names[g.crack as usize],
                    tip(g.tip),
                    g.grown,
                    g.fatigue[0],
                    g.fatigue[1]
                )?;
            }
        }
        Ok(())
    }

    /// After a resume from the run in folder `from` into this one: its first `frames` VTK
    /// frames stay there, and the collection files point to them (nothing changes when
    /// the two folders are one, or `from` does not hold them).
    pub fn frames_in(&mut self, from: &Path, frames: usize) {
        let (Ok(from), Ok(here)) = (from.canonicalize(), self.dir.canonicalize()) else {
            return;
        };
        if from != here && (frames == 0 || from.join(frame_name(0)).exists()) {
            self.earlier = Some((frames, relative(&here, &from)));
        }
    }

    /// The name of frame `k` of kind `kind` ("particles", "cracks") in the collection file,
    /// of extension `ext` ("vtu", or "pvtu" joining the pieces of a split run).
    fn listed(&self, kind: &str, k: usize, ext: &str) -> String {
        let name = format!("{kind}_{k:05}.{ext}");
        match &self.earlier {
            Some((n, dir)) if k < *n => format!("{dir}{name}"),
            _ => name,
        }
    }

    /// Writes a VTK frame of `world` and the collection file listing every frame so far.
    /// Split across ranks, the frame is a `.pvtu` joining the ranks' pieces ([`piece`]).
    pub fn frame<D: Dim>(&mut self, world: &World<D>, state: &mut RunState) -> anyhow::Result<()> {
        let k = state.frames.len();
        let comm = &world.domain.comm;
        let ext = if comm.is_split() {
            let pieces: Vec<String> = (0..comm.size()).map(|r| piece_name(k, r)).collect();
            let plastic = !world.particles.hardened.is_empty();
            whole(&self.dir.join(format!("particles_{k:05}.pvtu")), |p| {
                vtk::write_particle_pieces(p, &pieces, plastic)
            })?;
            "pvtu"
        } else {
            whole(&self.dir.join(frame_name(k)), |p| {
                vtk::write_particles(p, &world.particles)
            })?;
            "vtu"
        };
        state.frames.push(world.time);
        let list: Vec<(f64, String)> = (state.frames.iter().enumerate())
            .map(|(k, &t)| (t, self.listed("particles", k, ext)))
            .collect();
        whole(&self.dir.join("particles.pvd"), |p| {
            vtk::write_collection(p, &list)
        })?;
        if let Some(c) = &world.cracks {
            let crack_name = |k: usize| format!("cracks_{k:05}.vtu");
            let last = state.history.fracture.last().map(|t| t.step);
            let tips: Vec<TipResult> = (state.history.fracture.iter().rev())
                .take_while(|t| Some(t.step) == last)
                .copied()
                .collect();
            whole(&self.dir.join(crack_name(state.frames.len() - 1)), |p| {
                vtk::write_cracks(p, c, &tips)
            })?;
            let list: Vec<(f64, String)> = (state.frames.iter().enumerate())
                .map(|(k, &t)| (t, self.listed("cracks", k, "vtu")))
                .collect();
            whole(&self.dir.join("cracks.pvd"), |p| {
                vtk::write_collection(p, &list)
            })?;
        }
        Ok(())
    }

    /// Flushes the CSV files (before a snapshot, and at the end).
    pub fn flush(&mut self) -> anyhow::Result<()> {
        self.energy.flush()?;
        self.probes.flush()?;
        if let Some((f, _)) = &mut self.fracture {
            f.flush()?;
        }
        if let Some(f) = &mut self.paths {
            f.flush()?;
        }
        if let Some((f, _)) = &mut self.growth {
            f.flush()?;
        }
        if let Some(f) = &mut self.cycles {
            f.flush()?;
        }
        if let Some(f) = &mut self.solver {
            f.flush()?;
        }
        Ok(())
    }
}

/// Writes the file at `path` with `write`; on failure removes what was written of it (a
/// truncated frame would mislead a reader) and names it in the error.
fn whole(path: &Path, write: impl FnOnce(&Path) -> std::io::Result<()>) -> anyhow::Result<()> {
    write(path).map_err(|e| {
        std::fs::remove_file(path).ok();
        anyhow::anyhow!("cannot write {}: {e}", path.display())
    })
}

fn frame_name(k: usize) -> String {
    format!("particles_{k:05}.vtu")
}

/// Rank `rank`'s piece of particle frame `k` in a split run.
fn piece_name(k: usize, rank: usize) -> String {
    format!("particles_{k:05}_{rank}.vtu")
}

/// Writes this rank's particles as its piece of frame `k` into `dir` (a split run; every
/// rank writes one, the first also the `.pvtu` joining them).
pub fn piece<D: Dim>(dir: &Path, k: usize, world: &World<D>) -> anyhow::Result<()> {
    let name = piece_name(k, world.domain.comm.rank());
    whole(&dir.join(name), |p| {
        vtk::write_particles(p, &world.particles)
    })
}

/// The path from folder `from` to folder `to` (both absolute), ending in a separator:
/// up to their common ancestor, then down.
fn relative(from: &Path, to: &Path) -> String {
    let (a, b): (Vec<_>, Vec<_>) = (from.components().collect(), to.components().collect());
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..a.len() {
        out.push("..");
    }
    for c in &b[common..] {
        out.push(c);
    }
    format!("{}/", out.display())
}
