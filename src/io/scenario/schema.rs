//! The scenario file format (TOML). Every table rejects unknown keys.

use crate::physics::shape::ShapeKind;
use crate::physics::timefn::TimeFn;
use crate::store::world::{Dilatation, LinearSolver, Solver, Update};
use serde::Deserialize;

/// A whole scenario file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Name used in reports (default: the file stem).
    pub name: Option<String>,
    /// Free text.
    pub description: Option<String>,
    /// Time integration and kinematics.
    pub simulation: Simulation,
    /// Background grid.
    pub grid: GridSpec,
    /// Materials.
    #[serde(default, rename = "material")]
    pub materials: Vec<MaterialSpec>,
    /// Bodies filled with particles.
    #[serde(default, rename = "body")]
    pub bodies: Vec<BodySpec>,
    /// Explicit cracks (2D polylines).
    #[serde(default, rename = "crack")]
    pub cracks: Vec<CrackSpec>,
    /// Prescribed grid velocities.
    #[serde(default, rename = "boundary")]
    pub boundaries: Vec<BoundarySpec>,
    /// External particle forces.
    #[serde(default, rename = "load")]
    pub loads: Vec<LoadSpec>,
    /// Recorded particle averages.
    #[serde(default, rename = "probe")]
    pub probes: Vec<ProbeSpec>,
    /// Output cadence.
    #[serde(default)]
    pub output: OutputSpec,
    /// Snapshot cadence for checkpoint and restart.
    #[serde(default)]
    pub checkpoint: CheckpointSpec,
    /// J-integral and K at crack tips (needs cracks).
    pub fracture: Option<FractureSpec>,
    /// Self-checks against reference values.
    #[serde(default, rename = "expect")]
    pub expects: Vec<ExpectSpec>,
}

/// `[simulation]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Simulation {
    /// 2 or 3.
    pub dimension: u8,
    /// 2D only: "strain" (default) or "stress".
    pub plane: Option<String>,
    /// 2D only: out-of-plane thickness (m), default 1.
    pub thickness: Option<f64>,
    /// Shape function.
    #[serde(default)]
    pub shape: ShapeKind,
    /// Stress-update order.
    #[serde(default)]
    pub update: Update,
    /// Simulated duration (s).
    pub duration: f64,
    /// Time step as a fraction of the stability limit (0 < cfl < 1; default 0.5).
    pub cfl: Option<f64>,
    /// Explicit time step (s) instead of `cfl`; must not exceed the stability limit.
    pub dt: Option<f64>,
    /// Mass-proportional damping alpha = d_k/rho (1/s).
    #[serde(default)]
    pub damping: f64,
    /// Body force per unit mass (m/s^2).
    pub gravity: Option<Vec<f64>>,
    /// Cells per tile edge (default 8 in 2D, 4 in 3D).
    pub tile: Option<usize>,
    /// "explicit" (default) or "static".
    #[serde(default)]
    pub solver: Solver,
    /// A static scene's load steps over `duration` (default: one per history row when
    /// `[output] history_interval` is given, else 10).
    pub load_steps: Option<u64>,
    /// A static scene's residual, relative to the external force, at which a load step has
    /// converged (default 1e-8).
    pub tolerance: Option<f64>,
    /// A static scene's linear solver: "auto" (default), "direct", "cg" or "two_level".
    pub linear: Option<LinearSolver>,
    /// The volumetric strain a particle's stress sees: "particle" (its own, default) or
    /// "cell_mean" (its cell's mean: plane strain and 3D, static or explicit).
    #[serde(default)]
    pub dilatation: Dilatation,
}

/// `[grid]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSpec {
    /// Lower corner (m).
    pub min: Vec<f64>,
    /// Upper corner (m).
    pub max: Vec<f64>,
    /// Cell size per axis (m).
    pub cell: Vec<f64>,
    /// Lays the nodes from a point instead of from `min`, so that a scene keeps its place
    /// in the lattice when the cell size changes; `min` and `max` are then widened to
    /// whole cells.
    pub anchor: Option<AnchorSpec>,
}

/// `[grid] anchor`: the nodes lie at `point + (k + offset) cell` on each axis.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnchorSpec {
    /// A point of the lattice (m).
    pub point: Vec<f64>,
    /// Per axis, the fraction of a cell the nodes are shifted from the point, in [0, 1)
    /// (0.5 puts the point at a cell's centre on that axis); default 0.
    pub offset: Option<Vec<f64>>,
}

/// `[[material]]`: isotropic linear elastic.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Name bodies refer to.
    pub name: String,
    /// Young's modulus (Pa).
    #[serde(rename = "E")]
    pub youngs: f64,
    /// Poisson's ratio.
    pub nu: f64,
    /// Density (kg/m^3).
    pub rho: f64,
    /// Constitutive model: "elastic" (default) or "j2" (von Mises plasticity).
    #[serde(default)]
    pub model: ModelKind,
    /// j2: initial yield stress (Pa).
    pub sigma_y: Option<f64>,
    /// j2: linear isotropic hardening modulus (Pa); 0 (the default) is perfectly plastic.
    #[serde(rename = "H")]
    pub hardening: Option<f64>,
    /// j2: modified Ramberg-Osgood exponent n (> 1), instead of `H`.
    pub n: Option<f64>,
    /// j2 with `n`: the handbook's Ramberg-Osgood form eps/eps_0 = sigma/sigma_0 + alpha
    /// (sigma/sigma_0)^n (Kumar, German & Shih 1981), `sigma_y` its reference stress.
    pub alpha: Option<f64>,
}

/// A material's constitutive model.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ModelKind {
    /// Small-strain isotropic linear elasticity.
    #[default]
    Elastic,
    /// J2 (von Mises) plasticity with isotropic hardening.
    J2,
}

/// An axis-aligned box (m).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    /// Lower corner.
    pub min: Vec<f64>,
    /// Upper corner.
    pub max: Vec<f64>,
}

/// A region of boundary nodes, loaded particles or probed particles (m). Exactly one shape:
/// `min` and `max` (an axis-aligned box, inclusive); `polygon` (2D); `center`, `half` and
/// `angle` (2D, degrees from +x) or `axes` (3D, the first two axis directions) (an
/// oriented box); `center` and `radius` (a disc in 2D, a ball in 3D); `point` and `normal`
/// (the half-space the normal points into).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionSpec {
    /// Lower corner of a box.
    pub min: Option<Vec<f64>>,
    /// Upper corner of a box.
    pub max: Option<Vec<f64>>,
    /// Polygon vertices [[x, y], ...], either winding, not crossing itself.
    pub polygon: Option<Vec<Vec<f64>>>,
    /// Centre of an oriented box, disc or ball.
    pub center: Option<Vec<f64>>,
    /// Radius of a disc (2D) or ball (3D).
    pub radius: Option<f64>,
    /// Half-sizes of an oriented box along its axes.
    pub half: Option<Vec<f64>>,
    /// 2D oriented box: angle of its first axis, degrees from +x.
    pub angle: Option<f64>,
    /// 3D oriented box: its first two axis directions (perpendicular).
    pub axes: Option<Vec<Vec<f64>>>,
    /// A point on a half-space's boundary plane.
    pub point: Option<Vec<f64>>,
    /// A half-space's normal, pointing into it.
    pub normal: Option<Vec<f64>>,
}

/// A body bounded by the closed surface in an STL file (ASCII or binary) or an OBJ file,
/// placed by x = R (scale * x_file) + translate.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshBodySpec {
    /// The file, relative to the scenario file's folder.
    pub file: String,
    /// Factor from the file's units to metres (default 1; 1e-3 for a part in mm).
    pub scale: Option<f64>,
    /// Rotation after scaling, before the offset.
    pub rotate: Option<RotateSpec>,
    /// Offset after scaling and rotating (m).
    pub translate: Option<Vec<f64>>,
}

/// A crack surface read from an OBJ or STL file (faces split into triangles, all objects
/// together, corners at one place one vertex), placed by x = R (scale * x_file) +
/// translate.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrackFileSpec {
    /// The file, relative to the scenario file's folder.
    pub file: String,
    /// Factor from the file's units to metres (default 1).
    pub scale: Option<f64>,
    /// Rotation after scaling, before the offset.
    pub rotate: Option<RotateSpec>,
    /// Offset after scaling and rotating (m).
    pub translate: Option<Vec<f64>>,
    /// Front vertices in order along the front, as positions in the file's units
    /// (default: the boundary edges inside a body; `[]`: no front).
    pub front: Option<Vec<Vec<f64>>>,
}

/// A rotation by `angle` degrees about `axis` (right-handed).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotateSpec {
    /// Axis direction (any length but zero).
    pub axis: Vec<f64>,
    /// Angle (degrees).
    pub angle: f64,
}

/// A disc (2D) or sphere (3D), or a ring or spherical shell when `inner_radius` is given.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoundSpec {
    /// Centre (m).
    pub center: Vec<f64>,
    /// Radius (m).
    pub radius: f64,
    /// Radius of the hole (m); default 0, a full disc or sphere.
    #[serde(default)]
    pub inner_radius: f64,
}

/// A 3D circular cylinder, or a tube when `inner_radius` is given.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderSpec {
    /// Centre of the base (m).
    pub center: Vec<f64>,
    /// Axis direction: "x", "y" or "z".
    pub axis: String,
    /// Radius (m).
    pub radius: f64,
    /// Radius of the bore of a tube (m); default 0, a solid cylinder.
    #[serde(default)]
    pub inner_radius: f64,
    /// Length along the axis (m).
    pub length: f64,
}

/// A polygon in the x-y plane; in 3D extruded over `z = [z0, z1]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolygonSpec {
    /// Vertices (m), at least three, in either winding.
    pub points: Vec<Vec<f64>>,
    /// 3D only: extrusion range (m).
    pub z: Option<Vec<f64>>,
}

/// `[[body]]`: a region filled with particles. Exactly one geometry key is given.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Optional name.
    pub name: Option<String>,
    /// Material name.
    pub material: String,
    /// Particles per cell per direction.
    #[serde(default = "default_ppc")]
    pub ppc: usize,
    /// Initial velocity (m/s).
    pub velocity: Option<Vec<f64>>,
    /// Initial rigid spin (rad/s): one value (about z) in 2D, a vector in 3D.
    pub angular_velocity: Option<Vec<f64>>,
    /// Centre of the initial spin (m); default the centre of the geometry's bounding box
    /// (before any `clip`).
    pub spin_center: Option<Vec<f64>>,
    /// Box geometry.
    #[serde(rename = "box")]
    pub box_: Option<BoxSpec>,
    /// Disc geometry (2D).
    pub disc: Option<RoundSpec>,
    /// Sphere geometry (3D).
    pub sphere: Option<RoundSpec>,
    /// Cylinder geometry (3D).
    pub cylinder: Option<CylinderSpec>,
    /// Polygon geometry (2D, or extruded in 3D).
    pub polygon: Option<PolygonSpec>,
    /// A closed triangulated surface read from a file (3D).
    pub mesh: Option<MeshBodySpec>,
    /// Keep only the part of the geometry inside this region (e.g. the half-space on one
    /// side of a symmetry plane).
    pub clip: Option<RegionSpec>,
    /// Holes cut out of the geometry: discs (2D) or balls (3D), `{ center, radius }`.
    #[serde(default)]
    pub holes: Vec<RoundSpec>,
}

fn default_ppc() -> usize {
    2
}

/// `[[crack]]`: an explicit crack, a polyline of massless points. Exactly one of `points`
/// and `line`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrackSpec {
    /// Name used in reports (default `crack<k>`).
    pub name: Option<String>,
    /// Vertices `[[x, y], ...]` (m), at least two.
    pub points: Option<Vec<Vec<f64>>>,
    /// A straight crack with evenly spaced vertices.
    pub line: Option<LineSpec>,
    /// 3D: a triangle mesh given as vertex and triangle lists.
    pub mesh: Option<MeshSpec>,
    /// 3D: a triangle mesh read from an OBJ file.
    pub mesh_file: Option<CrackFileSpec>,
    /// 3D: a planar rectangle (no front: a crack cutting through a body).
    pub rectangle: Option<PlanarSpec>,
    /// 3D: a planar ellipse, whole (an embedded crack) or half (a surface crack).
    pub ellipse: Option<EllipseSpec>,
    /// 3D: a circular (penny-shaped) crack.
    pub penny: Option<PennySpec>,
    /// Which ends are crack tips: "start" and/or "end" (default `["end"]`).
    pub tips: Option<Vec<String>>,
    /// Contact between the crack faces (default: none, an open crack).
    pub contact: Option<ContactSpec>,
    /// Which particle-node pairs the crack splits: "crossing" (default) or "inside".
    pub split: Option<String>,
    /// 2D: how the crack's tips grow (default: they do not).
    pub growth: Option<GrowthSpec>,
}

/// `[crack.growth]`: when a tip starts to grow, which way, and how far or how fast.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GrowthSpec {
    /// "hoop" (maximum hoop stress reaches `KIc`), "energy" (J reaches `Gc`) or "time"
    /// (at time `at`).
    pub initiation: String,
    /// Fracture toughness K_Ic (Pa sqrt(m)), for "hoop".
    #[serde(rename = "KIc")]
    pub k_ic: Option<f64>,
    /// Critical energy release rate G_c (J/m^2), for "energy".
    #[serde(rename = "Gc")]
    pub g_c: Option<f64>,
    /// Start time (s), for "time".
    pub at: Option<f64>,
    /// "hoop" (the direction of the largest hoop stress; the default in 2D) or "straight"
    /// (on along the last segment; in 3D in the crack plane, the only choice there).
    pub direction: Option<String>,
    /// Once started, run at this speed (m/s) whatever K does, on the heading taken at the
    /// start (default: extend by `extension` at every check at which the criterion
    /// holds).
    pub speed: Option<f64>,
    /// Length of a new crack segment (m; default half the smallest cell).
    pub extension: Option<f64>,
    /// Time between evaluations of the criterion and direction (s; default every tenth
    /// step).
    /// Under fatigue, long enough for the damped run to settle after each extension.
    pub interval: Option<f64>,
    /// Fatigue: the Paris-Erdogan law; each extension then costs load cycles.
    pub paris: Option<ParisSpec>,
}

/// `paris = { C, m, R }`: da/dN = C (Delta K_eq)^m, Delta K in Pa sqrt(m), a in m.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParisSpec {
    /// C (m per cycle per (Pa sqrt(m))^m).
    #[serde(rename = "C")]
    pub c: f64,
    /// Exponent m (> 0).
    pub m: f64,
    /// Load ratio R = K_min / K_max in [0, 1) (default 0); the run holds the largest load.
    #[serde(rename = "R")]
    pub r: Option<f64>,
}

/// A 3D crack surface as lists: `vertices = [[x, y, z], ...]` (m), `triangles = [[i, j,
/// k], ...]` (counterclockwise seen from the side called above), and optionally the front
/// as an ordered list of vertex indices.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// Vertex positions (m).
    pub vertices: Vec<Vec<f64>>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<Vec<i64>>,
    /// Front vertices in order along the front (default: no front).
    pub front: Option<Vec<i64>>,
}

/// A planar rectangle: centre and the two half-side vectors (m); above is the side of
/// their cross product.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanarSpec {
    /// Centre (m).
    pub center: Vec<f64>,
    /// Half-side vectors `[[ux, uy, uz], [vx, vy, vz]]` (m), not parallel.
    pub axes: Vec<Vec<f64>>,
    /// Target triangle edge length (m; default half the smallest cell).
    pub spacing: Option<f64>,
}

/// A planar ellipse: centre and semi-axis vectors (m). `half = true` keeps the half on the
/// side of the second axis, a surface crack whose straight edge (through the centre, along
/// the first axis) is carried 1.5 cells outwards so that it reaches past the surface.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EllipseSpec {
    /// Centre (m).
    pub center: Vec<f64>,
    /// Semi-axis vectors `[[ax, ay, az], [bx, by, bz]]` (m), not parallel.
    pub axes: Vec<Vec<f64>>,
    /// Only the half on the second axis's side (default false).
    #[serde(default)]
    pub half: bool,
    /// Target triangle edge length (m; default half the smallest cell).
    pub spacing: Option<f64>,
}

/// A circular crack: centre, normal (towards the side called above) and radius (m).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PennySpec {
    /// Centre (m).
    pub center: Vec<f64>,
    /// Normal, any length.
    pub normal: Vec<f64>,
    /// Radius (m).
    pub radius: f64,
    /// Target triangle edge length (m; default half the smallest cell).
    pub spacing: Option<f64>,
}

/// `contact = { law = "frictionless" }` on a crack.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// "none", "stick", "frictionless" or "friction".
    pub law: String,
    /// Coulomb coefficient for "friction".
    pub friction: Option<f64>,
    /// Check that the faces approach before testing their overlap (default false).
    pub approach_check: Option<bool>,
}

/// A straight crack from `start` to `end` (m), a vertex every `spacing` (m; default half
/// the smallest cell).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LineSpec {
    /// First vertex (m).
    pub start: Vec<f64>,
    /// Last vertex (m).
    pub end: Vec<f64>,
    /// Largest distance between vertices (m).
    pub spacing: Option<f64>,
}

/// A plane of nodes `axis = at` (m).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    /// "x", "y" or "z".
    pub axis: String,
    /// Coordinate of the plane (m); must lie on a grid line.
    pub at: f64,
}

/// `[[boundary]]`: prescribed velocity components on the nodes of a region or plane.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// Nodes inside this region (inclusive).
    pub region: Option<RegionSpec>,
    /// Nodes on this plane (a symmetry plane fixes its normal component).
    pub plane: Option<PlaneSpec>,
    /// Components to prescribe; default all (region) or the normal (plane).
    pub fix: Option<Vec<String>>,
    /// Prescribed velocity (m/s); default zero.
    pub velocity: Option<Vec<f64>>,
    /// Time multiplier on the velocity.
    #[serde(default)]
    pub time: TimeFn,
}

/// `[[load]]`: on the particles initially inside a region, either a total force spread
/// equally (`force`) or a traction on a face: a `pressure`, or the stress of a closed-form
/// field (`williams`, `centre_crack`), with the face's outward `normal` or, for a pressure,
/// a round face's centre.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Particles initially inside this region are loaded.
    pub region: RegionSpec,
    /// Total force (N).
    pub force: Option<Vec<f64>>,
    /// A uniform pressure on a face.
    pub pressure: Option<PressureSpec>,
    /// Traction of the near-tip (Williams) stress field, 2D only.
    pub williams: Option<WilliamsSpec>,
    /// Traction of the exact field of a centre crack in an infinite plate, 2D only.
    pub centre_crack: Option<CentreCrackSpec>,
    /// Outward normal of the face a traction acts on (any direction in the plane).
    pub normal: Option<Vec<f64>>,
    /// Time multiplier.
    #[serde(default)]
    pub time: TimeFn,
}

/// A uniform pressure on a planar face (the load's `normal`) or on a circle (2D) or sphere
/// (3D) about `center`, such as a bore.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PressureSpec {
    /// Pressure (Pa); positive pushes on the face, against its outward normal.
    pub value: f64,
    /// Centre of a round face (m).
    pub center: Option<Vec<f64>>,
    /// Which side of the loaded layer a round face is: "inner" (a bore) or "outer".
    pub face: Option<String>,
}

/// The leading (Williams / Irwin) term of the stress field around a crack tip.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WilliamsSpec {
    /// Mode I stress intensity factor (Pa sqrt(m)).
    #[serde(rename = "KI")]
    pub k1: f64,
    /// Mode II stress intensity factor (Pa sqrt(m)).
    #[serde(rename = "KII")]
    pub k2: f64,
    /// Tip position (m).
    pub tip: Vec<f64>,
    /// Direction the crack points (from its faces to its tip), degrees from +x; default 0.
    #[serde(default)]
    pub direction: f64,
}

/// `[[probe]]`: a particle average (or a support's reaction) recorded at every step.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    /// Name used by `[[expect]]` and in probes.csv.
    pub name: String,
    /// Particles initially inside this region are averaged (for a reaction, its nodes summed).
    pub region: RegionSpec,
    /// "displacement", "velocity", "position", "stress", "strain", "opening" (the mean
    /// displacement beyond the region's centroid minus that short of it, along `component`),
    /// "plastic_radius" (on a disc or ball region: the largest initial distance from its
    /// centre of a particle that has yielded; no component) or "reaction" (the force the
    /// region's prescribed-velocity nodes exerted on the body, N).
    pub quantity: String,
    /// "x", "y", "z" for vectors; "xx", "yy", "zz", "yz", "xz", "xy" for tensors.
    pub component: Option<String>,
}

/// A straight crack in an infinite plate under a uniform remote stress.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CentreCrackSpec {
    /// Remote stress (xx, yy, xy) in global axes (Pa).
    pub stress: Vec<f64>,
    /// Crack centre (m).
    pub center: Vec<f64>,
    /// Half-length a (m).
    pub half_length: f64,
    /// Angle of the crack line, degrees from +x; default 0.
    #[serde(default)]
    pub angle: f64,
}

/// `[output]`.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Simulated time between VTK frames (s); default duration / 20.
    pub interval: Option<f64>,
    /// Simulated time between energy.csv and probes.csv rows (s); default duration / 400.
    pub history_interval: Option<f64>,
    /// Write VTK particle files (default true).
    pub vtk: Option<bool>,
    /// Write PNG plots (default true).
    pub plot: Option<bool>,
}

/// `[fracture]`: J and K at every crack tip, at the history cadence (fracture.csv).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FractureSpec {
    /// Half-size n of the square contour, in cells (default 2), or in m with `lengths = "m"`.
    pub contour: Option<f64>,
    /// Include the area term of Guo & Nairn 2D (2004) Eq. 8 (default true).
    pub area_term: Option<bool>,
    /// Further contour sizes (cells) on which J is also measured, its line and area parts
    /// apart, for the path-independence record paths.csv; in 3D tube radii (each with its
    /// half-length, at least 2), set against the main tube of `domain` cells.
    pub compare: Option<Vec<f64>>,
    /// Start of the window (s) over which summary.json and `J_path` expects compare the
    /// contours (default 0), e.g. once the first stress wave has passed the tip.
    pub compare_from: Option<f64>,
    /// fracture.png shows K / k0 (k0 in Pa sqrt(m), e.g. s0 sqrt(pi a)); default: K.
    pub k0: Option<f64>,
    /// The crack opening that splits G into K_I and K_II is fitted over the crack from 1 to
    /// `opening` cells behind the tip (default 8; on a crack with two tips, at most half its
    /// length).
    pub opening: Option<f64>,
    /// Which K are reported in the KI, KII (, KIII) columns and expects: "lower_g" (the
    /// default: of "interaction" and "mixity", the one of lower G), "interaction" (the
    /// interaction integral), "mixity" (G from J split in the interaction integral's
    /// ratios) or "opening" (G split by the crack opening).
    pub k_from: Option<String>,
    /// Radius of the interaction integral's domain around the tip, in cells (default 6 in
    /// 2D; in 3D the radius and half-length of the tube around the front, default 3).
    pub domain: Option<f64>,
    /// The unit of `contour`, `compare`, `domain` and `opening`: "cells" (default) or "m",
    /// so that a refined grid keeps the contours where they were (rounded to whole cells
    /// for the square contours and compared tubes).
    pub lengths: Option<String>,
}

/// `along = { shape, zero, normal }` of a front expect: the reference at a front vertex is
/// `reference` times cos(theta) or sin(theta), theta the vertex's angle about the front's
/// centre (the mean of its vertices) from the direction `zero`, counterclockwise about
/// `normal` (e.g. an inclined penny's K_II and K_III); or, with shape "ellipse" and
/// `ratio` = b/a, Irwin's (sin^2 phi + (b/a)^2 cos^2 phi)^(1/4) for an elliptical front
/// whose major axis is `zero`, phi its parametric angle (1 at the ends of the minor axis).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AlongSpec {
    /// "cos", "sin" or "ellipse".
    pub shape: String,
    /// Direction of theta = 0 (projected onto the plane normal to `normal`).
    pub zero: Vec<f64>,
    /// Axis theta turns about.
    pub normal: Vec<f64>,
    /// For "ellipse": the ratio b/a of the minor to the major semi-axis, in (0, 1].
    pub ratio: Option<f64>,
}

/// The eta estimate J = K^2 / E' + eta A_pl / (B b) of a cracked specimen's J from its
/// load-displacement record (Rice, Paris & Merkle 1973; ASTM E1820), with K = K_per_load P.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EtaSpec {
    /// The plastic eta factor of the specimen and displacement measured (e.g. 1.9 for a
    /// bend bar's load-line displacement).
    pub factor: f64,
    /// The uncracked ligament b (m).
    pub ligament: f64,
    /// The handbook's K_I per unit load (Pa sqrt(m) / N; in 2D per load on the scene's
    /// thickness).
    #[serde(rename = "K_per_load")]
    pub k_per_load: f64,
    /// The material at the tip, whose E' turns K into the elastic J.
    pub material: String,
}

/// `[checkpoint]`: when to write snapshots into `<out>/snapshots/` (any combination; none
/// set means snapshots only on a clean stop).
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct CheckpointSpec {
    /// Every this many steps.
    pub every_steps: Option<u64>,
    /// Every this much simulated time (s).
    pub every_time: Option<f64>,
    /// Every this many minutes of wall-clock time.
    pub every_wall_minutes: Option<f64>,
    /// How many of the newest snapshots to keep (default 2).
    pub keep: Option<usize>,
}

/// `[[expect]]`: a measured quantity checked against a reference.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpectSpec {
    /// One of: final, max, min, frequency, wave_speed, slope (the change of the first probe
    /// over the second's from `from` to the end), momentum_drift, energy_drift,
    /// angular_momentum_drift; KI, KII, J1, J2 (at a crack tip: the last value, or at `at`);
    /// J_path (largest difference of J on the `[fracture] compare` contours from the main
    /// one, relative to the main one's largest |J|; in 3D the worst front vertex, or the
    /// one `near` a point); K_drift (largest |K(t) - K(end)| from
    /// `from` on, relative to |K(end)|); in 3D KI_front, KII_front, KIII_front, J1_front
    /// (the value farthest from the reference over a crack's front vertices, or at the
    /// vertex `near` a point, last row); for a growing 2D tip kink (its first turn,
    /// degrees), path_angle (its line over the last quarter of the length grown, to x, degrees in
    /// (-90, 90]), turn (the chord from the tip's start to its last new vertex, as a turn
    /// from the crack, degrees) and cycles (fatigue: load cycles to grow by `length`); for
    /// a growing 3D front kink (its largest turn at the first check, degrees) and cycles;
    /// J_eta (|J| at a 2D tip against the `eta` estimate from a load and a displacement
    /// probe, relative); G_interaction (at a 2D tip at rest, the largest difference of the
    /// interaction integral's G from J along the tip from `from` on, relative to J's
    /// largest).
    pub quantity: String,
    /// Probe(s) the quantity is measured on (wave_speed and slope take two).
    #[serde(default)]
    pub probes: Vec<String>,
    /// Crack name, for KI, KII, J1, J2.
    pub crack: Option<String>,
    /// Tip of that crack: "start" or "end" (default "end").
    pub tip: Option<String>,
    /// For final, KI, KII, J1, J2: the value at this time (s) instead of the last one (a
    /// probe: its last sample at or before it).
    pub at: Option<f64>,
    /// For K_drift, G_interaction, kinetic_fraction and slope: the start of the window (s).
    pub from: Option<f64>,
    /// For cycles: the length grown (m) whose cycles are compared.
    pub length: Option<f64>,
    /// For the front quantities: how the reference varies along the front (default: it
    /// does not).
    pub along: Option<AlongSpec>,
    /// For the front quantities: only the front vertex nearest this point (m), e.g. the
    /// deepest point of a surface crack (default: every front vertex).
    pub near: Option<Vec<f64>>,
    /// For J_eta: the specimen's eta estimate of J from its load-displacement record.
    pub eta: Option<EtaSpec>,
    /// For G_interaction: the material at the tip, whose E' turns K into G (default: the
    /// scene's only material).
    pub material: Option<String>,
    /// Reference value (SI).
    pub reference: f64,
    /// Where the reference comes from.
    pub source: String,
    /// Allowed error: relative to |reference|, or absolute when the reference is 0.
    pub tolerance: f64,
}
