//! Bit-true, cycle-true model of `super::axi_top::GyroInterfaceAxi`: the
//! datapath model and the models that sit beside the bus top's blocks,
//! wired as the top wires the blocks: `WriteChannels` (`super::axil_write`),
//! `ReadChannels` (`super::axil_read`), the settings' `RegisterBank`
//! (`super::register_file`), `Counters` (`super::status_counters`) and
//! `Fifo` (`super::sample_fifo`). `step` plays one rising edge with the
//! inputs of the current cycle and returns the outputs after it, like every
//! model in `crate::model`.

use super::axil_read::ReadChannels;
use super::axil_write::WriteChannels;
use super::register_file::{STATUS, status_live};
use super::register_map::{self, ADC_CLIP, Access, BusError, RegisterBank, SAMPLE_COUNT};
use super::sample_fifo::Fifo;
use super::status_counters::{Counters, StatusInputs};
use super::{Z_BITS, Z_MASK};
use crate::model::gyro_interface::{CarrierProfile, GyroInterface, Outputs};

/// The input ports of `gyro_interface_axi` during one cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BusInputs {
    /// `aresetn` (active low).
    pub aresetn: bool,
    /// ADC words.
    pub adc: (i16, i16),
    /// `s_axil_awvalid`.
    pub awvalid: bool,
    /// `s_axil_awaddr` (8 bits).
    pub awaddr: u8,
    /// `s_axil_wvalid`.
    pub wvalid: bool,
    /// `s_axil_wdata`.
    pub wdata: u32,
    /// `s_axil_wstrb` (4 bits).
    pub wstrb: u8,
    /// `s_axil_bready`.
    pub bready: bool,
    /// `s_axil_arvalid`.
    pub arvalid: bool,
    /// `s_axil_araddr` (8 bits).
    pub araddr: u8,
    /// `s_axil_rready`.
    pub rready: bool,
    /// `m_axis_tready`.
    pub tready: bool,
}

impl Default for BusInputs {
    /// Out of reset, every valid low, every ready high, strobes all set.
    fn default() -> Self {
        Self {
            aresetn: true,
            adc: (0, 0),
            awvalid: false,
            awaddr: 0,
            wvalid: false,
            wdata: 0,
            wstrb: 0xf,
            bready: true,
            arvalid: false,
            araddr: 0,
            rready: true,
            tready: true,
        }
    }
}

/// The output ports of `gyro_interface_axi` during one cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BusOutputs {
    /// DAC words.
    pub dac: (i16, i16),
    /// `s_axil_awready`.
    pub awready: bool,
    /// `s_axil_wready`.
    pub wready: bool,
    /// `s_axil_bvalid`.
    pub bvalid: bool,
    /// `s_axil_bresp`.
    pub bresp: u8,
    /// `s_axil_arready`.
    pub arready: bool,
    /// `s_axil_rvalid`.
    pub rvalid: bool,
    /// `s_axil_rdata`.
    pub rdata: u32,
    /// `s_axil_rresp`.
    pub rresp: u8,
    /// `m_axis_tvalid`.
    pub tvalid: bool,
    /// `m_axis_tdata` (96 bits).
    pub tdata: u128,
    /// `m_axis_tlast`.
    pub tlast: bool,
}

/// The registers of the bus wrapper (everything `aresetn` resets), block
/// by block: the write and read channels (`super::axil_write`,
/// `super::axil_read`), and the register file's settings and counters
/// (`super::register_file`, `super::status_counters`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Wrapper {
    bank: RegisterBank,
    write: WriteChannels,
    read: ReadChannels,
    counters: Counters,
    /// The core's carrier profile (PROFILE reads its word).
    profile: CarrierProfile,
}

impl Wrapper {
    fn power_up(profile: CarrierProfile) -> Self {
        Self {
            profile,
            bank: RegisterBank::power_up(),
            write: WriteChannels::default(),
            read: ReadChannels::default(),
            counters: Counters::default(),
        }
    }

    /// What a read of word `index` returns during this cycle, the core
    /// publishing z when `z_valid`: a setting from the bank, a status word
    /// from its source (`register_file::status_live`) cut to its field.
    fn read_word(&self, index: u32, z_valid: bool) -> Result<u32, BusError> {
        let reg = register_map::lookup(index * 4).ok_or(BusError::Unmapped)?;
        if reg.access == Access::ReadWrite {
            return self.bank.read(reg.offset);
        }
        let live = status_live(&self.counters.words(z_valid), self.profile);
        let i = STATUS
            .iter()
            .position(|s| s.offset == reg.offset)
            .expect("every read-only word of the map is in STATUS");
        Ok(reg.extend(live[i]))
    }
}

/// Cycle-true model of the bus top.
#[derive(Clone, Debug)]
pub struct GyroInterfaceAxi {
    core: GyroInterface,
    bus: Wrapper,
    /// Apart from `bus`, which is copied every clock: the FIFO's step reads
    /// only its own state.
    fifo: Fifo,
}

impl Default for GyroInterfaceAxi {
    fn default() -> Self {
        Self::new()
    }
}

impl GyroInterfaceAxi {
    /// The bus top at power-up.
    pub fn new() -> Self {
        Self::with_profile(CarrierProfile::Table)
    }

    /// The bus top around the core with this carrier profile, at power-up.
    pub fn with_profile(profile: CarrierProfile) -> Self {
        Self {
            core: GyroInterface::with_profile(profile),
            bus: Wrapper::power_up(profile),
            fifo: Fifo::default(),
        }
    }

    /// The output ports during the current cycle.
    pub fn outputs(&self) -> BusOutputs {
        let (awready, wready) = self.bus.write.ready();
        let (bvalid, bresp) = self.bus.write.response();
        let (rvalid, rdata, rresp) = self.bus.read.response();
        BusOutputs {
            dac: self.core.outputs().dac,
            awready,
            wready,
            bvalid,
            bresp,
            arready: self.bus.read.ready(),
            rvalid,
            rdata,
            rresp,
            tvalid: self.fifo.output().0,
            tdata: self.fifo.output().1,
            tlast: true,
        }
    }

    /// The settings the datapath sees during the current cycle.
    pub fn bank(&self) -> &RegisterBank {
        &self.bus.bank
    }

    /// The datapath's own ports during the current cycle.
    pub fn core_outputs(&self) -> Outputs {
        self.core.outputs()
    }

    /// One rising edge with the inputs `i` of the current cycle.
    pub fn step(&mut self, i: &BusInputs) -> BusOutputs {
        let core = self.core.outputs();
        let regs = self.bus.bank.registers();
        let now = self.bus;
        let next = &mut self.bus;
        // The write channels, and the register file's write.
        let accepted = now
            .write
            .write()
            .is_some_and(|w| next.bank.write(w.index * 4, w.data, w.strb).is_ok());
        let aw = i.awvalid.then_some(i.awaddr);
        let w = i.wvalid.then_some((i.wdata, i.wstrb));
        next.write.step(aw, w, i.bready, accepted);
        // The read channels, and the register file's read.
        let read = now.read.read();
        let answer = read.and_then(|index| now.read_word(index, core.z_valid).ok());
        next.read
            .step(i.arvalid.then_some(i.araddr), i.rready, answer);
        // The counters, the snapshot and the stream.
        let push = (core.z_valid && now.bank.stream_enabled())
            .then(|| now.counters.beat(core.z, core.z_valid));
        let dropped = self.fifo.step(push, i.tready);
        let snapshot = read == Some(SAMPLE_COUNT.word_index());
        let clip_clear = read == Some(ADC_CLIP.word_index());
        let status = StatusInputs {
            z: core.z,
            z_valid: core.z_valid,
            dropped,
            snapshot,
            adc: i.adc,
            clip_clear,
        };
        next.counters.step(&status);
        if !i.aresetn {
            *next = Wrapper::power_up(next.profile);
            self.fifo = Fifo::default();
        }
        self.core.step(i.adc, &regs);
        self.outputs()
    }
}

/// z1, z2 and the 16-bit sequence number of a stream word.
pub fn unpack_sample(word: u128) -> (i64, i64, u16) {
    let z =
        |shift: usize| (((word >> shift) as u64 & Z_MASK) << (64 - Z_BITS)) as i64 >> (64 - Z_BITS);
    (z(0), z(Z_BITS), (word >> (2 * Z_BITS)) as u16)
}

#[cfg(test)]
mod tests {
    use super::super::register_map::{Z1_HI, Z1_LO, Z2_HI, Z2_LO};
    use super::*;

    /// A bus read of the word at `offset`: AR held until accepted, then
    /// the cycles to RVALID; the data and response.
    fn bus_read(top: &mut GyroInterfaceAxi, offset: u32) -> (u32, u8) {
        let ar = BusInputs {
            arvalid: true,
            araddr: offset as u8,
            ..BusInputs::default()
        };
        let (idle, mut accepted) = (BusInputs::default(), false);
        for _ in 0..8 {
            let before = top.outputs();
            if before.rvalid {
                top.step(&idle);
                return (before.rdata, before.rresp);
            }
            top.step(if accepted { &idle } else { &ar });
            accepted |= before.arready;
        }
        panic!("no read response in 8 cycles");
    }

    /// PROFILE reads the core's carrier profile, in either top, also after
    /// a reset: the word a host checks before it calibrates.
    #[test]
    fn profile_reads_the_cores_carrier_profile() {
        use super::super::register_map::PROFILE;
        for profile in CarrierProfile::ALL {
            let mut top = GyroInterfaceAxi::with_profile(profile);
            assert_eq!(bus_read(&mut top, PROFILE.offset), (profile.word(), 0));
            top.step(&BusInputs {
                aresetn: false,
                ..BusInputs::default()
            });
            assert_eq!(bus_read(&mut top, PROFILE.offset), (profile.word(), 0));
        }
    }

    /// Z1_HI:Z1_LO and Z2_HI:Z2_LO give back any 40-bit snapshot, sign
    /// included: the register map's contract for a host that reads z. The
    /// bus tests' traffic keeps |z| far below 2^31, where the high word is
    /// only the sign, so the high word's slice is checked here at the
    /// rails and across bit 31.
    #[test]
    fn the_z_words_give_back_any_snapshot() {
        let mut w = Wrapper::power_up(CarrierProfile::Table);
        let rails = [
            0i64,
            1,
            -1,
            0x7fff_ffff,
            0x8000_0000,
            -0x8000_0001,
            0x12_3456_789a,
            -0x12_3456_789a,
            (1 << (Z_BITS - 1)) - 1,
            -(1 << (Z_BITS - 1)),
        ];
        for z in rails {
            let mut counters = Counters::default();
            counters.step(&StatusInputs {
                z: (z, !z),
                snapshot: true,
                ..StatusInputs::default()
            });
            w.counters = counters;
            let word = |reg: &register_map::Register| w.read_word(reg.word_index(), false).unwrap();
            let join = |hi: u32, lo: u32| (i64::from(hi as i32) << 32) | i64::from(lo);
            assert_eq!(join(word(&Z1_HI), word(&Z1_LO)), z, "z1 = {z:#x}");
            assert_eq!(join(word(&Z2_HI), word(&Z2_LO)), !z, "z2 = {:#x}", !z);
        }
    }
}
