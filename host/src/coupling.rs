//! The quadrature (stiffness) coupling, measured at rest through the same
//! four cross responses as the drive-gain ratio ([`crate::drive_ratio`]).
//!
//! # Why rest suffices
//!
//! With a stiffness coupling k (x1'' gets + k x2, x2'' gets + k x1; k =
//! 2 lambda w1 Omega_q, `[gyro] quadrature_dps` Omega_q) the phasor
//! equations at the carrier are, with G_k = 1 / (w_k^2 - w^2 + j w b_k)
//! and c = j w 2 lambda Omega,
//!
//! ```text
//! [ 1/G_1  k - c ] [X_1]   [F_1]              1   [ 1/G_2   -(k - c) ]
//! [ k + c  1/G_2 ] [X_2] = [F_2],   M = ----- [                    ]
//!                                        det   [ -(k + c)   1/G_1  ]
//! ```
//!
//! At rest (c = 0) the cross responses are M_12 = M_21 = -k / det, and
//! with the lines of [`crate::drive_ratio`] (Z_1 = P_1 + Q_1 W_2, Z_2 /
//! W_2 = P_2 + Q_2 W_2; rho = g_2 / g_1 the drive-gain ratio)
//!
//! ```text
//! Q_1 / P_1 = -j rho M_12 / (M_11 W_1) =  j rho k G_2 / W_1   ->  k_1 = -j W_1 (Q_1 / P_1) / (rho G_2)
//! P_2 / Q_2 =  j W_1 M_21 / (rho M_22) = -j k G_1 W_1 / rho   ->  k_2 =  j rho (P_2 / Q_2) / (W_1 G_1)
//! ```
//!
//! ADC gains and each output's reference phase and filter gain cancel in
//! each; rho (the design ratio here) enters k_1 as 1 / r and k_2 as r for
//! a true ratio r times the design's, so their mean carries (r + 1 / r) / 2,
//! 1 + 5e-5 for a ratio 1% off. The estimate is linear in the windows (no
//! square root), so a device without coupling reads 0 within its noise.
//! Its real part is the stiffness k; a damping coupling d (`[gyro]
//! damping_coupling_dps`, kappa = k + j w d on both modes,
//! `crate::theory`) is its imaginary part, at the carrier. In deg/s, with
//! G in 1 / Hz^2 (k in Hz^2, 4 pi^2 of it in rad^2/s^2), Omega_q = 4 pi^2
//! k / (2 lambda 2 pi f_1) rad/s = 180 k / (lambda f_1) deg/s and
//! Omega_d = 180 Im / (lambda f_c) deg/s, with the datasheet's lambda. The
//! prediction turns them back with the same lambda, so lambda's error
//! does not enter it; the figures in deg/s carry it
//! ([`crate::identify::CouplingFigure`]).
//!
//! # A device turning during the windows
//!
//! The cycle assumes rest. A rate Omega puts c = j w 2 lambda Omega in
//! the two cross responses with opposite signs (k - c in M_12, k + c in
//! M_21), and c has the damping term's form j w d: output 1's D reads
//! d - 2 lambda Omega, output 2's d + 2 lambda Omega. Their mean is the
//! damping coupling; half their difference, in the same units, is the
//! rate (`Coupling::rate_dps`). On five devices at rest it read within
//! 2.3 of its sigmas of 0 (about 0.02 deg/s), at 5 and -2 deg/s within
//! 1.7% of the rate. The cycle predicts the calibration at it
//! (`selfcal::Operating::cycle_rate_dps`), fits the modes with its pull
//! (`uncouple`) and, beyond `selfcal::CYCLE_RATE_SEEN` of its sigmas, says
//! the device turned.
//!
//! # Images
//!
//! The windows see the sampled loop, not the phasor theory's single tone:
//! each DAC image of a drive lands on the carrier (`crate::images`). On a
//! detuned output at a few clocks per carrier the images are percents of
//! the direct response (a Q 270 / 410 device split by 12.6 bandwidths at
//! 2.64 clocks per carrier: 3% of output 2's), while the cross response,
//! a product of two resonators, carries some 1e-4 of them. Dividing by
//! the phasor G_k then read both couplings 1.6% large there (-304.86 +-
//! 0.43 deg/s for -300, 11 sigma; a Q 2000 device at 2.81 clocks per
//! carrier 14 to 21 sigma, its self-calibrated scale factors 9 sigma
//! through the drive-gain ratio measured at rest). So each output's
//! cross over direct response is modelled with the images summed
//! (`drive_ratio::Folded`: the fine fits' front ends and `IMAGES` each
//! side), and as kappa(v) = K + j v D at each image the stiffness and
//! the damping term grow differently: one complex equation per output
//! gives K and D, then the outputs' mean.
//!
//! # Uncertainty
//!
//! The spread of the `BATCHES` batch estimates (standard error, times the
//! coverage factor of its 7 degrees of freedom, 1.51, as the drive-gain
//! ratio's) and the identified G_1, G_2 (each k_i moves with |G|; finite
//! differences over f_k and Q_k), in quadrature. Without the factor, on an
//! unseen device (2.2 MHz, Q 8000 / 6000, six noise seeds) the quadrature
//! coupling at one step lay at an RMS of 1.5 of its sigmas, one seed at
//! -3.18.
//!
//! On the table core, a third term: the carrier spurs (`selfcal::spurs`).
//! A line that beats slower than a window is the same in each of its
//! batches, so the spread never sees it, yet it moves the window's mean.
//! A line multiplies an output's signal by 1 + rho e^(j(Omega t + phi));
//! the four windows (two signs, in-phase and quadrature) read it at
//! their own times, 30 to 200 ms apart. `spur_lines` takes each line's
//! rho at the cross responses' drive amplitudes, times |sinc(pi f T)|
//! over a window T, and `spur_sigma` carries it through the estimate's
//! slopes by the windows' means, at those times (its doc comment has the
//! algebra). A line that barely moves over the measurement is a common
//! complex gain on an output's windows, which the estimate's ratios
//! cancel; one that turns between the windows does not cancel. Seed 2258
//! of `tests/field_coverage.rs` (2 MHz, 3.06 clocks per carrier) at 35
//! deg C, whose report names a line 2.8 Hz from the carrier, read its
//! quadrature coupling (truly 0) at -2.25 to +1.71 deg/s over eight noise
//! seeds (RMS 1.56) against sigmas of 0.19 to 0.72; the term makes them
//! 2.3 to 2.5 (`a_slow_spur_line_is_in_the_couplings_sigma`). On the fine
//! core (no such lines) the same device read -0.55 to +0.03. Taking the
//! windows' phases as independent instead had tripled the consumer
//! device's coupling sigma at 35 deg C (0.016 -> 0.048 deg/s, its
//! scattered estimates within 0.02 of the truth), and through it its
//! output 2's scale-factor sigma (0.075% -> 0.216%).

use crate::drive_ratio::{
    BATCHES, CrossWindows, DRIVE1_FRACTION, Folded, mean_and_error, propagated, resonator,
};
use crate::error::Error;
use crate::identify::{self, Estimate, FrontEnd, Identified, ModeFit};
use crate::knowns::Knowns;
use crate::selfcal::Operating;
use crate::selfcal::spurs::{self, RelativeLine};
use nalgebra::Complex;
use serde::Serialize;

type C64 = Complex<f64>;

/// The measured coupling.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Coupling {
    /// Omega_q (deg/s), the sign convention of `[gyro] quadrature_dps`.
    pub quadrature_dps: Estimate,
    /// The damping coupling Omega_d (deg/s, the sign convention of
    /// `[gyro] damping_coupling_dps`), from the same estimate's imaginary
    /// part.
    pub damping_dps: Estimate,
    /// The rate the device turned at during the windows (deg/s, the sign
    /// of `SimBoard::set_rate`'s): the two outputs' D in opposition
    /// (`coupling_hz2`, module header), in the damping coupling's units; 0
    /// within its sigma at rest.
    pub rate_dps: Estimate,
    /// Clocks the measurement took.
    pub clocks: u64,
}

/// (K, D) from output `k`'s measured cross over direct response `ratio`
/// (M_cross / M_direct), its responses `s` folded: one complex equation,
/// two real unknowns.
fn solve(s: &Folded, ratio: C64) -> (f64, f64) {
    let m = -ratio * s.direct;
    let (a, b) = (s.stiffness, s.damping);
    let det = a.re * b.im - b.re * a.im;
    (
        (m.re * b.im - b.re * m.im) / det,
        (a.re * m.im - m.re * a.im) / det,
    )
}

/// kappa at the carrier, K + j fc D (Hz^2), from one batch's lines
/// (module header): each output's (K, D) from its cross over direct
/// response (`solve`), then their mean, for the design drive-gain
/// ratio `rho`. With the device turning, the Coriolis term c enters the
/// two cross responses with opposite signs (k - c and k + c, module
/// header) and has the damping term's form: the outputs' D differ by
/// twice it. The second value is half that difference, times fc (Hz^2),
/// which is 0 at rest.
fn coupling_hz2(
    lines: ((C64, C64), (C64, C64)),
    w1: f64,
    folded: &[Folded; 2],
    rho: f64,
    carrier_hz: f64,
) -> (C64, f64) {
    let j = C64::new(0.0, 1.0);
    let ((p1, q1), (p2, q2)) = lines;
    // M_12 / M_11 and M_21 / M_22 (module header).
    let (k1, d1) = solve(&folded[0], j * w1 * (q1 / p1) / rho);
    let (k2, d2) = solve(&folded[1], -j * rho * (p2 / q2) / w1);
    (
        C64::new(0.5 * (k1 + k2), 0.5 * (d1 + d2) * carrier_hz),
        0.5 * (d2 - d1) * carrier_hz,
    )
}

/// The relative 1-sigma of the mean inverse magnitude of G_1 and G_2 at
/// `carrier_hz` from `id` (`drive_ratio::propagated`): k_1 scales as
/// 1 / |G_2| and k_2 as 1 / |G_1|.
fn resonator_error(id: &Identified, carrier_hz: f64) -> f64 {
    let size = |v: [f64; 4]| {
        let g = [
            resonator(v[0], v[1], carrier_hz),
            resonator(v[2], v[3], carrier_hz),
        ];
        0.5 * (1.0 / g[0].norm() + 1.0 / g[1].norm())
    };
    propagated(id, size)
}

/// What the windows' lines read at an identification and operating
/// point: `coupling_hz2` in deg/s, and the relative error the identified
/// resonators put on its magnitude.
struct Reading {
    folded: [Folded; 2],
    rho: f64,
    per_hz2: f64,
    carrier_hz: f64,
    g_error: f64,
    to_damping: f64,
}

impl Reading {
    fn new(knowns: &Knowns, op: &Operating, id: &Identified) -> Self {
        Self {
            folded: [0, 1].map(|k| Folded::of(id, k, op.carrier_hz, knowns.clock_hz)),
            rho: knowns.force_full_scale[1] / knowns.force_full_scale[0],
            per_hz2: 180.0 / (knowns.nominal.angular_gain * id.modes[0].f_hz.value),
            carrier_hz: op.carrier_hz,
            g_error: resonator_error(id, op.carrier_hz),
            to_damping: id.modes[0].f_hz.value / op.carrier_hz,
        }
    }

    /// `[Omega_q, Omega_d, Omega]` (deg/s) of batch `b` (`None`: every
    /// sample). The real part of kappa is Omega_q (k = 2 lambda w1
    /// Omega_q); its imaginary part w_c d with d = 2 lambda Omega_d, so
    /// Omega_d is it times f1 / fc; the rate term likewise.
    fn read(&self, w: &CrossWindows, b: Option<usize>) -> [f64; 3] {
        let (kappa, rate) = coupling_hz2(w.lines(b), w.w1, &self.folded, self.rho, self.carrier_hz);
        let (kappa, rate) = (self.per_hz2 * kappa, self.per_hz2 * rate);
        [kappa.re, kappa.im * self.to_damping, rate * self.to_damping]
    }

    /// The batches' mean and its sigma: their spread, the resonators'
    /// error on the magnitude and the spur lines' term, in quadrature.
    fn estimate(&self, v: &[f64], spur: f64) -> Estimate {
        let noise = mean_and_error(v);
        Estimate {
            value: noise.value,
            uncertainty: noise
                .uncertainty
                .hypot(self.g_error * noise.value)
                .hypot(spur),
        }
    }
}

/// The coupling from the cross-response windows measured at the
/// operating point `op` of identification `id`, and the rate the device
/// turned at meanwhile: one round, which the cycle iterates with
/// [`uncouple`] (`selfcal`).
///
/// `spur_lines`: the table core's lines in the windows' means
/// ([`spur_lines`]), which the batches' spread does not see.
pub(crate) fn from_windows(
    windows: &CrossWindows,
    knowns: &Knowns,
    op: &Operating,
    id: &Identified,
    spur_lines: Option<&[TurningLine]>,
) -> Result<Coupling, Error> {
    let reading = Reading::new(knowns, op, id);
    let batches: Vec<[f64; 3]> = (0..BATCHES)
        .map(|b| reading.read(windows, Some(b)))
        .collect();
    if batches.iter().any(|[k, ..]| !k.is_finite()) {
        return Err(Error::Measurement {
            what: "quadrature coupling",
            reason: "a direct response (P_1 or Q_2) read zero".into(),
        });
    }
    let spurs = spur_lines.map_or([0.0; 3], |lines| {
        spur_sigma(windows, lines, |w| reading.read(w, None))
    });
    let [quadrature_dps, damping_dps, rate_dps] = std::array::from_fn(|part| {
        let v: Vec<f64> = batches.iter().map(|b| b[part]).collect();
        reading.estimate(&v, spurs[part])
    });
    Ok(Coupling {
        quadrature_dps,
        damping_dps,
        rate_dps,
        clocks: windows.clocks,
    })
}

/// The table core's carrier spur lines in the windows' means at the cross
/// responses' drive amplitudes, each per output as a fraction of that
/// output's magnitude (`spurs::relative_lines_over_records` over one
/// window), as the windows read them ([`TurningLine`]); `None` on the
/// fine core.
pub(crate) fn spur_lines(
    windows: &CrossWindows,
    knowns: &Knowns,
    op: &Operating,
    id: &Identified,
) -> Result<Option<Vec<TurningLine>>, Error> {
    let cross = Operating {
        amplitude: (DRIVE1_FRACTION * op.amplitude.0, op.amplitude.1),
        ..op.clone()
    };
    let lines = spurs::relative_lines_over_records(knowns, id, &cross, windows.window_s)?;
    Ok(lines.map(|lines| turning(windows, &lines)))
}

/// A spur line as the four windows read it: its relative amplitude per
/// output and, at each side of the carrier, its phasor e^(j Omega t_sq)
/// at window (s, q)'s time. Made once per measurement ([`turning`]): the
/// coupling's rounds (`selfcal`'s `uncoupled`, nine of them) read the
/// same lines with other slopes, and a step on a slow clock has some 1e5
/// lines, whose phasors were most of a field step's time.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TurningLine {
    /// rho per output ([`RelativeLine::rho`]).
    rho: [f64; 2],
    /// `turn[side][s][q]`: side 0 at +Omega (above the carrier), 1 at
    /// -Omega.
    turn: [[[C64; 2]; 2]; 2],
}

/// `lines` as `windows` read them, at their `times_s`.
pub(crate) fn turning(windows: &CrossWindows, lines: &[RelativeLine]) -> Vec<TurningLine> {
    let phasors = |omega: f64| {
        windows
            .times_s
            .map(|by_q| by_q.map(|time| C64::from_polar(1.0, omega * time)))
    };
    lines
        .iter()
        .map(|line| TurningLine {
            rho: line.rho,
            turn: [1.0, -1.0].map(|side| phasors(side * std::f64::consts::TAU * line.offset_hz)),
        })
        .collect()
}

/// The 1-sigma of each of the estimate `estimate`'s `N` parts (deg/s)
/// from the spur `lines` (module header, "Uncertainty"), all parts from
/// one pass over the lines.
/// A line of relative amplitude rho on output k multiplies its signal by
/// 1 + rho e^(j(Omega t + phi)): window (s, q) at time t_sq reads the part
/// q of Z_sk (1 + rho e^(j(Omega t_sq + phi))). With a and b the
/// estimate's slopes by output k's in-phase and quadrature means at sign
/// s, the error is rho Re(e^(j phi) S_k), S_k = sum_s (a e^(j Omega t_s0) -
/// j b e^(j Omega t_s1)) Z_sk, whose variance over phi is rho^2 |S_k|^2
/// / 2; the outputs' lines (other carriers) are taken independent, each
/// line at whichever side of the carrier gives the larger, the lines
/// added in power. A line that barely moves over the measurement is a
/// common complex gain on an output's windows, which the estimate's
/// ratios cancel.
pub(crate) fn spur_sigma<const N: usize>(
    windows: &CrossWindows,
    lines: &[TurningLine],
    estimate: impl Fn(&CrossWindows) -> [f64; N],
) -> [f64; N] {
    // slope[s][q][k][part]: the estimate's derivative by window (s, q)'s
    // output-k mean.
    let mut slope = [[[[0.0; N]; 2]; 2]; 2];
    for (s, by_q) in slope.iter_mut().enumerate() {
        for (q, by_k) in by_q.iter_mut().enumerate() {
            for (k, d) in by_k.iter_mut().enumerate() {
                let h = 1e-6 * windows.mean(s, k).norm();
                let (up, down) = (
                    estimate(&windows.shifted(s, q, k, h)),
                    estimate(&windows.shifted(s, q, k, -h)),
                );
                *d = std::array::from_fn(|part| (up[part] - down[part]) / (2.0 * h));
            }
        }
    }
    // The windows' means once a call: the sums below read each 4 times a
    // line.
    let mean = [0, 1].map(|s| [0, 1].map(|k| windows.mean(s, k)));
    // a e^(j x) - j b e^(j y), written out: the complex product by j b
    // that it stands for gives the same numbers but for the signs of
    // zeros, which |S_k|^2 squares away.
    let turned =
        |a: f64, b: f64, [x, y]: [C64; 2]| C64::new(a * x.re + b * y.im, a * x.im - b * y.re);
    let mut variance = [0.0; N];
    for line in lines {
        let mut worst = [0.0f64; N];
        for turn in &line.turn {
            let mut v = [0.0; N];
            for (part, v) in v.iter_mut().enumerate() {
                for (k, rho) in line.rho.iter().enumerate() {
                    let term = |s: usize| {
                        let (a, b) = (slope[s][0][k][part], slope[s][1][k][part]);
                        turned(a, b, turn[s]) * mean[s][k]
                    };
                    let s_k = term(0) + term(1);
                    *v += rho * rho * s_k.norm_sqr() / 2.0;
                }
            }
            worst = std::array::from_fn(|part| worst[part].max(v[part]));
        }
        variance = std::array::from_fn(|part| variance[part] + worst[part]);
    }
    variance.map(f64::sqrt)
}

/// Fixed-point rounds of [`uncouple`] at most (each mode's pull is
/// k^2 |G_1 G_2| <= `MAX_MIXING` of its response, so each round shrinks
/// the change some fiftyfold).
const UNCOUPLE_ROUNDS: usize = 20;

/// Largest coupling strength |k^2 G_1 G_2| at either mode's resonance for
/// which [`uncouple`] separates the modes. Each mode's fit is a Lorentzian
/// of a response that the coupling makes a little less than one; what it
/// leaves grows faster than k^2. Measured on the consumer device
/// (`tests/data/field_coupled.toml` at 25 and 60 deg C, the coupling
/// scaled): at 3,000 deg/s (0.014) the coupling came out 0.17 deg/s low
/// (17 of its sigma) and the self-calibrated scale factors within 1.1 of
/// their sigma; at 4,000 (0.026) 0.34 deg/s low and 2.9 sigma; at 5,000
/// (0.04) 4.6 sigma; at 10,000 (0.16) 58 sigma. Beyond the limit the
/// cycle stops with a one-line error instead of a figure (30,000 deg/s:
/// 0.65).
pub const MAX_MIXING: f64 = 0.02;

/// The uncoupled modes behind the `apparent` identified ones, for the
/// `coupling`'s Omega_q, Omega_d and rate (deg/s; kappa^2 - c^2 in place
/// of k^2 below when there is a damping coupling or a rate): each mode's fit sees its direct
/// response M_kk = 1 / (1/G_k - k^2 G_(1-k)), a resonator whose 1/G is
/// pulled by k^2 G_(1-k)(f), the other mode's uncoupled response. Each
/// mode's fine sweep is fitted again with that pull in the model
/// (`identify::refit`), the other mode's G from its last refit: a fixed
/// point, iterated from the apparent modes. The pull is nearly constant
/// across a sweep when the other mode is many bandwidths away (it then
/// moves f_k^2 by k^2 Re G_(1-k)(f_k), the bandwidth by k^2 Im
/// G_(1-k)(f_k) / f_k); with the modes 4 to 5 bandwidths apart it changes
/// across the sweep, and a constant correction left Q 3 to 7.5 sigma high
/// (seeds 2003 and 2025 of `tests/field_coverage.rs`). The couplings
/// (deg/s) are turned back into kappa with the datasheet's lambda. The
/// loop phase at `carrier_hz` and the group delay are read again off the
/// refitted modes' phases, which the pull had moved. On the
/// consumer device with 250 deg/s the shift is 4e-4 Hz (k^2 / (f_2^2 -
/// f_1^2) / 2 f_1), which its detuned output's scale factor feels.
pub fn uncouple(
    apparent: &Identified,
    coupling: &Coupling,
    angular_gain: f64,
    clock_hz: f64,
    carrier_hz: f64,
) -> Result<Identified, Error> {
    let pull = Pull {
        coupling,
        angular_gain,
        f1_hz: apparent.modes[0].f_hz.value,
    };
    let modes = pull.fixed_point(&apparent.modes, clock_hz, carrier_hz)?;
    // The uncertainties once, at the fixed point (each mode's jackknife
    // refits its sweep five times).
    let (pull1, pull2) = (pull.on(&modes, 0), pull.on(&modes, 1));
    let modes = FrontEnd::complete(&modes, carrier_hz, clock_hz, [&pull1, &pull2])?;
    let mut id = apparent.clone();
    (id.loop_phase_deg, id.group_delay_s) = identify::loop_phase(&modes, carrier_hz);
    id.modes = modes;
    Ok(id)
}

/// What couples the modes in [`uncouple`]: the quadrature and damping
/// couplings and the rate (deg/s) through lambda, as the pull
/// kappa^2 - c^2 (Hz^4) that one mode's response puts on the other's.
struct Pull<'a> {
    /// Omega_q, Omega_d and the rate during the cycle, as measured.
    coupling: &'a Coupling,
    /// lambda, the datasheet's.
    angular_gain: f64,
    /// Mode 1's apparent frequency, where k is taken (Hz).
    f1_hz: f64,
}

impl Pull<'_> {
    /// The measured values of Omega_q, Omega_d and the rate (deg/s).
    fn dps(&self) -> [f64; 3] {
        let c = self.coupling;
        [c.quadrature_dps, c.damping_dps, c.rate_dps].map(|e| e.value)
    }

    /// kappa(f) = k + j w d in Hz^2 (`crate::theory`): k from Omega_q at
    /// f1, the damping term j f (lambda Omega_d / 180) at f. A rate adds
    /// the Coriolis term c = j f (lambda Omega / 180) with opposite signs
    /// to the two cross terms (module header), whose product is then
    /// kappa^2 - c^2: that is the pull ("kappa^2" in [`uncouple`]).
    fn kappa_squared(&self, f: f64) -> C64 {
        let [quadrature, damping, rate] = self.dps();
        let kappa = C64::new(
            quadrature * self.angular_gain * self.f1_hz / 180.0,
            damping * self.angular_gain * f / 180.0,
        );
        let c = C64::new(0.0, rate * self.angular_gain * f / 180.0);
        kappa * kappa - c * c
    }

    /// The other mode's pull on mode i, from the other's estimate in
    /// `modes`.
    fn on(&self, modes: &[ModeFit; 2], i: usize) -> impl Fn(f64) -> C64 + '_ {
        let o = &modes[1 - i];
        let (fo, qo) = (o.f_hz.value, o.q.value);
        move |v: f64| self.kappa_squared(v) * resonator(fo, qo, v)
    }

    /// The error of modes too strongly coupled to separate, named by
    /// what couples them: the rate, where it is the larger.
    fn too_strong(&self, reason: impl std::fmt::Display) -> Error {
        let [q, d, r] = self.dps();
        let by = if r.abs() > q.abs().max(d.abs()) {
            format!("a rate of {r:.1} deg/s during the cycle (its Coriolis coupling)")
        } else {
            format!("{q:.1} deg/s")
        };
        Error::Measurement {
            what: "quadrature coupling",
            reason: format!("{by} couples the modes too strongly to separate: {reason}"),
        }
    }

    /// The uncoupled modes behind the `apparent` fits: each refitted with
    /// the other's pull, from the other's last refit, until no frequency
    /// moves by a thousandth of its (residuals') sigma; then the mixing
    /// k^2 |G_1 G_2| at each mode held to `MAX_MIXING`. Uncertainties are
    /// the residuals' until [`FrontEnd::complete`].
    fn fixed_point(
        &self,
        apparent: &[ModeFit; 2],
        clock_hz: f64,
        carrier_hz: f64,
    ) -> Result<[ModeFit; 2], Error> {
        let mut modes = apparent.clone();
        let mut converged = false;
        for _ in 0..UNCOUPLE_ROUNDS {
            let (before, _) = values(&modes);
            let front = FrontEnd::of(&modes, carrier_hz);
            for i in 0..2 {
                let pull = self.on(&modes, i);
                modes[i] =
                    identify::refit(&apparent[i], i, clock_hz, &pull, &front).map_err(|e| {
                        self.too_strong(format!("no uncoupled modes behind the fits ({e})"))
                    })?;
            }
            let (f, q) = values(&modes);
            if !(f.iter().chain(&q).all(|v| v.is_finite() && *v > 0.0)) {
                return Err(self.too_strong("no uncoupled modes behind the fits"));
            }
            let settled =
                (0..2).all(|i| (f[i] - before[i]).abs() < 1e-3 * modes[i].f_hz.uncertainty);
            if settled {
                converged = true;
                break;
            }
        }
        let (f, q) = values(&modes);
        for i in 0..2 {
            let g = [resonator(f[0], q[0], f[i]), resonator(f[1], q[1], f[i])];
            let mixing = (g[0] * g[1] * self.kappa_squared(f[i])).norm();
            if mixing > MAX_MIXING {
                return Err(self.too_strong(format!(
                    "k^2 |G_1 G_2| = {mixing:.2} at mode {}, at most {MAX_MIXING}",
                    i + 1
                )));
            }
        }
        if !converged {
            return Err(self.too_strong("the uncoupled modes did not converge"));
        }
        Ok(modes)
    }
}

/// The two modes' frequencies and Qs.
fn values(modes: &[ModeFit; 2]) -> ([f64; 2], [f64; 2]) {
    (
        [modes[0].f_hz.value, modes[1].f_hz.value],
        [modes[0].q.value, modes[1].q.value],
    )
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use rand_xoshiro::Xoshiro256PlusPlus;
    use rand_xoshiro::rand_core::{Rng, SeedableRng};

    /// The module header's coupled response at one frequency: the inverse
    /// of [[1 / G1, kappa], [kappa, 1 / G2]].
    fn coupled(g: [C64; 2], kappa: C64) -> [[C64; 2]; 2] {
        let det = 1.0 / (g[0] * g[1]) - kappa * kappa;
        [
            [1.0 / (g[1] * det), -kappa / det],
            [-kappa / det, 1.0 / (g[0] * det)],
        ]
    }

    /// The demodulated outputs of the cross responses `m` with drive 1 at
    /// `w1` and drive 2 at `w` (unit gains and phases).
    fn outputs(m: &[[C64; 2]; 2], w1: f64, w: f64) -> [C64; 2] {
        let j = C64::new(0.0, 1.0);
        let x1 = m[0][0] * w1 - j * m[0][1] * w;
        let x2 = m[1][0] * w1 - j * m[1][1] * w;
        [w1 * x1, w * x2]
    }

    /// The module header's model with a stiffness coupling at rest, chosen
    /// gains, pick-off phases and a drive-gain ratio 1% off the design's:
    /// the estimate returns k within (r + 1/r) / 2.
    #[test]
    fn the_cross_responses_at_rest_return_the_coupling() {
        let f = 25.1e3;
        let g = [resonator(25.1e3, 3000.0, f), resonator(25.8e3, 3000.0, f)];
        for k in [3.0e3, -1.2e4, 0.0] {
            let m = coupled(g, C64::new(k, 0.0));
            let r = 1.01;
            let (gain1, gain2) = (2.0, 2.0 * r);
            let (a1, a2) = (C64::from_polar(3.0, 0.2), C64::from_polar(5.0, -0.4));
            let (kappa1, kappa2) = (C64::from_polar(0.7, -1.0), C64::from_polar(0.4, 2.0));
            let w1 = 2500.0;
            let w2 = [15000.0, -14999.0];
            let j = C64::new(0.0, 1.0);
            let z = |w: f64| {
                let x1 = a1 * (gain1 * m[0][0] * w1 - j * gain2 * m[0][1] * w);
                let x2 = a2 * (gain1 * m[1][0] * w1 - j * gain2 * m[1][1] * w);
                [kappa1 * w1 * x1, kappa2 * w * x2]
            };
            let (y0, y1) = (z(w2[0]), z(w2[1]));
            let lines = (
                crate::drive_ratio::line([y0[0], y1[0]], w2),
                crate::drive_ratio::line([y0[1] / w2[0], y1[1] / w2[1]], w2),
            );
            let folded = [0, 1].map(|k| Folded::phasor(g, k, f));
            let got = coupling_hz2(lines, w1, &folded, 1.0, f).0;
            let expected = k * 0.5 * (r + 1.0 / r);
            assert!(
                (got.re - expected).abs() <= 1e-9 * k.abs().max(1.0),
                "{got} vs {k}"
            );
            assert!(got.im.abs() <= 1e-9 * k.abs().max(1.0), "{got}");
        }
    }

    /// The RMS error of `estimate` over 4000 draws of `line`'s phases
    /// (one per output), at the side of the carrier that gives the larger
    /// (`spur_sigma`'s premise, its doc comment): each output's signal
    /// times 1 + rho_k e^(j(Omega t + phi_k)), each window reading it at
    /// its own time.
    pub(crate) fn line_error_rms<const N: usize>(
        windows: &CrossWindows,
        line: &RelativeLine,
        estimate: impl Fn(&CrossWindows) -> [f64; N],
    ) -> [f64; N] {
        let clean = estimate(windows);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(2258);
        // A phase uniform over a turn, from the top 53 bits.
        let mut phase = || (rng.next_u64() >> 11) as f64 / 2f64.powi(53) * std::f64::consts::TAU;
        let draws = 4000;
        let mut rms = [0.0f64; N];
        for side in [1.0, -1.0] {
            let omega = side * std::f64::consts::TAU * line.offset_hz;
            let mut sum = [0.0; N];
            for _ in 0..draws {
                let mut moved = windows.clone();
                for (k, rho) in line.rho.iter().enumerate() {
                    let phi = phase();
                    for (s, at) in windows.times_s.iter().enumerate() {
                        let zk = windows.mean(s, k);
                        let ripple = |q: usize| zk * C64::from_polar(*rho, omega * at[q] + phi);
                        moved = moved.shifted(s, 0, k, ripple(0).re);
                        moved = moved.shifted(s, 1, k, ripple(1).im);
                    }
                }
                let e = estimate(&moved);
                for (sum, (e, clean)) in sum.iter_mut().zip(e.iter().zip(&clean)) {
                    *sum += (e - clean).powi(2);
                }
            }
            rms = std::array::from_fn(|p| rms[p].max((sum[p] / f64::from(draws)).sqrt()));
        }
        rms
    }

    /// `spur_sigma` against its premise (its doc comment): one line of
    /// relative amplitudes rho_k multiplying each output's signal by 1 +
    /// rho_k e^(j(Omega t + phi_k)), each window reading it at its own
    /// time. Over 4000 draws of the phases, at the side of the carrier
    /// that gives the larger, the estimate's error has an RMS equal to the
    /// sigma, real and imaginary part, within 5% (the RMS of 4000 draws
    /// scatters by about 1 / sqrt(2 x 4000) = 1.1%). A line that barely
    /// moves over the measurement is a common gain on each output's
    /// windows and leaves (almost) nothing.
    #[test]
    fn the_spur_sigma_is_the_spread_a_line_leaves() {
        let f = 25.1e3;
        let g = [resonator(25.1e3, 3000.0, f), resonator(25.8e3, 3000.0, f)];
        let m = coupled(g, C64::new(3.0e3, 800.0));
        let (w1, w2) = (2500.0, [15000.0, -14999.0]);
        let z = |w: f64| outputs(&m, w1, w);
        let times = [[0.05, 0.09], [0.17, 0.21]];
        let windows = CrossWindows::constant([z(w2[0]), z(w2[1])], w1, w2, times);
        let folded = [0, 1].map(|k| Folded::phasor(g, k, f));
        let estimate = |w: &CrossWindows| {
            let kappa = coupling_hz2(w.lines(None), w.w1, &folded, 1.0, f).0;
            [kappa.re, kappa.im]
        };
        let line = |offset_hz: f64| RelativeLine {
            offset_hz,
            rho: [3e-4, 1e-3],
        };
        let sigma = spur_sigma(&windows, &turning(&windows, &[line(2.8)]), estimate);
        let rms = line_error_rms(&windows, &line(2.8), estimate);
        let ratio = [rms[0] / sigma[0], rms[1] / sigma[1]];
        assert!(
            ratio.iter().all(|r| (r - 1.0).abs() <= 0.05),
            "RMS over sigma {ratio:?}, sigma {sigma:?}"
        );
        let slow = spur_sigma(&windows, &turning(&windows, &[line(1e-4)]), estimate);
        assert!(
            slow[0] < 1e-3 * sigma[0] && slow[1] < 1e-3 * sigma[1],
            "{slow:?} against {sigma:?}"
        );
    }

    /// The windows of a device at 2.64 clocks per carrier with its output 2
    /// detuned by 12.6 bandwidths (seed 2360 of `tests/field_coverage.rs`,
    /// Q 268 / 406), each DAC image's coupled response summed as the
    /// sampled loop sees it (`crate::images`: the exact 2x2 inverse at v,
    /// weighted f / v), with a stiffness and a damping coupling: both come
    /// back within 1e-4 (what the first-order model leaves at the images,
    /// the coupling's mixing there being 1e-3 of the response). The
    /// phasor G_k read them 1.6% off (module header, "Images").
    #[test]
    fn the_images_are_in_the_estimate() {
        let modes = [(1.022937e5, 267.7369), (9.749131e4, 406.1596)];
        let (f, clock) = (modes[0].0, 2.697518e5);
        let (kk, dd) = (3.0e6, 50.0);
        let mut m = [[C64::new(0.0, 0.0); 2]; 2];
        for i in -identify::IMAGES..=identify::IMAGES {
            let v = f + f64::from(i) * clock;
            let g = modes.map(|(fk, qk)| resonator(fk, qk, v));
            let at_v = coupled(g, C64::new(kk, v * dd));
            for (row, sums) in at_v.iter().zip(&mut m) {
                for (x, sum) in row.iter().zip(sums) {
                    *sum += x * (f / v);
                }
            }
        }
        let (w1, w2) = (2500.0, [15000.0, -14999.0]);
        let (y0, y1) = (outputs(&m, w1, w2[0]), outputs(&m, w1, w2[1]));
        let lines = (
            crate::drive_ratio::line([y0[0], y1[0]], w2),
            crate::drive_ratio::line([y0[1] / w2[0], y1[1] / w2[1]], w2),
        );
        let folded = [0, 1].map(|k| Folded::sum(modes, k, f, clock, |_| C64::new(1.0, 0.0)));
        let got = coupling_hz2(lines, w1, &folded, 1.0, f).0;
        let error = [(got.re - kk) / kk, (got.im - dd * f) / (dd * f)];
        assert!(
            error.iter().all(|e| e.abs() <= 1e-4),
            "{got} vs ({kk}, {}): {error:?}",
            dd * f
        );
        let g = modes.map(|(fk, qk)| resonator(fk, qk, f));
        let phasor = [0, 1].map(|k| Folded::phasor(g, k, f));
        let old = coupling_hz2(lines, w1, &phasor, 1.0, f).0;
        assert!((old.im - dd * f).abs() > 1e-2 * dd * f, "{old}");
    }
}
