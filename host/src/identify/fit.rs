//! The fits of identification: the narrow-band form of the coarse search,
//! the exact form over a whole scan, and the Gauss-Newton fit of the fine
//! sweep (module header of `super`).

use super::{C64, Estimate, ModeFit};
use crate::stats::mean_and_standard_error;
use crate::theory::hold_gain;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::TAU;

/// The narrow-band solution: 1 / (Y f) = a + b (f - f0), so that
/// D = -b / 2, fk = f0 + Re(a / D) / 2, bk = Im(a / D), peak |Y| = 1 / (|D| fk bk).
/// Returns (fk, bk, peak) from two or more points.
pub(super) fn narrow_band(points: &[(f64, C64)]) -> Option<(f64, f64, f64)> {
    let f0 = points.iter().map(|p| p.0).sum::<f64>() / points.len() as f64;
    // Complex least squares of v = a + b u.
    let n = points.len() as f64;
    let u: Vec<f64> = points.iter().map(|p| p.0 - f0).collect();
    let v: Vec<C64> = points.iter().map(|p| 1.0 / (p.1 * p.0)).collect();
    let mu = u.iter().sum::<f64>() / n;
    let mv = v.iter().sum::<C64>() / n;
    let suu: f64 = u.iter().map(|x| (x - mu) * (x - mu)).sum();
    if suu <= 0.0 {
        return None;
    }
    let suv: C64 = u.iter().zip(&v).map(|(x, y)| (y - mv) * (x - mu)).sum();
    let b = suv / suu;
    let a = mv - b * mu;
    let d = -b / 2.0;
    let r = a / d;
    let fk = f0 + r.re / 2.0;
    let bk = r.im;
    let peak = 1.0 / (d.norm() * fk * bk.abs());
    (fk.is_finite() && bk.is_finite() && bk > 0.0).then_some((fk, bk, peak))
}

/// DAC images each side of the carrier in the fine fit's model
/// (`crate::images`): they fall as 1 / j^3 against the first, so 32 leave
/// 5e-4 of it; the first is at most 1e-3 of the resonant response over
/// the supported span (clock at least 2.6 carriers, Q at least 100).
pub(super) const FIT_IMAGES: i32 = 32;

/// No other mode's pull (`fit_mode`).
pub(crate) fn no_pull(_: f64) -> C64 {
    C64::new(0.0, 0.0)
}

/// The front end's response across a sweep, relative to its value at the
/// mode, to first order: (1 + a (f - fk)) e^(-j 2 pi tau (f - fk)), a
/// gain slope a (per Hz) and a group delay tau (s). A front end that lags
/// the carrier by phi has a slope of that order: the pick-off of
/// `frontend::PickoffPhase` (x cos phi - v sin phi / w) a group delay
/// sin(phi) cos(phi) / w and a gain slope sin(phi)^2 / f, a first-order
/// low-pass the same delay and the opposite slope, a pure delay phi / w
/// and none. To the fit of a mode alone, a phase sloping across a
/// Lorentzian is a constant background in quadrature with C (as the
/// hold's gain slope is one in phase) that narrows or widens the
/// resonance: with 1 and 2 deg of pick-off lag, Q came out higher by
/// 0.86 phi (absolute, phi in radians) on every device of
/// `tests/field_coverage.rs`, from Q 100 to 1e4, and the misfit
/// it left inflated the residuals' and the jackknife's sigmas of fk
/// twofold. The delay is measured (the line through the two modes'
/// phases, `super::loop_phase`) and put in the model
/// (`super::FrontEnd`); the gain slope cannot be measured (each mode has
/// its own channel gains) and is bounded instead.
///
/// Across the sweep the two forms below agree; at the DAC's images, some
/// clocks away, they part, and what a front end does there is not known
/// (a pick-off's gain grows with frequency, a low-pass's falls, a delay's
/// stays): the unit-magnitude turn is the model, the first-order
/// (linear) form the other end of what `super::FrontEnd::moves` counts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct FrontSlope {
    /// Group delay tau (s).
    pub delay_s: f64,
    /// Relative gain slope a (per Hz).
    pub gain_per_hz: f64,
    /// The first-order form 1 + (a - j 2 pi tau)(f - fk) instead (exact
    /// for the simulator's pick-off).
    pub linear: bool,
}

impl FrontSlope {
    /// The response h at `f` relative to the mode `fk`, and its
    /// derivative in fk.
    pub(crate) fn at(self, f: f64, fk: f64) -> (C64, C64) {
        let d = f - fk;
        if self.linear {
            let s = C64::new(self.gain_per_hz, -TAU * self.delay_s);
            return (1.0 + s * d, -s);
        }
        let turn = C64::from_polar(1.0, -TAU * self.delay_s * d);
        let gain = 1.0 + self.gain_per_hz * d;
        (
            turn * gain,
            turn * C64::new(-self.gain_per_hz, TAU * self.delay_s * gain),
        )
    }
}

/// The model's shape at carrier `f` (`fit_mode`, without C) and its
/// derivatives in fk and bk.
fn shape(
    fk: f64,
    bk: f64,
    f: f64,
    clock_hz: Option<f64>,
    pull: &dyn Fn(f64) -> C64,
    front: FrontSlope,
) -> (C64, C64, C64) {
    let images = if clock_hz.is_some() { FIT_IMAGES } else { 0 };
    let fs = clock_hz.unwrap_or(0.0);
    let hold = clock_hz.map_or(1.0, |fs| hold_gain(f, fs));
    let (mut g, mut dfk, mut dbk) = (C64::new(0.0, 0.0), C64::new(0.0, 0.0), C64::new(0.0, 0.0));
    for j in -images..=images {
        let v = f + f64::from(j) * fs;
        // The front end acts on the analog response, each image at its own
        // frequency v.
        let (h, dh) = front.at(v, fk);
        let w = hold * f / v;
        let d = C64::new((fk - v) * (fk + v), v * bk) - pull(v);
        g += h * w / d;
        dfk += (dh - h * 2.0 * fk / d) * w / d;
        dbk += -h * w * C64::new(0.0, v) / (d * d);
    }
    (g, dfk, dbk)
}

/// The fitted model's response at carrier `f` (without another mode's
/// pull), as `fit_mode` fitted it.
pub(super) fn response(m: &ModeFit, f: f64, clock_hz: f64) -> C64 {
    let (fk, q) = (m.f_hz.value, m.q.value);
    m.c * shape(fk, fk / q, f, Some(clock_hz), &no_pull, m.front).0
}

/// Gauss-Newton fit of the sampled response
/// Y = C h(f) sum_j (f / (f + j fs)) / ((fk - v)(fk + v) + j v bk), v = f + j fs,
/// h the DAC hold's gain sin(pi f / fs) / (pi f / fs) (`theory::hold_gain`;
/// its delay is what REF_PHASE's aligned value takes out),
/// from a start (fk, bk); returns the mode's estimates. The j = 0 term is
/// the mode's own response; the others are the DAC's images that the ADC
/// folds onto the carrier (`crate::images`), which at a clock a few
/// carriers fast and a broad mode shift the fitted phase and frequency by
/// several sigma if left out (a Q 960 mode at 0.38 of the clock: the loop
/// phase 0.054 deg, 4 sigma, low). The hold's gain falls across the
/// sweep (by 2e-5 over the paper device's +-1.5 bandwidths at 0.19 of
/// the clock); to a fit without it, a gain sloping across a Lorentzian is
/// a constant background whose even real part pulls fk, by -8.6e-7 bk on
/// the paper device (`the_hold_gains_slope_is_in_the_model`), a bias
/// hidden under the settling floor of fk's uncertainty
/// (`super::settling_residue`). `clock_hz` None fits the mode alone.
///
/// `pull` is the other mode's pull on this one through a coupling kappa,
/// kappa^2 G_other(v) in Hz^2 (`crate::coupling::uncouple`): the direct
/// response of coupled modes is 1 / (1 / G_k - kappa^2 G_other), and with
/// the other mode a few bandwidths away the pull changes across the sweep.
/// [`no_pull`] for a mode alone.
pub(super) fn fit_mode(
    points: &[(f64, C64)],
    fk0: f64,
    bk0: f64,
    clock_hz: Option<f64>,
    pull: &dyn Fn(f64) -> C64,
    front: FrontSlope,
) -> Result<ModeFit, FitError> {
    let shape = |fk: f64, bk: f64, f: f64| shape(fk, bk, f, clock_hz, pull, front);
    // Best C for given (fk, bk) is linear: C = sum(Y conj(g)) / sum |g|^2,
    // g the model's shape.
    let c = {
        let (mut num, mut norm) = (C64::new(0.0, 0.0), 0.0);
        for &(f, y) in points {
            let g = shape(fk0, bk0, f).0;
            num += y * g.conj();
            norm += g.norm_sqr();
        }
        num / norm
    };
    let (p, cov, rss) = gauss_newton(points, [c.re, c.im, fk0, bk0], &shape)?;
    mode_fit(points, p, &cov, rss, clock_hz, front)
}

/// Why a fit of a mode gave no estimates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub(crate) enum FitError {
    /// The normal equations had no inverse.
    #[error("singular fit")]
    Singular,
    /// The estimates left the model's domain.
    #[error("the fit diverged (no finite, positive bandwidth)")]
    Diverged,
}

/// Gauss-Newton from `p` = [Re C, Im C, fk, bk] on the model C
/// shape(fk, bk, f), at most 30 steps, until a step moves fk and bk by less
/// than 1e-9 bk: the parameters, their unscaled covariance (times the
/// residuals' variance it is theirs) and the residuals' sum of squares,
/// both taken at the end (or, should the normal equations be singular
/// there, at the last step's start).
fn gauss_newton(
    points: &[(f64, C64)],
    mut p: [f64; 4],
    shape: &impl Fn(f64, f64, f64) -> (C64, C64, C64),
) -> Result<([f64; 4], DMatrix<f64>, f64), FitError> {
    let mut last = None;
    for _ in 0..30 {
        let (j, r) = jacobian(points, &p, shape);
        let (step, cov) = scaled_solve(&j, &r).ok_or(FitError::Singular)?;
        for (v, s) in p.iter_mut().zip(step.iter()) {
            *v += s;
        }
        last = Some((cov, r.norm_squared()));
        if step[2].abs() < 1e-9 * p[3] && step[3].abs() < 1e-9 * p[3] {
            break;
        }
    }
    let (j, r) = jacobian(points, &p, shape);
    let (cov, rss) = match scaled_solve(&j, &r) {
        Some((_, cov)) => (cov, r.norm_squared()),
        None => last.ok_or(FitError::Singular)?,
    };
    Ok((p, cov, rss))
}

/// The residuals Y - C g (real and imaginary rows) at `p` and their
/// Jacobian by (Re C, Im C, fk, bk), with the sign that makes a step
/// J^+ r.
fn jacobian(
    points: &[(f64, C64)],
    p: &[f64; 4],
    shape: &impl Fn(f64, f64, f64) -> (C64, C64, C64),
) -> (DMatrix<f64>, DVector<f64>) {
    let n = points.len();
    let c = C64::new(p[0], p[1]);
    let mut j = DMatrix::<f64>::zeros(2 * n, 4);
    let mut r = DVector::<f64>::zeros(2 * n);
    for (i, &(f, y)) in points.iter().enumerate() {
        let (g, dfk, dbk) = shape(p[2], p[3], f);
        let res = y - c * g;
        r[2 * i] = res.re;
        r[2 * i + 1] = res.im;
        let cols = [g, C64::new(0.0, 1.0) * g, c * dfk, c * dbk];
        for (col, v) in cols.iter().enumerate() {
            j[(2 * i, col)] = v.re;
            j[(2 * i + 1, col)] = v.im;
        }
    }
    (j, r)
}

/// The least-squares step J^+ r and (J^T J)^-1, with J's columns scaled
/// to unit norm for the inverse (fk and C differ by orders of magnitude);
/// `None` when singular.
fn scaled_solve(j: &DMatrix<f64>, r: &DVector<f64>) -> Option<(DVector<f64>, DMatrix<f64>)> {
    let scale: Vec<f64> = (0..4).map(|c| j.column(c).norm()).collect();
    let mut js = j.clone();
    for (c, s) in scale.iter().enumerate() {
        js.column_mut(c).scale_mut(1.0 / s);
    }
    let normal = js.transpose() * &js;
    let inv = normal.try_inverse()?;
    let step = &inv * js.transpose() * r;
    let mut cov = inv;
    for a in 0..4 {
        for b in 0..4 {
            cov[(a, b)] /= scale[a] * scale[b];
        }
    }
    Some((step.component_div(&DVector::from_vec(scale)), cov))
}

/// The mode's estimates from the fit's parameters `p`, unscaled
/// covariance `cov` and residual sum of squares `rss` over `points`.
fn mode_fit(
    points: &[(f64, C64)],
    p: [f64; 4],
    cov: &DMatrix<f64>,
    rss: f64,
    clock_hz: Option<f64>,
    front: FrontSlope,
) -> Result<ModeFit, FitError> {
    let n = points.len();
    let dof = (2 * n).saturating_sub(4).max(1) as f64;
    let s2 = rss / dof;
    let sd = |a: usize| (s2 * cov[(a, a)]).sqrt();
    let (fk, bk) = (p[2], p[3]);
    if !(fk.is_finite() && bk.is_finite() && bk > 0.0) {
        return Err(FitError::Diverged);
    }
    let q = fk / bk;
    let q_sd = q * ((sd(3) / bk).powi(2) + (sd(2) / fk).powi(2)).sqrt();
    let c = C64::new(p[0], p[1]);
    // phi = -arg C; d arg / d (Cr, Ci) = (-Ci, Cr) / |C|^2.
    let g = [-p[1] / c.norm_sqr(), p[0] / c.norm_sqr()];
    let var_phi = s2
        * (g[0] * g[0] * cov[(0, 0)] + 2.0 * g[0] * g[1] * cov[(0, 1)] + g[1] * g[1] * cov[(1, 1)]);
    let peak = c.norm() / (fk * bk);
    Ok(ModeFit {
        f_hz: Estimate {
            value: fk,
            uncertainty: sd(2),
        },
        q: Estimate {
            value: q,
            uncertainty: q_sd,
        },
        phase_deg: Estimate {
            value: -c.arg().to_degrees(),
            uncertainty: var_phi.sqrt().to_degrees(),
        },
        relative_rms: (rss / n as f64).sqrt() / peak,
        waits: Default::default(),
        spur_sd: vec![],
        gain_hz2: c.norm() * clock_hz.map_or(1.0, |fs| hold_gain(fk, fs)),
        scanned: false,
        sweep: points.to_vec(),
        c,
        front,
        residual_sd: s2.sqrt(),
        probe: vec![],
        probed_delay_s: None,
    })
}

/// The fit of `m` linearized at its solution: the step each residual row
/// makes in p = [Re C, Im C, fk, bk], A = (J^T J)^-1 J^T (4 rows, a column
/// per real residual), and the hat matrix J A's diagonal (how much of a
/// row's error the fit absorbs); `None` when singular.
fn linearized(
    m: &ModeFit,
    clock_hz: Option<f64>,
    pull: &dyn Fn(f64) -> C64,
    front: FrontSlope,
) -> Option<(DMatrix<f64>, Vec<f64>)> {
    let shape = |fk: f64, bk: f64, f: f64| shape(fk, bk, f, clock_hz, pull, front);
    let (fk, bk) = (m.f_hz.value, m.f_hz.value / m.q.value);
    let (j, r) = jacobian(&m.sweep, &[m.c.re, m.c.im, fk, bk], &shape);
    let (_, cov) = scaled_solve(&j, &r)?;
    let a = cov * j.transpose();
    let hat = (0..j.nrows())
        .map(|r| (0..4).map(|p| j[(r, p)] * a[(p, r)]).sum())
        .collect();
    Some((a, hat))
}

/// The 1-sigma of (fk Hz, Q, phase deg) from independent errors of
/// variance `variance[r]` on residual row r (row 2i the real, 2i + 1 the
/// imaginary part of point i) through the step matrix `a`: cov = A
/// diag(variance) A^T, then Q = fk / bk and phi = -arg C through their
/// gradients at `m`.
fn through(m: &ModeFit, a: &DMatrix<f64>, variance: &[f64]) -> [f64; 3] {
    let (fk, bk) = (m.f_hz.value, m.f_hz.value / m.q.value);
    let c2 = m.c.norm_sqr();
    let gradients = [
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0 / bk, -fk / (bk * bk)],
        [-m.c.im / c2, m.c.re / c2, 0.0, 0.0].map(f64::to_degrees),
    ];
    gradients.map(|g| {
        let sum: f64 = (0..a.ncols())
            .map(|col| {
                let d: f64 = (0..4).map(|r| g[r] * a[(r, col)]).sum();
                d * d * variance[col]
            })
            .sum();
        sum.sqrt()
    })
}

/// The 1-sigma of (fk Hz, Q, phase deg) from the sweep's noise and its
/// points' own errors of 1-sigma `sd[i]` per real component (the table
/// core's lines, `super::spurs`), without counting the lines twice: the
/// residuals' sum of squares has the expectation sum_r (1 - h_r)
/// (sigma_n^2 + sd_r^2) over rows r (h the hat matrix's diagonal), which
/// gives the noise's variance sigma_n^2 (0 when the lines explain all of
/// it), and each row's variance sigma_n^2 + sd_r^2 goes through the fit
/// ([`through`]). With `sd` all zero it is the residuals' own sigma;
/// with the lines larger beside the carriers that pull fk most, larger
/// than it. `None` when `sd` is not one per point or the fit is singular.
pub(super) fn noise_and_lines(
    m: &ModeFit,
    sd: &[f64],
    clock_hz: Option<f64>,
    pull: &dyn Fn(f64) -> C64,
    front: FrontSlope,
) -> Option<[f64; 3]> {
    if sd.len() != m.sweep.len() {
        return None;
    }
    let (a, hat) = linearized(m, clock_hz, pull, front)?;
    let lines: Vec<f64> = sd.iter().flat_map(|s| [s * s; 2]).collect();
    let dof: f64 = hat.iter().map(|h| 1.0 - h).sum();
    let explained: f64 = hat.iter().zip(&lines).map(|(h, l)| (1.0 - h) * l).sum();
    let rss = m.residual_sd.powi(2) * dof;
    let noise = ((rss - explained) / dof).max(0.0);
    let variance: Vec<f64> = lines.iter().map(|l| noise + l).collect();
    Some(through(m, &a, &variance))
}

/// Delete-one-carrier jackknife standard errors of (fk, Q, phase): each
/// carrier of the sweep (its up and down points) left out in turn; a
/// leave-one-out fit that fails is not counted.
pub(super) fn jackknife(
    points: &[(f64, C64)],
    full: &ModeFit,
    clock_hz: Option<f64>,
    pull: &dyn Fn(f64) -> C64,
    front: FrontSlope,
) -> [f64; 3] {
    let mut carriers: Vec<f64> = points.iter().map(|p| p.0).collect();
    carriers.sort_by(f64::total_cmp);
    carriers.dedup();
    let bk = full.f_hz.value / full.q.value;
    let fits: Vec<[f64; 3]> = carriers
        .iter()
        .filter_map(|&c| {
            let kept: Vec<(f64, C64)> = points.iter().copied().filter(|p| p.0 != c).collect();
            fit_mode(&kept, full.f_hz.value, bk, clock_hz, pull, front)
                .ok()
                .map(|m| [m.f_hz.value, m.q.value, m.phase_deg.value])
        })
        .collect();
    // (g - 1) / g times the sum of squared deviations over the g fits that
    // converged, which is (g - 1) standard errors of their mean.
    let g = fits.len() as f64;
    std::array::from_fn(|i| {
        let values: Vec<f64> = fits.iter().map(|f| f[i]).collect();
        (g - 1.0) * mean_and_standard_error(&values).1
    })
}

/// The exact form over a scan, 1 / Y = (fk^2 - f^2 + j f bk) / C: a
/// quadratic in f, written in s = (f - f0) / h (f0 the scan's centre, h its
/// half-width) for conditioning, 1 / Y = Q0 + Q1 s + Q2 s^2, fitted by
/// weighted least squares (real regressors: the real and imaginary parts
/// are two fits of one design), each row weighted by |Y|^2: the noise of a
/// z average is additive, so the variance of 1 / Y is that of Y over
/// |Y|^4. The weights span many decades, so the system is solved by SVD of
/// the weighted rows, never through the squared normal equations. With r = h / f0, Q2 = -f0^2 r^2 / C,
/// Q1 = (-2 f0^2 + j f0 bk) r / C and Q0 = (fk^2 - f0^2 + j f0 bk) / C, so
/// fk^2 = f0^2 (1 - r^2 Re(Q0 / Q2)) and bk = -f0 r Im(Q1 / Q2). Returns
/// (fk, bk) when fk^2 comes out positive.
pub(super) fn scan_fit(points: &[(f64, C64)]) -> Option<(f64, f64)> {
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.0), h.max(p.0))
        });
    let (f0, h) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    let top = points.iter().map(|p| p.1.norm()).fold(0.0, f64::max);
    if !(h > 0.0 && top > 0.0) {
        return None;
    }
    let n = points.len();
    let mut x = DMatrix::<f64>::zeros(n, 3);
    let mut v = DMatrix::<f64>::zeros(n, 2);
    for (i, &(f, y)) in points.iter().enumerate() {
        let s = (f - f0) / h;
        let w = (y.norm() / top).powi(2);
        let inv = 1.0 / y;
        for (c, value) in [1.0, s, s * s].into_iter().enumerate() {
            x[(i, c)] = w * value;
        }
        v[(i, 0)] = w * inv.re;
        v[(i, 1)] = w * inv.im;
    }
    let sol = x.svd(true, true).solve(&v, 1e-14).ok()?;
    let (re, im) = (sol.column(0), sol.column(1));
    let q = |i: usize| C64::new(re[i], im[i]);
    let r = h / f0;
    let fk2 = f0 * f0 * (1.0 - r * r * (q(0) / q(2)).re);
    let bk = -f0 * r * (q(1) / q(2)).im;
    (fk2.is_finite() && fk2 > 0.0).then(|| (fk2.sqrt(), bk))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn narrow_band_and_the_fit_recover_a_lorentzian() {
        let (fk, bk, phi) = (9.64e6 + 123.0, 175.3f64, 3.0f64.to_radians());
        let c = C64::from_polar(2.0e9, -phi);
        let y = |f: f64| c / C64::new((fk - f) * (fk + f), f * bk);
        let far: Vec<(f64, C64)> = [-1.0, 0.0, 1.0]
            .iter()
            .map(|s| (9.64e6 - 2000.0 + s * 175.0, y(9.64e6 - 2000.0 + s * 175.0)))
            .collect();
        let (f_est, b_est, _) = narrow_band(&far).unwrap();
        assert!((f_est - fk).abs() < 1.0, "{f_est}");
        assert!((b_est / bk - 1.0).abs() < 0.01, "{b_est}");
        let near: Vec<(f64, C64)> = (0..9)
            .map(|i| fk + 30.0 + bk * (i as f64 / 4.0 - 1.0))
            .map(|f| (f, y(f)))
            .collect();
        let m = fit_mode(
            &near,
            fk + 30.0,
            150.0,
            None,
            &no_pull,
            FrontSlope::default(),
        )
        .unwrap();
        assert!((m.f_hz.value - fk).abs() < 1e-6, "{:?}", m.f_hz);
        assert!((m.q.value / (fk / bk) - 1.0).abs() < 1e-9);
        assert!((m.phase_deg.value - 3.0).abs() < 1e-9, "{:?}", m.phase_deg);
    }

    /// A scan over +-5% of a 9.64 MHz guess finds a resonance anywhere in
    /// it (on a scan point or between two, near the centre or the edge),
    /// with a front-end phase and noise on every point, to a small fraction
    /// of the scan's spacing (noise-free, it is exact: the form is).
    #[test]
    fn the_scan_fit_finds_a_far_resonance() {
        let guess = 9.64e6;
        let spacing = guess * 0.005;
        for shift in [0.985, 0.9873, 1.003, 1.0412, 0.9512] {
            let (fk, bk) = (guess * shift, 175.3);
            let c = C64::from_polar(2.0e9, -0.3);
            let mut state = 7u64;
            let mut noise = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            let points: Vec<(f64, C64)> = (0..21)
                .map(|i| guess * (1.0 + 0.05 * (i as f64 / 10.0 - 1.0)))
                .map(|f| {
                    let y = c / C64::new((fk - f) * (fk + f), f * bk);
                    // Additive noise of 1e-6 of the peak response: some 3% of
                    // the farthest points' (the simulated board's z averages
                    // leave about 3e-7 of a peak at half the ADC's full scale).
                    let n = C64::new(noise(), noise()) * 1e-6 * (c.norm() / (fk * bk));
                    (f, y + n)
                })
                .collect();
            let (f, _) = scan_fit(&points).unwrap();
            // A quarter of the spacing (12 kHz, 69 bandwidths): where the
            // coarse search starts; its narrow-band form reaches that far
            // (1 / (Y f) is linear in f to Delta / f = 1e-3 there) and
            // its spacing grows with the move (`search::coarse`). Near the
            // scan's edge, with points on one side only, it is the worst.
            assert!((f - fk).abs() < 0.25 * spacing, "{f} vs {fk}");
        }
    }

    /// The hold's gain, falling across the sweep, is in the model: on
    /// the paper device's modes (9.64 MHz, Q 55e3, 50 MHz clock) and the
    /// consumer device's (25.1 kHz, Q 3000, 1.2345 MHz), with the images,
    /// the fit of a noise-free sweep returns fk within 1e-9 bk (float
    /// rounding over the sums leaves about 1e-12 of the peak). Without the
    /// hold in the model it was -8.6e-7 bk and -1.7e-7 bk off: a bias
    /// larger than the paper device's statistical sigma of fk.
    #[test]
    fn the_hold_gains_slope_is_in_the_model() {
        for (fk, q, fs) in [(9.64e6, 55e3, 50e6), (25.1e3, 3000.0, 1.2345e6)] {
            let bk = fk / q;
            let c = C64::from_polar(2.0e9, -0.05);
            let y = |f: f64| {
                let sum: C64 = (-FIT_IMAGES..=FIT_IMAGES)
                    .map(|j| f + f64::from(j) * fs)
                    .map(|v| (f / v) / C64::new((fk - v) * (fk + v), v * bk))
                    .sum();
                c * sum * hold_gain(f, fs)
            };
            let points: Vec<(f64, C64)> = (0..5)
                .map(|i| fk + bk * 1.5 * (i as f64 / 2.0 - 1.0))
                .map(|f| (f, y(f)))
                .collect();
            let m = fit_mode(
                &points,
                fk + 0.01 * bk,
                bk,
                Some(fs),
                &no_pull,
                FrontSlope::default(),
            )
            .unwrap();
            let bias = (m.f_hz.value - fk) / bk;
            assert!(bias.abs() < 1e-9, "fk {fk}: {bias:e} bk");
            assert!((m.q.value / q - 1.0).abs() < 1e-9, "{:?}", m.q);
        }
    }

    /// The modes the waits' pulls are measured on: the consumer device's,
    /// the paper device's, Q 100 to 1e5, 2.6 to 50 clocks per carrier
    /// (fk, Q, clock Hz); in bandwidths the shape is the same.
    const PULL_MODES: [(f64, f64, f64); 7] = [
        (25.1e3, 3000.0, 1.2345e6),
        (9.64e6, 55e3, 50e6),
        (1e4, 100.0, 4e4),
        (1e5, 1e3, 2.6e5),
        (1e6, 1e4, 3e7),
        (1e5, 1e5, 1e6),
        (2e6, 300.0, 6e6),
    ];

    /// The response C / ((fk - f)(fk + f) + j f bk) through the DAC hold's
    /// gain at the clock `fs`: the waits' pull tests' mode.
    fn held(c: C64, fk: f64, bk: f64, fs: f64) -> impl Fn(f64) -> C64 {
        move |f| c * hold_gain(f, fs) / C64::new((fk - f) * (fk + f), f * bk)
    }

    /// How far a residue of size `eps` moves fk (in `bk`), Q (relative)
    /// and the phase (rad), per unit of `eps`: `fit(eps)` against `fit(0)`,
    /// the same points without it, so the model's own misfit (no images
    /// in the points) cancels.
    fn moved_per_unit(fit: impl Fn(f64) -> ModeFit, eps: f64, bk: f64) -> [f64; 3] {
        let (m, m0) = (fit(eps), fit(0.0));
        let phase =
            (C64::from_polar(1.0, (m0.phase_deg.value - m.phase_deg.value).to_radians())).arg();
        [
            (m.f_hz.value - m0.f_hz.value) / bk,
            m.q.value / m0.q.value - 1.0,
            phase,
        ]
        .map(|d| d / eps)
    }

    /// What the filter's residue after the REF_PHASE step does to the
    /// fit: the Q window keeps eps of the step from I to Q, so Y becomes
    /// Y + j eps (Re Y - Im Y); over every phase of C, on seven modes
    /// (the consumer device's, the paper device's, Q 100 to 1e5, 2.6 to 50
    /// clocks per carrier; the shape in bandwidths is the same), fk moves by
    /// at most 0.185 eps bk, Q by 0.368 eps of itself and the phase by
    /// 0.519 eps radians: within `super::REF_STEP_PULL`; their RMS over
    /// C's phase and the modes is 0.131, 0.261 and 0.500 eps: within
    /// `super::REF_STEP_SD`.
    #[test]
    fn the_ref_phase_residue_moves_the_estimates_within_its_bound() {
        let eps = 1e-6;
        let mut squares = [0.0f64; 3];
        let mut count = 0.0;
        for (fk, q, fs) in PULL_MODES {
            let bk = fk / q;
            let mut worst = [0.0f64; 3];
            for deg in (0..360).step_by(10) {
                let c = C64::from_polar(2.0e9, f64::from(deg).to_radians());
                let y = held(c, fk, bk, fs);
                let fit = |e: f64| {
                    let points: Vec<(f64, C64)> = (0..5)
                        .map(|i| fk + bk * 1.5 * (i as f64 / 2.0 - 1.0))
                        .map(|f| (f, y(f) + C64::new(0.0, e * (y(f).re - y(f).im))))
                        .collect();
                    fit_mode(&points, fk, bk, Some(fs), &no_pull, FrontSlope::default()).unwrap()
                };
                let moved = moved_per_unit(fit, eps, bk);
                for ((w, s), d) in worst.iter_mut().zip(squares.iter_mut()).zip(moved) {
                    *w = w.max(d.abs());
                    *s += d * d;
                }
                count += 1.0;
            }
            for (w, bound) in worst.iter().zip(super::super::REF_STEP_PULL) {
                assert!(
                    *w <= bound,
                    "{fk} Hz: {worst:?} against {:?}",
                    super::super::REF_STEP_PULL
                );
            }
            assert!(worst[0] > 0.1, "the residue moves fk: {worst:?}");
        }
        // Over C's phase, which no sweep chooses, and the seven modes, the
        // pull's RMS, which `super::sweep_uncertainty` takes as its sigma.
        let rms = squares.map(|s| (s / count).sqrt());
        for (r, sd) in rms.iter().zip(super::super::REF_STEP_SD) {
            assert!(
                *r <= sd,
                "RMS {rms:?} against {:?}",
                super::super::REF_STEP_SD
            );
        }
    }

    /// The fine sweep's order, which the tests below play: five carriers
    /// 0.75 bandwidths apart, up, then the same down.
    #[test]
    fn the_fine_sweep_goes_up_then_down() {
        assert_eq!(
            super::super::fine_offsets(),
            [-1.5, -0.75, 0.0, 0.75, 1.5, 1.5, 0.75, 0.0, -0.75, -1.5]
        );
    }

    /// What the resonator's settling residue does to the fit, at a delay
    /// u = pi bk D from the I window to the Q window (`super::settle_sd`),
    /// per unit of residue: the RMS over the transient's turn and the
    /// seven modes of fk's pull (in bk), Q's (relative) and the phase's
    /// (rad).
    ///
    /// The fine sweep steps up, then down (`super::fine_sweep`), each
    /// point starting from the one before (the first from the coarse
    /// search's centre, the sixth from the same carrier). A point a step
    /// from f' to f keeps eps (Y(f') - Y(f)) e^(-j 2 pi (f - fk) T) of the
    /// step in its I window, eps the settling bound relative to the step
    /// (`super::Waits::settling`, at most the peak's 0.83 on this grid):
    /// the transient turns at the detuning over the wait T, and the same T
    /// at every carrier turns the up and down points' residues alike, so
    /// the first-order parts cancel. The Q window starts D later
    /// (`super::Waits::quarter_s`): its part of Y keeps e^-u of the
    /// residue, turned on by 2 u (f - fk) / bk. No sweep chooses the turn
    /// 2 pi bk T (the wait is the coarse search's bandwidth's, rounded,
    /// and bk is the unknown), so the RMS is over it: 400 turns from 0 to
    /// 404 rad.
    fn settling_pull_rms(u: f64) -> [f64; 3] {
        let eps = 1e-6;
        let offsets = super::super::fine_offsets();
        let later = |s: f64| C64::from_polar((-u).exp(), -2.0 * u * s);
        let mut squares = [0.0f64; 3];
        let mut count = 0.0;
        for (fk, q, fs) in PULL_MODES {
            let bk = fk / q;
            let c = C64::from_polar(2.0e9, 0.3);
            let y = held(c, fk, bk, fs);
            for turn in (0..400).map(|i| 1.0137 * f64::from(i)) {
                let fit = |e: f64| {
                    let mut from = fk;
                    let points: Vec<(f64, C64)> = offsets
                        .iter()
                        .map(|s| {
                            let f = fk + s * bk;
                            let in_i = (y(from) - y(f)) * C64::from_polar(e, -turn * s);
                            let in_q = in_i * later(*s);
                            from = f;
                            (f, y(f) + C64::new(in_i.re, in_q.im))
                        })
                        .collect();
                    fit_mode(&points, fk, bk, Some(fs), &no_pull, FrontSlope::default()).unwrap()
                };
                for (s, d) in squares.iter_mut().zip(moved_per_unit(fit, eps, bk)) {
                    *s += d * d;
                }
                count += 1.0;
            }
        }
        squares.map(|s| (s / count).sqrt())
    }

    /// `super::settle_sd`, which `super::sweep_uncertainty` takes as the
    /// settling residue's 1-sigma, within 10% above the pulls' RMS
    /// (`settling_pull_rms`) at each of its delays, halfway between them
    /// (where it interpolates) and beyond the last (where it holds): not
    /// below (the sigma would be short), not far above (inflated). Q's
    /// pull falls with the delay (0.768 at none, 0.21 from u = 2.4: the
    /// residue has gone from the Q window), fk's rises (0.085 to 0.107).
    /// Stop 71's constants put the same residue in both windows (u = 0);
    /// before them the sigma was the bound over sqrt 3 for all three: 6.8
    /// times the fk pull, 3.5 times the phase's.
    #[test]
    fn the_settling_residue_moves_the_estimates_by_settle_sd() {
        let grid = super::super::SETTLE_SD.map(|(u, _)| u);
        let halves = grid.windows(2).map(|w| 0.5 * (w[0] + w[1]));
        let beyond = [grid[grid.len() - 1] * 2.0, 20.0];
        for u in grid.into_iter().chain(halves).chain(beyond) {
            let (rms, sd) = (settling_pull_rms(u), super::super::settle_sd(u));
            for (r, s) in rms.iter().zip(sd) {
                assert!(*r <= s && s <= 1.1 * r, "u {u}: RMS {rms:?} against {sd:?}");
            }
        }
    }

    /// `super::sweep_uncertainty`'s settling term is `super::settle_sd` at
    /// the sweep's own delay from the I window to the Q window
    /// (`super::Waits::quarter_s`, u = pi bk D): on a noise-free sweep (no
    /// residuals, no jackknife spread, no lines) with the filter's residue
    /// made nil, each sigma is the settling residue times its pull at u.
    /// Q's pull is 0.8 with no delay and 0.222 at u = 2.4, fk's 0.09 and
    /// 0.111: a sigma read at the wrong delay is off by 3.6 times or 19%.
    #[test]
    fn the_settling_sigma_reads_the_q_windows_delay() {
        let (fk, q, fs) = PULL_MODES[0];
        let bk = fk / q;
        let c = C64::from_polar(2.0e9, 0.3);
        let y = held(c, fk, bk, fs);
        let points: Vec<(f64, C64)> = (super::super::fine_offsets().iter())
            .map(|s| (fk + s * bk, y(fk + s * bk)))
            .collect();
        let front = FrontSlope::default();
        let mut m = fit_mode(&points, fk, bk, Some(fs), &no_pull, front).unwrap();
        let (bk, q) = (m.f_hz.value / m.q.value, m.q.value);
        for u in [0.0, 2.4] {
            m.waits = super::super::Waits {
                waited_s: 3.0 / (PI * bk),
                window_s: 1.0,
                filter_decay_per_s: 1e15,
                quarter_s: u / (PI * bk),
                kept: 1.0,
            };
            let settle = m.waits.settling(bk);
            let pull = super::super::settle_sd(u);
            let expected = [
                pull[0] * settle * bk,
                pull[1] * settle * q,
                pull[2] * settle,
            ];
            let expected = [expected[0], expected[1], expected[2].to_degrees()];
            let got = super::super::sweep_uncertainty(&m, fs, &no_pull, front);
            for (g, e) in got.iter().zip(expected) {
                assert!(
                    (g / e - 1.0).abs() < 1e-6,
                    "u {u}: {got:?} against {expected:?}"
                );
            }
        }
    }

    /// `noise_and_lines`' covariance is the fit's (on a noise-free sweep,
    /// where the residuals leave no noise of their own): noise of a different
    /// 1-sigma on each point (1 to 4 times, the larger beside the peak, as
    /// a fold puts the table's lines nearer some carriers than others),
    /// 4000 noisy fits of a Lorentzian, their spread of fk, Q and the
    /// phase against what `noise_and_lines` gives. A spread of 4000 normal
    /// draws has a relative sigma of 1 / sqrt(8000) = 1.1%: 5% is 4.5 of
    /// those (measured 0.981, 1.005, 0.981; the fit is linear within 1e-3
    /// at noise of 1e-4 of the peak). The same noise taken as alike on
    /// every point (its RMS) reads 9% to 14% low, beyond 5%: the weights
    /// are what the test sees.
    #[test]
    fn the_lines_through_the_fit_are_its_spread() {
        use rand_distr::{Distribution, StandardNormal};
        use rand_xoshiro::Xoshiro256PlusPlus;
        use rand_xoshiro::rand_core::SeedableRng;
        let (fk, bk, fs) = (25722.4, 7.0, 1.2345e6);
        let c = C64::from_polar(3.0e9, -0.3);
        let truth = |f: f64| c * shape(fk, bk, f, Some(fs), &no_pull, FrontSlope::default()).0;
        let offsets = super::super::fine_offsets();
        let carriers: Vec<f64> = offsets.iter().map(|s| fk + s * bk).collect();
        let peak = c.norm() / (fk * bk);
        let scale = [1.0, 4.0, 2.0, 1.0, 1.0, 1.0, 1.0, 2.0, 4.0, 1.0];
        let sd: Vec<f64> = scale.iter().map(|s| s * 1e-4 * peak).collect();
        let exact: Vec<(f64, C64)> = carriers.iter().map(|&f| (f, truth(f))).collect();
        let centre = fit_mode(&exact, fk, bk, Some(fs), &no_pull, FrontSlope::default()).unwrap();
        let front = FrontSlope::default();
        let lines = |sd: &[f64]| noise_and_lines(&centre, sd, Some(fs), &no_pull, front).unwrap();
        let predicted = lines(&sd);
        let rms_sd = (sd.iter().map(|s| s * s).sum::<f64>() / sd.len() as f64).sqrt();
        let alike = vec![rms_sd; sd.len()];
        let flat = lines(&alike);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(23);
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        let draws: Vec<[f64; 3]> = (0..4000)
            .map(|_| {
                let noisy: Vec<(f64, C64)> = exact
                    .iter()
                    .zip(&sd)
                    .map(|(&(f, y), &s)| (f, y + C64::new(normal(), normal()) * s))
                    .collect();
                let m =
                    fit_mode(&noisy, fk, bk, Some(fs), &no_pull, FrontSlope::default()).unwrap();
                [m.f_hz.value, m.q.value, m.phase_deg.value]
            })
            .collect();
        for (i, name) in ["fk", "Q", "phase"].iter().enumerate() {
            let values: Vec<f64> = draws.iter().map(|d| d[i]).collect();
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let spread = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>()
                / (values.len() - 1) as f64)
                .sqrt();
            let ratio = spread / predicted[i];
            eprintln!(
                "{name}: spread {spread:.4e}, propagated {:.4e}, ratio {ratio:.3}",
                predicted[i]
            );
            assert!(
                (ratio - 1.0).abs() < 0.05,
                "{name}: spread / propagated {ratio:.3}"
            );
            let unweighted = spread / flat[i];
            assert!(
                (unweighted - 1.0).abs() > 0.05,
                "{name}: alike {unweighted:.3}"
            );
        }
    }
}
