//! The crack store's topology: a tip keeps its vertex when the crack grows behind it, the
//! crack systems follow the new elements at once, and a snapshot keeps the grown crack.

mod common;
use common::{final_world_with, source, strip_2d};
use fissure::base::dim::D2;
use fissure::io::scenario::build;
use fissure::io::snapshot::Reader;
use fissure::io::snapshot::state::{restore, write};
use fissure::record::state::RunState;
use fissure::store::crack::Cracks;
use fissure::systems::{bin, classify};
use glam::DVec2;

/// A 32 x 4 mm bar whose halves are pulled apart at 1 m/s each, with an edge crack from
/// below the bar to mid-height along the grid line x = 20 mm where the halves meet: the
/// ligament above it holds the halves together.
fn half_cracked_bar() -> String {
    strip_2d(
        "shape = \"ugimp\"\nupdate = \"usavg\"",
        2e-5,
        r#"[[body]]
material = "m"
box = { min = [0.004, 0.004], max = [0.02, 0.008] }
velocity = [-1.0, 0.0]
[[body]]
material = "m"
box = { min = [0.02, 0.004], max = [0.036, 0.008] }
velocity = [1.0, 0.0]
[[crack]]
line = { start = [0.02, 0.0025], end = [0.02, 0.006], spacing = 5e-4 }
"#,
    )
}

/// Where the extended tip goes: past the bar's top edge, so the crack cuts the section.
const THROUGH: DVec2 = DVec2::new(0.02, 0.0095);

#[test]
fn a_tip_keeps_its_vertex_when_the_crack_grows() {
    let src = source(&half_cracked_bar());
    let mut cracks: Cracks<D2> = build::<D2>(&src).unwrap().world.cracks.unwrap();
    let before = cracks.topology.clone();
    let tip = before.fronts()[0].vertices[0];
    let old = before.cracks()[0].vertices.clone();
    let new = cracks.extend_tip(0, THROUGH);
    let t = &cracks.topology;
    assert_ne!(t.version(), before.version());
    assert_eq!(new as usize, before.vertex_count());
    assert_eq!(t.fronts()[0].vertices, [tip], "the tip keeps its index");
    assert_eq!(cracks.geometry.x[tip as usize], THROUGH);
    assert_eq!(
        cracks.geometry.x[new as usize],
        before_x(&src, tip),
        "the new vertex takes the tip's old place"
    );
    // The polyline runs start -> new -> tip, every other vertex where it was.
    let path = &t.cracks()[0].vertices;
    assert_eq!(path[..old.len() - 1], old[..old.len() - 1]);
    assert_eq!(path[old.len() - 1..], [new, tip]);
    // Its segments join consecutive vertices in the polyline's direction (the crack's
    // above and below sides are unchanged).
    let mut segs: Vec<[u32; 2]> = t.elems().to_vec();
    segs.sort_unstable();
    let mut want: Vec<[u32; 2]> = path.windows(2).map(|w| [w[0], w[1]]).collect();
    want.sort_unstable();
    assert_eq!(segs, want);
}

fn before_x(src: &fissure::io::scenario::Source, tip: u32) -> DVec2 {
    build::<D2>(src).unwrap().world.cracks.unwrap().geometry.x[tip as usize]
}

/// Classified against the half crack, then grown through the section before the first
/// step: the halves then separate unstressed, as with a crack through the bar from the
/// start (tests/cracks.rs). Classification reused from before the growth would keep the
/// ligament's particles joined and stretch them.
#[test]
fn the_crack_systems_follow_a_grown_crack_at_once() {
    let text = half_cracked_bar();
    let stretched = final_world_with::<D2>(&text, 1, |_| {});
    let e = stretched.energies();
    assert!(e.strain > 1e-3 * e.kinetic, "the ligament holds the halves");

    let grown = final_world_with::<D2>(&text, 1, |w| {
        bin::run(w).unwrap();
        classify::run(w).expect("room for every crack");
        w.cracks.as_mut().unwrap().extend_tip(0, THROUGH);
    });
    let e = grown.energies();
    assert!(
        e.strain < 1e-20 * e.kinetic,
        "strain energy {:e} J after the crack cut through",
        e.strain
    );
}

/// A snapshot of a grown crack resumes with the grown topology and every vertex where it
/// was, although the stored scenario builds the crack as it started.
#[test]
fn a_snapshot_keeps_the_grown_crack() {
    let src = source(&half_cracked_bar());
    let mut world = build::<D2>(&src).unwrap().world;
    let cracks = world.cracks.as_mut().unwrap();
    cracks.extend_tip(0, THROUGH);
    let grown = cracks.clone();
    let mut state = RunState::start(&world, 0, 10, 1e-6, 1e-6, None);
    state.sample(&world, &[]);
    let dir = std::env::temp_dir().join(format!("fissure-topology-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("grown.fsnap");
    write(&path, &src, &world, &state).unwrap();
    let mut r = Reader::open(&path).unwrap();
    let back = restore::<D2>(&mut r).unwrap().scene.world.cracks.unwrap();
    std::fs::remove_dir_all(&dir).ok();
    let (a, b) = (&grown.topology, &back.topology);
    assert_eq!(a.elems(), b.elems());
    assert_eq!(a.elem_crack(), b.elem_crack());
    assert_eq!(a.fronts(), b.fronts());
    assert_eq!(a.cracks()[0].vertices, b.cracks()[0].vertices);
    assert_eq!(a.vertex_count(), b.vertex_count());
    assert_eq!(a.version(), b.version());
    assert_eq!(grown.geometry.x, back.geometry.x);
    assert_eq!(grown.geometry.top, back.geometry.top);
    assert_eq!(grown.geometry.bottom, back.geometry.bottom);
}
