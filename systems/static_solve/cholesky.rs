//! Sparse Cholesky factorizations of an assembled stiffness (faer): the symbolic analysis
//! after an approximate minimum degree ordering (Amestoy, Davis & Duff 1996) and the
//! numeric factor, shared by the direct solver and the coarse grid.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Par, Side};

/// The symbolic Cholesky factorization of the lower triangle `pattern` after an
/// approximate minimum degree ordering; `whose` names the solver in the error.
pub(super) fn analyse(
    pattern: &SymbolicSparseColMat<usize>,
    whose: &str,
) -> Result<SymbolicCholesky<usize>, String> {
    factorize_symbolic_cholesky(
        pattern.as_ref(),
        Side::Lower,
        SymmetricOrdering::Amd,
        Default::default(),
    )
    .map_err(|e| format!("{whose}'s symbolic analysis failed: {e:?}"))
}

/// The numeric Cholesky factor of K's lower triangle `values` on `pattern`, on one thread
/// (the same bits for any thread count), in `memory`; None where K is not positive
/// definite.
pub(super) fn factorize(
    symbolic: &SymbolicCholesky<usize>,
    pattern: &SymbolicSparseColMat<usize>,
    values: &[f64],
    memory: &mut MemBuffer,
) -> Option<Vec<f64>> {
    let mut factor = vec![0.0; symbolic.len_val()];
    symbolic
        .factorize_numeric_llt(
            &mut factor,
            SparseColMatRef::new(pattern.as_ref(), values),
            Side::Lower,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(memory),
            Default::default(),
        )
        .ok()?;
    Some(factor)
}
