//! `GyroInterfaceAxi`: the bus-attached top, exported as `gyro_interface_axi`.
//!
//! ```text
//!            ┌──────────────────────────────── gyro_interface_axi ─────────────────────────────────┐
//!  s_axil_aw*├► AxilWrite ── write, index, data, mask ─►┌──────────────┐                            │
//!  s_axil_w* │   (AW, W, B) ◄──────────── write_hit ────┤ RegisterFile ├─ settings ─► GyroInterface ├─► dac1, dac2
//!  s_axil_b* ◄┤                                          │  settings,   │              (the core)   ◄┤ adc1, adc2
//!  s_axil_ar*├► AxilRead ─── read, index ──────────────►│  status,     │◄─ z1, z2, z_valid ──┘     │
//!  s_axil_r* ◄┤   (AR, R) ◄─ read_word, read_hit ───────┤  counters    │◄─ adc1, adc2              │
//!            │                                           └──────┬───────┘                           │
//!  m_axis_*  ◄┤ SampleFifo (256 x 96 bit) ◄── beat {count[15:0], z2, z1} when STREAM_ENABLE         │
//!            └───────────────────────────────────────────────────────────────────────────────────────┘
//! ```
//!
//! Read in this order: `axil_write.rs` and `axil_read.rs` (the bus
//! handshakes), `register_file.rs` (the map, with `setting_register.rs`,
//! `status_word.rs`, `status_counters.rs` and `clip_counter.rs`),
//! `sample_fifo.rs` (the stream). This file only wires them.
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

use super::RESP_BITS;
use super::axil_read::AxilRead;
use super::axil_write::AxilWrite;
use super::register_file::RegisterFile;
pub use super::register_file::{SETTINGS, STATUS};
use super::register_map::{ADDRESS_BITS, DATA_BITS};
use super::sample_fifo::{SAMPLE_BITS, SampleFifo};
use crate::gyro_interface::{FineGyroInterface, GyroInterface};
use gyrocal_regs::datapath::CarrierProfile;
use rust_hdl::prelude::*;

/// Declares a bus-attached top around the given datapath core: the struct,
/// its constructor and its wiring, written once for both cores.
macro_rules! axi_top {
    ($(#[$meta:meta])* $name:ident, $core:ident, $profile:expr) => {
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
            axil_write: AxilWrite,
            axil_read: AxilRead,
            registers: RegisterFile,
            fifo: SampleFifo,
            reset: Signal<Local, Bit>,
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
                    axil_write: AxilWrite::new(),
                    axil_read: AxilRead::new(),
                    registers: RegisterFile::new($profile),
                    fifo: SampleFifo::new(),
                    reset: Default::default(),
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
                self.reset.next = !self.aresetn.val();
                self.core.clock.next = self.aclk.val();
                self.axil_write.clock.next = self.aclk.val();
                self.axil_read.clock.next = self.aclk.val();
                self.registers.clock.next = self.aclk.val();
                self.fifo.clock.next = self.aclk.val();
                self.axil_write.reset.next = self.reset.val();
                self.axil_read.reset.next = self.reset.val();
                self.registers.reset.next = self.reset.val();
                self.fifo.reset.next = self.reset.val();
                // Write channels, then the register file's write.
                self.axil_write.s_axil_awvalid.next = self.s_axil_awvalid.val();
                self.axil_write.s_axil_awaddr.next = self.s_axil_awaddr.val();
                self.axil_write.s_axil_wvalid.next = self.s_axil_wvalid.val();
                self.axil_write.s_axil_wdata.next = self.s_axil_wdata.val();
                self.axil_write.s_axil_wstrb.next = self.s_axil_wstrb.val();
                self.axil_write.s_axil_bready.next = self.s_axil_bready.val();
                self.s_axil_awready.next = self.axil_write.s_axil_awready.val();
                self.s_axil_wready.next = self.axil_write.s_axil_wready.val();
                self.s_axil_bvalid.next = self.axil_write.s_axil_bvalid.val();
                self.s_axil_bresp.next = self.axil_write.s_axil_bresp.val();
                self.registers.write.next = self.axil_write.write.val();
                self.registers.write_index.next = self.axil_write.index.val();
                self.registers.write_data.next = self.axil_write.data.val();
                self.registers.write_mask.next = self.axil_write.mask.val();
                self.axil_write.accepted.next = self.registers.write_hit.val();
                // Read channels, then the register file's read.
                self.axil_read.s_axil_arvalid.next = self.s_axil_arvalid.val();
                self.axil_read.s_axil_araddr.next = self.s_axil_araddr.val();
                self.axil_read.s_axil_rready.next = self.s_axil_rready.val();
                self.s_axil_arready.next = self.axil_read.s_axil_arready.val();
                self.s_axil_rvalid.next = self.axil_read.s_axil_rvalid.val();
                self.s_axil_rdata.next = self.axil_read.s_axil_rdata.val();
                self.s_axil_rresp.next = self.axil_read.s_axil_rresp.val();
                self.registers.read.next = self.axil_read.read.val();
                self.registers.read_index.next = self.axil_read.index.val();
                self.axil_read.word.next = self.registers.read_word.val();
                self.axil_read.accepted.next = self.registers.read_hit.val();
                // Status sources: z for the counters and snapshot, the ADC words
                // for the clip counters, the FIFO's drops.
                self.registers.z1.next = self.core.z1.val();
                self.registers.z2.next = self.core.z2.val();
                self.registers.z_valid.next = self.core.z_valid.val();
                self.registers.dropped.next = self.fifo.dropped.val();
                self.registers.adc1.next = self.adc1.val();
                self.registers.adc2.next = self.adc2.val();
                // Stream.
                self.fifo.push.next = self.core.z_valid.val() & self.registers.stream_enable.val();
                self.fifo.push_data.next = self.registers.beat.val();
                self.fifo.tready.next = self.m_axis_tready.val();
                self.m_axis_tvalid.next = self.fifo.tvalid.val();
                self.m_axis_tdata.next = self.fifo.tdata.val();
                self.m_axis_tlast.next = true;
                // The datapath: the settings on its ports, the converters on its pins.
                self.core.select.next = self.registers.select.val();
                self.core.carrier_step.next = self.registers.carrier_step.val();
                self.core.ref_phase.next = self.registers.ref_phase.val();
                self.core.ref_delay.next = self.registers.ref_delay.val();
                self.core.mod_step.next = self.registers.mod_step.val();
                self.core.amp1.next = self.registers.amp1.val();
                self.core.amp2.next = self.registers.amp2.val();
                self.core.cic_decimation.next = self.registers.cic_decimation.val();
                self.core.cic_shift.next = self.registers.cic_shift.val();
                self.core.iir_k0.next = self.registers.iir_k0.val();
                self.core.iir_k1.next = self.registers.iir_k1.val();
                self.core.iir_k2.next = self.registers.iir_k2.val();
                self.core.iir_alpha.next = self.registers.iir_alpha.val();
                self.core.adc1.next = self.adc1.val();
                self.core.adc2.next = self.adc2.val();
                self.dac1.next = self.core.dac1.val();
                self.dac2.next = self.core.dac2.val();
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
    GyroInterface,
    CarrierProfile::Table
);

axi_top!(
    /// `GyroInterfaceAxi` around the fine-carrier core
    /// (`crate::gyro_interface::FineGyroInterface`): the ECP5 top. Same
    /// ports, registers and timing.
    FineGyroInterfaceAxi,
    FineGyroInterface,
    CarrierProfile::Fine
);
