//! Parallel scatter helpers of the bulk (data-parallel) operations
//! (`ops::bulk_split`, `ops::bulk_flip`) and of the store's own parallel
//! builds: the only `unsafe` of the core.
//!
//! A bulk operation applies one local operation to many disjoint cavities at
//! once. Each parallel task owns its cavity's slots and the one adjacency
//! entry of every untouched neighbour facing its cavity, so every element of
//! the mesh arrays has at most one writer and nobody reads what another task
//! writes; [`Disjoint`] is the raw shared access that lets rayon tasks write
//! those elements without locks. Everything a task needs to know about *other*
//! cavities (which slots their new tets take) is computed beforehand into
//! read-only tables.
//!
//! Results equal those of applying the local operation to the cavities one
//! after another in ascending order: the same slots (see
//! [`crate::mesh::TetMesh::claim_slots`]), generations and vertex → tet
//! entries ([`LastTouch`]), so a bulk phase is byte-identical for any number
//! of threads and to the sequential code it replaces.

use std::marker::PhantomData;
use std::sync::atomic::{AtomicU32, Ordering};

use rayon::prelude::*;

/// Shared write access to a mutable slice for tasks that touch disjoint
/// elements.
pub(crate) struct Disjoint<'a, T> {
    ptr: *mut T,
    len: usize,
    _borrow: PhantomData<&'a mut [T]>,
}

// SAFETY: `Disjoint` only hands out element reads and writes through `unsafe`
// methods whose contract is that no two tasks access one element (or, for
// `write_lane`, one lane) where one of them writes.
unsafe impl<T: Send> Send for Disjoint<'_, T> {}
unsafe impl<T: Send> Sync for Disjoint<'_, T> {}

impl<'a, T: Copy> Disjoint<'a, T> {
    /// Wraps `s` for the duration of its borrow.
    pub(crate) fn new(s: &'a mut [T]) -> Self {
        Disjoint {
            ptr: s.as_mut_ptr(),
            len: s.len(),
            _borrow: PhantomData,
        }
    }

    /// Reads element `i`.
    ///
    /// # Safety
    /// No other task writes element `i` while this runs.
    #[inline]
    pub(crate) unsafe fn read(&self, i: usize) -> T {
        assert!(i < self.len);
        // SAFETY: in bounds; the caller excludes concurrent writes.
        unsafe { self.ptr.add(i).read() }
    }

    /// Writes element `i`.
    ///
    /// # Safety
    /// No other task reads or writes element `i` while this runs.
    #[inline]
    pub(crate) unsafe fn write(&self, i: usize, v: T) {
        assert!(i < self.len);
        // SAFETY: in bounds; the caller excludes concurrent access.
        unsafe { self.ptr.add(i).write(v) }
    }
}

impl Disjoint<'_, [u32; 4]> {
    /// Writes lane `lane` of element `i` (one adjacency entry).
    ///
    /// # Safety
    /// No other task reads or writes that lane of element `i` while this runs.
    #[inline]
    pub(crate) unsafe fn write_lane(&self, i: usize, lane: usize, v: u32) {
        assert!(i < self.len && lane < 4);
        // SAFETY: in bounds (`[u32; 4]` is four contiguous `u32`); the caller
        // excludes concurrent access to this lane, and no reference to the
        // whole element is formed.
        unsafe { (self.ptr.add(i) as *mut u32).add(lane).write(v) }
    }
}

/// Per point: the last (highest-numbered) operation that touched it, found
/// with an atomic maximum so that any number of threads gives the same answer.
/// Sequential code leaves a point's vertex → tet entry to the last operation
/// that created a tet over it; this reproduces that.
pub(crate) struct LastTouch(Vec<AtomicU32>);

impl LastTouch {
    /// Nothing touched yet, for `n` points.
    pub(crate) fn new(n: usize) -> Self {
        LastTouch((0..n).into_par_iter().map(|_| AtomicU32::new(0)).collect())
    }

    /// Records that operation `op` touched point `x`. Visit operations in
    /// descending order (`par_iter().enumerate().rev()`) for speed.
    #[inline]
    pub(crate) fn touch(&self, x: u32, op: usize) {
        let (a, v) = (&self.0[x as usize], op as u32 + 1);
        // A plain load first: when operations are visited in descending
        // order, most points were already touched by a later one.
        if a.load(Ordering::Relaxed) < v {
            a.fetch_max(v, Ordering::Relaxed);
        }
    }

    /// The last operation that touched point `x`, or `None`.
    #[inline]
    pub(crate) fn get(&self, x: usize) -> Option<usize> {
        (self.0[x].load(Ordering::Relaxed) as usize).checked_sub(1)
    }

    /// Per point, the last operation that touched it, `none` where none
    /// did. Consumes the table and reuses its memory.
    pub(crate) fn into_last(self, none: u32) -> Vec<u32> {
        self.0
            .into_iter()
            .map(|a| a.into_inner().checked_sub(1).unwrap_or(none))
            .collect()
    }
}
