//! Coefficients of the output filter from cut-off frequencies in Hz.
//!
//! The hardware (`gyrocal_hdl::iir_lowpass`) runs at f_z = f_clk / R after the
//! CIC. Its biquad is a 2nd-order Butterworth low-pass designed by the
//! bilinear transform with pre-warping:
//!
//! ```text
//!   W = tan(pi f_c / f_z),  d = 1 + sqrt2 W + W^2
//!   b = (W^2 / d) [1, 2, 1],  a1 = 2 (W^2 - 1) / d,  a2 = (1 - sqrt2 W + W^2) / d
//! ```
//!
//! stored as k0 = g = b0 / G_cic, k1 = -a1 - 2 = -(4 W^2 + 2 sqrt2 W) / d and
//! k2 = 1 - a2 = 2 sqrt2 W / d (both computed without cancellation), where
//! G_cic = R^4 / 2^ceil(4 log2 R) is the CIC's residual gain, so the chain
//! has unity gain at DC. The RC section is the impulse-invariant one-pole
//! alpha = 1 - exp(-2 pi f_rc / f_z). Every coefficient is rounded to Q2.30
//! (the `fixed` crate's `I2F30`: nearest, ties to even, range checked);
//! the realized DC gain, 4 k0 / -(k1 + k2) G_cic, is computed from the
//! quantized values and reported, so results never depend on the ideal one.
//!
//! Limits, checked with a one-line error: `MIN_DECIMATION` <= R <= 4096
//! (the filter's micro-program takes `iir_lowpass::SCHEDULE_CLOCKS` = 166
//! clocks per sample); cut-offs between f_z / 1000 and
//! f_z / 5. Below f_z / 1000 the biquad's dead band would approach half an
//! output LSB (`dead_band_lsb` bounds it; the guard bits of the states are
//! sized for this range); above f_z / 5, k1 would leave the Q2.30 range.

use crate::PlanError;
use crate::datapath::{
    CIC_STAGES as STAGES, COEFFICIENT_FRACTION_BITS, GUARD_BITS, OUTPUT_FRACTION_BITS,
};
pub use crate::datapath::{MAX_DECIMATION, MIN_DECIMATION};
use crate::registers::Coefficients;
/// Lowest cut-off as a fraction of the output rate.
pub const MIN_CUTOFF_RATIO: f64 = 1.0 / 1000.0;
/// Highest cut-off as a fraction of the output rate.
pub const MAX_CUTOFF_RATIO: f64 = 0.2;

/// A realized filter: the register values and what they amount to.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterDesign {
    /// Decimation R.
    pub decimation: u32,
    /// CIC output shift register value, ceil(4 log2 R) - 8.
    pub cic_shift: u32,
    /// CIC residual gain R^4 / 2^ceil(4 log2 R), in (1/2, 1].
    pub cic_gain: f64,
    /// Quantized coefficients.
    pub coefficients: Coefficients,
    /// Output rate f_clk / R in Hz.
    pub output_rate_hz: f64,
    /// Butterworth cut-off in Hz (as asked).
    pub butterworth_hz: f64,
    /// RC cut-off in Hz (as asked).
    pub rc_hz: f64,
    /// DC gain from the mixer output to z / 2^8, from the quantized values.
    pub dc_gain: f64,
    /// Bound on the biquad's zero-input dead band, in output LSBs.
    pub dead_band_lsb: f64,
}

/// ceil(4 log2 R), exactly: the smallest s with 2^s >= R^4.
pub fn cic_bit_growth(decimation: u32) -> u32 {
    let gain = (decimation as u128).pow(STAGES);
    let mut s = 0;
    while (1u128 << s) < gain {
        s += 1;
    }
    s
}

fn quantize(x: f64, what: &'static str) -> Result<i32, PlanError> {
    let q = (x * f64::from(1u32 << COEFFICIENT_FRACTION_BITS)).round();
    if !(i32::MIN as f64..=i32::MAX as f64).contains(&q) {
        return Err(PlanError::Coefficient {
            name: what,
            value: x,
        });
    }
    Ok(q as i32)
}

/// Design the CIC scaling and the IIR coefficients.
pub fn design(
    clock_hz: f64,
    decimation: u32,
    butterworth_hz: f64,
    rc_hz: f64,
) -> Result<FilterDesign, PlanError> {
    if !(MIN_DECIMATION..=MAX_DECIMATION).contains(&decimation) {
        return Err(PlanError::out_of_range(
            "cic decimation",
            decimation,
            format!("allowed {MIN_DECIMATION}..={MAX_DECIMATION}"),
        ));
    }
    let fz = clock_hz / decimation as f64;
    for (name, f) in [("butterworth_hz", butterworth_hz), ("rc_hz", rc_hz)] {
        let (lo, hi) = (fz * MIN_CUTOFF_RATIO, fz * MAX_CUTOFF_RATIO);
        if !(f.is_finite() && f >= lo && f <= hi) {
            return Err(PlanError::out_of_range(
                name,
                f,
                format!(
                    "allowed {lo:.6} to {hi:.3} Hz (f_clk / R / 1000 to f_clk / R / 5 with R = {decimation})"
                ),
            ));
        }
    }
    let growth = cic_bit_growth(decimation);
    let cic_gain = (decimation as f64).powi(STAGES as i32) / 2f64.powi(growth as i32);
    let w = (std::f64::consts::PI * butterworth_hz / fz).tan();
    let sqrt2 = std::f64::consts::SQRT_2;
    let d = 1.0 + sqrt2 * w + w * w;
    let b0 = w * w / d;
    let k1 = -(4.0 * w * w + 2.0 * sqrt2 * w) / d;
    let k2 = 2.0 * sqrt2 * w / d;
    let alpha = -(-std::f64::consts::TAU * rc_hz / fz).exp_m1();
    let coefficients = Coefficients {
        k0: quantize(b0 / cic_gain, "k0")?,
        k1: quantize(k1, "k1")?,
        k2: quantize(k2, "k2")?,
        alpha: quantize(alpha, "alpha")?,
    };
    let scale = f64::from(1u32 << COEFFICIENT_FRACTION_BITS);
    let (q1, q2) = (
        coefficients.k1 as f64 / scale,
        coefficients.k2 as f64 / scale,
    );
    // Quantized feedback a1 = -2 - k1, a2 = 1 - k2: the stability triangle.
    let (a1, a2) = (-2.0 - q1, 1.0 - q2);
    if !(a2.abs() < 1.0 && a1.abs() < 1.0 + a2) || coefficients.alpha <= 0 {
        return Err(PlanError::Unstable {
            butterworth_hz,
            rc_hz,
        });
    }
    let sum = -(coefficients.k1 as i64 + coefficients.k2 as i64) as f64;
    let dc_gain = cic_gain * 4.0 * coefficients.k0 as f64 / sum;
    // Zero input, y1 = y2 = c: y = c + round(-(1 + a1 + a2) c) stays at c
    // while |(1 + a1 + a2) c| < 1/2 state LSB. 1 + a1 + a2 = sum / 2^30.
    let dead_band_state_lsb = 0.5 * scale / sum;
    let dead_band_lsb = dead_band_state_lsb / f64::from(1u32 << GUARD_BITS);
    Ok(FilterDesign {
        decimation,
        cic_shift: growth - OUTPUT_FRACTION_BITS,
        cic_gain,
        coefficients,
        output_rate_hz: fz,
        butterworth_hz,
        rc_hz,
        dc_gain,
        dead_band_lsb,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bit_growth_is_exact() {
        assert_eq!(cic_bit_growth(16), 16);
        assert_eq!(cic_bit_growth(4096), 48);
        assert_eq!(cic_bit_growth(1000), 40); // 1000^4 = 1e12 <= 2^40
        assert_eq!(cic_bit_growth(17), 17); // 17^4 = 83521 > 2^16
    }

    #[test]
    fn dc_gain_is_unity_to_coefficient_precision() {
        // k0 carries 1 / G_cic, so the realized gain differs from 1 only by
        // the rounding of k0, k1, k2 (each +-2^-31 absolute): relative error
        // below 2^-31 (1 / k0 + 2 / |k1 + k2|) * 2^30.
        for (r, fb, frc) in [
            (1000, 500.0, 2000.0),
            (200, 8e3, 1.6e4),
            (4096, 13.0, 30.0),
            (333, 2e3, 1e3),
        ] {
            let f = design(50e6, r, fb, frc).unwrap();
            let k = f.coefficients;
            let bound = 0.5 * (1.0 / k.k0 as f64 + 2.0 / -(k.k1 as f64 + k.k2 as f64));
            assert!(
                (f.dc_gain - 1.0).abs() <= bound,
                "R {r}: gain {}",
                f.dc_gain
            );
        }
    }

    /// The RC section y += alpha (x - y) passes its asked cut-off at
    /// -3 dB: |H|^2 = alpha^2 / (1 - 2 (1 - alpha) cos w + (1 - alpha)^2)
    /// at w = 2 pi f_rc / f_z, from the quantized alpha. The exponential
    /// mapping matches the analog pole to first order in w, so the gain
    /// is 1 / sqrt(2) within w / 4 (2% at the ratios below, all <= 0.012).
    #[test]
    fn the_rc_section_is_3_db_down_at_its_cut_off() {
        for (r, fb, frc) in [(1000, 500.0, 200.0), (200, 8e3, 1.6e3), (4096, 13.0, 30.0)] {
            let f = design(50e6, r, fb, frc).unwrap();
            let fz = f.output_rate_hz;
            let alpha = f.coefficients.alpha as f64 / (1u64 << 30) as f64;
            let w = std::f64::consts::TAU * frc / fz;
            let gain = (alpha * alpha
                / (1.0 - 2.0 * (1.0 - alpha) * w.cos() + (1.0 - alpha).powi(2)))
            .sqrt();
            assert!(
                (gain * 2f64.sqrt() - 1.0).abs() < w / 4.0 + 1e-6,
                "R {r}, f_rc {frc}: |H| {gain} at w {w}"
            );
        }
    }

    #[test]
    fn dead_band_is_below_a_quarter_output_lsb_over_the_allowed_range() {
        let f = design(
            50e6,
            4096,
            50e6 / 4096.0 * MIN_CUTOFF_RATIO * 1.0001,
            1000.0,
        )
        .unwrap();
        assert!(f.dead_band_lsb < 0.25, "{}", f.dead_band_lsb);
    }

    #[test]
    fn out_of_range_settings_name_the_setting() {
        assert!(
            design(50e6, 8, 100.0, 100.0)
                .unwrap_err()
                .to_string()
                .starts_with("cic decimation = 8")
        );
        assert!(
            design(50e6, 1000, 20e3, 100.0)
                .unwrap_err()
                .to_string()
                .starts_with("butterworth_hz = 20000")
        );
        assert!(
            design(50e6, 1000, 500.0, f64::NAN)
                .unwrap_err()
                .to_string()
                .starts_with("rc_hz = NaN")
        );
    }
}
