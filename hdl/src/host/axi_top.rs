//! `GyroInterfaceAxi`: the bus-attached top, exported as `gyro_interface_axi`.
//!
//! ```text
//!            ┌──────────────────────────── gyro_interface_axi ─────────────────────────────┐
//!  s_axil_* ─┤ AXI4-Lite slave ─► SettingRegister x15 ──► settings ports ─► GyroInterface ├─ dac1, dac2
//!            │        ▲          StatusWord x9 ◄─ ID, VERSION, counters,   (the core)    ├◄ adc1, adc2
//!            │        ├──────────────────────── z snapshot ◄── z1, z2, z_valid ──┘       │
//!            │        └──────────────────────── ClipCounter x2 ◄── adc1, adc2            │
//!  m_axis_* ◄┤ SampleFifo (256 x 96 bit) ◄── {count[15:0], z2, z1} when STREAM_ENABLE      │
//!            └────────────────────────────────────────────────────────────────────────────┘
//! ```
//!
//! One clock `aclk` for the bus, the stream and the datapath. `aresetn`
//! (active low, synchronous, as AXI requires for the handshake state)
//! returns every register of this wrapper to its power-up value: the
//! settings (drives off), the handshakes, counters, snapshot and FIFO. The
//! datapath core has no reset; its state flushes within 4R + 12 clocks.
//!
//! AXI4-Lite slave (8-bit byte address, 32-bit data, register map in
//! `register_map`): AW and W are each taken into a holding register
//! (`awready` = AW holding empty, likewise `wready`), in either order or
//! together; once both are held and no response is pending, the write
//! happens and B is raised, held until `bready`. AR is held likewise; the
//! read happens once no R is pending and R is held until `rready`, its data
//! fixed. Latency: write response 2 clocks after the later of AW and W;
//! read data 2 clocks after AR. SLVERR (resp = 2) for an unmapped offset or
//! a write to a read-only word; then nothing changes. Ready signals depend
//! only on registers, never combinationally on a valid.
//!
//! Coherent snapshot: the read of SAMPLE_COUNT latches z1 and z2 at the
//! edge that returns the count, so Z1_LO..Z2_HI read afterwards hold that
//! sample. The count during a z_valid clock includes that sample (the core's
//! z ports hold it during that clock).
//!
//! AXI4-Stream master: `m_axis_tdata` 96 bits = {sample count \[15:0\], z2,
//! z1} (z 40-bit two's complement, 8 fractional bits), `m_axis_tlast` = 1.

use super::clip_counter::{COUNT_BITS, ClipCounter};
use super::register_map::{
    self, ADC_CLIP, ADDRESS_BITS, AMP1, AMP2, CARRIER_STEP, CIC_DECIMATION, CIC_SHIFT, DATA_BITS,
    ID, IIR_ALPHA, IIR_K0, IIR_K1, IIR_K2, MOD_STEP_HI, MOD_STEP_LO, REF_DELAY, REF_PHASE,
    Register, SAMPLE_COUNT, SELECT, STREAM_ENABLE, STREAM_OVERFLOW, VERSION, WORD_INDEX_BITS,
    Z1_HI, Z1_LO, Z2_HI, Z2_LO,
};
use super::sample_fifo::{SAMPLE_BITS, SampleFifo};
use super::setting_register::SettingRegister;
use super::status_word::StatusWord;
use super::{RESP_BITS, SLVERR, Z_BITS};
use crate::gyro_interface::{FineGyroInterface, GyroInterface};
use rust_hdl::prelude::*;

/// The settings in the order of `GyroInterfaceAxi::settings` (the wiring in
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

/// The status words in the order of `GyroInterfaceAxi::status`.
pub const STATUS: [Register; 9] = [
    ID,
    VERSION,
    STREAM_OVERFLOW,
    SAMPLE_COUNT,
    Z1_LO,
    Z1_HI,
    Z2_LO,
    Z2_HI,
    ADC_CLIP,
];

const _: () = assert!(Z_BITS == 40 && SAMPLE_BITS == 2 * Z_BITS + 16);
const _: () = assert!(SETTINGS.len() + STATUS.len() == register_map::REGISTERS.len());

/// Declares a bus-attached top around the given datapath core: the struct,
/// its constructor and its wiring, written once for both cores.
macro_rules! axi_top {
    ($(#[$meta:meta])* $name:ident, $core:ident) => {
        $(#[$meta])*
        #[derive(LogicBlock)]
        pub struct $name {
            /// The clock of the bus, the stream and the datapath (rising edge).
            pub aclk: Signal<In, Clock>,
            /// Active-low synchronous reset of the bus wrapper (not of the datapath core).
            pub aresetn: Signal<In, Bit>,
            /// ADC word of gyroscope output 1 (16-bit two's complement).
            pub adc1: Signal<In, Signed<16>>,
            /// ADC word of gyroscope output 2 (16-bit two's complement).
            pub adc2: Signal<In, Signed<16>>,
            /// DAC word of drive 1 (16-bit two's complement).
            pub dac1: Signal<Out, Signed<16>>,
            /// DAC word of drive 2 (16-bit two's complement).
            pub dac2: Signal<Out, Signed<16>>,
            /// AXI4-Lite write address valid.
            pub s_axil_awvalid: Signal<In, Bit>,
            /// AXI4-Lite write address ready.
            pub s_axil_awready: Signal<Out, Bit>,
            /// AXI4-Lite write byte address (bits 1..0 ignored).
            pub s_axil_awaddr: Signal<In, Bits<ADDRESS_BITS>>,
            /// AXI4-Lite write data valid.
            pub s_axil_wvalid: Signal<In, Bit>,
            /// AXI4-Lite write data ready.
            pub s_axil_wready: Signal<Out, Bit>,
            /// AXI4-Lite write data.
            pub s_axil_wdata: Signal<In, Bits<DATA_BITS>>,
            /// AXI4-Lite write strobes, one per byte.
            pub s_axil_wstrb: Signal<In, Bits<4>>,
            /// AXI4-Lite write response valid.
            pub s_axil_bvalid: Signal<Out, Bit>,
            /// AXI4-Lite write response ready.
            pub s_axil_bready: Signal<In, Bit>,
            /// AXI4-Lite write response: 0 OKAY, 2 SLVERR.
            pub s_axil_bresp: Signal<Out, Bits<RESP_BITS>>,
            /// AXI4-Lite read address valid.
            pub s_axil_arvalid: Signal<In, Bit>,
            /// AXI4-Lite read address ready.
            pub s_axil_arready: Signal<Out, Bit>,
            /// AXI4-Lite read byte address (bits 1..0 ignored).
            pub s_axil_araddr: Signal<In, Bits<ADDRESS_BITS>>,
            /// AXI4-Lite read data valid.
            pub s_axil_rvalid: Signal<Out, Bit>,
            /// AXI4-Lite read data ready.
            pub s_axil_rready: Signal<In, Bit>,
            /// AXI4-Lite read data.
            pub s_axil_rdata: Signal<Out, Bits<DATA_BITS>>,
            /// AXI4-Lite read response: 0 OKAY, 2 SLVERR.
            pub s_axil_rresp: Signal<Out, Bits<RESP_BITS>>,
            /// AXI4-Stream z sample valid.
            pub m_axis_tvalid: Signal<Out, Bit>,
            /// AXI4-Stream consumer ready.
            pub m_axis_tready: Signal<In, Bit>,
            /// AXI4-Stream sample: {count\[15:0\], z2\[39:0\], z1\[39:0\]}.
            pub m_axis_tdata: Signal<Out, Bits<SAMPLE_BITS>>,
            /// AXI4-Stream end of packet: always 1 (one sample per packet).
            pub m_axis_tlast: Signal<Out, Bit>,
            core: $core,
            settings: [SettingRegister; 15],
            status: [StatusWord; 9],
            clip: [ClipCounter; 2],
            fifo: SampleFifo,
            aw_held: DFF<Bit>,
            aw_index: DFF<Bits<WORD_INDEX_BITS>>,
            w_held: DFF<Bit>,
            w_data: DFF<Bits<DATA_BITS>>,
            w_strb: DFF<Bits<4>>,
            b_valid: DFF<Bit>,
            b_resp: DFF<Bits<RESP_BITS>>,
            ar_held: DFF<Bit>,
            ar_index: DFF<Bits<WORD_INDEX_BITS>>,
            r_valid: DFF<Bit>,
            r_data: DFF<Bits<DATA_BITS>>,
            r_resp: DFF<Bits<RESP_BITS>>,
            mod_step_low: DFF<Bits<DATA_BITS>>,
            sample_count: DFF<Bits<DATA_BITS>>,
            overflow_count: DFF<Bits<DATA_BITS>>,
            snapshot_z1: DFF<Bits<Z_BITS>>,
            snapshot_z2: DFF<Bits<Z_BITS>>,
            id_word: Constant<Bits<DATA_BITS>>,
            version_word: Constant<Bits<DATA_BITS>>,
            slverr: Constant<Bits<RESP_BITS>>,
            byte_lane: Constant<Bits<DATA_BITS>>,
            reset: Signal<Local, Bit>,
            write: Signal<Local, Bit>,
            write_ok: Signal<Local, Bit>,
            read: Signal<Local, Bit>,
            read_ok: Signal<Local, Bit>,
            read_word: Signal<Local, Bits<DATA_BITS>>,
            lane0: Signal<Local, Bits<DATA_BITS>>,
            lane1: Signal<Local, Bits<DATA_BITS>>,
            lane2: Signal<Local, Bits<DATA_BITS>>,
            lane3: Signal<Local, Bits<DATA_BITS>>,
            count_now: Signal<Local, Bits<DATA_BITS>>,
            z1_bits: Signal<Local, Bits<Z_BITS>>,
            z2_bits: Signal<Local, Bits<Z_BITS>>,
        }

        impl $name {
            /// The bus top at power-up.
            pub fn new() -> Self {
                Self {
                    aclk: Default::default(),
                    aresetn: Default::default(),
                    adc1: Default::default(),
                    adc2: Default::default(),
                    dac1: Default::default(),
                    dac2: Default::default(),
                    s_axil_awvalid: Default::default(),
                    s_axil_awready: Default::default(),
                    s_axil_awaddr: Default::default(),
                    s_axil_wvalid: Default::default(),
                    s_axil_wready: Default::default(),
                    s_axil_wdata: Default::default(),
                    s_axil_wstrb: Default::default(),
                    s_axil_bvalid: Default::default(),
                    s_axil_bready: Default::default(),
                    s_axil_bresp: Default::default(),
                    s_axil_arvalid: Default::default(),
                    s_axil_arready: Default::default(),
                    s_axil_araddr: Default::default(),
                    s_axil_rvalid: Default::default(),
                    s_axil_rready: Default::default(),
                    s_axil_rdata: Default::default(),
                    s_axil_rresp: Default::default(),
                    m_axis_tvalid: Default::default(),
                    m_axis_tready: Default::default(),
                    m_axis_tdata: Default::default(),
                    m_axis_tlast: Default::default(),
                    core: $core::new(),
                    settings: std::array::from_fn(|i| SettingRegister::new(&SETTINGS[i])),
                    status: std::array::from_fn(|i| StatusWord::new(&STATUS[i])),
                    clip: Default::default(),
                    fifo: SampleFifo::new(),
                    aw_held: Default::default(),
                    aw_index: Default::default(),
                    w_held: Default::default(),
                    w_data: Default::default(),
                    w_strb: Default::default(),
                    b_valid: Default::default(),
                    b_resp: Default::default(),
                    ar_held: Default::default(),
                    ar_index: Default::default(),
                    r_valid: Default::default(),
                    r_data: Default::default(),
                    r_resp: Default::default(),
                    mod_step_low: Default::default(),
                    sample_count: Default::default(),
                    overflow_count: Default::default(),
                    snapshot_z1: Default::default(),
                    snapshot_z2: Default::default(),
                    id_word: Constant::new(u64::from(ID.power_up).into()),
                    version_word: Constant::new(u64::from(VERSION.power_up).into()),
                    slverr: Constant::new(u64::from(SLVERR).into()),
                    byte_lane: Constant::new(0xffu64.into()),
                    reset: Default::default(),
                    write: Default::default(),
                    write_ok: Default::default(),
                    read: Default::default(),
                    read_ok: Default::default(),
                    read_word: Default::default(),
                    lane0: Default::default(),
                    lane1: Default::default(),
                    lane2: Default::default(),
                    lane3: Default::default(),
                    count_now: Default::default(),
                    z1_bits: Default::default(),
                    z2_bits: Default::default(),
                }
            }
        }

        impl Default for $name {
            fn default() -> Self {
                Self::new()
            }
        }

        impl Logic for $name {
            #[hdl_gen]
            fn update(&mut self) {
                dff_setup!(
                    self,
                    aclk,
                    aw_held,
                    aw_index,
                    w_held,
                    w_data,
                    w_strb,
                    b_valid,
                    b_resp,
                    ar_held,
                    ar_index,
                    r_valid,
                    r_data,
                    r_resp,
                    mod_step_low,
                    sample_count,
                    overflow_count,
                    snapshot_z1,
                    snapshot_z2
                );
                self.core.clock.next = self.aclk.val();
                self.fifo.clock.next = self.aclk.val();
                self.reset.next = !self.aresetn.val();
                // Write channel: AW and W holding registers, then one write.
                self.s_axil_awready.next = !self.aw_held.q.val();
                self.s_axil_wready.next = !self.w_held.q.val();
                self.s_axil_bvalid.next = self.b_valid.q.val();
                self.s_axil_bresp.next = self.b_resp.q.val();
                if self.s_axil_awvalid.val() & (!self.aw_held.q.val()) {
                    self.aw_held.d.next = true;
                    self.aw_index.d.next = self.s_axil_awaddr.val().get_bits::<WORD_INDEX_BITS>(2);
                }
                if self.s_axil_wvalid.val() & (!self.w_held.q.val()) {
                    self.w_held.d.next = true;
                    self.w_data.d.next = self.s_axil_wdata.val();
                    self.w_strb.d.next = self.s_axil_wstrb.val();
                }
                self.write.next = self.aw_held.q.val() & self.w_held.q.val() & (!self.b_valid.q.val());
                self.lane0.next = 0.into();
                self.lane1.next = 0.into();
                self.lane2.next = 0.into();
                self.lane3.next = 0.into();
                if self.w_strb.q.val().get_bit(0) {
                    self.lane0.next = self.byte_lane.val();
                }
                if self.w_strb.q.val().get_bit(1) {
                    self.lane1.next = self.byte_lane.val() << 8;
                }
                if self.w_strb.q.val().get_bit(2) {
                    self.lane2.next = self.byte_lane.val() << 16;
                }
                if self.w_strb.q.val().get_bit(3) {
                    self.lane3.next = self.byte_lane.val() << 24;
                }
                self.write_ok.next = false;
                for i in 0..15 {
                    self.settings[i].clock.next = self.aclk.val();
                    self.settings[i].reset.next = self.reset.val();
                    self.settings[i].write.next = self.write.val();
                    self.settings[i].write_index.next = self.aw_index.q.val();
                    self.settings[i].write_data.next = self.w_data.q.val();
                    self.settings[i].write_mask.next =
                        self.lane0.val() | self.lane1.val() | self.lane2.val() | self.lane3.val();
                    self.settings[i].read_index.next = self.ar_index.q.val();
                    if self.settings[i].write_hit.val() {
                        self.write_ok.next = true;
                    }
                }
                if self.write.val() {
                    self.aw_held.d.next = false;
                    self.w_held.d.next = false;
                    self.b_valid.d.next = true;
                    self.b_resp.d.next = 0.into();
                    if !self.write_ok.val() {
                        self.b_resp.d.next = self.slverr.val();
                    }
                }
                if self.b_valid.q.val() & self.s_axil_bready.val() {
                    self.b_valid.d.next = false;
                }
                // mod_step: the staged low word moves to the port with the high word.
                if self.settings[5].write_hit.val() {
                    self.mod_step_low.d.next = self.settings[4].value.val();
                }
                // Status words.
                self.z1_bits.next = unsigned_cast(self.core.z1.val());
                self.z2_bits.next = unsigned_cast(self.core.z2.val());
                self.count_now.next = self.sample_count.q.val();
                if self.core.z_valid.val() {
                    self.count_now.next = self.sample_count.q.val() + 1;
                }
                self.sample_count.d.next = self.count_now.val();
                if self.fifo.dropped.val() {
                    self.overflow_count.d.next = self.overflow_count.q.val() + 1;
                }
                self.status[0].live.next = self.id_word.val();
                self.status[1].live.next = self.version_word.val();
                self.status[2].live.next = self.overflow_count.q.val();
                self.status[3].live.next = self.count_now.val();
                self.status[4].live.next = self.snapshot_z1.q.val().get_bits::<DATA_BITS>(0);
                self.status[5].live.next =
                    bit_cast::<DATA_BITS, 8>(self.snapshot_z1.q.val().get_bits::<8>(32));
                self.status[6].live.next = self.snapshot_z2.q.val().get_bits::<DATA_BITS>(0);
                self.status[7].live.next =
                    bit_cast::<DATA_BITS, 8>(self.snapshot_z2.q.val().get_bits::<8>(32));
                // Over-range counts of ADC1 (bits 15..0) and ADC2 (31..16), 16 = COUNT_BITS.
                self.status[8].live.next = bit_cast::<DATA_BITS, COUNT_BITS>(self.clip[0].count.val())
                    | (bit_cast::<DATA_BITS, COUNT_BITS>(self.clip[1].count.val()) << 16);
                // Read channel: AR holding register, then one read.
                self.s_axil_arready.next = !self.ar_held.q.val();
                self.s_axil_rvalid.next = self.r_valid.q.val();
                self.s_axil_rdata.next = self.r_data.q.val();
                self.s_axil_rresp.next = self.r_resp.q.val();
                if self.s_axil_arvalid.val() & (!self.ar_held.q.val()) {
                    self.ar_held.d.next = true;
                    self.ar_index.d.next = self.s_axil_araddr.val().get_bits::<WORD_INDEX_BITS>(2);
                }
                self.read.next = self.ar_held.q.val() & (!self.r_valid.q.val());
                self.read_ok.next = false;
                self.read_word.next = 0.into();
                for i in 0..15 {
                    if self.settings[i].read_hit.val() {
                        self.read_ok.next = true;
                        self.read_word.next = self.settings[i].read_word.val();
                    }
                }
                for i in 0..9 {
                    self.status[i].read_index.next = self.ar_index.q.val();
                    if self.status[i].read_hit.val() {
                        self.read_ok.next = true;
                        self.read_word.next = self.status[i].read_word.val();
                    }
                }
                if self.read.val() {
                    self.ar_held.d.next = false;
                    self.r_valid.d.next = true;
                    self.r_data.d.next = self.read_word.val();
                    self.r_resp.d.next = 0.into();
                    if !self.read_ok.val() {
                        self.r_resp.d.next = self.slverr.val();
                    }
                    if self.status[3].read_hit.val() {
                        self.snapshot_z1.d.next = self.z1_bits.val();
                        self.snapshot_z2.d.next = self.z2_bits.val();
                    }
                }
                if self.r_valid.q.val() & self.s_axil_rready.val() {
                    self.r_valid.d.next = false;
                }
                // The over-range counters restart on a read of ADC_CLIP.
                self.clip[0].adc.next = self.adc1.val();
                self.clip[1].adc.next = self.adc2.val();
                for i in 0..2 {
                    self.clip[i].clock.next = self.aclk.val();
                    self.clip[i].reset.next = self.reset.val();
                    self.clip[i].clear.next = self.read.val() & self.status[8].read_hit.val();
                }
                // Stream.
                self.fifo.reset.next = self.reset.val();
                self.fifo.push.next = self.core.z_valid.val() & self.settings[14].value.val().get_bit(0);
                // Shifts by Z_BITS = 40 and 2 Z_BITS = 80 (literals: #[hdl_gen] takes no const).
                self.fifo.push_data.next = bit_cast::<SAMPLE_BITS, Z_BITS>(self.z1_bits.val())
                    | (bit_cast::<SAMPLE_BITS, Z_BITS>(self.z2_bits.val()) << 40)
                    | (bit_cast::<SAMPLE_BITS, 16>(self.count_now.val().get_bits::<16>(0)) << 80);
                self.fifo.tready.next = self.m_axis_tready.val();
                self.m_axis_tvalid.next = self.fifo.tvalid.val();
                self.m_axis_tdata.next = self.fifo.tdata.val();
                self.m_axis_tlast.next = true;
                // The datapath's settings ports.
                self.core.select.next = self.settings[0].value.val().get_bit(0);
                self.core.carrier_step.next = self.settings[1].value.val();
                self.core.ref_phase.next = self.settings[2].value.val();
                self.core.ref_delay.next = self.settings[3].value.val().get_bits::<6>(0);
                self.core.mod_step.next = bit_cast::<48, DATA_BITS>(self.mod_step_low.q.val())
                    | (bit_cast::<48, 16>(self.settings[5].value.val().get_bits::<16>(0)) << 32);
                self.core.amp1.next = signed_cast(self.settings[6].value.val().get_bits::<16>(0));
                self.core.amp2.next = signed_cast(self.settings[7].value.val().get_bits::<16>(0));
                self.core.cic_decimation.next = self.settings[8].value.val().get_bits::<13>(0);
                self.core.cic_shift.next = self.settings[9].value.val().get_bits::<6>(0);
                self.core.iir_k0.next = signed_cast(self.settings[10].value.val());
                self.core.iir_k1.next = signed_cast(self.settings[11].value.val());
                self.core.iir_k2.next = signed_cast(self.settings[12].value.val());
                self.core.iir_alpha.next = signed_cast(self.settings[13].value.val());
                self.core.adc1.next = self.adc1.val();
                self.core.adc2.next = self.adc2.val();
                self.dac1.next = self.core.dac1.val();
                self.dac2.next = self.core.dac2.val();
                // Reset of the wrapper's own registers (not of the core).
                if self.reset.val() {
                    self.aw_held.d.next = false;
                    self.aw_index.d.next = 0.into();
                    self.w_held.d.next = false;
                    self.w_data.d.next = 0.into();
                    self.w_strb.d.next = 0.into();
                    self.b_valid.d.next = false;
                    self.b_resp.d.next = 0.into();
                    self.ar_held.d.next = false;
                    self.ar_index.d.next = 0.into();
                    self.r_valid.d.next = false;
                    self.r_data.d.next = 0.into();
                    self.r_resp.d.next = 0.into();
                    self.mod_step_low.d.next = 0.into();
                    self.sample_count.d.next = 0.into();
                    self.overflow_count.d.next = 0.into();
                    self.snapshot_z1.d.next = 0.into();
                    self.snapshot_z2.d.next = 0.into();
                }
            }
        }

        impl crate::drive::Clocked for $name {
            fn clock_input(&mut self) -> &mut Signal<In, Clock> {
                &mut self.aclk
            }
        }
    };
}

axi_top!(
    /// The datapath with an AXI4-Lite register slave and an AXI4-Stream z
    /// master: the table core, which fits an iCE40 UltraPlus.
    GyroInterfaceAxi,
    GyroInterface
);

axi_top!(
    /// `GyroInterfaceAxi` around the fine-carrier core
    /// (`crate::gyro_interface::FineGyroInterface`): the ECP5 top. Same
    /// ports, registers and timing.
    FineGyroInterfaceAxi,
    FineGyroInterface
);
