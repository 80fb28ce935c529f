//! A simulated board on the wire: the device a `gyrocal run` or `gyrocal
//! field` file describes, free-running behind Etherbone over TCP as LiteX's
//! `litex_server` puts a real board, so that any Etherbone client (LiteX's
//! `RemoteClient`, `gyrocal calibrate --board etherbone://...`) reaches it
//! through the register map alone and measures time by SAMPLE_COUNT.
//!
//! - [`device`]: the file's device (at a `[drift]` temperature) on a
//!   powered-up [`crate::field::board::SimBoard`] of any engine, and what
//!   a host knows about it.
//! - [`server`]: the Etherbone server: one thread steps the board in
//!   chunks of clocks and serves the connections' bus requests between
//!   chunks.

pub mod device;
pub mod server;
