//! Which particle-node pairs a crack splits between the fields of its two sides.

/// The rule by which `classify` puts a particle-node pair in the node's field for the far
/// side of a crack (scenario key `split`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Split {
    /// The line from the particle to the node crosses the crack (Guo & Nairn 2D (2004)
    /// section 2.1; 3D (2006) Appendix A).
    #[default]
    Crossing,
    /// The line crosses the crack, and the feet of the particle and of the node on the
    /// crossed element's plane both lie inside the crack. A line from a node behind the
    /// front to a particle ahead of it (or the reverse) no longer splits the pair, which
    /// under `Crossing` makes the discrete crack act longer than drawn by a part of a cell
    /// (this project's rule; docs/fracture.md has the measurements).
    Inside,
}

impl Split {
    /// The rule named `name` in a scenario, if there is one.
    pub fn named(name: &str) -> Option<Split> {
        match name {
            "crossing" => Some(Split::Crossing),
            "inside" => Some(Split::Inside),
            _ => None,
        }
    }
}
