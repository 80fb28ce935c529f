//! Host-side identification of a drifting gyroscope through the gateware's
//! registers alone: f1, f2, Q1, Q2 and the loop (front-end) phase, each
//! with a 1-sigma uncertainty from the data.
//!
//! # What is measured
//!
//! In readout (SELECT = 0) with one drive on (AMP_k, the other 0), output k
//! is the mean of ADC_k times drive k's own word. At rest the modes are
//! uncoupled, so the ADC sees mode k's response to that word alone. With
//! REF_PHASE at its aligned value (carrier_step / 2, `settings`) the
//! mixer gives the in-phase part; with REF_PHASE advanced by a quarter
//! turn, the quadrature part. The complex response per drive LSB is
//!
//! ```text
//! Y(f) = 2 (z_I + j z_Q) / (dc_gain W^2) = C / ((fk - f)(fk + f) + j f bk),   C = G e^(-j phi)
//! ```
//!
//! with W the drive word's amplitude (known from AMP), dc_gain the filter's
//! (known from its settings), bk = fk / Qk the bandwidth (Hz), G > 0 the
//! product of drive gain, hold, pick-off and ADC gain (unknown, and not
//! needed), and phi the front end's unmodelled phase lag. This is the
//! exact steady state of the model (the DAC hold's delay is what
//! REF_PHASE's aligned value cancels; its gain, the hold's sinc, falls by
//! 2e-5 across a sweep, enough to pull fk, and is in the fine fit's model).
//!
//! # How
//!
//! 1. Coarse search from the datasheet frequency (`search`): Y at three
//!    carriers around a centre, and the narrow-band form
//!    1 / (Y f) = a + b (f - f0) (linear in two complex unknowns) gives fk,
//!    bk and the peak response even many bandwidths away; the centre moves
//!    there, the three carriers spread to a quarter of the move, until it
//!    lands within a quarter bandwidth. The drive amplitude is set from the
//!    predicted peak so that the ADC stays below `ADC_TARGET` of full
//!    scale; a measurement during which the ADC clipped (`ADC_CLIP`
//!    counts, or a response above `ADC_NEAR_CLIP` of full scale) is made
//!    again at a quarter of the amplitude (`probe`). Mode 2's search
//!    starts at mode 1's identified frequency plus the datasheet's split.
//!    When the search cannot converge (a datasheet off by more than the
//!    narrow-band form reaches: far from resonance the response is nearly
//!    real and its bandwidth lost in the noise), a scan of `SCAN_POINTS`
//!    carriers over +-`SCAN_SPAN` of the guess (process spread is 1 to 5%)
//!    and the exact form 1 / Y = (fk^2 - f^2 + j f bk) / C, linear in its
//!    three complex coefficients over all the scan's points (`fit`),
//!    give an estimate; scans zooming in around it (each a third of the
//!    last one's span, `search::scan`) narrow it down to a couple of
//!    bandwidths, where a second search starts.
//! 2. Fine sweep: `FINE_POINTS` carriers over +-`FINE_SPAN` bandwidths,
//!    up then down, so that any settling lag shows as a misfit instead of
//!    a shift. Each point waits `SETTLE_TAUS` amplitude time constants
//!    after a carrier step (the coarse search's bandwidth gives the time
//!    constant; the datasheet's until then, each with a 20% margin) and the
//!    filter's settling after a REF_PHASE step.
//! 3. Gauss-Newton fit (`fit`) of the exact form above (4 real unknowns: C, fk, bk)
//!    from the narrow-band solution, each mode alone; then again without
//!    what the waits leave of the resonator's ringing after each carrier
//!    step, which that fit and the sweep's timing predict (`settling`:
//!    the SAMPLE_COUNT reads either side of each step and each window's
//!    sample counts).
//! 4. Both fits again with the front end's group delay in the model
//!    (`front`): the line through the two modes' phases gives it (with
//!    the modes not resolved, one more measurement `front::PROBE_SPAN`
//!    bandwidths each side of each mode), and a phase sloping across a
//!    resonance narrows it (2 deg of pick-off lag
//!    had put Q 0.86 phi high on every device, and its misfit had doubled
//!    fk's sigma). Uncertainties: the largest of the residuals' (variance
//!    times the inverse normal matrix, propagated to Qk = fk / bk and
//!    phi = -arg C), a jackknife over the carriers, and the table core's
//!    carrier lines in each point with the noise the residuals leave
//!    beside them (`spurs`), then in quadrature the waits' sigmas, the
//!    delay's sigma, the bound of the front end's unmeasurable gain slope
//!    and its weighting of the DAC's images (`with_uncertainty`).
//!
//! The loop phase is read off the line through the two modes' phi at the
//! operating carrier (both references go through one REF_PHASE, so one
//! common correction is what the gateware can apply); the line's slope is
//! the front end's group delay, which the prediction needs: a front end
//! that lags the carrier by phi usually delays the envelope too (a pure
//! delay by phi / w, the pick-off model of `frontend::PickoffPhase` by
//! about sin(phi) cos(phi) / w), and in calibration that mixes the
//! resonant part of the response into the output (13% of the detuned
//! output of a 25 kHz device with 3 deg, measured).

mod departures;
pub use departures::datasheet_departures;
mod fit;
mod front;
mod probe;
mod search;
pub mod settling;
pub use settling::filter_response;
mod spurs;
pub use spurs::point_spur_sd;

use crate::board::Board;
use crate::device::GyroParams;
use crate::error::Error;
use crate::knowns::{FILTER_SETTLE, Knowns, TAU_MARGIN};
pub(crate) use front::FrontEnd;
use gyrocal_regs::datapath::CarrierProfile;
use nalgebra::Complex;
use probe::Prober;
use serde::Serialize;
use std::f64::consts::{PI, TAU};

type C64 = Complex<f64>;

/// Amplitude time constants Qk / (pi fk) waited after a carrier step: the
/// transient falls to e^-12 = 6e-6 of the step in response.
pub const SETTLE_TAUS: f64 = 12.0;
/// Fraction of ADC full scale the identification drives the peak to.
pub const ADC_TARGET: f64 = 0.5;
/// Above this fraction of full scale a response is taken as clipped even
/// before the ADC_CLIP counts say so (the counts see words within 1/128
/// of full scale only).
pub const ADC_NEAR_CLIP: f64 = 0.8;
/// Carriers of the fine sweep (each measured going up and coming down).
pub const FINE_POINTS: usize = 5;
/// Half-width of the fine sweep in bandwidths bk.
pub const FINE_SPAN: f64 = 1.5;
/// z samples averaged for each of I and Q.
pub const SAMPLES_PER_PHASE: u64 = 128;

/// The length of each I and Q window (s): `SAMPLES_PER_PHASE` z samples.
fn window_s(knowns: &Knowns) -> f64 {
    SAMPLES_PER_PHASE as f64 * f64::from(knowns.filter.decimation) / knowns.clock_hz
}
/// What the waits leave of a step in the response, relative to the peak
/// response: the resonator's transient e^(-pi bk t) after the `waited_s`
/// from a carrier step to the I window, with the fitted bandwidth bk (the
/// wait is `SETTLE_TAUS` time constants of the coarse search's bandwidth
/// with the 20% `TAU_MARGIN`, so some e^-14.4 when that bandwidth was
/// right, e^-12 when it was 20% high). It is a bias, not noise: it moves
/// fk by [`settle_sd`] times this times bk, Q by that fraction and the
/// phase by that many radians, the up and down sweeps cancelling its
/// first order in fk. (The residuals see the part that differs between a
/// carrier's two visits: on a fork part with no ADC noise, twice the wait
/// halved Q1's residual sigma.) The fit takes the residue off each point
/// ([`settling`]); what it may leave is this times `Waits::kept`.
pub fn settling_residue(bk_hz: f64, waited_s: f64) -> f64 {
    (-PI * bk_hz * waited_s).exp()
}
/// How far the filter's residue after the REF_PHASE step, `FILTER_SETTLE`
/// of the step from I to Q kept in the Q window, moves fk (in bk), Q
/// (relative) and the phase (rad), per unit of residue: 0.185, 0.368 and
/// 0.519 at worst over C's phase and seven modes, from the fit itself
/// (`fit::tests::the_ref_phase_residue_moves_the_estimates_within_its_bound`).
pub const REF_STEP_PULL: [f64; 3] = [0.2, 0.4, 0.55];
/// The same pulls' RMS over C's phase, which no sweep chooses, and the
/// seven modes: 0.131, 0.261 and 0.500 (the same test). What the
/// uncertainty takes as the residue's 1-sigma (`sweep_uncertainty`): the
/// pull of fk and Q turns with C's phase as a sine does (RMS the peak
/// over sqrt 2), the phase's hardly at all.
pub const REF_STEP_SD: [f64; 3] = [0.14, 0.28, 0.52];
/// How far the resonator's settling residue (`Waits::settling`, relative
/// to the carrier step) moves fk (in bk), Q (relative) and the phase
/// (rad), per unit of residue, at its RMS over the transient's turn during
/// the wait, which no sweep chooses, against the delay u = pi bk D from
/// the I window to the Q window (`Waits::quarter_s`): the Q window sees
/// e^-u of the residue. The up and down sweeps cancel the first order in
/// fk, not in Q, whose pull comes from the sweep's ends, and which the
/// delay takes out of the Q window (0.768 at u = 0, 0.21 from 2.4); fk's
/// rises from 0.085 to 0.107
/// (`fit::tests::the_settling_residue_moves_the_estimates_by_settle_sd`).
/// What the uncertainty takes as the residue's 1-sigma
/// (`sweep_uncertainty`, through [`settle_sd`]).
pub const SETTLE_SD: [(f64, [f64; 3]); 12] = [
    (0.0, [0.09, 0.8, 0.18]),
    (0.1, [0.09, 0.72, 0.17]),
    (0.2, [0.092, 0.65, 0.165]),
    (0.3, [0.094, 0.59, 0.162]),
    (0.4, [0.096, 0.535, 0.16]),
    (0.6, [0.097, 0.45, 0.155]),
    (0.8, [0.097, 0.39, 0.151]),
    (1.2, [0.098, 0.33, 0.145]),
    (1.6, [0.103, 0.285, 0.145]),
    (2.4, [0.111, 0.222, 0.143]),
    (3.2, [0.111, 0.226, 0.13]),
    (5.0, [0.111, 0.216, 0.13]),
];

/// [`SETTLE_SD`] at the delay `u` (pi bk times the time from the I
/// window's start to the Q window's): linear between its delays, its
/// last beyond them (the residue has left the Q window).
///
/// ```
/// use gyrocal_host::identify::{SETTLE_SD, settle_sd};
/// assert_eq!(settle_sd(0.0), SETTLE_SD[0].1);
/// assert_eq!(settle_sd(1e3), SETTLE_SD[SETTLE_SD.len() - 1].1);
/// ```
pub fn settle_sd(u: f64) -> [f64; 3] {
    let last = SETTLE_SD[SETTLE_SD.len() - 1];
    match SETTLE_SD.windows(2).find(|w| u < w[1].0) {
        Some([(u0, a), (u1, b)]) => {
            let x = ((u - u0) / (u1 - u0)).max(0.0);
            std::array::from_fn(|i| a[i] + x * (b[i] - a[i]))
        }
        _ => last.1,
    }
}
/// Most coarse-search moves before giving up.
pub const MAX_MOVES: usize = 12;
/// Half-width of the fallback scan, relative to the guessed frequency:
/// the process spread of a resonance.
pub const SCAN_SPAN: f64 = 0.05;
/// Carriers of the fallback scan (odd: one at the guess).
pub const SCAN_POINTS: usize = 21;

/// Fundamental amplitude (LSB) of a readout drive word for a Q1.15
/// amplitude on the core with `profile`
/// (`gyrocal_regs::datapath::readout_word`), unsigned.
pub fn readout_word(profile: CarrierProfile, amp: i16) -> f64 {
    gyrocal_regs::datapath::readout_word(profile, amp).abs()
}

/// A value and its 1-sigma uncertainty.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// 1-sigma uncertainty.
    pub uncertainty: f64,
}

impl Estimate {
    /// An estimate within its noise taken as none: 0, with the value and
    /// its sigma in quadrature as the sigma (what an unseen one could
    /// leave). The cycle does so with a damping coupling
    /// (`selfcal::DAMPING_SEEN`) and the rate during it
    /// (`selfcal::predicted_rate`).
    pub fn as_unseen(self) -> Estimate {
        Estimate {
            value: 0.0,
            uncertainty: self.value.hypot(self.uncertainty),
        }
    }
}

/// A mode coupling measured at rest ([`crate::coupling`]), in deg/s at
/// the datasheet's lambda: the host measures a stiffness (Hz^2) and turns
/// it into deg/s with that lambda, so the figure is off by lambda's error
/// against the device's coupling, while the prediction, which turns it
/// back with the same lambda, does not see lambda at all.
///
/// ```
/// use gyrocal_host::identify::{CouplingFigure, Estimate};
/// // 3 deg/s measured to 0.02, lambda known to 2.5%: 0.075 from lambda.
/// let c = CouplingFigure::new(Estimate { value: 3.0, uncertainty: 0.02 }, 0.025);
/// assert!((c.uncertainty - 0.02f64.hypot(0.075)).abs() < 1e-15);
/// assert_eq!(c.measurement_uncertainty, 0.02);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CouplingFigure {
    /// The coupling (deg/s).
    pub value: f64,
    /// Its 1-sigma against the device's coupling in deg/s: the
    /// measurement's and lambda's (the datasheet's relative 1-sigma of
    /// lambda times the value) in quadrature.
    pub uncertainty: f64,
    /// The measurement's 1-sigma alone (batch spread and the identified
    /// resonators): what the prediction sees, and what the scale factor's
    /// budget moves the coupling by (`selfcal::budget::identified`).
    pub measurement_uncertainty: f64,
}

impl CouplingFigure {
    /// The figure of `measured` (deg/s at the datasheet's lambda) for a
    /// lambda of relative 1-sigma `angular_gain_relative`.
    pub fn new(measured: Estimate, angular_gain_relative: f64) -> Self {
        Self {
            value: measured.value,
            uncertainty: measured
                .uncertainty
                .hypot(measured.value * angular_gain_relative),
            measurement_uncertainty: measured.uncertainty,
        }
    }

    /// The measurement, without lambda's part.
    pub fn measured(&self) -> Estimate {
        Estimate {
            value: self.value,
            uncertainty: self.measurement_uncertainty,
        }
    }
}

/// The timing of a fine sweep's points, which bounds what the resonator's
/// and the filter's transients leave in each point's window.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Waits {
    /// Time from each carrier step to its I window (s), for the settling
    /// bound (`settling_residue`).
    pub waited_s: f64,
    /// The length of each I and Q window (s): the transients the waits
    /// leave decay further within it (`window_mean`).
    pub window_s: f64,
    /// The output filter's slowest decay rate (1/s,
    /// `Knowns::filter_decay_per_s`).
    pub filter_decay_per_s: f64,
    /// Time from each point's I window's start to its Q window's (s): the
    /// window and the filter's wait after the REF_PHASE step. The Q
    /// window sees the resonator's residue that much later
    /// ([`settle_sd`]).
    pub quarter_s: f64,
    /// The fraction of the resonator's residue that its correction may
    /// leave in the points (`settling::kept`; 1 for points not corrected,
    /// 0 for points with no residue).
    pub kept: f64,
}

impl Waits {
    /// The resonator's settling residue over the window's mean, relative
    /// to the peak response, for a mode of bandwidth `bk_hz`, that the
    /// correction may leave: the bound `settling_residue` after
    /// `waited_s`, decayed on through the window (`window_mean`), times
    /// `kept`.
    ///
    /// ```
    /// use gyrocal_host::identify::{Waits, settling_residue};
    /// let w = Waits { waited_s: 0.5, window_s: 0.0, filter_decay_per_s: 100.0, quarter_s: 0.1, kept: 1.0 };
    /// assert_eq!(w.settling(8.0), settling_residue(8.0, 0.5));
    /// let corrected = Waits { kept: 0.01, ..w };
    /// assert_eq!(corrected.settling(8.0), 0.01 * settling_residue(8.0, 0.5));
    /// ```
    pub fn settling(&self, bk_hz: f64) -> f64 {
        settling_residue(bk_hz, self.waited_s) * window_mean(PI * bk_hz, self.window_s) * self.kept
    }

    /// The filter's residue after the REF_PHASE step over the Q window's
    /// mean: `FILTER_SETTLE` of the step at the window's start, decayed on
    /// through it at the filter's slowest rate.
    pub fn filter(&self) -> f64 {
        FILTER_SETTLE * window_mean(self.filter_decay_per_s, self.window_s)
    }
}

/// One mode's fitted response.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModeFit {
    /// Resonance frequency (Hz).
    pub f_hz: Estimate,
    /// Quality factor.
    pub q: Estimate,
    /// Loop phase lag seen through this mode (deg).
    pub phase_deg: Estimate,
    /// RMS residual over the peak response (relative misfit).
    pub relative_rms: f64,
    /// |C| of the fitted form Y = C / ((fk - f)(fk + f) + j f bk), with
    /// the DAC hold's gain at fk in C: ADC LSB per drive LSB, times Hz^2
    /// (the peak response is |C| / (fk bk)).
    pub gain_hz2: f64,
    /// The coarse search from the guess did not converge and the scan
    /// over +-`SCAN_SPAN` found the mode: the datasheet was off.
    pub scanned: bool,
    /// Sweep points (carrier Hz) and responses (ADC LSB per drive LSB).
    #[serde(skip)]
    pub sweep: Vec<(f64, C64)>,
    /// The sweep's waits and windows, for what the waits leave in each
    /// point ([`Waits`]); all 0 for a sweep not measured here.
    #[serde(skip)]
    pub waits: Waits,
    /// The 1-sigma per real component of the error the table core's
    /// carrier lines can put on each `sweep` point (ADC LSB per drive LSB,
    /// [`point_spur_sd`]); empty on the fine core or for a sweep not
    /// measured here.
    #[serde(skip)]
    pub spur_sd: Vec<f64>,
    /// C of the fitted form (ADC LSB per drive LSB, times Hz^2).
    #[serde(skip)]
    pub c: C64,
    /// The front end's slope the fit took (`FrontEnd`).
    #[serde(skip)]
    pub(crate) front: fit::FrontSlope,
    /// The residuals' sigma per real component (ADC LSB per drive LSB).
    #[serde(skip)]
    pub residual_sd: f64,
    /// Responses at `front::PROBE_SPAN` bandwidths each side, measured
    /// when the two modes are not resolved (carrier Hz, Y).
    #[serde(skip)]
    pub probe: Vec<(f64, C64)>,
    /// The front end's delay those give against this fit's model (s).
    #[serde(skip)]
    pub probed_delay_s: Option<Estimate>,
}

impl ModeFit {
    /// The front end's response at `f_hz` relative to this mode's
    /// frequency, as the fit took it (`front`): what weights each DAC image
    /// of the output this mode was identified through.
    pub(crate) fn front_at(&self, f_hz: f64) -> C64 {
        self.front.at(f_hz, self.f_hz.value).0
    }
}

/// DAC images each side of the carrier that the models of the sampled
/// responses sum (`fit::FIT_IMAGES`).
pub(crate) const IMAGES: i32 = fit::FIT_IMAGES;

/// The identified device.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Identified {
    /// Mode 1 and mode 2.
    pub modes: [ModeFit; 2],
    /// Loop phase lag at the operating carrier (deg): the line through
    /// the two modes' phases, evaluated there.
    pub loop_phase_deg: Estimate,
    /// Group delay of the loop (s): the slope of that line, d phi / d w
    /// (with the modes not resolved, what the probe points each side of
    /// them give, `front::probed_delay`). It delays the response's envelope against the
    /// references', which REF_PHASE (a carrier phase) cannot undo: the
    /// prediction carries it as an envelope lead
    /// (`selfcal::predicted_ratio`), and the fine fits and the images as
    /// a phase sloping with frequency (`FrontEnd`, `images::ImageFront`).
    pub group_delay_s: Estimate,
    /// The quadrature (stiffness) coupling Omega_q (deg/s, the sign
    /// convention of `[gyro] quadrature_dps`), measured at rest from the
    /// cross responses once the operating point is known
    /// ([`crate::coupling`]); `None` until then, when the datasheet's is
    /// used.
    pub quadrature_dps: Option<CouplingFigure>,
    /// The damping coupling Omega_d (deg/s, the sign convention of
    /// `[gyro] damping_coupling_dps`), measured with it; `None` until then.
    pub damping_coupling_dps: Option<CouplingFigure>,
    /// The rate the device turned at during the couplings' windows
    /// (deg/s, `coupling::Coupling::rate_dps`); `None` until measured.
    /// The cycle assumes rest: a rate beyond its sigma is said
    /// (`SelfCal::warnings`).
    pub cycle_rate_dps: Option<Estimate>,
    /// Clocks the identification took.
    pub clocks: u64,
}

impl Identified {
    /// The identified mechanical parameters and mode couplings (the
    /// datasheet's until measured), lambda from the datasheet.
    pub fn gyro(&self, nominal: &GyroParams) -> GyroParams {
        GyroParams {
            f1_hz: self.modes[0].f_hz.value,
            f2_hz: self.modes[1].f_hz.value,
            q1: self.modes[0].q.value,
            q2: self.modes[1].q.value,
            quadrature_dps: self
                .quadrature_dps
                .map_or(nominal.quadrature_dps, |q| q.value),
            damping_coupling_dps: self
                .damping_coupling_dps
                .map_or(nominal.damping_coupling_dps, |d| d.value),
            ..nominal.clone()
        }
    }
}

/// Identify mode k starting from `guess_hz`: the coarse search, the
/// scan when it cannot converge, then the fine sweep and its fit (the
/// mode alone, no front-end slope, the residuals' sigmas: [`identify`]
/// refits it with the front end's delay and completes the sigmas).
///
/// The search's carrier spacing and waits come from the datasheet's Q.
/// When it misses the mode in a way a wrong Q explains (`Missed`), it
/// tries again (`RETRIES` times at most) from the Q it measured there, or
/// from ten times the Q it tried when it measured none; a success costs
/// the clocks of every try and changes nothing else. A mode found at the
/// first try takes exactly the path it took before the retries existed.
pub fn identify_mode(
    board: &mut dyn Board,
    knowns: &Knowns,
    k: usize,
    guess_hz: f64,
) -> Result<(ModeFit, u64), Error> {
    let first = match attempt(board, knowns, k, guess_hz)? {
        Ok(found) => return Ok(found),
        Err(missed) => missed,
    };
    let (mut last, mut clocks, mut tried) = (first.retry_q, first.clocks, vec![]);
    let mut latest = None;
    while let Some(q) = last.filter(|_| tried.len() < RETRIES) {
        let mut retry = knowns.clone();
        match k {
            0 => retry.nominal.q1 = q,
            _ => retry.nominal.q2 = q,
        }
        tried.push(search::shown_q(q));
        match attempt(board, &retry, k, guess_hz)? {
            Ok((fit, more)) => return Ok((fit, clocks + more)),
            Err(missed) => {
                (last, clocks) = (missed.retry_q, clocks + missed.clocks);
                latest = Some(missed.reason);
            }
        }
    }
    let reason = match latest {
        None => first.reason,
        Some(latest) => format!(
            "{}; tried again from Q{} = {}, the last time: {latest}",
            first.reason,
            k + 1,
            tried.join(" and ")
        ),
    };
    Err(Error::Identification {
        mode: k + 1,
        reason,
    })
}

/// Second tries of [`identify_mode`] at most, each from the Q the last
/// one measured (or ten times its own, `search::Unsettled::retry_q`):
/// two reach a datasheet Q a hundred times low.
const RETRIES: usize = 2;

/// An attempt at a mode that missed it: why, the Q a second attempt
/// starts from when a wrong datasheet Q explains the miss, and the clocks
/// it spent.
struct Missed {
    reason: String,
    retry_q: Option<f64>,
    clocks: u64,
}

impl Missed {
    /// The same miss, having spent `clocks`.
    fn after(self, clocks: u64) -> Self {
        Self { clocks, ..self }
    }
}

/// One attempt of [`identify_mode`] with `knowns`' Q: the fit, or how it
/// missed (a board's error is an error). The mode is located
/// ([`locate`]), swept ([`fine_sweep`]) and fitted alone; the fit then
/// carries the sweep's waits and each point's carrier lines
/// ([`lines_per_point`]).
fn attempt(
    board: &mut dyn Board,
    knowns: &Knowns,
    k: usize,
    guess_hz: f64,
) -> Result<Result<(ModeFit, u64), Missed>, Error> {
    let max = [knowns.amplitude.0, knowns.amplitude.1][k].abs();
    let mut probe = Prober::new(board, knowns, k, max / 8.0);
    let Located {
        centre,
        bk,
        scanned,
    } = match locate(&mut probe, guess_hz, knowns.bandwidth_hz(k))? {
        Ok(found) => found,
        Err(reason) => return Ok(Err(reason.after(probe.clocks))),
    };
    // The mode's own time constant 1 / (pi bk), with the datasheet's 20%
    // margin for the narrow-band estimate of bk.
    probe.tau_s = TAU_MARGIN / (PI * bk);
    let mut fit = match fine_fit(&mut probe, centre, bk)? {
        Ok(fit) => fit,
        Err(why) => return Ok(Err(unfitted(knowns, k, (centre, bk), why, probe.clocks))),
    };
    fit.scanned = scanned;
    // The amplitude only falls during the sweep (`Prober::measure`): its
    // last value is the smallest, whose lines are the largest part of Y.
    let amplitude = probe.amplitude();
    fit.spur_sd = lines_per_point(knowns, k, &fit.sweep, amplitude, (centre, bk))?;
    Ok(Ok((fit, probe.clocks)))
}

/// The fine sweep around `(centre, bk)` ([`fine_sweep`]) fitted, then
/// fitted again without what the waits leave of the resonator's ringing
/// after each carrier step (`settling`: the first fit's resonance and the
/// sweep's timing predict it), with the sweep's [`Waits`]; or why it could
/// not be fitted.
fn fine_fit(
    probe: &mut Prober,
    centre: f64,
    bk: f64,
) -> Result<Result<ModeFit, fit::FitError>, Error> {
    let knowns = probe.knowns();
    let (sweep, arrivals) = fine_sweep(probe, centre, bk)?;
    let (clock_hz, filter) = (knowns.clock_hz, &knowns.filter);
    let alone = |points: &[(f64, C64)], (fk, bk)| {
        let front = fit::FrontSlope::default();
        fit::fit_mode(points, fk, bk, Some(clock_hz), &fit::no_pull, front)
    };
    let fitted = alone(&sweep, (centre, bk)).and_then(|first| {
        let points = settling::corrected(&first, &sweep, &arrivals, clock_hz, filter);
        let start = (first.f_hz.value, first.f_hz.value / first.q.value);
        let mut fit = alone(&points, start)?;
        fit.waits = Waits {
            waited_s: probe.waited_s(),
            window_s: window_s(knowns),
            filter_decay_per_s: knowns.filter_decay_per_s(),
            quarter_s: probe.quarter_s(),
            kept: settling::kept(&first, &sweep, &arrivals),
        };
        Ok(fit)
    });
    Ok(fitted)
}

/// Where the coarse search found a mode.
struct Located {
    /// Its centre (Hz).
    centre: f64,
    /// Its bandwidth (Hz).
    bk: f64,
    /// The scan over +-`SCAN_SPAN` had to find it first: the datasheet
    /// was off.
    scanned: bool,
}

/// Where mode k lies near `guess_hz`, with the datasheet's bandwidth
/// `bw`, or why neither the search nor the scan settled (its clocks filled
/// in by the caller).
fn locate(probe: &mut Prober, guess_hz: f64, bw: f64) -> Result<Result<Located, Missed>, Error> {
    let located = |(centre, bk), scanned| Located {
        centre,
        bk,
        scanned,
    };
    if let Ok(found) = search::coarse(probe, guess_hz, bw)? {
        return Ok(Ok(located(found, false)));
    }
    let start = search::scan(probe, guess_hz, bw)?;
    Ok(match search::coarse(probe, start, bw)? {
        Ok(found) => Ok(located(found, true)),
        Err(why) => Err(Missed {
            reason: format!(
                "the scan of +-{}% around {guess_hz:.1} Hz pointed at {start:.1} Hz, but the search from there did not settle: {why}",
                100.0 * SCAN_SPAN
            ),
            retry_q: why.retry_q(),
            clocks: 0,
        }),
    })
}

/// A fine sweep's points (carrier Hz, Y) and what the resonator carried
/// into each.
type Swept = (Vec<(f64, C64)>, Vec<settling::Arrival>);

/// The fine sweep: `FINE_POINTS` carriers over +-`FINE_SPAN` bandwidths
/// `bk` around `centre`, up then down ([`fine_offsets`]), and what the
/// resonator carried into each point.
fn fine_sweep(probe: &mut Prober, centre: f64, bk: f64) -> Result<Swept, Error> {
    let mut swept: Swept = (vec![], vec![]);
    for s in fine_offsets() {
        let (f, y, arrival) = probe.measure_arriving(centre + s * bk)?;
        swept.0.push((f, y));
        swept.1.push(arrival);
    }
    Ok(swept)
}

/// The fine sweep's carriers in the order it visits them, in bandwidths
/// from its centre: `FINE_POINTS` over +-`FINE_SPAN` up, then the same
/// down (the fit's tests play this order too).
fn fine_offsets() -> Vec<f64> {
    let up: Vec<f64> = (0..FINE_POINTS)
        .map(|i| FINE_SPAN * (2.0 * i as f64 / (FINE_POINTS - 1) as f64 - 1.0))
        .collect();
    up.iter().chain(up.iter().rev()).copied().collect()
}

/// The miss of a fine sweep around the coarse search's `(centre, bk)`
/// that could not be fitted (`why`): a datasheet Q far from the part's
/// misleads the search, so the coarse search's bandwidth, when it lies
/// farther than a part's spread from the datasheet's, is the Q to try
/// again from.
fn unfitted(
    knowns: &Knowns,
    k: usize,
    (centre, bk): (f64, f64),
    why: impl std::fmt::Display,
    clocks: u64,
) -> Missed {
    let (q, bw) = (knowns.nominal.q(k), knowns.bandwidth_hz(k));
    let reason = format!(
        "the fine sweep around {centre:.1} Hz, {bk:.4} Hz a step (the coarse search's \
         bandwidth; Q{} = {} gives {bw:.4} Hz), could not be fitted: \
         {why}; a datasheet Q far from the part's misleads the search: check \
         [datasheet] q{}",
        k + 1,
        search::shown_q(q),
        k + 1
    );
    let measured = centre / bk;
    let far = crate::datasheet::q_beyond_spread(measured / q);
    Missed {
        reason,
        retry_q: far.then_some(measured),
        clocks,
    }
}

/// The 1-sigma the table core's carrier lines put on each point of
/// `sweep` (absolute, [`point_spur_sd`] times |Y|), at the drive
/// `amplitude`, for mode k about `(centre, bk)`. Each carrier is measured
/// twice (up and down): its lines are worked out once.
fn lines_per_point(
    knowns: &Knowns,
    k: usize,
    sweep: &[(f64, C64)],
    amplitude: f64,
    (centre, bk): (f64, f64),
) -> Result<Vec<f64>, Error> {
    let mut relative: Vec<(f64, f64)> = Vec::with_capacity(FINE_POINTS);
    let mut out = Vec::with_capacity(sweep.len());
    for &(f, y) in sweep {
        let sd = match relative.iter().find(|r| r.0 == f) {
            Some(&(_, sd)) => sd,
            None => {
                let sd = point_spur_sd(knowns, k, f, amplitude, centre, bk)?;
                relative.push((f, sd));
                sd
            }
        };
        out.push(sd * y.norm());
    }
    Ok(out)
}

/// Mode k's fine sweep fitted again, with the other mode's `pull` and
/// the `front` end's delay (`fit::fit_mode`), from `mode`'s estimates;
/// the uncertainties are the residuals' alone until [`with_uncertainty`]
/// completes them.
pub(crate) fn refit(
    mode: &ModeFit,
    k: usize,
    clock_hz: f64,
    pull: &dyn Fn(f64) -> C64,
    front: &FrontEnd,
) -> Result<ModeFit, Error> {
    let bk0 = mode.f_hz.value / mode.q.value;
    let mut fit = fit::fit_mode(
        &mode.sweep,
        mode.f_hz.value,
        bk0,
        Some(clock_hz),
        pull,
        front.slope,
    )
    .map_err(|reason| Error::Identification {
        mode: k + 1,
        reason: reason.to_string(),
    })?;
    fit.waits = mode.waits;
    fit.spur_sd = mode.spur_sd.clone();
    fit.scanned = mode.scanned;
    fit.probe = mode.probe.clone();
    fit.probed_delay_s = front::probed_delay(&fit, clock_hz, pull);
    Ok(fit)
}

/// The part of `fit`'s uncertainties (fk Hz, Q, phase deg) that its sweep
/// alone gives, whatever the front end's sigmas: the residuals' sigma
/// takes every point's noise as alike, the jackknife over carriers
/// (`fit::jackknife`, with the front end's `slope` the fit took) sees noise
/// that differs from point to point and misfits that move with the
/// carrier, and the larger of the two is taken, or the larger still
/// that the sweep's noise and the table core's carrier lines give through
/// the fit (`spur_sd`, `fit::noise_and_lines`: the lines counted once,
/// where the residuals saw them or not); then in quadrature the waits'
/// terms: the filter's residue after the REF_PHASE step at its RMS over
/// C's phase (`REF_STEP_SD`), and what the correction may leave of the
/// resonator's settling residue (`settling_residue`, the bound after the
/// wait, times `Waits::kept`) through the fit at its RMS over the
/// transient's turn, at the sweep's delay from the I window to the Q
/// window ([`settle_sd`]: the up and down sweeps cancel its first order
/// in fk, not in Q, and the Q window sees less of it the later it comes).
/// Each is its residue at its window's start, which decays on through the
/// window its mean is taken over (`window_mean`).
pub(crate) fn sweep_uncertainty(
    fit: &ModeFit,
    clock_hz: f64,
    pull: &dyn Fn(f64) -> C64,
    slope: fit::FrontSlope,
) -> [f64; 3] {
    let jk = fit::jackknife(&fit.sweep, fit, Some(clock_hz), pull, slope);
    let (bk, q) = (fit.f_hz.value / fit.q.value, fit.q.value);
    let (settle, filter) = (fit.waits.settling(bk), fit.waits.filter());
    let settle_pull = settle_sd(PI * bk * fit.waits.quarter_s);
    let waits: [f64; 3] =
        std::array::from_fn(|i| (settle_pull[i] * settle).hypot(REF_STEP_SD[i] * filter));
    let waits = [waits[0] * bk, waits[1] * q, waits[2].to_degrees()];
    let own = [fit.f_hz, fit.q, fit.phase_deg].map(|e| e.uncertainty);
    let lines = fit::noise_and_lines(fit, &fit.spur_sd, Some(clock_hz), pull, slope);
    let lines = lines.unwrap_or([0.0; 3]);
    std::array::from_fn(|i| own[i].max(jk[i]).max(lines[i]).hypot(waits[i]))
}

/// What the mean over a window of `window_s` keeps of a transient that
/// decays at `rate` (1/s) from its value at the window's start:
/// (1 - e^(-rate T)) / (rate T), the envelope's mean, which bounds the
/// mean of an oscillating transient under it (1 for an empty window).
///
/// ```
/// use gyrocal_host::identify::window_mean;
/// assert_eq!(window_mean(10.0, 0.0), 1.0);
/// // A window of 14 time constants keeps a fourteenth.
/// assert!((window_mean(14.0, 1.0) - 1.0 / 14.0).abs() < 1e-7);
/// ```
pub fn window_mean(rate: f64, window_s: f64) -> f64 {
    let x = rate * window_s;
    if x < 1e-9 { 1.0 } else { -(-x).exp_m1() / x }
}

/// `fit` (fitted with `pull` and `front`, [`refit`]) with each
/// uncertainty completed: its `sweep` part ([`sweep_uncertainty`]) and in
/// quadrature the front end's terms (`FrontEnd::moves`): its delay's
/// sigma; its gain slope's bound, taken as one sigma (the first-order
/// front ends sit at its ends, a pick-off at +a, a low-pass at -a, a pure
/// delay at 0: a device's is not spread evenly between, and a / sqrt 3
/// left the pick-off's pull at 1.7 sigma); and what the images' weighting
/// can move.
pub(crate) fn with_uncertainty(
    mut fit: ModeFit,
    sweep: [f64; 3],
    k: usize,
    clock_hz: f64,
    pull: &dyn Fn(f64) -> C64,
    front: &FrontEnd,
) -> Result<ModeFit, Error> {
    let [delay, gain, images] = front.moves(&fit, k, clock_hz, pull)?;
    for (i, e) in [&mut fit.f_hz, &mut fit.q, &mut fit.phase_deg]
        .into_iter()
        .enumerate()
    {
        e.uncertainty = sweep[i].hypot(delay[i]).hypot(gain[i]).hypot(images[i]);
    }
    Ok(fit)
}

/// The loop phase at `carrier_hz` and the group delay (module header):
/// the line through the two modes' phases. With the modes not
/// [`resolved`] that line has no slope: the delay is the one the modes'
/// probe points give (`front::probed_delay`), and without them a
/// first-order front end's, sin(phi) cos(phi) / w at the lag phi, with all
/// of itself as its sigma.
pub(crate) fn loop_phase(modes: &[ModeFit; 2], carrier_hz: f64) -> (Estimate, Estimate) {
    let [m1, m2] = modes;
    let (f1, f2) = (m1.f_hz.value, m2.f_hz.value);
    let (p1, p2) = (m1.phase_deg, m2.phase_deg);
    let resolvable = resolved(modes);
    let w2 = if resolvable {
        (carrier_hz - f1) / (f2 - f1)
    } else {
        0.5
    };
    let loop_phase_deg = Estimate {
        value: p1.value + w2 * (p2.value - p1.value),
        uncertainty: ((1.0 - w2) * p1.uncertainty).hypot(w2 * p2.uncertainty),
    };
    let per_hz = 1.0f64.to_radians() / (TAU * (f2 - f1));
    let group_delay_s = if resolvable {
        Estimate {
            value: (p2.value - p1.value) * per_hz,
            uncertainty: p1.uncertainty.hypot(p2.uncertainty) * per_hz.abs(),
        }
    } else if let Some(probed) = front::combined(modes.iter().filter_map(|m| m.probed_delay_s)) {
        probed
    } else {
        let phi = loop_phase_deg.value.to_radians();
        let first_order = phi.sin() * phi.cos() / (TAU * 0.5 * (f1 + f2));
        Estimate {
            value: first_order,
            uncertainty: first_order.abs(),
        }
    };
    (loop_phase_deg, group_delay_s)
}

/// The two modes are resolved: farther apart than a tenth of a bandwidth.
/// Closer, they are one frequency with one phase, and the line through
/// their phases has no slope to give.
pub(crate) fn resolved(modes: &[ModeFit; 2]) -> bool {
    let [m1, m2] = modes;
    let (f1, f2) = (m1.f_hz.value, m2.f_hz.value);
    (f2 - f1).abs() > 0.1 * (f1 / m1.q.value).max(f2 / m2.q.value)
}

/// Identify both modes, starting from `guess` (the datasheet or the last
/// identification).
///
/// On a [`fake`](crate::fake) board with the paper's modes, from a
/// datasheet whose f1 is 0.3% high:
///
/// ```
/// use gyrocal_host::{GyroParams, identify, fake::Lorentzian};
/// use gyrocal_host::knowns::{Derived, Knowns};
/// use gyrocal_regs::datapath::CarrierProfile;
/// use nalgebra::Complex;
/// let c = Complex::from_polar(2.0e9, -3f64.to_radians());
/// let (f1, f2) = (9.64e6, 9.64025e6);
/// let mut board = Lorentzian::new(50e6, [(f1, f1 / 55e3, c), (f2, f2 / 55e3, c)], 1e-3);
/// let datasheet = GyroParams { f1_hz: 1.003 * f1, f2_hz: 1.003 * f1 + 250.0, q1: 55e3,
///     q2: 55e3, angular_gain: 0.6, quadrature_dps: 0.0, damping_coupling_dps: 0.0 };
/// let knowns = Knowns {
///     filter: Derived { decimation: 1000, butterworth_hz: 500.0, rc_hz: 2000.0,
///         min_window_s: 0.05 },
///     carrier_profile: CarrierProfile::Fine,
///     ..Knowns::exact(datasheet.clone(), 50e6, 1.003 * f1)
/// };
/// let id = identify::identify(&mut board, &knowns, &datasheet).unwrap();
/// let mode1 = &id.modes[0];
/// assert!((mode1.f_hz.value - f1).abs() < 3.0 * mode1.f_hz.uncertainty);
/// assert!((mode1.q.value / 55e3 - 1.0).abs() < 1e-3);
/// assert!((id.loop_phase_deg.value - 3.0).abs() < 0.01);
/// ```
pub fn identify(
    board: &mut dyn Board,
    knowns: &Knowns,
    guess: &GyroParams,
) -> Result<Identified, Error> {
    let (m1, c1) = identify_mode(board, knowns, 0, guess.f1_hz)?;
    // Mode 2 from mode 1 plus the guess's split, scaled with mode 1's
    // move: the common drift (hundreds of Hz per K) is gone, what is left is
    // the split's drift (a few Hz per K), within the coarse search's first
    // look.
    let guess_f2 = m1.f_hz.value + (guess.f2_hz - guess.f1_hz) * (m1.f_hz.value / guess.f1_hz);
    let (m2, c2) = identify_mode(board, knowns, 1, guess_f2)?;
    let carrier = knowns.operating_carrier(m1.f_hz.value, m2.f_hz.value);
    let mut modes = [m1, m2];
    let mut clocks = c1 + c2;
    if !resolved(&modes) {
        for (k, mode) in modes.iter_mut().enumerate() {
            clocks += front::probe(board, knowns, k, mode)?;
        }
    }
    let modes = FrontEnd::refit_both(&modes, carrier, knowns.clock_hz)?;
    let modes = FrontEnd::complete(&modes, carrier, knowns.clock_hz, [&fit::no_pull; 2])?;
    let (loop_phase_deg, group_delay_s) = loop_phase(&modes, carrier);
    Ok(Identified {
        modes,
        loop_phase_deg,
        group_delay_s,
        quadrature_dps: None,
        damping_coupling_dps: None,
        cycle_rate_dps: None,
        clocks,
    })
}
