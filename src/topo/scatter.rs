//! Parallel scatter helpers of the bulk (data-parallel) operations
//! (`ops::bulk_split`, `ops::bulk_flip`), of the store's own parallel builds
//! and reorder, and of the improvement's parallel passes: the only `unsafe`
//! of the core.
//!
//! A bulk operation applies one local operation to many disjoint cavities at
//! once. Each parallel task owns its cavity's slots and the one adjacency
//! entry of every untouched neighbour facing its cavity, so every element of
//! the mesh arrays has at most one writer and nobody reads what another task
//! writes. Everything a task needs to know about *other* cavities (which
//! slots their new tets take) is computed beforehand into read-only tables.
//!
//! The helpers here make those writes safe without trusting the callers'
//! reasoning about disjointness:
//!
//! - [`Shared`] views a `&mut` slice as a slice of atomics for the length of
//!   the borrow; every read and write is a relaxed atomic access (a plain
//!   load or store on x86-64 and AArch64), so no access pattern, however
//!   wrong, is a data race. One writer per element is what makes a result
//!   deterministic, and that stays the callers' argument; it is no longer a
//!   safety condition.
//! - [`permute_into`] scatters by a map that it checks is a permutation.
//! - [`CountingSort`] computes the prefix sums of a counting sort itself and
//!   hands each part a cursor that cannot leave the stretch its counts
//!   reserved, so each output slot has one writer by construction.
//!
//! Results equal those of applying the local operation to the cavities one
//! after another in ascending order: the same slots (see
//! [`crate::mesh::TetMesh::claim_slots`]), generations and vertex → tet
//! entries ([`LastTouch`]), so a bulk phase is byte-identical for any number
//! of threads and to the sequential code it replaces.

use std::mem::{align_of, size_of};
use std::sync::atomic::{AtomicBool, AtomicI32, AtomicU32, AtomicU64, AtomicU8, Ordering};

use rayon::prelude::*;

/// A plain value with an atomic twin of the same size and bit validity,
/// read and written whole through it with relaxed ordering.
///
/// # Safety
/// `Atom` has the size of `Self`, every bit pattern valid for one is valid
/// for the other, and `Atom` only changes through shared references by
/// atomic operations (so viewing a `&mut [Self]` as `&[Atom]` for the
/// borrow's length is sound, as `AtomicU32::from_mut_slice` would be).
pub(crate) unsafe trait Atomic: Copy {
    /// The atomic twin.
    type Atom: Sync;
    /// Relaxed load.
    fn load(a: &Self::Atom) -> Self;
    /// Relaxed store.
    fn store(a: &Self::Atom, v: Self);
}

macro_rules! atomic_scalar {
    ($t:ty, $a:ty) => {
        // SAFETY: the standard library documents `$a` as having the same
        // size and bit validity (in-memory representation) as `$t`.
        unsafe impl Atomic for $t {
            type Atom = $a;
            #[inline]
            fn load(a: &$a) -> $t {
                a.load(Ordering::Relaxed)
            }
            #[inline]
            fn store(a: &$a, v: $t) {
                a.store(v, Ordering::Relaxed)
            }
        }
    };
}
atomic_scalar!(u32, AtomicU32);
atomic_scalar!(i32, AtomicI32);
atomic_scalar!(u8, AtomicU8);
atomic_scalar!(bool, AtomicBool);

// SAFETY: `AtomicU64` has the size and bit validity of `u64`, and every
// `u64` bit pattern is a valid `f64` and back (`to_bits` / `from_bits`).
unsafe impl Atomic for f64 {
    type Atom = AtomicU64;
    #[inline]
    fn load(a: &AtomicU64) -> f64 {
        f64::from_bits(a.load(Ordering::Relaxed))
    }
    #[inline]
    fn store(a: &AtomicU64, v: f64) {
        a.store(v.to_bits(), Ordering::Relaxed)
    }
}

// SAFETY: an array of `AtomicU32` has the size and bit validity of the same
// array of `u32`, lane by lane.
unsafe impl<const N: usize> Atomic for [u32; N] {
    type Atom = [AtomicU32; N];
    #[inline]
    fn load(a: &[AtomicU32; N]) -> [u32; N] {
        a.each_ref().map(|x| x.load(Ordering::Relaxed))
    }
    #[inline]
    fn store(a: &[AtomicU32; N], v: [u32; N]) {
        for (x, v) in a.iter().zip(v) {
            x.store(v, Ordering::Relaxed);
        }
    }
}

/// Shared read and write access to a mutable slice for parallel tasks, by
/// relaxed atomic accesses (see the module documentation): safe for any
/// access pattern; deterministic where each element that is written has one
/// writer and no other task reads it.
pub(crate) struct Shared<'a, T: Atomic>(&'a [T::Atom]);

impl<'a, T: Atomic> Shared<'a, T> {
    /// Views `s` for the length of its borrow.
    pub(crate) fn new(s: &'a mut [T]) -> Self {
        // Checked at run time: `AtomicU64` is more aligned than `f64` on
        // some 32-bit targets.
        assert_eq!(size_of::<T::Atom>(), size_of::<T>());
        assert!(
            (s.as_ptr() as usize) % align_of::<T::Atom>() == 0,
            "slice aligned for its atomic view"
        );
        // SAFETY: `Atomic` guarantees equal size and bit validity, the
        // alignment is checked above, and the `&mut` borrow, held for `'a`,
        // excludes every non-atomic access to the elements meanwhile.
        Shared(unsafe { std::slice::from_raw_parts(s.as_mut_ptr().cast::<T::Atom>(), s.len()) })
    }

    /// Reads element `i`.
    #[inline]
    pub(crate) fn get(&self, i: usize) -> T {
        T::load(&self.0[i])
    }

    /// Writes element `i`.
    #[inline]
    pub(crate) fn set(&self, i: usize, v: T) {
        T::store(&self.0[i], v)
    }
}

impl<const N: usize> Shared<'_, [u32; N]> {
    /// Writes lane `lane` of element `i` (one adjacency entry) alone.
    #[inline]
    pub(crate) fn set_lane(&self, i: usize, lane: usize, v: u32) {
        self.0[i][lane].store(v, Ordering::Relaxed)
    }
}

/// The table `out` with `out[dest] = value` for every `(dest, value)` of
/// `pairs`; panics unless the `dest` are a permutation of `0..len` (as many
/// pairs as slots, every slot written; `value` must not be `u32::MAX`, the
/// mark of an unwritten slot).
pub(crate) fn permute_into<I>(len: usize, pairs: I) -> Vec<u32>
where
    I: IndexedParallelIterator<Item = (usize, u32)>,
{
    const UNSET: u32 = u32::MAX;
    assert_eq!(pairs.len(), len, "a permutation writes every slot once");
    let mut out = vec![UNSET; len];
    {
        let w = Shared::new(&mut out);
        pairs.for_each(|(dest, v)| {
            assert_ne!(v, UNSET, "permuted values are below u32::MAX");
            w.set(dest, v);
        });
    }
    // `len` writes and no slot left unset: no slot was written twice.
    assert!(
        out.par_iter().all(|&v| v != UNSET),
        "the destinations are a permutation"
    );
    out
}

/// The scatter of a counting sort done in parallel parts: part `p` holds
/// `counts[p][k]` items of key `k`, and the output lists the items key by
/// key, each key's items part by part, each part's in its own order (the
/// result of one sequential pass, for any number of parts).
///
/// The prefix sums are computed here, and each part's cursor for key `k`
/// stops after `counts[p][k]` items, so the stretches of (part, key) pairs
/// are disjoint and each output slot has one writer by construction.
pub(crate) struct CountingSort {
    /// Per part and key: the next output slot.
    next: Vec<Vec<u32>>,
    /// Per part and key: the slots left in the stretch.
    left: Vec<Vec<u32>>,
    total: usize,
}

impl CountingSort {
    /// Prefix sums of `counts` (per part, `n_keys` counts each), key-major.
    pub(crate) fn new(counts: Vec<Vec<u32>>, n_keys: usize) -> Self {
        assert!(counts.iter().all(|c| c.len() == n_keys));
        let mut next = vec![vec![0u32; n_keys]; counts.len()];
        let mut at = 0u64;
        for k in 0..n_keys {
            for (c, n) in counts.iter().zip(next.iter_mut()) {
                n[k] = u32::try_from(at).expect("a counting sort's output fits in u32");
                at += c[k] as u64;
            }
        }
        let total = u32::try_from(at).expect("a counting sort's output fits in u32") as usize;
        CountingSort {
            next,
            left: counts,
            total,
        }
    }

    /// Where the items of key `k` start in the output.
    pub(crate) fn key_start(&self, k: usize) -> usize {
        match self.next.first() {
            Some(n) if k < n.len() => n[k] as usize,
            _ => self.total,
        }
    }

    /// The output, `init` where a part put fewer items than it counted:
    /// calls `fill(item, part)` in parallel for each `item` of `parts` (one
    /// per part, in part order) with that part's [`PartFill`].
    pub(crate) fn fill<T, I, F>(self, init: T, parts: I, fill: F) -> Vec<T>
    where
        T: Atomic + Send + Sync,
        I: IndexedParallelIterator,
        F: Fn(I::Item, &mut PartFill<'_, '_, T>) + Sync,
    {
        assert_eq!(parts.len(), self.next.len(), "one item per part");
        let mut out = vec![init; self.total];
        {
            let out = Shared::new(&mut out);
            let out = &out;
            let (mut next, mut left) = (self.next, self.left);
            parts
                .zip(next.par_iter_mut().zip(left.par_iter_mut()))
                .for_each(|(item, (next, left))| {
                    fill(item, &mut PartFill { out, next, left });
                });
        }
        out
    }
}

/// One part's cursors of a [`CountingSort`].
pub(crate) struct PartFill<'s, 'a, T: Atomic> {
    out: &'s Shared<'a, T>,
    next: &'s mut [u32],
    left: &'s mut [u32],
}

impl<T: Atomic> PartFill<'_, '_, T> {
    /// Puts `v` as this part's next item of key `k`; returns its slot.
    /// Panics when the part has put all the items of `k` it counted.
    #[inline]
    pub(crate) fn put(&mut self, k: usize, v: T) -> u32 {
        assert!(
            self.left[k] > 0,
            "a part puts no more items than it counted"
        );
        self.left[k] -= 1;
        let at = self.next[k];
        self.next[k] += 1;
        self.out.set(at as usize, v);
        at
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_writes_reach_the_slice() {
        let mut v = vec![[0u32; 4]; 100];
        let mut q = vec![0.0f64; 100];
        {
            let s = Shared::new(&mut v);
            let sq = Shared::new(&mut q);
            (0..100usize).into_par_iter().for_each(|i| {
                s.set(i, [i as u32, 1, 2, 3]);
                s.set_lane(i, 2, 7);
                sq.set(i, i as f64 * 0.5);
            });
            assert_eq!(s.get(9), [9, 1, 7, 3]);
        }
        assert_eq!(v[42], [42, 1, 7, 3]);
        assert_eq!(q[3], 1.5);
    }

    #[test]
    fn permute_into_inverts_a_permutation() {
        let p = [2usize, 0, 3, 1];
        let out = permute_into(4, p.par_iter().enumerate().map(|(i, &d)| (d, i as u32)));
        assert_eq!(out, [1, 3, 0, 2]);
    }

    #[test]
    #[should_panic(expected = "permutation")]
    fn permute_into_refuses_a_repeated_slot() {
        let p = [2usize, 0, 2, 1];
        permute_into(4, p.par_iter().enumerate().map(|(i, &d)| (d, i as u32)));
    }

    #[test]
    fn counting_sort_lists_keys_then_parts() {
        // Part 0 holds keys [1, 0, 1], part 1 holds [0, 2].
        let parts: Vec<Vec<usize>> = vec![vec![1, 0, 1], vec![0, 2]];
        let counts = vec![vec![1, 2, 0], vec![1, 0, 1]];
        let sort = CountingSort::new(counts, 3);
        assert_eq!(
            (0..4).map(|k| sort.key_start(k)).collect::<Vec<_>>(),
            [0, 2, 4, 5]
        );
        let out = sort.fill(0u32, parts.par_iter().enumerate(), |(p, keys), w| {
            for (i, &k) in keys.iter().enumerate() {
                w.put(k, (10 * p + i) as u32);
            }
        });
        // key 0: part 0's item 1, part 1's item 0; key 1: part 0's 0 and 2;
        // key 2: part 1's item 1.
        assert_eq!(out, [1, 10, 0, 2, 11]);
    }

    #[test]
    #[should_panic(expected = "no more items than it counted")]
    fn counting_sort_stops_a_part_at_its_count() {
        let sort = CountingSort::new(vec![vec![1, 1]], 2);
        sort.fill(0u32, rayon::iter::once(()), |(), w| {
            w.put(0, 1);
            w.put(0, 2);
        });
    }
}
