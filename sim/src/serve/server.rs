//! An Etherbone/TCP server around a simulated board, as LiteX's
//! `litex_server` serves a real one.
//!
//! ```text
//!   client ──TCP──► connection thread ──┐
//!   client ──TCP──► connection thread ──┼──► Mutex<board> ◄── clock thread (free-running):
//!                                       │    serve a record       loop { run CHUNK_CLOCKS }
//!                        answer ◄───────┘    (paced: then run N clocks)
//! ```
//!
//! - Each connection thread serves its client's records itself, under the
//!   board's lock: a record's writes first (to `base`, `base + 4`, ...),
//!   then its reads, answered at once. A record is served whole between
//!   two clocks: a 5-word z snapshot is coherent, as on the hardware, where
//!   SAMPLE_COUNT latches z anyway.
//! - Free-running (the default), a clock thread runs the board
//!   continuously, `chunk` clocks per hold of the lock, as fast as it
//!   simulates, and yields the lock to any connection waiting for it. The
//!   board never waits for a client: samples go by while a client reads,
//!   and the client measures time by SAMPLE_COUNT alone. How many go by
//!   depends on the simulation's speed against the wire's round trip, so
//!   on the machine's load.
//! - Paced ([`Clocking::per_request`] = N), there is no clock thread: after
//!   answering each record the connection runs the board N clocks, then
//!   the board waits for the next record. A clock that a slow wire or a
//!   loaded machine can follow, the same on any machine (a client that
//!   polls, as `Polled` does, keeps it running). With N at most R, a client
//!   that reads z in a loop misses no sample.
//! - Each connection gets the greeting `CommGyrocalSim:IP:PORT` (one
//!   write, under the 128 bytes LiteX's `RemoteClient` reads); a read
//!   record is answered with one record whose writes are the values read
//!   (write base = the record's return address); writes are not answered.
//!   Connections may come and go, one after another or at once; a
//!   free-running board runs on.
//! - Etherbone carries no bus error: a read of an unmapped word (any byte
//!   address from 2^ADDRESS_BITS up, or a hole of the map) answers 0, a
//!   write to one or to a read-only register changes nothing; each such
//!   address is logged once. A malformed frame closes its connection.

use gyrocal_host::board::Board;
use gyrocal_host::transport::etherbone::{FrameError, Record, read_frame};
use gyrocal_regs::map::{ADDRESS_BITS, BusError};
use std::collections::HashSet;
use std::io::Write;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError, Weak};

/// Clocks the free-running board runs per hold of its lock: at the model
/// engine's speed tens of microseconds, well under a TCP round trip, so a
/// record waits about as long as it would on a bus shared with a CPU.
pub const CHUNK_CLOCKS: u64 = 1000;

/// How the board's clock runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Clocking {
    /// Free-running: clocks per hold of the lock.
    pub chunk: u64,
    /// Paced: this many clocks after each record, then wait for the next;
    /// `None`: free-running.
    pub per_request: Option<u64>,
}

impl Default for Clocking {
    /// Free-running in chunks of [`CHUNK_CLOCKS`].
    fn default() -> Self {
        Self {
            chunk: CHUNK_CLOCKS,
            per_request: None,
        }
    }
}

/// Where the server's one-line notes go (the command line: stderr).
pub type Log = Arc<dyn Fn(&str) + Send + Sync>;

/// The board and the addresses already logged, behind one lock.
struct Shared {
    board: Box<dyn Board + Send>,
    logged: HashSet<u32>,
    /// Why the board stopped, if it failed.
    stopped: Option<String>,
}

/// What the server's threads share.
struct Bus {
    shared: Mutex<Shared>,
    /// Connections waiting for the lock: the clock thread yields to them.
    waiting: AtomicUsize,
    clocking: Clocking,
    log: Log,
}

/// A listening server whose board already runs.
pub struct Server {
    listener: TcpListener,
    bus: Arc<Bus>,
}

impl Server {
    /// Power `board` on as `clocking` says (free-running: its clock thread
    /// starts now), to be served on `listener` by [`Server::run`].
    pub fn start(
        board: Box<dyn Board + Send>,
        listener: TcpListener,
        clocking: Clocking,
        log: Log,
    ) -> Self {
        let bus = Arc::new(Bus {
            shared: Mutex::new(Shared {
                board,
                logged: HashSet::new(),
                stopped: None,
            }),
            waiting: AtomicUsize::new(0),
            clocking,
            log,
        });
        if clocking.per_request.is_none() {
            let weak = Arc::downgrade(&bus);
            std::thread::spawn(move || free_run(&weak));
        }
        Self { listener, bus }
    }

    /// The address it listens on (the port, when port 0 was asked for).
    pub fn local_addr(&self) -> std::io::Result<SocketAddr> {
        self.listener.local_addr()
    }

    /// Accept connections, one thread each, until the listener fails.
    pub fn run(self) -> std::io::Result<()> {
        let here = self.listener.local_addr()?;
        let greeting = format!("CommGyrocalSim:{}:{}", here.ip(), here.port());
        for stream in self.listener.incoming() {
            let stream = stream?;
            let (bus, greeting) = (self.bus.clone(), greeting.clone());
            std::thread::spawn(move || connection(stream, &bus, &greeting));
        }
        Ok(())
    }
}

fn lock(shared: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    shared.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The free-running clock: a chunk per hold of the lock, letting waiting
/// connections in between; ends with the server or when the board fails.
fn free_run(bus: &Weak<Bus>) {
    while let Some(bus) = bus.upgrade() {
        while bus.waiting.load(Ordering::Acquire) > 0 {
            std::thread::yield_now();
        }
        let mut shared = lock(&bus.shared);
        if !shared.run(bus.clocking.chunk, &bus.log) {
            return;
        }
    }
}

/// Whether a byte address is inside the core's window.
fn in_window(address: u32) -> bool {
    address < 1 << ADDRESS_BITS
}

impl Shared {
    /// Run `clocks` clocks; false (and logged once) if the board failed.
    fn run(&mut self, clocks: u64, log: &Log) -> bool {
        if self.stopped.is_none()
            && let Err(e) = self.board.wait_clocks(clocks)
        {
            log(&format!("the board stopped: {e}"));
            self.stopped = Some(e.to_string());
        }
        self.stopped.is_none()
    }

    /// A failed access at `address`, logged the first time.
    fn note(&mut self, address: u32, what: &str, e: BusError, log: &Log) {
        if self.logged.insert(address) {
            log(&format!(
                "{what} 0x{address:08x}: {e}; Etherbone cannot report it (logged once per address)"
            ));
        }
    }

    /// One record on the board: its writes, then its reads' values.
    fn record(&mut self, record: &Record, log: &Log) -> Vec<u32> {
        for (i, &word) in record.writes.iter().enumerate() {
            let address = record.write_base.wrapping_add(4 * i as u32);
            let result = if in_window(address) {
                self.board.write_register(address, word)
            } else {
                Err(BusError::Unmapped)
            };
            if let Err(e) = result {
                self.note(address, "write to", e, log);
            }
        }
        let mut values = Vec::with_capacity(record.reads.len());
        for &address in &record.reads {
            let result = if in_window(address) {
                self.board.read_register(address)
            } else {
                Err(BusError::Unmapped)
            };
            values.push(result.unwrap_or_else(|e| {
                self.note(address, "read of", e, log);
                0
            }));
        }
        values
    }
}

impl Bus {
    /// Serve one record under the lock, answer its reads on `client`, and,
    /// paced, run the board its clocks.
    fn serve(&self, record: &Record, client: &mut impl Write) -> Result<(), ConnectionError> {
        self.waiting.fetch_add(1, Ordering::AcqRel);
        let mut shared = lock(&self.shared);
        self.waiting.fetch_sub(1, Ordering::AcqRel);
        if let Some(why) = &shared.stopped {
            return Err(ConnectionError::Stopped(why.clone()));
        }
        let values = shared.record(record, &self.log);
        if !record.reads.is_empty() {
            let answer = Record {
                write_base: record.read_return,
                writes: values,
                ..Record::default()
            };
            let frame = answer.encode()?;
            client
                .write_all(&frame)
                .map_err(ConnectionError::socket("cannot answer: "))?;
        }
        if let Some(n) = self.clocking.per_request {
            shared.run(n, &self.log);
        }
        Ok(())
    }
}

/// Why a connection was closed: one line for the log.
#[derive(Debug, thiserror::Error)]
enum ConnectionError {
    /// The board stopped (why, as the log said it).
    #[error("the board has stopped: {0}")]
    Stopped(String),
    /// A record that is no Etherbone record, or an answer too large for one.
    #[error(transparent)]
    Frame(#[from] FrameError),
    /// The socket failed (what the server was doing).
    #[error("{doing}{error}")]
    Socket {
        /// What failed, with its trailing ": " (or nothing).
        doing: &'static str,
        /// The system's error.
        error: std::io::Error,
    },
}

impl ConnectionError {
    fn socket(doing: &'static str) -> impl FnOnce(std::io::Error) -> Self {
        move |error| Self::Socket { doing, error }
    }
}

/// One client: greeting, then records until it closes.
fn connection(mut stream: TcpStream, bus: &Bus, greeting: &str) {
    let peer = stream
        .peer_addr()
        .map_or_else(|_| "a client".to_string(), |a| a.to_string());
    if let Err(e) = talk(&mut stream, bus, greeting) {
        (bus.log)(&format!("{peer}: {e}; connection closed"));
    }
}

/// The connection's exchange; `Ok` at a clean end.
fn talk(stream: &mut TcpStream, bus: &Bus, greeting: &str) -> Result<(), ConnectionError> {
    stream
        .set_nodelay(true)
        .map_err(ConnectionError::socket(""))?;
    stream
        .write_all(greeting.as_bytes())
        .map_err(ConnectionError::socket("cannot send the greeting: "))?;
    while let Some(frame) = read_frame(stream).map_err(ConnectionError::socket(""))? {
        bus.serve(&Record::decode(&frame)?, stream)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyrocal_host::board::ZSample;
    use gyrocal_host::transport::etherbone::Etherbone;
    use gyrocal_regs::map::{
        AMP1, ID, ID_WORD, RegisterAccess, RegisterBank, SAMPLE_COUNT, STREAM_OVERFLOW,
    };
    use std::sync::Mutex;

    /// A bank whose SAMPLE_COUNT is the clocks run so far (a sample per clock).
    struct Counter {
        bank: RegisterBank,
        clocks: u64,
    }

    impl RegisterAccess for Counter {
        fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
            self.bank.write(offset, word, 0xf)
        }
        fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
            match offset {
                o if o == SAMPLE_COUNT.offset => Ok(self.clocks as u32),
                o if o == ID.offset => Ok(ID_WORD),
                o if o == STREAM_OVERFLOW.offset => Ok(0),
                o => self.bank.read(o),
            }
        }
    }

    impl Board for Counter {
        fn wait_clocks(&mut self, clocks: u64) -> Result<(), BusError> {
            self.clocks += clocks;
            Ok(())
        }
        fn next_sample(&mut self, after: u32) -> Result<ZSample, BusError> {
            self.clocks += u64::from(after == self.clocks as u32);
            self.read_z()
        }
    }

    fn started(clocking: Clocking) -> (SocketAddr, Arc<Mutex<Vec<String>>>) {
        let notes = Arc::new(Mutex::new(vec![]));
        let sink = notes.clone();
        let log: Log = Arc::new(move |line| sink.lock().unwrap().push(line.to_string()));
        let board = Counter {
            bank: RegisterBank::power_up(),
            clocks: 0,
        };
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let server = Server::start(Box::new(board), listener, clocking, log);
        let address = server.local_addr().unwrap();
        std::thread::spawn(move || server.run());
        (address, notes)
    }

    /// The board runs between requests and across connections; settings
    /// persist; unmapped words read 0 and are logged once.
    #[test]
    fn serves_reads_writes_and_runs_between_connections() {
        let free = Clocking {
            chunk: 10,
            per_request: None,
        };
        let (address, notes) = started(free);
        let mut a = Etherbone::connect(&address.to_string(), 0).unwrap();
        assert_eq!(a.read_register(ID.offset).unwrap(), ID_WORD);
        a.write_register(AMP1.offset, 0x8001).unwrap();
        let first = a.read_register(SAMPLE_COUNT.offset).unwrap();
        drop(a);
        let mut b = Etherbone::connect(&address.to_string(), 0).unwrap();
        assert_eq!(b.read_register(AMP1.offset).unwrap(), 0xffff_8001);
        // The clock thread runs when the machine lets it: wait up to 5 s.
        let t = std::time::Instant::now();
        let mut later = first;
        while later == first && t.elapsed().as_secs() < 5 {
            std::thread::sleep(std::time::Duration::from_millis(1));
            later = b.read_register(SAMPLE_COUNT.offset).unwrap();
        }
        assert!(later > first, "{first} then {later}");
        let words = b.read_registers(&[0x80, 0x100, ID.offset, 0x80]).unwrap();
        assert_eq!(words, [0, 0, ID_WORD, 0]);
        b.write_register(ID.offset, 1).unwrap();
        assert_eq!(b.read_register(ID.offset).unwrap(), ID_WORD);
        let notes = notes.lock().unwrap().clone();
        assert_eq!(notes.len(), 3, "{notes:?}");
        assert!(
            notes[0].starts_with("read of 0x00000080: no register"),
            "{notes:?}"
        );
        assert!(notes[2].starts_with("write to 0x00000000: write to a read-only"));
    }

    /// A frame that is not Etherbone closes its connection, not the server.
    #[test]
    fn a_bad_frame_closes_only_its_connection() {
        let (address, notes) = started(Clocking::default());
        let mut raw = TcpStream::connect(address).unwrap();
        let mut greeting = [0u8; 128];
        let n = std::io::Read::read(&mut raw, &mut greeting).unwrap();
        assert!(greeting[..n].starts_with(b"CommGyrocalSim:127.0.0.1:"));
        raw.write_all(&[0u8; 12]).unwrap();
        let mut rest = vec![];
        std::io::Read::read_to_end(&mut raw, &mut rest).unwrap();
        assert!(rest.is_empty());
        let mut c = Etherbone::connect(&address.to_string(), 0).unwrap();
        assert_eq!(c.read_register(ID.offset).unwrap(), ID_WORD);
        let notes = notes.lock().unwrap().clone();
        assert!(notes[0].contains("bad Etherbone magic"), "{notes:?}");
    }

    /// Paced, the clock runs exactly N clocks after each record and stops
    /// until the next: 3 reads of SAMPLE_COUNT (one sample per clock) see
    /// it move by N each time, even after a pause.
    #[test]
    fn a_paced_board_runs_n_clocks_per_request() {
        let paced = Clocking {
            chunk: 1000,
            per_request: Some(30),
        };
        let (address, _) = started(paced);
        let mut bus = Etherbone::connect(&address.to_string(), 0).unwrap();
        let a = bus.read_register(SAMPLE_COUNT.offset).unwrap();
        std::thread::sleep(std::time::Duration::from_millis(50));
        let b = bus.read_register(SAMPLE_COUNT.offset).unwrap();
        let c = bus.read_register(SAMPLE_COUNT.offset).unwrap();
        assert_eq!((b - a, c - b), (30, 30), "{a} {b} {c}");
    }
}
