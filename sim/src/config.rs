//! The experiment a user describes: device, drive, converters, filter and
//! points, as one type that is its own TOML schema.
//!
//! ```toml
//! [gyro]        # required: f1_hz, f2_hz, q1, q2, angular_gain
//!               # quadrature_dps, damping_coupling_dps (0): mode couplings
//! [drive]       # required: carrier_hz, clock_hz
//!               # amplitude1, amplitude2 (0.9), force_full_scale1_n_per_kg,
//!               # force_full_scale2_n_per_kg (1.0), clock_tolerance_ppm
//!               # (0: the oscillator's bound the host is told),
//!               # clock_error_ppm (0: the simulated board's oscillator)
//! [frontend]    # dac_latency (2), adc_latency (3), dac_bits, adc_bits (16),
//!               # adc_headroom (0.9), adc_per_meter1, adc_per_meter2 (from
//!               # adc_headroom), noise_lsb (1), seed (1)
//! [filter]      # decimation, butterworth_hz, rc_hz: derived when unset
//! [experiment]  # required: readout_rates_dps, cal_freqs_hz
//!               # tolerance (1e-4), min_window_s (derived), budget_s (60),
//!               # rest_bound_dps (none: the device may turn during the cycle)
//! [noise]       # Brownian force noise: mass_kg (1e-8), temperature_k
//!               # (0: off), seed (1); and, read by `gyrocal datasheet`
//!               # alone ([`NoiseModel`]), the rate noises
//!               # arw_deg_per_sqrt_h, bias_instability_deg_per_h,
//!               # rrw_deg_per_h_per_sqrt_h (0: off)
//! ```
//!
//! A file with the required keys alone describes a complete experiment:
//! the keys in parentheses have fixed defaults, and the filter and the first
//! averaging window are derived from the device ([`Experiment::derived`]).
//! Unknown keys, values of the wrong type, and values out of range are
//! refused with one line naming the section, the key and what is allowed;
//! an error never names a key the user did not write. Every limit comes from
//! the constant beside the hardware or model parameter it protects.
//!
//! ```
//! let text = "
//!     [gyro]
//!     f1_hz = 25.1e3
//!     f2_hz = 25.8e3
//!     q1 = 3000
//!     q2 = 3000
//!     angular_gain = 0.8
//!     [drive]
//!     carrier_hz = 25.1e3
//!     clock_hz = 1.2345e6
//!     [experiment]
//!     readout_rates_dps = [50, 100, 150, 200]
//!     cal_freqs_hz = [2, 4, 6]
//! ";
//! let e = gyrocal_sim::config::parse("consumer.toml", text).unwrap();
//! let d = e.derived().unwrap();
//! assert!(d.decimation >= 166 && d.butterworth_hz < d.rc_hz);
//! ```

use crate::error::ConfigError;
use crate::gyro::GyroParams;
use crate::noise::ThermalNoise;
use crate::rate_drift::RateNoise;
use gyrocal_hdl::cic_decimator::MAX_DECIMATION;
use gyrocal_hdl::filter_design::{MAX_CUTOFF_RATIO, MIN_CUTOFF_RATIO, MIN_DECIMATION};
use gyrocal_hdl::host::clip_counter::MIN_CONVERTER_BITS;
use gyrocal_hdl::model::gyro_interface::CarrierProfile;
use gyrocal_hdl::settings::{MAX_CAL_RATIO, MAX_REF_DELAY};
use serde::{Deserialize, Serialize};

/// Everything an experiment needs, section by section as in the TOML file.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Experiment {
    /// `[gyro]`: the two modes and the angular gain.
    pub gyro: GyroParams,
    /// `[drive]`: carrier, clock and drive amplitudes.
    pub drive: Drive,
    /// `[frontend]`: DACs and ADCs.
    #[serde(default)]
    pub frontend: Frontend,
    /// `[filter]`: CIC decimation and IIR cut-offs (derived when unset).
    #[serde(default)]
    pub filter: Filter,
    /// `[experiment]`: the points and how precisely to measure them.
    #[serde(rename = "experiment")]
    pub points: Points,
    /// `[noise]`: thermomechanical force noise (off, 0 K, when unset).
    #[serde(default)]
    pub noise: ThermalNoise,
    /// `[datasheet]`: what host code is told about the device, key by key
    /// over `[gyro]` (`gyrocal field`, `gyrocal calibrate`; `run` compares
    /// with `[gyro]` and does not use it).
    #[serde(default)]
    pub datasheet: gyrocal_host::datasheet::Datasheet,
}

/// `[drive]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Drive {
    /// Carrier (excitation) frequency (Hz): 0 < carrier < clock / 2.
    pub carrier_hz: f64,
    /// FPGA clock (Hz).
    pub clock_hz: f64,
    /// Drive 1 amplitude as a fraction of DAC full scale, -1 <= a < 1, not 0.
    #[serde(default = "Drive::default_amplitude")]
    pub amplitude1: f64,
    /// Drive 2 amplitude, as `amplitude1`.
    #[serde(default = "Drive::default_amplitude")]
    pub amplitude2: f64,
    /// Force per unit mass of a full-scale DAC word, channel 1 (N/kg).
    #[serde(default = "Drive::default_force")]
    pub force_full_scale1_n_per_kg: f64,
    /// The same, channel 2 (N/kg).
    #[serde(default = "Drive::default_force")]
    pub force_full_scale2_n_per_kg: f64,
    /// Which core's carriers: "table" (the UP5K core, the default) or
    /// "fine" (the ECP5 core: interpolated carriers without the slow error
    /// at a short fold of the clock). The model and rtl engines run both;
    /// the verilator engine builds the table core.
    #[serde(
        default,
        deserialize_with = "carrier_profile::deserialize",
        serialize_with = "carrier_profile::serialize",
        skip_serializing_if = "carrier_profile::is_default"
    )]
    pub carrier_profile: CarrierProfile,
    /// The bound of the board oscillator's frequency error the host is
    /// told (+- ppm of `clock_hz`; 0, the default: none). Everything the
    /// host measures runs on that clock, so it cannot see the error; it
    /// enters the self-calibrated scale factors' sigma
    /// (`SfUncertainty::clock`). 0 <= bound <= [`MAX_CLOCK_PPM`].
    #[serde(default, skip_serializing_if = "is_zero")]
    pub clock_tolerance_ppm: f64,
    /// How far the simulated board's oscillator runs from `clock_hz`
    /// (ppm; 0, the default): the simulator's board alone, never what the
    /// host knows, as `[gyro]` is to `[datasheet]`. |error| <=
    /// [`MAX_CLOCK_PPM`].
    #[serde(default, skip_serializing_if = "is_zero")]
    pub clock_error_ppm: f64,
}

/// An unset clock key is left out of a written configuration, as it was
/// before the keys existed.
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// The largest oscillator error `[drive]` takes (ppm): a crystal or MEMS
/// oscillator stays within +-100 ppm over temperature and life. The
/// budget's clock term is first order in the error (its second order is
/// the square, 1e-4 of the term at 1%); an FPGA's internal RC oscillator
/// (+-10% on an iCE40's) is beyond it and beyond any 0.1% figure.
pub const MAX_CLOCK_PPM: f64 = 10_000.0;

/// `[drive] carrier_profile` through its name (`CarrierProfile`'s `FromStr`).
mod carrier_profile {
    use super::CarrierProfile;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<CarrierProfile, D::Error> {
        let name = String::deserialize(d)?;
        name.parse().map_err(serde::de::Error::custom)
    }

    pub fn serialize<S: Serializer>(p: &CarrierProfile, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(p.name())
    }

    pub fn is_default(p: &CarrierProfile) -> bool {
        *p == CarrierProfile::default()
    }
}

impl Drive {
    fn default_amplitude() -> f64 {
        0.9
    }
    fn default_force() -> f64 {
        1.0
    }
    /// A drive at `carrier_hz` on `clock_hz` with the default amplitudes
    /// and force gains.
    pub fn new(carrier_hz: f64, clock_hz: f64) -> Self {
        Self {
            carrier_hz,
            clock_hz,
            amplitude1: Self::default_amplitude(),
            amplitude2: Self::default_amplitude(),
            force_full_scale1_n_per_kg: Self::default_force(),
            force_full_scale2_n_per_kg: Self::default_force(),
            carrier_profile: CarrierProfile::default(),
            clock_tolerance_ppm: 0.0,
            clock_error_ppm: 0.0,
        }
    }
    /// The simulated board's clock (Hz): `clock_hz` moved by
    /// `clock_error_ppm`.
    pub fn board_clock_hz(&self) -> f64 {
        self.clock_hz * (1.0 + self.clock_error_ppm * 1e-6)
    }
    /// (amplitude1, amplitude2).
    pub fn amplitude(&self) -> (f64, f64) {
        (self.amplitude1, self.amplitude2)
    }
    /// [force_full_scale1, force_full_scale2] (N/kg).
    pub fn force_full_scale(&self) -> [f64; 2] {
        [
            self.force_full_scale1_n_per_kg,
            self.force_full_scale2_n_per_kg,
        ]
    }
}

/// Widest converter, in bits (the datapath's 16-bit ports).
pub const MAX_CONVERTER_BITS: u32 = 16;

/// `[frontend]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Frontend {
    /// DAC pipeline latency (clocks), at most `frontend::MAX_LATENCY`.
    pub dac_latency: u32,
    /// ADC pipeline latency (clocks), at most `frontend::MAX_LATENCY`.
    pub adc_latency: u32,
    /// DAC resolution (bits), 1..=`MAX_CONVERTER_BITS`.
    pub dac_bits: u32,
    /// ADC resolution (bits), `MIN_CONVERTER_BITS`..=`MAX_CONVERTER_BITS`
    /// (`ADC_CLIP` sees the rails of no narrower converter).
    pub adc_bits: u32,
    /// Peak ADC input as a fraction of full scale, used to set the ADC gains
    /// from the theory when `adc_per_meter1/2` are not given.
    pub adc_headroom: f64,
    /// ADC LSBs per metre, channel 1 (give both or neither).
    pub adc_per_meter1: Option<f64>,
    /// ADC LSBs per metre, channel 2.
    pub adc_per_meter2: Option<f64>,
    /// RMS noise at the ADC input (LSB). The default, 1 LSB, is a real
    /// converter's transition noise and dithers the quantizer: its error
    /// then no longer depends on the signal (Widrow), so no point carries a
    /// static bias that longer windows cannot average and the batches
    /// cannot see. 0 gives an ideal quantizer (`run` warns when a rate
    /// signal is then below one LSB).
    pub noise_lsb: f64,
    /// Noise seed.
    pub seed: u64,
}

impl Default for Frontend {
    fn default() -> Self {
        Self {
            dac_latency: 2,
            adc_latency: 3,
            dac_bits: 16,
            adc_bits: 16,
            adc_headroom: 0.9,
            adc_per_meter1: None,
            adc_per_meter2: None,
            noise_lsb: 1.0,
            seed: 1,
        }
    }
}

/// `[filter]`: unset values are derived from the device.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Filter {
    /// CIC decimation R, `MIN_DECIMATION..=MAX_DECIMATION`.
    pub decimation: Option<u32>,
    /// Butterworth cut-off (Hz), f_z `MIN_CUTOFF_RATIO`..`MAX_CUTOFF_RATIO`.
    pub butterworth_hz: Option<f64>,
    /// RC cut-off (Hz), same range.
    pub rc_hz: Option<f64>,
}

/// `[experiment]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Points {
    /// Readout rates (deg/s), at least 2 distinct, |rate| <= `MAX_RATE_DPS`.
    pub readout_rates_dps: Vec<f64>,
    /// Calibration frequencies (Hz), at least 2 distinct.
    pub cal_freqs_hz: Vec<f64>,
    /// Each point settles to this fraction of the signal it measures, and
    /// averaging goes on until each ratio's 1-sigma uncertainty is at most
    /// this fraction of it (`MIN_TOLERANCE..MAX_TOLERANCE`).
    #[serde(default = "Points::default_tolerance")]
    pub tolerance: f64,
    /// First averaging window (s), derived when unset; averaging is
    /// extended from there (`(0, MAX_WINDOW_S]`).
    #[serde(default)]
    pub min_window_s: Option<f64>,
    /// Wall-time budget of the run (s) for extending the windows
    /// (`(0, MAX_BUDGET_S]`).
    #[serde(default = "Points::default_budget")]
    pub budget_s: f64,
    /// The device rests during the self-calibration cycle, turning at
    /// most this fast about its sensitive axis (deg/s, `(0,
    /// MAX_REST_BOUND_DPS]`): 0.0042 on a fixed fixture, Earth's rate
    /// (`gyrocal_host::knowns::EARTH_RATE_DPS`). The cycle's sigma then
    /// takes an unseen rate within it (`gyrocal_host::selfcal::predicted_rate`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rest_bound_dps: Option<f64>,
}

impl Points {
    fn default_tolerance() -> f64 {
        1e-4
    }
    fn default_budget() -> f64 {
        60.0
    }
    /// Points with the default tolerance, derived window and budget.
    pub fn new(readout_rates_dps: Vec<f64>, cal_freqs_hz: Vec<f64>) -> Self {
        Self {
            readout_rates_dps,
            cal_freqs_hz,
            tolerance: Self::default_tolerance(),
            min_window_s: None,
            budget_s: Self::default_budget(),
            rest_bound_dps: None,
        }
    }
}

/// Largest |readout rate| (deg/s).
pub const MAX_RATE_DPS: f64 = 1e5;
/// Tolerance range (exclusive at both ends).
pub const MIN_TOLERANCE: f64 = 0.0;
/// Tolerance range (exclusive at both ends).
pub const MAX_TOLERANCE: f64 = 0.1;
/// Longest first window (s).
pub const MAX_WINDOW_S: f64 = 100.0;
/// Largest wall-time budget (s).
pub const MAX_BUDGET_S: f64 = 86_400.0;
/// Largest `[experiment] rest_bound_dps` (deg/s): a bound beyond what the
/// couplings' windows read to (hundredths of a deg/s on the consumer
/// device) says nothing the reading does not, and a device turning at a
/// degree a second does not rest.
pub const MAX_REST_BOUND_DPS: f64 = 1.0;
/// z samples per period of the calibration ripple (2 f_cal) at least: the
/// window average integrates the interpolated samples, with an error below
/// 1e-4 of the ripple from 20 samples per period on (`average.rs`).
pub const SAMPLES_PER_RIPPLE: f64 = 20.0;

/// The filter and first window derived from the device, with the user's
/// explicit values where given (the host programs them: `gyrocal_host`).
pub use gyrocal_host::Derived;

/// Ratio of the RC cut-off to the Butterworth cut-off, and of the
/// Butterworth cut-off to the slowest signal (`Experiment::derived`).
const CUTOFF_STEP: f64 = 4.0;
/// z rate over the RC cut-off asked of a derived decimation (twice the
/// least `1 / MAX_CUTOFF_RATIO`, so the cut-offs sit inside the range).
const Z_RATE_OVER_RC: f64 = 10.0;
/// Butterworth time constants per batch of the first window: batches
/// shorter than the filter's memory would be correlated.
const FILTER_TIMES_PER_BATCH: f64 = 10.0;

/// A numeric key with its range check.
fn check(
    section: &'static str,
    key: &str,
    value: f64,
    ok: bool,
    allowed: &str,
) -> Result<(), ConfigError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(ConfigError::key(section, key, value, allowed))
    }
}

/// The whole `[noise]` section as `gyrocal datasheet` reads it: the
/// Brownian force noise's keys ([`ThermalNoise`]) and the rate noises'
/// ([`RateNoise`], `crate::rate_drift`). The other commands read
/// `[noise]` as [`ThermalNoise`] and refuse the rate keys by name, rather
/// than run without them.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseModel {
    /// [`ThermalNoise::mass_kg`].
    pub mass_kg: f64,
    /// [`ThermalNoise::temperature_k`].
    pub temperature_k: f64,
    /// Seed of the Brownian noise, and (jumped) of the rate noises.
    pub seed: u64,
    /// [`RateNoise::arw_deg_per_sqrt_h`].
    pub arw_deg_per_sqrt_h: f64,
    /// [`RateNoise::bias_instability_deg_per_h`].
    pub bias_instability_deg_per_h: f64,
    /// [`RateNoise::rrw_deg_per_h_per_sqrt_h`].
    pub rrw_deg_per_h_per_sqrt_h: f64,
}

impl Default for NoiseModel {
    fn default() -> Self {
        let t = ThermalNoise::default();
        Self {
            mass_kg: t.mass_kg,
            temperature_k: t.temperature_k,
            seed: t.seed,
            arw_deg_per_sqrt_h: 0.0,
            bias_instability_deg_per_h: 0.0,
            rrw_deg_per_h_per_sqrt_h: 0.0,
        }
    }
}

impl NoiseModel {
    /// The Brownian part.
    pub fn thermal(&self) -> ThermalNoise {
        ThermalNoise {
            mass_kg: self.mass_kg,
            temperature_k: self.temperature_k,
            seed: self.seed,
        }
    }

    /// The rate-noise part.
    pub fn rate(&self) -> RateNoise {
        RateNoise {
            arw_deg_per_sqrt_h: self.arw_deg_per_sqrt_h,
            bias_instability_deg_per_h: self.bias_instability_deg_per_h,
            rrw_deg_per_h_per_sqrt_h: self.rrw_deg_per_h_per_sqrt_h,
        }
    }

    /// Every key's range; one line naming `[noise]` and the key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.thermal().validate()?;
        self.rate().validate()
    }
}

/// The section a byte offset of `text` falls in: the last header up to
/// the end of its line (a header's own line is its section).
fn section_at(text: &str, offset: usize) -> Option<String> {
    let offset = offset.min(text.len());
    let line_end = text[offset..].find('\n').map_or(text.len(), |n| offset + n);
    text[..line_end]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('[') && l.ends_with(']'))
        .map(|l| l.to_owned())
}

/// One line from a TOML or schema error: position, section, message.
pub(crate) fn parse_error(name: &str, text: &str, e: toml::de::Error) -> String {
    let message = e.message().replace('\n', " ");
    match e.span() {
        Some(span) => {
            let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
            let at = match section_at(text, span.start) {
                Some(s) => format!(" in {s}"),
                None => String::new(),
            };
            format!("{name} line {line}{at}: {message}")
        }
        None => format!("{name}: {message}"),
    }
}

/// Parse a configuration file's text, checking every key and that the
/// derived values exist. `name` labels error messages (the file path).
pub fn parse(name: &str, text: &str) -> Result<Experiment, ConfigError> {
    let e: Experiment =
        toml::from_str(text).map_err(|e| ConfigError::Syntax(parse_error(name, text, e)))?;
    e.validate()?;
    e.derived()?;
    Ok(e)
}

impl Experiment {
    /// The paper's device and measurement: mode 1 at 9.64 MHz, mode 2 250 Hz
    /// above, Q 55,000, lambda 0.6 (n = 3 modes), excited at mode 1,
    /// 50 MHz clock, rates 1..20 deg/s, staircase 10..15 Hz, with the
    /// paper's filter (R = 1000, 500 Hz Butterworth, 2 kHz RC), noiseless
    /// converters, 0.15 s first windows and a 9 s wall-time budget.
    pub fn paper() -> Self {
        Self {
            gyro: GyroParams {
                f1_hz: 9.64e6,
                f2_hz: 9.64e6 + 250.0,
                q1: 55_000.0,
                q2: 55_000.0,
                angular_gain: 0.6,
                quadrature_dps: 0.0,
                damping_coupling_dps: 0.0,
            },
            drive: Drive::new(9.64e6, 50e6),
            // Dithered converters, the default: the readout's rate signal
            // spans 3.5 ADC LSB on output 2, and an ideal quantizer leaves
            // a rate-dependent residue (ratio uncertainty 4.3e-4) that 1 LSB
            // of noise turns into white noise (2.7e-5 in the same time).
            frontend: Frontend::default(),
            filter: Filter {
                decimation: Some(1000),
                butterworth_hz: Some(500.0),
                rc_hz: Some(2000.0),
            },
            points: Points {
                // One round of 0.15 s windows fits the 9 s budget on 2
                // idle cores (4.9 s of simulated time, 2.45e8 clocks) and
                // leaves the detuned ratio's uncertainty near 3e-5
                // (dithered; the spread over 16 seeds at 0.1 s was 3.7e-5),
                // a third of the 1e-4 `reproduce` must reach: longer first
                // windows spend the budget better than a second round,
                // which repeats the settling. The calibration windows are
                // 3 whole ripple periods (0.15 s at 10 Hz, 0.1 s at 15 Hz).
                min_window_s: Some(0.15),
                // `reproduce` promises a result within 10 s of wall time.
                budget_s: 9.0,
                ..Points::new(
                    (1..=20).map(f64::from).collect(),
                    (10..=15).map(f64::from).collect(),
                )
            },
            noise: ThermalNoise::default(),
            datasheet: Default::default(),
        }
    }

    /// A device with the required keys alone: everything else defaulted or
    /// derived.
    pub fn with_required(
        gyro: GyroParams,
        carrier_hz: f64,
        clock_hz: f64,
        readout_rates_dps: Vec<f64>,
        cal_freqs_hz: Vec<f64>,
    ) -> Self {
        Self {
            gyro,
            drive: Drive::new(carrier_hz, clock_hz),
            frontend: Frontend::default(),
            filter: Filter::default(),
            points: Points::new(readout_rates_dps, cal_freqs_hz),
            noise: ThermalNoise::default(),
            datasheet: Default::default(),
        }
    }

    /// Both ADC gains, if given.
    pub fn adc_per_meter(&self) -> Option<[f64; 2]> {
        match (self.frontend.adc_per_meter1, self.frontend.adc_per_meter2) {
            (Some(a), Some(b)) => Some([a, b]),
            _ => None,
        }
    }

    /// Every key's own range, with the names of the configuration file.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.validate_gyro()?;
        self.validate_drive()?;
        self.validate_frontend()?;
        self.validate_points()?;
        self.datasheet.over(&self.gyro)?;
        Ok(self.noise.validate()?)
    }

    fn validate_gyro(&self) -> Result<(), ConfigError> {
        let g = &self.gyro;
        let positive = "must be a positive number";
        let nyquist = self.drive.clock_hz / 2.0;
        let below = format!("must be above 0 and below clock_hz / 2 = {nyquist} Hz");
        check(
            "drive",
            "clock_hz",
            self.drive.clock_hz,
            self.drive.clock_hz > 0.0,
            positive,
        )?;
        check(
            "gyro",
            "f1_hz",
            g.f1_hz,
            g.f1_hz > 0.0 && g.f1_hz < nyquist,
            &below,
        )?;
        check(
            "gyro",
            "f2_hz",
            g.f2_hz,
            g.f2_hz > 0.0 && g.f2_hz < nyquist,
            &below,
        )?;
        check("gyro", "q1", g.q1, g.q1 > 0.0, positive)?;
        check("gyro", "q2", g.q2, g.q2 > 0.0, positive)?;
        check(
            "gyro",
            "angular_gain",
            g.angular_gain,
            true,
            "must be a finite number",
        )?;
        Ok(g.check_couplings()?)
    }

    fn validate_drive(&self) -> Result<(), ConfigError> {
        let d = &self.drive;
        let nyquist = d.clock_hz / 2.0;
        let below = format!("must be above 0 and below clock_hz / 2 = {nyquist} Hz");
        check(
            "drive",
            "carrier_hz",
            d.carrier_hz,
            d.carrier_hz > 0.0 && d.carrier_hz < nyquist,
            &below,
        )?;
        check(
            "drive",
            "clock_tolerance_ppm",
            d.clock_tolerance_ppm,
            (0.0..=MAX_CLOCK_PPM).contains(&d.clock_tolerance_ppm),
            &format!("allowed 0 to {MAX_CLOCK_PPM} (+- ppm of clock_hz)"),
        )?;
        check(
            "drive",
            "clock_error_ppm",
            d.clock_error_ppm,
            d.clock_error_ppm.abs() <= MAX_CLOCK_PPM,
            &format!("allowed -{MAX_CLOCK_PPM} to {MAX_CLOCK_PPM} (ppm of clock_hz)"),
        )?;
        let amp = "allowed -1 <= amplitude < 1 (fraction of DAC full scale), not 0";
        for (key, a) in [("amplitude1", d.amplitude1), ("amplitude2", d.amplitude2)] {
            check("drive", key, a, (-1.0..1.0).contains(&a) && a != 0.0, amp)?;
        }
        for (key, g) in [
            ("force_full_scale1_n_per_kg", d.force_full_scale1_n_per_kg),
            ("force_full_scale2_n_per_kg", d.force_full_scale2_n_per_kg),
        ] {
            check("drive", key, g, g > 0.0, "must be a positive number")?;
        }
        Ok(())
    }

    fn validate_frontend(&self) -> Result<(), ConfigError> {
        let f = &self.frontend;
        let max = crate::frontend::MAX_LATENCY;
        for (key, v) in [
            ("dac_latency", f.dac_latency),
            ("adc_latency", f.adc_latency),
        ] {
            check(
                "frontend",
                key,
                f64::from(v),
                v <= max,
                &format!("allowed 0..={max} clocks"),
            )?;
        }
        let delay = f.dac_latency + f.adc_latency;
        if delay > MAX_REF_DELAY {
            return Err(ConfigError::key(
                "frontend",
                "dac_latency + adc_latency",
                delay,
                format!("at most {MAX_REF_DELAY} clocks (the reference delay line)"),
            ));
        }
        // ADC_CLIP sees the rail codes of converters of MIN_CONVERTER_BITS
        // and more only (`gyrocal_hdl::host::clip_counter`): a narrower
        // ADC would clip high unseen.
        let adc_why = format!(
            " (ADC_CLIP sees the rails of converters of {MIN_CONVERTER_BITS} bits and more)"
        );
        for (key, v, least, why) in [
            ("dac_bits", f.dac_bits, 1, ""),
            ("adc_bits", f.adc_bits, MIN_CONVERTER_BITS, adc_why.as_str()),
        ] {
            check(
                "frontend",
                key,
                f64::from(v),
                (least..=MAX_CONVERTER_BITS).contains(&v),
                &format!("allowed {least}..={MAX_CONVERTER_BITS}{why}"),
            )?;
        }
        let h = f.adc_headroom;
        check(
            "frontend",
            "adc_headroom",
            h,
            h > 0.0 && h <= 1.0,
            "allowed 0 < adc_headroom <= 1",
        )?;
        match (f.adc_per_meter1, f.adc_per_meter2) {
            (None, None) => {}
            (Some(p1), Some(p2)) => {
                check(
                    "frontend",
                    "adc_per_meter1",
                    p1,
                    p1 > 0.0,
                    "must be a positive number",
                )?;
                check(
                    "frontend",
                    "adc_per_meter2",
                    p2,
                    p2 > 0.0,
                    "must be a positive number",
                )?;
            }
            _ => {
                return Err(ConfigError::rule(
                    "frontend",
                    "adc_per_meter1 and adc_per_meter2",
                    "give both or neither (neither: set from adc_headroom)",
                ));
            }
        }
        check(
            "frontend",
            "noise_lsb",
            f.noise_lsb,
            f.noise_lsb >= 0.0,
            "must be >= 0",
        )
    }

    fn validate_points(&self) -> Result<(), ConfigError> {
        let p = &self.points;
        check_list(
            "readout_rates_dps",
            &p.readout_rates_dps,
            &|x| x.abs() <= MAX_RATE_DPS,
            &format!("rates must be finite, |rate| <= {MAX_RATE_DPS} deg/s"),
        )?;
        let max_cal = self.drive.clock_hz * MAX_CAL_RATIO;
        check_list(
            "cal_freqs_hz",
            &p.cal_freqs_hz,
            &|x| x > 0.0 && x <= max_cal,
            &format!(
                "frequencies must be above 0 and at most clock_hz x {MAX_CAL_RATIO} = {max_cal} Hz"
            ),
        )?;
        check(
            "experiment",
            "tolerance",
            p.tolerance,
            p.tolerance > MIN_TOLERANCE && p.tolerance < MAX_TOLERANCE,
            &format!("allowed {MIN_TOLERANCE} < tolerance < {MAX_TOLERANCE}"),
        )?;
        if let Some(w) = p.min_window_s {
            check(
                "experiment",
                "min_window_s",
                w,
                w > 0.0 && w <= MAX_WINDOW_S,
                &format!("allowed 0 < min_window_s <= {MAX_WINDOW_S} s"),
            )?;
        }
        if let Some(b) = p.rest_bound_dps {
            check(
                "experiment",
                "rest_bound_dps",
                b,
                b > 0.0 && b <= MAX_REST_BOUND_DPS,
                &format!(
                    "allowed 0 < rest_bound_dps <= {MAX_REST_BOUND_DPS} deg/s (a device on a fixed fixture turns at Earth's rate, 0.0042 deg/s, at most)"
                ),
            )?;
        }
        check(
            "experiment",
            "budget_s",
            p.budget_s,
            p.budget_s > 0.0 && p.budget_s <= MAX_BUDGET_S,
            &format!("allowed 0 < budget_s <= {MAX_BUDGET_S} s"),
        )
    }

    /// The slowest signal the filter must follow (Hz): a mode's half
    /// bandwidth f_k / (2 Q_k) (its amplitude pole) or the calibration
    /// ripple 2 f_cal.
    pub fn signal_band_hz(&self) -> f64 {
        let g = &self.gyro;
        let half_bandwidth = (g.f1_hz / (2.0 * g.q1)).max(g.f2_hz / (2.0 * g.q2));
        let ripple = 2.0 * self.points.cal_freqs_hz.iter().cloned().fold(0.0, f64::max);
        half_bandwidth.max(ripple)
    }

    /// The filter and first window, derived from the device where the user
    /// left them unset (see docs/your-device.md, "Derived settings"):
    ///
    /// - Butterworth cut-off `CUTOFF_STEP` x the signal band, RC cut-off
    ///   `CUTOFF_STEP` x that;
    /// - decimation R so that f_z = clock / R is `Z_RATE_OVER_RC` x the RC
    ///   cut-off, within `MIN_DECIMATION..=MAX_DECIMATION`, and small
    ///   enough that f_z samples the calibration ripple `SAMPLES_PER_RIPPLE`
    ///   times per period;
    /// - both cut-offs then clamped into f_z x
    ///   [`MIN_CUTOFF_RATIO`, `MAX_CUTOFF_RATIO`];
    /// - first window: 8 batches of `FILTER_TIMES_PER_BATCH` Butterworth
    ///   time constants.
    ///
    /// An explicit value that conflicts with the others is refused with
    /// both values and what is allowed.
    pub fn derived(&self) -> Result<Derived, ConfigError> {
        let decimation = self.decimation()?;
        let (rc_hz, butterworth_hz) = self.cutoffs(decimation)?;
        let fz = self.drive.clock_hz / f64::from(decimation);
        let min_window_s = match self.points.min_window_s {
            Some(w) => w,
            None => {
                let batch = FILTER_TIMES_PER_BATCH / (std::f64::consts::TAU * butterworth_hz);
                8.0 * batch.max(64.0 / fz)
            }
        };
        Ok(Derived {
            decimation,
            butterworth_hz,
            rc_hz,
            min_window_s,
        })
    }

    /// The CIC decimation: `[filter] decimation` checked against its range
    /// and the calibration ripple's `SAMPLES_PER_RIPPLE` z samples a
    /// period, or derived from the signal band within both.
    fn decimation(&self) -> Result<u32, ConfigError> {
        let clock = self.drive.clock_hz;
        let band = self.signal_band_hz();
        let max_cal = self.points.cal_freqs_hz.iter().cloned().fold(0.0, f64::max);
        // Largest R that still samples the ripple SAMPLES_PER_RIPPLE times.
        let ripple_limit = (clock / (SAMPLES_PER_RIPPLE * 2.0 * max_cal)).floor();
        Ok(match self.filter.decimation {
            Some(r) => {
                if !(MIN_DECIMATION..=MAX_DECIMATION).contains(&r) {
                    return Err(ConfigError::key(
                        "filter",
                        "decimation",
                        r,
                        format!("allowed {MIN_DECIMATION}..={MAX_DECIMATION}"),
                    ));
                }
                if f64::from(r) > ripple_limit {
                    return Err(ConfigError::key(
                        "filter",
                        "decimation",
                        r,
                        format!(
                            "the calibration ripple at 2 x {max_cal} Hz needs {SAMPLES_PER_RIPPLE} z samples per period, so decimation <= {ripple_limit} (clock_hz / (2 x {SAMPLES_PER_RIPPLE} x max cal_freqs_hz)); lower it or the calibration frequencies"
                        ),
                    ));
                }
                r
            }
            None => {
                if ripple_limit < f64::from(MIN_DECIMATION) {
                    let max = clock / (SAMPLES_PER_RIPPLE * 2.0 * f64::from(MIN_DECIMATION));
                    return Err(ConfigError::rule(
                        "experiment",
                        format!("cal_freqs_hz contains {max_cal}"),
                        format!(
                            "at most {max:.3} Hz on this clock (clock_hz / (2 x {SAMPLES_PER_RIPPLE} z samples per ripple period x decimation {MIN_DECIMATION}))"
                        ),
                    ));
                }
                let fz_wanted = Z_RATE_OVER_RC * CUTOFF_STEP * CUTOFF_STEP * band;
                (clock / fz_wanted).round().clamp(
                    f64::from(MIN_DECIMATION),
                    f64::from(MAX_DECIMATION).min(ripple_limit),
                ) as u32
            }
        })
    }

    /// The RC and Butterworth cutoffs (Hz) at `decimation`: given ones
    /// checked against `MIN_CUTOFF_RATIO..=MAX_CUTOFF_RATIO` of the z
    /// rate, missing ones derived from the signal band within it.
    fn cutoffs(&self, decimation: u32) -> Result<(f64, f64), ConfigError> {
        let (clock, band) = (self.drive.clock_hz, self.signal_band_hz());
        let fz = clock / f64::from(decimation);
        let (lo, hi) = (fz * MIN_CUTOFF_RATIO, fz * MAX_CUTOFF_RATIO);
        let why = match self.filter.decimation {
            Some(_) => format!("clock_hz / decimation = {fz} Hz"),
            None => format!(
                "clock_hz / derived decimation {decimation} = {fz} Hz; set [filter] decimation to move it"
            ),
        };
        let cutoff = |key: &str, given: Option<f64>, wanted: f64| -> Result<f64, ConfigError> {
            match given {
                Some(v) => check(
                    "filter",
                    key,
                    v,
                    v >= lo && v <= hi,
                    &format!("allowed {lo:.6} to {hi:.3} Hz ({MIN_CUTOFF_RATIO} to {MAX_CUTOFF_RATIO} of the z rate, {why})"),
                )
                .map(|_| v),
                None => Ok(wanted.clamp(lo, hi)),
            }
        };
        let rc_hz = cutoff("rc_hz", self.filter.rc_hz, CUTOFF_STEP * CUTOFF_STEP * band)?;
        let butterworth_hz = cutoff(
            "butterworth_hz",
            self.filter.butterworth_hz,
            (CUTOFF_STEP * band).min(rc_hz),
        )?;
        Ok((rc_hz, butterworth_hz))
    }
}

/// A list of values: not empty, each in range, at least 2 distinct.
fn check_list(
    key: &str,
    v: &[f64],
    ok: &dyn Fn(f64) -> bool,
    allowed: &str,
) -> Result<(), ConfigError> {
    let rule = |what: String, rule: &str| Err(ConfigError::rule("experiment", what, rule));
    if v.is_empty() {
        return rule(format!("{key} is empty"), "give at least 2 distinct values");
    }
    if let Some(x) = v.iter().find(|x| !(x.is_finite() && ok(**x))) {
        return rule(format!("{key} contains {x}"), allowed);
    }
    if v.iter().all(|x| *x == v[0]) {
        return rule(key.into(), "give at least 2 distinct values for a slope");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const REQUIRED: &str = "[gyro]\nf1_hz = 1.0123e6\nf2_hz = 1.01236e6\nq1 = 5000\nq2 = 5000\nangular_gain = 0.6\n[drive]\ncarrier_hz = 1.0123e6\nclock_hz = 10e6\n[experiment]\nreadout_rates_dps = [100, 200]\ncal_freqs_hz = [2, 4]\n";

    #[test]
    fn the_required_keys_alone_make_an_experiment() {
        let e = parse("c.toml", REQUIRED).unwrap();
        assert_eq!(e.frontend, Frontend::default());
        assert_eq!(e.filter, Filter::default());
        assert_eq!(e.points.tolerance, 1e-4);
        let d = e.derived().unwrap();
        let fz = 10e6 / f64::from(d.decimation);
        assert!(d.butterworth_hz >= fz * MIN_CUTOFF_RATIO && d.rc_hz <= fz * MAX_CUTOFF_RATIO);
    }

    #[test]
    fn the_paper_round_trips_through_toml() {
        let e = Experiment::paper();
        let text = toml::to_string(&e).unwrap();
        assert_eq!(parse("c.toml", &text).unwrap(), e);
    }

    #[test]
    fn the_couplings_default_to_zero_and_round_trip() {
        let e = parse("c.toml", REQUIRED).unwrap();
        assert_eq!(
            [e.gyro.quadrature_dps, e.gyro.damping_coupling_dps],
            [0.0; 2]
        );
        let text = REQUIRED.replace(
            "q1 = 5000",
            "q1 = 5000\nquadrature_dps = -300.5\ndamping_coupling_dps = 20",
        );
        let e = parse("c.toml", &text).unwrap();
        assert_eq!(
            [e.gyro.quadrature_dps, e.gyro.damping_coupling_dps],
            [-300.5, 20.0]
        );
        assert_eq!(parse("c.toml", &toml::to_string(&e).unwrap()).unwrap(), e);
    }

    #[test]
    fn the_carrier_profile_defaults_to_the_table_round_trips_and_names_a_bad_value() {
        let e = parse("c.toml", REQUIRED).unwrap();
        assert_eq!(e.drive.carrier_profile, CarrierProfile::Table);
        assert!(!toml::to_string(&e).unwrap().contains("carrier_profile"));
        let fine = REQUIRED.replace("[drive]\n", "[drive]\ncarrier_profile = \"fine\"\n");
        let e = parse("c.toml", &fine).unwrap();
        assert_eq!(e.drive.carrier_profile, CarrierProfile::Fine);
        assert_eq!(parse("c.toml", &toml::to_string(&e).unwrap()).unwrap(), e);
        let bad = REQUIRED.replace("[drive]\n", "[drive]\ncarrier_profile = \"ecp5\"\n");
        let err = parse("c.toml", &bad).unwrap_err().to_string();
        assert!(!err.contains('\n'), "{err}");
        assert!(
            err.contains("\"ecp5\"")
                && err.contains("allowed \"table\"")
                && err.contains("\"fine\""),
            "{err}"
        );
    }

    /// The clock's keys default to an exact clock, round-trip, and a value
    /// out of range is one line naming the key and what is allowed.
    #[test]
    fn the_clock_keys_default_to_zero_and_name_a_bad_value() {
        let e = parse("c.toml", REQUIRED).unwrap();
        assert_eq!(
            [e.drive.clock_tolerance_ppm, e.drive.clock_error_ppm],
            [0.0, 0.0]
        );
        assert_eq!(e.drive.board_clock_hz(), e.drive.clock_hz);
        let set = |keys: &str| REQUIRED.replace("[drive]\n", &format!("[drive]\n{keys}\n"));
        let e = parse(
            "c.toml",
            &set("clock_tolerance_ppm = 50\nclock_error_ppm = -20"),
        )
        .unwrap();
        assert_eq!(e.drive.board_clock_hz(), e.drive.clock_hz * (1.0 - 20e-6));
        assert_eq!(parse("c.toml", &toml::to_string(&e).unwrap()).unwrap(), e);
        for (keys, says) in [
            (
                "clock_tolerance_ppm = -1",
                "[drive] clock_tolerance_ppm = -1: allowed 0 to 10000",
            ),
            (
                "clock_error_ppm = 20000",
                "[drive] clock_error_ppm = 20000: allowed -10000 to 10000",
            ),
        ] {
            let err = parse("c.toml", &set(keys)).unwrap_err().to_string();
            assert!(!err.contains('\n') && err.starts_with(says), "{err}");
        }
    }

    #[test]
    fn a_missing_required_key_is_named() {
        let text = REQUIRED.replace("carrier_hz = 1.0123e6\n", "");
        let err = parse("c.toml", &text).unwrap_err().to_string();
        assert!(err.contains("missing field `carrier_hz`"), "{err}");
    }

    #[test]
    fn a_conflicting_explicit_value_names_both() {
        // An RC cut-off above the derived z rate's range: the error names the
        // user's value, the derived decimation and the key that moves it.
        let text = REQUIRED.replace("[experiment]", "[filter]\nrc_hz = 1e6\n[experiment]");
        let err = parse("c.toml", &text).unwrap_err().to_string();
        assert!(
            err.starts_with("[filter] rc_hz = 1000000: allowed"),
            "{err}"
        );
        assert!(
            err.contains("derived decimation") && err.contains("[filter] decimation"),
            "{err}"
        );
    }

    /// The errors are typed: a caller tells a key out of range from a rule
    /// over keys, a coupling or a file that does not parse, with the
    /// section and key as data.
    #[test]
    fn errors_carry_the_section_and_key() {
        let err = |text: &str| parse("c.toml", text).unwrap_err();
        assert!(matches!(
            err(&REQUIRED.replace("q1 = 5000", "q1 = -5.0")),
            ConfigError::Key { section: "gyro", ref key, ref value, .. } if key == "q1" && value == "-5"
        ));
        assert!(matches!(
            err(&format!("{REQUIRED}[frontend]\nadc_per_meter1 = 1e9\n")),
            ConfigError::Rule {
                section: "frontend",
                ..
            }
        ));
        assert!(matches!(
            err(&REQUIRED.replace("q1 = 5000", "q1 = 5000\nquadrature_dps = 2e5")),
            ConfigError::Coupling(_)
        ));
        assert!(matches!(
            err(&REQUIRED.replace("[gyro]", "[gyro")),
            ConfigError::Syntax(_)
        ));
    }

    #[test]
    fn every_error_is_one_line_naming_the_key() {
        let cases = [
            (REQUIRED.replace("q1 = 5000", "q1 = -5.0"), "[gyro] q1 = -5"),
            (REQUIRED.replace("q2 = 5000", "q2 = nan"), "[gyro] q2 = NaN"),
            (
                REQUIRED.replace("q1 = 5000", "q1 = 5000\nbogus = 1"),
                "c.toml line 5 in [gyro]: unknown field `bogus`",
            ),
            (
                format!("[bogus]\nx = 1\n{REQUIRED}"),
                "c.toml line 1 in [bogus]: unknown field `bogus`",
            ),
            (
                REQUIRED.replace("carrier_hz = 1.0123e6", "carrier_hz = 30e6"),
                "[drive] carrier_hz = 30000000",
            ),
            (
                REQUIRED.replace("[100, 200]", "[]"),
                "[experiment] readout_rates_dps is empty",
            ),
            (
                REQUIRED.replace("[2, 4]", "[10.0, 10.0]"),
                "[experiment] cal_freqs_hz: give at least 2 distinct",
            ),
            (
                REQUIRED.replace("q1 = 5000", "q1 = \"high\""),
                "c.toml line 4 in [gyro]: invalid type",
            ),
            (REQUIRED.replace("[gyro]", "[gyro"), "c.toml line 1"),
            (
                format!("{REQUIRED}[filter]\ndecimation = 8\n"),
                &format!("[filter] decimation = 8: allowed {MIN_DECIMATION}..=4096"),
            ),
            (
                REQUIRED.replace("cal_freqs_hz", "budget_s = 0\ncal_freqs_hz"),
                "[experiment] budget_s = 0: allowed",
            ),
            (
                REQUIRED.replace("cal_freqs_hz", "rest_bound_dps = 0\ncal_freqs_hz"),
                "[experiment] rest_bound_dps = 0: allowed 0 < rest_bound_dps <= 1 deg/s",
            ),
            (
                REQUIRED.replace("cal_freqs_hz", "rest_bound_dps = 5\ncal_freqs_hz"),
                "[experiment] rest_bound_dps = 5: allowed 0 < rest_bound_dps <= 1 deg/s",
            ),
            (
                format!("{REQUIRED}[frontend]\nadc_per_meter1 = 1e9\n"),
                "[frontend] adc_per_meter1 and adc_per_meter2",
            ),
            (
                format!("{REQUIRED}[frontend]\nadc_bits = 7\n"),
                "[frontend] adc_bits = 7: allowed 8..=16 (ADC_CLIP sees the rails of converters of 8 bits and more)",
            ),
            (
                format!("{REQUIRED}[frontend]\ndac_bits = 0\n"),
                "[frontend] dac_bits = 0: allowed 1..=16",
            ),
            (
                REQUIRED.replace("q1 = 5000", "q1 = 5000\nquadrature_dps = 2e5"),
                "[gyro] quadrature_dps = 200000: allowed |quadrature_dps| <= 1e5 deg/s",
            ),
            (
                // sqrt(B1 B2) / (2 lambda) = 1060.1 rad/s = 60,740 deg/s.
                REQUIRED.replace("q1 = 5000", "q1 = 5000\ndamping_coupling_dps = -8e4"),
                "[gyro] damping_coupling_dps = -80000: allowed",
            ),
        ];
        for (text, start) in cases {
            let err = parse("c.toml", &text).unwrap_err().to_string();
            assert!(err.starts_with(start), "{text:?} gave {err:?}");
            assert!(!err.contains('\n'), "{err:?}");
        }
    }
}
