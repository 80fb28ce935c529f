//! `Polled`: time from SAMPLE_COUNT on a board reached only through its
//! registers, on a fake board (no simulator): "N clocks" is ceil(N / R) + 1
//! samples, with R the decimation last written (or read at the start);
//! counts may jump (samples that went by unread) and wrap at 2^32.

mod common;

use common::Fake;
use gyrocal_host::board::{Board, Polled, STALL_TIMEOUT};
use gyrocal_regs::map::{CIC_DECIMATION, RegisterAccess};
use std::time::Instant;

/// The samples `wait_clocks(clocks)` must let pass at decimation `r`.
fn samples(clocks: u64, r: u64) -> u32 {
    (clocks.div_ceil(r) + 1) as u32
}

/// The count at the first SAMPLE_COUNT read of `wait_clocks` (its start)
/// and at the last (where the wait ended).
fn waited(fake: Fake, r: Option<u32>, clocks: u64) -> (u32, u32) {
    let start_count = fake.count;
    let mut board = Polled::new(fake).unwrap();
    if let Some(r) = r {
        board.write_register(CIC_DECIMATION.offset, r).unwrap();
    }
    board.wait_clocks(clocks).unwrap();
    let fake = board.inner_mut();
    (start_count.wrapping_add(fake.steps[0]), fake.count)
}

#[test]
fn wait_clocks_waits_ceil_n_over_r_plus_one_samples() {
    for (clocks, r) in [
        (1000, 200),
        (1001, 200),
        (1, 166),
        (0, 4096),
        (123_457, 333),
    ] {
        let (start, end) = waited(Fake::new(77, &[1]), Some(r), clocks);
        assert_eq!(
            end - start,
            samples(clocks, u64::from(r)),
            "{clocks} clocks, R {r}"
        );
    }
}

#[test]
fn the_decimation_is_read_from_the_board_at_the_start() {
    let mut fake = Fake::new(5, &[1]);
    fake.bank.write(CIC_DECIMATION.offset, 1000, 0xf).unwrap();
    let (start, end) = waited(fake, None, 5000);
    assert_eq!(end - start, samples(5000, 1000));
    // Power-up R = 256.
    let (start, end) = waited(Fake::new(5, &[1]), None, 2560);
    assert_eq!(end - start, samples(2560, 256));
}

#[test]
fn jumps_in_the_count_end_the_wait_at_the_first_count_past_the_target() {
    let steps = [1, 0, 0, 5, 0, 2, 7];
    let (start, end) = waited(Fake::new(0, &steps), Some(200), 10_000);
    let need = samples(10_000, 200);
    let got = end - start;
    assert!(
        got >= need && got < need + 7,
        "waited {got} samples for {need}"
    );
}

#[test]
fn the_count_wraps_at_2_to_the_32() {
    let c0 = u32::MAX - 3;
    let (start, end) = waited(Fake::new(c0, &[1]), Some(200), 2000);
    assert!(end < start, "the count wrapped: {start} then {end}");
    assert_eq!(end.wrapping_sub(start), samples(2000, 200));
}

#[test]
fn next_sample_returns_the_first_newer_sample_across_gaps_and_the_wrap() {
    for c0 in [10, u32::MAX - 1] {
        let mut board = Polled::new(Fake::new(c0, &[0, 0, 0, 4])).unwrap();
        let now = board.read_z().unwrap();
        assert_eq!(now.count, c0, "no move on the first read");
        let s = board.next_sample(now.count).unwrap();
        assert_eq!(s.count, c0.wrapping_add(4));
        // z is the latched count (z1 = count, z2 = -count, z LSB).
        assert_eq!(s.z, [f64::from(s.count), -f64::from(s.count)]);
    }
}

/// A board clocked in wall time (1 kHz samples): waits take the time the
/// samples take, far inside the stall timeout.
#[test]
fn normal_waits_do_not_reach_the_stall_timeout() {
    let mut board = Polled::new(Fake::clocked()).unwrap();
    board.write_register(CIC_DECIMATION.offset, 1000).unwrap();
    let t = Instant::now();
    board.wait_clocks(30_000).unwrap();
    let mut last = board.read_z().unwrap().count;
    for _ in 0..5 {
        last = board.next_sample(last).unwrap().count;
    }
    let took = t.elapsed();
    assert!(took.as_millis() >= 30, "{took:?}: 31 samples of 1 ms");
    assert!(took < STALL_TIMEOUT / 10, "{took:?}");
}
