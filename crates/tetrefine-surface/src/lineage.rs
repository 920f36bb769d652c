//! Per-face attributes that follow the faces through the subdivision steps,
//! for colouring the output in a viewer, and the observer that sees every
//! generation.
//!
//! Every face of a scheme's output carries three numbers
//! ([`FaceAttributes`]):
//!
//! * **generation**: the step that made the face (0 for an input face). A
//!   face that merely continues a face of the previous mesh keeps the
//!   generation and the group of that face: the shrunk face of vertex
//!   truncation, the F-face of Doo–Sabin and a triangle that adaptive √3
//!   left unsplit;
//! * **origin**: the index of the input face it descends from (faces made
//!   around a vertex or an edge descend from one face at that vertex or
//!   edge, named in the table below);
//! * **group**: what the scheme knows of the face, per scheme:
//!
//! | scheme | group (0 for input faces) | origin of vertex/edge faces |
//! |---|---|---|
//! | Loop | the child: 0, 1, 2 at the parent's corners 0, 1, 2; 3 the central triangle | — |
//! | Catmull–Clark | the child: the parent's corner `k` it holds | — |
//! | √3 | the child: the parent's half-edge `i` (0, 1, 2) it stands on; unsplit triangles keep theirs | — |
//! | Doo–Sabin | what the face was made as: 0 input face, 1 E-face, 2 V-face (F-faces continue their face) | the face of the edge's first half-edge; the face of the vertex's first outgoing half-edge |
//! | weighted Catmull–Clark | the face group of the weights file plus one, 0 for faces in none | — |
//! | Sierpinski | 0 corner triangle, 1 back face, 2 tube (joint) | back face: the face of the apex's first outgoing half-edge; tube: the face of the edge whose midpoint made the joint |
//! | truncation | what the face was made as: 0 input face, 1 the face cut off a vertex (shrunk faces continue their face) | the face of the vertex's first outgoing half-edge |
//!
//! For Loop, Catmull–Clark and √3 the group is the index of the map of the
//! scheme's iterated function system that made the face (the child of its
//! parent), as in [`super::ifs`].

use super::polymesh::PolyMesh;
use std::ops::ControlFlow;

/// Generation, origin face and group of every face of a mesh (see the
/// [module docs](self)); all three vectors have one entry per face.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FaceAttributes {
    /// The step that made each face (0 for input faces).
    pub generation: Vec<u32>,
    /// The input face each face descends from.
    pub origin: Vec<u32>,
    /// The scheme-specific group of each face.
    pub group: Vec<u32>,
}

impl FaceAttributes {
    /// The attributes of `faces` input faces: generation 0, origin the face
    /// itself, group 0.
    pub fn input(faces: usize) -> FaceAttributes {
        FaceAttributes {
            generation: vec![0; faces],
            origin: (0..faces as u32).collect(),
            group: vec![0; faces],
        }
    }

    /// Number of faces.
    pub fn len(&self) -> usize {
        self.generation.len()
    }

    /// True when there are no faces.
    pub fn is_empty(&self) -> bool {
        self.generation.is_empty()
    }

    /// Empty attributes with room for `n` faces.
    pub(crate) fn with_capacity(n: usize) -> FaceAttributes {
        FaceAttributes {
            generation: Vec::with_capacity(n),
            origin: Vec::with_capacity(n),
            group: Vec::with_capacity(n),
        }
    }

    /// Appends a face made in step `generation` from face `parent` of
    /// `old`, in `group`.
    #[inline]
    pub(crate) fn push_child(
        &mut self,
        old: &FaceAttributes,
        parent: u32,
        generation: u32,
        group: u32,
    ) {
        self.generation.push(generation);
        self.origin.push(old.origin[parent as usize]);
        self.group.push(group);
    }

    /// Appends a face that continues face `parent` of `old` (generation and
    /// group kept).
    #[inline]
    pub(crate) fn push_kept(&mut self, old: &FaceAttributes, parent: u32) {
        let p = parent as usize;
        self.generation.push(old.generation[p]);
        self.origin.push(old.origin[p]);
        self.group.push(old.group[p]);
    }

    /// The attributes after a step in which every face `i` is a child of
    /// `parent[i]` in group `group[i]`.
    pub(crate) fn children(&self, generation: u32, parent: &[u32], group: &[u32]) -> Self {
        let mut out = FaceAttributes::with_capacity(parent.len());
        for (&p, &g) in parent.iter().zip(group) {
            out.push_child(self, p, generation, g);
        }
        out
    }
}

/// Sees each generation of a subdivision: called with 0 and the input, then
/// with `k` and the mesh after step `k`. Returning [`ControlFlow::Break`]
/// stops the subdivision (the scheme then returns what it has).
pub type StepObserver<'a> = dyn FnMut(usize, &PolyMesh, &FaceAttributes) -> ControlFlow<()> + 'a;

/// Calls `observe` (if any) and tells whether to go on.
pub(crate) fn observe(
    observer: &mut Option<&mut StepObserver<'_>>,
    generation: usize,
    mesh: &PolyMesh,
    attributes: &FaceAttributes,
) -> bool {
    match observer {
        Some(o) => o(generation, mesh, attributes).is_continue(),
        None => true,
    }
}

/// A subdivided mesh with the attributes of its faces.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Subdivided {
    /// The mesh after the last step done.
    pub mesh: PolyMesh,
    /// Generation, origin and group of each of its faces.
    pub attributes: FaceAttributes,
    /// The steps done (fewer than asked when the observer stopped them).
    pub steps: usize,
}
