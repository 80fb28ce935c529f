//! The bus top `gyro_interface_axi` on a live datapath: the coherent z
//! snapshot, in the bit-true model and in rust-hdl's simulation of the
//! design, and the two engines against each other.
//!
//! The bus writes calibration settings (SELECT = 1, a 48-bit modulation step
//! with both words non-zero, both drives on, the least decimation, R = 166)
//! and turns the stream on; the ADC words are random, so once the carrier
//! tables are filled (`DRIVE_START_CLOCKS` = 8232) the DAC words move and z
//! is non-zero and changes with every sample. Then, around 9 consecutive z
//! samples, the bus reads SAMPLE_COUNT one clock before, during and one
//! clock after the sample's `z_valid` clock, and Z1_LO, Z1_HI, Z2_LO, Z2_HI
//! after it. The test checks the header's contract (`host::axi_top`):
//! - the count includes a sample from its `z_valid` clock on;
//! - the four z words hold the sample the count names: the one the stream
//!   carried with that sequence number;
//!
//! and that rust-hdl's outputs equal the model's on every clock, DAC words
//! included (`axi_model_vs_rtl` stops before the drives start).
//!
//! Issue 19: latching the snapshot on a read of STREAM_OVERFLOW instead of
//! SAMPLE_COUNT passed every other hdl test (their z was 0 throughout), and
//! so did applying MOD_STEP_LO on its own write instead of with MOD_STEP_HI
//! (their drives were 0). About 10,000 clocks: 2.5 s of CPU in release (9 s
//! wall on the loaded 2-core machine).

use gyrocal_hdl::filter_design::{self, MIN_DECIMATION};
use gyrocal_hdl::gyro_interface::DRIVE_START_CLOCKS;
use gyrocal_hdl::host::model::{BusInputs, BusOutputs, GyroInterfaceAxi, unpack_sample};
use gyrocal_hdl::host::register_map::{
    self, Register, SAMPLE_COUNT, STREAM_ENABLE, Z1_HI, Z1_LO, Z2_HI, Z2_LO,
};
use gyrocal_hdl::host::rtl::RtlGyroInterfaceAxi;
use gyrocal_hdl::model::gyro_interface::Registers;

/// Samples around which the snapshot is read.
const GROUPS: usize = 9;
/// The reads of one group, in order.
const GROUP_READS: [Register; 5] = [SAMPLE_COUNT, Z1_LO, Z1_HI, Z2_LO, Z2_HI];
/// Clocks per read: AR taken, read, R taken (`rready` always high).
const READ_CLOCKS: usize = 3;

/// Calibration settings (a non-round carrier, a 5 kHz modulation at a
/// 10 MHz clock, both drives on, the least decimation and its filter) and
/// STREAM_ENABLE, written through the bus in register order (MOD_STEP_LO
/// before MOD_STEP_HI): AW and W together for 3 clocks, then an idle clock.
fn configuration() -> Vec<BusInputs> {
    let filter = filter_design::design(10e6, MIN_DECIMATION, 5e3, 10e3).unwrap();
    let regs = Registers {
        select: true,
        carrier_step: 0x19e9_1d37,
        mod_step: 0x0020_c49b_a5e3,
        amp: (29491, -22937),
        cic_decimation: MIN_DECIMATION as u16,
        cic_shift: filter.cic_shift as u8,
        iir: filter.coefficients,
        ..Registers::default()
    };
    let mut writes = register_map::encode(&regs);
    writes.push((STREAM_ENABLE.offset, 1));
    let mut inputs = Vec::new();
    for (offset, word) in writes {
        let write = BusInputs {
            awvalid: true,
            awaddr: offset as u8,
            wvalid: true,
            wdata: word,
            ..BusInputs::default()
        };
        inputs.extend([write; 3]);
        inputs.push(BusInputs::default());
    }
    inputs
}

/// Random ADC words on every cycle (xorshift).
fn with_random_adc(mut inputs: Vec<BusInputs>) -> Vec<BusInputs> {
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    for i in &mut inputs {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        i.adc = (s as i16, (s >> 16) as i16);
    }
    inputs
}

/// The clocks during which the core's `z_valid` is high and z is not 0,
/// on the model, with the configuration and no reads.
fn live_samples(cycles: usize) -> Vec<usize> {
    let mut inputs = configuration();
    inputs.resize(cycles, BusInputs::default());
    let mut model = GyroInterfaceAxi::new();
    let mut live = Vec::new();
    for (n, i) in with_random_adc(inputs).iter().enumerate() {
        let core = model.core_outputs();
        if core.z_valid && core.z != (0, 0) {
            live.push(n);
        }
        model.step(i);
    }
    live
}

/// The test's traffic and, per group, the clock whose `z_valid` it reads
/// around and its offset (-1, 0, +1) to the SAMPLE_COUNT read's clock.
fn traffic() -> (Vec<BusInputs>, Vec<(usize, i64)>) {
    let live = live_samples(DRIVE_START_CLOCKS + 1200 + GROUPS * MIN_DECIMATION as usize);
    assert!(live.len() > GROUPS, "too few live samples: {live:?}");
    let groups: Vec<(usize, i64)> = (0..GROUPS)
        .map(|k| (live[k + 1], k as i64 % 3 - 1))
        .collect();
    let last = groups.last().unwrap().0 + 2 + READ_CLOCKS * GROUP_READS.len();
    let mut inputs = configuration();
    inputs.resize(last, BusInputs::default());
    for &(clock, offset) in &groups {
        // The read happens during the clock after AR is taken.
        let first_ar = (clock as i64 + offset - 1) as usize;
        for (r, register) in GROUP_READS.iter().enumerate() {
            let i = &mut inputs[first_ar + READ_CLOCKS * r];
            i.arvalid = true;
            i.araddr = register.offset as u8;
        }
    }
    (with_random_adc(inputs), groups)
}

/// What the bus returned: the read data in order, and the stream's
/// samples by 16-bit sequence number.
struct Seen {
    reads: Vec<u32>,
    stream: std::collections::HashMap<u16, (i64, i64)>,
}

fn observe(
    mut outputs: BusOutputs,
    inputs: &[BusInputs],
    mut step: impl FnMut(&BusInputs) -> BusOutputs,
) -> Seen {
    let mut seen = Seen {
        reads: Vec::new(),
        stream: Default::default(),
    };
    for i in inputs {
        if outputs.rvalid && i.rready {
            assert_eq!(outputs.rresp, 0, "a read of a mapped word failed");
            seen.reads.push(outputs.rdata);
        }
        if outputs.tvalid && i.tready {
            let (z1, z2, count) = unpack_sample(outputs.tdata);
            seen.stream.insert(count, (z1, z2));
        }
        outputs = step(i);
    }
    seen
}

/// 40-bit z from its LO word and the low byte of its HI word.
fn z(lo: u32, hi: u32) -> i64 {
    ((((hi as u64 & 0xff) << 32 | lo as u64) << 24) as i64) >> 24
}

fn check(engine: &str, seen: &Seen, groups: &[(usize, i64)], count_at: &[u32]) {
    assert_eq!(seen.reads.len(), GROUPS * GROUP_READS.len(), "{engine}");
    let mut snapshots = Vec::new();
    for (k, (words, &(clock, offset))) in seen.reads.chunks(5).zip(groups).enumerate() {
        // The count includes the sample from its z_valid clock on.
        let expected = count_at[k] - u32::from(offset < 0);
        assert_eq!(
            words[0], expected,
            "{engine}: SAMPLE_COUNT read at z_valid clock {clock} {offset:+}"
        );
        let snapshot = (z(words[1], words[2]), z(words[3], words[4]));
        let streamed = seen.stream.get(&(words[0] as u16)).copied();
        assert_eq!(
            Some(snapshot),
            streamed,
            "{engine}: group {k}: the snapshot is not the sample the count names"
        );
        snapshots.push(snapshot);
    }
    snapshots.dedup();
    assert!(
        snapshots.len() >= GROUPS - 2 && snapshots.iter().all(|s| *s != (0, 0)),
        "{engine}: z must be live and change: {snapshots:?}"
    );
}

#[test]
fn the_snapshot_is_the_counted_sample_on_a_live_datapath() {
    let (inputs, groups) = traffic();
    // The sample count during each group's z_valid clock, on the model.
    let mut counted = 0u32;
    let mut count_at = Vec::new();
    let mut model = GyroInterfaceAxi::new();
    for (n, i) in inputs.iter().enumerate() {
        counted += u32::from(model.core_outputs().z_valid);
        if groups.iter().any(|g| g.0 == n) {
            count_at.push(counted);
        }
        model.step(i);
    }
    let mut model = GyroInterfaceAxi::new();
    let seen = observe(model.outputs(), &inputs, |i| model.step(i));
    check("model", &seen, &groups, &count_at);
    // rust-hdl, with the model beside it: every output of every clock agrees.
    let (mut rtl, mut twin) = (RtlGyroInterfaceAxi::new(), GyroInterfaceAxi::new());
    assert_eq!(rtl.outputs(), twin.outputs(), "power-up");
    let (mut clock, mut driving) = (0, 0);
    let seen = observe(rtl.outputs(), &inputs, |i| {
        let (r, m) = (rtl.step(i), twin.step(i));
        clock += 1;
        assert_eq!(r, m, "rust-hdl against the model after clock {clock}");
        driving += usize::from(r.dac != (0, 0));
        r
    });
    check("rust-hdl", &seen, &groups, &count_at);
    assert!(driving > 1000, "the drives ran for {driving} clocks only");
}
