//! Bulk 2-3 flips: every old interior face between two split tets flipped at
//! once, in parallel — the second phase of a √3 step.
//!
//! After the 1-4 splits, each child holds exactly one old face, so the flip
//! candidates are disjoint pairs of children: no tet takes part in two flips.
//!
//! ```text
//!            q                 flip k of face (a,b,c) = face f of tet t
//!           /|\                (apex p, t's barycentre), shared with tet u
//!          / | \               (apex q):
//!         a--|--c                N0 = (a,b,p,q)  in slot u
//!          \ | /                 N1 = (b,c,p,q)  in slot t
//!           \|/                  N2 = (c,a,p,q)  in claimed slot k
//!            b   (p below)     N0|N1 meet at (b,p,q), N1|N2 at (c,p,q),
//!                              N2|N0 at (a,p,q); the outer face of t opposite
//!                              a/b/c becomes face 3 of N1/N2/N0, that of u
//!                              opposite a/b/c face 2 of N1/N2/N0
//! ```
//!
//! The outer faces of t and u are faces between siblings of one split, so a
//! neighbour across them is often flipped in the same pass. Each flip's
//! "outer face → new half-face" map depends only on its own record (slots of
//! t, u, the claimed slot, the local index of the face and where a, b, c sit
//! in u), so a task resolves a flipped neighbour from that read-only table;
//! an unflipped neighbour (refused flip, unsplit tet, constrained face) gets
//! its one facing adjacency entry rewritten by the one task that faces it.
//!
//! The result equals calling [`super::flip23`](fn@super::flip23) on the faces in order (same
//! slots, generations and vertex → tet entries). Seed paper §3.1 (Figure 5).

use crate::geom::all_positive;
use crate::mesh::{SharedSlots, TetMesh, DEAD, NO_ADJ};
use crate::topo::scatter::{LastTouch, Shared};
use crate::topo::TET_FACES;
use glam::DVec3;
use rayon::prelude::*;

const NONE: u32 = u32::MAX;

/// One flip of a batch: slots of the two old tets and of the third new tet
/// (set when the batch is applied), `f | ia << 2 | ib << 4 | ic << 6` — the
/// local index of the face in `t` and the local indices of its vertices a,
/// b, c in `u` — and whether the flip is to be done.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Flip {
    t: u32,
    u: u32,
    s: u32,
    code: u8,
    ok: bool,
}

impl Flip {
    /// The flip of face `f` of `t` (interior; `u` is across it).
    #[inline]
    fn new(tets: &[[u32; 4]], t: u32, f: usize, u: u32) -> Flip {
        let (vt, vu) = (tets[t as usize], tets[u as usize]);
        let l = TET_FACES[f];
        let mut code = f as u8;
        for (s, &i) in l.iter().enumerate() {
            let x = vt[i];
            let j = (0..4)
                .find(|&j| vu[j] == x)
                .expect("the two tets of a flip share face f, so u holds every vertex of it");
            code |= (j as u8) << (2 + 2 * s);
        }
        Flip {
            t,
            u,
            s: 0,
            code,
            ok: false,
        }
    }

    #[inline]
    fn f(self) -> usize {
        (self.code & 3) as usize
    }

    /// Local indices of a, b, c in `u`.
    #[inline]
    fn in_u(self) -> [usize; 3] {
        [2, 4, 6].map(|s| ((self.code >> s) & 3) as usize)
    }

    /// The three new tets N0, N1, N2 over the current vertices of t and u.
    #[inline]
    fn new_tets(self, vt: [u32; 4], vu: [u32; 4]) -> [[u32; 4]; 3] {
        let l = TET_FACES[self.f()];
        let [a, b, c] = [vt[l[0]], vt[l[1]], vt[l[2]]];
        let [ia, ib, ic] = self.in_u();
        let (p, q) = (vt[self.f()], vu[6 - ia - ib - ic]);
        [[a, b, p, q], [b, c, p, q], [c, a, p, q]]
    }

    /// Whether the three new tets are positive (exact predicate).
    #[inline]
    fn positive(self, tets: &[[u32; 4]], points: &[DVec3]) -> bool {
        let n = self.new_tets(tets[self.t as usize], tets[self.u as usize]);
        all_positive(n.iter().map(|v| v.map(|x| points[x as usize])))
    }

    /// The new half-face that outer face `m` (local index in `t` when `side`
    /// is 0, in `u` when 1) of the cavity becomes.
    #[inline]
    fn outer_dest(self, side: u32, m: usize) -> u32 {
        let abc = if side == 0 {
            let l = TET_FACES[self.f()];
            [l[0], l[1], l[2]]
        } else {
            self.in_u()
        };
        // Opposite a: N1 (slot t); opposite b: N2 (slot s); opposite c: N0
        // (slot u). Face 3 (opposite q) from t's side, face 2 (opposite p)
        // from u's.
        let face = 3 - side;
        if m == abc[0] {
            4 * self.t + face
        } else if m == abc[1] {
            4 * self.s + face
        } else {
            debug_assert_eq!(m, abc[2]);
            4 * self.u + face
        }
    }
}

/// The 2-3 flips of one √3 step, found and judged in one parallel pass over
/// the tets by [`FlipBatch::barycentre_faces`], applied by [`flip23_bulk`].
#[derive(Clone, Debug, Default)]
pub struct FlipBatch {
    flips: Vec<Flip>,
}

impl FlipBatch {
    /// The faces of the √3 flip phase: for each child of a split of this step
    /// (it has exactly one vertex at or above `first_barycentre`, the
    /// barycentre) the old face opposite that vertex when the tet across it
    /// is a child too and the face is not constrained
    /// ([`TetMesh::is_interface_face`]). Each face once, as `(t, f)` with `t` the
    /// lower slot, in ascending `t`; each flip is marked valid when its three
    /// new tets are positive (exact predicate, as [`super::flip23_valid`]).
    ///
    /// The batch is counted first and then filled in place, block by block,
    /// so that it is allocated once at its exact size (no collect through
    /// per-thread lists, which would hold it twice).
    pub fn barycentre_faces(mesh: &TetMesh, first_barycentre: u32) -> FlipBatch {
        const BLOCK: usize = 1 << 14;
        let first = first_barycentre;
        let (tets, points) = (&mesh.tets, &mesh.points);
        // The face of `t` to flip (local index) and the tet across it.
        let candidate = |t: u32| -> Option<(usize, u32)> {
            let v = tets[t as usize];
            if v[0] == DEAD {
                return None;
            }
            let mut bary = (0..4).filter(|&j| v[j] >= first);
            let i = bary.next()?;
            if bary.next().is_some() {
                return None;
            }
            let h = mesh.adj[t as usize][i];
            if h == NO_ADJ {
                return None;
            }
            let (u, g) = TetMesh::half_face(h);
            if u < t || tets[u as usize][g] < first || mesh.is_interface_face(t, i) {
                return None;
            }
            Some((i, u))
        };
        let n = tets.len();
        let block = |b: usize| (b * BLOCK) as u32..((b + 1) * BLOCK).min(n) as u32;
        let counts: Vec<usize> = (0..n.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| block(b).filter(|&t| candidate(t).is_some()).count())
            .collect();
        let empty = Flip {
            t: 0,
            u: 0,
            s: 0,
            code: 0,
            ok: false,
        };
        let mut flips = vec![empty; counts.iter().sum()];
        let mut parts = Vec::with_capacity(counts.len());
        let mut rest = &mut flips[..];
        for &c in &counts {
            let (part, tail) = rest.split_at_mut(c);
            parts.push(part);
            rest = tail;
        }
        parts.into_par_iter().enumerate().for_each(|(b, part)| {
            let found = block(b).filter_map(|t| candidate(t).map(|(i, u)| (t, i, u)));
            for (slot, (t, i, u)) in part.iter_mut().zip(found) {
                let mut fl = Flip::new(tets, t, i, u);
                fl.ok = fl.positive(tets, points);
                *slot = fl;
            }
        });
        FlipBatch { flips }
    }

    /// Number of faces.
    pub fn len(&self) -> usize {
        self.flips.len()
    }

    /// Whether there is no face.
    pub fn is_empty(&self) -> bool {
        self.flips.is_empty()
    }

    /// The faces `(t, f)`, in order.
    pub fn faces(&self) -> Vec<(u32, usize)> {
        self.flips.iter().map(|fl| (fl.t, fl.f())).collect()
    }

    /// Whether face `i` will be flipped.
    pub fn is_valid(&self, i: usize) -> bool {
        self.flips[i].ok
    }

    /// Number of faces that will be flipped.
    pub fn valid_count(&self) -> usize {
        self.flips.par_iter().filter(|fl| fl.ok).count()
    }

    /// The faces whose flip would not give three positive tets.
    pub fn invalid_faces(&self) -> Vec<(u32, usize)> {
        self.flips
            .par_iter()
            .filter(|fl| !fl.ok)
            .map(|fl| (fl.t, fl.f()))
            .collect()
    }

    /// Judges every flip again on the current points (after some moved).
    pub fn revalidate(&mut self, mesh: &TetMesh) {
        let (tets, points) = (&mesh.tets, &mesh.points);
        self.flips
            .par_iter_mut()
            .for_each(|fl| fl.ok = fl.positive(tets, points));
    }

    /// Refuses flip `i` (it will not be done).
    pub fn refuse(&mut self, i: usize) {
        self.flips[i].ok = false;
    }

    /// The index of the flip whose lower slot is `t`, if any (each child
    /// takes part in at most one flip; the flips are sorted by that slot).
    pub(crate) fn index_of_slot(&self, t: u32) -> Option<usize> {
        self.flips.binary_search_by_key(&t, |fl| fl.t).ok()
    }

    /// The two old tets of flip `i`: `(t, u)`, `t < u`.
    pub(crate) fn slots(&self, i: usize) -> (u32, u32) {
        (self.flips[i].t, self.flips[i].u)
    }

    /// The face `[a, b, c]` of flip `i` and its two apexes `p` (in `t`) and
    /// `q` (in `u`).
    pub(crate) fn face_and_apexes(&self, tets: &[[u32; 4]], i: usize) -> ([u32; 3], u32, u32) {
        let fl = self.flips[i];
        let [n0, n1, _] = fl.new_tets(tets[fl.t as usize], tets[fl.u as usize]);
        ([n0[0], n0[1], n1[1]], n0[2], n0[3])
    }

    /// Whether flip `i` would give three positive tets with the points
    /// `moved[j].0` at `moved[j].1` instead of where they are (exact
    /// predicate).
    pub(crate) fn positive_with(
        &self,
        tets: &[[u32; 4]],
        points: &[DVec3],
        i: usize,
        moved: &[(u32, DVec3)],
    ) -> bool {
        let fl = self.flips[i];
        let at = |x: u32| {
            moved
                .iter()
                .find(|m| m.0 == x)
                .map_or(points[x as usize], |m| m.1)
        };
        all_positive(
            fl.new_tets(tets[fl.t as usize], tets[fl.u as usize])
                .iter()
                .map(|v| v.map(at)),
        )
    }

    /// Judges flip `i` again on the current points.
    pub(crate) fn rejudge(&mut self, mesh: &TetMesh, i: usize) {
        let ok = self.flips[i].positive(&mesh.tets, &mesh.points);
        self.flips[i].ok = ok;
    }
}

/// 2-3 flips all valid faces of `batch` at once (made by
/// [`FlipBatch::barycentre_faces`] on this mesh, unchanged since but for
/// moved points and a [`FlipBatch::revalidate`]). Returns the number of
/// faces flipped.
pub fn flip23_bulk(mesh: &mut TetMesh, batch: FlipBatch) -> usize {
    let mut flips = batch.flips;
    flips.retain(|fl| fl.ok);
    let k = flips.len();
    if k == 0 {
        return 0;
    }
    let n = mesh.tets.len();
    let slots = mesh.claim_slots(k);
    // Per old slot: 2k for the t of flip k, 2k+1 for its u.
    let mut role = vec![NONE; n];
    {
        let r = Shared::new(&mut role);
        flips.par_iter_mut().enumerate().for_each(|(i, fl)| {
            fl.s = slots.get(i);
            // The pairs are disjoint, so each slot has one writer.
            r.set(fl.t as usize, 2 * i as u32);
            r.set(fl.u as usize, 2 * i as u32 + 1);
        });
    }
    let last = LastTouch::new(mesh.points.len());

    {
        let SharedSlots {
            tets,
            adj,
            generation,
            region,
            level,
            parent,
        } = mesh.shared_slots();
        let (role, flips, last) = (&role, &flips, &last);
        // Descending, so that most `LastTouch` records are no-ops.
        flips.par_iter().enumerate().rev().for_each(|(i, &fl)| {
            let (t, u, s) = (fl.t as usize, fl.u as usize, fl.s as usize);
            // This task alone reads and writes slots t, u and s (the pairs
            // are disjoint, s was claimed for this flip only); the lane it
            // writes in an unflipped neighbour faces t or u, so no other task
            // writes it, and no task reads unflipped neighbours: one writer
            // per element, a deterministic result.
            let (vt, vu) = (tets.get(t), tets.get(u));
            let (at, au) = (adj.get(t), adj.get(u));
            let l = TET_FACES[fl.f()];
            let [a, b, c] = [vt[l[0]], vt[l[1]], vt[l[2]]];
            let [ia, ib, ic] = fl.in_u();
            let p = vt[fl.f()];
            let q = vu[6 - ia - ib - ic];
            for x in [a, b, c, p, q] {
                last.touch(x, i);
            }
            // The outer half-face across local face m of t (side 0) or u
            // (side 1), which becomes `dest`.
            let outer = |side: u32, m: usize, dest: u32| {
                let h = if side == 0 { at[m] } else { au[m] };
                if h == NO_ADJ {
                    return NO_ADJ;
                }
                let (w, mw) = TetMesh::half_face(h);
                match role[w as usize] {
                    NONE => {
                        adj.set_lane(w as usize, mw, dest);
                        h
                    }
                    r => flips[(r / 2) as usize].outer_dest(r & 1, mw),
                }
            };
            let n0 = [
                4 * fl.t + 1,
                4 * fl.s,
                outer(1, ic, 4 * fl.u + 2),
                outer(0, l[2], 4 * fl.u + 3),
            ];
            let n1 = [
                4 * fl.s + 1,
                4 * fl.u,
                outer(1, ia, 4 * fl.t + 2),
                outer(0, l[0], 4 * fl.t + 3),
            ];
            let n2 = [
                4 * fl.u + 1,
                4 * fl.t,
                outer(1, ib, 4 * fl.s + 2),
                outer(0, l[1], 4 * fl.s + 3),
            ];
            // New tets take region, level and parent of the higher-level
            // old tet (t on a tie), as `replace_cavity` does.
            let o = if level.get(u) > level.get(t) { u } else { t };
            let (r, lv, pa) = (region.get(o), level.get(o), parent.get(o));
            for (slot, v, a) in [
                (u, [a, b, p, q], n0),
                (t, [b, c, p, q], n1),
                (s, [c, a, p, q], n2),
            ] {
                tets.set(slot, v);
                adj.set(slot, a);
                region.set(slot, r);
                level.set(slot, lv);
                parent.set(slot, pa);
            }
            // Slots t and u were freed and taken again.
            generation.set(t, generation.get(t).wrapping_add(2));
            generation.set(u, generation.get(u).wrapping_add(2));
        });
    }
    drop(role);

    // Vertex → tet: flip k allocated N0, N1, N2 in this order, so its last
    // tet over b is N1 (slot t) and over a, c, p, q it is N2 (slot s).
    let tets = &mesh.tets;
    mesh.v2t.par_iter_mut().enumerate().for_each(|(x, e)| {
        if let Some(i) = last.get(x) {
            let fl = flips[i];
            *e = if tets[fl.t as usize][0] == x as u32 {
                fl.t
            } else {
                fl.s
            };
        }
    });
    k
}
