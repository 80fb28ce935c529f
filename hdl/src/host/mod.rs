//! The host interface: `gyro_interface_axi`, the datapath behind an
//! AXI4-Lite register slave and an AXI4-Stream z-sample master.
//!
//! - [`register_map`]: the one source of the register map (decoding,
//!   `REGISTERS.md`, the C header, `Registers` <-> bus words);
//! - `gyrocal_regs::systemrdl`: the same map as SystemRDL (`gyro_interface.rdl`);
//! - [`axi_top`]: the rust-hdl top `GyroInterfaceAxi`, which wires
//!   [`axil_write`] and [`axil_read`] (the bus channels) to
//!   [`register_file`] (the map: [`setting_register`], [`status_word`],
//!   [`status_counters`] with [`clip_counter`]) and [`sample_fifo`] (the
//!   stream);
//! - [`model`]: its bit-true, cycle-true model; [`rtl`]: the rust-hdl
//!   design driven directly with the same interface.

pub mod axi_top;
pub mod axil_read;
pub mod axil_write;
pub mod clip_counter;
pub mod model;
pub mod register_file;
/// The register map, from the leaf crate `gyrocal-regs`.
pub use gyrocal_regs::map as register_map;
pub mod rtl;
pub mod sample_fifo;
pub mod setting_register;
pub mod status_counters;
pub mod status_word;
pub mod traffic;

/// Width of z1 and z2 (40-bit two's complement, 8 fractional bits).
pub const Z_BITS: usize = gyrocal_regs::datapath::Z_BITS as usize;
/// The low `Z_BITS` bits: a z as its two's complement bits.
pub const Z_MASK: u64 = (1 << Z_BITS) - 1;
/// Width of an AXI response code.
pub const RESP_BITS: usize = 2;
/// AXI response OKAY.
pub const OKAY: u8 = 0;
/// AXI response SLVERR.
pub const SLVERR: u8 = 2;
