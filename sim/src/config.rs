//! The TOML description of a user's device and experiment.
//!
//! Every key has a default: the paper's device (`Experiment::paper()`),
//! except that the carrier follows `[gyro] f1_hz` when it is not given
//! (excitation at mode 1). Unknown keys, values of the wrong type, and
//! values out of range are rejected with one line naming the section, the
//! key and what is allowed.
//!
//! ```toml
//! [gyro]        # f1_hz, f2_hz, q1, q2, angular_gain
//! [drive]       # carrier_hz, clock_hz, amplitude1, amplitude2,
//!               # force_full_scale1_n_per_kg, force_full_scale2_n_per_kg
//! [frontend]    # dac_latency, adc_latency, dac_bits, adc_bits, adc_headroom,
//!               # adc_per_meter1, adc_per_meter2, noise_lsb, seed
//! [filter]      # decimation, butterworth_hz, rc_hz
//! [experiment]  # readout_rates_dps, cal_freqs_hz, tolerance, min_window_s
//! ```

use crate::experiment::Experiment;
use serde::Deserialize;

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct File {
    #[serde(default)]
    gyro: Gyro,
    #[serde(default)]
    drive: Drive,
    #[serde(default)]
    frontend: Frontend,
    #[serde(default)]
    filter: Filter,
    #[serde(default)]
    experiment: Points,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct Gyro {
    f1_hz: Option<f64>,
    f2_hz: Option<f64>,
    q1: Option<f64>,
    q2: Option<f64>,
    angular_gain: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct Drive {
    carrier_hz: Option<f64>,
    clock_hz: Option<f64>,
    amplitude1: Option<f64>,
    amplitude2: Option<f64>,
    force_full_scale1_n_per_kg: Option<f64>,
    force_full_scale2_n_per_kg: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct Frontend {
    dac_latency: Option<u32>,
    adc_latency: Option<u32>,
    dac_bits: Option<u32>,
    adc_bits: Option<u32>,
    adc_headroom: Option<f64>,
    adc_per_meter1: Option<f64>,
    adc_per_meter2: Option<f64>,
    noise_lsb: Option<f64>,
    seed: Option<u64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct Filter {
    decimation: Option<u32>,
    butterworth_hz: Option<f64>,
    rc_hz: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct Points {
    readout_rates_dps: Option<Vec<f64>>,
    cal_freqs_hz: Option<Vec<f64>>,
    tolerance: Option<f64>,
    min_window_s: Option<f64>,
}

/// A numeric key with its range check.
fn check(section: &str, key: &str, value: f64, ok: bool, allowed: &str) -> Result<(), String> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(format!("[{section}] {key} = {value}: {allowed}"))
    }
}

/// The section a byte offset of `text` falls in.
fn section_at(text: &str, offset: usize) -> Option<String> {
    text[..offset.min(text.len())]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('[') && l.ends_with(']'))
        .map(|l| l.to_owned())
}

/// One line from a TOML or schema error: position, section, message.
fn parse_error(name: &str, text: &str, e: toml::de::Error) -> String {
    let message = e.message().replace('\n', " ");
    match e.span() {
        Some(span) => {
            let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
            let at = match section_at(text, span.start) {
                Some(s) => format!(" in {s}"),
                None => String::new(),
            };
            format!("{name} line {line}{at}: {message}")
        }
        None => format!("{name}: {message}"),
    }
}

/// Parse a configuration file's text into an experiment, checking every
/// key. `name` labels error messages (usually the file path).
pub fn parse(name: &str, text: &str) -> Result<Experiment, String> {
    let file: File = toml::from_str(text).map_err(|e| parse_error(name, text, e))?;
    let mut e = Experiment::paper();
    let g = file.gyro;
    e.gyro.f1_hz = g.f1_hz.unwrap_or(e.gyro.f1_hz);
    e.gyro.f2_hz = g.f2_hz.unwrap_or(e.gyro.f2_hz);
    e.gyro.q1 = g.q1.unwrap_or(e.gyro.q1);
    e.gyro.q2 = g.q2.unwrap_or(e.gyro.q2);
    e.gyro.angular_gain = g.angular_gain.unwrap_or(e.gyro.angular_gain);
    let d = file.drive;
    e.clock_hz = d.clock_hz.unwrap_or(e.clock_hz);
    e.carrier_hz = d.carrier_hz.unwrap_or(e.gyro.f1_hz);
    e.amplitude = (
        d.amplitude1.unwrap_or(e.amplitude.0),
        d.amplitude2.unwrap_or(e.amplitude.1),
    );
    e.force_full_scale = [
        d.force_full_scale1_n_per_kg
            .unwrap_or(e.force_full_scale[0]),
        d.force_full_scale2_n_per_kg
            .unwrap_or(e.force_full_scale[1]),
    ];
    let f = file.frontend;
    e.dac_latency = f.dac_latency.unwrap_or(e.dac_latency);
    e.adc_latency = f.adc_latency.unwrap_or(e.adc_latency);
    e.dac_bits = f.dac_bits.unwrap_or(e.dac_bits);
    e.adc_bits = f.adc_bits.unwrap_or(e.adc_bits);
    e.adc_headroom = f.adc_headroom.unwrap_or(e.adc_headroom);
    e.adc_per_meter = match (f.adc_per_meter1, f.adc_per_meter2) {
        (None, None) => None,
        (Some(a), Some(b)) => Some([a, b]),
        _ => {
            return Err(
                "[frontend] adc_per_meter1 and adc_per_meter2: give both or neither (neither: set from adc_headroom)"
                    .into(),
            );
        }
    };
    e.noise_lsb = f.noise_lsb.unwrap_or(e.noise_lsb);
    e.seed = f.seed.unwrap_or(e.seed);
    let fl = file.filter;
    e.decimation = fl.decimation.unwrap_or(e.decimation);
    e.butterworth_hz = fl.butterworth_hz.unwrap_or(e.butterworth_hz);
    e.rc_hz = fl.rc_hz.unwrap_or(e.rc_hz);
    let p = file.experiment;
    if let Some(r) = p.readout_rates_dps {
        e.readout_rates_dps = r;
    }
    if let Some(c) = p.cal_freqs_hz {
        e.cal_freqs_hz = c;
    }
    e.tolerance = p.tolerance.unwrap_or(e.tolerance);
    e.min_window_s = p.min_window_s.unwrap_or(e.min_window_s);
    validate(&e)?;
    Ok(e)
}

/// Range checks with section-qualified names; `experiment::plan` repeats
/// the ones it depends on.
pub fn validate(e: &Experiment) -> Result<(), String> {
    let positive = "must be a positive number";
    check("drive", "clock_hz", e.clock_hz, e.clock_hz > 0.0, positive)?;
    let nyquist = e.clock_hz / 2.0;
    let below = format!("must be above 0 and below clock_hz / 2 = {nyquist} Hz");
    check(
        "gyro",
        "f1_hz",
        e.gyro.f1_hz,
        e.gyro.f1_hz > 0.0 && e.gyro.f1_hz < nyquist,
        &below,
    )?;
    check(
        "gyro",
        "f2_hz",
        e.gyro.f2_hz,
        e.gyro.f2_hz > 0.0 && e.gyro.f2_hz < nyquist,
        &below,
    )?;
    check("gyro", "q1", e.gyro.q1, e.gyro.q1 > 0.0, positive)?;
    check("gyro", "q2", e.gyro.q2, e.gyro.q2 > 0.0, positive)?;
    check(
        "gyro",
        "angular_gain",
        e.gyro.angular_gain,
        true,
        "must be a finite number",
    )?;
    check(
        "drive",
        "carrier_hz",
        e.carrier_hz,
        e.carrier_hz > 0.0 && e.carrier_hz < nyquist,
        &below,
    )?;
    let amp = "allowed -1 <= amplitude < 1 (fraction of DAC full scale), not 0";
    let (a1, a2) = e.amplitude;
    check(
        "drive",
        "amplitude1",
        a1,
        (-1.0..1.0).contains(&a1) && a1 != 0.0,
        amp,
    )?;
    check(
        "drive",
        "amplitude2",
        a2,
        (-1.0..1.0).contains(&a2) && a2 != 0.0,
        amp,
    )?;
    let [g1, g2] = e.force_full_scale;
    check(
        "drive",
        "force_full_scale1_n_per_kg",
        g1,
        g1 > 0.0,
        positive,
    )?;
    check(
        "drive",
        "force_full_scale2_n_per_kg",
        g2,
        g2 > 0.0,
        positive,
    )?;
    let latency = |key: &str, v: u32| {
        check(
            "frontend",
            key,
            f64::from(v),
            v <= crate::frontend::MAX_LATENCY,
            "allowed 0..=31 clocks",
        )
    };
    latency("dac_latency", e.dac_latency)?;
    latency("adc_latency", e.adc_latency)?;
    if e.dac_latency + e.adc_latency > 63 {
        return Err(format!(
            "[frontend] dac_latency + adc_latency = {}: at most 63 clocks (the reference delay line)",
            e.dac_latency + e.adc_latency
        ));
    }
    let bits = "allowed 1..=16";
    check(
        "frontend",
        "dac_bits",
        f64::from(e.dac_bits),
        (1..=16).contains(&e.dac_bits),
        bits,
    )?;
    check(
        "frontend",
        "adc_bits",
        f64::from(e.adc_bits),
        (1..=16).contains(&e.adc_bits),
        bits,
    )?;
    let h = e.adc_headroom;
    check(
        "frontend",
        "adc_headroom",
        h,
        h > 0.0 && h <= 1.0,
        "allowed 0 < adc_headroom <= 1",
    )?;
    if let Some([p1, p2]) = e.adc_per_meter {
        check("frontend", "adc_per_meter1", p1, p1 > 0.0, positive)?;
        check("frontend", "adc_per_meter2", p2, p2 > 0.0, positive)?;
    }
    check(
        "frontend",
        "noise_lsb",
        e.noise_lsb,
        e.noise_lsb >= 0.0,
        "must be >= 0",
    )?;
    let r = e.decimation;
    if !(16..=4096).contains(&r) {
        return Err(format!("[filter] decimation = {r}: allowed 16..=4096"));
    }
    let fz = e.clock_hz / f64::from(r);
    let cut = format!(
        "allowed {:.6} to {:.3} Hz (clock_hz / decimation / 1000 to / 5)",
        fz / 1000.0,
        fz / 5.0
    );
    for (key, v) in [("butterworth_hz", e.butterworth_hz), ("rc_hz", e.rc_hz)] {
        check("filter", key, v, v >= fz / 1000.0 && v <= fz / 5.0, &cut)?;
    }
    let list =
        |key: &str, v: &[f64], ok: &dyn Fn(f64) -> bool, allowed: &str| -> Result<(), String> {
            if v.is_empty() {
                return Err(format!(
                    "[experiment] {key} is empty: give at least 2 distinct values"
                ));
            }
            if let Some(x) = v.iter().find(|x| !(x.is_finite() && ok(**x))) {
                return Err(format!("[experiment] {key} contains {x}: {allowed}"));
            }
            if v.iter().all(|x| *x == v[0]) {
                return Err(format!(
                    "[experiment] {key}: give at least 2 distinct values for a slope"
                ));
            }
            Ok(())
        };
    list(
        "readout_rates_dps",
        &e.readout_rates_dps,
        &|x| x.abs() <= 1e5,
        "rates must be finite, |rate| <= 1e5 deg/s",
    )?;
    let max_cal = e.clock_hz / 1000.0;
    list(
        "cal_freqs_hz",
        &e.cal_freqs_hz,
        &|x| x > 0.0 && x <= max_cal,
        &format!("frequencies must be above 0 and at most clock_hz / 1000 = {max_cal} Hz"),
    )?;
    check(
        "experiment",
        "tolerance",
        e.tolerance,
        e.tolerance > 0.0 && e.tolerance < 0.1,
        "allowed 0 < tolerance < 0.1",
    )?;
    let w = e.min_window_s;
    check(
        "experiment",
        "min_window_s",
        w,
        w > 0.0 && w <= 100.0,
        "allowed 0 < min_window_s <= 100 s",
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_file_is_the_paper() {
        assert_eq!(parse("c.toml", "").unwrap(), Experiment::paper());
    }

    #[test]
    fn carrier_follows_mode_1_unless_given() {
        let e = parse(
            "c.toml",
            "[gyro]\nf1_hz = 1.0123e6\nf2_hz = 1.0124e6\n[drive]\nclock_hz = 10e6\n",
        )
        .unwrap();
        assert_eq!(e.carrier_hz, 1.0123e6);
        let e = parse("c.toml", "[gyro]\nf1_hz = 1.0123e6\nf2_hz = 1.0124e6\n[drive]\nclock_hz = 10e6\ncarrier_hz = 1.01e6\n").unwrap();
        assert_eq!(e.carrier_hz, 1.01e6);
    }

    #[test]
    fn every_error_is_one_line_naming_the_key() {
        let cases = [
            ("[gyro]\nq1 = -5.0\n", "[gyro] q1 = -5"),
            ("[gyro]\nq2 = nan\n", "[gyro] q2 = NaN"),
            (
                "[gyro]\nbogus = 1\n",
                "c.toml line 2 in [gyro]: unknown field `bogus`",
            ),
            ("[bogus]\nx = 1\n", "c.toml line 1"),
            (
                "[drive]\ncarrier_hz = 30e6\n",
                "[drive] carrier_hz = 30000000",
            ),
            (
                "[experiment]\nreadout_rates_dps = []\n",
                "[experiment] readout_rates_dps is empty",
            ),
            (
                "[experiment]\ncal_freqs_hz = [10.0, 10.0]\n",
                "[experiment] cal_freqs_hz: give at least 2 distinct",
            ),
            (
                "[gyro]\nq1 = \"high\"\n",
                "c.toml line 2 in [gyro]: invalid type",
            ),
            ("[gyro\nq1 = 3\n", "c.toml line 1"),
            ("[filter]\ndecimation = 8\n", "[filter] decimation = 8"),
        ];
        for (text, start) in cases {
            let err = parse("c.toml", text).unwrap_err();
            assert!(err.starts_with(start), "{text:?} gave {err:?}");
            assert!(!err.contains('\n'), "{err:?}");
        }
    }
}
