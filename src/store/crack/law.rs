//! Contact laws on crack faces (Guo & Nairn 3D (2006) Appendix B).

use crate::base::dim::Dim;

/// Contact law on a crack's faces (Guo & Nairn 3D (2006) Appendix B).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Law {
    /// Faces pass through each other (open crack).
    None,
    /// Touching faces move together (Eqs. 71-72).
    Stick,
    /// Touching faces cannot interpenetrate but slide freely.
    Frictionless,
    /// Coulomb friction with this coefficient: stick while |f_t| <= mu |f_n|, else slide
    /// with |f_t| = mu |f_n|.
    Coulomb(f64),
}

/// A crack's contact settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The law.
    pub law: Law,
    /// Also require the faces to approach (Eq. 70) before the displacement test (Eq. 69).
    pub approach_check: bool,
}

impl Contact {
    /// Faces with no contact law: they pass through each other (the default).
    pub const OPEN: Contact = Contact {
        law: Law::None,
        approach_check: false,
    };
}

impl Law {
    /// The momentum change of the field above the crack (the field below gets its
    /// negative, so momentum is conserved exactly) for masses `ma`, `mb`, velocities `va`,
    /// `vb` and unit normal `n` pointing into the material above. Stick moves both to their
    /// centre-of-mass velocity (Eqs. 71-72 times dt); frictionless keeps only the normal
    /// part; Coulomb caps the tangential part at mu times the normal one. Faces that are
    /// separating get no normal push (no tension across a contact) unless they stick.
    pub fn momentum_change<D: Dim>(
        self,
        ma: f64,
        va: D::Vec,
        mb: f64,
        vb: D::Vec,
        n: D::Vec,
    ) -> D::Vec {
        let vcm = (va * ma + vb * mb) * (1.0 / (ma + mb));
        let stick = (vcm - va) * ma;
        let dn = D::dot(stick, n);
        let normal = n * dn;
        let tangential = stick - normal;
        match self {
            Law::None => D::zero(),
            Law::Stick => stick,
            _ if dn <= 0.0 => D::zero(),
            Law::Frictionless => normal,
            Law::Coulomb(mu) => {
                let t = D::dot(tangential, tangential).sqrt();
                if t <= mu * dn {
                    stick
                } else {
                    normal + tangential * (mu * dn / t)
                }
            }
        }
    }
}
