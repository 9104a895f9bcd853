//! Particle component store: one column per component (struct of arrays).

use crate::base::columnar::Columnar;
use crate::base::dim::Dim;
use crate::physics::plastic::Hardened;

/// Material points. Columns a scene does not need stay empty (e.g. `half` unless uGIMP).
#[derive(Clone, Debug)]
pub struct Particles<D: Dim> {
    /// Position (m).
    pub x: Vec<D::Vec>,
    /// Velocity (m/s).
    pub v: Vec<D::Vec>,
    /// Initial position (m); the displacement is `x - x0` (see
    /// [`displacement`](Self::displacement)), so no step has to integrate it.
    pub x0: Vec<D::Vec>,
    /// Mass (kg).
    pub mass: Vec<f64>,
    /// Initial volume (m^3; in 2D area times thickness).
    pub volume: Vec<f64>,
    /// Cauchy stress (Pa), small strain.
    pub stress: Vec<D::Sym>,
    /// Velocity gradient dv_i/dx_j (1/s) from the most recent gather; only allocated when
    /// J-integrals are measured (their area term reads it).
    pub grad_v: Vec<D::Mat>,
    /// Index into the world's material table.
    pub material: Vec<u16>,
    /// Particle half-width per axis (m); only allocated for uGIMP.
    pub half: Vec<D::Vec>,
    /// Displacement gradient du_i/dx_j, accumulated from grad v; only allocated when
    /// J-integrals are measured (Guo & Nairn 2D (2004) section 3 tracks it on particles).
    pub grad_u: Vec<D::Mat>,
    /// Plastic strain; only allocated when a material is plastic.
    pub plastic_strain: Vec<D::Sym>,
    /// Hardening state (equivalent plastic strain, yield stress, plastic work); only
    /// allocated when a material is plastic.
    pub hardened: Vec<Hardened>,
    /// Index in the whole scene; only allocated when the scene is split across ranks,
    /// whose stores then hold their particles in ascending id.
    pub id: Vec<u64>,
}

/// An operation on each particle column in turn, whatever its element type.
pub trait ColumnOp {
    /// Applies the operation to one column (empty when the scene does not need it).
    fn column<T: Columnar>(&mut self, col: &mut Vec<T>);
}

impl<D: Dim> Default for Particles<D> {
    fn default() -> Self {
        Particles {
            x: Vec::new(),
            v: Vec::new(),
            x0: Vec::new(),
            mass: Vec::new(),
            volume: Vec::new(),
            stress: Vec::new(),
            grad_v: Vec::new(),
            material: Vec::new(),
            half: Vec::new(),
            grad_u: Vec::new(),
            plastic_strain: Vec::new(),
            hardened: Vec::new(),
            id: Vec::new(),
        }
    }
}

impl<D: Dim> Particles<D> {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether the store is empty.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Appends one particle at rest and unstressed.
    pub fn push(&mut self, x: D::Vec, v: D::Vec, mass: f64, volume: f64, material: u16) {
        self.x.push(x);
        self.v.push(v);
        self.x0.push(x);
        self.mass.push(mass);
        self.volume.push(volume);
        self.stress.push(D::Sym::default());
        self.material.push(material);
    }

    /// Bytes held per particle by the allocated columns.
    pub fn bytes_per_particle(&self) -> usize {
        let vec = std::mem::size_of::<D::Vec>();
        let base = 3 * vec
            + 2 * std::mem::size_of::<f64>()
            + std::mem::size_of::<D::Sym>()
            + std::mem::size_of::<u16>();
        let mat = std::mem::size_of::<D::Mat>();
        base + if self.half.is_empty() { 0 } else { vec }
            + if self.grad_u.is_empty() { 0 } else { 2 * mat }
            + if self.hardened.is_empty() {
                0
            } else {
                std::mem::size_of::<D::Sym>() + std::mem::size_of::<Hardened>()
            }
    }

    /// Allocates the plastic columns (zero plastic strain, no hardening yet).
    pub fn make_plastic(&mut self) {
        self.plastic_strain = vec![D::Sym::default(); self.len()];
        self.hardened = vec![Hardened::default(); self.len()];
    }

    /// Plastic work per unit volume of particle `p` (J/m^3; zero when no material is plastic).
    #[inline(always)]
    pub fn plastic_work(&self, p: usize) -> f64 {
        self.hardened.get(p).map_or(0.0, |h| h.work)
    }

    /// Applies `op` to every column.
    pub fn for_each_column(&mut self, op: &mut impl ColumnOp) {
        op.column(&mut self.x);
        op.column(&mut self.v);
        op.column(&mut self.x0);
        op.column(&mut self.mass);
        op.column(&mut self.volume);
        op.column(&mut self.stress);
        op.column(&mut self.grad_v);
        op.column(&mut self.material);
        op.column(&mut self.half);
        op.column(&mut self.grad_u);
        op.column(&mut self.plastic_strain);
        op.column(&mut self.hardened);
        op.column(&mut self.id);
    }

    /// Reorders every column so that new particle `k` is old particle `order[k]` (a
    /// shorter `order` drops the particles it does not name).
    pub fn permute(&mut self, order: &[u32]) {
        struct Permute<'a>(&'a [u32]);
        impl ColumnOp for Permute<'_> {
            fn column<T: Columnar>(&mut self, col: &mut Vec<T>) {
                if !col.is_empty() {
                    *col = self.0.iter().map(|&i| col[i as usize]).collect();
                }
            }
        }
        self.for_each_column(&mut Permute(order));
    }

    /// Displacement of particle `p` from its initial position (m).
    #[inline(always)]
    pub fn displacement(&self, p: usize) -> D::Vec {
        self.x[p] - self.x0[p]
    }

    /// Half-width of particle `p` (zero when the scene's shape function does not use one).
    #[inline(always)]
    pub fn half_of(&self, p: usize) -> D::Vec {
        if self.half.is_empty() {
            D::zero()
        } else {
            self.half[p]
        }
    }
}
