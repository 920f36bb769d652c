//! Marking strategies checked against their definitions on hand-made data:
//! Dörfler's set reaches θ and no smaller set does (brute force over all
//! subsets), `fraction` selects exactly ⌈F·n⌉ of the largest values with ties
//! broken by tet id, `max` and `threshold` by their inequalities, and the
//! geometric selections by centroids computed here from the plain mesh data.

// Tet ids index several parallel arrays here; a range reads clearest.
#![allow(clippy::needless_range_loop)]

use crate::support::{centroid, kuhn_mesh, Rng};
use tetrefine::TetMesh;
use tetrefine::{doerfler_count, fraction_count, ranking, select, MarkStrategy};

fn parse(s: &str) -> MarkStrategy {
    s.parse()
        .unwrap_or_else(|e| panic!("'{s}' should parse: {e}"))
}

/// A row of `k` Kuhn cubes: 6k tets.
fn mesh_with_cubes(k: usize) -> TetMesh {
    kuhn_mesh(k, 1, 1).1
}

fn chosen(sel: &[bool]) -> Vec<usize> {
    sel.iter()
        .enumerate()
        .filter(|(_, &s)| s)
        .map(|(i, _)| i)
        .collect()
}

// ---------------------------------------------------------------------------
// fraction
// ---------------------------------------------------------------------------

#[test]
fn fraction_count_is_the_ceiling_of_f_times_n() {
    // F = p/q with exact integer ceilings ⌈p·n/q⌉. In floating point 0.07·n
    // lies a little above the integer for n = 100, 200, …, which a plain
    // `ceil` would round up.
    for (p, q) in [
        (1u64, 10u64),
        (3, 10),
        (1, 4),
        (1, 3),
        (2, 3),
        (7, 10),
        (1, 1),
        (1, 100),
        (7, 100),
        (57, 100),
    ] {
        let f = p as f64 / q as f64;
        for n in 1..=1000u64 {
            let want = (p * n).div_ceil(q).max(1) as usize;
            assert_eq!(fraction_count(f, n as usize), want, "F={p}/{q}, n={n}");
        }
    }
    // The tripod's 2,799 tets with F = 0.1: 279.9 → 280.
    assert_eq!(fraction_count(0.1, 2799), 280);
    assert!(std::hint::black_box(0.07) * 100.0 > 7.0);
    assert_eq!(fraction_count(0.07, 100), 7);
    assert_eq!(fraction_count(1e-9, 5), 1);
    assert_eq!(fraction_count(0.5, 0), 0);
}

#[test]
fn fraction_selects_exactly_the_top_values() {
    let mesh = mesh_with_cubes(4); // 24 tets
    let n = mesh.n_tets();
    assert_eq!(n, 24);
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for round in 0..200 {
        // Few distinct values, so that ties at the cut are common.
        let values: Vec<f64> = (0..n).map(|_| rng.below(6) as f64 * 0.5).collect();
        let f = [0.05, 0.1, 0.25, 0.3, 0.5, 0.9, 1.0][round % 7];
        let sel = select(&MarkStrategy::Fraction(f), Some(&values), &mesh).unwrap();
        let c = chosen(&sel);
        assert_eq!(c.len(), fraction_count(f, n));
        assert_eq!(c.len(), (f * n as f64 - 1e-9).ceil() as usize);
        for &a in &c {
            for b in (0..n).filter(|b| !sel[*b]) {
                // Every chosen value is at least every other; at equal values
                // the chosen tet comes first.
                assert!(values[a] >= values[b], "{values:?} {c:?}");
                if values[a] == values[b] {
                    assert!(a < b, "tie broken against tet order: {a} chosen, {b} not");
                }
            }
        }
    }
}

#[test]
fn fraction_ties_go_to_the_lower_tet_id() {
    let mesh = mesh_with_cubes(1); // 6 tets
    let values = [1.0, 3.0, 3.0, 2.0, 3.0, 0.0];
    // ⌈0.34·6⌉ = 3 → the three 3.0s; ⌈0.3·6⌉ = 2 → the 3.0s at ids 1 and 2.
    let s = select(&parse("fraction:0.34"), Some(&values), &mesh).unwrap();
    assert_eq!(chosen(&s), vec![1, 2, 4]);
    let s = select(&parse("fraction:0.3"), Some(&values), &mesh).unwrap();
    assert_eq!(chosen(&s), vec![1, 2]);
    // All equal: the first k ids.
    let flat = [7.0; 6];
    let s = select(&parse("fraction:0.5"), Some(&flat), &mesh).unwrap();
    assert_eq!(chosen(&s), vec![0, 1, 2]);
    // 0.0 and -0.0 are equal values.
    let zeros = [0.0, -0.0, 0.0, -0.0, 0.0, -0.0];
    let s = select(&parse("fraction:0.5"), Some(&zeros), &mesh).unwrap();
    assert_eq!(chosen(&s), vec![0, 1, 2]);
    assert_eq!(ranking(&values), vec![1, 2, 4, 3, 0, 5]);
}

// ---------------------------------------------------------------------------
// Dörfler
// ---------------------------------------------------------------------------

#[test]
fn doerfler_hand_made() {
    let mesh = mesh_with_cubes(1);
    // Squares 0, 9, 16, 1, 0, 4: total 30.
    let v = [0.0, 3.0, 4.0, 1.0, 0.0, 2.0];
    let take =
        |theta: f64| chosen(&select(&MarkStrategy::Doerfler(theta), Some(&v), &mesh).unwrap());
    assert_eq!(take(0.5), vec![2]); // 16 ≥ 15
    assert_eq!(take(0.54), vec![1, 2]); // 16 < 16.2 ≤ 25
    assert_eq!(take(25.0 / 30.0), vec![1, 2]); // 25 ≥ 25 exactly
    assert_eq!(take(0.9), vec![1, 2, 5]); // 29 ≥ 27
    assert_eq!(take(1.0), vec![1, 2, 3, 5]); // 30: the zeros are never needed
                                             // Nothing to reach: all zero.
    let z = [0.0; 6];
    assert!(chosen(&select(&MarkStrategy::Doerfler(1.0), Some(&z), &mesh).unwrap()).is_empty());
}

/// Sum of squares of the values in subset `mask`, exact for small integers.
fn subset_sum(values: &[f64], mask: u32) -> f64 {
    (0..values.len())
        .filter(|i| mask >> i & 1 == 1)
        .map(|i| values[i] * values[i])
        .sum()
}

#[test]
fn doerfler_set_reaches_theta_and_no_smaller_set_does() {
    let mut rng = Rng(0x00dd_b1a5_e5ee_d5e5);
    let thetas = [0.1, 0.25, 0.3, 0.5, 0.6, 2.0 / 3.0, 0.75, 0.9, 0.99, 1.0];
    for case in 0..400 {
        let n = 1 + (case % 12);
        // Small integers (squares and their sums are exact in f64), many ties
        // and zeros; now and then all multiplied by 2^±600, values whose
        // squares would overflow or underflow without scaling.
        let scale = match case % 10 {
            0 => 2f64.powi(600),
            1 => 2f64.powi(-600),
            _ => 1.0,
        };
        let values: Vec<f64> = (0..n).map(|_| rng.below(9) as f64 * scale).collect();
        let theta = thetas[case % thetas.len()];
        let k = doerfler_count(&values, theta);
        // For the brute force, compare the integers the values are multiples of.
        let ints: Vec<f64> = values.iter().map(|v| (v / scale).round()).collect();
        let total = subset_sum(&ints, (1u32 << n) - 1);
        let goal = theta * total;
        let order = ranking(&ints);
        let chosen_mask: u32 = order[..k].iter().map(|&i| 1u32 << i).sum();
        assert!(
            subset_sum(&ints, chosen_mask) >= goal,
            "{ints:?} θ={theta}: chosen set misses θ"
        );
        for mask in 0u32..(1 << n) {
            if (mask.count_ones() as usize) < k {
                assert!(
                    subset_sum(&ints, mask) < goal,
                    "{ints:?} θ={theta}: {mask:b} reaches θ with fewer than {k} tets"
                );
            }
        }
        // Through `select`, on a mesh with at least n tets: pad with zeros.
        let mesh = mesh_with_cubes(2);
        let mut padded = values.clone();
        padded.resize(mesh.n_tets(), 0.0);
        let sel = select(&MarkStrategy::Doerfler(theta), Some(&padded), &mesh).unwrap();
        let mut expect: Vec<usize> = order[..k].to_vec();
        expect.sort_unstable();
        assert_eq!(chosen(&sel), expect, "{values:?} θ={theta}");
    }
}

#[test]
fn doerfler_ties_go_to_the_lower_tet_id() {
    let mesh = mesh_with_cubes(1);
    let v = [1.0, 2.0, 1.0, 2.0, 1.0, 2.0]; // squares 1,4,1,4,1,4: total 15
    let take =
        |theta: f64| chosen(&select(&MarkStrategy::Doerfler(theta), Some(&v), &mesh).unwrap());
    assert_eq!(take(0.2), vec![1]); // 4 ≥ 3
    assert_eq!(take(0.5), vec![1, 3]); // 8 ≥ 7.5
    assert_eq!(take(0.85), vec![0, 1, 3, 5]); // 13 ≥ 12.75
}

// ---------------------------------------------------------------------------
// max, threshold
// ---------------------------------------------------------------------------

#[test]
fn max_and_threshold_follow_their_inequalities() {
    let mesh = mesh_with_cubes(4);
    let n = mesh.n_tets();
    let mut rng = Rng(77);
    for _ in 0..50 {
        let values: Vec<f64> = (0..n).map(|_| rng.next_f64() * 10.0).collect();
        let vmax = values.iter().cloned().fold(0.0, f64::max);
        for g in [0.0, 0.3, 0.5, 0.8, 1.0] {
            let sel = select(&MarkStrategy::Max(g), Some(&values), &mesh).unwrap();
            for t in 0..n {
                assert_eq!(sel[t], values[t] >= g * vmax);
            }
            if g == 1.0 {
                assert!(chosen(&sel).iter().all(|&t| values[t] == vmax));
                assert!(!chosen(&sel).is_empty());
            }
        }
        for x in [-1.0, 0.0, 2.5, 9.0, 11.0] {
            let sel = select(&MarkStrategy::Threshold(x), Some(&values), &mesh).unwrap();
            for t in 0..n {
                assert_eq!(sel[t], values[t] >= x);
            }
        }
    }
    // Hand-made: max 4, γ = 0.5 → values ≥ 2; threshold 1 → values ≥ 1.
    let mesh = mesh_with_cubes(1);
    let v = [0.0, 1.0, 2.0, 4.0, 1.5, 3.0];
    assert_eq!(
        chosen(&select(&parse("max:0.5"), Some(&v), &mesh).unwrap()),
        vec![2, 3, 5]
    );
    assert_eq!(
        chosen(&select(&parse("threshold:1"), Some(&v), &mesh).unwrap()),
        vec![1, 2, 3, 4, 5]
    );
    // All zero: γ·0 = 0 and every value is ≥ 0.
    let z = [0.0; 6];
    assert_eq!(
        chosen(&select(&parse("max:0.5"), Some(&z), &mesh).unwrap()).len(),
        6
    );
}

// ---------------------------------------------------------------------------
// geometric selections and unions
// ---------------------------------------------------------------------------

#[test]
fn region_box_and_sphere_follow_the_centroids() {
    let (d, mesh) = kuhn_mesh(4, 3, 2);
    let n = d.tets.len();
    assert_eq!(mesh.n_tets(), n);
    let sel = select(&parse("region:2,4"), None, &mesh).unwrap();
    for t in 0..n {
        assert_eq!(sel[t], d.tet_regions[t] == 2 || d.tet_regions[t] == 4);
    }
    assert_eq!(chosen(&sel).len(), 2 * 3 * 2 * 6);

    // A box from its lower to its upper corner; the closed box.
    let boxes: [[f64; 6]; 2] = [
        [0.5, 0.2, 0.0, 2.5, 2.0, 1.0],
        [1.25, 0.0, 0.0, 1.75, 3.0, 2.0],
    ];
    for b in boxes {
        let spec = format!("box:{},{},{},{},{},{}", b[0], b[1], b[2], b[3], b[4], b[5]);
        let sel = select(&parse(&spec), None, &mesh).unwrap();
        let mut count = 0;
        for t in 0..n {
            let c = centroid(&d, t);
            let inside = (0..3).all(|a| {
                let (lo, hi) = (b[a].min(b[a + 3]), b[a].max(b[a + 3]));
                lo <= c[a] && c[a] <= hi
            });
            assert_eq!(sel[t], inside, "{spec}: tet {t} at {c:?}");
            count += inside as usize;
        }
        assert!(count > 0 && count < n, "{spec}: {count} of {n}");
    }
    // Centroids of a Kuhn cube [i,i+1]³ have x in {i+1/4, i+1/2, i+3/4}: the
    // slab 1.25 ≤ x ≤ 1.75 holds all 6 tets of each cube with i = 1, closed
    // bounds included (3·2 = 6 cubes → 36 tets).
    let slab = select(&parse("box:1.25,0,0,1.75,3,2"), None, &mesh).unwrap();
    assert_eq!(chosen(&slab).len(), 36);

    for (center, r) in [
        ([2.0, 1.5, 1.0], 1.0),
        ([0.0, 0.0, 0.0], 1.3),
        ([4.0, 3.0, 2.0], 2.0),
    ] {
        let spec = format!("sphere:{},{},{},{r}", center[0], center[1], center[2]);
        let sel = select(&parse(&spec), None, &mesh).unwrap();
        for t in 0..n {
            let c = centroid(&d, t);
            let d2: f64 = (0..3).map(|a| (c[a] - center[a]).powi(2)).sum();
            assert_eq!(sel[t], d2 <= r * r, "{spec}: tet {t}");
        }
    }
}

#[test]
fn union_is_the_or_of_its_parts() {
    let (_, mesh) = kuhn_mesh(3, 2, 2);
    let n = mesh.n_tets();
    let mut rng = Rng(99);
    let values: Vec<f64> = (0..n).map(|_| rng.next_f64()).collect();
    let parts = [
        "fraction:0.1",
        "region:3",
        "sphere:0,0,0,1.2",
        "threshold:0.95",
    ];
    let each: Vec<Vec<bool>> = parts
        .iter()
        .map(|p| select(&parse(p), Some(&values), &mesh).unwrap())
        .collect();
    let u = parse(&parts.join("+"));
    assert!(matches!(&u, MarkStrategy::Union(p) if p.len() == 4));
    let sel = select(&u, Some(&values), &mesh).unwrap();
    for t in 0..n {
        assert_eq!(sel[t], each.iter().any(|s| s[t]));
    }
    let built = MarkStrategy::union(parts.iter().map(|p| parse(p)).collect());
    assert_eq!(select(&built, Some(&values), &mesh).unwrap(), sel);
}

// ---------------------------------------------------------------------------
// parsing and contract
// ---------------------------------------------------------------------------

#[test]
fn parser_reads_every_strategy_and_round_trips() {
    assert_eq!(parse("fraction:0.1"), MarkStrategy::Fraction(0.1));
    assert_eq!(parse("doerfler:0.5"), MarkStrategy::Doerfler(0.5));
    assert_eq!(parse("dorfler:0.5"), MarkStrategy::Doerfler(0.5));
    assert_eq!(parse("max:0"), MarkStrategy::Max(0.0));
    assert_eq!(parse("threshold:1e+5"), MarkStrategy::Threshold(1e5));
    assert_eq!(parse("region:1, -2"), MarkStrategy::Region(vec![1, -2]));
    assert_eq!(
        parse("threshold:1e+5+region:3"),
        MarkStrategy::Union(vec![
            MarkStrategy::Threshold(1e5),
            MarkStrategy::Region(vec![3])
        ])
    );
    for s in [
        "fraction:0.25",
        "doerfler:0.7",
        "max:0.5",
        "threshold:2.5",
        "region:1,2,3",
        "box:0,1,2,3,4,5",
        "sphere:1,2,3,0.5",
        "fraction:0.1+box:0,0,0,1,1,1+sphere:0,0,0,2",
    ] {
        let m = parse(s);
        assert_eq!(m.to_string(), s);
        assert_eq!(parse(&m.to_string()), m);
    }
    assert!(parse("fraction:0.1+region:2").needs_indicator());
    assert!(!parse("box:0,0,0,1,1,1+region:2").needs_indicator());
}

#[test]
fn parser_errors_say_what_is_needed() {
    let cases = [
        ("doerfler:0", "doerfler:θ needs θ in (0,1]"),
        ("doerfler:1.5", "doerfler:θ needs θ in (0,1]"),
        ("doerfler:x", "doerfler:θ needs θ in (0,1]"),
        ("fraction:0", "fraction:F needs F in (0,1]"),
        ("fraction:-0.2", "fraction:F needs F in (0,1]"),
        ("fraction:NaN", "fraction:F needs F in (0,1]"),
        ("max:1.1", "max:γ needs γ in [0,1]"),
        ("threshold:inf", "threshold:X needs a finite number"),
        ("region:a", "integer region ids"),
        ("box:0,0,0,1,1", "needs 6 comma-separated numbers"),
        ("box:0,0,0,1,1,nan", "not a finite number"),
        ("box:1,1,1,0,0,0", "inverted along x (x0 = 1 > x1 = 0)"),
        ("box:0,1,0,1,0,1", "inverted along y"),
        ("box:0,0,2,1,1,-2", "inverted along z"),
        ("sphere:0,0,0,0", "radius r > 0"),
        ("sphere:0,0,0", "needs 4 comma-separated numbers"),
        ("bisect:0.3", "unknown marking strategy 'bisect'"),
        ("fraction", "NAME:PARAMETERS"),
    ];
    for (s, want) in cases {
        let e = s.parse::<MarkStrategy>().unwrap_err();
        assert!(e.contains(want), "'{s}': '{e}' lacks '{want}'");
    }
}

#[test]
fn select_checks_its_indicator() {
    let mesh = mesh_with_cubes(1);
    let e = select(&parse("fraction:0.5"), None, &mesh).unwrap_err();
    assert!(e.contains("indicator"), "{e}");
    let e = select(&parse("region:1"), Some(&[1.0; 5]), &mesh).unwrap_err();
    assert!(e.contains("5 values") && e.contains("6 tets"), "{e}");
    for bad in [f64::NAN, f64::INFINITY, -1.0] {
        let mut v = [1.0; 6];
        v[4] = bad;
        let e = select(&parse("max:0.5"), Some(&v), &mesh).unwrap_err();
        assert!(e.contains("tet 4"), "{e}");
    }
}
