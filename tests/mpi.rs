//! A scene split across MPI ranks gives bitwise the outputs of one process (built with the
//! `mpi` feature; each case starts `mpirun` as a child, since MPI starts once per process).
//! Without the feature, a launch by mpirun is refused with a clear message.

#[cfg(feature = "mpi")]
mod common;

use std::path::Path;
use std::process::Command;

/// The environment that lets mpirun run as root, more ranks than cores, on this machine only.
#[cfg(feature = "mpi")]
const OMPI_ENV: [(&str, &str); 7] = [
    ("OMPI_ALLOW_RUN_AS_ROOT", "1"),
    ("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1"),
    ("OMPI_MCA_rmaps_base_oversubscribe", "1"),
    ("OMPI_MCA_btl", "self,vader"),
    ("OMPI_MCA_oob_tcp_if_include", "lo"),
    ("OMPI_MCA_pml", "ob1"),
    ("HWLOC_COMPONENTS", "-gl,-opencl"),
];

/// Runs `scene` with `args`, under `mpirun -np ranks` when `ranks` is given, into `out`;
/// it must succeed.
#[cfg(feature = "mpi")]
fn run(scene: &str, ranks: Option<usize>, out: &Path, args: &[&str]) {
    succeeded(&launch(scene, ranks, out, args));
}

/// Asserts that a launch succeeded, showing its errors if not.
#[cfg(feature = "mpi")]
fn succeeded(done: &std::process::Output) {
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
}

/// Asserts that `other` holds `serial`'s energy.csv and probes.csv byte for byte.
#[cfg(feature = "mpi")]
fn same_outputs(serial: &Path, other: &Path, what: &str) {
    same_files(serial, other, &["energy.csv", "probes.csv"], what);
}

/// Asserts that `other` holds `serial`'s `files`, each with rows, byte for byte.
#[cfg(feature = "mpi")]
fn same_files(serial: &Path, other: &Path, files: &[&str], what: &str) {
    for f in files {
        let a = std::fs::read(serial.join(f)).unwrap();
        assert!(a.len() > 100, "{f} has rows");
        assert!(
            a == std::fs::read(other.join(f)).unwrap(),
            "{what}: {f} differs"
        );
    }
}

/// Runs `scene` as [`run`] does and returns how it ended.
#[cfg(feature = "mpi")]
fn launch(scene: &str, ranks: Option<usize>, out: &Path, args: &[&str]) -> std::process::Output {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join(scene);
    let mut cmd = fissure(ranks);
    cmd.arg("run").arg(&scene).arg("--out").arg(out);
    cmd.args(args).output().expect("mpirun starts")
}

/// The launcher, under `mpirun -np ranks` when `ranks` is given.
#[cfg(feature = "mpi")]
fn fissure(ranks: Option<usize>) -> Command {
    let bin = env!("CARGO_BIN_EXE_fissure");
    let mut cmd = match ranks {
        Some(n) => {
            let mut c = Command::new("mpirun");
            // A hang (a rank waiting for one that failed) ends the job instead of CI; unbound,
            // a rank may run more threads than one core.
            c.args([
                "--timeout",
                "300",
                "--bind-to",
                "none",
                "-np",
                &n.to_string(),
                bin,
            ]);
            c
        }
        None => Command::new(bin),
    };
    cmd.envs(OMPI_ENV);
    cmd
}

/// Resumes `snapshot` into `out`, under `mpirun -np ranks` when `ranks` is given.
#[cfg(feature = "mpi")]
fn resume(snapshot: &Path, ranks: Option<usize>, out: &Path) -> std::process::Output {
    let mut cmd = fissure(ranks);
    cmd.arg("resume").arg(snapshot).arg("--out").arg(out);
    cmd.args(["--threads", "1"])
        .output()
        .expect("mpirun starts")
}

/// energy.csv and probes.csv of `scene` on 2 and 3 ranks equal the serial run's, byte for byte.
#[cfg(feature = "mpi")]
fn same_on_ranks(scene: &str, args: &[&str]) {
    let stem = Path::new(scene).file_stem().unwrap().to_string_lossy();
    let dir = std::env::temp_dir().join(format!("fissure_mpi_{}_{stem}", std::process::id()));
    let serial = dir.join("serial");
    run(scene, None, &serial, args);
    for n in [2, 3] {
        let split = dir.join(format!("ranks{n}"));
        run(
            scene,
            Some(n),
            &split,
            &[&["--threads", "1"], args].concat(),
        );
        same_outputs(&serial, &split, &format!("{scene} on {n} ranks"));
        same_frames(&serial, &split, n);
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The split run's VTK frames are `.pvtu` files joining one piece per rank, whose point
/// arrays are the pieces' own and whose pieces hold, together, the serial frame's points.
#[cfg(feature = "mpi")]
fn same_frames(serial: &Path, split: &Path, ranks: usize) {
    let frames = |dir: &Path| -> Vec<String> {
        let pvd = std::fs::read_to_string(dir.join("particles.pvd")).unwrap();
        let doc = roxmltree::Document::parse(&pvd).unwrap();
        (doc.descendants().filter(|e| e.has_tag_name("DataSet")))
            .map(|e| e.attribute("file").unwrap().to_string())
            .collect()
    };
    let (one, many) = (frames(serial), frames(split));
    assert_eq!(one.len(), many.len());
    assert!(many.iter().all(|f| f.ends_with(".pvtu")), "{many:?}");
    let last = many.last().unwrap();
    let pvtu = std::fs::read_to_string(split.join(last)).unwrap();
    let doc = roxmltree::Document::parse(&pvtu).expect("pvtu is well-formed XML");
    let pieces: Vec<&str> = (doc.descendants().filter(|e| e.has_tag_name("Piece")))
        .map(|e| e.attribute("Source").unwrap())
        .collect();
    assert_eq!(pieces.len(), ranks);
    let declared: Vec<&str> = (doc.descendants().filter(|e| e.has_tag_name("PDataArray")))
        .filter_map(|e| e.attribute("Name"))
        .collect();
    let mut points = Vec::new();
    for piece in pieces {
        let (names, mut p) = points_of(&split.join(piece));
        assert_eq!(names, declared, "the pvtu declares the piece's arrays");
        points.append(&mut p);
    }
    let (_, mut whole) = points_of(&serial.join(one.last().unwrap()));
    points.sort_unstable();
    whole.sort_unstable();
    assert!(points == whole, "the pieces hold the serial frame's points");
}

/// A `.vtu` file's array names and its points (as bit patterns).
#[cfg(feature = "mpi")]
fn points_of(path: &Path) -> (Vec<String>, Vec<[u64; 3]>) {
    let bytes = std::fs::read(path).unwrap();
    let marker = b"<AppendedData encoding=\"raw\">\n_";
    let at = (bytes.windows(marker.len()))
        .position(|w| w == marker)
        .expect("appended data");
    let header = std::str::from_utf8(&bytes[..at + marker.len() - 1]).unwrap();
    let xml = format!("{header}</AppendedData>\n</VTKFile>\n");
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let data = &bytes[at + marker.len()..];
    let arrays: Vec<_> = doc
        .descendants()
        .filter(|e| e.has_tag_name("DataArray"))
        .collect();
    let names = arrays
        .iter()
        .filter_map(|e| e.attribute("Name"))
        .map(String::from)
        .collect();
    let pts = arrays
        .iter()
        .find(|e| e.attribute("Name") == Some("Points"))
        .unwrap();
    let offset: usize = pts.attribute("offset").unwrap().parse().unwrap();
    let len = u64::from_le_bytes(data[offset..offset + 8].try_into().unwrap()) as usize;
    let values: Vec<u64> = (data[offset + 8..offset + 8 + len].chunks_exact(8))
        .map(|b| u64::from_le_bytes(b.try_into().unwrap()))
        .collect();
    let points = values.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    (names, points)
}

#[cfg(feature = "mpi")]
#[test]
fn colliding_disks_split_across_ranks_match_one_process() {
    same_on_ranks("scenarios/disks_2d.toml", &[]);
}

/// A small plastic disc flying across a large grid: most ranks start with no particle and
/// take the disc's as it passes; 4 ranks give the serial run's bits.
#[cfg(feature = "mpi")]
#[test]
fn a_disc_crossing_empty_ranks_matches_one_process() {
    let scene = r#"
name = "crossing_disc"
[simulation]
dimension = 2
duration = 0.3
cfl = 0.4
[grid]
min = [0.0, 0.0]
max = [0.2, 0.2]
cell = [0.0025, 0.0025]
[[material]]
name = "soft"
E = 1000.0
nu = 0.3
rho = 1000.0
model = "j2"
sigma_y = 50.0
[[body]]
material = "soft"
disc = { center = [0.03, 0.04], radius = 0.012 }
velocity = [0.5, 0.4]
[[probe]]
name = "vx"
region = { min = [0.018, 0.028], max = [0.042, 0.052] }
quantity = "velocity"
component = "x"
[[probe]]
name = "gap"
region = { min = [0.018, 0.028], max = [0.042, 0.052] }
quantity = "opening"
component = "x"
[[probe]]
name = "yielded"
region = { center = [0.03, 0.04], radius = 0.012 }
quantity = "plastic_radius"
[output]
interval = 0.05
"#;
    let (dir, file) = scene_file(scene, "disc");
    snapshots_resume_on_any_rank_count(&dir, &file);
    let serial = dir.join("serial");
    run(file.to_str().unwrap(), None, &serial, &[]);
    let split = dir.join("ranks4");
    run(file.to_str().unwrap(), Some(4), &split, &["--threads", "1"]);
    same_outputs(&serial, &split, "the disc on 4 ranks");
    let summary = std::fs::read_to_string(split.join("summary.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&summary).unwrap();
    // The disc started in the first rank's tiles: the tiles were divided anew as it moved.
    let rebalances = json["ranks"]["rebalances"].as_u64().unwrap();
    assert!(rebalances >= 1, "{}", json["ranks"]);

    // Flown on, the disc leaves the grid: the rank holding the particle that left stops
    // every rank with its message, and the rows written so far are the serial run's.
    let (dir, file) = scene_file(
        &scene.replace("duration = 0.3", "duration = 0.6"),
        "leaving",
    );
    let (serial, split) = (dir.join("serial"), dir.join("ranks3"));
    let one = launch(file.to_str().unwrap(), None, &serial, &[]);
    let many = launch(file.to_str().unwrap(), Some(3), &split, &["--threads", "1"]);
    assert!(!one.status.success() && !many.status.success());
    let said = String::from_utf8_lossy(&many.stderr);
    assert!(said.contains("left the grid"), "{said}");
    let a = std::fs::read(serial.join("energy.csv")).unwrap();
    assert!(a == std::fs::read(split.join("energy.csv")).unwrap());
    std::fs::remove_dir_all(&dir).ok();
}

/// The disc's run on 4 ranks (some of them empty) writes snapshot sets of a manifest and 4
/// pieces, keeping the newest 2; a set resumed on 3 ranks and on one process, and a
/// one-process snapshot resumed on 2 ranks, end as the uninterrupted serial run, bit for
/// bit; a set with a piece missing is refused, once.
#[cfg(feature = "mpi")]
fn snapshots_resume_on_any_rank_count(dir: &Path, file: &Path) {
    let every = [
        "--set",
        "checkpoint.every_steps=50",
        "--set",
        "checkpoint.keep=2",
    ];
    let serial = dir.join("serial_snapshots");
    run(file.to_str().unwrap(), None, &serial, &every);
    let split = dir.join("ranks4_snapshots");
    let args = [&["--threads", "1"], &every[..]].concat();
    run(file.to_str().unwrap(), Some(4), &split, &args);
    let snaps = split.join("snapshots");
    let mut names: Vec<String> = (std::fs::read_dir(&snaps).unwrap())
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let manifests: Vec<&String> = names.iter().filter(|n| n.ends_with(".fsnap")).collect();
    assert_eq!(manifests.len(), 2, "{names:?}");
    assert_eq!(
        names.len(),
        2 * 5,
        "a manifest and 4 pieces per set: {names:?}"
    );
    let older = snaps.join(manifests[0]);
    for (ranks, name) in [(Some(3), "resumed3"), (None, "resumed1")] {
        let out = dir.join(name);
        succeeded(&resume(&older, ranks, &out));
        same_outputs(
            &serial,
            &out,
            &format!("the 4-rank set resumed on {ranks:?}"),
        );
    }
    // A one-process snapshot (one file, no pieces) resumed on 2 ranks, each keeping its
    // share of the file's particles.
    let mut whole: Vec<std::path::PathBuf> = (std::fs::read_dir(serial.join("snapshots")))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    whole.sort();
    let out = dir.join("resumed2_from_one");
    succeeded(&resume(&whole[0], Some(2), &out));
    same_outputs(&serial, &out, "the one-process snapshot resumed on 2 ranks");
    let piece = names.iter().find(|n| n.ends_with(".fpiece")).unwrap();
    std::fs::remove_file(snaps.join(piece)).unwrap();
    let done = resume(&older, Some(2), &dir.join("incomplete"));
    let said = String::from_utf8_lossy(&done.stderr);
    assert!(!done.status.success());
    assert!(
        said.contains("is missing: the snapshot set is incomplete"),
        "{said}"
    );
    assert_eq!(said.matches("error:").count(), 1, "{said}");
}

/// Writes `scene` into a fresh folder named after `name`; returns the folder and the file.
#[cfg(feature = "mpi")]
fn scene_file(scene: &str, name: &str) -> (std::path::PathBuf, std::path::PathBuf) {
    let dir = std::env::temp_dir().join(format!("fissure_mpi_{}_{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, scene).unwrap();
    (dir, file)
}

/// The earliest snapshot set (its manifest) a run wrote into `out`.
#[cfg(feature = "mpi")]
fn first_set(out: &Path) -> std::path::PathBuf {
    let mut sets: Vec<_> = (std::fs::read_dir(out.join("snapshots")).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "fsnap"))
        .collect();
    sets.sort();
    sets.swap_remove(0)
}

/// `file` (a scene with cracks) on 2 ranks of 2 threads, and 3 and 4 ranks of one, as on
/// one process: `files` byte for byte, the frames' particles and the cracks' last frame (the advected, or grown, vertices
/// and surfaces); and a snapshot set written mid-run on 2 ranks, resumed on 3, ends with
/// the same `files`. The serial run's outputs are left in `dir/serial`.
#[cfg(feature = "mpi")]
fn cracks_alike_on_ranks(file: &Path, dir: &Path, files: &[&str], every_steps: u32) {
    let file = file.to_str().unwrap();
    let serial = dir.join("serial");
    run(file, None, &serial, &[]);
    let frames = std::fs::read_to_string(serial.join("cracks.pvd")).unwrap();
    let last = frames.lines().filter(|l| l.contains("file=")).count() - 1;
    let crack = format!("cracks_{last:05}.vtu");
    for n in [2, 3, 4] {
        let split = dir.join(format!("ranks{n}"));
        let threads = if n == 2 { "2" } else { "1" };
        run(file, Some(n), &split, &["--threads", threads]);
        same_files(&serial, &split, files, &format!("{file} on {n} ranks"));
        same_frames(&serial, &split, n);
        assert!(
            std::fs::read(serial.join(&crack)).unwrap()
                == std::fs::read(split.join(&crack)).unwrap(),
            "{file}: {crack} differs on {n} ranks"
        );
    }
    let every = format!("checkpoint.every_steps={every_steps}");
    let split = dir.join("ranks2_snapshots");
    run(file, Some(2), &split, &["--set", &every, "--threads", "1"]);
    let resumed = dir.join("resumed3");
    succeeded(&resume(&first_set(&split), Some(3), &resumed));
    same_files(
        &serial,
        &resumed,
        files,
        &format!("{file} resumed on 3 ranks"),
    );
}

/// `scenarios/perf/<name>.toml` (a crack with Coulomb faces) split across ranks as on one
/// process ([`cracks_alike_on_ranks`]): energy.csv (friction's work among it, which must be
/// positive), probes.csv, fracture.csv and paths.csv (J and K).
#[cfg(feature = "mpi")]
fn cracks_slide_alike_on_ranks(name: &str) {
    let dir = std::env::temp_dir().join(format!("fissure_mpi_{}_{name}", std::process::id()));
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenarios/perf/{name}.toml"));
    let files = ["energy.csv", "probes.csv", "fracture.csv", "paths.csv"];
    cracks_alike_on_ranks(&file, &dir, &files, 20);
    let energy = std::fs::read_to_string(dir.join("serial/energy.csv")).unwrap();
    let last = energy.lines().last().unwrap();
    let friction: f64 = last.rsplit(',').next().unwrap().parse().unwrap();
    assert!(friction > 0.0, "the faces slid under friction: {last}");
    std::fs::remove_dir_all(&dir).ok();
}

#[cfg(feature = "mpi")]
#[test]
fn a_sliding_crack_split_across_ranks_matches_one_process() {
    cracks_slide_alike_on_ranks("sliding_crack_2d");
}

#[cfg(feature = "mpi")]
#[test]
fn a_squeezed_penny_split_across_ranks_matches_one_process() {
    cracks_slide_alike_on_ranks("squeezed_penny_3d");
}

/// Kalthoff's crack (`scenarios/kalthoff_2d.toml`: started by the hoop stress reaching
/// K_Ic, turned by it, run at a set speed to the free surface, where it stops) grows alike
/// on 1 to 4 ranks: growth.csv among the files, and the grown crack's last frame.
#[cfg(feature = "mpi")]
#[test]
fn a_growing_2d_crack_split_across_ranks_matches_one_process() {
    let dir = std::env::temp_dir().join(format!("fissure_mpi_{}_kalthoff", std::process::id()));
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/kalthoff_2d.toml");
    let files = ["energy.csv", "probes.csv", "fracture.csv", "growth.csv"];
    cracks_alike_on_ranks(&file, &dir, &files, 200);
    let summary = std::fs::read_to_string(dir.join("serial/summary.json")).unwrap();
    assert!(summary.contains("reached the free surface"), "{summary}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A penny pulled open and sheared across the ranks' boundary, whose front extends by half
/// a cell at every check in the hoop stress's direction, grows alike on 1 to 4 ranks: the
/// squeezed penny of `scenarios/perf/squeezed_penny_3d.toml`, pulled instead, its faces
/// free, its front growing from 0.4 us.
#[cfg(feature = "mpi")]
#[test]
fn a_growing_3d_front_split_across_ranks_matches_one_process() {
    let perf = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/perf/squeezed_penny_3d.toml");
    let squeezed = std::fs::read_to_string(perf).unwrap();
    let (push, pull) = (
        "velocity = [3.0, -10.0, 0.0]",
        "velocity = [3.0, 10.0, 0.0]",
    );
    let faces = "contact = { law = \"friction\", friction = 0.3 }";
    let growth = "[crack.growth]\ninitiation = \"time\"\nat = 4.0e-7\ndirection = \"hoop\"\n\
                  extension = 5.0e-4\ninterval = 4.0e-7";
    assert!(squeezed.contains(push) && squeezed.contains(faces));
    let scene = squeezed.replace(push, pull).replace(faces, growth);
    let (dir, file) = scene_file(&scene, "growing_penny");
    let files = ["energy.csv", "fracture.csv", "paths.csv", "growth.csv"];
    cracks_alike_on_ranks(&file, &dir, &files, 12);
    let rows = std::fs::read_to_string(dir.join("serial/growth.csv")).unwrap();
    assert!(rows.lines().count() > 3, "the front grew: {rows}");
    std::fs::remove_dir_all(&dir).ok();
}

#[cfg(feature = "mpi")]
#[test]
fn a_3d_bar_split_across_ranks_matches_one_process() {
    same_on_ranks("scenarios/bar_wave_3d.toml", &[]);
}

/// `scene` (a scenario file) with `args`, on 2 ranks of 2 threads and 3 of one, as on one
/// process: `files` byte for byte, and the frames' particles. The outputs are left in `dir`.
#[cfg(feature = "mpi")]
fn alike_on_ranks(scene: &str, args: &[&str], dir: &Path, files: &[&str]) {
    let serial = dir.join("serial");
    run(scene, None, &serial, args);
    for n in [2, 3] {
        let split = dir.join(format!("ranks{n}"));
        let threads = if n == 2 { "2" } else { "1" };
        run(
            scene,
            Some(n),
            &split,
            &[args, &["--threads", threads]].concat(),
        );
        same_files(&serial, &split, files, &format!("{scene} on {n} ranks"));
        same_frames(&serial, &split, n);
    }
}

/// Coulomb faces that stick on one rank's pairs only: a stuck pair keeps the slip it had at
/// its load step's start, which takes a product with K, a collective; the ranks without
/// a stuck pair of their own skipped it and the others waited for ever (a pressed and
/// sheared oblique ellipse in a cube, 4 load steps, 27,000 particles). Now every rank
/// joins, and 2 and 3 ranks give one process's files byte for byte.
#[cfg(feature = "mpi")]
#[test]
fn faces_stuck_on_some_ranks_only_solve_alike() {
    let dir = std::env::temp_dir().join(format!("fissure_mpi_{}_stuck", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("pressed_ellipse.toml");
    let ellipse = "{ center = [0.014497, 0.013514, 0.012051], axes = [[-0.0060298, \
                   0.00058676, 0.002395], [-0.0012549, -0.0052853, -0.0018644]] }";
    let text = common::pressed_cube([9136.75, -90000.0, 44246.16], ellipse, 0.2, 4);
    // J and K on a tube of 2 cells, compared too.
    std::fs::write(&scene, format!("{text}[fracture]\ndomain = 2\n")).unwrap();
    let cg = ["--set", "simulation.linear=\"cg\""];
    let files = ["energy.csv", "solver.csv", "fracture.csv"];
    alike_on_ranks(scene.to_str().unwrap(), &cg, &dir.join("out"), &files);
}

/// Static scenes (`solver = "static"`, conjugate gradients) split across ranks give one
/// process's files byte for byte: a cantilever on its clamp (the reaction probe; and with
/// its load held over the last two of 4 load steps, which keep the answer), the ENF
/// specimen whose crack faces close (the active set across the ranks' boundary, K_II;
/// and with Coulomb friction, whose sliding pairs carry mu N and dissipate), a
/// straight 3D front (J and K along it; with Jacobi, and with the coarse grid of
/// `linear = "two_level"`, whose factor the second step of its ramp keeps), and a bar pulled past
/// yield by a moving grip in 40
/// load steps (Newton iterations with the return map), whose snapshot set written on 2
/// ranks resumes on 3 to the same files.
#[cfg(feature = "mpi")]
#[test]
fn static_scenes_split_across_ranks_match_one_process() {
    let dir = std::env::temp_dir().join(format!("fissure_mpi_{}_static", std::process::id()));
    let cg = ["--set", "simulation.linear=\"cg\""];
    let solved = ["energy.csv", "probes.csv", "solver.csv"];
    let cracked = ["energy.csv", "solver.csv", "fracture.csv"];
    let static_cg = [&["--set", "simulation.solver=\"static\""][..], &cg].concat();
    let two_level = [
        "--set",
        "simulation.linear=\"two_level\"",
        "--set",
        "simulation.load_steps=2",
        "--set",
        "load[0].time={kind=\"ramp\",rise=1.0}",
    ];
    let one_step = ["--set", "simulation.load_steps=1"];
    let rubbing = ["--set", "crack[0].contact={law=\"friction\",friction=0.3}"];
    let cases: [(&str, &str, Vec<&str>, &[&str]); 5] = [
        (
            "scenarios/cantilever_static_2d.toml",
            "",
            cg.to_vec(),
            &solved,
        ),
        (
            "scenarios/enf_2d.toml",
            "",
            [&static_cg[..], &one_step].concat(),
            &cracked,
        ),
        (
            "scenarios/enf_2d.toml",
            "_friction",
            [&static_cg[..], &one_step, &rubbing].concat(),
            &cracked,
        ),
        (
            "scenarios/straight_front_3d.toml",
            "",
            cg.to_vec(),
            &cracked,
        ),
        (
            "scenarios/straight_front_3d.toml",
            "_two_level",
            two_level.to_vec(),
            &cracked,
        ),
    ];
    for (scene, tag, args, files) in cases {
        let stem = Path::new(scene).file_stem().unwrap().to_string_lossy();
        alike_on_ranks(scene, &args, &dir.join(format!("{stem}{tag}")), files);
    }
    // The coarse grid took fewer iterations than Jacobi, and its second load step (the
    // same cracks and supports) kept its factor on every rank.
    let log = |tag: &str| {
        let f = dir.join(format!("straight_front_3d{tag}/ranks2/solver.csv"));
        std::fs::read_to_string(f).unwrap()
    };
    let first = |l: String| -> u32 {
        let row = l.lines().nth(1).unwrap().to_string();
        row.split(',').nth(3).unwrap().parse().unwrap()
    };
    let (jacobi, coarse) = (first(log("")), first(log("_two_level")));
    assert!(coarse < jacobi / 2, "{coarse} against {jacobi}");
    let summary = dir.join("straight_front_3d_two_level/ranks2/summary.json");
    let summary = std::fs::read_to_string(summary).unwrap();
    assert!(
        summary.contains("\"coarse_factorizations\": 1"),
        "{summary}"
    );
    // The cantilever's load ramped over half of 4 load steps: the last two keep the
    // answer, their reactions taken from the particles' stresses on every rank.
    let held = dir.join("cantilever_held");
    let ramp = [
        "--set",
        "simulation.load_steps=4",
        "--set",
        "load[0].time={kind=\"ramp\",rise=0.5}",
    ];
    alike_on_ranks(
        "scenarios/cantilever_static_2d.toml",
        &[&cg[..], &ramp].concat(),
        &held,
        &solved,
    );
    let log = std::fs::read_to_string(held.join("serial/solver.csv")).unwrap();
    let rounds = |l: &str| l.split(',').nth(6).unwrap().parse::<u32>().unwrap();
    let kept: Vec<bool> = log.lines().skip(1).map(|l| rounds(l) == 0).collect();
    assert_eq!(kept, [false, false, true, true], "{log}");
    let enf = std::fs::read_to_string(dir.join("enf_2d/serial/solver.csv")).unwrap();
    let row: Vec<&str> = enf.lines().nth(1).unwrap().split(',').collect();
    assert!(row[7].parse::<usize>().unwrap() > 0, "faces closed: {enf}");

    let scene = "scenarios/bar_plastic_2d.toml";
    let plastic = [&static_cg[..], &["--set", "simulation.load_steps=40"]].concat();
    let bar = dir.join("bar_plastic_2d");
    alike_on_ranks(scene, &plastic, &bar, &solved);
    let newton = std::fs::read_to_string(bar.join("serial/solver.csv")).unwrap();
    let iterations = |l: &str| l.split(',').nth(2).unwrap().parse::<u32>().unwrap();
    assert!(
        newton.lines().skip(1).any(|l| iterations(l) > 1),
        "the load steps past yield took Newton iterations: {newton}"
    );
    let every = [&plastic[..], &["--set", "checkpoint.every_steps=10"]].concat();
    let written = bar.join("snapshots2");
    run(
        scene,
        Some(2),
        &written,
        &[&every[..], &["--threads", "1"]].concat(),
    );
    let resumed = bar.join("resumed3");
    succeeded(&resume(&first_set(&written), Some(3), &resumed));
    same_files(&bar.join("serial"), &resumed, &solved, "resumed on 3 ranks");
    std::fs::remove_dir_all(&dir).ok();
}

/// `validate` on 3 ranks prints, once, the table one process prints (the wall times
/// aside): the colliding disks' momentum drift (relative to the momentum scale summed
/// over the ranks) and angular momentum drift (about the centre of mass of all ranks) too.
#[cfg(feature = "mpi")]
#[test]
fn validate_on_ranks_reports_what_one_process_does() {
    let dir = std::env::temp_dir().join(format!("fissure_mpi_{}_validate", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let disks = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/disks_2d.toml");
    // A spinning lower disc gives the pair angular momentum to compare.
    let text = std::fs::read_to_string(disks).unwrap().replacen(
        "velocity = [0.1, 0.1]",
        "velocity = [0.1, 0.1]\nangular_velocity = [0.05]",
        1,
    ) + "\n[[expect]]\nquantity = \"angular_momentum_drift\"\nreference = 0.0\n\
           source = \"no torque on the pair\"\ntolerance = 0.05\n";
    let file = dir.join("disks.toml");
    std::fs::write(&file, text).unwrap();
    let table = |ranks: Option<usize>| -> Vec<String> {
        let done = fissure(ranks)
            .arg("validate")
            .arg(&file)
            .args(["--threads", "1"])
            .output()
            .unwrap();
        assert!(
            done.status.success(),
            "{}",
            String::from_utf8_lossy(&done.stderr)
        );
        // Each row without its last field, the wall time, and the padding before it (its
        // width follows the time's digits).
        (String::from_utf8_lossy(&done.stdout).lines())
            .map(|l| {
                l.rsplit_once(' ')
                    .map_or(l, |(row, _)| row)
                    .trim_end()
                    .to_string()
            })
            .collect()
    };
    let (one, three) = (table(None), table(Some(3)));
    assert!(
        one.iter().any(|l| l.contains("angular_momentum_drift")),
        "{one:?}"
    );
    assert_eq!(one, three);
    std::fs::remove_dir_all(&dir).ok();
}

/// Ctrl-C (SIGINT to mpirun, which passes it to every rank) stops a split run on all its
/// ranks after one step, with a snapshot set; resumed on 3 ranks in the same folder, the
/// run ends with the files of the uninterrupted one-process run.
#[cfg(feature = "mpi")]
#[test]
fn a_split_run_stopped_by_a_signal_resumes_bit_for_bit() {
    let dir = std::env::temp_dir().join(format!("fissure_mpi_{}_signal", std::process::id()));
    let args = ["--set", "simulation.duration=4e-4"];
    let serial = dir.join("serial");
    run("scenarios/bar_mode_2d.toml", None, &serial, &args);
    let split = dir.join("ranks2");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/bar_mode_2d.toml");
    let child = fissure(Some(2))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&split)
        .args(["--threads", "1"])
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Signalled once it writes (a signal during set-up ends it at once, writing nothing).
    let t0 = std::time::Instant::now();
    while !split.join("energy.csv").exists() && t0.elapsed().as_secs() < 120 {
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    std::thread::sleep(std::time::Duration::from_millis(300));
    let signalled = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(signalled.success());
    let said = child.wait_with_output().unwrap();
    let summary = std::fs::read_to_string(split.join("summary.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&summary).unwrap();
    assert_eq!(
        json["status"],
        "interrupted",
        "{}",
        String::from_utf8_lossy(&said.stderr)
    );
    succeeded(&resume(&split, Some(3), &split));
    same_outputs(&serial, &split, "the stopped run resumed on 3 ranks");
    std::fs::remove_dir_all(&dir).ok();
}

#[cfg(not(feature = "mpi"))]
#[test]
fn a_build_without_mpi_refuses_several_ranks() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/bar_wave_2d.toml");
    let done = Command::new(env!("CARGO_BIN_EXE_fissure"))
        .env("OMPI_COMM_WORLD_SIZE", "2")
        .args(["run", scene.to_str().unwrap(), "--out"])
        .arg(std::env::temp_dir().join("fissure_no_mpi"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&done.stderr);
    assert!(!done.status.success());
    assert!(err.contains("--features mpi"), "{err}");
}

/// Each rank builds only its own tiles' particles, so a check on the whole scene combines
/// the ranks' answers: a crack whose front lies near no particle of any rank, or whose
/// tip lies near particles of one rank only, is judged as one process judges it, and a
/// refusal is one message, the one process's, not a hang.
#[test]
#[cfg(feature = "mpi")]
fn a_scene_built_rank_by_rank_is_checked_whole() {
    let dir = std::env::temp_dir().join(format!("fissure_mpi_{}_whole", std::process::id()));
    let away = ["--set", "crack[0].line.end=[0.05, 0.027]"];
    let one = launch("scenarios/dcb_2d.toml", None, &dir, &away);
    let two = launch("scenarios/dcb_2d.toml", Some(2), &dir, &away);
    let (one, two) = (
        String::from_utf8_lossy(&one.stderr),
        String::from_utf8_lossy(&two.stderr),
    );
    assert!(one.contains("is outside every body"), "{one}");
    assert_eq!(two.matches("error:").count(), 1, "{two}");
    let line = |s: &str| s.lines().find(|l| l.contains("error:")).map(str::to_owned);
    assert_eq!(line(&one), line(&two));
    // The tip near particles of one rank only (4 mm from the clamped end): accepted, and
    // its J and K those of one process (the beam cut nearly through fails the scene's
    // expects, which is not what is tested here).
    let near = [
        "--set",
        "crack[0].line.end=[0.004, 0.012]",
        "--until",
        "1e-4",
    ];
    let fracture = |ranks: Option<usize>| {
        let out = dir.join(format!("near_{}", ranks.unwrap_or(1)));
        let done = launch("scenarios/dcb_2d.toml", ranks, &out, &near);
        let said = String::from_utf8_lossy(&done.stderr);
        assert!(!said.contains("error:"), "{said}");
        std::fs::read(out.join("fracture.csv")).expect("fracture.csv written")
    };
    assert_eq!(fracture(None), fracture(Some(2)));
    std::fs::remove_dir_all(&dir).ok();
}

/// What a split run cannot do yet is refused by name, once (by the first rank): the sparse
/// direct solver, and the commands that run on one process.
#[cfg(feature = "mpi")]
#[test]
fn split_runs_refuse_what_they_cannot_do_yet() {
    let dir = std::env::temp_dir().join(format!("fissure_mpi_{}_refuse", std::process::id()));
    let done = launch(
        "scenarios/cantilever_static_2d.toml",
        Some(2),
        &dir,
        &["--set", "simulation.linear=\"direct\""],
    );
    let said = String::from_utf8_lossy(&done.stderr);
    assert!(!done.status.success());
    assert!(
        said.contains("the sparse direct solver runs on one process only"),
        "{said}"
    );
    assert_eq!(said.matches("error:").count(), 1, "{said}");

    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/dcb_2d.toml");
    let done = Command::new("mpirun")
        .args([
            "--timeout",
            "300",
            "-np",
            "2",
            env!("CARGO_BIN_EXE_fissure"),
            "check",
        ])
        .arg(scene)
        .envs(OMPI_ENV)
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&done.stderr);
    assert!(!done.status.success());
    assert!(
        said.contains("`fissure check` runs on one process"),
        "{said}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
