//! The register map of `gyro_interface_axi`: the one source of truth.
//!
//! Every 32-bit word the AXI4-Lite slave decodes is one entry of
//! [`REGISTERS`]: name, byte offset, field width, signedness, access,
//! power-up value and documentation. From this table come
//!
//! - the slave's decoding (`gyrocal_hdl::host::axi_top` builds one decoder block per
//!   entry from it: offset, width mask, sign extension, power-up value),
//! - `verilog-out/REGISTERS.md` ([`markdown`]) and the C header
//!   `verilog-out/gyro_interface_regs.h` ([`c_header`]),
//! - the conversion between the datapath's [`Registers`] and bus words
//!   ([`encode`], [`RegisterBank::registers`]), which the co-simulation uses
//!   to program its engines, the bit-true bus model (`gyrocal_hdl::host::model`)
//!   and the host code (`gyrocal-host`), which reaches a board through
//!   [`RegisterAccess`].
//!
//! Bus words: a field occupies bits `bits-1..0` of its word. A write keeps
//! the low `bits` bits (`WSTRB` selects bytes); a read returns the field
//! zero-extended, or sign-extended when it is signed. Byte addresses are
//! [`ADDRESS_BITS`] wide; bits 1..0 are ignored (word access).
//!
//! ```
//! use gyrocal_regs::map::{self as register_map, RegisterBank};
//! use gyrocal_regs::Registers;
//! let mut regs = Registers::default();
//! regs.mod_step = 0x1234_5678_9abc;
//! regs.amp = (-5, 7);
//! let mut bank = RegisterBank::power_up();
//! for (offset, word) in register_map::encode(&regs) {
//!     bank.write(offset, word, 0xf).unwrap();
//! }
//! assert_eq!(bank.registers(), regs.at_ports());
//! assert_eq!(bank.read(register_map::AMP1.offset), Ok(-5i32 as u32));
//! ```

use crate::datapath::{CarrierProfile, DELAY_BITS, DRIVE_START_CLOCKS, FIFO_DEPTH, Z_BITS};
use crate::registers::{Coefficients, Registers};

/// Width of the AXI4-Lite byte address (a 256-byte window).
pub const ADDRESS_BITS: usize = 8;
/// Width of the word index: the byte address without its two low bits.
pub const WORD_INDEX_BITS: usize = ADDRESS_BITS - 2;
/// Width of a bus word.
pub const DATA_BITS: usize = 32;
/// The identification word: ASCII "GYRO".
pub const ID_WORD: u32 = 0x4759_524f;
/// Register map version: major in bits 31..16, minor in 15..0. Minor 2
/// added PROFILE; a host reads it only from a core whose minor says so.
pub const VERSION_WORD: u32 = 0x0001_0002;
/// The first minor version with the PROFILE register.
pub const PROFILE_SINCE_MINOR: u32 = 2;

/// Who may write a register.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    /// Read and write: a setting held by the slave.
    ReadWrite,
    /// Read only: status from the datapath; a write answers SLVERR.
    ReadOnly,
}

/// One 32-bit word of the map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Register {
    /// Name (upper case; the C header prefixes it with `GYRO_`).
    pub name: &'static str,
    /// Byte offset, a multiple of 4 below 2^ADDRESS_BITS.
    pub offset: u32,
    /// Field width: bits `bits-1..0` of the word.
    pub bits: u32,
    /// Two's complement field (read back sign-extended).
    pub signed: bool,
    /// Read-write setting or read-only status.
    pub access: Access,
    /// Value after power-up and after `aresetn` (the field, as read).
    pub power_up: u32,
    /// A read returns the field and clears it (a read side effect).
    pub read_clears: bool,
    /// The core port or status it maps to, and its meaning.
    pub doc: &'static str,
}

impl Register {
    /// The bits the field occupies.
    pub const fn mask(&self) -> u32 {
        if self.bits >= 32 {
            u32::MAX
        } else {
            (1 << self.bits) - 1
        }
    }

    /// Bit `bits - 1` when the field is signed (0 otherwise).
    pub const fn sign_bit(&self) -> u32 {
        if self.signed && self.bits < 32 {
            1 << (self.bits - 1)
        } else {
            0
        }
    }

    /// The word a read returns for a field value: zero- or sign-extended.
    pub const fn extend(&self, field: u32) -> u32 {
        let field = field & self.mask();
        if field & self.sign_bit() != 0 {
            field | !self.mask()
        } else {
            field
        }
    }

    /// Index of the word (offset / 4).
    pub const fn word_index(&self) -> u32 {
        self.offset / 4
    }
}

const fn setting(
    name: &'static str,
    offset: u32,
    bits: u32,
    signed: bool,
    power_up: u32,
    doc: &'static str,
) -> Register {
    Register {
        name,
        offset,
        bits,
        signed,
        access: Access::ReadWrite,
        power_up,
        read_clears: false,
        doc,
    }
}

const fn status(
    name: &'static str,
    offset: u32,
    bits: u32,
    signed: bool,
    doc: &'static str,
) -> Register {
    Register {
        name,
        offset,
        bits,
        signed,
        access: Access::ReadOnly,
        power_up: 0,
        read_clears: false,
        doc,
    }
}

/// Identification, "GYRO".
pub const ID: Register = Register {
    power_up: ID_WORD,
    ..status(
        "ID",
        0x00,
        32,
        false,
        "Identification: 0x4759524f, ASCII \"GYRO\".",
    )
};
/// Register map version.
pub const VERSION: Register = Register {
    power_up: VERSION_WORD,
    ..status(
        "VERSION",
        0x04,
        32,
        false,
        "Register map version: major in bits 31..16, minor in 15..0.",
    )
};
/// SELECT.
pub const SELECT: Register = setting(
    "SELECT",
    0x08,
    1,
    false,
    0,
    "Port `select`: 0 readout, 1 calibration.",
);
/// Carrier phase step.
pub const CARRIER_STEP: Register = setting(
    "CARRIER_STEP",
    0x0c,
    32,
    false,
    0,
    "Port `carrier_step`: f_carrier = CARRIER_STEP * f_clk / 2^32.",
);
/// Reference phase advance.
pub const REF_PHASE: Register = setting(
    "REF_PHASE",
    0x10,
    32,
    false,
    0,
    "Port `ref_phase`: reference phase advance, 2^32 = 360 deg (carrier_step / 2 cancels the DAC hold).",
);
/// Reference delay.
pub const REF_DELAY: Register = setting(
    "REF_DELAY",
    0x14,
    DELAY_BITS,
    false,
    0,
    "Port `ref_delay`: references delayed by REF_DELAY + 1 clocks; set to L_dac + L_adc.",
);
/// Modulation step, low word (staged).
pub const MOD_STEP_LO: Register = setting(
    "MOD_STEP_LO",
    0x18,
    32,
    false,
    0,
    "Bits 31..0 of port `mod_step`. Staged: reaches the port when MOD_STEP_HI is written.",
);
/// Modulation step, high word (applies the pair).
pub const MOD_STEP_HI: Register = setting(
    "MOD_STEP_HI",
    0x1c,
    Registers::MOD_STEP_BITS - 32,
    false,
    0,
    "Bits 47..32 of port `mod_step`; writing it applies both words at once. f_cal = mod_step * f_clk / 2^48.",
);
/// Drive amplitude F1.
pub const AMP1: Register = setting(
    "AMP1",
    0x20,
    16,
    true,
    0,
    "Port `amp1`: drive amplitude F1, Q1.15 (32767 full scale). 0 at power-up: the drives are off.",
);
/// Drive amplitude F2.
pub const AMP2: Register = setting(
    "AMP2",
    0x24,
    16,
    true,
    0,
    "Port `amp2`: drive amplitude F2, Q1.15.",
);
/// CIC decimation R.
pub const CIC_DECIMATION: Register = setting(
    "CIC_DECIMATION",
    0x28,
    Registers::CIC_DECIMATION_BITS,
    false,
    256,
    "Port `cic_decimation`: R, 166..4096; z is updated every R clocks.",
);
/// CIC output shift.
pub const CIC_SHIFT: Register = setting(
    "CIC_SHIFT",
    0x2c,
    Registers::CIC_SHIFT_BITS,
    false,
    24,
    "Port `cic_shift`: ceil(4 log2 R) - 8 (24 for the power-up R = 256).",
);
/// IIR numerator gain.
pub const IIR_K0: Register = setting(
    "IIR_K0",
    0x30,
    32,
    true,
    0,
    "Port `iir_k0`: biquad numerator gain, Q2.30.",
);
/// IIR feedback 1.
pub const IIR_K1: Register = setting(
    "IIR_K1",
    0x34,
    32,
    true,
    0,
    "Port `iir_k1`: biquad feedback -a1 - 2, Q2.30.",
);
/// IIR feedback 2.
pub const IIR_K2: Register = setting(
    "IIR_K2",
    0x38,
    32,
    true,
    0,
    "Port `iir_k2`: biquad feedback 1 - a2, Q2.30.",
);
/// RC coefficient.
pub const IIR_ALPHA: Register = setting(
    "IIR_ALPHA",
    0x3c,
    32,
    true,
    0,
    "Port `iir_alpha`: RC section 1 - exp(-2 pi f_rc R / f_clk), Q2.30.",
);
/// Stream enable.
pub const STREAM_ENABLE: Register = setting(
    "STREAM_ENABLE",
    0x40,
    1,
    false,
    0,
    "1: every z sample is offered on the AXI4-Stream master (through the FIFO); 0: none.",
);
/// Samples the stream dropped.
pub const STREAM_OVERFLOW: Register = status(
    "STREAM_OVERFLOW",
    0x44,
    32,
    false,
    "Samples dropped because the stream FIFO was full (wraps at 2^32).",
);
/// Sample counter; reading it latches the snapshot.
pub const SAMPLE_COUNT: Register = status(
    "SAMPLE_COUNT",
    0x48,
    32,
    false,
    "z samples since power-up or reset (wraps). Reading it latches Z1_LO..Z2_HI: the sample it counts.",
);
/// Snapshot z1, low word.
pub const Z1_LO: Register = status(
    "Z1_LO",
    0x4c,
    32,
    false,
    "Bits 31..0 of z1 latched by the last SAMPLE_COUNT read.",
);
/// Snapshot z1, high bits.
pub const Z1_HI: Register = status(
    "Z1_HI",
    0x50,
    Z_BITS - 32,
    true,
    "Bits 39..32 of the latched z1, sign-extended (z has 8 fractional bits).",
);
/// Snapshot z2, low word.
pub const Z2_LO: Register = status(
    "Z2_LO",
    0x54,
    32,
    false,
    "Bits 31..0 of z2 latched by the last SAMPLE_COUNT read.",
);
/// Snapshot z2, high bits.
pub const Z2_HI: Register = status(
    "Z2_HI",
    0x58,
    Z_BITS - 32,
    true,
    "Bits 39..32 of the latched z2, sign-extended.",
);

/// ADC over-range counts; reading clears them.
pub const ADC_CLIP: Register = Register {
    read_clears: true,
    ..status(
        "ADC_CLIP",
        0x5c,
        32,
        false,
        "Clocks on which ADC1 (bits 15..0) and ADC2 (bits 31..16) read a word within 1/128 of full scale (top byte 0x7f or 0x80: +32512..+32767 or -32768..-32513, which holds both rail codes of any left-justified converter of 8 to 16 bits) since the last read of this word; each count saturates at 65535. A read returns the counts and restarts them (a rail code on the clock of the read counts toward the next read). Any count means a measurement over that time was not linear.",
    )
};

/// The core's carrier profile, fixed when the core is built.
pub const PROFILE: Register = status(
    "PROFILE",
    0x60,
    1,
    false,
    "The core's carrier profile, fixed at build: 0 table (`gyro_interface.v`, an iCE40 UltraPlus), 1 fine (`ecp5/gyro_interface.v`). The host's predictions depend on it; a host reads it before it calibrates.",
);

/// Every register, in offset order.
pub const REGISTERS: [Register; 25] = [
    ID,
    VERSION,
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
    STREAM_OVERFLOW,
    SAMPLE_COUNT,
    Z1_LO,
    Z1_HI,
    Z2_LO,
    Z2_HI,
    ADC_CLIP,
    PROFILE,
];

/// The register at a byte offset (bits 1..0 ignored), if any.
pub fn lookup(offset: u32) -> Option<&'static Register> {
    let index = (offset % (1 << ADDRESS_BITS)) / 4;
    REGISTERS.iter().find(|r| r.word_index() == index)
}

/// The bus writes that program `regs` into the slave, in an order that
/// applies them (MOD_STEP_LO before MOD_STEP_HI): (byte offset, word).
/// Words are the fields cut to their width, as the slave keeps them.
pub fn encode(regs: &Registers) -> Vec<(u32, u32)> {
    let r = regs;
    let fields: [(&Register, u32); 14] = [
        (&SELECT, r.select as u32),
        (&CARRIER_STEP, r.carrier_step),
        (&REF_PHASE, r.ref_phase),
        (&REF_DELAY, r.ref_delay as u32),
        (&MOD_STEP_LO, r.mod_step as u32),
        (&MOD_STEP_HI, (r.mod_step >> 32) as u32),
        (&AMP1, r.amp.0 as u16 as u32),
        (&AMP2, r.amp.1 as u16 as u32),
        (&CIC_DECIMATION, r.cic_decimation as u32),
        (&CIC_SHIFT, r.cic_shift as u32),
        (&IIR_K0, r.iir.k0 as u32),
        (&IIR_K1, r.iir.k1 as u32),
        (&IIR_K2, r.iir.k2 as u32),
        (&IIR_ALPHA, r.iir.alpha as u32),
    ];
    fields
        .iter()
        .map(|(reg, v)| (reg.offset, v & reg.mask()))
        .collect()
}

/// Why a register access failed: the slave answered SLVERR, or the
/// transport to the board did.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BusError {
    /// No register at this offset (SLVERR).
    #[error("no register at this offset (SLVERR)")]
    Unmapped,
    /// A write to a read-only register (SLVERR).
    #[error("write to a read-only register (SLVERR)")]
    ReadOnly,
    /// The transport failed (a socket, a device file): what and why.
    #[error("{0}")]
    Transport(String),
}

/// The settings as the slave holds them: one field per read-write register,
/// plus the applied `mod_step` (MOD_STEP_LO is staged until MOD_STEP_HI is
/// written). This is the bus model's and the co-simulation's register file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegisterBank {
    fields: [u32; REGISTERS.len()],
    mod_step_applied_low: u32,
}

impl RegisterBank {
    /// Every setting at its power-up value, in the table core (PROFILE 0).
    pub fn power_up() -> Self {
        Self::power_up_for(CarrierProfile::Table)
    }

    /// Every setting at its power-up value, in the core with this carrier
    /// profile (PROFILE reads its word).
    pub fn power_up_for(profile: CarrierProfile) -> Self {
        let mut bank = Self::power_up_fields();
        bank.fields[Self::slot(PROFILE.offset).expect("PROFILE is mapped")] = profile.word();
        bank
    }

    fn power_up_fields() -> Self {
        let mut fields = [0; REGISTERS.len()];
        for (f, r) in fields.iter_mut().zip(&REGISTERS) {
            *f = r.power_up & r.mask();
        }
        Self {
            fields,
            mod_step_applied_low: MOD_STEP_LO.power_up,
        }
    }

    fn slot(offset: u32) -> Option<usize> {
        let index = (offset % (1 << ADDRESS_BITS)) / 4;
        REGISTERS.iter().position(|r| r.word_index() == index)
    }

    /// The field of a read-write register (its power-up value if `reg` is
    /// read-only: status lives in the datapath, not here).
    pub fn field(&self, reg: &Register) -> u32 {
        Self::slot(reg.offset).map_or(0, |i| self.fields[i])
    }

    /// A bus write: bytes of `word` selected by `strobe` (bit i = byte i)
    /// replace those of the field, which keeps its low `bits` bits.
    pub fn write(&mut self, offset: u32, word: u32, strobe: u8) -> Result<(), BusError> {
        let i = Self::slot(offset).ok_or(BusError::Unmapped)?;
        let reg = &REGISTERS[i];
        if reg.access == Access::ReadOnly {
            return Err(BusError::ReadOnly);
        }
        let bytes = byte_mask(strobe);
        self.fields[i] = ((self.fields[i] & !bytes) | (word & bytes)) & reg.mask();
        if reg.offset == MOD_STEP_HI.offset {
            self.mod_step_applied_low = self.field(&MOD_STEP_LO);
        }
        Ok(())
    }

    /// A bus read of a read-write register (status words come from the
    /// datapath: `gyrocal_hdl::host::model` answers those).
    pub fn read(&self, offset: u32) -> Result<u32, BusError> {
        let i = Self::slot(offset).ok_or(BusError::Unmapped)?;
        Ok(REGISTERS[i].extend(self.fields[i]))
    }

    /// The datapath's settings: what the core's ports see.
    pub fn registers(&self) -> Registers {
        let f = |r: &Register| self.field(r);
        let signed16 = |r: &Register| f(r) as u16 as i16;
        Registers {
            select: f(&SELECT) != 0,
            carrier_step: f(&CARRIER_STEP),
            ref_phase: f(&REF_PHASE),
            ref_delay: f(&REF_DELAY) as u8,
            mod_step: (u64::from(f(&MOD_STEP_HI)) << 32) | u64::from(self.mod_step_applied_low),
            amp: (signed16(&AMP1), signed16(&AMP2)),
            cic_decimation: f(&CIC_DECIMATION) as u16,
            cic_shift: f(&CIC_SHIFT) as u8,
            iir: Coefficients {
                k0: f(&IIR_K0) as i32,
                k1: f(&IIR_K1) as i32,
                k2: f(&IIR_K2) as i32,
                alpha: f(&IIR_ALPHA) as i32,
            },
        }
    }

    /// STREAM_ENABLE.
    pub fn stream_enabled(&self) -> bool {
        self.field(&STREAM_ENABLE) != 0
    }
}

/// Register access as host software sees it: whole 32-bit words at byte
/// offsets of this map. The co-simulation implements it on its engines
/// (`gyrocal_sim::cosim::CoSim`); a board's driver over a real AXI4-Lite
/// bus could implement it the same way.
pub trait RegisterAccess {
    /// Write a word; `Err` where the slave answers SLVERR.
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError>;
    /// Read a word; `Err` where the slave answers SLVERR.
    fn read_register(&mut self, offset: u32) -> Result<u32, BusError>;
    /// Read several words, in this order (a transport with a round trip
    /// per request sends them as one: the bus still sees them in order).
    fn read_registers(&mut self, offsets: &[u32]) -> Result<Vec<u32>, BusError> {
        offsets.iter().map(|&o| self.read_register(o)).collect()
    }
}

/// Program every setting of `regs` through `bus` ([`encode`]'s writes).
pub fn program(bus: &mut impl RegisterAccess, regs: &Registers) -> Result<(), BusError> {
    encode(regs)
        .into_iter()
        .try_for_each(|(offset, word)| bus.write_register(offset, word))
}

/// The 32-bit mask of the bytes a 4-bit `WSTRB` selects.
pub fn byte_mask(strobe: u8) -> u32 {
    (0..4)
        .filter(|b| strobe >> b & 1 == 1)
        .fold(0, |m, b| m | (0xff << (8 * b)))
}

/// `verilog-out/REGISTERS.md`.
pub fn markdown() -> String {
    let mut md = String::from(
        "# gyro_interface_axi registers\n\n\
         Generated by `gyrocal export` from `regs/src/map.rs`, the same source\n\
         as the AXI4-Lite slave's decoding and `gyro_interface_regs.h`; do not edit.\n\n\
         32-bit words at byte offsets from the slave's base address (8-bit address,\n\
         bits 1..0 ignored). A field occupies bits `bits-1..0`; a write keeps those\n\
         bits (WSTRB selects bytes), a read returns the field zero-extended, or\n\
         sign-extended when signed. An unmapped offset, or a write to a read-only\n\
         register, answers SLVERR (resp = 2) and changes nothing.\n\n\
         | offset | name | access | bits | power-up | description |\n\
         |---|---|---|---|---|---|\n",
    );
    for r in &REGISTERS {
        let access = match (r.access, r.read_clears) {
            (Access::ReadWrite, _) => "RW",
            (Access::ReadOnly, false) => "RO",
            (Access::ReadOnly, true) => "RO, read clears",
        };
        let signed = if r.signed { " signed" } else { "" };
        let power_up = match r.access {
            Access::ReadWrite => format!("{}", r.extend(r.power_up) as i32),
            Access::ReadOnly if r.power_up != 0 => format!("0x{:08x}", r.power_up),
            Access::ReadOnly => "-".into(),
        };
        md.push_str(&format!(
            "| 0x{:02x} | `{}` | {access} | {}{signed} | {power_up} | {} |\n",
            r.offset, r.name, r.bits, r.doc
        ));
    }
    md.push_str(&coherence_notes());
    md
}

/// The access rules after the register table (the FIFO depth from
/// `crate::datapath`).
fn coherence_notes() -> String {
    COHERENCE_NOTES
        .replace("{fifo_depth}", &FIFO_DEPTH.to_string())
        .replace("{drive_start}", &DRIVE_START_CLOCKS.to_string())
}

const COHERENCE_NOTES: &str = r#"
## Coherent access

- **z snapshot.** Reading `SAMPLE_COUNT` latches z1, z2 and that count together at the
  same clock edge: then read `Z1_LO`, `Z1_HI`, `Z2_LO`, `Z2_HI` in any order; they hold
  the sample `SAMPLE_COUNT` returned until the next `SAMPLE_COUNT` read. A read never
  mixes two samples. z = (HI << 32 | LO) / 256 in mixer LSBs.
- **mod_step.** Write `MOD_STEP_LO`, then `MOD_STEP_HI`: the 48-bit step reaches the
  datapath at once when `MOD_STEP_HI` is written, never half-updated.
- **Stream.** With `STREAM_ENABLE` = 1 every z sample enters a FIFO of {fifo_depth} samples
  (`GYRO_STREAM_FIFO_DEPTH`, block RAM) feeding the AXI4-Stream master (`tdata` 96 bits:
  z1 in 39..0, z2 in 79..40, SAMPLE_COUNT's low 16 bits in 95..80; `tlast` = 1, one
  sample per packet), offered 3 clocks after it is computed. A sample arriving while the
  FIFO is full is dropped and counted in `STREAM_OVERFLOW`.
- **Reset.** `aresetn` low (synchronous) returns every register above to its power-up
  value and empties the FIFO; the datapath core itself has no reset.
- **Over range.** `ADC_CLIP` counts the clocks on which each ADC read a word within 1/128
  of full scale (the rail codes of any converter of 8 to 16 bits, left-justified); reading
  it restarts both counts. Read it before and after a measurement: a non-zero second read
  means the converter clipped during it.
- **Power-up.** The core fills its carrier tables during its first clocks: the drives are
  0 until clock {drive_start} after configuration (`GYRO_DRIVE_START_CLOCKS`), and so are
  the references the demodulators use.
"#;

/// `verilog-out/gyro_interface_regs.h`: offsets, widths, power-up values.
pub fn c_header() -> String {
    let mut h = String::from(
        "/* gyro_interface_regs.h: register map of gyro_interface_axi (AXI4-Lite).\n \
         * Generated by `gyrocal export` from regs/src/map.rs, the same\n \
         * source as the hardware's decoding and REGISTERS.md; do not edit.\n \
         * Offsets are bytes from the slave's base address; access 32-bit words. */\n\
         #ifndef GYRO_INTERFACE_REGS_H\n#define GYRO_INTERFACE_REGS_H\n\n",
    );
    h.push_str(&format!("#define GYRO_ID_VALUE 0x{ID_WORD:08x}u\n"));
    h.push_str(&format!(
        "#define GYRO_VERSION_VALUE 0x{VERSION_WORD:08x}u\n"
    ));
    h.push_str(&format!(
        "/* PROFILE's values: the carrier profile the core was built with; a core\n \
         * reports it from this minor version of the map on. */\n\
         #define GYRO_PROFILE_TABLE {}u\n#define GYRO_PROFILE_FINE {}u\n\
         #define GYRO_PROFILE_SINCE_MINOR {PROFILE_SINCE_MINOR}u\n",
        CarrierProfile::Table.word(),
        CarrierProfile::Fine.word()
    ));
    h.push_str(&format!(
        "/* Samples the AXI4-Stream FIFO holds before it drops one. */\n\
         #define GYRO_STREAM_FIFO_DEPTH {FIFO_DEPTH}u\n"
    ));
    h.push_str(&format!(
        "/* Clocks after configuration before the drives leave 0: the core fills its\n \
         * carrier tables first. */\n\
         #define GYRO_DRIVE_START_CLOCKS {DRIVE_START_CLOCKS}u\n\n"
    ));
    for r in &REGISTERS {
        let access = match r.access {
            Access::ReadWrite => "read-write",
            Access::ReadOnly => "read-only",
        };
        h.push_str(&format!(
            "/* {}: {access}, {} bits{}. {} */\n",
            r.name,
            r.bits,
            if r.signed { " signed" } else { "" },
            r.doc.replace("*/", "* /")
        ));
        h.push_str(&format!(
            "#define GYRO_{}_OFFSET 0x{:02x}u\n",
            r.name, r.offset
        ));
        h.push_str(&format!("#define GYRO_{}_BITS {}u\n", r.name, r.bits));
        h.push_str(&format!(
            "#define GYRO_{}_MASK 0x{:08x}u\n",
            r.name,
            r.mask()
        ));
        if r.access == Access::ReadWrite {
            h.push_str(&format!(
                "#define GYRO_{}_POWER_UP 0x{:08x}u\n",
                r.name,
                r.extend(r.power_up)
            ));
        }
        h.push('\n');
    }
    h.push_str(
        "/* z from the snapshot: read SAMPLE_COUNT first (it latches the set), then\n \
         * z = ((int64_t)(int32_t)Z1_HI << 32) | Z1_LO, in 1/256 mixer LSB. */\n\
         #endif /* GYRO_INTERFACE_REGS_H */\n",
    );
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decimation's documented range is the limits of record, and the
    /// power-up R and shift are a valid pair with unit CIC gain.
    #[test]
    fn decimation_text_and_power_up_follow_the_limits() {
        use crate::datapath::{MAX_DECIMATION, MIN_DECIMATION};
        let range = format!("{MIN_DECIMATION}..{MAX_DECIMATION}");
        assert!(CIC_DECIMATION.doc.contains(&range));
        let r = CIC_DECIMATION.power_up;
        assert!((MIN_DECIMATION..=MAX_DECIMATION).contains(&r));
        let shift = (4.0 * f64::from(r).log2()).ceil() as u32 - 8;
        assert_eq!(CIC_SHIFT.power_up, shift);
        // A power of two: the CIC's residual gain R^4 / 2^ceil(4 log2 R)
        // (`filter_design`) is then exactly 1, and z at the power-up
        // settings needs no gain divided out (R = 255 would leave 0.98).
        assert!(r.is_power_of_two(), "power-up R = {r}");
        assert_eq!(u64::from(r).pow(4), 1 << (shift + 8));
    }

    #[test]
    fn offsets_are_distinct_aligned_sorted_and_inside_the_window() {
        for pair in REGISTERS.windows(2) {
            assert!(
                pair[0].offset < pair[1].offset,
                "{} / {}",
                pair[0].name,
                pair[1].name
            );
        }
        for r in &REGISTERS {
            assert_eq!(r.offset % 4, 0, "{}", r.name);
            assert!(r.offset < 1 << ADDRESS_BITS, "{}", r.name);
            assert!((1..=32).contains(&r.bits), "{}", r.name);
            assert_eq!(
                r.power_up & !r.mask(),
                0,
                "{} power-up wider than its field",
                r.name
            );
        }
    }

    #[test]
    fn encode_then_decode_gives_the_ports_values() {
        // xorshift64*: a fixed sequence of 64-bit words.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..1000 {
            let mut x = || {
                state ^= state >> 12;
                state ^= state << 25;
                state ^= state >> 27;
                state.wrapping_mul(0x2545_f491_4f6c_dd1d)
            };
            let regs = Registers {
                select: x() & 1 == 1,
                carrier_step: x() as u32,
                ref_phase: x() as u32,
                ref_delay: x() as u8,
                mod_step: x(),
                amp: (x() as i16, x() as i16),
                cic_decimation: x() as u16,
                cic_shift: x() as u8,
                iir: Coefficients {
                    k0: x() as i32,
                    k1: x() as i32,
                    k2: x() as i32,
                    alpha: x() as i32,
                },
            };
            let mut bank = RegisterBank::power_up();
            for (offset, word) in encode(&regs) {
                bank.write(offset, word, 0xf).unwrap();
            }
            assert_eq!(bank.registers(), regs.at_ports());
        }
    }

    #[test]
    fn mod_step_low_word_waits_for_the_high_word() {
        let mut bank = RegisterBank::power_up();
        bank.write(MOD_STEP_LO.offset, 0xdead_beef, 0xf).unwrap();
        assert_eq!(bank.registers().mod_step, 0);
        assert_eq!(bank.read(MOD_STEP_LO.offset), Ok(0xdead_beef));
        bank.write(MOD_STEP_HI.offset, 0x1_2345, 0xf).unwrap();
        assert_eq!(bank.registers().mod_step, 0x2345_dead_beef);
    }

    #[test]
    fn strobes_bytes_widths_and_errors() {
        let mut bank = RegisterBank::power_up();
        bank.write(AMP1.offset, 0x1234_8001, 0b0001).unwrap();
        assert_eq!(bank.read(AMP1.offset), Ok(0x01));
        bank.write(AMP1.offset, 0x1234_8001, 0b0010).unwrap();
        assert_eq!(bank.read(AMP1.offset), Ok(0xffff_8001), "sign-extended");
        assert_eq!(bank.write(0x80, 1, 0xf), Err(BusError::Unmapped));
        assert_eq!(bank.read(0xfc), Err(BusError::Unmapped));
        assert_eq!(bank.write(ID.offset, 1, 0xf), Err(BusError::ReadOnly));
        bank.write(REF_DELAY.offset, 0xff, 0xf).unwrap();
        assert_eq!(bank.read(REF_DELAY.offset), Ok(63));
        assert_eq!(byte_mask(0b1010), 0xff00_ff00);
    }

    #[test]
    fn header_and_table_name_every_register() {
        let (md, h) = (markdown(), c_header());
        for r in &REGISTERS {
            assert!(md.contains(&format!("`{}`", r.name)));
            assert!(h.contains(&format!(
                "#define GYRO_{}_OFFSET 0x{:02x}u",
                r.name, r.offset
            )));
        }
    }
}
