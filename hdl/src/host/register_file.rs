//! `RegisterFile`: everything the bus top's register map
//! (`register_map`) holds: the settings, the status words and their
//! sources, the decode of a write and of a read, and the settings as the
//! datapath core's ports.
//!
//! ```text
//!  write, write_index, write_data, write_mask ──► SettingRegister x15 ──► core ports
//!                                      write_hit ◄┘    (MOD_STEP_LO staged until MOD_STEP_HI)
//!  z1, z2, z_valid, dropped, adc1, adc2 ──► StatusCounters ──► beat (stream)
//!                               counts, z snapshot, clip counts ──┐
//!  ID, VERSION, PROFILE ──────────────────────────────────────────┴──► StatusWord x10
//!  read_index ──► SettingRegister x15 / StatusWord x10 ──► read_hit, read_word
//!  read ──► a read of SAMPLE_COUNT latches the snapshot, of ADC_CLIP clears the clip counts
//! ```
//!
//! Widths: bus words 32 bits, word index `WORD_INDEX_BITS`; the core ports
//! take each field's width (REGISTERS.md). `write_hit`, `read_hit` and
//! `read_word` are combinational from the inputs and the registers; a write
//! shows on the core ports one clock after its edge, except MOD_STEP_LO,
//! which is staged and reaches `mod_step` together with the next write of
//! MOD_STEP_HI (the 48-bit step changes at once). `reset` (active high,
//! synchronous) restores every setting's power-up value (drives off),
//! clears the staged low word, the counts and the snapshot.

use super::clip_counter::COUNT_BITS;
use super::register_map::{
    ADC_CLIP, AMP1, AMP2, CARRIER_STEP, CIC_DECIMATION, CIC_SHIFT, DATA_BITS, ID, IIR_ALPHA,
    IIR_K0, IIR_K1, IIR_K2, MOD_STEP_HI, MOD_STEP_LO, PROFILE, REF_DELAY, REF_PHASE, Register,
    SAMPLE_COUNT, SELECT, STREAM_ENABLE, STREAM_OVERFLOW, VERSION, WORD_INDEX_BITS, Z1_HI, Z1_LO,
    Z2_HI, Z2_LO,
};
use super::sample_fifo::SAMPLE_BITS;
use super::setting_register::SettingRegister;
use super::status_counters::{CounterWords, StatusCounters};
use super::status_word::StatusWord;
use super::{Z_BITS, register_map};
use crate::cic_decimator::{DECIMATION_BITS, SHIFT_BITS};
use crate::reference_alignment::DELAY_BITS;
use gyrocal_regs::datapath::CarrierProfile;
use rust_hdl::prelude::*;

/// The settings in the order of `RegisterFile::settings` (the wiring in
/// `update` uses these indices).
pub const SETTINGS: [Register; 15] = [
    SELECT,
    CARRIER_STEP,
    REF_PHASE,
    REF_DELAY,
    MOD_STEP_LO,
    MOD_STEP_HI,
    AMP1,
    AMP2,
    CIC_DECIMATION,
    CIC_SHIFT,
    IIR_K0,
    IIR_K1,
    IIR_K2,
    IIR_ALPHA,
    STREAM_ENABLE,
];

/// The status words in the order of `RegisterFile::status`.
pub const STATUS: [Register; 10] = [
    ID,
    VERSION,
    STREAM_OVERFLOW,
    SAMPLE_COUNT,
    Z1_LO,
    Z1_HI,
    Z2_LO,
    Z2_HI,
    ADC_CLIP,
    PROFILE,
];

/// The model of the status words' sources, as `update` wires them: the
/// live value of each word of `STATUS`, in its order, from the counters'
/// words of the cycle (`StatusCounters`' model), in the core with this
/// carrier profile. Each `StatusWord` then returns its field
/// (`Register::extend`).
pub fn status_live(counters: &CounterWords, profile: CarrierProfile) -> [u32; STATUS.len()] {
    let c = counters;
    [
        ID.power_up,
        VERSION.power_up,
        c.overflow,
        c.count,
        c.z1_low,
        c.z1_high,
        c.z2_low,
        c.z2_high,
        c.clip,
        profile.word(),
    ]
}

const _: () = assert!(SETTINGS.len() + STATUS.len() == register_map::REGISTERS.len());
// The core ports' widths, which `update` cuts from the fields as literals.
const _: () = assert!(DELAY_BITS == 6 && DECIMATION_BITS == 13 && SHIFT_BITS == 6);
const _: () = assert!(Z_BITS == 40 && COUNT_BITS == 16);

/// Settings, status words and their decode.
#[derive(LogicBlock)]
pub struct RegisterFile {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset of the settings to power-up (active high).
    pub reset: Signal<In, Bit>,
    /// A bus write happens at this edge.
    pub write: Signal<In, Bit>,
    /// Word index of the write.
    pub write_index: Signal<In, Bits<WORD_INDEX_BITS>>,
    /// Write data.
    pub write_data: Signal<In, Bits<DATA_BITS>>,
    /// Bytes the write strobes select, as a bit mask.
    pub write_mask: Signal<In, Bits<DATA_BITS>>,
    /// `write` addresses a setting (else the write answers SLVERR).
    pub write_hit: Signal<Out, Bit>,
    /// A bus read happens at this edge.
    pub read: Signal<In, Bit>,
    /// Word index of the read.
    pub read_index: Signal<In, Bits<WORD_INDEX_BITS>>,
    /// `read_index` is a mapped word (else the read answers SLVERR).
    pub read_hit: Signal<Out, Bit>,
    /// The word at `read_index` (0 when unmapped).
    pub read_word: Signal<Out, Bits<DATA_BITS>>,
    /// The core's z1.
    pub z1: Signal<In, Signed<Z_BITS>>,
    /// The core's z2.
    pub z2: Signal<In, Signed<Z_BITS>>,
    /// The core publishes a new z during this clock.
    pub z_valid: Signal<In, Bit>,
    /// The stream FIFO drops a sample at this edge.
    pub dropped: Signal<In, Bit>,
    /// ADC word 1, for its clip counter.
    pub adc1: Signal<In, Signed<16>>,
    /// ADC word 2, for its clip counter.
    pub adc2: Signal<In, Signed<16>>,
    /// The stream beat {count\[15:0\], z2, z1} (`StatusCounters`).
    pub beat: Signal<Out, Bits<SAMPLE_BITS>>,
    /// STREAM_ENABLE.
    pub stream_enable: Signal<Out, Bit>,
    /// SELECT: calibration (1) or readout (0).
    pub select: Signal<Out, Bit>,
    /// CARRIER_STEP.
    pub carrier_step: Signal<Out, Bits<32>>,
    /// REF_PHASE.
    pub ref_phase: Signal<Out, Bits<32>>,
    /// REF_DELAY.
    pub ref_delay: Signal<Out, Bits<DELAY_BITS>>,
    /// {MOD_STEP_HI\[15:0\], MOD_STEP_LO} as of the last MOD_STEP_HI write.
    pub mod_step: Signal<Out, Bits<48>>,
    /// AMP1.
    pub amp1: Signal<Out, Signed<16>>,
    /// AMP2.
    pub amp2: Signal<Out, Signed<16>>,
    /// CIC_DECIMATION.
    pub cic_decimation: Signal<Out, Bits<DECIMATION_BITS>>,
    /// CIC_SHIFT.
    pub cic_shift: Signal<Out, Bits<SHIFT_BITS>>,
    /// IIR_K0.
    pub iir_k0: Signal<Out, Signed<32>>,
    /// IIR_K1.
    pub iir_k1: Signal<Out, Signed<32>>,
    /// IIR_K2.
    pub iir_k2: Signal<Out, Signed<32>>,
    /// IIR_ALPHA.
    pub iir_alpha: Signal<Out, Signed<32>>,
    settings: [SettingRegister; 15],
    status: [StatusWord; 10],
    counters: StatusCounters,
    mod_step_low: DFF<Bits<DATA_BITS>>,
    id_word: Constant<Bits<DATA_BITS>>,
    version_word: Constant<Bits<DATA_BITS>>,
    profile_word: Constant<Bits<DATA_BITS>>,
}

impl RegisterFile {
    /// The register file at power-up, in the core with this carrier
    /// profile (PROFILE reads its word).
    pub fn new(profile: CarrierProfile) -> Self {
        Self {
            clock: Default::default(),
            reset: Default::default(),
            write: Default::default(),
            write_index: Default::default(),
            write_data: Default::default(),
            write_mask: Default::default(),
            write_hit: Default::default(),
            read: Default::default(),
            read_index: Default::default(),
            read_hit: Default::default(),
            read_word: Default::default(),
            z1: Default::default(),
            z2: Default::default(),
            z_valid: Default::default(),
            dropped: Default::default(),
            adc1: Default::default(),
            adc2: Default::default(),
            beat: Default::default(),
            stream_enable: Default::default(),
            select: Default::default(),
            carrier_step: Default::default(),
            ref_phase: Default::default(),
            ref_delay: Default::default(),
            mod_step: Default::default(),
            amp1: Default::default(),
            amp2: Default::default(),
            cic_decimation: Default::default(),
            cic_shift: Default::default(),
            iir_k0: Default::default(),
            iir_k1: Default::default(),
            iir_k2: Default::default(),
            iir_alpha: Default::default(),
            settings: std::array::from_fn(|i| SettingRegister::new(&SETTINGS[i])),
            status: std::array::from_fn(|i| StatusWord::new(&STATUS[i])),
            counters: StatusCounters::new(),
            mod_step_low: Default::default(),
            id_word: Constant::new(u64::from(ID.power_up).into()),
            version_word: Constant::new(u64::from(VERSION.power_up).into()),
            profile_word: Constant::new(u64::from(profile.word()).into()),
        }
    }
}

impl Default for RegisterFile {
    /// The table core's.
    fn default() -> Self {
        Self::new(CarrierProfile::Table)
    }
}

impl Logic for RegisterFile {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, mod_step_low);
        // Each setting decodes the write's index and the read's itself.
        self.write_hit.next = false;
        self.read_hit.next = false;
        self.read_word.next = 0.into();
        for i in 0..15 {
            self.settings[i].clock.next = self.clock.val();
            self.settings[i].reset.next = self.reset.val();
            self.settings[i].write.next = self.write.val();
            self.settings[i].write_index.next = self.write_index.val();
            self.settings[i].write_data.next = self.write_data.val();
            self.settings[i].write_mask.next = self.write_mask.val();
            self.settings[i].read_index.next = self.read_index.val();
            if self.settings[i].write_hit.val() {
                self.write_hit.next = true;
            }
            if self.settings[i].read_hit.val() {
                self.read_hit.next = true;
                self.read_word.next = self.settings[i].read_word.val();
            }
        }
        // mod_step: the staged low word moves to the port with the high word.
        if self.settings[5].write_hit.val() {
            self.mod_step_low.d.next = self.settings[4].value.val();
        }
        if self.reset.val() {
            self.mod_step_low.d.next = 0.into();
        }
        // The status words' sources: z counters and snapshot, clip counters.
        self.counters.clock.next = self.clock.val();
        self.counters.reset.next = self.reset.val();
        self.counters.z1.next = self.z1.val();
        self.counters.z2.next = self.z2.val();
        self.counters.z_valid.next = self.z_valid.val();
        self.counters.dropped.next = self.dropped.val();
        self.beat.next = self.counters.beat.val();
        self.counters.adc1.next = self.adc1.val();
        self.counters.adc2.next = self.adc2.val();
        // The over-range counters restart on a read of ADC_CLIP.
        self.counters.clip_clear.next = self.read.val() & self.status[8].read_hit.val();
        // Status words.
        self.status[0].live.next = self.id_word.val();
        self.status[1].live.next = self.version_word.val();
        self.status[2].live.next = self.counters.overflow.val();
        self.status[3].live.next = self.counters.count.val();
        self.status[4].live.next = self.counters.z1_low.val();
        self.status[5].live.next = self.counters.z1_high.val();
        self.status[6].live.next = self.counters.z2_low.val();
        self.status[7].live.next = self.counters.z2_high.val();
        self.status[8].live.next = self.counters.clip.val();
        self.status[9].live.next = self.profile_word.val();
        // Reads: the one word that decodes the index, else none (0).
        for i in 0..10 {
            self.status[i].read_index.next = self.read_index.val();
            if self.status[i].read_hit.val() {
                self.read_hit.next = true;
                self.read_word.next = self.status[i].read_word.val();
            }
        }
        // The read of SAMPLE_COUNT latches the z it counts.
        self.counters.snapshot.next = self.read.val() & self.status[3].read_hit.val();
        // The settings as the core's ports, each cut to its field.
        self.stream_enable.next = self.settings[14].value.val().get_bit(0);
        self.select.next = self.settings[0].value.val().get_bit(0);
        self.carrier_step.next = self.settings[1].value.val();
        self.ref_phase.next = self.settings[2].value.val();
        self.ref_delay.next = self.settings[3].value.val().get_bits::<6>(0);
        self.mod_step.next = bit_cast::<48, DATA_BITS>(self.mod_step_low.q.val())
            | (bit_cast::<48, 16>(self.settings[5].value.val().get_bits::<16>(0)) << 32);
        self.amp1.next = signed_cast(self.settings[6].value.val().get_bits::<16>(0));
        self.amp2.next = signed_cast(self.settings[7].value.val().get_bits::<16>(0));
        self.cic_decimation.next = self.settings[8].value.val().get_bits::<13>(0);
        self.cic_shift.next = self.settings[9].value.val().get_bits::<6>(0);
        self.iir_k0.next = signed_cast(self.settings[10].value.val());
        self.iir_k1.next = signed_cast(self.settings[11].value.val());
        self.iir_k2.next = signed_cast(self.settings[12].value.val());
        self.iir_alpha.next = signed_cast(self.settings[13].value.val());
    }
}

crate::impl_clocked!(RegisterFile);
