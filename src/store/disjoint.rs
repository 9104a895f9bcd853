//! Shared write access to a column whose entries are partitioned between threads.
//!
//! The tile schedule guarantees the partition: tiles of one colour class never share a
//! node, and every particle sits in exactly one tile, each tile handled by one thread. The
//! scatter systems use this to write grid and particle columns from several threads
//! without atomics or locks, in a fixed order.

use crate::physics::shape::Rows;
use crate::ranks::domain::Shared;
use bytemuck::Pod;
use std::marker::PhantomData;
use std::ops::{AddAssign, Mul};

/// A column borrowed for writes at indices that no two threads touch at once.
pub struct Disjoint<'a, T> {
    ptr: *mut T,
    len: usize,
    _borrow: PhantomData<&'a mut [T]>,
}

// SAFETY: entries are only reached through the unsafe accessors, whose contract requires
// that no two threads access one index at once; the column is exclusively borrowed for the
// writer's lifetime.
unsafe impl<T: Send> Sync for Disjoint<'_, T> {}
// SAFETY: as for Sync; the pointer refers to a column that outlives the writer.
unsafe impl<T: Send> Send for Disjoint<'_, T> {}

impl<'a, T: Copy> Disjoint<'a, T> {
    /// Borrows `column` for disjoint writes.
    pub fn new(column: &'a mut [T]) -> Self {
        Disjoint {
            ptr: column.as_mut_ptr(),
            len: column.len(),
            _borrow: PhantomData,
        }
    }

    /// Entry `i`.
    ///
    /// # Safety
    /// No other thread may write entry `i` during the call.
    #[inline(always)]
    pub unsafe fn get(&self, i: usize) -> T {
        assert!(i < self.len);
        // SAFETY: i is in bounds (checked above); the caller guarantees no concurrent write.
        unsafe { *self.ptr.add(i) }
    }

    /// Overwrites entry `i`.
    ///
    /// # Safety
    /// No other thread may access entry `i` during the call.
    #[inline(always)]
    pub unsafe fn set(&self, i: usize, value: T) {
        assert!(i < self.len);
        // SAFETY: i is in bounds (checked above); the caller guarantees exclusive access.
        unsafe { *self.ptr.add(i) = value };
    }

    /// Adds `value(r)[a]` to entry `rows.first[r] + a` for every row `r` of a stencil's
    /// [`Rows`] and every `a < N` (a row's nodes are consecutive entries), with one bounds
    /// check for the whole stencil: its last row ends highest (an invariant of `Rows`,
    /// which only `Stencil::rows` builds).
    ///
    /// # Safety
    /// No other thread may access the stencil's entries during the call.
    #[inline(always)]
    pub unsafe fn add_rows<const N: usize>(
        &self,
        rows: &Rows,
        mut value: impl FnMut(usize) -> [T; N],
    ) where
        T: AddAssign,
    {
        assert!(rows.end(N) <= self.len);
        for r in 0..rows.len {
            debug_assert!(r == 0 || rows.first[r] >= rows.first[r - 1] + N);
            for (a, v) in value(r).into_iter().enumerate() {
                // SAFETY: first[r] + a < first[r] + N <= end(N) <= len (checked above); the
                // caller guarantees exclusive access.
                unsafe { *self.ptr.add(rows.first[r] + a) += v };
            }
        }
    }

    /// Adds `value` times each node's weight, `(value q[r]) w_x[a]`, to the entries of a
    /// stencil of `N` nodes per axis (`w_x`: its x weights; the mass or momentum scatter), as
    /// [`add_rows`](Self::add_rows).
    ///
    /// # Safety
    /// No other thread may access the stencil's entries during the call.
    #[inline(always)]
    pub unsafe fn add_weighted<const N: usize>(&self, rows: &Rows, w_x: &[f64; 3], value: T)
    where
        T: AddAssign + Mul<f64, Output = T>,
    {
        // SAFETY: the caller's guarantee, passed on.
        unsafe {
            self.add_rows(rows, |r| {
                let vq = value * rows.q[r];
                std::array::from_fn::<_, N, _>(|a| vq * w_x[a])
            })
        }
    }
}

/// A column shared across ranks between colour classes.
impl<T: Pod + Send> Shared for Disjoint<'_, T> {
    fn pack(&self, nodes: &[u32], out: &mut Vec<u8>) {
        for &n in nodes {
            // SAFETY: called between colour classes, when no other thread writes the column.
            let v = unsafe { self.get(n as usize) };
            out.extend_from_slice(bytemuck::bytes_of(&v));
        }
    }

    fn unpack(&self, nodes: &[u32], bytes: &[u8]) -> usize {
        let size = std::mem::size_of::<T>();
        for (k, &n) in nodes.iter().enumerate() {
            let v: T = bytemuck::pod_read_unaligned(&bytes[k * size..(k + 1) * size]);
            // SAFETY: as in `pack`.
            unsafe { self.set(n as usize, v) };
        }
        nodes.len() * size
    }
}
