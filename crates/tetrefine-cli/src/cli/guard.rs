//! Guards that refuse a request before it does harm: a refinement whose
//! memory would not fit (instead of the kernel's OOM killer), and
//! selections that select nothing or cannot select anything.

use tetrefine::MarkStrategy;
use tetrefine::TetMesh;

/// Peak bytes per output tet of a √3 step: the README's measured 91 bytes
/// per output tet (1.27 GB for 13,990,012 tets), rounded up.
pub const PEAK_BYTES_PER_OUTPUT_TET: u64 = 100;
/// Bytes per tet of a mesh the command keeps beside the one it refines (the
/// input, for locating parents): the store's ~50 bytes per tet (README).
pub const STORE_BYTES_PER_TET: u64 = 50;
/// Output tets per refined input tet of one √3 step (the README's cube
/// runs: 384,000 → 2,379,840 → 13,990,012 tets, ratios 6.2 and 5.9).
pub const TETS_PER_SPLIT_TET: f64 = 6.3;

/// Peak bytes per output tet of a 1:8 bisection run, its input (kept until
/// the output is built) and the written file included: `VmHWM` 103 MB for
/// the tripod bisected three times (1,433,088 output tets, 72 bytes each),
/// rounded up.
pub const BISECT_BYTES_PER_OUTPUT_TET: u64 = 100;
/// Peak bytes per tet of `improve` (reading, the store, its queues and the
/// statistics before and after): `VmHWM` 192 MB for the 1,433,088 tets of
/// the tripod bisected three times (134 bytes each), rounded up.
pub const IMPROVE_BYTES_PER_TET: u64 = 200;

/// Parses `--max-memory`: bytes, or with a suffix K, M, G, T (powers of 1024).
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (num, mult) = match t.char_indices().find(|(_, c)| c.is_ascii_alphabetic()) {
        Some((i, _)) => {
            let unit = t[i..].trim_end_matches(['B', 'b']).to_ascii_uppercase();
            let m: u64 = match unit.as_str() {
                "" => 1,
                "K" | "KI" => 1 << 10,
                "M" | "MI" => 1 << 20,
                "G" | "GI" => 1 << 30,
                "T" | "TI" => 1 << 40,
                _ => return Err(format!("--max-memory {s}: unknown unit (use K, M, G or T)")),
            };
            (&t[..i], m)
        }
        None => (t, 1),
    };
    let v: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("--max-memory {s}: not a number of bytes"))?;
    if !(v.is_finite() && v > 0.0) {
        return Err(format!("--max-memory {s}: must be a positive size"));
    }
    Ok((v * mult as f64).min(u64::MAX as f64) as u64)
}

/// `MemAvailable` of `/proc/meminfo`, in bytes, if the system tells.
pub fn mem_available() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Resident memory of this process now (`/proc/self/statm`), in bytes.
fn resident() -> u64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/statm") else {
        return 0;
    };
    let pages: u64 = s
        .split_whitespace()
        .nth(1)
        .and_then(|p| p.parse().ok())
        .unwrap_or(0);
    pages * 4096
}

/// The memory a refinement may use: `--max-memory`, else what the system
/// has available plus what this process holds already.
pub struct MemoryBudget {
    limit: Option<u64>,
    source: &'static str,
}

impl MemoryBudget {
    /// From `--max-memory` (if given) or `/proc/meminfo`.
    pub fn new(max_memory: Option<&str>) -> Result<MemoryBudget, String> {
        Ok(match max_memory {
            Some(s) => MemoryBudget {
                limit: Some(parse_bytes(s)?),
                source: "--max-memory",
            },
            None => MemoryBudget {
                limit: mem_available().map(|a| a + resident()),
                source: "MemAvailable in /proc/meminfo plus this process's resident memory",
            },
        })
    }

    /// Refuses `what` (e.g. "step 3 of bisect") when `need` bytes (`how`:
    /// how they were estimated) exceed the budget.
    pub fn check(&self, what: &str, need: f64, how: &str) -> Result<(), String> {
        let Some(limit) = self.limit else {
            return Ok(());
        };
        if need > limit as f64 {
            return Err(format!(
                "{what} would not fit in memory: {how} need about {} at the peak, but {} allows {}; ask for less, or set --max-memory",
                human(need),
                self.source,
                human(limit as f64)
            ));
        }
        Ok(())
    }

    /// Refuses `steps` bisection steps of a mesh of `tets` tets at the first
    /// step whose peak would not fit (each step has 8 times the tets).
    pub fn check_bisect(&self, steps: usize, tets: u64, first_step: usize) -> Result<(), String> {
        let mut n = tets as f64;
        for s in first_step..first_step + steps {
            let out = (8.0 * n).min(1e30);
            self.check(
                &format!("bisect step {s}"),
                out * BISECT_BYTES_PER_OUTPUT_TET as f64,
                &format!(
                    "{n:.3e} → {out:.3e} tets at {BISECT_BYTES_PER_OUTPUT_TET} bytes per output tet (measured)"
                ),
            )?;
            n = out;
        }
        Ok(())
    }

    /// Refuses `improve` of a mesh of `tets` tets whose peak would not fit.
    pub fn check_improve(&self, tets: u64) -> Result<(), String> {
        self.check(
            "improve",
            (tets * IMPROVE_BYTES_PER_TET) as f64,
            &format!("{tets} tets at {IMPROVE_BYTES_PER_TET} bytes per tet (measured)"),
        )
    }

    /// Refuses step `step` when its estimated peak exceeds the budget: a
    /// step that splits `split` of the mesh's `tets` tets ends with about
    /// `tets + (TETS_PER_SPLIT_TET − 1)·split` tets, each costing
    /// [`PEAK_BYTES_PER_OUTPUT_TET`] at the peak, beside `kept_tets` tets of
    /// meshes held besides.
    pub fn check_step(
        &self,
        step: usize,
        tets: u64,
        split: u64,
        kept_tets: u64,
    ) -> Result<(), String> {
        let Some(limit) = self.limit else {
            return Ok(());
        };
        let out = tets as f64 + (TETS_PER_SPLIT_TET - 1.0) * split as f64;
        let need =
            out * PEAK_BYTES_PER_OUTPUT_TET as f64 + (kept_tets * STORE_BYTES_PER_TET) as f64;
        if need > limit as f64 {
            return Err(format!(
                "step {step} would not fit in memory: about {:.3e} output tets need about {} at the peak ({} bytes per output tet, measured), but {} allows {}; ask for fewer steps or a smaller selection, or set --max-memory",
                out,
                human(need),
                PEAK_BYTES_PER_OUTPUT_TET,
                self.source,
                human(limit as f64)
            ));
        }
        Ok(())
    }

    /// Projects `steps` steps from a mesh of `tets` tets with `split` of them
    /// selected (each later step splits the descendants: × the step ratio),
    /// and refuses at the first step that would not fit, before any work.
    pub fn check_plan(
        &self,
        steps: usize,
        tets: u64,
        split: u64,
        kept_tets: u64,
    ) -> Result<(), String> {
        let (mut n, mut s) = (tets as f64, split as f64);
        for step in 1..=steps {
            if n > 1e18 {
                return self.check_step(step, u64::MAX / 128, 0, kept_tets);
            }
            self.check_step(step, n as u64, s as u64, kept_tets)?;
            n += (TETS_PER_SPLIT_TET - 1.0) * s;
            s *= TETS_PER_SPLIT_TET;
        }
        Ok(())
    }
}

fn human(b: f64) -> String {
    if b >= (1u64 << 30) as f64 {
        format!("{:.1} GiB", b / (1u64 << 30) as f64)
    } else {
        format!("{:.1} MiB", b / (1u64 << 20) as f64)
    }
}

/// Refuses selections that cannot select anything meaningful: a region id
/// the mesh does not have, a box of zero extent along an axis (the sphere's
/// radius is checked when it is parsed).
pub fn check_selection(strategy: &MarkStrategy, mesh: &TetMesh) -> Result<(), String> {
    match strategy {
        MarkStrategy::Union(parts) => parts.iter().try_for_each(|p| check_selection(p, mesh)),
        MarkStrategy::Region(ids) => {
            let mut have: Vec<i32> = mesh.tet_ids().map(|t| mesh.region(t)).collect();
            have.sort_unstable();
            have.dedup();
            match ids.iter().find(|i| have.binary_search(i).is_err()) {
                Some(i) => Err(format!(
                    "--mark {strategy}: the mesh has no region {i} (its regions are {})",
                    have.iter()
                        .map(|r| r.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
                None => Ok(()),
            }
        }
        MarkStrategy::Box { min, max } => {
            for (axis, name) in ["x", "y", "z"].iter().enumerate() {
                if max[axis].partial_cmp(&min[axis]) != Some(std::cmp::Ordering::Greater) {
                    return Err(format!(
                        "--mark {strategy}: the box has zero extent along {name}, so it holds no tet's centroid but by accident"
                    ));
                }
            }
            Ok(())
        }
        MarkStrategy::Sphere { radius, .. } if !(*radius > 0.0 && radius.is_finite()) => Err(
            format!("--mark {strategy}: the radius must be positive and finite"),
        ),
        _ => Ok(()),
    }
}

/// A note naming the non-manifold places of the boundary, if any: edges
/// with more than two boundary faces (two tets sharing only an edge), and
/// vertices whose boundary faces form more than one fan (two tets sharing
/// only a vertex). Such meshes are accepted (solvers can use them), but
/// boundary rules and feature detection see several surfaces meeting there.
/// Vertex numbers are 1-based, as in the mesh files.
pub fn nonmanifold_note(mesh: &TetMesh) -> Option<String> {
    use std::collections::HashMap;
    let mut faces: Vec<[u32; 3]> = Vec::new();
    for t in mesh.tet_ids() {
        for f in 0..4 {
            if mesh.is_boundary_face(t, f) {
                faces.push(mesh.face_vertices(t, f));
            }
        }
    }
    let mut edge_count: HashMap<[u32; 2], u32> = HashMap::new();
    for f in &faces {
        for (a, b) in [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])] {
            *edge_count.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    let mut bad_edges: Vec<[u32; 2]> = edge_count
        .iter()
        .filter(|(_, &n)| n > 2)
        .map(|(e, _)| *e)
        .collect();
    bad_edges.sort_unstable();
    // Fans at each vertex: union the boundary faces at v that share an edge at v.
    let mut at: HashMap<u32, Vec<usize>> = HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        for &v in f {
            at.entry(v).or_default().push(i);
        }
    }
    let mut bad_vertices: Vec<u32> = Vec::new();
    for (&v, fs) in &at {
        let mut parent: Vec<usize> = (0..fs.len()).collect();
        fn find(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        let mut by_edge: HashMap<u32, usize> = HashMap::new();
        for (k, &fi) in fs.iter().enumerate() {
            for &w in faces[fi].iter().filter(|&&w| w != v) {
                if edge_count.get(&[v.min(w), v.max(w)]).copied().unwrap_or(0) > 2 {
                    continue; // counted as an edge already
                }
                match by_edge.get(&w) {
                    Some(&j) => {
                        let (a, b) = (find(&mut parent, k), find(&mut parent, j));
                        parent[a.max(b)] = a.min(b);
                    }
                    None => {
                        by_edge.insert(w, k);
                    }
                }
            }
        }
        let fans = (0..fs.len()).filter(|&k| find(&mut parent, k) == k).count();
        let on_bad_edge = bad_edges.iter().any(|e| e.contains(&v));
        if fans > 1 && !on_bad_edge {
            bad_vertices.push(v);
        }
    }
    bad_vertices.sort_unstable();
    if bad_edges.is_empty() && bad_vertices.is_empty() {
        return None;
    }
    let mut parts = Vec::new();
    if let Some(e) = bad_edges.first() {
        parts.push(format!(
            "{} boundary edges where more than two boundary faces meet (the first joins vertices {} and {})",
            bad_edges.len(),
            e[0] + 1,
            e[1] + 1
        ));
    }
    if let Some(v) = bad_vertices.first() {
        parts.push(format!(
            "{} boundary vertices where separate parts of the boundary touch (the first is vertex {})",
            bad_vertices.len(),
            v + 1
        ));
    }
    Some(format!(
        "the boundary is not a manifold: {}; accepted as is",
        parts.join(", and ")
    ))
}

/// Refuses a subdivided surface with coincident points or zero-area faces
/// (a `--neck` or `--cut` so small, or so many steps, that the new points
/// round onto old ones): no solver or viewer wants such a file.
pub fn check_surface_output(mesh: &tetrefine_surface::PolyMesh, what: &str) -> Result<(), String> {
    use std::collections::HashMap;
    let mut used = vec![false; mesh.points.len()];
    for f in &mesh.faces {
        for &v in f {
            if let Some(u) = used.get_mut(v as usize) {
                *u = true;
            }
        }
    }
    let mut seen: HashMap<[u64; 3], usize> = HashMap::new();
    for (i, p) in mesh.points.iter().enumerate().filter(|(i, _)| used[*i]) {
        let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
        if let Some(j) = seen.insert(key, i) {
            return Err(format!(
                "{what}: the result has coincident points (vertices {} and {} at {:?}); use a larger --neck/--cut or fewer steps",
                j + 1,
                i + 1,
                p.to_array()
            ));
        }
    }
    for (k, f) in mesh.faces.iter().enumerate() {
        let pts: Vec<glam::DVec3> = f.iter().map(|&v| mesh.points[v as usize]).collect();
        let mut n = glam::DVec3::ZERO;
        for i in 0..pts.len() {
            n += pts[i].cross(pts[(i + 1) % pts.len()]);
        }
        if n.length().partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(format!(
                "{what}: face {} of the result has zero area; use a larger --neck/--cut or fewer steps",
                k + 1
            ));
        }
    }
    Ok(())
}
