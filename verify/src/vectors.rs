//! Golden vectors: rust-hdl's own simulation of `GyroInterface`, recorded
//! cycle by cycle, for replay against the exported Verilog.
//!
//! ```text
//!   seed ──► stimulus(seed) ──► Stimulus { segments, inputs[n] }
//!                                   │  (adc, Registers) per cycle
//!                                   ▼
//!            record() ──► RtlGyroInterface::step ──► GoldenVectors { power_up, cycles[n] }
//!                                                         │
//!                                                         ▼ to_hex()
//!                                                  vector file for the testbench
//! ```
//!
//! The stimulus is one continuous run from power-up, made of segments with
//! different settings (the registers are reprogrammed between segments, as a
//! CPU would): readout and calibration, SELECT toggling in the middle of a
//! segment, decimations 166 (the least, `MIN_DECIMATION`), 199, 250, 1000 and
//! 4096 plus a random one, extreme
//! amplitudes (-32768 and 32767), random carrier and modulation steps,
//! reference phases and delays (including 0 and 63), and IIR coefficients
//! designed by `gyrocal_hdl::filter_design` for random cut-offs over the whole
//! allowed range. The ADC words alternate between bursts of uniform random
//! words, constant full-scale (32767) and most-negative (-32768) words,
//! full-scale square waves and slow sines (some clipping at both rails); one
//! segment feeds full-scale (clipped) copies of the carrier at random phases
//! through the fastest allowed filter, which drives z near the top of its
//! range.
//! Everything comes from a seeded SplitMix64 generator: the same seed gives
//! the same vectors on every machine.
//!
//! The expected outputs come from `gyrocal_hdl::rtl::RtlGyroInterface`, the
//! rust-hdl design itself (not the bit-true model), at about 7,000 clocks per
//! second in a release build.
//!
//! # Vector file format
//!
//! Text, one record per line, fields separated by one space, every number in
//! lower-case hexadecimal, two's complement at the port's width, zero-padded
//! to `ceil(bits / 4)` digits:
//!
//! ```text
//! line 1:    number of cycles n, in decimal
//! line 2:    power-up outputs: dac1 dac2 z1 z2 z_valid
//! line 3...: one line per cycle: the input ports in `export::PORTS` order
//!            (without clock), then the output ports after that cycle's
//!            rising edge, in `export::PORTS` order
//! ```

use gyrocal_hdl::export::{PORTS, Port, PortDirection};
use gyrocal_hdl::filter_design;
use gyrocal_hdl::model::gyro_interface::CarrierProfile;
use gyrocal_hdl::model::gyro_interface::{Outputs, Registers};
use gyrocal_hdl::rtl::RtlGyroInterface;

/// The seed of the standard vectors.
pub const DEFAULT_SEED: u64 = 0x6779_726f_6361_6c01;

/// The standard stimulus is at least this many cycles long.
pub const MIN_CYCLES: usize = 20_000;

/// The inputs of one cycle: ADC words and settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Inputs {
    /// ADC words (adc1, adc2).
    pub adc: (i16, i16),
    /// Every other input port.
    pub regs: Registers,
}

/// One cycle of golden vectors: inputs and the outputs after the edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cycle {
    /// Inputs applied during the cycle (captured at its rising edge).
    pub inputs: Inputs,
    /// Output ports after the rising edge.
    pub expected: Outputs,
}

/// A stretch of cycles with one kind of setting.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Segment {
    /// What the segment exercises.
    pub name: String,
    /// First cycle.
    pub start: usize,
    /// Number of cycles.
    pub cycles: usize,
}

/// Inputs for every cycle of a run from power-up.
#[derive(Clone, Debug)]
pub struct Stimulus {
    /// The seed it came from.
    pub seed: u64,
    /// The segments, in order, covering every cycle.
    pub segments: Vec<Segment>,
    /// Inputs per cycle.
    pub inputs: Vec<Inputs>,
}

/// Recorded inputs and outputs of a run from power-up.
#[derive(Clone, Debug)]
pub struct GoldenVectors {
    /// The seed of the stimulus.
    pub seed: u64,
    /// The segments of the stimulus.
    pub segments: Vec<Segment>,
    /// Output ports at power-up, before the first rising edge.
    pub power_up: Outputs,
    /// One entry per clock cycle.
    pub cycles: Vec<Cycle>,
}

/// The standard vectors for `seed`: [`stimulus`] run through [`record`].
/// Takes a few seconds (rust-hdl simulates about 7,000 clocks per second).
pub fn golden_vectors(seed: u64) -> GoldenVectors {
    record(&stimulus(seed))
}

/// The standard vectors for `seed` on the core with this carrier profile.
pub fn golden_vectors_for(profile: CarrierProfile, seed: u64) -> GoldenVectors {
    record_with(profile, &stimulus(seed))
}

/// Run `stimulus` through rust-hdl's simulation of the design, from power-up.
pub fn record(stimulus: &Stimulus) -> GoldenVectors {
    record_with(CarrierProfile::Table, stimulus)
}

/// [`record`] on the core with this carrier profile.
pub fn record_with(profile: CarrierProfile, stimulus: &Stimulus) -> GoldenVectors {
    let mut rtl = RtlGyroInterface::with_profile(profile);
    let power_up = rtl.outputs();
    let cycles = stimulus
        .inputs
        .iter()
        .map(|i| Cycle {
            inputs: *i,
            expected: rtl.step(i.adc, &i.regs),
        })
        .collect();
    GoldenVectors {
        seed: stimulus.seed,
        segments: stimulus.segments.clone(),
        power_up,
        cycles,
    }
}

/// The input ports carried in the vector file (every input except `clock`),
/// in `export::PORTS` order.
pub fn input_ports() -> impl Iterator<Item = &'static Port> {
    PORTS
        .iter()
        .filter(|p| p.direction == PortDirection::Input && p.name != "clock")
}

/// The output ports, in `export::PORTS` order.
pub fn output_ports() -> impl Iterator<Item = &'static Port> {
    PORTS
        .iter()
        .filter(|p| p.direction == PortDirection::Output)
}

/// The value of input port `port` as an unsigned word of the port's width.
/// Panics on a port this module does not know: when a port is added to the
/// design, this function must learn it (the replay would otherwise not drive
/// it).
pub fn input_word(port: &Port, i: &Inputs) -> u128 {
    let r = &i.regs;
    let v: i128 = match port.name {
        "adc1" => i.adc.0 as i128,
        "adc2" => i.adc.1 as i128,
        "select" => r.select as i128,
        "carrier_step" => r.carrier_step as i128,
        "ref_phase" => r.ref_phase as i128,
        "ref_delay" => r.ref_delay as i128,
        "mod_step" => r.mod_step as i128,
        "amp1" => r.amp.0 as i128,
        "amp2" => r.amp.1 as i128,
        "cic_decimation" => r.cic_decimation as i128,
        "cic_shift" => r.cic_shift as i128,
        "iir_k0" => r.iir.k0 as i128,
        "iir_k1" => r.iir.k1 as i128,
        "iir_k2" => r.iir.k2 as i128,
        "iir_alpha" => r.iir.alpha as i128,
        other => panic!("input port `{other}` is not known to verify::vectors::input_word"),
    };
    mask(v, port.bits)
}

/// The value of output port `port` as an unsigned word of the port's width.
/// Panics on an unknown port, like [`input_word`].
pub fn output_word(port: &Port, o: &Outputs) -> u128 {
    let v: i128 = match port.name {
        "dac1" => o.dac.0 as i128,
        "dac2" => o.dac.1 as i128,
        "z1" => o.z.0 as i128,
        "z2" => o.z.1 as i128,
        "z_valid" => o.z_valid as i128,
        other => panic!("output port `{other}` is not known to verify::vectors::output_word"),
    };
    mask(v, port.bits)
}

fn mask(v: i128, bits: usize) -> u128 {
    if bits >= 128 {
        v as u128
    } else {
        (v as u128) & ((1u128 << bits) - 1)
    }
}

fn hex(v: u128, bits: usize) -> String {
    format!("{v:0width$x}", width = bits.div_ceil(4))
}

fn output_fields(o: &Outputs) -> Vec<String> {
    output_ports()
        .map(|p| hex(output_word(p, o), p.bits))
        .collect()
}

impl GoldenVectors {
    /// The vector file (format in the module documentation).
    pub fn to_hex(&self) -> String {
        let mut s = String::with_capacity(130 * (self.cycles.len() + 2));
        s.push_str(&format!("{}\n", self.cycles.len()));
        s.push_str(&output_fields(&self.power_up).join(" "));
        s.push('\n');
        for c in &self.cycles {
            let fields: Vec<String> = input_ports()
                .map(|p| hex(input_word(p, &c.inputs), p.bits))
                .chain(output_fields(&c.expected))
                .collect();
            s.push_str(&fields.join(" "));
            s.push('\n');
        }
        s
    }

    /// The first `cycles` cycles (all of them if fewer), for quick runs.
    pub fn prefix(&self, cycles: usize) -> GoldenVectors {
        let n = cycles.min(self.cycles.len());
        GoldenVectors {
            seed: self.seed,
            segments: self
                .segments
                .iter()
                .filter(|g| g.start < n)
                .map(|g| Segment {
                    cycles: g.cycles.min(n - g.start),
                    ..g.clone()
                })
                .collect(),
            power_up: self.power_up,
            cycles: self.cycles[..n].to_vec(),
        }
    }

    /// Number of cycles.
    pub fn len(&self) -> usize {
        self.cycles.len()
    }

    /// True when there are no cycles.
    pub fn is_empty(&self) -> bool {
        self.cycles.is_empty()
    }
}

/// SplitMix64: small, fast, and identical on every platform.
#[derive(Clone, Debug)]
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in 0..n (n > 0).
    fn below(&mut self, n: u64) -> u64 {
        ((self.next_u64() as u128 * n as u128) >> 64) as u64
    }

    /// Uniform in lo..=hi.
    fn range(&mut self, lo: i64, hi: i64) -> i64 {
        lo + self.below((hi - lo + 1) as u64) as i64
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    /// Log-uniform in [lo, hi].
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + self.unit() * (hi.ln() - lo.ln())).exp()
    }
}

/// How SELECT behaves in a segment.
#[derive(Clone, Copy, Debug)]
enum SelectPlan {
    Fixed(bool),
    /// Toggle at random intervals of `min..=max` cycles.
    Toggle {
        min: i64,
        max: i64,
    },
}

#[derive(Clone, Copy, Debug)]
struct SegmentPlan {
    name: &'static str,
    cycles: usize,
    /// `None`: random in MIN_DECIMATION..=MIN_DECIMATION + 200.
    decimation: Option<u32>,
    select: SelectPlan,
    /// `None`: random.
    amp: Option<(i16, i16)>,
    /// `None`: random.
    ref_delay: Option<u8>,
    /// ADC words follow the carrier (full scale, clipped) in bursts with
    /// random phases, and the filter has its highest cut-offs: drives z
    /// towards the top of its range.
    correlated: bool,
}

const PLANS: &[SegmentPlan] = &[
    SegmentPlan {
        name: "readout, least R (166), amplitudes (32767, -32768), ref_delay 0",
        cycles: 10000,
        decimation: Some(filter_design::MIN_DECIMATION),
        select: SelectPlan::Fixed(false),
        amp: Some((32767, -32768)),
        ref_delay: Some(0),
        correlated: false,
    },
    SegmentPlan {
        name: "readout, least R (166), ADC following the carrier at full scale, fastest filter",
        cycles: 10000,
        decimation: Some(filter_design::MIN_DECIMATION),
        select: SelectPlan::Fixed(false),
        amp: Some((32767, -32768)),
        ref_delay: None,
        correlated: true,
    },
    SegmentPlan {
        name: "calibration, R = 199, ref_delay 63",
        cycles: 8000,
        decimation: Some(199),
        select: SelectPlan::Fixed(true),
        amp: None,
        ref_delay: Some(63),
        correlated: false,
    },
    SegmentPlan {
        name: "SELECT toggling every 37..900 cycles, random R in 166..=366",
        cycles: 9000,
        decimation: None,
        select: SelectPlan::Toggle { min: 37, max: 900 },
        amp: None,
        ref_delay: None,
        correlated: false,
    },
    SegmentPlan {
        name: "calibration, R = 250, amplitudes (-32768, -32768)",
        cycles: 6000,
        decimation: Some(250),
        select: SelectPlan::Fixed(true),
        amp: Some((-32768, -32768)),
        ref_delay: None,
        correlated: false,
    },
    SegmentPlan {
        name: "readout, R = 1000, amplitudes (-32768, 32767)",
        cycles: 3000,
        decimation: Some(1000),
        select: SelectPlan::Fixed(false),
        amp: Some((-32768, 32767)),
        ref_delay: None,
        correlated: false,
    },
    SegmentPlan {
        name: "SELECT toggling every 1000..3000 cycles, R = 4096",
        cycles: 5000,
        decimation: Some(4096),
        select: SelectPlan::Toggle {
            min: 1000,
            max: 3000,
        },
        amp: None,
        ref_delay: None,
        correlated: false,
    },
];

/// Random valid registers for a segment.
fn registers(rng: &mut Rng, plan: &SegmentPlan) -> Registers {
    let least = filter_design::MIN_DECIMATION as i64;
    let decimation = plan
        .decimation
        .unwrap_or_else(|| rng.range(least, least + 200) as u32);
    let clock_hz = rng.log_uniform(10e6, 125e6);
    let fz = clock_hz / decimation as f64;
    let (lo, hi) = (
        fz * filter_design::MIN_CUTOFF_RATIO,
        fz * filter_design::MAX_CUTOFF_RATIO,
    );
    let filter = (0..1000)
        .find_map(|_| {
            let (butterworth, rc) = if plan.correlated {
                (hi * 0.999, hi * 0.999)
            } else {
                (rng.log_uniform(lo, hi), rng.log_uniform(lo, hi))
            };
            filter_design::design(clock_hz, decimation, butterworth, rc).ok()
        })
        .expect("no valid random filter in 1000 tries");
    let carrier_step = rng.next_u64() as u32;
    let ref_phase = if rng.chance(0.5) {
        carrier_step.div_ceil(2)
    } else {
        rng.next_u64() as u32
    };
    let mod_step = if rng.chance(0.5) {
        rng.next_u64() >> 16 // anywhere in the 48-bit range
    } else {
        rng.next_u64() >> 28 // slow modulation, up to 2^36
    };
    let amp = plan
        .amp
        .unwrap_or_else(|| (rng.next_u64() as i16, rng.next_u64() as i16));
    Registers {
        select: match plan.select {
            SelectPlan::Fixed(s) => s,
            SelectPlan::Toggle { .. } => rng.chance(0.5),
        },
        carrier_step,
        ref_phase,
        ref_delay: plan.ref_delay.unwrap_or_else(|| rng.range(0, 63) as u8),
        mod_step,
        amp,
        cic_decimation: filter.decimation as u16,
        cic_shift: filter.cic_shift as u8,
        iir: filter.coefficients,
    }
}

/// ADC word pattern of a burst.
#[derive(Clone, Copy, Debug)]
enum AdcMode {
    /// Uniform over the whole 16-bit range.
    Random,
    /// A constant pair (full scale and most negative combinations).
    Constant(i16, i16),
    /// 32767 / -32768 alternating every cycle, the channels in anti-phase.
    Square,
    /// Slow sine and cosine, clipped at the rails, with a little noise.
    Sine {
        amplitude: f64,
        period: f64,
        phase: f64,
    },
    /// 33000 cos / sin of the carrier phase plus an offset, clipped at the
    /// rails: correlated with the demodulation references.
    Carrier { phase: f64 },
}

struct AdcSource {
    mode: AdcMode,
    left: i64,
    t: u64,
}

impl AdcSource {
    fn new() -> Self {
        Self {
            mode: AdcMode::Random,
            left: 0,
            t: 0,
        }
    }

    /// Start a new burst at the next cycle.
    fn restart(&mut self) {
        self.left = 0;
    }

    fn pick(&mut self, rng: &mut Rng, correlated: bool) {
        if correlated {
            let phase = rng.unit() * std::f64::consts::TAU;
            (self.mode, self.left) = (AdcMode::Carrier { phase }, rng.range(600, 1000));
            return;
        }
        const RAILS: [(i16, i16); 4] = [
            (i16::MAX, i16::MAX),
            (i16::MIN, i16::MIN),
            (i16::MAX, i16::MIN),
            (i16::MIN, i16::MAX),
        ];
        let u = rng.unit();
        (self.mode, self.left) = if u < 0.25 {
            (AdcMode::Random, rng.range(20, 400))
        } else if u < 0.5 {
            let (a, b) = RAILS[rng.below(4) as usize];
            (AdcMode::Constant(a, b), rng.range(5, 300))
        } else if u < 0.6 {
            (AdcMode::Square, rng.range(10, 200))
        } else {
            let amplitude = if rng.chance(0.3) {
                33000.0 // clips at both rails
            } else {
                rng.log_uniform(100.0, 32767.0)
            };
            let mode = AdcMode::Sine {
                amplitude,
                period: rng.log_uniform(100.0, 5000.0),
                phase: rng.unit() * std::f64::consts::TAU,
            };
            (mode, rng.range(200, 2500))
        };
    }

    fn next(&mut self, rng: &mut Rng, regs: &Registers, correlated: bool) -> (i16, i16) {
        if self.left <= 0 {
            self.pick(rng, correlated);
        }
        self.left -= 1;
        self.t += 1;
        let clip = |x: f64| x.round().clamp(i16::MIN as f64, i16::MAX as f64) as i16;
        match self.mode {
            AdcMode::Random => (rng.next_u64() as i16, rng.next_u64() as i16),
            AdcMode::Constant(a, b) => (a, b),
            AdcMode::Square => {
                if self.t.is_multiple_of(2) {
                    (i16::MAX, i16::MIN)
                } else {
                    (i16::MIN, i16::MAX)
                }
            }
            AdcMode::Sine {
                amplitude,
                period,
                phase,
            } => {
                let w = std::f64::consts::TAU * self.t as f64 / period + phase;
                let noise = |rng: &mut Rng| rng.range(-2, 2) as f64;
                (
                    clip(amplitude * w.sin() + noise(rng)),
                    clip(amplitude * w.cos() + noise(rng)),
                )
            }
            AdcMode::Carrier { phase } => {
                let turns = (regs.carrier_step as u64).wrapping_mul(self.t) & 0xffff_ffff;
                let w = std::f64::consts::TAU * turns as f64 / 4294967296.0 + phase;
                (clip(33000.0 * w.cos()), clip(33000.0 * w.sin()))
            }
        }
    }
}

/// The standard stimulus for `seed`: the segments listed in the module
/// documentation, [`MIN_CYCLES`] cycles or more in total.
pub fn stimulus(seed: u64) -> Stimulus {
    let mut rng = Rng(seed);
    let mut adc = AdcSource::new();
    let mut segments = Vec::new();
    let mut inputs = Vec::new();
    for plan in PLANS {
        let mut regs = registers(&mut rng, plan);
        let mut next_toggle = match plan.select {
            SelectPlan::Toggle { min, max } => rng.range(min, max),
            SelectPlan::Fixed(_) => i64::MAX,
        };
        adc.restart();
        segments.push(Segment {
            name: plan.name.to_owned(),
            start: inputs.len(),
            cycles: plan.cycles,
        });
        for k in 0..plan.cycles as i64 {
            if k == next_toggle {
                regs.select = !regs.select;
                if let SelectPlan::Toggle { min, max } = plan.select {
                    next_toggle += rng.range(min, max);
                }
            }
            inputs.push(Inputs {
                adc: adc.next(&mut rng, &regs, plan.correlated),
                regs,
            });
        }
    }
    Stimulus {
        seed,
        segments,
        inputs,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Longest run of cycles where `f` holds.
    fn longest_run(s: &Stimulus, f: impl Fn(&Inputs) -> bool) -> usize {
        let (mut best, mut run) = (0, 0);
        for i in &s.inputs {
            run = if f(i) { run + 1 } else { 0 };
            best = best.max(run);
        }
        best
    }

    #[test]
    fn standard_stimulus_covers_what_it_claims() {
        let s = stimulus(DEFAULT_SEED);
        assert!(s.inputs.len() >= MIN_CYCLES, "{} cycles", s.inputs.len());
        assert_eq!(
            s.segments.iter().map(|g| g.cycles).sum::<usize>(),
            s.inputs.len()
        );
        let any = |f: &dyn Fn(&Inputs) -> bool| s.inputs.iter().any(f);
        assert!(any(&|i| i.regs.select) && any(&|i| !i.regs.select));
        let toggles = s
            .inputs
            .windows(2)
            .filter(|w| w[0].regs.select != w[1].regs.select)
            .count();
        assert!(toggles >= 6, "{toggles} SELECT toggles");
        let least = filter_design::MIN_DECIMATION as u16;
        for r in [least, 199, 250, 1000, 4096] {
            assert!(any(&|i| i.regs.cic_decimation == r), "R = {r}");
        }
        assert!(any(&|i| !i.regs.cic_decimation.is_power_of_two()));
        for a in [i16::MIN, i16::MAX] {
            assert!(any(&|i| i.regs.amp.0 == a), "amp1 = {a}");
            assert!(any(&|i| i.regs.amp.1 == a), "amp2 = {a}");
        }
        assert!(any(&|i| i.regs.ref_delay == 0) && any(&|i| i.regs.ref_delay == 63));
        for v in [i16::MIN, i16::MAX] {
            assert!(
                longest_run(&s, |i| i.adc.0 == v) >= 20,
                "burst of adc1 = {v}"
            );
            assert!(
                longest_run(&s, |i| i.adc.1 == v) >= 20,
                "burst of adc2 = {v}"
            );
        }
        // Slow sines: long runs of small steps that are not constant.
        let slow = longest_run(&s, |i| {
            i.adc.0 != i16::MIN && i.adc.0 != i16::MAX && i.adc.0.unsigned_abs() < 32000
        });
        assert!(slow >= 200, "no slow sine ({slow})");
        for i in &s.inputs {
            let r = i.regs;
            assert!((least..=4096).contains(&r.cic_decimation));
            assert_eq!(
                r.cic_shift as u32,
                filter_design::cic_bit_growth(r.cic_decimation as u32) - 8
            );
            assert!(r.ref_delay < 64 && r.mod_step < 1 << 48);
        }
    }

    #[test]
    fn stimulus_is_reproducible() {
        let (a, b) = (stimulus(7), stimulus(7));
        assert_eq!(a.inputs, b.inputs);
        assert_ne!(a.inputs, stimulus(8).inputs);
    }

    #[test]
    fn hex_records_hold_every_port_at_its_width() {
        let s = Stimulus {
            seed: 0,
            segments: vec![],
            inputs: stimulus(1).inputs[..3].to_vec(),
        };
        let mut v = record(&s);
        v.cycles[1].expected.z = (-1, (1 << 39) - 1);
        v.cycles[1].expected.dac = (i16::MIN, -2);
        let text = v.to_hex();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "3");
        let n_out = output_ports().count();
        assert_eq!(lines[1].split(' ').count(), n_out);
        let fields: Vec<&str> = lines[3].split(' ').collect();
        assert_eq!(fields.len(), input_ports().count() + n_out);
        let widths: Vec<usize> = input_ports()
            .chain(output_ports())
            .map(|p| p.bits.div_ceil(4))
            .collect();
        assert_eq!(fields.iter().map(|f| f.len()).collect::<Vec<_>>(), widths);
        let out = &fields[input_ports().count()..];
        assert_eq!(out, ["8000", "fffe", "ffffffffff", "7fffffffff", "0"]);
    }
}
