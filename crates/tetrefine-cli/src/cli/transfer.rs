//! `refine --transfer`: the input's fields carried over to the refined mesh
//! (point fields interpolated linearly in the input tet holding each output
//! point, cell fields copied from each tet's parent), and the vertex parent
//! map that lets a solver do the transfer itself.

use std::path::Path;
use tetrefine::io::{CellArray, PointArray, DERIVED_CELL_ARRAYS, DERIVED_POINT_ARRAYS};
use tetrefine::io::{Field, MeshMeta};
use tetrefine::{copy_cell_field, interpolate_point_field, PointParent, TetMesh};

/// The input's fields on the output mesh (compacted: point `i` and tet `i`
/// are the `i`-th of the output).
pub fn transfer_fields(
    input: &TetMesh,
    mesh: &TetMesh,
    meta: &MeshMeta,
    locations: &[PointParent],
) -> (Vec<Field>, Vec<Field>) {
    let points = meta
        .point_fields
        .iter()
        .map(|f| Field {
            name: f.name.clone(),
            components: f.components,
            values: interpolate_point_field(input.tet_slots(), locations, &f.values, f.components),
        })
        .collect();
    let parents: Vec<u32> = mesh.tet_ids().map(|t| mesh.parent(t)).collect();
    let cells = meta
        .cell_fields
        .iter()
        .map(|f| Field {
            name: f.name.clone(),
            components: f.components,
            values: copy_cell_field(&parents, &f.values, f.components),
        })
        .collect();
    (points, cells)
}

/// A field name for the `.vtu`: one the writer or the vertex parent map
/// uses gets `_input` appended.
pub(super) fn vtu_name(name: &str, taken: &[&str]) -> String {
    if taken.contains(&name) {
        format!("{name}_input")
    } else {
        name.to_string()
    }
}

/// The `.vtu` point and cell arrays: the vertex parent map (`parent_tet`,
/// `parent_vertices`, `parent_bary`, `parent_outside`) when `locations` are
/// given (`vertices(i)`: the input vertices of location `i`'s tet), and the
/// transferred fields.
pub fn vtu_arrays(
    vertices: &dyn Fn(usize) -> [u32; 4],
    locations: Option<&[PointParent]>,
    point_fields: &[Field],
    cell_fields: &[Field],
) -> (Vec<PointArray>, Vec<CellArray<'static>>) {
    let mut points = Vec::new();
    if let Some(locs) = locations {
        points.push(PointArray::Int32(
            "parent_tet".into(),
            1,
            locs.iter().map(|l| l.tet as i32).collect(),
        ));
        points.push(PointArray::Int32(
            "parent_vertices".into(),
            4,
            (0..locs.len())
                .flat_map(|i| vertices(i).map(|v| v as i32))
                .collect(),
        ));
        points.push(PointArray::Float64(
            "parent_bary".into(),
            4,
            locs.iter().flat_map(|l| l.bary).collect(),
        ));
        points.push(PointArray::Int32(
            "parent_outside".into(),
            1,
            locs.iter().map(|l| i32::from(l.outside)).collect(),
        ));
    }
    for f in point_fields {
        points.push(PointArray::Float64(
            vtu_name(&f.name, &DERIVED_POINT_ARRAYS),
            f.components,
            f.values.clone(),
        ));
    }
    let cells = cell_fields
        .iter()
        .map(|f| {
            CellArray::Float64Components(
                vtu_name(&f.name, &DERIVED_CELL_ARRAYS),
                f.components,
                f.values.clone(),
            )
        })
        .collect();
    (points, cells)
}

/// Writes the `--parent-map` file: per output tet its parent, then per
/// output point its input tet, that tet's vertices (`vertices(i)` for
/// location `i`) and the barycentric coordinates (all ids 0-based).
pub fn write_parent_map(
    path: &Path,
    vertices: &dyn Fn(usize) -> [u32; 4],
    mesh: &TetMesh,
    locations: &[PointParent],
) -> super::CliResult {
    let ids: Vec<u32> = mesh.tet_ids().collect();
    tetrefine::io::write_atomic(path, |w| {
        use std::io::Write;
        writeln!(
            w,
            "# new_tet parent_tet (0-based; parent = input tet holding the centroid)"
        )?;
        for (i, &t) in ids.iter().enumerate() {
            writeln!(w, "{i} {}", mesh.parent(t))?;
        }
        writeln!(
            w,
            "# points: new_point input_tet v0 v1 v2 v3 b0 b1 b2 b3 outside (0-based; v = the input tet's vertices, b = the point's barycentric coordinates for them; outside = 1: the point lies outside the input domain and b give the nearest input boundary point)"
        )?;
        for (i, l) in locations.iter().enumerate() {
            let v = vertices(i);
            writeln!(
                w,
                "{i} {} {} {} {} {} {:?} {:?} {:?} {:?} {}",
                l.tet,
                v[0],
                v[1],
                v[2],
                v[3],
                l.bary[0],
                l.bary[1],
                l.bary[2],
                l.bary[3],
                u8::from(l.outside)
            )?;
        }
        Ok(())
    })
    .map_err(|e| e.to_string())
}
