//! Identification on a board the host knows only through its registers,
//! with datasheets that miss the device by the process spread: a small
//! fake board whose z is the exact steady state of two Lorentzian modes
//! (no simulator, no transient), so the search logic is tested alone and
//! in milliseconds. The simulated board's own test is `tests/identify.rs`.

use gyrocal_host::GyroParams;
use gyrocal_host::board::{Board, ZSample};
use gyrocal_host::identify;
use gyrocal_host::knowns::{Derived, Knowns};
use gyrocal_regs::datapath::readout_word;
use gyrocal_regs::filter_design::cic_bit_growth;
use gyrocal_regs::map::{
    BusError, RegisterAccess, RegisterBank, SAMPLE_COUNT, Z1_HI, Z1_LO, Z2_HI, Z2_LO,
};
use nalgebra::Complex;
use std::f64::consts::TAU;

type C64 = Complex<f64>;

/// Two modes, each seen only through its own drive, behind the register map.
struct Lorentzian {
    bank: RegisterBank,
    clock_hz: f64,
    cycle: u64,
    /// (fk, bk, C): Y = C / ((fk - f)(fk + f) + j f bk), ADC LSB per drive LSB.
    modes: [(f64, f64, C64); 2],
    /// Additive noise on z (z LSB, uniform +-).
    noise: f64,
    state: u64,
    snapshot: [f64; 2],
}

impl Lorentzian {
    fn z_now(&mut self) -> [f64; 2] {
        let r = self.bank.registers();
        let f = f64::from(r.carrier_step) * self.clock_hz / 2f64.powi(32);
        let theta =
            f64::from(r.ref_phase.wrapping_sub(r.carrier_step.div_ceil(2))) * TAU / 2f64.powi(32);
        let rr = f64::from(r.cic_decimation);
        let cic = rr.powi(4) / 2f64.powi(cic_bit_growth(u32::from(r.cic_decimation)) as i32);
        let k = r.iir;
        let dc = cic * 4.0 * f64::from(k.k0) / -(f64::from(k.k1) + f64::from(k.k2));
        let amps = [r.amp.0, r.amp.1];
        std::array::from_fn(|m| {
            let (fk, bk, c) = self.modes[m];
            let y = c / C64::new((fk - f) * (fk + f), f * bk);
            let w = readout_word(amps[m]);
            self.state = self.state.wrapping_mul(6364136223846793005).wrapping_add(1);
            let n = ((self.state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * self.noise;
            dc / 2.0 * w * w * (y * C64::from_polar(1.0, -theta)).re + n
        })
    }

    fn count(&self) -> u32 {
        (self.cycle / u64::from(self.bank.registers().cic_decimation.max(1))) as u32
    }
}

fn words(z: f64) -> (u32, u32) {
    let raw = (z * 256.0).round() as i64;
    (raw as u32, (raw >> 32) as u32)
}

impl RegisterAccess for Lorentzian {
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        self.bank.write(offset, word, 0xf)
    }

    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        let [z1, z2] = self.snapshot;
        Ok(match offset {
            o if o == SAMPLE_COUNT.offset => {
                self.snapshot = self.z_now();
                self.count()
            }
            o if o == Z1_LO.offset => words(z1).0,
            o if o == Z1_HI.offset => words(z1).1,
            o if o == Z2_LO.offset => words(z2).0,
            o if o == Z2_HI.offset => words(z2).1,
            o => match self.bank.read(o) {
                Ok(w) => w,
                Err(BusError::Unmapped) => return Err(BusError::Unmapped),
                Err(_) => 0,
            },
        })
    }
}

impl Board for Lorentzian {
    fn wait_clocks(&mut self, clocks: u64) -> Result<(), BusError> {
        self.cycle += clocks;
        Ok(())
    }

    fn next_sample(&mut self, after: u32) -> Result<ZSample, BusError> {
        let r = u64::from(self.bank.registers().cic_decimation.max(1));
        while self.count() == after {
            self.cycle += r - self.cycle % r;
        }
        self.read_z()
    }
}

/// The paper's modes: 9.64 MHz and 250 Hz above, Q 55,000, a 3 deg front end.
fn paper_truth() -> [(f64, f64, C64); 2] {
    let c = C64::from_polar(2.0e9, -3f64.to_radians());
    [
        (9.64e6, 9.64e6 / 55e3, c),
        (9.64e6 + 250.0, (9.64e6 + 250.0) / 55e3, c * 0.8),
    ]
}

fn knowns(datasheet: GyroParams) -> Knowns {
    Knowns {
        clock_hz: 50e6,
        angular_gain_uncertainty: 0.0,
        amplitude: (0.9, 0.9),
        force_full_scale: [1.0, 1.0],
        dac_latency: 2,
        adc_latency: 3,
        filter: Derived {
            decimation: 1000,
            butterworth_hz: 500.0,
            rc_hz: 2000.0,
            min_window_s: 0.05,
        },
        carrier_hz: 9.64e6,
        rates_dps: vec![1.0, 20.0],
        cal_freqs_hz: vec![10.0, 15.0],
        nominal: datasheet,
    }
}

fn board(modes: [(f64, f64, C64); 2]) -> Lorentzian {
    Lorentzian {
        bank: RegisterBank::power_up(),
        clock_hz: 50e6,
        cycle: 0,
        modes,
        noise: 1e-3,
        state: 1,
        snapshot: [0.0; 2],
    }
}

/// f1 off by the amounts the issue saw fail (+0.3%, -1.5%) and by the
/// process spread's edge (+-4.9%), Q off by a factor of 2 either way, the
/// split off by the whole of f1's error, with little z noise and with a
/// noise that buries the far responses (30 z LSB: there the coarse search
/// alone cannot converge and the scan finds the mode): each mode within 3
/// of its sigmas, the sigmas below 1% of a bandwidth and 0.1% of Q.
#[test]
fn a_datasheet_off_by_the_process_spread_is_found_and_refined() {
    let truth = paper_truth();
    let cases = [
        (1.003, 1.0),
        (0.985, 1.0),
        (1.049, 0.5),
        (0.951, 2.0),
        (1.0, 2.0),
    ];
    for (noise, (f_rel, q_rel)) in [1e-3, 30.0].into_iter().flat_map(|n| cases.map(|c| (n, c))) {
        let ds = GyroParams {
            f1_hz: truth[0].0 * f_rel,
            f2_hz: truth[1].0,
            q1: 55e3 * q_rel,
            q2: 55e3 * q_rel,
            angular_gain: 0.6,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
        };
        let kn = knowns(ds.clone());
        let mut b = board(truth);
        b.noise = noise;
        let id = identify::identify(&mut b, &kn, &ds)
            .unwrap_or_else(|e| panic!("f x {f_rel}, Q x {q_rel}: {e}"));
        eprintln!(
            "noise {noise}, f1 x {f_rel}, Q x {q_rel}: scanned {} / {}, {} clocks",
            id.modes[0].scanned, id.modes[1].scanned, id.clocks
        );
        for (m, (fk, bk, _)) in id.modes.iter().zip(truth) {
            // Within 3 sigma, and sigma itself small: the fit's noise.
            let (df, dq) = (m.f_hz.value - fk, m.q.value - fk / bk);
            assert!(
                df.abs() < 3.0 * m.f_hz.uncertainty,
                "f x {f_rel}: {df} vs {:?}",
                m.f_hz
            );
            assert!(
                dq.abs() < 3.0 * m.q.uncertainty,
                "Q x {q_rel}: {dq} vs {:?}",
                m.q
            );
            assert!(m.f_hz.uncertainty < 1e-2 * bk && m.q.uncertainty < 1e-3 * fk / bk);
        }
    }
}

/// No resonance within +-5% of the datasheet: one line saying where the
/// host looked, not a wrong figure.
#[test]
fn no_resonance_in_reach_is_one_clear_error() {
    let truth = paper_truth();
    let ds = GyroParams {
        f1_hz: truth[0].0 * 1.2,
        f2_hz: truth[0].0 * 1.2 + 250.0,
        q1: 55e3,
        q2: 55e3,
        angular_gain: 0.6,
        quadrature_dps: 0.0,
        damping_coupling_dps: 0.0,
    };
    let mut b = board(truth);
    let e = identify::identify(&mut b, &knowns(ds.clone()), &ds)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("identification of mode 1: no resonance found from"),
        "{e}"
    );
    assert!(!e.contains('\n'));
}
