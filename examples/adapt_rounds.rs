//! Development probe: three adaptive rounds (distance indicator, fraction 0.1)
//! and where the worst tet of each round is.
use std::path::Path;
use tetrefine::refine::marking::{select, MarkStrategy};
use tetrefine::refine::{refine_step, RefineOptions};
fn main() {
    let mut m = tetrefine::io::load_mesh(Path::new("meshes/tripod.mesh"))
        .unwrap()
        .0;
    for round in 0..3 {
        let vals: Vec<f64> = m
            .tet_ids()
            .map(|t| {
                let p = m.tet_points(t);
                let c = (p[0] + p[1] + p[2] + p[3]) / 4.0;
                1.0 / (1.0 + c.length())
            })
            .collect();
        let st: MarkStrategy = "fraction:0.1".parse().unwrap();
        let sel = select(&st, Some(&vals), &m).unwrap();
        let opts = RefineOptions {
            selection: Some(sel),
            smooth_refined_only: true,
            ..Default::default()
        };
        let r = refine_step(&mut m, 1, &opts);
        m.compact();
        let fixed = tetrefine::smooth::fixed_vertices(&m);
        let mut q: Vec<(f64, u32)> = m
            .tet_ids()
            .map(|t| {
                (
                    tetrefine::geom::tet_quality(&m.tet_points(t)).min_dihedral_deg,
                    t,
                )
            })
            .collect();
        q.sort_by(|a, b| a.0.total_cmp(&b.0));
        println!(
            "round {round}: {} tets; refused flips {} bflips {} ; worst:",
            m.n_tets(),
            r.refused_flips,
            r.refused_boundary_flips
        );
        for &(a, t) in q.iter().take(4) {
            println!(
                "   {a:.2}° fixed {} bfaces {} level {}",
                m.tet(t).iter().filter(|&&v| fixed[v as usize]).count(),
                (0..4).filter(|&f| m.is_boundary_face(t, f)).count(),
                m.level(t)
            );
        }
        for l in 0..4u8 {
            let n = m.tet_ids().filter(|&t| m.level(t) == l).count();
            if n > 0 {
                print!(" level{l}:{n}");
            }
        }
        println!();
    }
}
