//! What `gyrocal calibrate` prints: one JSON object, or a table. Scale
//! factors are z LSB per deg/s, one per output; uncertainties 1 sigma
//! (relative for the scale factors, as in `gyrocal field`).

use super::{Halted, Outcome, Truth};
use gyrocal_host::identify::{Estimate, Identified};
use gyrocal_host::selfcal::{ScaledDrives, SelfCal};
use gyrocal_sim::coverage::{Scored, uncovered_selfcal_errors};
use serde_json::{Map, Value, json};
use std::fmt::Write as _;

/// `name` and `name_uncertainty` of an estimate.
fn put(map: &mut Map<String, Value>, name: &str, e: Estimate) {
    map.insert(name.into(), json!(e.value));
    map.insert(format!("{name}_uncertainty"), json!(e.uncertainty));
}

/// The identified parameters, in the order the table shows them.
fn estimates(id: &Identified) -> [(&'static str, Estimate); 6] {
    let [m1, m2] = &id.modes;
    [
        ("f1_hz", m1.f_hz),
        ("f2_hz", m2.f_hz),
        ("q1", m1.q),
        ("q2", m2.q),
        ("loop_phase_deg", id.loop_phase_deg),
        ("group_delay_s", id.group_delay_s),
    ]
}

/// sf / sf_true - 1 per output.
fn error(sf: [f64; 2], truth: [f64; 2]) -> [f64; 2] {
    std::array::from_fn(|k| sf[k] / truth[k] - 1.0)
}

/// The self-calibration error's own 1-sigma: the self-calibrated scale
/// factor's and the rate table's in quadrature, two independent
/// measurements (as `field`'s `selfcal_error_uncertainty`).
fn error_sigma(cal: &SelfCal, t: &Truth) -> [f64; 2] {
    std::array::from_fn(|k| cal.sf_selfcal_uncertainty.total[k].hypot(t.table.uncertainty[k]))
}

/// The line naming the self-calibration errors beyond 3 of their sigmas
/// against the in-process board's truth (as `gyrocal field` says it), or
/// None.
pub fn uncovered(cal: &SelfCal, t: &Truth) -> Option<String> {
    let scored = Scored::outputs(
        None,
        t.device.temperature_c,
        error(cal.sf_selfcal_per_dps, t.table.sf_per_dps),
        error_sigma(cal, t),
    );
    uncovered_selfcal_errors(&scored)
}

/// The identified parameters as JSON: each `name` with its
/// `name_uncertainty`.
fn identified_json(id: &Identified) -> Value {
    let mut identified = Map::new();
    for (name, e) in estimates(id) {
        put(&mut identified, name, e);
    }
    if let Some(t) = id.cycle_rate_dps {
        put(&mut identified, "cycle_rate_dps", t);
    }
    Value::Object(identified)
}

/// The one JSON object of `--json`.
pub fn json(o: &Outcome) -> Value {
    let identified = identified_json(&o.cal.identified);
    let cal = &o.cal;
    let truth = o.truth.as_ref().map(|t| {
        let d = &t.device;
        let combined = error_sigma(cal, t);
        json!({
            "temperature_c": d.temperature_c,
            "f1_hz": d.gyro.f1_hz,
            "f2_hz": d.gyro.f2_hz,
            "q1": d.gyro.q1,
            "q2": d.gyro.q2,
            "front_end_phase_deg": d.front_end_phase_deg,
            "adc_gain": d.adc_gain,
            "drive_gain": d.drive_gain,
            "sf_true_per_dps": t.table.sf_per_dps,
            "sf_true_uncertainty": t.table.uncertainty,
            "sf_true_windows": t.table.windows,
            "selfcal_error": error(cal.sf_selfcal_per_dps, t.table.sf_per_dps),
            "selfcal_error_uncertainty": combined,
            "clocks": t.clocks,
        })
    });
    json!({
        "board": o.board,
        "identified": identified,
        "operating": cal.operating,
        "cal_hz": cal.cal_hz,
        "sf_cal_per_dps": cal.sf_cal_per_dps,
        "ratio": cal.ratio.exact,
        "ratio_eq56": cal.ratio.eq56,
        "sf_selfcal_per_dps": cal.sf_selfcal_per_dps,
        "sf_selfcal_uncertainty": cal.sf_selfcal_uncertainty.total,
        "sf_selfcal_uncertainty_sources": cal.sf_selfcal_uncertainty,
        "sf_eq56_per_dps": cal.sf_eq56_per_dps,
        "clocks": cal.clocks,
        "wall_s": o.wall_s,
        "samples": {"read": o.samples.read, "missed": o.samples.missed},
        "carrier_spurs": cal.carrier_spurs,
        "warnings": o.warnings,
        "failed": null,
        "truth": truth,
    })
}

/// The JSON object of a cycle that stopped after identification: the
/// board, what it identified, `failed` (the stage and its error), the
/// clocks identification took, wall time, samples and warnings; the keys
/// of the later stages are absent.
pub fn halted_json(h: &Halted, id: &Identified, warnings: &[String]) -> Value {
    json!({
        "board": h.board,
        "identified": identified_json(id),
        "clocks": id.clocks,
        "wall_s": h.wall_s,
        "samples": {"read": h.samples.read, "missed": h.samples.missed},
        "warnings": warnings,
        "failed": {"stage": STOPPED_STAGE, "error": h.error},
    })
}

/// What `failed.stage` names when a cycle stops after identification.
pub const STOPPED_STAGE: &str = "self-calibration after identification";

/// The table of a cycle that stopped after identification.
pub fn halted_table(h: &Halted, id: &Identified, warnings: &[String]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "board: {}", h.board);
    identified_rows(&mut s, id, None);
    for w in warnings {
        let _ = writeln!(s, "{w}");
    }
    let _ = writeln!(s, "FAILED ({STOPPED_STAGE}): {}", h.error);
    let _ = writeln!(
        s,
        "{:.3e} clocks, {:.1} s wall; {} z samples read, {} went by unread",
        id.clocks as f64, h.wall_s, h.samples.read, h.samples.missed
    );
    s
}

/// The identified parameters' rows, with the truth's where it is known.
fn identified_rows(s: &mut String, id: &Identified, true_values: Option<[f64; 4]>) {
    let _ = writeln!(
        s,
        "{:<16} {:>18} {:>12} {:>18}",
        "identified", "value", "1-sigma", "truth"
    );
    for (i, (name, e)) in estimates(id).into_iter().enumerate() {
        let t = true_values
            .and_then(|v| v.get(i).copied())
            .map_or(String::new(), |v| format!("{v:.6}"));
        let value = if e.value.abs() < 1e-2 {
            format!("{:.6e}", e.value)
        } else {
            format!("{:.6}", e.value)
        };
        let _ = writeln!(s, "{name:<16} {value:>18} {:>12.3e} {t:>18}", e.uncertainty);
    }
}

/// The table.
pub fn table(o: &Outcome) -> String {
    let mut s = String::new();
    let cal = &o.cal;
    let _ = writeln!(s, "board: {}", o.board);
    let truth = o.truth.as_ref().map(|t| &t.device.gyro);
    identified_rows(
        &mut s,
        &cal.identified,
        truth.map(|g| [g.f1_hz, g.f2_hz, g.q1, g.q2]),
    );
    let _ = writeln!(
        s,
        "operating: carrier {:.6} Hz, phase correction {:.5} deg",
        cal.operating.carrier_hz, cal.operating.ref_lag_deg
    );
    let scaled = cal.operating.scaled_drives;
    if let Some(d) = scaled.filter(ScaledDrives::is_said) {
        let _ = writeln!(s, "{d}");
    }
    for w in &o.warnings {
        let _ = writeln!(s, "{w}");
    }
    if let Some(sp) = &cal.carrier_spurs {
        let _ = writeln!(s, "{sp}");
    }
    let _ = writeln!(
        s,
        "{:<32} {:>14} {:>14}",
        "z LSB per deg/s", "output 1", "output 2"
    );
    let mut row = |name: &str, v: [f64; 2], pct: bool| {
        let _ = if pct {
            writeln!(
                s,
                "{name:<32} {:>13.4}% {:>13.4}%",
                100.0 * v[0],
                100.0 * v[1]
            )
        } else {
            writeln!(s, "{name:<32} {:>14.6e} {:>14.6e}", v[0], v[1])
        };
    };
    row("SF_cal", cal.sf_cal_per_dps, false);
    row("ratio (exact theory)", cal.ratio.exact, false);
    row("SF_selfcal", cal.sf_selfcal_per_dps, false);
    row("SF_selfcal 1-sigma", cal.sf_selfcal_uncertainty.total, true);
    if let Some(t) = &o.truth {
        row("SF_true (rate table)", t.table.sf_per_dps, false);
        row("SF_true 1-sigma", t.table.uncertainty, true);
        row(
            "self-cal error",
            error(cal.sf_selfcal_per_dps, t.table.sf_per_dps),
            true,
        );
        row("self-cal error 1-sigma", error_sigma(cal, t), true);
    }
    let _ = writeln!(
        s,
        "{:.3e} clocks, {:.1} s wall; {} z samples read, {} went by unread",
        cal.clocks as f64, o.wall_s, o.samples.read, o.samples.missed
    );
    s
}
