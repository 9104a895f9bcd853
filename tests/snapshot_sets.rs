//! A split run's snapshot set: one piece per rank and a manifest. The set restores the
//! whole state (written again as one file, it is byte for byte the one-process snapshot);
//! a run resumed from it matches the uninterrupted run; an incomplete or mixed set is
//! refused naming the piece; pieces no snapshot names are removed. The sets here are
//! written by hand from a one-process run, so no MPI is needed (tests/mpi.rs has them
//! written by ranks).

mod common;
use common::{mixed_scene, source};
use fissure::app::run::{RunOptions, resume, run};
use fissure::base::dim::D2;
use fissure::io::scenario::Source;
use fissure::io::snapshot::Reader;
use fissure::io::snapshot::pieces::{self, Piece};
use fissure::io::snapshot::state::{Restored, restore, write, write_manifest};
use std::path::{Path, PathBuf};

/// A fresh, empty folder under the system temp folder.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fissure-sets-{}-{name}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A plastic scene (so the optional plastic columns travel too) with a history row every
/// step and snapshots every 7 steps.
fn text() -> String {
    common::plastic(&mixed_scene(2, "ugimp", "usavg"), 2e7, "n = 5")
        .replace("dimension = 2", "dimension = 2\nplane = \"stress\"")
        + "[output]\nhistory_interval = 1e-8\n[checkpoint]\nevery_steps = 7\nkeep = 50\n"
}

fn opts(out: &Path) -> RunOptions {
    RunOptions {
        out: Some(out.to_path_buf()),
        threads: 1,
        ..RunOptions::default()
    }
}

fn restored(path: &Path) -> Restored<D2> {
    restore::<D2>(&mut Reader::open(path).unwrap()).unwrap_or_else(|e| panic!("{e:#}"))
}

/// Writes the snapshot at `whole` as a set of `ranks` pieces (particle i to rank i mod
/// `ranks`, as a split run holds them: ascending ids) and its manifest in `dir`; returns
/// the manifest and the pieces.
fn split_set(whole: &Path, ranks: usize, dir: &Path) -> (PathBuf, Vec<Piece>) {
    let src: Source = restored(whole).source;
    let step = Reader::open(whole).unwrap().header.step;
    let stem = format!("step_{step:012}");
    let pieces: Vec<Piece> = (0..ranks)
        .map(|r| {
            let mut part = restored(whole);
            let p = &mut part.scene.world.particles;
            p.id = (0..p.len() as u64).collect();
            let mine: Vec<u32> = (0..p.len() as u32)
                .filter(|i| *i as usize % ranks == r)
                .collect();
            p.permute(&mine);
            pieces::write(dir, &stem, r, &src, &part.scene.world).unwrap()
        })
        .collect();
    let first = restored(whole);
    let manifest = dir.join(format!("{stem}.fsnap"));
    write_manifest(&manifest, &src, &first.scene.world, &first.state, &pieces).unwrap();
    (manifest, pieces)
}

/// Restoring `manifest` fails; returns the message.
fn refused(manifest: &Path) -> String {
    match restore::<D2>(&mut Reader::open(manifest).unwrap()) {
        Ok(_) => panic!("{}: an unsound set was accepted", manifest.display()),
        Err(e) => format!("{e:#}"),
    }
}

/// A set of three pieces restores the state the one-process snapshot holds: written again
/// as one file, the bytes are the same; resumed, the run ends as the uninterrupted one.
#[test]
fn a_set_restores_the_whole_state() {
    let dir = scratch("whole");
    let src = source(&text());
    let full = run(&src, &opts(&dir.join("full"))).unwrap();
    let whole = dir.join("full/snapshots/step_000000000014.fsnap");
    let set = dir.join("set");
    std::fs::create_dir_all(&set).unwrap();
    let (manifest, pieces) = split_set(&whole, 3, &set);
    assert_eq!(pieces.len(), 3);
    let n: u64 = pieces.iter().map(|p| p.particles).sum();
    assert_eq!(n, Reader::open(&whole).unwrap().header.particles);

    let back = restored(&manifest);
    let again = set.join("again.fsnap");
    write(&again, &back.source, &back.scene.world, &back.state).unwrap();
    assert!(
        std::fs::read(&again).unwrap() == std::fs::read(&whole).unwrap(),
        "the set's state written as one file is the one-process snapshot"
    );

    let resumed = resume(&manifest, &opts(&dir.join("resumed"))).unwrap();
    assert_eq!(resumed.summary.steps, full.summary.steps);
    for f in ["energy.csv", "probes.csv"] {
        let a = std::fs::read(dir.join("full").join(f)).unwrap();
        let b = std::fs::read(dir.join("resumed").join(f)).unwrap();
        assert!(a == b, "{f}: the run resumed from the set differs");
    }
    std::fs::remove_dir_all(dir).ok();
}

/// A piece missing, a piece of another set under the name the manifest gives, or two
/// pieces holding the same particles: each refused, naming the file and the problem.
#[test]
fn an_unsound_set_is_refused() {
    let dir = scratch("unsound");
    run(&source(&text()), &opts(&dir.join("full"))).unwrap();
    let snaps = dir.join("full/snapshots");
    let (a, b) = (dir.join("a"), dir.join("b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    let (manifest, pieces) = split_set(&snaps.join("step_000000000014.fsnap"), 2, &a);
    let (_, other) = split_set(&snaps.join("step_000000000007.fsnap"), 2, &b);

    let second = a.join(&pieces[1].name);
    let kept = std::fs::read(&second).unwrap();
    std::fs::remove_file(&second).unwrap();
    let err = refused(&manifest);
    assert!(
        err.contains(&pieces[1].name) && err.contains("missing"),
        "{err}"
    );

    std::fs::copy(b.join(&other[1].name), &second).unwrap();
    let err = refused(&manifest);
    assert!(err.contains("not the piece the manifest"), "{err}");
    std::fs::write(&second, kept).unwrap();
    restored(&manifest);

    // The same piece listed twice: its particles would be in two places.
    let whole = restored(&snaps.join("step_000000000014.fsnap"));
    let twice = a.join("twice.fsnap");
    let doubled = [pieces[0].clone(), pieces[0].clone()];
    write_manifest(
        &twice,
        &whole.source,
        &whole.scene.world,
        &whole.state,
        &doubled,
    )
    .unwrap();
    let err = refused(&twice);
    assert!(
        err.contains("in two pieces") || err.contains("particles"),
        "{err}"
    );
    std::fs::remove_dir_all(dir).ok();
}

/// Resuming in a run folder removes the pieces no snapshot names (a set cut short before
/// its manifest) and the partial piece files, and keeps the pieces of the set it resumes.
#[test]
fn unlisted_pieces_are_removed() {
    let dir = scratch("unlisted");
    let text = text();
    let first = run(&source(&text), &opts(&dir)).unwrap();
    let snaps = dir.join("snapshots");
    let last = first.snapshot.unwrap();
    let set = dir.join("set");
    std::fs::create_dir_all(&set).unwrap();
    let (manifest, pieces) = split_set(&last, 2, &set);
    // The set replaces the one-process snapshot of the same step.
    for f in std::iter::once(manifest.clone()).chain(pieces.iter().map(|p| set.join(&p.name))) {
        std::fs::rename(&f, snaps.join(f.file_name().unwrap())).unwrap();
    }
    let orphan = snaps.join("step_000000000099.r00001.0123456789abcdef.fpiece");
    let partial = snaps.join("step_000000000099.r00000.0123456789abcdef.fpiece.tmp");
    std::fs::write(&orphan, b"a set cut short").unwrap();
    std::fs::write(&partial, b"a write cut short").unwrap();
    let later = RunOptions {
        until: Some(first.summary.time * 1.5),
        ..opts(&dir)
    };
    resume(&dir, &later).unwrap();
    assert!(
        !orphan.exists() && !partial.exists(),
        "unlisted files removed"
    );
    for p in &pieces {
        assert!(snaps.join(&p.name).exists(), "{} kept", p.name);
    }
    std::fs::remove_dir_all(dir).ok();
}
