//! Pipelined signed multiplier: `p = a * b`, exact, 4 clocks, built from
//! eight partial products no wider than 17 x 17 bits.
//!
//! ```text
//!  a = a3 2^48 + a2 2^32 + a1 2^16 + a0    (a0..a2: 16-bit unsigned chunks, a3: signed top, A - 48 bits)
//!  b =                     b1 2^16 + b0    (b0: 16-bit unsigned chunk, b1: signed top, B - 16 bits)
//!
//!  clock 1   pp_ij = a_i b_j                      8 products, <= 17 x 17 bits (one DSP each)
//!  clock 2   row_i = pp_i0 + pp_i1 2^16  = a_i b   4 adders, 17 + B bits
//!  clock 3   pair_0 = row_0 + row_1 2^16 = (a mod 2^32) b      33 + B bits
//!            pair_1 = row_2 + row_3 2^16 = (a div 2^32) b      A - 32 + B bits
//!  clock 4   p = pair_0 + pair_1 2^32    = a b                 A + B bits
//! ```
//!
//! Each register stage holds at most one carry chain, so the product no
//! longer limits the clock: the widest stage is the last, one (A + B)-bit
//! adder. Every partial product fits one 18 x 18 ECP5 `MULT18X18D` (the
//! unsigned chunks are 17-bit signed words with a zero sign bit) and, after
//! Yosys narrows the zero sign bits, one iCE40 `SB_MAC16`. Every stage is
//! exact (its width is the width of the integer product it holds), so
//! nothing can overflow; `new()` checks the shape (A in 49..=64, B in
//! 17..=32, P = A + B).
//!
//! Leaf with hand-written Verilog (not single-source): the golden-vector
//! replay of the whole design in Icarus and Verilator covers it.
//!
//! Latency: `p` during cycle n is the product of `a` and `b` during cycle
//! n - 4. Power-up: every stage 0 (Verilog `initial`).

use super::convert::{i128_to_signed, signed_to_i128};
use rust_hdl::prelude::*;

/// Bits of an unsigned chunk.
pub const CHUNK_BITS: usize = 16;
/// Clocks from the factors to their product.
pub const LATENCY: usize = 4;

/// `p` = `a * b` four clocks later; `P` must equal `A + B`.
#[derive(Clone, Debug, LogicBlock)]
pub struct PipelinedMultiplier<const A: usize, const B: usize, const P: usize> {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// First factor, two's complement, 49..=64 bits.
    pub a: Signal<In, Signed<A>>,
    /// Second factor, two's complement, 17..=32 bits.
    pub b: Signal<In, Signed<B>>,
    /// Product of the factors present four rising edges earlier.
    pub p: Signal<Out, Signed<P>>,
    /// Products in flight: the values of the three internal stages.
    _stages: Vec<Signed<P>>,
}

impl<const A: usize, const B: usize, const P: usize> PipelinedMultiplier<A, B, P> {
    /// A multiplier; panics at construction unless A is 49..=64, B is
    /// 17..=32 and P = A + B (four chunks of `a`, two of `b`).
    pub fn new() -> Self {
        assert!(
            (3 * CHUNK_BITS + 1..=4 * CHUNK_BITS).contains(&A),
            "PipelinedMultiplier needs a 49..=64-bit first factor"
        );
        assert!(
            (CHUNK_BITS + 1..=2 * CHUNK_BITS).contains(&B),
            "PipelinedMultiplier needs a 17..=32-bit second factor"
        );
        assert_eq!(P, A + B, "PipelinedMultiplier needs P = A + B");
        Self {
            clock: Default::default(),
            a: Default::default(),
            b: Default::default(),
            p: Signal::new_with_default(Signed::default()),
            _stages: vec![Signed::default(); LATENCY - 1],
        }
    }
}

impl<const A: usize, const B: usize, const P: usize> Default for PipelinedMultiplier<A, B, P> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const A: usize, const B: usize, const P: usize> Logic for PipelinedMultiplier<A, B, P> {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let product = signed_to_i128(self.a.val()) * signed_to_i128(self.b.val());
            self.p.next = self._stages[LATENCY - 2];
            self._stages.rotate_right(1);
            self._stages[0] = i128_to_signed::<P>(product);
        }
    }

    fn connect(&mut self) {
        self.p.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(verilog(A, B))
    }

    fn timing(&self) -> Vec<TimingInfo> {
        vec![TimingInfo {
            name: "pipelined_multiplier".into(),
            clock: "clock".into(),
            inputs: vec!["a".into(), "b".into()],
            outputs: vec!["p".into()],
        }]
    }
}

/// `name` (a signed `from`-bit word) sign-extended to `to` bits, as a
/// concatenation (so no operand of the adders below changes width).
fn extend(name: &str, from: usize, to: usize) -> String {
    if from == to {
        return name.to_string();
    }
    format!("{{{{{}{{{name}[{}]}}}}, {name}}}", to - from, from - 1)
}

/// `name` (a signed `from`-bit word) times 2^shift, sign-extended to `to` bits.
fn extend_shifted(name: &str, from: usize, shift: usize, to: usize) -> String {
    format!("{{{}, {shift}'d0}}", extend(name, from, to - shift))
}

/// The Verilog body for an `a_bits` x `b_bits` multiplier.
fn verilog(a_bits: usize, b_bits: usize) -> String {
    let c = CHUNK_BITS;
    // Chunk widths as signed words: unsigned chunks get a zero sign bit.
    let a_width = [c + 1, c + 1, c + 1, a_bits - 3 * c];
    let b_width = [c + 1, b_bits - c];
    // Exact widths: row_i = a_i b, pair_0 = (a mod 2^32) b, pair_1 = (a div 2^32) b.
    let row_width: Vec<usize> = a_width.iter().map(|w| w + b_bits).collect();
    let pair_width = [2 * c + 1 + b_bits, a_bits - 2 * c + b_bits];
    let p_width = a_bits + b_bits;
    let mut text = String::new();
    let mut line = |s: String| {
        text.push_str(&s);
        text.push('\n');
    };
    for (i, w) in a_width.iter().enumerate() {
        let source = if i < 3 {
            format!("{{1'b0, a[{}:{}]}}", c * (i + 1) - 1, c * i)
        } else {
            format!("a[{}:{}]", a_bits - 1, 3 * c)
        };
        line(format!("wire signed [{}:0] a_{i} = {source};", w - 1));
    }
    line(format!(
        "wire signed [{c}:0] b_0 = {{1'b0, b[{}:0]}};",
        c - 1
    ));
    line(format!(
        "wire signed [{}:0] b_1 = b[{}:{c}];",
        b_width[1] - 1,
        b_bits - 1
    ));
    let declare = |line: &mut dyn FnMut(String), name: String, width: usize| {
        line(format!("reg signed [{}:0] {name};", width - 1));
        line(format!("initial {name} = 0;"));
    };
    for (i, wa) in a_width.iter().enumerate() {
        for (j, wb) in b_width.iter().enumerate() {
            declare(&mut line, format!("pp_{i}_{j}"), wa + wb);
        }
        declare(&mut line, format!("row_{i}"), row_width[i]);
    }
    for (k, w) in pair_width.iter().enumerate() {
        declare(&mut line, format!("pair_{k}"), *w);
    }
    line("initial p = 0;\n\nalways @(posedge clock) begin".into());
    for i in 0..a_width.len() {
        for j in 0..b_width.len() {
            line(format!("   pp_{i}_{j} <= a_{i} * b_{j};"));
        }
    }
    for (i, wa) in a_width.iter().enumerate() {
        let low = extend(&format!("pp_{i}_0"), wa + b_width[0], row_width[i]);
        let high = extend_shifted(&format!("pp_{i}_1"), wa + b_width[1], c, row_width[i]);
        line(format!("   row_{i} <= {low} + {high};"));
    }
    for k in 0..2 {
        let low = extend(&format!("row_{}", 2 * k), row_width[2 * k], pair_width[k]);
        let high = extend_shifted(
            &format!("row_{}", 2 * k + 1),
            row_width[2 * k + 1],
            c,
            pair_width[k],
        );
        line(format!("   pair_{k} <= {low} + {high};"));
    }
    let low = extend("pair_0", pair_width[0], p_width);
    let high = extend_shifted("pair_1", pair_width[1], 2 * c, p_width);
    line(format!("   p <= {low} + {high};"));
    text.push_str("end");
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::primitives::convert::{i128_to_signed, signed_to_i128};
    use crate::test_util::Rng;

    #[derive(LogicBlock)]
    struct Harness {
        clock: Signal<In, Clock>,
        a: Signal<In, Signed<60>>,
        b: Signal<In, Signed<32>>,
        mul: PipelinedMultiplier<60, 32, 92>,
    }

    impl Logic for Harness {
        #[hdl_gen]
        fn update(&mut self) {
            self.mul.clock.next = self.clock.val();
            self.mul.a.next = self.a.val();
            self.mul.b.next = self.b.val();
        }
    }
    crate::impl_clocked!(Harness);

    #[test]
    fn products_come_out_four_clocks_later_exact_at_the_extremes() {
        let mut h = Harness {
            clock: Default::default(),
            a: Default::default(),
            b: Default::default(),
            mul: PipelinedMultiplier::new(),
        };
        prepare(&mut h);
        let mut rng = Rng::new(5);
        let extremes = [
            (-(1i128 << 59), -(1i128 << 31)),
            ((1 << 59) - 1, (1 << 31) - 1),
            (-(1 << 59), (1 << 31) - 1),
            (-1, -1),
            (0, 0),
        ];
        let mut factors: Vec<(i128, i128)> = extremes.to_vec();
        factors.extend((0..200).map(|_| {
            let a = rng.range(-(1 << 59), (1 << 59) - 1) as i128;
            (a, rng.range(-(1 << 31), (1 << 31) - 1) as i128)
        }));
        for (n, &(a, b)) in factors.iter().enumerate() {
            h.a.next = i128_to_signed(a);
            h.b.next = i128_to_signed(b);
            tick(&mut h);
            if n >= LATENCY {
                let (x, y) = factors[n + 1 - LATENCY];
                assert_eq!(signed_to_i128(h.mul.p.val()), x * y, "cycle {n}");
            }
        }
    }

    #[test]
    fn verilog_slices_cover_every_bit_once() {
        let v = verilog(60, 32);
        for s in [
            "a_0 = {1'b0, a[15:0]}",
            "a_3 = a[59:48]",
            "b_1 = b[31:16]",
            "reg signed [33:0] pp_0_0",
            "reg signed [27:0] pp_3_1",
            "reg signed [64:0] pair_0",
            "reg signed [59:0] pair_1",
            "p <= {{27{pair_0[64]}}, pair_0} + {pair_1, 32'd0};",
        ] {
            assert!(v.contains(s), "missing `{s}` in\n{v}");
        }
    }
}

#[cfg(test)]
mod verilog_tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::test_util::Rng;

    crate::impl_clocked!(PipelinedMultiplier<60, 32, 92>);

    /// The generated Verilog (chunks, partial products, adders) against
    /// the model's exact product, clock by clock, on random factors over
    /// their whole range with the rails among them: every chunk's top bit
    /// is set in some of them, which the design's own traffic (the IIR's
    /// states, far below 2^47) never does.
    #[test]
    fn the_verilog_matches_the_model_over_the_whole_range() {
        let mut mul = PipelinedMultiplier::<60, 32, 92>::new();
        prepare(&mut mul);
        let mut rng = Rng::new(17);
        let sext = |v: u64, bits: u32| ((v << (64 - bits)) as i64 >> (64 - bits)) as i128;
        let rails = [sext(1 << 59, 60), (1i128 << 59) - 1, -1, 0, 1];
        let mut expected = vec![];
        let mut steps = vec![];
        for n in 0..400 {
            let r = rng.next_u64();
            let a = if n < 25 { rails[n % 5] } else { sext(r, 60) };
            let b = if n < 25 {
                rails[n / 5] >> 28
            } else {
                sext(rng.next_u64(), 32)
            };
            mul.a.next = i128_to_signed(a);
            mul.b.next = i128_to_signed(b);
            tick(&mut mul);
            expected.push(signed_to_i128(mul.p.val()).to_string());
            steps.push(format!(
                "a = 60'h{:015x}; b = 32'h{:08x};",
                a as u64 & ((1 << 60) - 1),
                b as u64 & 0xffff_ffff
            ));
        }
        let got = crate::test_util::icarus_clocked(
            &generate_verilog(&mul),
            &[("a", 60, true), ("b", 32, true)],
            ("p", 92),
            &steps,
        );
        assert_eq!(got.len(), expected.len());
        // The pipeline's registers have no power-up value in the Verilog.
        for (n, (g, e)) in got.iter().zip(&expected).enumerate().skip(LATENCY) {
            assert_eq!(g, e, "edge {n}");
        }
    }
}
