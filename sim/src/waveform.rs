//! Waveform dumps (VCD, for GTKWave) of one co-simulated point: a window of
//! clocks and a selection of signals, never everything.
//!
//! Signals: the ports of `gyro_interface` (`clock`, `adc1`, `adc2`, `dac1`,
//! `dac2`, `z1`, `z2`, `z_valid`, `select`), the main internal ones
//! (`ref1`, `ref2`: reference words; `am1`, `am2`: modulation factors;
//! `w1`, `w2`: mixer products; `cic1`, `cic2`, `cic_valid`: CIC outputs)
//! and the gyroscope's displacements `x1_pm`, `x2_pm` (real, picometres).
//! Groups:
//! `ports`, `internals`, `analog`, `all`. Time: rising edge n at n clock
//! periods (1 ps resolution); inputs change at the falling edge before the
//! rising edge that captures them. Values are written only when they
//! change.

use crate::experiment::{ClockView, Observer};
use std::io::Write;
use std::ops::Range;
use vcd::{IdCode, TimescaleUnit, Value, VarType};

/// Longest window a dump may cover, in clocks (a few hundred MB of VCD).
pub const MAX_WINDOW: u64 = 2_000_000;

/// A dumpable signal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Probe {
    /// The clock.
    Clock,
    /// ADC word 1.
    Adc1,
    /// ADC word 2.
    Adc2,
    /// DAC word 1.
    Dac1,
    /// DAC word 2.
    Dac2,
    /// Output z1.
    Z1,
    /// Output z2.
    Z2,
    /// z strobe.
    ZValid,
    /// SELECT.
    Select,
    /// Reference word 1.
    Ref1,
    /// Reference word 2.
    Ref2,
    /// Modulation factor A1.
    Am1,
    /// Modulation factor A2.
    Am2,
    /// Mixer product 1.
    W1,
    /// Mixer product 2.
    W2,
    /// CIC output 1.
    Cic1,
    /// CIC output 2.
    Cic2,
    /// CIC strobe.
    CicValid,
    /// Displacement of mode 1 (pm).
    X1,
    /// Displacement of mode 2 (pm).
    X2,
}

use Probe::*;

const PORTS: [Probe; 9] = [Clock, Adc1, Adc2, Dac1, Dac2, Z1, Z2, ZValid, Select];
const INTERNALS: [Probe; 9] = [Ref1, Ref2, Am1, Am2, W1, W2, Cic1, Cic2, CicValid];
const ANALOG: [Probe; 2] = [X1, X2];

impl Probe {
    /// Name in the VCD and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Clock => "clock",
            Adc1 => "adc1",
            Adc2 => "adc2",
            Dac1 => "dac1",
            Dac2 => "dac2",
            Z1 => "z1",
            Z2 => "z2",
            ZValid => "z_valid",
            Select => "select",
            Ref1 => "ref1",
            Ref2 => "ref2",
            Am1 => "am1",
            Am2 => "am2",
            W1 => "w1",
            W2 => "w2",
            Cic1 => "cic1",
            Cic2 => "cic2",
            CicValid => "cic_valid",
            X1 => "x1_pm",
            X2 => "x2_pm",
        }
    }

    /// Width in bits (0 for real-valued).
    pub fn bits(self) -> u32 {
        match self {
            Clock | ZValid | Select | CicValid => 1,
            Adc1 | Adc2 | Dac1 | Dac2 | Ref1 | Ref2 | Am1 | Am2 => 16,
            W1 | W2 => 32,
            Z1 | Z2 | Cic1 | Cic2 => 40,
            X1 | X2 => 0,
        }
    }

    fn all() -> impl Iterator<Item = Probe> {
        PORTS.into_iter().chain(INTERNALS).chain(ANALOG)
    }

    /// Parse a comma-separated list of names and groups.
    pub fn parse_list(list: &str) -> Result<Vec<Probe>, ProbeError> {
        let mut out: Vec<Probe> = vec![];
        for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let add: Vec<Probe> = match item {
                "all" => Probe::all().collect(),
                "ports" => PORTS.to_vec(),
                "internals" => INTERNALS.to_vec(),
                "analog" => ANALOG.to_vec(),
                name => match Probe::all().find(|p| p.name() == name) {
                    Some(p) => vec![p],
                    None => return Err(ProbeError::UnknownSignal(name.into())),
                },
            };
            for p in add {
                if !out.contains(&p) {
                    out.push(p);
                }
            }
        }
        if out.is_empty() {
            return Err(ProbeError::Empty);
        }
        Ok(out)
    }
}

/// What the waveform's options (`--vcd-signals`, `--vcd-cycles`) refuse:
/// one line naming the option.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ProbeError {
    /// A name that is no signal or group.
    #[error("--vcd-signals: unknown signal {0:?}; allowed: all, ports, internals, analog, {names}", names = signal_names())]
    UnknownSignal(String),
    /// A list that names nothing.
    #[error("--vcd-signals: empty selection")]
    Empty,
    /// A window that is not `START:END` within the limit (the text).
    #[error(
        "--vcd-cycles {0:?}: expected START:END in clocks with START < END and END - START <= {MAX_WINDOW}"
    )]
    Window(String),
}

/// Every signal's name, comma-separated.
fn signal_names() -> String {
    Probe::all().map(Probe::name).collect::<Vec<_>>().join(", ")
}

/// Parse `START:END` (clocks, END exclusive).
pub fn parse_window(text: &str) -> Result<Range<u64>, ProbeError> {
    let bad = || ProbeError::Window(text.into());
    let (a, b) = text.split_once(':').ok_or_else(bad)?;
    let (a, b): (u64, u64) = (
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    );
    if a >= b || b - a > MAX_WINDOW {
        return Err(bad());
    }
    Ok(a..b)
}

fn bits_of(v: i64, width: u32) -> impl Iterator<Item = Value> {
    (0..width).rev().map(move |i| {
        if (v >> i) & 1 == 1 {
            Value::V1
        } else {
            Value::V0
        }
    })
}

/// Writes a VCD while observing a run.
pub struct VcdRecorder<W: Write> {
    writer: vcd::Writer<W>,
    window: Range<u64>,
    probes: Vec<(Probe, IdCode)>,
    last: Vec<Option<i64>>,
    last_real: Vec<Option<f64>>,
    period_ps: u64,
    error: Option<std::io::Error>,
}

impl<W: Write> VcdRecorder<W> {
    /// Start a dump: writes the header.
    pub fn new(
        out: W,
        window: Range<u64>,
        probes: &[Probe],
        clock_hz: f64,
        comment: &str,
    ) -> std::io::Result<Self> {
        let mut writer = vcd::Writer::new(out);
        writer.comment(comment)?;
        writer.timescale(1, TimescaleUnit::PS)?;
        writer.add_module("gyro_interface")?;
        let mut ids = vec![];
        for &p in probes {
            let id = if p.bits() == 0 {
                writer.add_var(VarType::Real, 64, p.name(), None)?
            } else {
                writer.add_wire(p.bits(), p.name())?
            };
            ids.push((p, id));
        }
        writer.upscope()?;
        writer.enddefinitions()?;
        Ok(Self {
            writer,
            window,
            last: vec![None; ids.len()],
            last_real: vec![None; ids.len()],
            probes: ids,
            period_ps: (1e12 / clock_hz).round() as u64,
            error: None,
        })
    }

    /// Finish the dump: flush, and return the first write error, if any.
    pub fn finish(mut self) -> std::io::Result<()> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        self.writer.flush()
    }

    fn value(p: Probe, v: &ClockView) -> i64 {
        let o = v.outputs;
        let q = v.probes;
        match p {
            Clock => 1,
            Adc1 => v.adc.0 as i64,
            Adc2 => v.adc.1 as i64,
            Dac1 => o.dac.0 as i64,
            Dac2 => o.dac.1 as i64,
            Z1 => o.z.0,
            Z2 => o.z.1,
            ZValid => o.z_valid as i64,
            Select => v.select as i64,
            Ref1 => q.reference.0 as i64,
            Ref2 => q.reference.1 as i64,
            Am1 => q.am.0 as i64,
            Am2 => q.am.1 as i64,
            W1 => q.w.0 as i64,
            W2 => q.w.1 as i64,
            Cic1 => q.cic.0,
            Cic2 => q.cic.1,
            CicValid => q.cic_valid as i64,
            X1 | X2 => 0,
        }
    }

    fn record(&mut self, v: &ClockView) -> std::io::Result<()> {
        let edge = v.cycle * self.period_ps;
        let falling = edge - self.period_ps / 2;
        // Inputs change at the falling edge before the rising edge.
        self.writer.timestamp(falling)?;
        for (k, &(p, id)) in self.probes.iter().enumerate() {
            let value = match p {
                Clock => 0,
                Adc1 | Adc2 | Select => Self::value(p, v),
                _ => continue,
            };
            if self.last[k] != Some(value) {
                self.writer.change_vector(id, bits_of(value, p.bits()))?;
                self.last[k] = Some(value);
            }
        }
        self.writer.timestamp(edge)?;
        for (k, &(p, id)) in self.probes.iter().enumerate() {
            match p {
                Adc1 | Adc2 | Select => {}
                X1 | X2 => {
                    let x = 1e12 * if p == X1 { v.x.0 } else { v.x.1 };
                    if self.last_real[k] != Some(x) {
                        self.writer.change_real(id, x)?;
                        self.last_real[k] = Some(x);
                    }
                }
                _ => {
                    let value = Self::value(p, v);
                    if self.last[k] != Some(value) {
                        self.writer.change_vector(id, bits_of(value, p.bits()))?;
                        self.last[k] = Some(value);
                    }
                }
            }
        }
        Ok(())
    }
}

impl<W: Write> Observer for VcdRecorder<W> {
    fn clock(&mut self, view: &ClockView) {
        if self.error.is_none()
            && self.window.contains(&view.cycle)
            && let Err(e) = self.record(view)
        {
            self.error = Some(e);
        }
    }

    fn last_cycle(&self) -> u64 {
        self.window.end
    }
}
