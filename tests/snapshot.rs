//! Snapshots: a run stopped at step k and resumed matches the uninterrupted run bit for bit;
//! damaged or foreign files are refused with a message naming the problem; hostile or
//! mutated files never panic the reader.

mod common;
use common::{mixed_scene, source};
use fissure::app::run::stop::{Request, StopFlag, StopRequests};
use fissure::app::run::{Outcome, RunOptions, resume, run};
use fissure::base::dim::{D2, D3};
use fissure::io::output::summary::Status;
use fissure::io::snapshot::Reader;
use fissure::io::snapshot::format::{FORMAT_VERSION, Header, MAGIC};
use fissure::io::snapshot::state::restore;
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A fresh, empty folder under the system temp folder.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fissure-snap-{}-{name}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The mixed scene with two probes (a velocity and the clamp's reaction), a history row
/// every step, VTK frames and checkpoints.
fn scene(dim: usize, shape: &str, update: &str) -> String {
    let v = |a: f64, b: f64| common::v(dim, a, b);
    format!(
        r#"{}
[[probe]]
name = "box_vx"
region = {{ min = {}, max = {} }}
quantity = "velocity"
component = "x"
[[probe]]
name = "clamp"
region = {{ min = {}, max = {} }}
quantity = "reaction"
component = "x"
[output]
history_interval = 1e-8
interval = 2e-6
[checkpoint]
every_steps = 7
keep = 3
"#,
        mixed_scene(dim, shape, update),
        v(0.002, 0.002),
        v(0.04, 0.012),
        v(0.0, 0.0),
        v(0.003, if dim == 2 { 0.032 } else { 0.016 }),
    )
}

fn opts(out: &Path, threads: usize) -> RunOptions {
    RunOptions {
        out: Some(out.to_path_buf()),
        threads,
        ..RunOptions::default()
    }
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Name of the highest-numbered VTK frame in `dir`.
fn newest_frame(dir: &Path) -> String {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".vtu"))
        .max()
        .expect("the run wrote frames")
}

/// Runs `text` through, and again stopped after `k` steps then resumed with `threads`
/// threads into a new folder; every output file and the final snapshot must match.
fn restart_is_bit_exact(text: &str, k: u64, threads: usize, name: &str) {
    let dir = scratch(name);
    let src = source(text);
    let full = run(&src, &opts(&dir.join("full"), threads)).unwrap();
    let part = run(
        &src,
        &RunOptions {
            pause_after: Some(k),
            ..opts(&dir.join("part"), 1)
        },
    )
    .unwrap();
    assert_eq!(part.summary.status, Status::Interrupted);
    assert_eq!(part.summary.steps, k);
    let snap = part.snapshot.expect("a stopped run writes a snapshot");
    let resumed: Outcome = resume(&snap, &opts(&dir.join("resumed"), threads)).unwrap();
    assert_eq!(resumed.summary.status, Status::Completed);
    let steps = full.summary.steps;
    assert_eq!(resumed.summary.steps, steps);
    assert!(k < steps && steps > 20, "the stop falls inside the run");

    let last_frame = newest_frame(&dir.join("full"));
    let final_snap = format!("snapshots/step_{steps:012}.fsnap");
    let measured = ["fracture.csv", "paths.csv", "growth.csv", "cycles.csv"]
        .into_iter()
        .filter(|f| dir.join("full").join(f).exists());
    for f in ["energy.csv", "probes.csv", &last_frame, &final_snap]
        .into_iter()
        .chain(measured)
    {
        assert!(
            read(&dir.join("full").join(f)) == read(&dir.join("resumed").join(f)),
            "{name}: {f} differs between the uninterrupted and the resumed run"
        );
    }
    // The resumed collection lists the same frames at the same times, those from before
    // the stop in the stopped run's folder.
    let pvd = |run: &str| std::fs::read_to_string(dir.join(run).join("particles.pvd")).unwrap();
    assert_eq!(
        pvd("full"),
        pvd("resumed").replace("../part/", ""),
        "{name}: particles.pvd"
    );
    assert_eq!(full.history.rows.len(), resumed.history.rows.len());
    let values = |o: &Outcome| -> Vec<u64> {
        let e = &o.summary.energies;
        vec![
            e.kinetic.to_bits(),
            e.strain.to_bits(),
            e.external_work.to_bits(),
        ]
    };
    assert_eq!(values(&full), values(&resumed));
    std::fs::remove_dir_all(dir).ok();
}

/// A run whose crack grows under fatigue resumes bit for bit: the tip's state (cycles,
/// last rate) and the new vertices travel in the snapshot.
#[test]
fn restart_is_bit_exact_with_a_growing_crack() {
    let text = common::edge_plate(common::PARIS_GROWTH, 2.2e-5)
        + "interval = 5.0e-6\n[checkpoint]\nevery_steps = 100\n";
    restart_is_bit_exact(&text, 330, 2, "growing");
}

/// A crack growing under fatigue in a static scene (a check every fourth load step)
/// resumes bit for bit: stopped after 13 of its 28 load steps, between two extensions, by
/// the direct solver and under `linear = "two_level"` (the run kept its coarse factor
/// across the extensions, the resumed run makes it afresh from the grown crack), the latter
/// on B-splines too (the blocks of the entries past the plate's edges made afresh).
#[test]
fn restart_is_bit_exact_with_quasi_static_growth() {
    for (linear, shape) in [
        ("direct", "ugimp"),
        ("two_level", "ugimp"),
        ("two_level", "bspline"),
    ] {
        let text = common::edge_plate(common::PARIS_GROWTH, 2.8e-5).replace(
            "[simulation]",
            &format!(
                "[simulation]\nsolver = \"static\"\nload_steps = 28\nlinear = \"{linear}\"\nshape = \"{shape}\""
            ),
        ) + "interval = 4.0e-6\n[checkpoint]\nevery_steps = 4\n";
        restart_is_bit_exact(&text, 13, 2, &format!("static_growing_{linear}_{shape}"));
    }
}

/// A 3D front growing under fatigue resumes bit for bit: the front's state, the vertices
/// and triangles it added and the strip's surfaces travel in the snapshot.
#[test]
fn restart_is_bit_exact_with_a_growing_front() {
    let text = common::penny_block(common::PENNY_FATIGUE, 7.2e3, 6.3e-6)
        + "interval = 2.0e-6\n[checkpoint]\nevery_steps = 100\n";
    restart_is_bit_exact(&text, 55, 2, "growing-front");
}

#[test]
fn restart_is_bit_exact_2d_one_and_two_threads() {
    let text = scene(2, "ugimp", "usavg");
    restart_is_bit_exact(&text, 33, 1, "2d-1");
    restart_is_bit_exact(&text, 33, 2, "2d-2");
}

/// A plastic scene resumes bit for bit: the plastic strain and hardening columns are in the
/// snapshot (energy.csv's plastic work and the final snapshot are compared).
#[test]
fn restart_is_bit_exact_with_plastic_state() {
    let text = common::plastic(&scene(2, "ugimp", "usavg"), 2e7, "n = 5")
        .replace("dimension = 2", "dimension = 2\nplane = \"stress\"");
    restart_is_bit_exact(&text, 33, 2, "plastic");
}

#[test]
fn restart_is_bit_exact_with_a_crack() {
    let crack = "[[crack]]\nline = { start = [0.02, 0.0005], end = [0.02, 0.0135], spacing = 5e-4 }\ntips = []\n";
    let text = scene(2, "ugimp", "usavg").replacen("[[probe]]", &format!("{crack}[[probe]]"), 1);
    restart_is_bit_exact(&text, 29, 2, "crack");
}

/// With a crack whose faces slide under friction: the friction work resumes too.
#[test]
fn restart_is_bit_exact_with_friction() {
    let crack = "[[crack]]\nline = { start = [0.0025, 0.0075], end = [0.0395, 0.0075], \
                 spacing = 5e-4 }\ntips = []\ncontact = { law = \"friction\", friction = 0.3 }\n";
    let text = scene(2, "ugimp", "usavg").replacen("[[probe]]", &format!("{crack}[[probe]]"), 1);
    let h = run(&source(&text), &RunOptions::default()).unwrap().history;
    let took = h.rows.last().unwrap().energies.friction_work;
    assert!(took > 0.0, "the faces slide under friction");
    restart_is_bit_exact(&text, 29, 2, "friction");
}

#[test]
fn restart_is_bit_exact_with_j_on_two_contours() {
    let crack = "[[crack]]\nline = { start = [0.02, 0.0005], end = [0.02, 0.0071], spacing = 5e-4 }\n\
                 tips = [\"end\"]\n[fracture]\ncontour = 2\ncompare = [3]\n";
    let text = scene(2, "ugimp", "usavg").replacen("[[probe]]", &format!("{crack}[[probe]]"), 1);
    let dir = scratch("paths-exist");
    let out = run(&source(&text), &opts(&dir, 1)).unwrap();
    assert!(!out.history.paths.is_empty() && dir.join("paths.csv").exists());
    std::fs::remove_dir_all(dir).ok();
    restart_is_bit_exact(&text, 29, 2, "paths");
}

#[test]
fn restart_is_bit_exact_3d_one_and_two_threads() {
    let text = scene(3, "bspline", "usl").replace("duration = 1e-5", "duration = 4e-6");
    restart_is_bit_exact(&text, 19, 1, "3d-1");
    restart_is_bit_exact(&text, 19, 2, "3d-2");
}

/// With J and K along the crack's front and J on a compared tube: fracture.csv, one row
/// per front vertex, and paths.csv, one per vertex and tube, resume bit for bit too. On
/// the main tube, where it was not shrunk, J in paths.csv (its two parts summed) is J1 of
/// fracture.csv, to the rounding of that sum.
#[test]
fn restart_is_bit_exact_with_a_3d_crack() {
    let crack = "[[crack]]\npenny = { center = [0.02, 0.007, 0.007], normal = [1.0, 0.3, 0.2], \
                 radius = 0.003 }\ncontact = { law = \"stick\" }\n[fracture]\ndomain = 2\n\
                 compare = [3]\n";
    let text = scene(3, "ugimp", "usavg")
        .replace("duration = 1e-5", "duration = 4e-6")
        .replacen("[[probe]]", &format!("{crack}[[probe]]"), 1);
    let dir = scratch("3d-paths");
    let h = run(&source(&text), &opts(&dir, 1)).unwrap().history;
    assert_eq!(
        h.paths.len(),
        2 * h.fracture.len(),
        "two tubes per front vertex"
    );
    let mut compared = 0;
    for t in h
        .fracture
        .iter()
        .filter(|t| t.domain == 2e-3 && t.j[0] != 0.0)
    {
        let p = (h.paths.iter())
            .find(|p| p.step == t.step && p.tip == t.tip && p.contour == 2)
            .unwrap();
        let j = p.line[0] + p.area[0];
        let scale = p.line[0].abs() + p.area[0].abs();
        assert!((j - t.j[0]).abs() <= 1e-12 * scale, "{j} vs {}", t.j[0]);
        assert!(
            p.line[1].is_nan() && p.area[1].is_nan(),
            "J2 is not measured"
        );
        compared += 1;
    }
    assert!(compared > 10, "{compared} rows compared");
    std::fs::remove_dir_all(dir).ok();
    restart_is_bit_exact(&text, 17, 2, "3d-crack");
}

/// Resumed into another folder, a run's collection files list the frames written before
/// the stop in the first folder, by a relative path, and every file they list exists; the
/// resumed folder holds only its own frames.
#[test]
fn collections_after_a_resume_elsewhere_point_to_existing_frames() {
    let dir = scratch("elsewhere");
    let crack = "[[crack]]\nline = { start = [0.02, 0.0005], end = [0.02, 0.0135], spacing = 5e-4 }\ntips = []\n";
    let text = scene(2, "ugimp", "usavg").replacen("[[probe]]", &format!("{crack}[[probe]]"), 1);
    let src = source(&text);
    let part = run(
        &src,
        &RunOptions {
            pause_after: Some(29),
            ..opts(&dir.join("a"), 1)
        },
    )
    .unwrap();
    let snap = part.snapshot.expect("a stopped run writes a snapshot");
    resume(&snap, &opts(&dir.join("b").join("c"), 1)).unwrap();
    for pvd in ["particles.pvd", "cracks.pvd"] {
        let text = std::fs::read_to_string(dir.join("b/c").join(pvd)).unwrap();
        let files: Vec<&str> = text
            .split("file=\"")
            .skip(1)
            .map(|s| s.split('"').next().unwrap())
            .collect();
        assert!(files.len() > 2, "{pvd}: {text}");
        assert!(files[0].starts_with("../../a/"), "{pvd}: {}", files[0]);
        for f in &files {
            assert!(
                dir.join("b/c").join(f).exists(),
                "{pvd} lists {f}, which is not there"
            );
        }
        let own = files.iter().filter(|f| !f.contains('/')).count();
        assert!(own > 0 && own < files.len(), "{pvd}: frames of both runs");
    }
    std::fs::remove_dir_all(dir).ok();
}

/// Periodic snapshots land on multiples of `every_steps`, the last step gets one, and only
/// the newest `keep` remain.
#[test]
fn checkpoint_cadence_and_keep() {
    let dir = scratch("keep");
    let text = scene(2, "linear", "usf");
    let out = run(&source(&text), &opts(&dir, 1)).unwrap();
    let steps = out.summary.steps;
    let mut names: Vec<String> = std::fs::read_dir(dir.join("snapshots"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let k = steps / 7 * 7;
    let want: Vec<String> = [k - 7, k, steps]
        .iter()
        .map(|s| format!("step_{s:012}.fsnap"))
        .collect();
    assert_eq!(names, want, "{steps} steps");
    std::fs::remove_dir_all(dir).ok();
}

/// A write cut short by a kill leaves a `.fsnap.tmp` file; the next resume in that folder,
/// and the next fresh run, remove it.
#[test]
fn partial_snapshot_files_are_removed() {
    let dir = scratch("partial");
    let text = scene(2, "linear", "usf").replace("duration = 1e-5", "duration = 2e-6");
    let first = run(&source(&text), &opts(&dir, 1)).unwrap();
    let partial = dir.join("snapshots").join("step_000000099999.fsnap.tmp");
    std::fs::write(&partial, b"cut short").unwrap();
    let later = RunOptions {
        until: Some(3e-6),
        ..opts(&dir, 1)
    };
    resume(&first.snapshot.unwrap(), &later).unwrap();
    assert!(!partial.exists(), "resume removed the partial file");
    std::fs::write(&partial, b"cut short").unwrap();
    run(&source(&text), &opts(&dir, 1)).unwrap();
    assert!(!partial.exists(), "a fresh run removed the partial file");
    std::fs::remove_dir_all(dir).ok();
}

/// A valid 2D snapshot (written once per test binary).
fn sample() -> &'static (PathBuf, Vec<u8>) {
    static SAMPLE: OnceLock<(PathBuf, Vec<u8>)> = OnceLock::new();
    SAMPLE.get_or_init(|| {
        let dir = scratch("sample");
        let text = scene(2, "ugimp", "usavg").replace("duration = 1e-5", "duration = 1e-6");
        let out = run(&source(&text), &opts(&dir, 1)).unwrap();
        let path = out.snapshot.unwrap();
        let bytes = read(&path);
        (path, bytes)
    })
}

/// Writes `bytes` as a snapshot file named `name` and returns the error opening and
/// restoring it gives (as text).
fn refusal(name: &str, bytes: &[u8]) -> String {
    let dir = scratch(name);
    let path = dir.join("bad.fsnap");
    std::fs::write(&path, bytes).unwrap();
    let err = match Reader::open(&path) {
        Err(e) => e.to_string(),
        Ok(mut r) => match restore::<D2>(&mut r) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("{name}: the damaged snapshot was accepted"),
        },
    };
    assert!(err.contains("bad.fsnap"), "{name}: names the file: {err}");
    std::fs::remove_dir_all(dir).ok();
    err
}

#[test]
fn refuses_a_truncated_file() {
    let bytes = &sample().1;
    let err = refusal("truncated", &bytes[..bytes.len() - 1000]);
    assert!(err.contains("truncated"), "{err}");
}

#[test]
fn refuses_a_flipped_byte_naming_the_column() {
    let (path, bytes) = sample();
    let at = Reader::open(path)
        .unwrap()
        .offset_of("particles.v")
        .unwrap() as usize
        + 13;
    let mut bad = bytes.clone();
    bad[at] ^= 0x10;
    let err = refusal("flipped", &bad);
    assert!(
        err.contains("`particles.v`") && err.contains("checksum"),
        "{err}"
    );
}

#[test]
fn refuses_a_damaged_header() {
    let mut bad = sample().1.clone();
    bad[30] ^= 0x01;
    let err = refusal("header", &bad);
    assert!(err.contains("corrupt"), "{err}");
}

#[test]
fn refuses_wrong_magic() {
    let mut bad = sample().1.clone();
    bad[0] = b'X';
    let err = refusal("magic", &bad);
    assert!(err.contains("wrong magic"), "{err}");
}

#[test]
fn refuses_a_newer_format_version() {
    let mut bad = sample().1.clone();
    bad[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    let err = refusal("version", &bad);
    assert!(err.contains("newer"), "{err}");
}

#[test]
fn refuses_a_3d_snapshot_resumed_as_2d() {
    let dir = scratch("dims");
    let text = scene(3, "ugimp", "usf").replace("duration = 1e-5", "duration = 3e-7");
    let out = run(&source(&text), &opts(&dir, 1)).unwrap();
    let mut r = Reader::open(&out.snapshot.unwrap()).unwrap();
    let err = restore::<D2>(&mut r).err().unwrap().to_string();
    assert!(err.contains("3D run") && err.contains("as 2D"), "{err}");
    assert!(restore::<D3>(&mut r).is_ok());
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn refuses_a_missing_file() {
    let err = resume(Path::new("no/such/snapshot.fsnap"), &RunOptions::default())
        .err()
        .unwrap();
    // The launcher prints the whole chain; the cause must appear in it once.
    let err = format!("{err:#}");
    assert!(
        err.contains("no/such/snapshot.fsnap") && err.contains("cannot read"),
        "{err}"
    );
    assert_eq!(err.matches("os error").count(), 1, "{err}");
}

/// A header whose checksum is right but whose counts are absurd is refused before any
/// allocation of that size.
#[test]
fn hostile_header_counts_are_capped_by_the_file_size() {
    let mut header: Header = Reader::open(&sample().0).unwrap().header;
    header.columns[2].len = 1 << 60;
    let head = postcard::to_stdvec(&header).unwrap();
    let mut bytes = MAGIC.to_vec();
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&(head.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&head);
    let sum = xxhash_rust::xxh3::xxh3_64(&bytes);
    bytes.resize(bytes.len().div_ceil(8) * 8 + header.data_len as usize, 0);
    bytes.extend_from_slice(&sum.to_le_bytes());
    let err = refusal("hostile", &bytes);
    assert!(err.contains("outside the file"), "{err}");
}

/// Reads a possibly damaged snapshot all the way; any outcome but a panic is fine.
fn read_all(bytes: &[u8], path: &Path) {
    std::fs::write(path, bytes).unwrap();
    if let Ok(mut r) = Reader::open(path) {
        let _ = r.verify();
        let _ = restore::<D2>(&mut r);
    }
}

proptest! {
    // 256 cases each by default; PROPTEST_CASES=100000 for a longer fuzzing session.
    /// Random byte flips, a truncation and an insertion anywhere in the file.
    #[test]
    fn mutated_snapshots_never_panic(
        flips in prop::collection::vec((any::<prop::sample::Index>(), 1u8..=255), 0..6),
        cut in prop::option::of(any::<prop::sample::Index>()),
        insert in prop::option::of((any::<prop::sample::Index>(), prop::collection::vec(any::<u8>(), 1..16))),
    ) {
        let mut bytes = sample().1.clone();
        for (i, x) in &flips {
            let at = i.index(bytes.len());
            bytes[at] ^= x;
        }
        if let Some(c) = cut {
            bytes.truncate(c.index(bytes.len()));
        }
        if let Some((i, ins)) = insert {
            let at = i.index(bytes.len() + 1);
            bytes.splice(at..at, ins);
        }
        read_all(&bytes, &fuzz_path());
    }

    /// Random edits of the header with its checksum recomputed, so the decoder and the
    /// column-table checks see garbage that passes the checksum.
    #[test]
    fn mutated_headers_with_valid_checksums_never_panic(
        flips in prop::collection::vec((any::<prop::sample::Index>(), 1u8..=255), 1..6),
    ) {
        let mut bytes = sample().1.clone();
        let head_len = u64::from_le_bytes(bytes[12..20].try_into().unwrap()) as usize;
        for (i, x) in &flips {
            let at = 12 + i.index(head_len + 8);
            bytes[at] ^= x;
        }
        let end = (20 + head_len).min(bytes.len() - 8);
        let sum = xxhash_rust::xxh3::xxh3_64(&bytes[..end]);
        let n = bytes.len();
        bytes[n - 8..].copy_from_slice(&sum.to_le_bytes());
        read_all(&bytes, &fuzz_path());
    }
}

/// A scratch file for one fuzz case.
fn fuzz_path() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fissure-snap-{}-fuzz", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(format!("{:?}.fsnap", std::thread::current().id()))
}

/// A run that goes unstable keeps its last good (finite) snapshot and names it.
#[test]
fn unstable_run_names_its_last_good_snapshot() {
    let text = common::block_2d(
        1e-3,
        0.006,
        0.014,
        "[[load]]\nregion = { min = [0.006, 0.006], max = [0.008, 0.014] }\nforce = [-1e7, 0.0]\n\
         [output]\nhistory_interval = 1e-6\nvtk = false\nplot = false\n\
         [checkpoint]\nevery_steps = 2\n",
    );
    let dir = scratch("unstable");
    let err = run(&source(&text), &opts(&dir, 1))
        .expect_err("must go unstable")
        .to_string();
    let named = err
        .split("last good snapshot ")
        .nth(1)
        .and_then(|s| s.split(" (step").next())
        .unwrap_or_else(|| panic!("no snapshot named: {err}"));
    let mut r = Reader::open(Path::new(named)).unwrap();
    let restored = restore::<D2>(&mut r).unwrap();
    let unstable_at: u64 = err
        .split("unstable at step ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("{err}"));
    let w = &restored.scene.world;
    assert!(w.step > 0 && w.step < unstable_at, "{err}");
    let inside = |x: &glam::DVec2| x.is_finite() && x.min_element() > 0.0 && x.max_element() < 0.02;
    assert!(w.particles.x.iter().all(inside), "{err}");
    std::fs::remove_dir_all(dir).ok();
}

/// `until` extends a finished run from its final snapshot, and refuses an end time that
/// is not after the snapshot's time.
#[test]
fn resume_until_extends_a_finished_run() {
    let dir = scratch("until");
    let text = scene(2, "linear", "usf").replace("duration = 1e-5", "duration = 2e-6");
    let first = run(&source(&text), &opts(&dir, 1)).unwrap();
    let snap = first.snapshot.unwrap();
    let early = RunOptions {
        until: Some(1e-6),
        ..opts(&dir, 1)
    };
    let err = resume(&snap, &early).err().unwrap();
    assert!(
        err.downcast_ref::<fissure::base::error::UsageError>()
            .is_some(),
        "bad input (exit code 2): {err}"
    );
    assert!(err.to_string().contains("after the current time"), "{err}");
    let later = RunOptions {
        until: Some(3e-6),
        ..opts(&dir, 1)
    };
    let more = resume(&snap, &later).unwrap();
    let dt = more.summary.dt;
    assert_eq!(more.summary.status, Status::Completed);
    assert_eq!(more.summary.steps, fissure::app::run::step_count(3e-6, dt));
    assert!(more.summary.steps > first.summary.steps);
    assert_eq!(
        more.summary.steps_run,
        more.summary.steps - first.summary.steps,
        "the resumed invocation counts its own steps"
    );
    std::fs::remove_dir_all(dir).ok();
}

/// `fissure inspect` verifies every column: exit 0 on a good file; on a damaged column it
/// names it and exits 2; `fissure resume` of a missing file exits 2.
#[test]
fn inspect_reports_checksums_and_exit_codes() {
    let (path, bytes) = sample();
    let fissure = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_fissure"))
            .args(args)
            .output()
            .unwrap()
    };
    let good = fissure(&["inspect", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&good.stdout);
    assert_eq!(good.status.code(), Some(0), "{text}");
    assert!(
        text.contains("column checksums ok") && text.contains("2D"),
        "{text}"
    );

    let dir = scratch("inspect");
    let bad_path = dir.join("bad.fsnap");
    let at = Reader::open(path)
        .unwrap()
        .offset_of("particles.stress")
        .unwrap() as usize;
    let mut bad = bytes.clone();
    bad[at + 3] ^= 0x04;
    std::fs::write(&bad_path, &bad).unwrap();
    let out = fissure(&["inspect", bad_path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(2), "{text}");
    let line = text
        .lines()
        .find(|l| l.starts_with("particles.stress"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(line.ends_with("MISMATCH"), "{text}");
    let missing = fissure(&["resume", dir.join("none.fsnap").to_str().unwrap()]);
    assert_eq!(missing.status.code(), Some(2));
    std::fs::remove_dir_all(dir).ok();
}

/// A stop asked for during set-up (the flag already set when the run starts) ends the run
/// before its first step: summary.json says "interrupted" and why, and no snapshot is
/// written, for there is nothing to resume.
#[test]
fn a_stop_during_set_up_ends_the_run_before_its_first_step() {
    let dir = scratch("early");
    let stop = StopFlag::default();
    stop.ask();
    let out = run(
        &source(&scene(2, "linear", "usf")),
        &RunOptions {
            stop: Some(stop),
            ..opts(&dir, 1)
        },
    )
    .unwrap();
    assert_eq!(out.summary.status, Status::Interrupted);
    assert_eq!(out.summary.steps, 0);
    assert!(out.snapshot.is_none());
    let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    assert!(summary.contains("during set-up"), "{summary}");
    assert!(
        !dir.join("snapshots").exists()
            || std::fs::read_dir(dir.join("snapshots"))
                .unwrap()
                .next()
                .is_none()
    );
    std::fs::remove_dir_all(dir).ok();
}

/// A full disk (here a frame that lands on /dev/full) ends the run as failed: the error and
/// summary.json name the file, the step and the last snapshot, and the partial frame is
/// removed while the frames before it stay.
#[cfg(target_os = "linux")]
#[test]
fn a_full_disk_names_the_file_and_keeps_a_summary() {
    if !Path::new("/dev/full").exists() {
        eprintln!("no /dev/full on this machine: the full-disk case is not tried");
        return;
    }
    let dir = scratch("full");
    std::os::unix::fs::symlink("/dev/full", dir.join("particles_00002.vtu")).unwrap();
    let err = run(&source(&scene(2, "linear", "usf")), &opts(&dir, 1))
        .expect_err("a full disk must stop the run")
        .to_string();
    assert!(
        err.contains("particles_00002.vtu") && err.contains("No space left"),
        "{err}"
    );
    assert!(err.contains("output failed at step") && err.contains("the last snapshot is"));
    let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    assert!(
        summary.contains("\"failed\"") && summary.contains("particles_00002.vtu"),
        "{summary}"
    );
    assert!(!dir.join("particles_00002.vtu").exists());
    assert!(dir.join("particles_00001.vtu").exists());
    std::fs::remove_dir_all(dir).ok();
}

/// A snapshot write that meets a full disk (its temporary file lands on /dev/full) fails,
/// and leaves neither the partial temporary file nor a snapshot behind.
#[cfg(target_os = "linux")]
#[test]
fn a_full_disk_during_a_snapshot_leaves_no_partial_file() {
    if !Path::new("/dev/full").exists() {
        eprintln!("no /dev/full on this machine: the full-disk case is not tried");
        return;
    }
    let dir = scratch("full-snap");
    let (path, tmp) = (dir.join("s.fsnap"), dir.join("s.fsnap.tmp"));
    std::os::unix::fs::symlink("/dev/full", &tmp).unwrap();
    let data = vec![1.0f64; 1 << 18];
    let mut columns = fissure::io::snapshot::format::ColumnSet::default();
    columns.add("x", &data);
    let header = Header {
        dimension: 2,
        particles: 0,
        nodes: 0,
        step: 0,
        time: 0.0,
        dt: 1.0,
        scenario: "full".into(),
        scenario_hash: 0,
        build: "test".into(),
        data_len: 0,
        columns: Vec::new(),
    };
    let err = columns
        .write(&path, header)
        .expect_err("a full disk must fail");
    assert_eq!(err.raw_os_error(), Some(28), "{err}");
    assert!(
        std::fs::symlink_metadata(&tmp).is_err(),
        "the partial file is gone"
    );
    assert!(!path.exists());
    std::fs::remove_dir_all(dir).ok();
}

/// A request before the run writes means "exit now" and records nothing; once it writes,
/// the first request only sets the run's flag and the second writes the abort summary and
/// tells the caller to exit.
#[test]
fn stop_requests_follow_the_run() {
    let dir = scratch("requests");
    let requests = StopRequests::new(&dir);
    let flag = requests.flag();
    assert_eq!(requests.request(), Request::SetUp);
    assert!(!flag.is_asked());
    flag.set_writing(true);
    assert_eq!(requests.request(), Request::Stop);
    assert!(flag.is_asked());
    assert!(!dir.join("summary.json").exists());
    assert_eq!(requests.request(), Request::Abort);
    let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    assert!(
        summary.contains("\"interrupted\"")
            && (summary.contains("second signal") || summary.contains("stopped on request")),
        "{summary}"
    );
    std::fs::remove_dir_all(dir).ok();
}

/// `fissure run FILE --out OUT` as a child process, its stdout discarded and its stderr
/// sent to `stderr`.
#[cfg(unix)]
fn spawn_run(file: &Path, out: &Path, stderr: std::process::Stdio) -> std::process::Child {
    std::process::Command::new(env!("CARGO_BIN_EXE_fissure"))
        .args([
            "run",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::null())
        .stderr(stderr)
        .spawn()
        .unwrap()
}

/// A signal while a large scene is being built (8 million particles, a few seconds of
/// set-up) ends the process at once with exit code 130, before anything is written.
#[cfg(unix)]
#[test]
fn a_signal_during_set_up_exits_before_writing() {
    let dir = scratch("setup-signal");
    let file = dir.join("big.toml");
    std::fs::write(
        &file,
        r#"name = "big"
[simulation]
dimension = 2
duration = 1.0
[grid]
min = [-0.0014, -0.0014]
max = [1.4014, 1.4014]
cell = [0.0007, 0.0007]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 7800.0
[[body]]
material = "steel"
box = { min = [0.0, 0.0], max = [1.4, 1.4] }
"#,
    )
    .unwrap();
    let out_dir = dir.join("out");
    let child = spawn_run(&file, &out_dir, std::process::Stdio::piped());
    std::thread::sleep(std::time::Duration::from_millis(300));
    std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(err.contains("during set-up"), "{err}");
    assert!(!out_dir.join("energy.csv").exists());
    assert!(!out_dir.join("summary.json").exists());
    std::fs::remove_dir_all(dir).ok();
}

/// Two signals in a row end the process with exit code 130 and an "interrupted"
/// summary.json. Which of the two wrote it depends on timing (the kernel may merge two
/// pending signals, or the clean stop may finish first), so either message is accepted.
#[cfg(unix)]
#[test]
fn two_signals_end_the_run_with_an_interrupted_summary() {
    let dir = scratch("twice");
    let file = dir.join("long.toml");
    std::fs::write(
        &file,
        scene(3, "ugimp", "usavg").replace("duration = 1e-5", "duration = 1.0"),
    )
    .unwrap();
    let out_dir = dir.join("out");
    let mut child = spawn_run(&file, &out_dir, std::process::Stdio::null());
    // Wait until the run is stepping (its first frame is written).
    let started = std::time::Instant::now();
    while !out_dir.join("particles_00001.vtu").exists() {
        assert!(started.elapsed().as_secs() < 60, "the run never got going");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let pid = child.id().to_string();
    for _ in 0..2 {
        std::process::Command::new("kill")
            .args(["-INT", &pid])
            .status()
            .unwrap();
    }
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if started.elapsed().as_secs() > 120 {
            child.kill().ok();
            panic!("the run did not stop on two signals");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    assert_eq!(status.code(), Some(130));
    let summary = std::fs::read_to_string(out_dir.join("summary.json")).unwrap();
    assert!(
        summary.contains("\"interrupted\"")
            && (summary.contains("second signal") || summary.contains("stopped on request")),
        "{summary}"
    );
    std::fs::remove_dir_all(dir).ok();
}

/// A snapshot copied out of its run's snapshots/ folder resumes into out/<its scenario
/// name>; a name that cannot be a folder there (here a path separator, in a header with
/// its checksum made good) is refused with exit code 2 before anything is written.
#[test]
fn a_copied_snapshot_with_a_bad_name_is_refused() {
    let (_, bytes) = sample();
    let mut bytes = bytes.clone();
    let head_len = u64::from_le_bytes(bytes[12..20].try_into().unwrap()) as usize;
    let at = (20..20 + head_len)
        .find(|&i| bytes[i..].starts_with(b"\x04test"))
        .expect("the header names the scenario `test`");
    bytes[at + 1..at + 5].copy_from_slice(b"a/..");
    let sum = xxhash_rust::xxh3::xxh3_64(&bytes[..20 + head_len]);
    let n = bytes.len();
    bytes[n - 8..].copy_from_slice(&sum.to_le_bytes());
    let dir = scratch("copied");
    std::fs::write(dir.join("copied.fsnap"), &bytes).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_fissure"))
        .args(["resume", "copied.fsnap"])
        .current_dir(&dir)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert!(
        text.contains("`a/..` cannot name an output folder") && text.contains("--out"),
        "{text}"
    );
    assert!(!dir.join("out").exists(), "nothing written");
    std::fs::remove_dir_all(dir).ok();
}

/// A static scene with a crack (the shipped centre crack on 2 mm cells, 24 load steps, its
/// load rising over the first four): each step moves the crack's surfaces, and the next
/// classifies against them; stopped after 7 and resumed, the same bits.
#[test]
fn restart_is_bit_exact_with_a_cracked_static_scene() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/centre_crack_2d.toml"
    ))
    .unwrap()
    .replace("cell = [0.001, 0.001]", "cell = [0.002, 0.002]")
    .replace(
        "damping = 1.5e5             # 1/s, near critical for the first axial mode",
        "solver = \"static\"\nload_steps = 24",
    ) + "\n[checkpoint]\nevery_steps = 10\n";
    assert!(text.contains("load_steps = 24"));
    restart_is_bit_exact(&text, 7, 2, "static_crack");
}

/// A static crack pressed shut and sheared against Coulomb friction (a 60 mm plate on
/// 2 mm cells, sigma = 100 MPa, tau = 50 MPa rising over 24 load steps, mu = 0.2): each
/// step's faces slide from the entries the particles recover, so nothing of the active
/// set travels in the snapshot; stopped after 7 and resumed, the same bits, the friction's
/// work among them.
#[test]
fn restart_is_bit_exact_with_static_friction() {
    let law = "{ law = \"friction\", friction = 0.2 }";
    let text = common::sheared_plate(0.002, 0.01, Some(law), 24, "")
        + "[output]\nhistory_interval = 0.125\n[checkpoint]\nevery_steps = 10\n";
    restart_is_bit_exact(&text, 7, 2, "static_friction");
}

/// A static scene whose grip moves (a bar pulled by a prescribed velocity's displacement
/// over 24 load steps): the grip's work over each step takes its force at the step's start
/// from the particles' stresses, so a resumed run books the same work; stopped after 7 and
/// resumed, the same bits.
#[test]
fn restart_is_bit_exact_with_a_moving_static_grip() {
    let text = common::strip_2d(
        "plane = \"stress\"\nthickness = 0.01\nsolver = \"static\"\nload_steps = 24",
        3e-5,
        r#"
[[body]]
material = "m"
box = { min = [0.002, 0.002], max = [0.03, 0.01] }
[[boundary]]
region = { min = [0.0, 0.0], max = [0.002, 0.012] }
fix = ["x", "y"]
[[boundary]]
region = { min = [0.03, 0.0], max = [0.04, 0.012] }
fix = ["x"]
velocity = [0.1, 0.0]
time = { kind = "ramp", rise = 1e-5 }
[checkpoint]
every_steps = 10
"#,
    );
    restart_is_bit_exact(&text, 7, 2, "static_grip");
}

/// A plastic static scene (the shipped Hill cylinder on 7.5 mm cells, 24 load steps): each
/// step's Newton iteration starts from the particles' committed state alone (its first
/// tangent the continuum one of that state), so stopped after 9 and resumed, the same bits.
#[test]
fn restart_is_bit_exact_with_a_plastic_static_scene() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/cylinder_plastic_2d.toml"
    ))
    .unwrap()
    .replace("cell = [0.0025, 0.0025]", "cell = [0.0075, 0.0075]")
    .replace(
        "[simulation]",
        "[simulation]\nsolver = \"static\"\nload_steps = 24",
    ) + "\n[checkpoint]\nevery_steps = 10\n";
    assert!(text.contains("cell = [0.0075, 0.0075]"));
    restart_is_bit_exact(&text, 9, 2, "static_plastic");
}

/// The shipped cantilever on 2 mm cells, its load ramped over 24 load steps, with a
/// snapshot every 10.
fn ramped_cantilever() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/cantilever_static_2d.toml"
    ))
    .unwrap()
    .replace("cell = [0.001, 0.001]", "cell = [0.002, 0.002]")
    .replace("load_steps = 1", "load_steps = 24")
    .replace(
        "force = [0.0, -100.0]     # N",
        "force = [0.0, -100.0]\ntime = { kind = \"ramp\", rise = 0.5 }",
    ) + "\n[checkpoint]\nevery_steps = 10\n"
}

/// A static scene (the ramped cantilever): stopped after 7 and resumed, every output and
/// the last snapshot the same bits; and stopped after 15, in the load's hold, where the
/// resumed run's first step keeps the answer it read (its reaction from the particles'
/// stresses, as the uninterrupted run's).
#[test]
fn restart_is_bit_exact_with_a_static_scene() {
    restart_is_bit_exact(&ramped_cantilever(), 7, 2, "static");
    restart_is_bit_exact(&ramped_cantilever(), 15, 2, "static_hold");
}

/// The coarse grid of `linear = "two_level"` is made at the first load step and reused by
/// the next while the supports and crack fields hold: a run resumed after 7 load steps
/// makes it afresh, and gives the same bits as the run that kept it.
#[test]
fn restart_is_bit_exact_with_the_coarse_grid() {
    let text =
        ramped_cantilever().replacen("[simulation]", "[simulation]\nlinear = \"two_level\"", 1);
    assert!(text.contains("two_level"));
    restart_is_bit_exact(&text, 7, 2, "static_two_level");
}
