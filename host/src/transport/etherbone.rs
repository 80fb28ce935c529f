//! Etherbone over TCP, the wire of LiteX's `litex_server`: its
//! `RemoteClient` and a board behind `litex_server --uart`, `--udp` or
//! `--pcie` speak exactly this. Also the codec the simulator's
//! `gyrocal serve` answers with.
//!
//! # Frames (as LiteX's `litex/tools/remote/etherbone.py` packs them)
//!
//! ```text
//! packet header, 8 bytes:  4e 6f | version 1 << 4 | nr pr pf | addr_size 4 << 4 | port_size 4 | 00 00 00 00
//! record header, 4 bytes:  flags | byte_enable 0x0f | wcount | rcount
//! writes (wcount > 0):     base address (BE u32), wcount words (BE u32) to base, base + 4, ...
//! reads  (rcount > 0):     return address (BE u32), rcount addresses (BE u32)
//! ```
//!
//! One record per packet. A read is answered with a record of `wcount` =
//! the number of reads whose words are the values read, in order; a write
//! is not answered. On connecting, the server sends one line of
//! information (`litex_server` sends `CommUDP:ip:port` and the like), which
//! the client reads and ignores. Etherbone carries no bus error: a read
//! of an unmapped word or a write to a read-only one comes back as a plain
//! word (LiteX's bus returns 0 or ignores it).

use gyrocal_regs::map::{BusError, RegisterAccess};
use std::io::{Read, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

/// The Etherbone magic, bytes 0..1 of every packet.
pub const MAGIC: u16 = 0x4e6f;
/// Bytes of the packet header.
pub const PACKET_HEADER_BYTES: usize = 8;
/// Bytes of a record header.
pub const RECORD_HEADER_BYTES: usize = 4;
/// Most reads or writes in one record (an 8-bit count).
pub const MAX_BURST: usize = 255;
/// How long the client waits for an answer before it reports the board
/// silent.
pub const TIMEOUT: Duration = Duration::from_secs(10);

/// One record: writes of consecutive words from `write_base`, then reads
/// of `reads` (any addresses).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Record {
    /// Address of the first written word.
    pub write_base: u32,
    /// Words written to `write_base`, `write_base + 4`, ...
    pub writes: Vec<u32>,
    /// Return address of the reads (echoed in the answer's write base).
    pub read_return: u32,
    /// Addresses read, in order.
    pub reads: Vec<u32>,
}

/// A malformed frame: what was wrong.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    /// Not an Etherbone packet.
    #[error("bad Etherbone magic 0x{0:04x} (expected 0x4e6f)")]
    Magic(u16),
    /// Only 32-bit addresses and data are spoken here.
    #[error("Etherbone address/port size byte 0x{0:02x}: only 32-bit (0x44) is supported")]
    Size(u8),
    /// More than 255 words in a record.
    #[error("an Etherbone record holds at most 255 reads or writes, not {0}")]
    Burst(usize),
    /// The frame ended early.
    #[error("Etherbone frame cut short: {0} bytes")]
    Short(usize),
}

fn be(bytes: &[u8], at: usize) -> u32 {
    u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

impl Record {
    /// The frame of one packet holding this record.
    pub fn encode(&self) -> Result<Vec<u8>, FrameError> {
        for n in [self.writes.len(), self.reads.len()] {
            if n > MAX_BURST {
                return Err(FrameError::Burst(n));
            }
        }
        let mut f = vec![0x4e, 0x6f, 0x10, 0x44, 0, 0, 0, 0];
        f.extend([0, 0x0f, self.writes.len() as u8, self.reads.len() as u8]);
        if !self.writes.is_empty() {
            f.extend(self.write_base.to_be_bytes());
            self.writes.iter().for_each(|w| f.extend(w.to_be_bytes()));
        }
        if !self.reads.is_empty() {
            f.extend(self.read_return.to_be_bytes());
            self.reads.iter().for_each(|a| f.extend(a.to_be_bytes()));
        }
        Ok(f)
    }

    /// Bytes of the whole frame, from its first 12 bytes (packet and
    /// record headers), as `litex_server` sizes what it reads.
    pub fn frame_bytes(head: &[u8; PACKET_HEADER_BYTES + RECORD_HEADER_BYTES]) -> usize {
        let (w, r) = (usize::from(head[10]), usize::from(head[11]));
        let mut n = PACKET_HEADER_BYTES + RECORD_HEADER_BYTES;
        if w > 0 {
            n += 4 * (w + 1);
        }
        if r > 0 {
            n += 4 * (r + 1);
        }
        n
    }

    /// The record of a whole frame.
    pub fn decode(frame: &[u8]) -> Result<Self, FrameError> {
        let head = PACKET_HEADER_BYTES + RECORD_HEADER_BYTES;
        if frame.len() < head {
            return Err(FrameError::Short(frame.len()));
        }
        let magic = u16::from_be_bytes([frame[0], frame[1]]);
        if magic != MAGIC {
            return Err(FrameError::Magic(magic));
        }
        if frame[3] != 0x44 {
            return Err(FrameError::Size(frame[3]));
        }
        let mut h = [0; 12];
        h.copy_from_slice(&frame[..head]);
        if frame.len() < Self::frame_bytes(&h) {
            return Err(FrameError::Short(frame.len()));
        }
        let (w, r) = (usize::from(frame[10]), usize::from(frame[11]));
        let mut at = head;
        let mut rec = Record::default();
        if w > 0 {
            rec.write_base = be(frame, at);
            rec.writes = (0..w).map(|i| be(frame, at + 4 + 4 * i)).collect();
            at += 4 * (w + 1);
        }
        if r > 0 {
            rec.read_return = be(frame, at);
            rec.reads = (0..r).map(|i| be(frame, at + 4 + 4 * i)).collect();
        }
        Ok(rec)
    }
}

/// Read one whole frame from a stream; `Ok(None)` at a clean end.
pub fn read_frame(stream: &mut impl Read) -> std::io::Result<Option<Vec<u8>>> {
    let mut head = [0u8; PACKET_HEADER_BYTES + RECORD_HEADER_BYTES];
    match stream.read_exact(&mut head) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(None),
        Err(e) => return Err(e),
    }
    let mut frame = head.to_vec();
    frame.resize(Record::frame_bytes(&head), 0);
    stream.read_exact(&mut frame[head.len()..])?;
    Ok(Some(frame))
}

/// A board over Etherbone/TCP: register offsets of the map at `base` on
/// the remote bus.
pub struct Etherbone {
    stream: TcpStream,
    base: u32,
}

fn transport(what: &str, e: impl std::fmt::Display) -> BusError {
    BusError::Transport(format!("etherbone: {what}: {e}"))
}

impl Etherbone {
    /// Connect to `host:port` (a `litex_server` or `gyrocal serve`) and
    /// read its greeting; the core's registers sit at `base`.
    pub fn connect(address: &str, base: u32) -> Result<Self, BusError> {
        let addr = address
            .to_socket_addrs()
            .map_err(|e| transport(&format!("cannot resolve {address}"), e))?
            .next()
            .ok_or_else(|| transport(address, "no address"))?;
        let mut stream = TcpStream::connect_timeout(&addr, TIMEOUT)
            .map_err(|e| transport(&format!("cannot connect to {address}"), e))?;
        stream
            .set_nodelay(true)
            .map_err(|e| transport("nodelay", e))?;
        stream
            .set_read_timeout(Some(TIMEOUT))
            .map_err(|e| transport("timeout", e))?;
        // The server's one-line greeting (RemoteClient reads up to 128 bytes).
        let mut greeting = [0u8; 128];
        let n = stream
            .read(&mut greeting)
            .map_err(|e| transport(&format!("no greeting from {address}"), e))?;
        if n == 0 {
            return Err(transport(address, "the server closed the connection"));
        }
        Ok(Self { stream, base })
    }

    fn send(&mut self, rec: &Record) -> Result<(), BusError> {
        let frame = rec.encode().map_err(|e| transport("encode", e))?;
        self.stream
            .write_all(&frame)
            .map_err(|e| transport("send", e))
    }
}

impl RegisterAccess for Etherbone {
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        self.send(&Record {
            write_base: self.base.wrapping_add(offset),
            writes: vec![word],
            ..Record::default()
        })
    }

    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        Ok(self.read_registers(&[offset])?[0])
    }

    /// One packet for up to 255 reads: one round trip.
    fn read_registers(&mut self, offsets: &[u32]) -> Result<Vec<u32>, BusError> {
        let mut out = Vec::with_capacity(offsets.len());
        for chunk in offsets.chunks(MAX_BURST) {
            self.send(&Record {
                reads: chunk.iter().map(|o| self.base.wrapping_add(*o)).collect(),
                ..Record::default()
            })?;
            let frame = read_frame(&mut self.stream)
                .map_err(|e| transport("no answer", e))?
                .ok_or_else(|| transport("answer", "the server closed the connection"))?;
            let answer = Record::decode(&frame).map_err(|e| transport("answer", e))?;
            if answer.writes.len() != chunk.len() {
                return Err(transport(
                    "answer",
                    format!("{} words for {} reads", answer.writes.len(), chunk.len()),
                ));
            }
            out.extend(answer.writes);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bytes LiteX's Python packs for a one-word write of 0x12345678
    /// to 0x40 and a two-word read of 0x48 and 0x4c (worked out from
    /// `etherbone.py`: big-endian fields, magic 4e 6f, version 1 in the
    /// high nibble of byte 2, 32-bit sizes 0x44).
    #[test]
    fn frames_are_litex_frames() {
        let w = Record {
            write_base: 0x40,
            writes: vec![0x1234_5678],
            ..Record::default()
        };
        assert_eq!(
            w.encode().unwrap(),
            [
                0x4e, 0x6f, 0x10, 0x44, 0, 0, 0, 0, 0, 0x0f, 1, 0, 0, 0, 0, 0x40, 0x12, 0x34, 0x56,
                0x78
            ]
        );
        let r = Record {
            reads: vec![0x48, 0x4c],
            ..Record::default()
        };
        let f = r.encode().unwrap();
        assert_eq!(&f[8..12], &[0, 0x0f, 0, 2]);
        assert_eq!(&f[12..], &[0, 0, 0, 0, 0, 0, 0, 0x48, 0, 0, 0, 0x4c]);
        let mut head = [0u8; 12];
        head.copy_from_slice(&f[..12]);
        assert_eq!(Record::frame_bytes(&head), f.len());
        assert_eq!(Record::decode(&f).unwrap(), r);
        assert_eq!(Record::decode(&w.encode().unwrap()).unwrap(), w);
    }

    #[test]
    fn bad_frames_are_refused() {
        let mut f = Record {
            reads: vec![4],
            ..Record::default()
        }
        .encode()
        .unwrap();
        assert_eq!(Record::decode(&f[..15]), Err(FrameError::Short(15)));
        f[3] = 0x88;
        assert_eq!(Record::decode(&f), Err(FrameError::Size(0x88)));
        f[0] = 0;
        assert!(matches!(Record::decode(&f), Err(FrameError::Magic(_))));
        let big = Record {
            reads: vec![0; 256],
            ..Record::default()
        };
        assert_eq!(big.encode(), Err(FrameError::Burst(256)));
    }
}
