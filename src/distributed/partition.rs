//! Cutting a mesh into parts with METIS (Karypis–Kumar, multilevel k-way)
//! on its dual graph: one node per tet, one edge per interior face, node
//! weights for the work each tet will bring.

use crate::mesh::{TetMesh, NO_ADJ};

/// The part of every live tet of `mesh` (in [`TetMesh::tet_ids`] order), in
/// `0..parts`, minimising the faces cut while balancing `weight` (per tet,
/// same order). One part, or one tet, needs no METIS.
pub fn partition_dual_graph(
    mesh: &TetMesh,
    parts: u32,
    weight: &[i32],
) -> Result<Vec<u32>, String> {
    let ids: Vec<u32> = mesh.tet_ids().collect();
    if parts <= 1 || ids.len() <= 1 {
        return Ok(vec![0; ids.len()]);
    }
    if (ids.len() as u64) < u64::from(parts) {
        return Err(format!(
            "{} tetrahedra cannot fill {parts} ranks; run on fewer ranks",
            ids.len()
        ));
    }
    // Dense index of each live slot.
    let mut dense = vec![u32::MAX; mesh.n_tet_slots()];
    for (i, &t) in ids.iter().enumerate() {
        dense[t as usize] = i as u32;
    }
    let mut xadj: Vec<metis::Idx> = Vec::with_capacity(ids.len() + 1);
    let mut adjncy: Vec<metis::Idx> = Vec::with_capacity(4 * ids.len());
    xadj.push(0);
    for &t in &ids {
        for h in mesh.adj(t) {
            if h != NO_ADJ {
                adjncy.push(dense[(h >> 2) as usize] as metis::Idx);
            }
        }
        xadj.push(adjncy.len() as metis::Idx);
    }
    let mut vwgt: Vec<metis::Idx> = weight.iter().map(|&w| w.max(1) as metis::Idx).collect();
    vwgt.resize(ids.len(), 1);
    let mut part = vec![0 as metis::Idx; ids.len()];
    metis::Graph::new(1, parts as metis::Idx, &xadj, &adjncy)
        .map_err(|e| format!("METIS refused the dual graph: {e}"))?
        .set_vwgt(&vwgt)
        .part_kway(&mut part)
        .map_err(|e| format!("METIS failed: {e}"))?;
    Ok(part.into_iter().map(|p| p as u32).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_parts_of_a_cube_grid_are_balanced_and_cover_every_tet() {
        let (mesh, _) = TetMesh::from_data(&crate::cube_grid(6)).unwrap();
        let n = mesh.n_tets();
        let part = partition_dual_graph(&mesh, 2, &vec![1; n]).unwrap();
        assert_eq!(part.len(), n);
        let ones = part.iter().filter(|&&p| p == 1).count();
        // METIS's default imbalance tolerance is 3 %.
        assert!(ones.abs_diff(n / 2) <= n * 3 / 100, "{ones} of {n}");
        // The cut is far below the 2n interior-face bound: a few faces per
        // tet on a plane, not a scattering.
        let cut = mesh
            .tet_ids()
            .flat_map(|t| mesh.adj(t).map(move |h| (t, h)))
            .filter(|&(t, h)| h != NO_ADJ && part[t as usize] != part[(h >> 2) as usize])
            .count()
            / 2;
        assert!(cut < n / 4, "{cut} cut faces for {n} tets");
        assert!(partition_dual_graph(&mesh, 2 * n as u32, &[]).is_err());
    }
}
