//! A memory-mapped board: the core's AXI4-Lite slave in the processor's
//! address space, as on Zynq-class Linux boards (the Red Pitaya class,
//! with 125 MS/s converters, is the common lab board for this work).
//!
//! - `/dev/uioN` (a UIO device for the core: the kernel maps it, no root
//!   needed with the right udev rule): map N of the device is at file
//!   offset N x page size; the core is usually map 0, at offset 0.
//! - `/dev/mem` (root): the core at its physical base address.
//!
//! Each register access is one volatile 32-bit load or store: the bus
//! sees exactly the reads and writes host code makes, in order (a read of
//! SAMPLE_COUNT latches z). A window of the map's 256 bytes is mapped,
//! from any base (the mapping library aligns it to a page).

use gyrocal_regs::map::{ADDRESS_BITS, BusError, RegisterAccess};
use memmap2::{MmapOptions, MmapRaw};
use std::fs::OpenOptions;
use std::path::Path;

/// Bytes of the register window.
pub const WINDOW_BYTES: usize = 1 << ADDRESS_BITS;

/// A board whose registers are a mapped window of a device file.
pub struct Mapped {
    map: MmapRaw,
}

impl Mapped {
    /// Map the core's registers at byte `base` of `path` (read and write).
    pub fn open(path: &Path, base: u64) -> Result<Self, BusError> {
        let fail = |what: &str, e: std::io::Error| {
            BusError::Transport(format!("{}: {what}: {e}", path.display()))
        };
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| fail("cannot open read-write", e))?;
        let map = MmapOptions::new()
            .offset(base)
            .len(WINDOW_BYTES)
            .map_raw(&file)
            .map_err(|e| fail(&format!("cannot map {WINDOW_BYTES} bytes at 0x{base:x}"), e))?;
        Ok(Self { map })
    }

    /// The word pointer of a byte offset (bits 1..0 ignored, as the bus
    /// ignores them; offsets wrap in the window as the slave's decoding does).
    fn word(&self, offset: u32) -> *mut u32 {
        let at = (offset as usize % WINDOW_BYTES) & !3;
        // In bounds: at + 4 <= WINDOW_BYTES, the mapped length; aligned:
        // the mapping starts on a 4-byte boundary of the device.
        self.map.as_mut_ptr().wrapping_add(at).cast::<u32>()
    }
}

impl RegisterAccess for Mapped {
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        // SAFETY: `word` points inside the live mapping (see `word`), which
        // this struct owns; device registers need volatile, unreordered access.
        unsafe { self.word(offset).write_volatile(word) };
        Ok(())
    }

    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        // SAFETY: as in `write_register`.
        Ok(unsafe { self.word(offset).read_volatile() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plain file stands for the device: what is written through the
    /// map is in the file at base + offset, and reads see the file.
    #[test]
    fn registers_are_words_of_the_mapped_file_at_the_base() {
        let dir = std::env::temp_dir().join(format!("gyrocal-mmap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("device");
        let base = 3 * 4096 + 0x100;
        let mut bytes = vec![0u8; base as usize + WINDOW_BYTES];
        bytes[base as usize..base as usize + 4].copy_from_slice(&0x4759_524fu32.to_ne_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let mut m = Mapped::open(&path, base).unwrap();
        assert_eq!(m.read_register(0).unwrap(), 0x4759_524f);
        m.write_register(0x24, 0xdead_beef).unwrap();
        assert_eq!(m.read_register(0x27).unwrap(), 0xdead_beef);
        drop(m);
        let back = std::fs::read(&path).unwrap();
        let at = base as usize + 0x24;
        assert_eq!(back[at..at + 4], 0xdead_beefu32.to_ne_bytes());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_missing_device_is_one_line() {
        let e = Mapped::open(Path::new("/nonexistent/uio9"), 0)
            .err()
            .unwrap();
        let text = e.to_string();
        assert!(text.starts_with("/nonexistent/uio9: cannot open"), "{text}");
        assert!(!text.contains('\n'));
    }
}
