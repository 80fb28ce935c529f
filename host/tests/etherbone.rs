//! The Etherbone client (`transport::etherbone::Etherbone`, and
//! `transport::open` on an `etherbone://` URL) against a server written
//! here with the same frame codec, as `litex_server` answers: a greeting,
//! one answer record per read record (its writes are the values read), no
//! answer to writes, 0 for a word outside the core.

mod common;

use common::Fake;
use gyrocal_host::transport::{
    self, etherbone::Etherbone, etherbone::Record, etherbone::read_frame,
};
use gyrocal_regs::map::{AMP1, AMP2, CIC_DECIMATION, ID, ID_WORD, RegisterAccess, VERSION_WORD};
use std::io::Write;
use std::net::{TcpListener, TcpStream};
use std::sync::{Arc, Mutex};

/// How the test server misbehaves, if it does.
#[derive(Clone, Copy, PartialEq)]
enum Mode {
    /// As litex_server.
    Good,
    /// Answers one word fewer than asked.
    ShortAnswer,
    /// Closes the connection after the greeting.
    Hangs,
}

/// The words of a read record: the fake's registers at `base`, 0 elsewhere.
fn read(fake: &mut Fake, base: u32, address: u32) -> u32 {
    let offset = address.wrapping_sub(base);
    if offset < 256 {
        fake.read_register(offset).unwrap_or(0)
    } else {
        0
    }
}

fn talk(mut stream: TcpStream, fake: &mut Fake, base: u32, mode: Mode, seen: &Mutex<Vec<Record>>) {
    stream.write_all(b"CommTest:127.0.0.1:0").unwrap();
    if mode == Mode::Hangs {
        return;
    }
    while let Ok(Some(frame)) = read_frame(&mut stream) {
        let record = Record::decode(&frame).unwrap();
        seen.lock().unwrap().push(record.clone());
        for (i, &w) in record.writes.iter().enumerate() {
            let offset = record.write_base.wrapping_sub(base) + 4 * i as u32;
            let _ = fake.write_register(offset, w);
        }
        if record.reads.is_empty() {
            continue;
        }
        let mut words: Vec<u32> = record.reads.iter().map(|&a| read(fake, base, a)).collect();
        if mode == Mode::ShortAnswer {
            words.pop();
        }
        let answer = Record {
            writes: words,
            ..Record::default()
        };
        stream.write_all(&answer.encode().unwrap()).unwrap();
    }
}

/// A server of a fake board at `base`; its address and the records it saw.
fn server(base: u32, mode: Mode) -> (String, Arc<Mutex<Vec<Record>>>) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let address = listener.local_addr().unwrap().to_string();
    let seen = Arc::new(Mutex::new(vec![]));
    let log = seen.clone();
    std::thread::spawn(move || {
        let mut fake = Fake::new(0, &[1]);
        for stream in listener.incoming() {
            talk(stream.unwrap(), &mut fake, base, mode, &log);
        }
    });
    (address, seen)
}

#[test]
fn reads_and_writes_are_litex_records_at_the_base() {
    let base = 0x4000_0000;
    let (address, seen) = server(base, Mode::Good);
    let mut bus = Etherbone::connect(&address, base).unwrap();
    bus.write_register(AMP1.offset, 0x8001).unwrap();
    assert_eq!(bus.read_register(AMP1.offset).unwrap(), 0xffff_8001);
    let offsets: Vec<u32> = (0..300).map(|i| [ID.offset, AMP2.offset][i % 2]).collect();
    let words = bus.read_registers(&offsets).unwrap();
    assert!(words.iter().step_by(2).all(|&w| w == ID_WORD));
    assert!(words.iter().skip(1).step_by(2).all(|&w| w == 0));
    let seen = seen.lock().unwrap();
    assert_eq!(seen[0].write_base, base + AMP1.offset);
    assert_eq!(seen[0].writes, [0x8001]);
    assert!(
        seen[0].reads.is_empty(),
        "a write is one record, not answered"
    );
    assert_eq!(seen[1].reads, [base + AMP1.offset]);
    let bursts: Vec<usize> = seen[2..].iter().map(|r| r.reads.len()).collect();
    assert_eq!(bursts, [255, 45], "300 reads: two round trips");
}

#[test]
fn open_checks_the_id_and_times_the_board_by_sample_count() {
    let (address, _) = server(0x100, Mode::Good);
    let mut board = transport::open(&format!("etherbone://{address}?base=0x100")).unwrap();
    assert_eq!(board.read_register(4).unwrap(), VERSION_WORD);
    board.write_register(CIC_DECIMATION.offset, 200).unwrap();
    let before = board.read_z().unwrap();
    board.wait_clocks(1000).unwrap();
    let now = board.read_z().unwrap().count;
    let s = board.next_sample(now).unwrap();
    assert!(
        s.count.wrapping_sub(before.count) >= 7,
        "{before:?} then {s:?}"
    );
    assert_eq!(s.z, [f64::from(s.count), -f64::from(s.count)]);
}

#[test]
fn a_wrong_base_reads_a_wrong_id_and_is_refused() {
    let (address, _) = server(0, Mode::Good);
    let e = transport::open(&format!("etherbone://{address}?base=0x1000"))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("ID register reads 0x00000000"), "{e}");
    assert!(e.contains("wrong base address"), "{e}");
}

#[test]
fn a_bad_answer_or_a_closed_connection_is_a_one_line_error() {
    let (address, _) = server(0, Mode::ShortAnswer);
    let mut bus = Etherbone::connect(&address, 0).unwrap();
    let e = bus.read_registers(&[0, 4]).unwrap_err().to_string();
    assert_eq!(e, "etherbone: answer: 1 words for 2 reads");
    let (address, _) = server(0, Mode::Hangs);
    let mut bus = Etherbone::connect(&address, 0).unwrap();
    let e = bus.read_register(0).unwrap_err().to_string();
    assert!(e.starts_with("etherbone: "), "{e}");
    assert!(!e.contains('\n'), "{e}");
    let refused = transport::open("etherbone://127.0.0.1:1")
        .err()
        .unwrap()
        .to_string();
    assert!(
        refused.contains("cannot connect to 127.0.0.1:1"),
        "{refused}"
    );
}
