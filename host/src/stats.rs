//! The few statistics the host needs: a least-squares line and a mean
//! with its standard error.

/// Least-squares line `y = slope x + intercept`; returns `(slope, intercept)`.
///
/// Centered two-pass sums, so a large common offset in `y` or `x` costs no accuracy.
///
/// ```
/// use gyrocal_host::stats::linear_fit;
/// let (slope, intercept) = linear_fit(&[1.0, 2.0, 3.0], &[5.0, 7.0, 9.0]);
/// assert_eq!((slope, intercept), (2.0, 3.0));
/// ```
///
/// # Panics
/// If the lengths differ, there are fewer than 2 points, or all `x` are equal.
pub fn linear_fit(x: &[f64], y: &[f64]) -> (f64, f64) {
    assert_eq!(x.len(), y.len(), "linear_fit: x and y lengths differ");
    assert!(x.len() >= 2, "linear_fit: needs at least 2 points");
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for (&xi, &yi) in x.iter().zip(y) {
        let dx = xi - mx;
        sxx += dx * dx;
        sxy += dx * (yi - my);
    }
    assert!(sxx > 0.0, "linear_fit: all x are equal");
    let slope = sxy / sxx;
    (slope, my - slope * mx)
}

/// Mean of `v` and the 1-sigma uncertainty of that mean: the sample
/// standard deviation (n - 1) over sqrt(n).
///
/// ```
/// use gyrocal_host::stats::mean_and_standard_error;
/// let (mean, error) = mean_and_standard_error(&[1.0, 2.0, 3.0, 6.0]);
/// assert_eq!(mean, 3.0);
/// // Sample variance (4 + 1 + 0 + 9) / 3 = 14 / 3, over 4.
/// assert!((error - (14.0f64 / 12.0).sqrt()).abs() < 1e-15);
/// ```
pub fn mean_and_standard_error(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}
