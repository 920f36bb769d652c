use super::*;

/// An axis-aligned box as six quadrilaterals, marker = face number; the
/// face orientations are deliberately mixed.
fn add_box(plc: &mut Plc, lo: [f64; 3], hi: [f64; 3]) {
    let base = plc.points.len() as u32;
    for i in 0..8 {
        plc.points.push([
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]);
    }
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 4, 5, 1], // inward
        [2, 6, 7, 3],
        [0, 2, 6, 4], // inward
        [1, 3, 7, 5],
    ];
    for (m, q) in quads.iter().enumerate() {
        plc.facets.push(Facet {
            polygons: vec![q.iter().map(|&v| base + v).collect()],
            holes: Vec::new(),
            marker: m as i32 + 1,
        });
    }
}

fn unit_cube() -> Plc {
    let mut p = Plc::default();
    add_box(&mut p, [0.0; 3], [1.0; 3]);
    p
}

#[test]
fn cube_encloses_one() {
    let v = unit_cube().analyze().unwrap();
    assert!((v.enclosed - 1.0).abs() < 1e-14, "{v:?}");
    assert_eq!(v.cells, 1);
}

#[test]
fn cube_from_triangles_encloses_one() {
    let c = unit_cube();
    let mut tris = Vec::new();
    for f in &c.facets {
        let q = &f.polygons[0];
        tris.push(([q[0], q[1], q[2]], f.marker));
        tris.push(([q[0], q[2], q[3]], f.marker));
    }
    let t = Plc::from_triangles(c.points.clone(), &tris);
    assert!((t.enclosed_volume().unwrap() - 1.0).abs() < 1e-14);
}

#[test]
fn nested_box_is_a_second_cell_unless_a_hole_empties_it() {
    let mut p = unit_cube();
    add_box(&mut p, [0.25; 3], [0.75; 3]);
    let v = p.analyze().unwrap();
    assert_eq!(v.cells, 2);
    assert!((v.enclosed - 1.0).abs() < 1e-14, "{v:?}");
    p.holes.push([0.5; 3]);
    let v = p.analyze().unwrap();
    assert_eq!(v.hole_cells, 1);
    assert!((v.enclosed - (1.0 - 0.125)).abs() < 1e-14, "{v:?}");
    // A hole outside everything changes nothing.
    p.holes[0] = [5.0, 5.0, 5.0];
    assert!((p.enclosed_volume().unwrap() - 1.0).abs() < 1e-14);
    // A hole in the outer cell leaves the inner box.
    p.holes[0] = [0.1, 0.1, 0.1];
    assert!((p.enclosed_volume().unwrap() - 0.125).abs() < 1e-14);
}

#[test]
fn inner_wall_splits_a_box_into_two_cells() {
    // Box [0,2]x[0,1]x[0,1] as two unit cubes sharing the face x = 1.
    let mut p = Plc::default();
    for i in 0..12 {
        p.points
            .push([(i % 3) as f64, ((i / 3) % 2) as f64, (i / 6) as f64]);
    }
    let id = |x: u32, y: u32, z: u32| x + 3 * y + 6 * z;
    let mut quad = |q: [u32; 4], m: i32| {
        p.facets.push(Facet {
            polygons: vec![q.to_vec()],
            holes: vec![],
            marker: m,
        })
    };
    for x in 0..2 {
        quad(
            [id(x, 0, 0), id(x + 1, 0, 0), id(x + 1, 1, 0), id(x, 1, 0)],
            1,
        );
        quad(
            [id(x, 0, 1), id(x + 1, 0, 1), id(x + 1, 1, 1), id(x, 1, 1)],
            2,
        );
        quad(
            [id(x, 0, 0), id(x + 1, 0, 0), id(x + 1, 0, 1), id(x, 0, 1)],
            3,
        );
        quad(
            [id(x, 1, 0), id(x + 1, 1, 0), id(x + 1, 1, 1), id(x, 1, 1)],
            4,
        );
    }
    for x in 0..3 {
        quad([id(x, 0, 0), id(x, 1, 0), id(x, 1, 1), id(x, 0, 1)], 5);
    }
    let v = p.analyze().unwrap();
    assert_eq!(v.cells, 2);
    assert!((v.enclosed - 2.0).abs() < 1e-14, "{v:?}");
    p.holes.push([1.5, 0.5, 0.5]);
    assert!((p.enclosed_volume().unwrap() - 1.0).abs() < 1e-14);
}

#[test]
fn disjoint_boxes_add_up() {
    let mut p = unit_cube();
    add_box(&mut p, [2.0, 0.0, 0.0], [3.0, 2.0, 1.0]);
    assert!((p.enclosed_volume().unwrap() - 3.0).abs() < 1e-14);
}

#[test]
fn open_box_is_rejected() {
    let mut p = unit_cube();
    p.facets.pop();
    assert!(matches!(p.validate(), Err(PlcError::Open { .. })));
}

#[test]
fn duplicated_facet_is_rejected() {
    let mut p = unit_cube();
    let f = p.facets[2].clone();
    p.facets.push(f);
    assert_eq!(
        p.validate(),
        Err(PlcError::DuplicateFacet { facet: 7, other: 3 })
    );
}

#[test]
fn degenerate_inputs_are_rejected() {
    let mut p = unit_cube();
    p.points[3][1] = f64::NAN;
    assert!(matches!(
        p.validate(),
        Err(PlcError::NonFinite { point: 4, .. })
    ));

    let mut p = unit_cube();
    p.facets[1].polygons[0][2] = 99;
    assert!(matches!(
        p.validate(),
        Err(PlcError::IndexOutOfRange {
            facet: 2,
            index: 100,
            ..
        })
    ));

    let mut p = unit_cube();
    for q in &mut p.points {
        q[2] = 0.0;
    }
    assert_eq!(p.validate(), Err(PlcError::Flat { axis: 'z' }));

    // All points on the tilted plane x + y + z = 1.5.
    let mut p = unit_cube();
    for q in &mut p.points {
        q[2] = 1.5 - q[0] - q[1];
    }
    assert_eq!(p.validate(), Err(PlcError::Coplanar));

    let mut p = unit_cube();
    p.facets[0].polygons[0] = vec![0, 2, 2, 1];
    assert!(matches!(
        p.validate(),
        Err(PlcError::BadFacet { facet: 1, .. })
    ));

    let mut p = unit_cube();
    p.points[7] = [1.0, 1.0, 1.3];
    assert!(matches!(p.validate(), Err(PlcError::BadFacet { .. })));
}

#[test]
fn interpenetrating_boxes_are_rejected() {
    let mut p = unit_cube();
    add_box(&mut p, [0.5; 3], [1.5; 3]);
    let e = p.validate().unwrap_err();
    assert!(matches!(e, PlcError::Intersect { .. }), "{e}");
    // A box poking through another's face, sharing no point with it.
    let mut p = unit_cube();
    add_box(&mut p, [0.25, 0.25, 0.5], [0.75, 0.75, 1.5]);
    let e = p.validate().unwrap_err();
    assert!(matches!(e, PlcError::Intersect { .. }), "{e}");
}

#[test]
fn seeds_on_a_facet_are_rejected() {
    let mut p = unit_cube();
    p.holes.push([0.5, 0.5, 1.0]);
    assert!(matches!(p.validate(), Err(PlcError::SeedOnFacet { .. })));
}

#[test]
fn merging_coincident_points_renumbers_facets() {
    let c = unit_cube();
    let mut tris = Vec::new();
    let mut points = Vec::new();
    for f in &c.facets {
        let q = &f.polygons[0];
        for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            let b = points.len() as u32;
            points.extend(t.iter().map(|&v| c.points[v as usize]));
            tris.push(([b, b + 1, b + 2], 0));
        }
    }
    let mut p = Plc::from_triangles(points, &tris);
    assert_eq!(p.points.len(), 36);
    p.merge_coincident_points();
    assert_eq!(p.points.len(), 8);
    assert!((p.enclosed_volume().unwrap() - 1.0).abs() < 1e-14);
}

/// `plc` with one region seed at `x`.
fn seeded(mut plc: Plc, x: [f64; 3]) -> Plc {
    plc.regions = vec![Region {
        point: x,
        attribute: 7,
        max_volume: None,
    }];
    plc
}

/// Issue 21: a seed outside every region is refused by an exact test, one
/// ulp from the surface and at every scale; a seed inside is never refused.
#[test]
fn seeds_are_located_exactly() {
    let outside = |p: &Plc| matches!(p.validate(), Err(PlcError::SeedOutside { .. }));
    // The cube of the issue: a seed at z = 2 and at y = 1e308.
    assert!(outside(&seeded(unit_cube(), [0.5, 0.5, 2.0])));
    assert!(outside(&seeded(unit_cube(), [0.5, 1e308, 0.5])));
    for s in [1.0, 1e300, 1e-300, 3.0e-10] {
        // Two boxes [0, s]³ and [2s, 3s] × [0, s]²: the gap between them is
        // inside the bounding box but outside the surface.
        let mut two = Plc::default();
        add_box(&mut two, [0.0; 3], [s; 3]);
        add_box(&mut two, [2.0 * s, 0.0, 0.0], [3.0 * s, s, s]);
        let h = 0.5 * s;
        assert!(outside(&seeded(two.clone(), [1.5 * s, h, h])), "{s}");
        let up = f64::from_bits(s.to_bits() + 1);
        let down = f64::from_bits(s.to_bits() - 1);
        assert!(
            outside(&seeded(two.clone(), [up, h, h])),
            "{s}: one ulp outside"
        );
        seeded(two.clone(), [down, h, h])
            .validate()
            .unwrap_or_else(|e| panic!("{s}: one ulp inside: {e}"));
        assert!(
            matches!(
                seeded(two.clone(), [s, h, h]).validate(),
                Err(PlcError::SeedOnFacet { .. })
            ),
            "{s}: on the facet"
        );
        // A seed in the second box, and one that moves off its corner edge.
        seeded(two.clone(), [2.5 * s, h, h]).validate().unwrap();
        let edge = f64::from_bits((2.0 * s).to_bits() - 1);
        assert!(outside(&seeded(two.clone(), [edge, up, h])), "{s}");
    }
    // A unit cube and coordinates of 1e-310 (subnormal): the adaptive
    // predicate's products underflow there, the exact test does not.
    seeded(unit_cube(), [1e-310, 0.5, 0.5]).validate().unwrap();
    seeded(unit_cube(), [1e-310, 1e-310, 1e-310])
        .validate()
        .unwrap();
    assert!(outside(&seeded(unit_cube(), [-1e-310, 0.5, 0.5])));
    // Holes are located the same way: a seed in the emptied cell is refused.
    let mut nested = unit_cube();
    add_box(&mut nested, [0.25; 3], [0.75; 3]);
    nested.holes = vec![[0.5; 3]];
    assert!(matches!(
        seeded(nested.clone(), [0.5, 0.5, 0.6]).validate(),
        Err(PlcError::SeedInHole { .. })
    ));
    let below = f64::from_bits(0.25f64.to_bits() - 1);
    seeded(nested, [0.5, 0.5, below]).validate().unwrap();
}

/// `plc` as the text of a 1-based `.poly` (or `.smesh`) file with comment
/// and blank lines between its sections, and the 1-based lines on which it
/// put each hole seed and each region seed (counted here, as written).
fn seed_file_text(plc: &Plc, smesh: bool) -> (String, Vec<usize>, Vec<usize>) {
    let mut lines: Vec<String> = vec!["# a test surface".into(), String::new()];
    lines.push(format!("{} 3 0 0", plc.points.len()));
    for (i, p) in plc.points.iter().enumerate() {
        lines.push(format!("{} {:?} {:?} {:?}", i + 1, p[0], p[1], p[2]));
    }
    lines.push("# facets".into());
    lines.push(format!("{} 1", plc.facets.len()));
    for f in &plc.facets {
        let ids = |p: &Vec<u32>| {
            let v: Vec<String> = p.iter().map(|v| (v + 1).to_string()).collect();
            format!("{} {}", p.len(), v.join(" "))
        };
        if smesh {
            lines.push(format!("{} {}", ids(&f.polygons[0]), f.marker));
        } else {
            lines.push(format!("{} 0 {}", f.polygons.len(), f.marker));
            lines.extend(f.polygons.iter().map(ids));
        }
    }
    lines.push(String::new());
    lines.push("# holes".into());
    lines.push(plc.holes.len().to_string());
    let mut hole_lines = Vec::new();
    for (i, h) in plc.holes.iter().enumerate() {
        lines.push(format!("{} {:?} {:?} {:?}", i + 1, h[0], h[1], h[2]));
        hole_lines.push(lines.len());
    }
    lines.push("# regions".into());
    lines.push(plc.regions.len().to_string());
    let mut region_lines = Vec::new();
    for (i, r) in plc.regions.iter().enumerate() {
        lines.push("# the next seed".into());
        let p = r.point;
        lines.push(format!(
            "{} {:?} {:?} {:?} {}",
            i + 1,
            p[0],
            p[1],
            p[2],
            r.attribute
        ));
        region_lines.push(lines.len());
    }
    (lines.join("\n") + "\n", hole_lines, region_lines)
}

/// Issue 21: the seed errors of a `.poly`/`.smesh` file name the line of
/// the seed (outside the surface, in a hole's cell, on a facet); a PLC built
/// in code names none.
#[test]
fn seed_errors_name_the_line_of_the_seed_in_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let region = |x: [f64; 3], attribute: i32| Region {
        point: x,
        attribute,
        max_volume: None,
    };
    // A cube with a good seed and, second, one outside (z = 2).
    let mut cube = unit_cube();
    cube.regions = vec![region([0.5; 3], 1), region([0.5, 0.5, 2.0], 2)];
    for smesh in [false, true] {
        let (text, _, region_lines) = seed_file_text(&cube, smesh);
        let path = dir
            .path()
            .join(if smesh { "cube.smesh" } else { "cube.poly" });
        std::fs::write(&path, text).unwrap();
        let read = Plc::read(&path).unwrap();
        assert_eq!(read.seed_lines.regions, region_lines, "{smesh}");
        let e = read.validate().unwrap_err();
        assert_eq!(
            e,
            PlcError::SeedOutside {
                index: 2,
                coords: [0.5, 0.5, 2.0],
                line: Some(region_lines[1]),
            },
            "{smesh}"
        );
        let want = format!("region 2 (line {}) has its seed at", region_lines[1]);
        assert!(e.to_string().starts_with(&want), "{smesh}: {e}");
    }
    // Nested boxes, the inner one emptied by a hole; a region seed in it.
    let mut nested = unit_cube();
    add_box(&mut nested, [0.25; 3], [0.75; 3]);
    nested.holes = vec![[0.5; 3]];
    nested.regions = vec![region([0.1; 3], 1), region([0.5, 0.5, 0.6], 2)];
    let (text, hole_lines, region_lines) = seed_file_text(&nested, false);
    let path = dir.path().join("nested.poly");
    std::fs::write(&path, text).unwrap();
    let e = Plc::read(&path).unwrap().validate().unwrap_err();
    assert_eq!(
        e,
        PlcError::SeedInHole {
            index: 2,
            hole: 1,
            line: Some(region_lines[1]),
            hole_line: Some(hole_lines[0]),
        }
    );
    let want = format!(
        "region 2 (line {}) has its seed in the cell that hole 1 (line {}) empties",
        region_lines[1], hole_lines[0]
    );
    assert!(e.to_string().starts_with(&want), "{e}");
    // A seed on a facet (x = 1).
    let mut on = unit_cube();
    on.regions = vec![region([1.0, 0.5, 0.5], 1)];
    let (text, _, region_lines) = seed_file_text(&on, false);
    let path = dir.path().join("on.poly");
    std::fs::write(&path, text).unwrap();
    let e = Plc::read(&path).unwrap().validate().unwrap_err();
    assert!(
        matches!(e, PlcError::SeedOnFacet { what: "region", index: 1, line: Some(l), .. } if l == region_lines[0]),
        "{e:?}"
    );
    assert!(
        e.to_string().starts_with(&format!(
            "region 1 (line {}) lies on facet",
            region_lines[0]
        )),
        "{e}"
    );
    // Built in code: no line, and the message says none.
    let e = seeded(unit_cube(), [0.5, 0.5, 2.0]).validate().unwrap_err();
    assert!(
        matches!(e, PlcError::SeedOutside { line: None, .. }),
        "{e:?}"
    );
    assert!(e.to_string().starts_with("region 1 has its seed at"), "{e}");
}
