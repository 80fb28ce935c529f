//! Helpers shared by the blocks' tests: a seeded generator and the stimulus
//! shapes every DSP block is tried with.

/// SplitMix64: small, seedable, good enough for test stimulus.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator with the given seed.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `lo..=hi`.
    pub fn range(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next_u64() % ((hi - lo) as u64 + 1)) as i64
    }

    /// A 16-bit word biased toward the extremes: a quarter of the draws are
    /// -32768, -32767, 32767 or 0, the rest uniform.
    pub fn word16(&mut self) -> i16 {
        match self.next_u64() % 16 {
            0 => i16::MIN,
            1 => -32767,
            2 => i16::MAX,
            3 => 0,
            _ => self.next_u64() as i16,
        }
    }
}

use proptest::prelude::*;

/// A 16-bit word, a quarter of the time one of the extremes (-32768,
/// -32767, 32767, 0).
pub fn word16() -> impl Strategy<Value = i16> {
    prop_oneof![
        1 => Just(i16::MIN),
        1 => Just(-32767i16),
        1 => Just(i16::MAX),
        1 => Just(0i16),
        12 => any::<i16>(),
    ]
}

/// A 16-bit word within +-32767 (sine, cosine and modulation outputs),
/// biased toward the extremes.
pub fn sample16() -> impl Strategy<Value = i16> {
    word16().prop_map(|w| w.max(-32767))
}

/// Segments of a stimulus: `(value, length)` pairs expanded into one value
/// per clock, so settings stay put for a while and then change.
pub fn segments<T: Clone + std::fmt::Debug>(
    value: impl Strategy<Value = T>,
    segments: std::ops::Range<usize>,
    length: std::ops::Range<usize>,
) -> impl Strategy<Value = Vec<T>> {
    prop::collection::vec((value, length), segments).prop_map(|s| {
        s.into_iter()
            .flat_map(|(v, n)| std::iter::repeat_n(v, n))
            .collect()
    })
}

use rustfft::{FftPlanner, num_complex::Complex};

/// Modified Bessel function I0 by its power series (converges fast for
/// the arguments of a Kaiser window).
fn bessel_i0(x: f64) -> f64 {
    let (mut sum, mut term, mut k) = (1.0, 1.0, 1.0);
    while term > 1e-17 * sum {
        term *= (x / (2.0 * k)).powi(2);
        sum += term;
        k += 1.0;
    }
    sum
}

/// Spur-free dynamic range in dBc of a real sequence: carrier power over
/// the largest bin outside the carrier's main lobe. Kaiser window with
/// beta = 25: side lobes near -190 dB, main lobe within +-9 bins, so
/// the window itself cannot produce a spur above the -80 dBc level
/// asserted here.
pub fn sfdr_dbc(x: &[f64]) -> f64 {
    let n = x.len();
    let beta = 25.0;
    let mut buf: Vec<Complex<f64>> = x
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let r = 2.0 * i as f64 / (n - 1) as f64 - 1.0;
            Complex::new(
                v * bessel_i0(beta * (1.0 - r * r).sqrt()) / bessel_i0(beta),
                0.0,
            )
        })
        .collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let power: Vec<f64> = buf[..n / 2].iter().map(|c| c.norm_sqr()).collect();
    let peak = (0..n / 2)
        .max_by(|&a, &b| power[a].total_cmp(&power[b]))
        .unwrap();
    let spur = (0..n / 2)
        .filter(|&k| k.abs_diff(peak) > 20)
        .map(|k| power[k])
        .fold(0.0, f64::max);
    10.0 * (power[peak] / spur).log10()
}

/// Run a leaf block's Verilog (`generate_verilog` of it: module `top`) in
/// Icarus under `testbench` (a module `tb` that instantiates `top` and
/// `$display`s), and return the lines it printed. The hand-written Verilog
/// of a primitive is checked this way against its own Rust model, on
/// traffic the whole design never makes (`tests/verilog_replay.rs` replays
/// only the design's). Needs `iverilog` and `vvp` (scripts/test.sh installs
/// them).
pub fn icarus_lines(design: &str, testbench: &str) -> Vec<String> {
    use std::process::Command;
    let dir = std::env::temp_dir().join(format!(
        "gyrocal-icarus-{}-{}",
        std::process::id(),
        Rng::new(design.len() as u64 ^ testbench.len() as u64).next_u64()
    ));
    std::fs::create_dir_all(&dir).expect("a scratch folder");
    let (v, out) = (dir.join("top.v"), dir.join("top.vvp"));
    std::fs::write(&v, format!("{design}\n{testbench}\n")).expect("write the Verilog");
    let compile = Command::new("iverilog")
        .args(["-g2012", "-s", "tb", "-o"])
        .arg(&out)
        .arg(&v)
        .output()
        .expect("iverilog not found: install the Debian package iverilog (scripts/test.sh does)");
    assert!(
        compile.status.success(),
        "iverilog: {}",
        String::from_utf8_lossy(&compile.stderr)
    );
    let run = Command::new("vvp")
        .arg("-n")
        .arg(&out)
        .output()
        .expect("vvp");
    assert!(
        run.status.success(),
        "vvp: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
    String::from_utf8_lossy(&run.stdout)
        .lines()
        .filter(|l| !l.starts_with("VCD") && !l.is_empty())
        .map(String::from)
        .collect()
}

/// [`icarus_lines`] under a clocked testbench `tb` for a leaf block's
/// `top`: `inputs` are its input registers (name, width, signed) besides
/// `clock`, `output` its output (name, width), printed signed in decimal.
/// Each of `steps` (Verilog assignments to the inputs) is applied with the
/// clock low, then a rising edge, then the output is printed: one line a
/// step, as the block's Rust model reads after `drive::tick`.
pub fn icarus_clocked(
    design: &str,
    inputs: &[(&str, usize, bool)],
    output: (&str, usize),
    steps: &[String],
) -> Vec<String> {
    let range = |w: usize| {
        if w == 1 {
            String::new()
        } else {
            format!(" [{}:0]", w - 1)
        }
    };
    let mut tb = String::from("module tb;\n   reg clock = 0;\n");
    let mut ports = vec![".clock(clock)".to_string()];
    for &(name, width, signed) in inputs {
        let sign = if signed { " signed" } else { "" };
        tb += &format!("   reg{sign}{} {name} = 0;\n", range(width));
        ports.push(format!(".{name}({name})"));
    }
    let (out, width) = output;
    tb += &format!("   wire signed{} {out};\n", range(width));
    ports.push(format!(".{out}({out})"));
    tb += &format!("   top uut({});\n   initial begin\n", ports.join(", "));
    for step in steps {
        tb += &format!("      {step} #1 clock = 1; #1 $display(\"%0d\", {out}); clock = 0; #1;\n");
    }
    tb += "   end\nendmodule";
    icarus_lines(design, &tb)
}
