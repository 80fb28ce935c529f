//! Transports to real boards, behind one URL:
//!
//! | URL | board |
//! |---|---|
//! | `etherbone://HOST:PORT[?base=0xADDR]` | LiteX `litex_server` (UART, Ethernet, PCIe) or `gyrocal serve`, Etherbone over TCP |
//! | `uio:///dev/uioN[?base=0xOFFSET]` | a UIO device (Zynq-class Linux boards) |
//! | `mem:///dev/mem?base=0xADDR` | `/dev/mem` at a physical base address (root) |
//!
//! `base` is where the core's register map starts on that bus (default 0);
//! the map's byte offsets (`REGISTERS.md`) are added to it. Every board
//! from [`open`] measures time by SAMPLE_COUNT ([`crate::board::Polled`]).

pub mod etherbone;
pub mod mmap;

use crate::board::{Board, Polled};
use gyrocal_regs::datapath::CarrierProfile;
use gyrocal_regs::map::{
    BusError, ID, ID_WORD, PROFILE, PROFILE_SINCE_MINOR, RegisterAccess, VERSION, VERSION_WORD,
};
use std::path::Path;

/// A board URL that cannot be used: what is wrong and what is allowed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum UrlError {
    /// Not one of the supported forms.
    #[error(
        "board URL {0:?}: allowed etherbone://HOST:PORT[?base=0xADDR], uio:///dev/uioN[?base=0xOFFSET], mem:///dev/mem?base=0xADDR"
    )]
    Form(String),
    /// A `base` that is not a number.
    #[error("board URL {url:?}: base = {base:?} is not a number (decimal or 0x hex)")]
    Base {
        /// The URL.
        url: String,
        /// The text after `base=`.
        base: String,
    },
}

/// Where a URL points.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// Etherbone over TCP to `host:port`.
    Etherbone {
        /// `host:port`.
        address: String,
        /// The core's base address on the remote bus.
        base: u32,
    },
    /// A mapped device file.
    Mapped {
        /// The device file.
        path: String,
        /// Byte offset of the core in it.
        base: u64,
    },
}

fn number(text: &str) -> Option<u64> {
    match text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        Some(hex) => u64::from_str_radix(&hex.replace('_', ""), 16).ok(),
        None => text.replace('_', "").parse().ok(),
    }
}

/// Parse a board URL.
///
/// ```
/// use gyrocal_host::transport::{parse, Target};
/// assert_eq!(
///     parse("etherbone://192.168.1.50:1234?base=0x40000000").unwrap(),
///     Target::Etherbone { address: "192.168.1.50:1234".into(), base: 0x4000_0000 }
/// );
/// assert!(parse("http://x").is_err());
/// ```
pub fn parse(url: &str) -> Result<Target, UrlError> {
    let form = || UrlError::Form(url.into());
    let (scheme, rest) = url.split_once("://").ok_or_else(form)?;
    let (location, query) = rest.split_once('?').unwrap_or((rest, ""));
    let base = match query {
        "" => 0,
        q => {
            let text = q.strip_prefix("base=").ok_or_else(form)?;
            number(text).ok_or_else(|| UrlError::Base {
                url: url.into(),
                base: text.into(),
            })?
        }
    };
    match scheme {
        "etherbone" => {
            let (host, port) = location.rsplit_once(':').ok_or_else(form)?;
            if host.is_empty() || port.parse::<u16>().is_err() {
                return Err(form());
            }
            let base = u32::try_from(base).map_err(|_| UrlError::Base {
                url: url.into(),
                base: format!("0x{base:x} (above 32 bits)"),
            })?;
            Ok(Target::Etherbone {
                address: location.into(),
                base,
            })
        }
        "uio" | "mem" if location.starts_with('/') => {
            if scheme == "mem" && query.is_empty() {
                return Err(form());
            }
            Ok(Target::Mapped {
                path: location.into(),
                base,
            })
        }
        _ => Err(form()),
    }
}

/// The ID register must read "GYRO": anything else is not this core (a
/// wrong base, a wrong board), and every figure from it would be wrong.
pub fn check_id(bus: &mut impl RegisterAccess) -> Result<(), BusError> {
    let id = bus.read_register(ID.offset)?;
    if id == ID_WORD {
        Ok(())
    } else {
        Err(BusError::Transport(format!(
            "ID register reads 0x{id:08x}, not 0x{ID_WORD:08x} (\"GYRO\"): wrong base address or not a gyrocal core"
        )))
    }
}

/// The register map's minor version the core reports, once its major is
/// this host's: a core of another major version lays its registers out
/// otherwise, and every figure from it would be wrong.
pub fn check_version(bus: &mut (impl RegisterAccess + ?Sized)) -> Result<u32, BusError> {
    let version = bus.read_register(VERSION.offset)?;
    let (major, minor) = (version >> 16, version & 0xffff);
    if major == VERSION_WORD >> 16 {
        Ok(minor)
    } else {
        Err(BusError::Transport(format!(
            "VERSION reads {major}.{minor} (0x{version:08x}): this host speaks register map {}.x",
            VERSION_WORD >> 16
        )))
    }
}

/// The carrier profile the core was built with, from PROFILE; `None` from
/// a core of a map older than PROFILE (minor below
/// [`PROFILE_SINCE_MINOR`]), which cannot say.
///
/// ```
/// use gyrocal_host::transport::core_profile;
/// use gyrocal_regs::datapath::CarrierProfile;
/// use gyrocal_regs::map::{BusError, PROFILE, RegisterAccess, RegisterBank, VERSION};
///
/// /// A bank answering VERSION with `version`.
/// struct Core(RegisterBank, u32);
/// impl RegisterAccess for Core {
///     fn write_register(&mut self, o: u32, w: u32) -> Result<(), BusError> {
///         self.0.write(o, w, 0xf)
///     }
///     fn read_register(&mut self, o: u32) -> Result<u32, BusError> {
///         if o == VERSION.offset { Ok(self.1) } else { self.0.read(o) }
///     }
/// }
/// let fine = RegisterBank::power_up_for(CarrierProfile::Fine);
/// assert_eq!(core_profile(&mut Core(fine, 0x0001_0002))?, Some(CarrierProfile::Fine));
/// assert_eq!(core_profile(&mut Core(fine, 0x0001_0001))?, None);
/// let newer = core_profile(&mut Core(fine, 0x0002_0000)).unwrap_err();
/// assert!(newer.to_string().contains("this host speaks register map 1.x"));
/// # Ok::<(), BusError>(())
/// ```
pub fn core_profile(
    bus: &mut (impl RegisterAccess + ?Sized),
) -> Result<Option<CarrierProfile>, BusError> {
    if check_version(bus)? < PROFILE_SINCE_MINOR {
        return Ok(None);
    }
    let word = bus.read_register(PROFILE.offset)?;
    CarrierProfile::from_word(word).map(Some).ok_or_else(|| {
        BusError::Transport(format!(
            "PROFILE reads {word}: allowed {} (table) or {} (fine)",
            CarrierProfile::Table.word(),
            CarrierProfile::Fine.word()
        ))
    })
}

/// Open the board a URL names, check its ID and version, and give it a clock from
/// SAMPLE_COUNT.
///
/// ```
/// use gyrocal_host::transport::{self, etherbone::{Record, read_frame}};
/// use gyrocal_regs::map::RegisterAccess;
/// use std::io::Write;
///
/// // A stand-in for litex_server with the core at 0x4000_0000: its
/// // greeting, then each read record answered (ID at the base, VERSION
/// // after it, 0 elsewhere).
/// let listener = std::net::TcpListener::bind("127.0.0.1:0")?;
/// let url = format!("etherbone://{}?base=0x40000000", listener.local_addr()?);
/// std::thread::spawn(move || -> std::io::Result<()> {
///     let (mut s, _) = listener.accept()?;
///     s.write_all(b"CommTest:127.0.0.1:0")?;
///     while let Some(frame) = read_frame(&mut s)? {
///         let reads = Record::decode(&frame).unwrap().reads;
///         if reads.is_empty() {
///             continue; // a write: not answered
///         }
///         let word = |a| match a {
///             0x4000_0000 => 0x4759_524f,
///             0x4000_0004 => 0x0001_0002,
///             _ => 0,
///         };
///         let writes = reads.iter().map(|&a| word(a));
///         let answer = Record { writes: writes.collect(), ..Record::default() };
///         s.write_all(&answer.encode().unwrap())?;
///     }
///     Ok(())
/// });
/// let mut board = transport::open(&url)?; // connects, checks ID and VERSION, clocks by SAMPLE_COUNT
/// assert_eq!(board.read_register(0)?, 0x4759_524f);
///
/// // Nothing listens on port 1 here, and an unknown scheme names the allowed ones.
/// let refused = transport::open("etherbone://127.0.0.1:1").err().unwrap();
/// assert!(refused.to_string().contains("cannot connect to 127.0.0.1:1"));
/// let wrong = transport::open("http://board").err().unwrap();
/// assert!(wrong.to_string().contains("allowed etherbone://HOST:PORT"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn open(url: &str) -> Result<Box<dyn Board + Send>, crate::Error> {
    let target = parse(url).map_err(|e| BusError::Transport(e.to_string()))?;
    match target {
        Target::Etherbone { address, base } => {
            checked(etherbone::Etherbone::connect(&address, base)?)
        }
        Target::Mapped { path, base } => checked(mmap::Mapped::open(Path::new(&path), base)?),
    }
}

/// A transport's core checked (ID, then VERSION), as a board clocked by
/// SAMPLE_COUNT: what `open` does with every transport.
fn checked<T: RegisterAccess + Send + 'static>(
    mut t: T,
) -> Result<Box<dyn Board + Send>, crate::Error> {
    check_id(&mut t)?;
    check_version(&mut t)?;
    Ok(Box::new(Polled::new(t)?))
}
