//! Regular background grid: geometry and the per-node component store.

use crate::base::dim::Dim;
use crate::physics::shape::ShapeKind;
use crate::store::mirror::Mirrors;

/// Geometry of a regular grid whose cells may be non-cubic.
#[derive(Clone, Debug)]
pub struct GridGeom<D: Dim> {
    /// Coordinates of node (0, 0, 0) (m).
    pub origin: D::Vec,
    /// Cell size per axis (m).
    pub h: D::Vec,
    /// Inverse cell size per axis (1/m).
    pub inv_h: D::Vec,
    /// Cells per axis (1 on the third axis in 2D).
    pub cells: [usize; 3],
    /// Nodes per axis (1 on the third axis in 2D).
    pub nodes: [usize; 3],
    /// Linear index strides of the node axes.
    pub stride: [usize; 3],
}

impl<D: Dim> GridGeom<D> {
    /// The range of cells per axis (first, last, inclusive) that the box `lo`..`hi` (m)
    /// touches, clamped to the grid.
    pub fn cell_range(&self, lo: D::Vec, hi: D::Vec) -> ([usize; 3], [usize; 3]) {
        let (mut a, mut b) = ([0; 3], [0; 3]);
        for k in 0..D::D {
            let cell = |x: f64| {
                let c = ((x - self.origin[k]) * self.inv_h[k]).floor();
                c.clamp(0.0, (self.cells[k] - 1) as f64) as usize
            };
            (a[k], b[k]) = (cell(lo[k]), cell(hi[k]));
        }
        (a, b)
    }

    /// A grid of `cells` cells of size `h` starting at `origin`.
    pub fn new(origin: D::Vec, h: D::Vec, cells: [usize; 3]) -> Self {
        let mut inv_h = h;
        let mut nodes = [1; 3];
        for a in 0..D::D {
            inv_h[a] = 1.0 / h[a];
            nodes[a] = cells[a] + 1;
        }
        GridGeom {
            origin,
            h,
            inv_h,
            cells,
            nodes,
            stride: [1, nodes[0], nodes[0] * nodes[1]],
        }
    }

    /// Total number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.iter().product()
    }

    /// Integer node coordinates of a linear node index.
    pub fn node_ijk(&self, n: usize) -> [usize; 3] {
        [
            n % self.nodes[0],
            (n / self.nodes[0]) % self.nodes[1],
            n / self.stride[2],
        ]
    }

    /// Position of a node (m).
    pub fn node_position(&self, n: usize) -> D::Vec {
        let ijk = self.node_ijk(n);
        let mut x = self.origin;
        for a in 0..D::D {
            x[a] += ijk[a] as f64 * self.h[a];
        }
        x
    }

    /// Smallest cell edge (m), which sets the stability limit.
    pub fn min_cell(&self) -> f64 {
        (0..D::D).map(|a| self.h[a]).fold(f64::INFINITY, f64::min)
    }

    /// Whether the `shape` stencil of a particle at `x` with half-width `half` (m) lies
    /// inside the grid (false for non-finite positions).
    #[inline(always)]
    pub fn fits(&self, shape: ShapeKind, x: D::Vec, half: D::Vec) -> bool {
        (0..D::D).all(|a| {
            let xi = (x[a] - self.origin[a]) * self.inv_h[a];
            shape.fits(xi, half[a] * self.inv_h[a], self.cells[a])
        })
    }
}

/// Per-node component store for the single (field-0) velocity field. Rebuilt every step.
#[derive(Clone, Debug)]
pub struct Grid<D: Dim> {
    /// Geometry.
    pub geom: GridGeom<D>,
    /// Lumped mass (kg).
    pub mass: Vec<f64>,
    /// Momentum (kg m/s).
    pub momentum: Vec<D::Vec>,
    /// Total force (N).
    pub force: Vec<D::Vec>,
    /// Velocity at the end of the step (m/s).
    pub velocity: Vec<D::Vec>,
    /// Acceleration over the step (m/s^2), including velocity-boundary corrections.
    pub accel: Vec<D::Vec>,
    /// The image nodes of the B-spline symmetry planes (none on other stencils).
    pub mirrors: Mirrors<D>,
}

impl<D: Dim> Grid<D> {
    /// A zeroed grid store.
    pub fn new(geom: GridGeom<D>) -> Self {
        let n = geom.node_count();
        Grid {
            geom,
            mass: vec![0.0; n],
            momentum: vec![D::zero(); n],
            force: vec![D::zero(); n],
            velocity: vec![D::zero(); n],
            accel: vec![D::zero(); n],
            mirrors: Mirrors::default(),
        }
    }

    /// Sizes the columns for the grid nodes plus `extra` crack-field rows after them.
    pub fn set_extra_fields(&mut self, extra: usize) {
        let n = self.geom.node_count() + extra;
        self.mass.resize(n, 0.0);
        self.momentum.resize(n, D::zero());
        self.force.resize(n, D::zero());
        self.velocity.resize(n, D::zero());
        self.accel.resize(n, D::zero());
    }

    /// Bytes held per node by the store's columns.
    pub fn bytes_per_node() -> usize {
        std::mem::size_of::<f64>() + 4 * std::mem::size_of::<D::Vec>()
    }
}
