//! Exact steady state of the linear gyroscope model, and the paper's equations.
//!
//! # Model and conventions
//!
//! Paper eqs (1)/(3) generalized to mismatched modes and mode couplings
//! (see [`crate::device`]):
//!
//! ```text
//! x1'' + B1 x1' - 2 lam Omz x2' + w1^2 x1 + d x2' + k x2 = f1
//! x2'' + B2 x2' + 2 lam Omz x1' + w2^2 x2 + d x1' + k x1 = f2
//! Bk = wk/Qk, wk = 2 pi fk, wb = 2 pi carrier_hz,
//! k = 2 lam w1 Omq (quadrature), d = 2 lam Omd (damping coupling).
//! Readout:     f1 = F1 cos(wb t),             f2 = F2 sin(wb t)
//!              z1 = DC[x1 F1 cos(wb t)],      z2 = DC[x2 F2 sin(wb t)]
//! Calibration: f1 = F1 cos(wb t) cos(Om t),   f2 = F2 sin(wb t) sin(Om t),  Omz = 0
//!              z1 = DC[x1 F2 sin(wb t) sin(Om t)],  z2 = DC[x2 F1 cos(wb t) cos(Om t)]
//! ```
//!
//! A calibration frequency `f_cal` (Hz) is the virtual rate `Om = 2 pi f_cal`
//! rad/s = `360 f_cal` deg/s. Readout outputs are negative for a positive rate,
//! calibration outputs positive (matched modes: ratio = -2 lam).
//!
//! # Exact steady state (continuous time, no sampling/hold/quantization)
//!
//! With `Dk(w) = wk^2 - w^2 + j w Bk`, `c = 2 lam Omz wb` and the coupling
//! `kap(w) = k + j w d` (both modes alike), the phasors at one frequency
//! solve a 2x2 system: in readout `[[D1, kap - j c], [kap + j c, D2]] X =
//! [F1, -j F2]` at `wb`. Without coupling (`det' = D1 D2 - c^2`):
//!
//! ```text
//! z1 = F1/2 Re[(F1 D2 + c F2)/det'] = F1/2 { F1 Re(1/D1) + Re[c (F2 D1 + c F1)/(D1 det')] }
//! z2 = F2/2 Re[(F2 D1 + c F1)/det'] = F2/2 { F2 Re(1/D2) + Re[c (F1 D2 + c F2)/(D2 det')] }
//! ```
//!
//! The second form (offset + rate term) is what is evaluated: it avoids the
//! cancellation between a large offset and a tiny rate signal. The coupling
//! adds to the phasors `X1'` and `Y2' = j X2'` inside the brackets, with
//! `det = det' - kap^2`:
//!
//! ```text
//! X1 = X1' + kap (j F2 + kap X1') / det,    Y2 = Y2' + kap (-j F1 + kap Y2') / det
//! ```
//!
//! In calibration (`Omz = 0`) each mode sees tones at `wb -+ Om` from both
//! drives, through `H = M^-1`: `Hkk = 1/Dk + kap^2/(Dk det)`, `H12 = H21 =
//! -kap/det`, `det = D1 D2 - kap^2`. The drive phasors are (F1/2, F2/2) at
//! wb - Om and (F1/2, -F2/2) at wb + Om; only equal frequencies give DC:
//!
//! ```text
//! z1 = F2/4 Re[X1(wb-Om) - X1(wb+Om)],   z2 = F1/4 Re[X2(wb-Om) + X2(wb+Om)]
//! ```
//!
//! Without coupling `Hk(a) - Hk(b) = (b - a)(j Bk - a - b)/(Dk(a) Dk(b))` gives
//! the closed form, and the coupling adds `H12`'s sum (an offset that does not
//! vanish at Om = 0) and the `kap^2` terms' difference:
//!
//! ```text
//! zk = F1 F2/8 Re[Hk(wb-Om) - Hk(wb+Om)] = F1 F2 Om/4 Re[(j Bk - 2 wb)/(Dk(wb-Om) Dk(wb+Om))]
//! ```
//!
//! Small-signal scale factors (exact derivatives at 0, per rad/s; `'` is
//! d/dw, `det = D1 D2 - kap^2` at wb):
//!
//! ```text
//! SF_read,1 = SF_read,2 = lam wb F1 F2 Re[1/det]           (both outputs identical)
//! SF_cal,1  = F1 F2/4 Re[-H11'] = F1 F2/4 Re[(D1' D2^2 + D2' kap^2 - 2 D2 kap kap')/det^2]
//! ```
//!
//! and `SF_cal,2` with 1 and 2 swapped (`D' = j B - 2 wb`, `kap' = j d`).
//! Every coupling term is added to the uncoupled value and is exactly zero
//! without coupling, so the functions then give the uncoupled theory bit for
//! bit.
//!
//! All `Dk` are evaluated as `(wk - wb)(wk + wb) + j wb Bk` with `wk - wb`
//! formed from `fk - fb` (exact in f64 for close frequencies), and everything is
//! normalized by `wb^2` so no intermediate can overflow.
//!
//! # Units
//!
//! Frequencies in Hz, rates in rad/s unless a name says `_dps` (deg/s), forces
//! per unit mass `F1`, `F2` in N/kg, positions in m, `z` in m^2/s^2 (m x N/kg),
//! scale factors in (m^2/s^2) per rad/s.
//!
//! The functions do not validate their inputs (a NaN or a zero frequency
//! propagates to the result); the simulator's `GyroModel::new` does.

use nalgebra::Complex;
use std::f64::consts::TAU;

use crate::device::GyroParams;

type C64 = Complex<f64>;

/// A gyroscope plus its excitation: everything the steady state depends on
/// (deserializable with the same names; the couplings default to 0).
#[derive(Clone, Debug, PartialEq, serde::Deserialize)]
pub struct Device {
    /// Resonance frequency of mode 1 (Hz).
    pub f1_hz: f64,
    /// Resonance frequency of mode 2 (Hz).
    pub f2_hz: f64,
    /// Quality factor of mode 1.
    pub q1: f64,
    /// Quality factor of mode 2.
    pub q2: f64,
    /// Angular gain lambda.
    pub angular_gain: f64,
    /// Quadrature (stiffness) coupling Omq (deg/s; [`GyroParams`]).
    #[serde(default)]
    pub quadrature_dps: f64,
    /// Damping coupling Omd (deg/s; [`GyroParams`]).
    #[serde(default)]
    pub damping_coupling_dps: f64,
    /// Excitation (carrier) frequency `fb`, `wb = 2 pi fb` (Hz).
    pub carrier_hz: f64,
    /// Drive amplitude F1 on mode 1 (force per unit mass) (N/kg).
    pub f1_force: f64,
    /// Drive amplitude F2 on mode 2 (force per unit mass) (N/kg).
    pub f2_force: f64,
}

impl Device {
    /// The mechanical parameters of the device.
    pub fn gyro_params(&self) -> GyroParams {
        GyroParams {
            f1_hz: self.f1_hz,
            f2_hz: self.f2_hz,
            q1: self.q1,
            q2: self.q2,
            angular_gain: self.angular_gain,
            quadrature_dps: self.quadrature_dps,
            damping_coupling_dps: self.damping_coupling_dps,
        }
    }
}

/// Per-mode quantities normalized by wb: `dk(w) = Dk(w)/wb^2`, `bk = Bk/wb`.
struct Norm {
    wb: f64,
    /// (wk - wb), (wk + wb) (rad/s)
    delta: [f64; 2],
    sigma: [f64; 2],
    /// Bk / wb
    b: [f64; 2],
    /// Quadrature stiffness k / wb^2.
    k: f64,
    /// Damping coupling d / wb.
    d: f64,
}

/// The coupling's part of the response `H = M^-1` at one frequency, times
/// wb^2 (`M = [[d1, kap - c], [kap + c, d2]]`, module header; `c = j w 2
/// lam Omz`, 0 at rest).
struct Coupling {
    /// `(kap^2 - c^2) / (dk det)`: what the coupling adds to `Hkk = 1/dk`.
    extra: [C64; 2],
    /// `[H12, H21] = [-(kap - c), -(kap + c)] / det` (equal at rest).
    cross: [C64; 2],
}

impl Norm {
    fn new(dev: &Device) -> Norm {
        let fb = dev.carrier_hz;
        let wb = TAU * fb;
        let f = [dev.f1_hz, dev.f2_hz];
        let q = [dev.q1, dev.q2];
        let gyro = dev.gyro_params();
        Norm {
            wb,
            delta: [TAU * (f[0] - fb), TAU * (f[1] - fb)],
            sigma: [TAU * (f[0] + fb), TAU * (f[1] + fb)],
            b: [f[0] / fb / q[0], f[1] / fb / q[1]],
            k: gyro.quadrature_stiffness() / (wb * wb),
            d: gyro.damping_coupling() / wb,
        }
    }

    /// `Dk(wb + dw) / wb^2` for mode k.
    fn d(&self, k: usize, dw: f64) -> C64 {
        let wb2 = self.wb * self.wb;
        let re = (self.delta[k] - dw) * (self.sigma[k] + dw) / wb2;
        let im = (self.wb + dw) * self.b[k] / self.wb;
        C64::new(re, im)
    }

    /// The coupling `kap(w) / wb^2 = (k + j w d) / wb^2` at `w = wb + dw`.
    fn kappa(&self, dw: f64) -> C64 {
        C64::new(self.k, (self.wb + dw) / self.wb * self.d)
    }

    /// The coupling's part of the response at `wb + dw` with the device
    /// turning at `c_wb` = 2 lam Omz / wb (0 at rest; exactly zero
    /// without coupling and rate, and at rest the same bits as without
    /// the rate's terms).
    fn coupling(&self, dw: f64, c_wb: f64) -> Coupling {
        let d = [self.d(0, dw), self.d(1, dw)];
        let kap = self.kappa(dw);
        // c / wb^2 = j w 2 lam Omz / wb^2 at w = wb + dw.
        let c = C64::new(0.0, (self.wb + dw) / self.wb * c_wb);
        let pair = kap * kap - c * c;
        let det = d[0] * d[1] - pair;
        Coupling {
            extra: d.map(|dk| pair / (dk * det)),
            cross: [-(kap - c) / det, -(kap + c) / det],
        }
    }
}

/// Exact steady-state readout outputs `[z1, z2]` (m^2/s^2) at rate `omz_rad_s`,
/// offsets included (coupled 2x2 phasor solve at `wb`, no narrow-band approximation).
pub fn readout_z(dev: &Device, omz_rad_s: f64) -> [f64; 2] {
    readout_z_lagged(dev, omz_rad_s, 0.0)
}

/// [`readout_z`] with the responses lagging their references by a further
/// `lag_rad` (a residual loop phase error): each response phasor times
/// e^(-j lag) before the mixer's real part.
pub fn readout_z_lagged(dev: &Device, omz_rad_s: f64, lag_rad: f64) -> [f64; 2] {
    let n = Norm::new(dev);
    let rot = C64::from_polar(1.0, -lag_rad);
    let (f1, f2) = (dev.f1_force, dev.f2_force);
    let d1 = n.d(0, 0.0);
    let d2 = n.d(1, 0.0);
    // c / wb^2
    let c = 2.0 * dev.angular_gain * omz_rad_s / n.wb;
    let det = d1 * d2 - c * c;
    let scale = 1.0 / (2.0 * n.wb * n.wb);
    // The uncoupled phasors X1 and Y2 = j X2 (times wb^2), then the coupling's part.
    let x1 = f1 * d1.inv() + c * (f2 * d1 + c * f1) / (d1 * det);
    let y2 = f2 * d2.inv() + c * (f1 * d2 + c * f2) / (d2 * det);
    let kap = n.kappa(0.0);
    let det = det - kap * kap;
    let j = C64::i();
    let x1 = x1 + kap * (j * f2 + kap * x1) / det;
    let y2 = y2 + kap * (-j * f1 + kap * y2) / det;
    [f1 * (rot * x1).re * scale, f2 * (rot * y2).re * scale]
}

/// Exact steady-state calibration outputs `[z1, z2]` (m^2/s^2) at calibration
/// (modulation) frequency `f_cal_hz`, i.e. virtual rate `Om = 2 pi f_cal_hz`.
pub fn calibration_z(dev: &Device, f_cal_hz: f64) -> [f64; 2] {
    let n = Norm::new(dev);
    let om = TAU * f_cal_hz;
    let k = dev.f1_force * dev.f2_force * om / (4.0 * n.wb.powi(3));
    let (f1, f2) = (dev.f1_force, dev.f2_force);
    // The coupling's part (module header): H12's sum, the kap^2 terms' difference.
    let [lo, hi] = [-om, om].map(|dw| n.coupling(dw, 0.0));
    let cross = (lo.cross[0] + hi.cross[0]) / 2.0;
    let extra = |m: usize| (lo.extra[m] - hi.extra[m]) / 2.0;
    let coupled = [
        f2 * (f1 * extra(0) + f2 * cross),
        f1 * (f1 * cross + f2 * extra(1)),
    ];
    let z = |m: usize| {
        let num = C64::new(-2.0, n.b[m]);
        k * (num / (n.d(m, -om) * n.d(m, om))).re + coupled[m].re / (4.0 * n.wb * n.wb)
    };
    [z(0), z(1)]
}

/// Exact steady-state calibration outputs `[z1, z2]` (m^2/s^2) when the
/// reference envelopes lead the drive envelopes by `envelope_lead_rad`
/// (references cos(Om t + lead) cos(wb t) and sin(Om t + lead) sin(wb t)
/// against drives cos(Om t) cos(wb t) and sin(Om t) sin(wb t)).
///
/// Sideband by sideband: drive 1 is F1/2 at wb + Om and at wb - Om, drive
/// 2 is -F2/2 and +F2/2; at rest x_k = Re sum (H_k1(w) c_1(w) + H_k2(w)
/// c_2(w)) e^(iwt) (module header; without coupling H_kk = 1 / (w_k^2 -
/// w^2 + i w w_k / Q_k) and H_12 = H_21 = 0), and the mean of a product of
/// two tones at the same frequency is Re(a conj(b)) / 2. Output 1 mixes x1
/// with reference 2, output 2 x2 with reference 1. With no lead this is
/// [`calibration_z`]. Without coupling, a lead L adds to output k
/// -L F1 F2 (Im H_k(wb - Om) + Im H_k(wb + Om)) / 8: the resonant part of
/// the response, which dwarfs the calibration signal (proportional to
/// Om), so a lead of Om T / 2 (the half clock the datapath's envelope
/// alignment leaves) moves a low-Q device's calibration scale factor by
/// parts in 1e4 (`hdl/src/settings.rs`).
pub fn calibration_z_with_envelope_lead(
    dev: &Device,
    f_cal_hz: f64,
    envelope_lead_rad: f64,
) -> [f64; 2] {
    calibration_z_of_datapath(dev, f_cal_hz, envelope_lead_rad, [1.0, 1.0])
}

/// [`calibration_z_with_envelope_lead`] with the drive's sidebands at
/// wb - Om and wb + Om scaled by `sideband_gain` (the DAC hold's sinc at
/// each sideband over its value at the carrier, which `dev`'s forces
/// already carry): the references are digital words and carry no hold.
pub fn calibration_z_of_datapath(
    dev: &Device,
    f_cal_hz: f64,
    envelope_lead_rad: f64,
    sideband_gain: [f64; 2],
) -> [f64; 2] {
    calibration_z_lagged(dev, f_cal_hz, envelope_lead_rad, sideband_gain, 0.0)
}

/// [`calibration_z_of_datapath`] with the responses lagging their
/// references by a further `lag_rad` (as [`readout_z_lagged`]).
pub fn calibration_z_lagged(
    dev: &Device,
    f_cal_hz: f64,
    envelope_lead_rad: f64,
    sideband_gain: [f64; 2],
    lag_rad: f64,
) -> [f64; 2] {
    calibration_z_turning(
        dev,
        f_cal_hz,
        envelope_lead_rad,
        sideband_gain,
        lag_rad,
        0.0,
    )
}

/// [`calibration_z_lagged`] with the device turning at `omz_rad_s`
/// during the calibration (at 0 the same bits). The Coriolis term enters
/// the two cross responses with opposite signs (`H12 = -(kap - c) /
/// det`, `H21 = -(kap + c) / det`, `c = j w 2 lam Omz`): output k's own
/// reference mixes drive k's sidebands that reach x_k through mode 1 - k,
/// a term linear in the rate. On a detuned output it is the resonant
/// response of the other mode, far above the calibration signal: the
/// consumer device's (`tests/data/field_consumer.toml`) output 2 moves by
/// 4.6% per deg/s.
pub fn calibration_z_turning(
    dev: &Device,
    f_cal_hz: f64,
    envelope_lead_rad: f64,
    sideband_gain: [f64; 2],
    lag_rad: f64,
    omz_rad_s: f64,
) -> [f64; 2] {
    let n = Norm::new(dev);
    let rot = C64::from_polar(1.0, -lag_rad);
    let om = TAU * f_cal_hz;
    let wb2 = n.wb * n.wb;
    let lead = C64::new(envelope_lead_rad.cos(), envelope_lead_rad.sin());
    let (f1, f2) = (dev.f1_force, dev.f2_force);
    // Sidebands [wb - Om, wb + Om]: drive and reference coefficients.
    let [g0, g1] = sideband_gain;
    let drive = [
        [f1 / 2.0 * g0, f1 / 2.0 * g1],
        [f2 / 2.0 * g0, -f2 / 2.0 * g1],
    ]
    .map(|c| c.map(|x| C64::new(x, 0.0)));
    let reference = [
        [f1 / 2.0 * lead.conj(), f1 / 2.0 * lead],
        [f2 / 2.0 * lead.conj(), -f2 / 2.0 * lead],
    ];
    let dw = [-om, om];
    let c_wb = 2.0 * dev.angular_gain * omz_rad_s / n.wb;
    let coupling = dw.map(|dw| n.coupling(dw, c_wb));
    let z = |k: usize| {
        (0..2)
            .map(|s| {
                let own = (1.0 / (n.d(k, dw[s]) * wb2) + coupling[s].extra[k] / wb2) * rot;
                let cross = coupling[s].cross[k] / wb2 * rot;
                let x = own * drive[k][s] + cross * drive[1 - k][s];
                0.5 * (x * reference[1 - k][s].conj()).re
            })
            .sum::<f64>()
    };
    [z(0), z(1)]
}

/// Exact small-signal readout scale factors `dz/dOmz` at `Omz = 0`
/// ((m^2/s^2)/(rad/s)); the two outputs are identical in exact arithmetic.
pub fn sf_read_per_rad_s(dev: &Device) -> [f64; 2] {
    let n = Norm::new(dev);
    let kap = n.kappa(0.0);
    let sf = dev.angular_gain * dev.f1_force * dev.f2_force / n.wb.powi(3)
        * (n.d(0, 0.0) * n.d(1, 0.0) - kap * kap).inv().re;
    [sf, sf]
}

/// Exact small-signal calibration scale factors `dz/dOm` at `Om -> 0`
/// ((m^2/s^2)/(rad/s) of virtual rate): `F1 F2/4 Re(-Hkk')` (module
/// header), evaluated as the uncoupled `dk'/dk^2` plus what the coupling
/// adds, `kap [dk' kap (2 d1 d2 - kap^2) + dk^2 (dj' kap - 2 dj kap')] /
/// (dk^2 det^2)` (j the other mode; derivatives in w / wb).
pub fn sf_cal_per_rad_s(dev: &Device) -> [f64; 2] {
    let n = Norm::new(dev);
    let k = dev.f1_force * dev.f2_force / (4.0 * n.wb.powi(3));
    let d = [n.d(0, 0.0), n.d(1, 0.0)];
    let slope = [0, 1].map(|m| C64::new(-2.0, n.b[m]));
    let (kap, kap_slope) = (n.kappa(0.0), C64::new(0.0, n.d));
    let det = d[0] * d[1] - kap * kap;
    let sf = |m: usize| {
        let o = 1 - m;
        let coupled = kap
            * (slope[m] * kap * (2.0 * d[0] * d[1] - kap * kap)
                + d[m] * d[m] * (slope[o] * kap - 2.0 * d[o] * kap_slope))
            / (d[m] * d[m] * det * det);
        k * (slope[m] / (d[m] * d[m]) + coupled).re
    };
    [sf(0), sf(1)]
}

/// Small-signal ratio `SF_read / SF_cal` per output (what calibration predicts).
pub fn sf_ratio(dev: &Device) -> [f64; 2] {
    let r = sf_read_per_rad_s(dev);
    let c = sf_cal_per_rad_s(dev);
    [r[0] / c[0], r[1] / c[1]]
}

/// `f(x) = x/(x^2 + 1)` of eqs (2) and (4).
fn paper_f(x: f64) -> f64 {
    x / (x * x + 1.0)
}

/// Paper eq (2), matched modes, as printed: `z1 = z2 = -(Q F1 F2 / (2 w0^2)) f(2 lam Omz Q / w0)`,
/// with `w0 = wb` (carrier) and `Q = q1`. Exact for matched modes excited at
/// resonance (`f1 = f2 = carrier`, `q1 = q2`); ignores `f1_hz`, `f2_hz`, `q2`.
pub fn eq2_readout_z(dev: &Device, omz_rad_s: f64) -> f64 {
    let w0 = TAU * dev.carrier_hz;
    let q = dev.q1;
    -q * dev.f1_force * dev.f2_force / (2.0 * w0 * w0)
        * paper_f(dev.angular_gain * 2.0 * omz_rad_s * q / w0)
}

/// Paper eq (4), matched modes, as printed: `z1 = z2 = (1/2)(Q F1 F2 / (2 w0^2)) f(2 Om Q / w0)`,
/// `Om = 2 pi f_cal_hz`, with `w0 = wb` and `Q = q1`. Narrow-band: for matched
/// modes at resonance it differs from the exact value by O((Om/w0)^2).
pub fn eq4_calibration_z(dev: &Device, f_cal_hz: f64) -> f64 {
    let w0 = TAU * dev.carrier_hz;
    let q = dev.q1;
    let om = TAU * f_cal_hz;
    0.5 * q * dev.f1_force * dev.f2_force / (2.0 * w0 * w0) * paper_f(2.0 * om * q / w0)
}

/// Paper eq (5), per rad/s, with `w0 = wb`, `dwk = wk - wb`:
///
/// ```text
/// SF_read = (lam F1 F2 / w0) (4 dw1 dw2 - b1 b2) / ([(2 dw1)^2 + b1^2][(2 dw2)^2 + b2^2]),  bk = w0/Qk
/// ```
///
/// identical to the printed formula when `q1 = q2` (the paper assumes one Q);
/// with unequal Q this is its narrow-band generalization. Signed like the exact
/// readout (negative near resonance): it is the narrow-band limit of
/// [`sf_read_per_rad_s`], not a magnitude.
pub fn eq5_sf_read_per_rad_s(dev: &Device) -> f64 {
    let w0 = TAU * dev.carrier_hz;
    let dw1 = TAU * (dev.f1_hz - dev.carrier_hz);
    let dw2 = TAU * (dev.f2_hz - dev.carrier_hz);
    let (b1, b2) = (w0 / dev.q1, w0 / dev.q2);
    dev.angular_gain * dev.f1_force * dev.f2_force / w0 * (4.0 * dw1 * dw2 - b1 * b2)
        / ((4.0 * dw1 * dw1 + b1 * b1) * (4.0 * dw2 * dw2 + b2 * b2))
}

/// Paper eq (6), per rad/s of virtual rate, `[SF_cal1, SF_cal2]` with `w0 = wb`,
/// `dwk = wk - wb`, `bk = w0/Qk` (the paper: "substituting dw2 for dw1"):
///
/// ```text
/// SF_cal,k = (F1 F2 / (2 w0)) (bk^2 - (2 dwk)^2) / [(2 dwk)^2 + bk^2]^2
/// ```
///
/// Signed like the exact calibration output; exact at a resonant output.
pub fn eq6_sf_cal_per_rad_s(dev: &Device) -> [f64; 2] {
    let w0 = TAU * dev.carrier_hz;
    let one = |f_hz: f64, q: f64| {
        let dw = TAU * (f_hz - dev.carrier_hz);
        let b = w0 / q;
        let den = 4.0 * dw * dw + b * b;
        dev.f1_force * dev.f2_force / (2.0 * w0) * (b * b - 4.0 * dw * dw) / (den * den)
    };
    [one(dev.f1_hz, dev.q1), one(dev.f2_hz, dev.q2)]
}

/// Peak displacements `[|x1|, |x2|]` (m) of the readout steady state at rate
/// `omz_rad_s`: the moduli of the two phasors (used to set ADC gains).
pub fn readout_peak_displacement(dev: &Device, omz_rad_s: f64) -> [f64; 2] {
    let n = Norm::new(dev);
    let d1 = n.d(0, 0.0);
    let d2 = n.d(1, 0.0);
    let c = 2.0 * dev.angular_gain * omz_rad_s / n.wb;
    let kap = n.kappa(0.0);
    let det = d1 * d2 - c * c - kap * kap;
    // [[D1, kap - j c], [kap + j c, D2]] X = [F1, -j F2] (all over wb^2).
    let j = C64::new(0.0, 1.0);
    let (f1, f2) = (C64::new(dev.f1_force, 0.0), -j * dev.f2_force);
    let x1 = (d2 * f1 + j * c * f2 - kap * f2) / det;
    let x2 = (d1 * f2 - j * c * f1 - kap * f1) / det;
    let wb2 = n.wb * n.wb;
    [x1.norm() / wb2, x2.norm() / wb2]
}

/// Upper bound on the calibration displacements `[|x1|, |x2|]` (m) at
/// `f_cal_hz`: each mode sees tones at wb -+ Om of amplitude Fk/2 from its
/// own drive and F_j/2 from the other's through the coupling, so its peak
/// is at most the sum of the moduli of the responses, `|Hkk| <= 1/|Dk| +
/// |kap^2/(Dk det)|`.
pub fn calibration_peak_displacement(dev: &Device, f_cal_hz: f64) -> [f64; 2] {
    calibration_peak_turning(dev, f_cal_hz, 0.0)
}

/// [`calibration_peak_displacement`] with the device turning at
/// `omz_rad_s` (the cross responses `calibration_z_turning` has).
pub fn calibration_peak_turning(dev: &Device, f_cal_hz: f64, omz_rad_s: f64) -> [f64; 2] {
    let n = Norm::new(dev);
    let om = TAU * f_cal_hz;
    let wb2 = n.wb * n.wb;
    let force = [dev.f1_force, dev.f2_force];
    let c_wb = 2.0 * dev.angular_gain * omz_rad_s / n.wb;
    let coupling = [-om, om].map(|dw| n.coupling(dw, c_wb));
    let peak = |k: usize, f: f64| {
        let coupled: f64 = coupling
            .iter()
            .map(|c| 0.5 * (f * c.extra[k].norm() + force[1 - k] * c.cross[k].norm()))
            .sum();
        (0.5 * f * (1.0 / n.d(k, -om).norm() + 1.0 / n.d(k, om).norm()) + coupled) / wb2
    };
    [peak(0, force[0]), peak(1, force[1])]
}

/// The lead of the reference envelopes over the drive envelopes the
/// datapath leaves in calibration (rad): the references are lined up with
/// the drives' carrier to the half clock of the DAC's hold by `ref_phase`,
/// but their envelope is not, so it is off by Om T / 2
/// (`gyrocal_regs::plan`). Negligible in phase (1e-6 rad), but it mixes
/// the resonant part of the response into the calibration output: 2e-4 of
/// the calibration scale factor on a Q 200 device at 100 kHz and 3.33 MHz.
pub fn envelope_lead_rad(cal_hz: f64, clock_hz: f64) -> f64 {
    ENVELOPE_LEAD_SIGN * std::f64::consts::PI * cal_hz / clock_hz
}

/// The sign of the datapath's envelope lead (see `envelope_lead_rad`).
const ENVELOPE_LEAD_SIGN: f64 = -1.0;

/// Fundamental gain of the DAC's zero-order hold at `f_hz`, sin(x) / x with
/// x = pi f / f_clk.
pub fn hold_gain(f_hz: f64, clock_hz: f64) -> f64 {
    let x = std::f64::consts::PI * f_hz / clock_hz;
    x.sin() / x
}

#[cfg(test)]
mod tests {
    use super::*;

    fn device(f2_offset: f64, q: [f64; 2], carrier_offset: f64) -> Device {
        Device {
            f1_hz: 100.3e3,
            f2_hz: 100.3e3 + f2_offset,
            q1: q[0],
            q2: q[1],
            angular_gain: 0.7,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
            carrier_hz: 100.3e3 + carrier_offset,
            f1_force: 0.8,
            f2_force: 0.6,
        }
    }

    /// A lag of a quarter turn takes the quadrature part: z(lag) =
    /// cos(lag) z(0) + sin(lag) z(quarter turn) for every lag, and half a
    /// turn negates (the mixer's real part of a rotated phasor).
    #[test]
    fn a_lag_rotates_the_mixed_phasor() {
        let dev = device(-37.0, [5e4, 3e4], 12.0);
        let q = std::f64::consts::FRAC_PI_2;
        for lag in [0.3f64, -1.1, 2.0 * q] {
            let (c, s) = (lag.cos(), lag.sin());
            let read = [0.0, q, lag].map(|l| readout_z_lagged(&dev, 0.7, l));
            let cal = [0.0, q, lag].map(|l| calibration_z_lagged(&dev, 2.5, 0.01, [1.0, 0.99], l));
            for k in 0..2 {
                for z in [read, cal] {
                    let want = c * z[0][k] + s * z[1][k];
                    assert!(
                        (z[2][k] - want).abs() <= 1e-12 * z[0][k].hypot(z[1][k]),
                        "{lag} {k}"
                    );
                }
            }
        }
    }

    /// `dev` with 2000 deg/s of quadrature and 20 deg/s of damping coupling.
    fn coupled(dev: Device) -> Device {
        Device {
            quadrature_dps: 2000.0,
            damping_coupling_dps: 20.0,
            ..dev
        }
    }

    /// The calibration of a turning device against the 2x2 system
    /// inverted directly at each sideband, in physical units: `M(w) =
    /// [[D1, kap - j w 2 lam Omz], [kap + j w 2 lam Omz, D2]]` (the
    /// equations of motion in the module header), the drives' and
    /// references' sideband phasors as `calibration_z_turning` documents
    /// them, and z_k the mean of x_k times reference 1 - k. With and
    /// without couplings, lead, lag and sideband gains; at rest the same
    /// bits as `calibration_z_lagged`.
    #[test]
    fn a_turning_device_is_the_direct_inverse() {
        use nalgebra::Matrix2;
        let j = C64::i();
        for (dev, f_cal, omz) in [
            (device(-37.0, [5e4, 3e4], 12.0), 2.5, 0.3),
            (coupled(device(-37.0, [5e4, 3e4], 12.0)), 2.5, -0.05),
            (coupled(device(1e3, [200.0, 200.0], 0.0)), 300.0, 2.0),
        ] {
            let (lead, gains, lag) = (0.01, [1.0, 0.99], 0.2);
            let got = calibration_z_turning(&dev, f_cal, lead, gains, lag, omz);
            let (wb, om) = (TAU * dev.carrier_hz, TAU * f_cal);
            let gyro = dev.gyro_params();
            let (k, d) = (gyro.quadrature_stiffness(), gyro.damping_coupling());
            let wk = [TAU * dev.f1_hz, TAU * dev.f2_hz];
            let bk = [wk[0] / dev.q1, wk[1] / dev.q2];
            let (f1, f2) = (dev.f1_force, dev.f2_force);
            let lead = C64::from_polar(1.0, lead);
            let drive = [
                [f1 / 2.0 * gains[0], f1 / 2.0 * gains[1]],
                [f2 / 2.0 * gains[0], -f2 / 2.0 * gains[1]],
            ];
            let reference = [
                [f1 / 2.0 * lead.conj(), f1 / 2.0 * lead],
                [f2 / 2.0 * lead.conj(), -f2 / 2.0 * lead],
            ];
            let mut want = [0.0; 2];
            for (s, dw) in [-om, om].into_iter().enumerate() {
                let w = wb + dw;
                let dk = |m: usize| wk[m] * wk[m] - w * w + j * w * bk[m];
                let (kap, c) = (k + j * w * d, j * w * 2.0 * dev.angular_gain * omz);
                let m = Matrix2::new(dk(0), kap - c, kap + c, dk(1));
                let h = m.try_inverse().unwrap();
                let x = h * nalgebra::Vector2::new(C64::from(drive[0][s]), C64::from(drive[1][s]));
                for (kk, want) in want.iter_mut().enumerate() {
                    let x = x[kk] * C64::from_polar(1.0, -lag);
                    *want += 0.5 * (x * reference[1 - kk][s].conj()).re;
                }
            }
            let size = want[0].abs().max(want[1].abs());
            for kk in 0..2 {
                assert!(
                    (got[kk] - want[kk]).abs() <= 1e-9 * size,
                    "{dev:?} {omz}: {got:?} {want:?}"
                );
            }
            let rest = calibration_z_turning(&dev, f_cal, 0.01, gains, lag, 0.0);
            let lagged = calibration_z_lagged(&dev, f_cal, 0.01, gains, lag);
            assert_eq!(rest.map(f64::to_bits), lagged.map(f64::to_bits));
        }
    }

    #[test]
    fn no_envelope_lead_is_the_closed_form() {
        // With couplings too: the closed form plus the coupling's terms
        // against the sideband-by-sideband sum.
        for (dev, f) in [
            (device(1e3, [200.0, 200.0], 0.0), 300.0),
            (device(-37.0, [5e4, 3e4], 12.0), 2.5),
            (device(0.0, [1e3, 1e3], 0.0), 40.0),
            (coupled(device(1e3, [200.0, 200.0], 0.0)), 300.0),
            (coupled(device(-37.0, [5e4, 3e4], 12.0)), 2.5),
            (coupled(device(0.0, [1e3, 1e3], 0.0)), 40.0),
        ] {
            let a = calibration_z(&dev, f);
            let b = calibration_z_with_envelope_lead(&dev, f, 0.0);
            for k in 0..2 {
                assert!((a[k] / b[k] - 1.0).abs() < 1e-9, "{a:?} {b:?}");
            }
        }
    }

    #[test]
    fn a_small_lead_adds_the_resonant_part() {
        // First order in the lead L, from the sums in the function's doc:
        // dz_k = -L F1 F2 / 8 (Im H_k(wb - Om) + Im H_k(wb + Om)).
        let dev = device(1e3, [200.0, 200.0], 0.0);
        let f = 300.0;
        let lead = 1e-6;
        let z0 = calibration_z_with_envelope_lead(&dev, f, 0.0);
        let z1 = calibration_z_with_envelope_lead(&dev, f, lead);
        let n = Norm::new(&dev);
        let om = TAU * f;
        let im = |k: usize| -> f64 {
            [-om, om]
                .iter()
                .map(|&dw| (1.0 / (n.d(k, dw) * n.wb * n.wb)).im)
                .sum()
        };
        let f12 = dev.f1_force * dev.f2_force;
        let expected = [-lead * f12 / 8.0 * im(0), -lead * f12 / 8.0 * im(1)];
        for k in 0..2 {
            let got = z1[k] - z0[k];
            assert!(
                (got / expected[k] - 1.0).abs() < 1e-4,
                "output {}: {got} vs {}",
                k + 1,
                expected[k]
            );
        }
    }
}
