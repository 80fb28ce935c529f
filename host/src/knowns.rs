//! What host code knows about a board and a device: the clock, the
//! datasheet (a starting guess, never the device at the current
//! temperature), the drives it writes, the board's latencies and design
//! force gains, and its own settings. From these it writes registers.

use crate::device::GyroParams;
use crate::error::Error;
use gyrocal_regs::Registers;
use gyrocal_regs::datapath::CarrierProfile;
use gyrocal_regs::map::{BusError, PROFILE_SINCE_MINOR, RegisterAccess};
use gyrocal_regs::plan::{self, FrequencyPlan, Realized};
use serde::Serialize;
use std::f64::consts::{PI, TAU};

/// The output filter and first averaging window the host programs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Derived {
    /// CIC decimation R.
    pub decimation: u32,
    /// Butterworth cut-off (Hz).
    pub butterworth_hz: f64,
    /// RC cut-off (Hz).
    pub rc_hz: f64,
    /// First averaging window (s).
    pub min_window_s: f64,
}

/// Margin on an amplitude time constant estimated from a bandwidth.
pub const TAU_MARGIN: f64 = 1.2;
/// The filter's transient is waited down to this fraction.
pub const FILTER_SETTLE: f64 = 1e-6;

/// What host software knows (module header).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Knowns {
    /// FPGA clock (Hz).
    pub clock_hz: f64,
    /// Relative bound of the clock's error (the oscillator's +-
    /// tolerance; 0: none given): the self-calibrated scale factors carry
    /// it (`selfcal::budget::clock`).
    pub clock_tolerance: f64,
    /// Datasheet device (at the factory temperature).
    pub nominal: GyroParams,
    /// Relative 1-sigma uncertainty of the datasheet's angular gain
    /// lambda (it enters every predicted ratio one for one).
    pub angular_gain_uncertainty: f64,
    /// Relative 1-sigma of the drive-gain ratio g2 / g1 against the
    /// design, from the datasheet: the budget's term for a ratio the cycle
    /// could not measure (`selfcal::budget::design_drive_ratio`).
    pub drive_gain_ratio_uncertainty: f64,
    /// Readout drive amplitudes (fractions of full scale).
    pub amplitude: (f64, f64),
    /// Design force per full-scale DAC word of drive 1 and 2 (N/kg): only
    /// their ratio enters the scale factors in z LSB.
    pub force_full_scale: [f64; 2],
    /// DAC latency (clocks).
    pub dac_latency: u32,
    /// ADC latency (clocks).
    pub adc_latency: u32,
    /// Output filter and first averaging window.
    pub filter: Derived,
    /// The configured carrier (Hz): where the host operates against the
    /// datasheet's modes (`operating_carrier`).
    pub carrier_hz: f64,
    /// Rates of the factory rate table (deg/s).
    pub rates_dps: Vec<f64>,
    /// Calibration frequencies of the staircase (Hz).
    pub cal_freqs_hz: Vec<f64>,
    /// The core the board carries (`[drive] carrier_profile`): how it
    /// forms its drive and reference words, which the predictions take
    /// at their realized amplitudes (`gyrocal_regs::datapath::readout_word`).
    #[serde(serialize_with = "profile_name")]
    pub carrier_profile: CarrierProfile,
    /// The most the device turns about its sensitive axis during the
    /// self-calibration cycle (deg/s), when the user knows it rests: on a
    /// fixed fixture, Earth's rate at most ([`EARTH_RATE_DPS`]). None: the
    /// cycle knows only what its couplings' windows read
    /// (`selfcal::predicted_rate`).
    pub rest_bound_dps: Option<f64>,
}

/// Earth's rotation rate (deg/s, 15.04 deg/h): the most a device resting
/// on a fixed fixture turns about any axis.
pub const EARTH_RATE_DPS: f64 = 4.178e-3;

fn profile_name<S: serde::Serializer>(p: &CarrierProfile, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(p.name())
}

/// REF_PHASE word of a phase in degrees (2^32 = 360 deg), wrapping.
pub fn phase_word(deg: f64) -> u32 {
    (deg / 360.0 * 2f64.powi(32)).round() as i64 as u32
}

impl Knowns {
    /// A board and device known exactly: the datasheet `nominal` with no
    /// uncertainty on lambda, the drive-gain ratio or the clock, readout
    /// drives at 0.9 of full scale with equal design force gains,
    /// converter latencies of 2 and 3 clocks, the table core, one readout
    /// rate (10 deg/s) and one calibration frequency (3 Hz), an output
    /// filter decimating by 100 with 50 Hz Butterworth and 200 Hz RC
    /// cut-offs and a 0.1 s first window, and no rest bound. What tests,
    /// examples and fake boards start from, each setting what differs by
    /// struct update; a real board's knowns come from its configuration
    /// (`gyrocal_sim::field::scenario`).
    ///
    /// ```
    /// use gyrocal_host::GyroParams;
    /// use gyrocal_host::knowns::Knowns;
    /// let gyro = GyroParams { f1_hz: 25.1e3, f2_hz: 25.8e3, q1: 3e3, q2: 3e3,
    ///     angular_gain: 0.8, quadrature_dps: 0.0, damping_coupling_dps: 0.0 };
    /// let knowns = Knowns {
    ///     rates_dps: vec![50.0, 100.0],
    ///     ..Knowns::exact(gyro, 1.2345e6, 25.1e3)
    /// };
    /// assert_eq!(knowns.bandwidth_hz(0), 25.1e3 / 3e3);
    /// // 0.1 s of z samples at 1.2345 MHz / 100.
    /// assert_eq!(knowns.window_samples(), 1235);
    /// ```
    pub fn exact(nominal: GyroParams, clock_hz: f64, carrier_hz: f64) -> Self {
        Self {
            clock_hz,
            clock_tolerance: 0.0,
            nominal,
            angular_gain_uncertainty: 0.0,
            drive_gain_ratio_uncertainty: 0.0,
            amplitude: (0.9, 0.9),
            force_full_scale: [1.0, 1.0],
            dac_latency: 2,
            adc_latency: 3,
            filter: Derived {
                decimation: 100,
                butterworth_hz: 50.0,
                rc_hz: 200.0,
                min_window_s: 0.1,
            },
            carrier_hz,
            rates_dps: vec![10.0],
            cal_freqs_hz: vec![3.0],
            carrier_profile: CarrierProfile::Table,
            rest_bound_dps: None,
        }
    }

    /// Registers for a carrier, calibration frequency (`None`: readout),
    /// drive amplitudes and a reference phase lag (deg) on top of the
    /// aligned value.
    pub fn registers(
        &self,
        carrier_hz: f64,
        cal_hz: Option<f64>,
        amplitude: (f64, f64),
        ref_lag_deg: f64,
    ) -> Result<(Registers, Realized), Error> {
        let plan = FrequencyPlan {
            clock_hz: self.clock_hz,
            carrier_hz,
            cal_hz: cal_hz.unwrap_or(0.0),
            calibration: cal_hz.is_some(),
            amplitude,
            decimation: self.filter.decimation,
            butterworth_hz: self.filter.butterworth_hz,
            rc_hz: self.filter.rc_hz,
            dac_latency: self.dac_latency,
            adc_latency: self.adc_latency,
        };
        let (mut regs, realized) = plan::registers(&plan)?;
        regs.ref_phase = regs.ref_phase.wrapping_add(phase_word(-ref_lag_deg));
        Ok((regs, realized))
    }

    /// One line when no clock tolerance was given for a real board: the
    /// host cannot see its oscillator's error (everything it measures
    /// runs on that clock), which moves the self-calibrated scale factors
    /// by one to two and a half times the error (`selfcal::budget::clock`)
    /// and is then in no sigma.
    pub fn clock_tolerance_missing(&self) -> Option<String> {
        (self.clock_tolerance == 0.0).then(|| {
            "warning: [drive] clock_tolerance_ppm is not given: the board's oscillator error, which the host cannot see, moves the scale factors by one to two and a half times itself (50 ppm: up to 1.2e-4) and is in no sigma; give the oscillator's +- tolerance".to_string()
        })
    }

    /// The board's word on its core over the configuration's: sets
    /// `carrier_profile` to the profile the board's PROFILE register reads
    /// (`transport::core_profile`). Returns one line where that overrides
    /// the configured profile, or where the core (a register map older
    /// than PROFILE) cannot say and the configured one stands.
    pub fn take_board_profile(
        &mut self,
        board: &mut (impl RegisterAccess + ?Sized),
    ) -> Result<Option<String>, BusError> {
        let configured = self.carrier_profile;
        Ok(match crate::transport::core_profile(board)? {
            Some(built) if built == configured => None,
            Some(built) => {
                self.carrier_profile = built;
                Some(format!(
                    "warning: the board's core is the {built} profile (PROFILE reads {}), not [drive] carrier_profile = \"{configured}\": the predictions take the board's",
                    built.word()
                ))
            }
            None => Some(format!(
                "warning: the board's core (register map older than 1.{PROFILE_SINCE_MINOR}) does not say its carrier profile: [drive] carrier_profile = \"{configured}\" is assumed"
            )),
        })
    }

    /// Clocks for the output filter to settle to `FILTER_SETTLE` (the
    /// slowest Butterworth pole, the RC pole, the CIC's 4 R).
    pub fn filter_settle_clocks(&self) -> u64 {
        let t = (1.0 / FILTER_SETTLE).ln() / self.filter_decay_per_s();
        (t * self.clock_hz).ceil() as u64 + 5 * u64::from(self.filter.decimation)
    }

    /// The output filter's slowest decay rate (1/s): the Butterworth
    /// poles' real part or the RC pole, the smaller.
    pub fn filter_decay_per_s(&self) -> f64 {
        let f = &self.filter;
        (TAU * f.butterworth_hz / 2f64.sqrt()).min(TAU * f.rc_hz)
    }

    /// Amplitude time constant of mode k from the datasheet, with a 20%
    /// margin for Q drift (s).
    pub fn tau_s(&self, k: usize) -> f64 {
        TAU_MARGIN * self.nominal.q(k) / (PI * self.nominal.f_hz(k))
    }

    /// Clocks to wait `taus` of the slower mode's time constant plus the
    /// filter.
    pub fn settle_clocks(&self, taus: f64) -> u64 {
        let tau = self.tau_s(0).max(self.tau_s(1));
        (taus * tau * self.clock_hz).ceil() as u64 + self.filter_settle_clocks()
    }

    /// The carrier for identified modes at `f1` and `f2` (Hz): the
    /// configured carrier keeps its offset from the nearer datasheet mode,
    /// so a carrier written at the datasheet's mode 1 follows mode 1
    /// wherever it is found, one written midway keeps its offset from the
    /// nearer mode, and a datasheet whose f1 is off (process spread)
    /// carries no error into the operating point.
    pub fn operating_carrier(&self, f1: f64, f2: f64) -> f64 {
        let (d1, d2) = (self.nominal.f1_hz, self.nominal.f2_hz);
        let c = self.carrier_hz;
        if (c - d1).abs() <= (c - d2).abs() {
            f1 + (c - d1)
        } else {
            f2 + (c - d2)
        }
    }

    /// One line when the configured carrier lies farther from the nearer
    /// datasheet mode than the modes lie from each other: the cycle keeps
    /// that offset from the mode it finds (`operating_carrier`), so the
    /// carrier runs off both modes, a readout unlike the one at a mode. The
    /// usual cause is a carrier written at the device's measured f1 while
    /// `[datasheet]` gives another; a carrier at a mode or between the two
    /// says nothing.
    pub fn carrier_off_the_modes(&self) -> Option<String> {
        let (d1, d2) = (self.nominal.f1_hz, self.nominal.f2_hz);
        let c = self.carrier_hz;
        let (k, d) = if (c - d1).abs() <= (c - d2).abs() {
            (1, d1)
        } else {
            (2, d2)
        };
        let split = (d2 - d1).abs();
        ((c - d).abs() > split).then(|| {
            format!(
                "warning: [drive] carrier_hz = {c:.1} Hz is {:+.1} Hz from the datasheet's f{k} ({d:.1} Hz), farther than the modes' split ({split:.1} Hz): the cycle keeps that offset from the f{k} it finds and runs the carrier off both modes; if it was meant on the mode, write carrier_hz at the datasheet's f{k} or correct [datasheet] f{k}_hz",
                c - d
            )
        })
    }

    /// These knowns with `gyro` as the device: every wait after
    /// identification uses the identified modes, not the datasheet's.
    pub fn with_device(&self, gyro: &GyroParams) -> Self {
        Self {
            nominal: gyro.clone(),
            carrier_hz: self.operating_carrier(gyro.f1_hz, gyro.f2_hz),
            ..self.clone()
        }
    }

    /// Datasheet bandwidth f / Q of mode k (Hz).
    pub fn bandwidth_hz(&self, k: usize) -> f64 {
        self.nominal.bandwidth_hz(k)
    }

    /// z samples in the first averaging window.
    pub fn window_samples(&self) -> u64 {
        (self.filter.min_window_s * self.clock_hz / f64::from(self.filter.decimation)).ceil() as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn knowns(carrier_hz: f64) -> Knowns {
        let nominal = GyroParams {
            f1_hz: 34_155.0,
            f2_hz: 34_570.0,
            q1: 1e4,
            q2: 1e4,
            angular_gain: 0.7,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
        };
        Knowns::exact(nominal, 1.6e6, carrier_hz)
    }

    /// At a mode, between the two, or beyond one by less than the split
    /// (415 Hz): nothing. Beyond by more, on either side: one line with
    /// the offset, the mode and the split.
    #[test]
    fn a_carrier_off_both_modes_is_said_and_one_near_them_is_not() {
        for c in [34_155.0, 34_362.5, 34_570.0, 33_741.0, 34_984.0] {
            assert_eq!(knowns(c).carrier_off_the_modes(), None, "{c}");
        }
        let line = knowns(33_000.0).carrier_off_the_modes().unwrap();
        assert!(
            line.starts_with(
                "warning: [drive] carrier_hz = 33000.0 Hz is -1155.0 Hz from the datasheet's f1 (34155.0 Hz), farther than the modes' split (415.0 Hz)"
            ),
            "{line}"
        );
        // Just past the split (416 Hz below f1).
        assert!(knowns(33_739.0).carrier_off_the_modes().is_some());
        let line = knowns(35_000.0).carrier_off_the_modes().unwrap();
        assert!(
            line.contains("is +430.0 Hz from the datasheet's f2 (34570.0 Hz)"),
            "{line}"
        );
    }

    /// A core's register bank that answers VERSION with `version`.
    struct Core(gyrocal_regs::map::RegisterBank, u32);

    impl RegisterAccess for Core {
        fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
            self.0.write(offset, word, 0xf)
        }
        fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
            if offset == gyrocal_regs::map::VERSION.offset {
                Ok(self.1)
            } else {
                self.0.read(offset)
            }
        }
    }

    /// The board's PROFILE over the configured profile: the same, nothing
    /// said; another, taken and said in one line; a core of map 1.1, which
    /// has no PROFILE, the configured one kept and said; a core of
    /// another major version, an error.
    #[test]
    fn the_boards_profile_is_taken_and_a_difference_said() {
        use gyrocal_regs::map::{RegisterBank, VERSION_WORD};
        let core = |p| RegisterBank::power_up_for(p);
        for built in CarrierProfile::ALL {
            for configured in CarrierProfile::ALL {
                let mut k = knowns(34_155.0);
                k.carrier_profile = configured;
                let said = k.take_board_profile(&mut Core(core(built), VERSION_WORD));
                assert_eq!(k.carrier_profile, built);
                let said = said.unwrap();
                assert_eq!(said.is_some(), built != configured, "{built} {configured}");
                if let Some(line) = said {
                    assert!(
                        line.contains(&format!(
                            "the board's core is the {built} profile (PROFILE reads {})",
                            built.word()
                        )) && line.contains(&format!("carrier_profile = \"{configured}\"")),
                        "{line}"
                    );
                }
            }
        }
        let mut k = knowns(34_155.0);
        k.carrier_profile = CarrierProfile::Fine;
        let line = k
            .take_board_profile(&mut Core(core(CarrierProfile::Table), 0x0001_0001))
            .unwrap()
            .unwrap();
        assert_eq!(k.carrier_profile, CarrierProfile::Fine);
        assert!(
            line.contains(
                "does not say its carrier profile: [drive] carrier_profile = \"fine\" is assumed"
            ),
            "{line}"
        );
        let other = k.take_board_profile(&mut Core(core(CarrierProfile::Table), 0x0002_0000));
        assert!(
            other
                .unwrap_err()
                .to_string()
                .starts_with("VERSION reads 2.0 (0x00020000)")
        );
    }
}
