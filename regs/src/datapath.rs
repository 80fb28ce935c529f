//! The datapath's numbers that the register map, the frequency plan and the
//! host code need: port widths, limits, the carrier peak, power-up timing.
//!
//! They are defined here, in the leaf crate, and the gateware
//! (`gyrocal-hdl`) imports them downward: the RTL, its bit-true model, the
//! filter design and the host code all read one definition. Where the
//! gateware derives a value from its own structure (a schedule's length, a
//! fill time), `gyrocal-hdl` asserts at compile time that it equals the
//! constant here.

use std::sync::OnceLock;

/// Number of CIC integrator and comb stages.
pub const CIC_STAGES: u32 = 4;
/// log2 of the largest CIC decimation.
pub const MAX_DECIMATION_LOG2: u32 = 12;
/// Largest CIC decimation R: 2^12.
pub const MAX_DECIMATION: u32 = 1 << MAX_DECIMATION_LOG2;
/// Smallest decimation: the IIR's micro-program takes this many clocks per
/// sample (`gyrocal_hdl::iir_lowpass::SCHEDULE_CLOCKS`, asserted equal).
pub const MIN_DECIMATION: u32 = 166;
/// Width of the `cic_decimation` port: R up to 2^12 needs 13 bits.
pub const DECIMATION_BITS: u32 = MAX_DECIMATION_LOG2 + 1;
/// Width of the `cic_shift` port: shifts 0..=40 need 6 bits.
pub const SHIFT_BITS: u32 = 6;
/// Fractional bits of the CIC output and of z (z = average x 2^8).
pub const OUTPUT_FRACTION_BITS: u32 = 8;
/// Fractional bits of the IIR coefficients (Q2.30).
pub const COEFFICIENT_FRACTION_BITS: u32 = 30;
/// Guard bits of the IIR states below the output LSB.
pub const GUARD_BITS: u32 = 16;
/// Width of z1 and z2 (two's complement, `OUTPUT_FRACTION_BITS` fractional).
pub const Z_BITS: u32 = 40;
/// Width of the `ref_delay` port: delays 0..=63 clocks.
pub const DELAY_BITS: u32 = 6;
/// Width of the `mod_step` port.
pub const MOD_STEP_BITS: u32 = 48;
/// Width of the `carrier_step` port and of the carrier phase accumulator.
pub const CARRIER_STEP_BITS: u32 = 32;
/// Peak amplitude of every sine and cosine word of the datapath: full scale
/// of a 16-bit signed word, kept symmetric (never -32768).
pub const PEAK: i32 = 32767;
/// Full-scale amplitude of a 16-bit converter word (LSB).
pub const CONVERTER_FULL_SCALE: f64 = 32767.0;
/// Samples the AXI4-Stream FIFO holds before it drops one.
pub const FIFO_DEPTH: usize = 256;
/// Clocks from configuration until the DAC words can leave 0: the carrier
/// tables are filled first (`gyrocal_hdl::gyro_interface::DRIVE_START_CLOCKS`,
/// asserted equal to the fill plus the carrier and AM latencies).
pub const DRIVE_START_CLOCKS: u64 = 8232;

/// How the carrier NCO makes its sines: the two cores of the gateware,
/// alike in every port, register and latency, different in their carriers.
///
/// ```
/// use gyrocal_regs::datapath::CarrierProfile;
/// assert_eq!("fine".parse::<CarrierProfile>(), Ok(CarrierProfile::Fine));
/// assert_eq!(CarrierProfile::default().to_string(), "table");
/// assert!("ecp5".parse::<CarrierProfile>().is_err());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum CarrierProfile {
    /// Integer words of a quarter-wave table filled at power-up, the phase
    /// rounded to 2^15 a turn (`gyrocal_hdl::table_sine`): the core that
    /// fits an iCE40 UltraPlus (`verilog-out/gyro_interface.v`).
    #[default]
    Table,
    /// Quarter-LSB words in an initialized ROM, three more phase bits
    /// interpolated, carriers kept to a quarter LSB (`gyrocal_hdl::sine_pair`)
    /// and F A x carrier rounded once to the DAC word
    /// (`gyrocal_hdl::am_mixer::FineAmMixer`): block RAM with contents and
    /// four more multipliers, an ECP5 or larger part
    /// (`verilog-out/ecp5/gyro_interface.v`). It removes the slow error a
    /// carrier near a short fold of the clock leaves on the rate.
    Fine,
}

impl CarrierProfile {
    /// Both profiles.
    pub const ALL: [CarrierProfile; 2] = [CarrierProfile::Table, CarrierProfile::Fine];

    /// The PROFILE register's field for this core (`map::PROFILE`):
    /// 0 table, 1 fine.
    pub fn word(self) -> u32 {
        match self {
            CarrierProfile::Table => 0,
            CarrierProfile::Fine => 1,
        }
    }

    /// The profile a PROFILE register's word names, if any.
    ///
    /// ```
    /// use gyrocal_regs::datapath::CarrierProfile;
    /// for p in CarrierProfile::ALL {
    ///     assert_eq!(CarrierProfile::from_word(p.word()), Some(p));
    /// }
    /// assert_eq!(CarrierProfile::from_word(2), None);
    /// ```
    pub fn from_word(word: u32) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.word() == word)
    }

    /// The name in configuration files.
    pub fn name(self) -> &'static str {
        match self {
            CarrierProfile::Table => "table",
            CarrierProfile::Fine => "fine",
        }
    }
}

impl std::fmt::Display for CarrierProfile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A carrier profile name that is not one.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownCarrierProfile(pub String);

impl std::fmt::Display for UnknownCarrierProfile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "carrier profile {:?}: allowed \"table\" (the UP5K core) or \"fine\" (the ECP5 core)",
            self.0
        )
    }
}

impl std::error::Error for UnknownCarrierProfile {}

impl std::str::FromStr for CarrierProfile {
    type Err = UnknownCarrierProfile;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        CarrierProfile::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| UnknownCarrierProfile(s.to_owned()))
    }
}

/// The AM mixer's Q1.15 product: `round(a b / 2^15)`, rounded half up,
/// wrapped to 16 bits (the model of `gyrocal_hdl::q15_multiplier`).
///
/// ```
/// use gyrocal_regs::datapath::q15_product;
/// assert_eq!(q15_product(16384, 16384), 8192);
/// assert_eq!(q15_product(32767, 32767), 32766);
/// ```
#[inline(always)]
pub fn q15_product(a: i16, b: i16) -> i16 {
    ((a as i32 * b as i32 + (1 << 14)) >> 15) as i16
}

/// Fundamental amplitude (LSB) of a readout drive word for a Q1.15
/// amplitude `amp` on the core with `profile`, with its sign: the envelope
/// E = `amp x PEAK / 2^15` rounded as the AM mixer rounds it, then the
/// carrier's product as that core forms it (`carrier_fundamental`). In
/// readout the modulation factor is PEAK.
///
/// ```
/// use gyrocal_regs::datapath::{CarrierProfile, readout_word};
/// // 0.9 of full scale: E = 29490 times the carrier's PEAK / 2^15.
/// assert_eq!(readout_word(CarrierProfile::Fine, 29491), 29490.0 * 32767.0 / 32768.0);
/// let table = readout_word(CarrierProfile::Table, 29491);
/// assert!((table / (29490.0 * 32767.0 / 32768.0) - 1.0).abs() < 1e-6);
/// ```
pub fn readout_word(profile: CarrierProfile, amp: i16) -> f64 {
    carrier_fundamental(profile, q15_product(amp, PEAK as i16))
}

/// Fundamental amplitude (LSB) of the drive word `E x carrier` for a held
/// envelope word E on the core with `profile`: on the fine core the exact
/// product E x PEAK / 2^15 (its rounding error is fed back with zeros at
/// the carrier, `gyrocal_hdl::carrier_multiplier`); on the table core the
/// fundamental of the words `round(E c / 2^15)` over the carrier table's
/// 32768 phases a turn (`table_product_fundamental`), which a carrier away
/// from short folds visits evenly.
///
/// A rounded sine of small amplitude has a fundamental off its own: on the
/// table core +3.0e-5 at E = 260, +1.0e-4 at E = 100 and +5e-4 at E = 37,
/// 1.4e-6 at 3686 and 1e-7 at 29490. An unseen device with Q 1e5 on a
/// 16.3 MHz clock, driven at E = 65, read its self-calibrated scale factors
/// +2.3e-4 off on the table core over four seeds (1.7 to 2.0 sigma, every
/// seed) and +0.8e-5 on the fine core, before the host counted it.
pub fn carrier_fundamental(profile: CarrierProfile, envelope: i16) -> f64 {
    match profile {
        CarrierProfile::Fine => exact_product(envelope),
        CarrierProfile::Table => table_product_fundamental(i32::from(envelope)),
    }
}

/// Intervals a quadrant of the table core's carrier table: 8192 words,
/// each a quarter of a modulation-ROM step from a ROM centre
/// (`gyrocal_hdl::carrier_table_fill`, whose model
/// `gyrocal_hdl::model::carrier_nco::table` the hdl crate checks against
/// [`carrier_table_word`]).
pub const CARRIER_TABLE_ENTRIES: usize = 2 * MODULATION_TABLE_ENTRIES;

/// The table core's carrier word `i` (first quadrant, 0..8192), as its
/// power-up fill writes it: the modulation ROM's words at the ROM centres
/// j = i / 2 and j -+ 1 (even i: j - 1, odd: j + 1), weights 3 : 1, rounded
/// half to even. Outside 0..4096 the ROM's sine runs on: -word(0) below,
/// word(4095) above (the quadrant's mirror).
pub fn carrier_table_word(i: usize) -> i32 {
    let rom = |k: i64| match k {
        -1 => -modulation_word(0),
        k if k >= MODULATION_TABLE_ENTRIES as i64 => modulation_word(MODULATION_TABLE_ENTRIES - 1),
        k => modulation_word(k as usize),
    };
    let j = (i / 2) as i64;
    let (near, far) = if i.is_multiple_of(2) {
        (rom(j), rom(j - 1))
    } else {
        (rom(j), rom(j + 1))
    };
    let sum = 3 * near + far;
    (sum + 1 + ((sum >> 2) & 1)) >> 2
}

/// A quarter-wave table's words over a whole turn, 4 x `entries` samples:
/// quadrant q reads `word(i)`, mirrored (`entries - 1 - i`) in odd
/// quadrants and negated in the second half, as the gateware's lookups do
/// (`gyrocal_hdl::quarter_wave`); each with the sine at its interval's
/// centre, (p + 1/2) / (4 entries) of a turn.
fn quarter_wave_turn(entries: usize, word: impl Fn(usize) -> i32) -> Vec<(i32, f64)> {
    let n = 4 * entries;
    (0..n)
        .map(|p| {
            let (q, i) = (p / entries, p % entries);
            let w = word(if q % 2 == 0 { i } else { entries - 1 - i });
            let theta = std::f64::consts::TAU * (p as f64 + 0.5) / n as f64;
            (if q >= 2 { -w } else { w }, theta.sin())
        })
        .collect()
}

/// The table core's carrier words over a turn (`quarter_wave_turn`),
/// built once per process.
fn carrier_turn() -> &'static [(i32, f64)] {
    static TURN: OnceLock<Vec<(i32, f64)>> = OnceLock::new();
    TURN.get_or_init(|| quarter_wave_turn(CARRIER_TABLE_ENTRIES, carrier_table_word))
}

/// The modulation sine's words over a turn (`quarter_wave_turn`), built
/// once per process.
fn modulation_turn() -> &'static [(i32, f64)] {
    static TURN: OnceLock<Vec<(i32, f64)>> = OnceLock::new();
    TURN.get_or_init(|| quarter_wave_turn(MODULATION_TABLE_ENTRIES, modulation_word))
}

/// Fundamental (LSB) of the table core's words `round(E c / 2^15)`, rounded
/// half up, over the carrier's turn.
fn table_product_fundamental(envelope: i32) -> f64 {
    let turn = carrier_turn();
    let sum: f64 = turn
        .iter()
        .map(|&(c, sin)| f64::from((envelope * c + (1 << 14)) >> 15) * sin)
        .sum();
    2.0 * sum / turn.len() as f64
}

/// The table core's words `round(E c / 2^15)` (rounded half up) over the
/// carrier's turn, one per interval of its N = 32768 (phase (p + 1/2) / N
/// of a turn): the function of the phase whose harmonics the sampling
/// folds (`gyrocal_host::selfcal::spurs`).
///
/// ```
/// use gyrocal_regs::datapath::{CarrierProfile::Table, readout_word, table_product_turn};
/// let words = table_product_turn(29490);
/// let n = words.len() as f64;
/// let sine: f64 = words.iter().enumerate()
///     .map(|(p, &w)| w * (std::f64::consts::TAU * (p as f64 + 0.5) / n).sin())
///     .sum();
/// assert_eq!(2.0 * sine / n, readout_word(Table, 29491));
/// ```
pub fn table_product_turn(envelope: i32) -> Vec<f64> {
    carrier_turn()
        .iter()
        .map(|&(c, _)| f64::from((envelope * c + (1 << 14)) >> 15))
        .collect()
}

/// Envelopes up to which the calibration word sums the table core's
/// products exactly ([`carrier_fundamental`]); above it, E x PEAK / 2^15,
/// which is within 1.4e-6 of the fundamental there (3686: 1.4e-6; 29490:
/// 1e-7), and the larger envelopes of a calibration period average their
/// differences further.
pub const EXACT_ENVELOPES: i32 = 4096;

/// [`carrier_fundamental`] of the table core for every envelope 0..=4096,
/// built once per process (0.1 s).
fn small_envelopes() -> &'static [f64] {
    static SMALL: OnceLock<Vec<f64>> = OnceLock::new();
    SMALL.get_or_init(|| {
        (0..=EXACT_ENVELOPES)
            .map(table_product_fundamental)
            .collect()
    })
}

/// Address bits of the modulation sine's quarter-wave ROM: 4096 words a
/// quadrant (`gyrocal_hdl::sine_table`, which reads them from here).
pub const MODULATION_TABLE_BITS: usize = 12;
/// Words a quadrant of the modulation sine's ROM.
pub const MODULATION_TABLE_ENTRIES: usize = 1 << MODULATION_TABLE_BITS;

/// The modulation ROM's word `i` (first quadrant, sampled at the centre of
/// its interval): `round(PEAK sin((i + 1/2) pi / 2 / 4096))`, in [0, PEAK].
///
/// ```
/// use gyrocal_regs::datapath::{MODULATION_TABLE_ENTRIES, PEAK, modulation_word};
/// assert_eq!(modulation_word(MODULATION_TABLE_ENTRIES - 1), PEAK);
/// assert_eq!(modulation_word(0), 6);
/// ```
pub fn modulation_word(i: usize) -> i32 {
    let d = std::f64::consts::FRAC_PI_2 / MODULATION_TABLE_ENTRIES as f64;
    (f64::from(PEAK) * ((i as f64 + 0.5) * d).sin()).round() as i32
}

/// Fundamental amplitude (LSB) of a calibration drive word's envelope
/// crest for a Q1.15 amplitude `amp` on the core with `profile`, with its
/// sign: the fundamental of the envelope words E = `round(amp x A / 2^15)`
/// (`q15_product`) over the modulation sine's words A, which a calibration
/// period visits evenly, each envelope times the carrier as that core
/// forms its product ([`carrier_fundamental`]: the carrier turns some
/// 1e5 times for every envelope step).
///
/// The envelope's rounding does not average out of its fundamental: a
/// rounded sine of small amplitude has a fundamental off its own. At the
/// drive a high-Q device gets to stay clear of the ADC's rails (amp 260,
/// 0.8% of full scale) the envelope's fundamental is 3.7e-5 above amp
/// PEAK / 2^15; drive and reference of a channel share that envelope, so
/// the calibration signal was 7.3e-5 above what the prediction took (amp
/// PEAK^2 / 2^30), on both outputs. Measured on an unseen device (4.1 MHz,
/// Q 20000, amp 260, 8 noise seeds, the rate table's truth 16 times
/// longer than a field step's): the self-calibrated scale factors were
/// +8.8e-5 and +6.6e-5 off (standard errors 0.8e-5 and 0.6e-5), on either
/// core and at calibration frequencies 15 to 25 Hz and 30 to 50 Hz alike.
/// At amp 29490 (0.9 of full scale) the difference is 3e-7.
///
/// ```
/// use gyrocal_regs::datapath::{CarrierProfile::Fine, PEAK, calibration_word};
/// let crest = |amp: i16| f64::from(amp) * f64::from(PEAK) / 32768.0 * f64::from(PEAK) / 32768.0;
/// assert!((calibration_word(Fine, 29490) / crest(29490) - 1.0).abs() < 1e-6);
/// assert!(calibration_word(Fine, 260) / crest(260) - 1.0 > 3e-5);
/// assert!((calibration_word(Fine, -260) + calibration_word(Fine, 260)).abs() < 1e-9);
/// ```
pub fn calibration_word(profile: CarrierProfile, amp: i16) -> f64 {
    let turn = modulation_turn();
    let sum: f64 = turn
        .iter()
        .map(|&(a, sin)| envelope_fundamental(profile, q15_product(amp, a as i16)) * sin)
        .sum();
    2.0 * sum / turn.len() as f64
}

/// [`carrier_fundamental`], from the table core's table of small envelopes
/// where it has one ([`EXACT_ENVELOPES`]).
fn envelope_fundamental(profile: CarrierProfile, envelope: i16) -> f64 {
    let e = i32::from(envelope);
    match profile {
        CarrierProfile::Table if e.abs() <= EXACT_ENVELOPES => {
            // Odd in E: the turn holds c and -c alike.
            small_envelopes()[e.unsigned_abs() as usize] * f64::from(e.signum())
        }
        _ => exact_product(envelope),
    }
}

/// E x PEAK / 2^15: the envelope times the carrier's amplitude, unrounded.
fn exact_product(envelope: i16) -> f64 {
    f64::from(envelope) * f64::from(PEAK) / 32768.0
}
