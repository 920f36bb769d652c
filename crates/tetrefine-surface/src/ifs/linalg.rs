//! Small dense linear algebra of the IFS maps: row-vector products,
//! matrix products, the restricted Frobenius norm, a 4 × 4 solve.

/// `out = w A` for a row vector `w` and row-major `m × m` `A`.
pub(super) fn row_times(w: &[f64], a: &[f64], m: usize, out: &mut [f64]) {
    out.iter_mut().for_each(|x| *x = 0.0);
    for (r, &wr) in w.iter().take(m).enumerate() {
        if wr != 0.0 {
            for (o, &x) in out.iter_mut().zip(&a[r * m..(r + 1) * m]) {
                *o += wr * x;
            }
        }
    }
}

/// `A B` for row-major `m × m` matrices.
pub(super) fn mat_mul(a: &[f64], b: &[f64], m: usize) -> Vec<f64> {
    let mut out = vec![0.0; m * m];
    for r in 0..m {
        row_times(&a[r * m..(r + 1) * m], b, m, &mut out[r * m..(r + 1) * m]);
    }
    out
}

/// Frobenius norm of `v ↦ v Π` restricted to `{Σ v = 0}`: with
/// `C = I − 11ᵀ/m` it is `‖C Π C‖_F`, and since `Π 1 = 1`,
/// `C Π C = Π − 1 · (column means of Π)`. Bounds the operator norm above.
pub(super) fn restricted_frobenius(p: &[f64], m: usize) -> f64 {
    let means: Vec<f64> = (0..m)
        .map(|c| (0..m).map(|r| p[r * m + c]).sum::<f64>() / m as f64)
        .collect();
    let mut sum = 0.0;
    for r in 0..m {
        for c in 0..m {
            let x = p[r * m + c] - means[c];
            sum += x * x;
        }
    }
    sum.sqrt()
}

/// Solve the 4 × 4 system `g y = b` by Gaussian elimination with partial
/// pivoting (a zero pivot leaves that unknown at 0).
pub(super) fn solve4(mut g: [[f64; 4]; 4], mut b: [f64; 4]) -> [f64; 4] {
    for col in 0..4 {
        let pivot = (col..4)
            .max_by(|&i, &j| g[i][col].abs().total_cmp(&g[j][col].abs()))
            .unwrap_or(col);
        g.swap(col, pivot);
        b.swap(col, pivot);
        if g[col][col] == 0.0 {
            continue;
        }
        for r in col + 1..4 {
            let f = g[r][col] / g[col][col];
            let pivot_row = g[col];
            for (x, p) in g[r][col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
            b[r] -= f * b[col];
        }
    }
    let mut y = [0.0; 4];
    for r in (0..4).rev() {
        if g[r][r] != 0.0 {
            let s: f64 = (r + 1..4).map(|c| g[r][c] * y[c]).sum();
            y[r] = (b[r] - s) / g[r][r];
        }
    }
    y
}
