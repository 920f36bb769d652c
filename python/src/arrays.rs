//! numpy arrays in: any integer dtype for ids, float32/float64 for points,
//! any strides; one pass that checks shape and range and copies into the
//! plain vectors the core builds from (the one copy in).

use numpy::{PyArray2, PyArrayDescrMethods, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// `obj` as a numpy array (without a copy when it already is one).
fn as_ndarray<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(a) = obj.cast::<PyUntypedArray>() {
        return Ok(a.clone());
    }
    let np = obj.py().import("numpy")?;
    let a = np.getattr("asarray")?.call1((obj,))?;
    Ok(a.cast_into::<PyUntypedArray>()?)
}

fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The array as `(n, k)`: a 2-D array with `k` columns, or for `k == 1` a
/// 1-D array (viewed as a column, no copy). An empty array of any shape with
/// no elements is `(0, k)`.
fn as_columns<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    k: usize,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    let a = as_ndarray(obj)?;
    let shape = a.shape().to_vec();
    let ok = match shape.as_slice() {
        [_, c] => *c == k,
        [_] => k == 1,
        _ => false,
    };
    let empty = shape.iter().product::<usize>() == 0;
    if !ok && !empty {
        let want = if k == 1 {
            "(n,)".to_string()
        } else {
            format!("(n, {k})")
        };
        return Err(PyValueError::new_err(format!(
            "{name} must have shape {want}, got {}",
            shape_text(&shape)
        )));
    }
    let cols = a.call_method1("reshape", ((-1i64, k as i64),))?;
    Ok(cols.cast_into::<PyUntypedArray>()?)
}

fn rows_of<T, U, const K: usize>(
    arr: &Bound<'_, PyArray2<T>>,
    name: &str,
    conv: &dyn Fn(i128) -> Option<U>,
    range: &str,
) -> PyResult<Vec<[U; K]>>
where
    T: numpy::Element + Copy + Into<i128>,
    U: Copy + Default,
{
    let ro = arr.readonly();
    let view = ro.as_array();
    let mut out = Vec::with_capacity(view.nrows());
    for (r, row) in view.rows().into_iter().enumerate() {
        let mut v = [U::default(); K];
        for (c, x) in row.iter().enumerate() {
            let x: i128 = (*x).into();
            v[c] = conv(x).ok_or_else(|| {
                let at = if K == 1 {
                    format!("{name}[{r}]")
                } else {
                    format!("{name}[{r}, {c}]")
                };
                PyValueError::new_err(format!("{at} is {x}: {range}"))
            })?;
        }
        out.push(v);
    }
    Ok(out)
}

/// Rows of `k = K` integers of any dtype, each converted by `conv` (which
/// refuses out-of-range values; `range` says what is allowed).
pub fn int_rows<U: Copy + Default, const K: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    conv: &dyn Fn(i128) -> Option<U>,
    range: &str,
) -> PyResult<Vec<[U; K]>> {
    let a = as_columns(obj, name, K)?;
    macro_rules! try_dtype {
        ($($t:ty),*) => {
            $(if let Ok(x) = a.cast::<PyArray2<$t>>() {
                return rows_of::<$t, U, K>(x, name, conv, range);
            })*
        };
    }
    try_dtype!(i64, i32, u32, u64, i16, u16, i8, u8);
    let dt = a.dtype();
    if a.len() == 0 {
        // An empty float or object array (e.g. `[]`) holds no bad id.
        return Ok(Vec::new());
    }
    Err(PyTypeError::new_err(format!(
        "{name} must hold integers, got dtype {}",
        dt.str()?
    )))
}

/// Point ids: 0 ≤ id < 2³² − 1 (the core's ids are `u32`; `u32::MAX` marks
/// "none"). Ids beyond the points are left to the core's own check.
pub fn ids<const K: usize>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[u32; K]>> {
    int_rows::<u32, K>(
        obj,
        name,
        &|x| u32::try_from(x).ok().filter(|&v| v != u32::MAX),
        "point ids are 0-based and must lie in [0, n_points)",
    )
}

/// 32-bit signed labels (regions, markers).
pub fn labels(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<i32>> {
    Ok(int_rows::<i32, 1>(
        obj,
        name,
        &|x| i32::try_from(x).ok(),
        "labels must fit in a 32-bit signed integer",
    )?
    .into_iter()
    .map(|[x]| x)
    .collect())
}

/// Points: `(n, 3)`, float64 or float32 (other real dtypes are converted).
pub fn points(obj: &Bound<'_, PyAny>) -> PyResult<Vec<[f64; 3]>> {
    let mut a = as_columns(obj, "points", 3)?;
    let kind = a.dtype().kind();
    if !matches!(kind, b'f' | b'i' | b'u') {
        return Err(PyTypeError::new_err(format!(
            "points must hold real numbers, got dtype {}",
            a.dtype().str()?
        )));
    }
    if kind != b'f' {
        a = a
            .call_method1("astype", ("float64",))?
            .cast_into::<PyUntypedArray>()?;
    }
    fn copy<T: numpy::Element + Copy + Into<f64>>(arr: &Bound<'_, PyArray2<T>>) -> Vec<[f64; 3]> {
        let ro = arr.readonly();
        let view = ro.as_array();
        view.rows()
            .into_iter()
            .map(|r| [r[0].into(), r[1].into(), r[2].into()])
            .collect()
    }
    if let Ok(x) = a.cast::<PyArray2<f64>>() {
        return Ok(copy(x));
    }
    if let Ok(x) = a.cast::<PyArray2<f32>>() {
        return Ok(copy(x));
    }
    // float16, longdouble: through float64.
    let b = a
        .call_method1("astype", ("float64",))?
        .cast_into::<PyArray2<f64>>()?;
    Ok(copy(&b))
}

/// A 1-D array of reals as float64 (an indicator).
pub fn reals(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<f64>> {
    let a = as_ndarray(obj)?;
    if a.ndim() != 1 {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape (n_tets,), got {}",
            shape_text(a.shape())
        )));
    }
    let kind = a.dtype().kind();
    if !matches!(kind, b'f' | b'i' | b'u' | b'b') {
        return Err(PyTypeError::new_err(format!(
            "{name} must hold real numbers, got dtype {}",
            a.dtype().str()?
        )));
    }
    let b = a.call_method1("astype", ("float64",))?;
    let b = b.cast::<numpy::PyArray1<f64>>()?;
    Ok(b.readonly().as_array().iter().copied().collect())
}

/// A table of reals, `(n,)` (one component) or `(n, k)`, as float64: the
/// component count and the values row after row (a field or a size map).
pub fn table(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(usize, Vec<f64>)> {
    let a = as_ndarray(obj)?;
    let kind = a.dtype().kind();
    if !matches!(kind, b'f' | b'i' | b'u' | b'b') {
        return Err(PyTypeError::new_err(format!(
            "{name} must hold real numbers, got dtype {}",
            a.dtype().str()?
        )));
    }
    let k = match a.shape() {
        [_] => 1,
        [_, k] if *k >= 1 => *k,
        s => {
            return Err(PyValueError::new_err(format!(
                "{name} must have shape (n,) or (n, k), got {}",
                shape_text(s)
            )))
        }
    };
    let np = obj.py().import("numpy")?;
    let b = np.getattr("ascontiguousarray")?.call1((a, "float64"))?;
    let b = b.cast::<numpy::PyArrayDyn<f64>>()?;
    let values = b
        .readonly()
        .as_slice()
        .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?
        .to_vec();
    Ok((k, values))
}

/// A dict `{name: array (n,) or (n, k)}` of fields (`arg` names the
/// argument in messages), in the dict's order.
pub fn fields(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<Vec<(String, usize, Vec<f64>)>> {
    let d = obj
        .cast::<pyo3::types::PyDict>()
        .map_err(|_| PyTypeError::new_err(format!("{arg} must be a dict of name -> array")))?;
    let mut out = Vec::with_capacity(d.len());
    for (k, v) in d.iter() {
        let name: String = k
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("{arg}: field names must be strings")))?;
        let (c, values) = table(&v, &format!("{arg}[{name:?}]"))?;
        out.push((name, c, values));
    }
    Ok(out)
}
