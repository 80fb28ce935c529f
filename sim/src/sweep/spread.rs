//! The `[spread]` section of `gyrocal sweep`: a production spread of
//! devices around the file's `[gyro]`, and the draw of device `i`.
//!
//! ```toml
//! [spread]
//! devices = 200
//! seed = 7
//! tolerance = 1e-3               # the yield's bound on |self-cal error|
//! f1_hz = { sd = 40.0 }          # normal, around [gyro] f1_hz
//! split_hz = { sd = 25.0 }       # f2 - f1
//! q1 = { rel_sd = 0.1 }
//! q2 = { rel_sd = 0.1 }
//! angular_gain = { rel_sd = 0.02 }
//! quadrature_dps = { sd = 50.0 }
//! damping_coupling_dps = { sd = 5.0 }
//! clock_error_ppm = { sd = 20.0 }  # each board's oscillator, around [drive]'s
//! ```
//!
//! Each parameter is normal around its nominal value, with an absolute
//! `sd` or a relative `rel_sd` (one of the two). A key left out does not
//! spread. A part 5 sigma out must still be a device the model takes
//! ([`Spread::validate`]).
//!
//! **Device `i` depends only on `seed` and `i`.** Its generator
//! (xoshiro256++) is seeded from a splitmix64 hash of the pair, and it draws
//! one standard normal per parameter in a fixed order, used or not. So a
//! device is the same whatever the shard count, and adding a key to the
//! section does not move the other parameters' draws. The device's noise
//! seeds (`[frontend] seed`, `[noise] seed`) come from the same generator,
//! after the parameters: each device has its own noise, as each part off a
//! line does. They are below 2^63, so each fits a TOML integer (an i64)
//! and the part's field file (`Sweep::part_file`) holds them as they are.
//! Its board's oscillator error (`clock_error_ppm`, an `sd` in
//! ppm around `[drive] clock_error_ppm`) is drawn last, after the seeds,
//! so the key leaves every other draw where it was.

use crate::config::MAX_CLOCK_PPM;
use crate::gyro::{GyroParams, MAX_COUPLING_DPS};
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

/// Most devices in one sweep.
pub const MAX_DEVICES: u32 = 100_000;
/// Widest relative spread: a parameter 5 sigma out still keeps its sign.
pub const MAX_REL_SD: f64 = 0.2;
/// The yield's default bound on |self-calibration error| (relative).
pub const DEFAULT_TOLERANCE: f64 = 1e-3;

/// One parameter's normal spread: `sd` (in the parameter's unit) or
/// `rel_sd` (relative to the nominal value).
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Sd {
    /// Absolute standard deviation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sd: Option<f64>,
    /// Standard deviation relative to the nominal value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rel_sd: Option<f64>,
}

/// The `[spread]` section.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Spread {
    /// Devices drawn, 1..=[`MAX_DEVICES`].
    pub devices: u32,
    /// Seed of the draws.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Bound on |self-calibration error| for the yield (relative).
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Mode 1's frequency (Hz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub f1_hz: Option<Sd>,
    /// The split f2 - f1 (Hz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub split_hz: Option<Sd>,
    /// Mode 1's Q.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub q1: Option<Sd>,
    /// Mode 2's Q.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub q2: Option<Sd>,
    /// The angular gain lambda.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_gain: Option<Sd>,
    /// The quadrature (stiffness) coupling (deg/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quadrature_dps: Option<Sd>,
    /// The damping coupling (deg/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping_coupling_dps: Option<Sd>,
    /// The board oscillator's error (ppm), around `[drive]
    /// clock_error_ppm`: an `sd` alone (its nominal is usually 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clock_error_ppm: Option<Sd>,
}

fn default_seed() -> u64 {
    1
}

fn default_tolerance() -> f64 {
    DEFAULT_TOLERANCE
}

/// A `[spread]` key whose value is not allowed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("[spread] {key}{}: {allowed}", shown(*.value))]
pub struct SpreadError {
    /// The key (`q1.rel_sd`, `devices`, ...).
    pub key: String,
    /// Its value (`None` when the key's form is wrong, not its value).
    pub value: Option<f64>,
    /// What is allowed.
    pub allowed: String,
}

/// ` = value`, or nothing when there is no one value to show.
fn shown(value: Option<f64>) -> String {
    value.map(|v| format!(" = {v}")).unwrap_or_default()
}

fn refuse(key: impl Into<String>, value: f64, allowed: impl Into<String>) -> SpreadError {
    SpreadError {
        key: key.into(),
        value: Some(value),
        allowed: allowed.into(),
    }
}

/// A parameter of the spread: its key, its nominal value, its spread,
/// and what it must stay 5 sigma out (`Spread::validate`).
struct Param {
    key: &'static str,
    nominal: f64,
    spread: Option<Sd>,
    limit: Limit,
}

/// What a parameter 5 sigma out must stay to be a device the model takes.
#[derive(Clone, Copy)]
enum Limit {
    /// f1: positive.
    Positive,
    /// The split: f2 = f1 + split positive, f1's sd and its own together.
    PositiveF2,
    /// Q and lambda: the nominal's sign.
    Sign,
    /// A coupling: within `MAX_COUPLING_DPS`.
    Coupling,
}

impl Sd {
    /// The standard deviation relative to `nominal` (of a spread
    /// [`Spread::validate`] accepted: one of the two given).
    pub fn relative(&self, nominal: f64) -> f64 {
        self.rel_sd
            .unwrap_or_else(|| self.sd.unwrap_or(0.0) / nominal.abs())
    }

    /// The absolute standard deviation around `nominal`, checked.
    fn absolute(&self, key: &str, nominal: f64) -> Result<f64, SpreadError> {
        match (self.sd, self.rel_sd) {
            (Some(sd), None) if sd.is_finite() && sd >= 0.0 => Ok(sd),
            (Some(sd), None) => Err(refuse(format!("{key}.sd"), sd, "must be 0 or more")),
            (None, Some(r)) if nominal == 0.0 => Err(refuse(
                format!("{key}.rel_sd"),
                r,
                "the nominal value is 0: give `sd` (absolute) instead",
            )),
            (None, Some(r)) if r.is_finite() && (0.0..=MAX_REL_SD).contains(&r) => {
                Ok(r * nominal.abs())
            }
            (None, Some(r)) => Err(refuse(
                format!("{key}.rel_sd"),
                r,
                format!("allowed 0..={MAX_REL_SD} (5 sigma out keeps the sign)"),
            )),
            _ => Err(SpreadError {
                key: key.into(),
                value: None,
                allowed: "give exactly one of `sd` (absolute) or `rel_sd` (relative)".into(),
            }),
        }
    }
}

/// A drawn seed as a TOML integer holds it: its top 63 bits (TOML integers
/// are i64, and a seed at or above 2^63 would make the part's field file
/// unreadable).
fn toml_seed(bits: u64) -> u64 {
    bits >> 1
}

/// What device `i` is: its parameters and its noise seeds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Drawn {
    /// The device.
    pub gyro: GyroParams,
    /// Its `[frontend] seed` (ADC noise).
    pub frontend_seed: u64,
    /// Its `[noise] seed` (Brownian noise).
    pub noise_seed: u64,
    /// Its board oscillator's error from `[drive] clock_error_ppm` (ppm;
    /// 0 without `[spread] clock_error_ppm`).
    #[serde(default)]
    pub clock_error_ppm: f64,
}

/// The splitmix64 finalizer (Steele, Lea, Flood 2014).
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Spread {
    fn params(&self, nominal: &GyroParams) -> [Param; 7] {
        let p = |key, nominal, spread, limit| Param {
            key,
            nominal,
            spread,
            limit,
        };
        [
            p("f1_hz", nominal.f1_hz, self.f1_hz, Limit::Positive),
            p(
                "split_hz",
                nominal.f2_hz - nominal.f1_hz,
                self.split_hz,
                Limit::PositiveF2,
            ),
            p("q1", nominal.q1, self.q1, Limit::Sign),
            p("q2", nominal.q2, self.q2, Limit::Sign),
            p(
                "angular_gain",
                nominal.angular_gain,
                self.angular_gain,
                Limit::Sign,
            ),
            p(
                "quadrature_dps",
                nominal.quadrature_dps,
                self.quadrature_dps,
                Limit::Coupling,
            ),
            p(
                "damping_coupling_dps",
                nominal.damping_coupling_dps,
                self.damping_coupling_dps,
                Limit::Coupling,
            ),
        ]
    }

    /// Checks every key against its limits (around `nominal`, the file's
    /// `[gyro]`): one line naming the key and what is allowed.
    pub fn validate(&self, nominal: &GyroParams) -> Result<(), SpreadError> {
        if !(1..=MAX_DEVICES).contains(&self.devices) {
            return Err(refuse(
                "devices",
                f64::from(self.devices),
                format!("allowed 1..={MAX_DEVICES}"),
            ));
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(refuse(
                "tolerance",
                self.tolerance,
                "a relative bound, greater than 0 and less than 1",
            ));
        }
        self.five_sigma_stays_valid(nominal, &self.sds(nominal)?)?;
        self.clock_sd(0.0).map(|_| ())
    }

    /// `clock_error_ppm`'s sd (ppm; 0 without it), checked: an `sd` alone,
    /// 5 of it out from `around_ppm` (the file's `[drive]
    /// clock_error_ppm`, which `Sweep`'s parse gives) within
    /// `MAX_CLOCK_PPM`.
    pub fn clock_sd(&self, around_ppm: f64) -> Result<f64, SpreadError> {
        let key = "clock_error_ppm";
        let Some(s) = self.clock_error_ppm else {
            return Ok(0.0);
        };
        let sd = match (s.sd, s.rel_sd) {
            (Some(sd), None) => sd,
            _ => {
                return Err(SpreadError {
                    key: key.into(),
                    value: None,
                    allowed: "give `sd` (ppm; a board's oscillator spreads around an exact clock)"
                        .into(),
                });
            }
        };
        let most = (MAX_CLOCK_PPM - around_ppm.abs()) / 5.0;
        if !(sd.is_finite() && (0.0..=most).contains(&sd)) {
            let around = if around_ppm == 0.0 {
                String::new()
            } else {
                format!(" from [drive] clock_error_ppm = {around_ppm}")
            };
            return Err(refuse(
                format!("{key}.sd"),
                sd,
                format!(
                    "allowed 0..={most} ppm, so that 5 sigma out{around} stays within \
                     {MAX_CLOCK_PPM} ppm"
                ),
            ));
        }
        Ok(sd)
    }

    /// Every parameter 5 sigma out (one draw in 1.7 million) must still
    /// be a device the model takes: the frequencies positive, Q and the
    /// angular gain of the nominal's sign, the couplings within the
    /// model's `MAX_COUPLING_DPS`. A spread wider than that would fail
    /// parts for the model's sake, not the part's.
    fn five_sigma_stays_valid(
        &self,
        nominal: &GyroParams,
        sds: &[f64; 7],
    ) -> Result<(), SpreadError> {
        let f1_sd = sds[0];
        for (p, &sd) in self.params(nominal).iter().zip(sds) {
            let (key, value) = (format!("{}.sd", p.key), p.nominal);
            match p.limit {
                Limit::Positive if 5.0 * sd >= value => {
                    return Err(refuse(
                        key,
                        sd,
                        format!(
                            "less than a fifth of f1 ({value} Hz), so that 5 sigma out stays \
                             positive"
                        ),
                    ));
                }
                // f2 = f1 + split spreads by both, drawn independently.
                Limit::PositiveF2 if 5.0 * f1_sd.hypot(sd) >= nominal.f2_hz => {
                    return Err(refuse(
                        key,
                        sd,
                        format!(
                            "f2's sd, sqrt(f1_hz.sd^2 + split_hz.sd^2) = {:.6} Hz, must be less \
                             than a fifth of f2 ({} Hz), so that 5 sigma out stays positive",
                            f1_sd.hypot(sd),
                            nominal.f2_hz
                        ),
                    ));
                }
                Limit::Sign if 5.0 * sd > value.abs() => {
                    return Err(refuse(
                        key,
                        sd,
                        format!(
                            "at most a fifth of |{}| ({}), so that 5 sigma out keeps the sign",
                            p.key,
                            value.abs()
                        ),
                    ));
                }
                Limit::Coupling if value.abs() + 5.0 * sd > MAX_COUPLING_DPS => {
                    return Err(refuse(
                        key,
                        sd,
                        format!(
                            "allowed up to {:e} deg/s, so that |{}| + 5 sd stays within the \
                             model's {MAX_COUPLING_DPS:e} deg/s",
                            ((MAX_COUPLING_DPS - value.abs()) / 5.0).max(0.0),
                            p.key
                        ),
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// The absolute standard deviations, in the order of `params`.
    fn sds(&self, nominal: &GyroParams) -> Result<[f64; 7], SpreadError> {
        let mut out = [0.0; 7];
        for (o, p) in out.iter_mut().zip(self.params(nominal)) {
            if let Some(s) = p.spread {
                *o = s.absolute(p.key, p.nominal)?;
            }
        }
        Ok(out)
    }

    /// Device `index` of the spread around `nominal` (which
    /// [`Spread::validate`] accepted): it depends on `seed` and `index`
    /// alone.
    ///
    /// ```
    /// use gyrocal_sim::sweep::spread::{Sd, Spread};
    /// use gyrocal_sim::gyro::GyroParams;
    /// let nominal = GyroParams { f1_hz: 25.1e3, f2_hz: 25.8e3, q1: 3e3, q2: 3e3,
    ///     angular_gain: 0.8, quadrature_dps: 0.0, damping_coupling_dps: 0.0 };
    /// let spread: Spread = toml::from_str("devices = 10\nf1_hz = { sd = 40.0 }").unwrap();
    /// spread.validate(&nominal).unwrap();
    /// let d = spread.draw(&nominal, 3).unwrap();
    /// assert_ne!(d.gyro.f1_hz, nominal.f1_hz);
    /// assert_eq!(d.gyro.f2_hz - d.gyro.f1_hz, 700.0); // the split does not spread
    /// assert_eq!(d, spread.draw(&nominal, 3).unwrap());
    /// ```
    pub fn draw(&self, nominal: &GyroParams, index: u32) -> Result<Drawn, SpreadError> {
        let sds = self.sds(nominal)?;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(mix(mix(self.seed) ^ u64::from(index)));
        let mut v = [0.0; 7];
        for ((v, p), sd) in v.iter_mut().zip(self.params(nominal)).zip(sds) {
            let z: f64 = StandardNormal.sample(&mut rng);
            *v = p.nominal + sd * z;
        }
        let [
            f1_hz,
            split_hz,
            q1,
            q2,
            angular_gain,
            quadrature_dps,
            damping_coupling_dps,
        ] = v;
        Ok(Drawn {
            gyro: GyroParams {
                f1_hz,
                f2_hz: f1_hz + split_hz,
                q1,
                q2,
                angular_gain,
                quadrature_dps,
                damping_coupling_dps,
            },
            frontend_seed: toml_seed(rng.next_u64()),
            noise_seed: toml_seed(rng.next_u64()),
            clock_error_ppm: {
                let z: f64 = StandardNormal.sample(&mut rng);
                self.clock_sd(0.0)? * z
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nominal() -> GyroParams {
        GyroParams {
            f1_hz: 25.1e3,
            f2_hz: 25.8e3,
            q1: 3e3,
            q2: 3e3,
            angular_gain: 0.8,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
        }
    }

    fn spread(text: &str) -> Spread {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn a_device_depends_on_the_seed_and_its_index_alone() {
        let s = spread("devices = 5\nseed = 7\nf1_hz = { sd = 40.0 }\nq1 = { rel_sd = 0.1 }");
        let n = nominal();
        let a: Vec<_> = (0..5).map(|i| s.draw(&n, i).unwrap()).collect();
        // The same device again, in any order, and with more devices.
        let more = Spread {
            devices: 500,
            ..s.clone()
        };
        for i in (0..5).rev() {
            assert_eq!(more.draw(&n, i).unwrap(), a[i as usize]);
        }
        // Every device differs, and another seed gives others.
        for i in 0..5 {
            for j in 0..i {
                assert_ne!(a[i].gyro.f1_hz, a[j].gyro.f1_hz);
                assert_ne!(a[i].frontend_seed, a[j].frontend_seed);
            }
        }
        let other = Spread { seed: 8, ..s };
        assert_ne!(other.draw(&n, 0).unwrap().gyro.q1, a[0].gyro.q1);
    }

    /// Every seed fits a TOML integer (an i64), so a part's field file
    /// holds it: over 2000 seeds a draw of the full 64 bits would have put
    /// about 1000 at or above 2^63.
    #[test]
    fn seeds_fit_a_toml_integer() {
        let s = spread("devices = 1000\nf1_hz = { sd = 40.0 }");
        let n = nominal();
        for i in 0..1000 {
            let d = s.draw(&n, i).unwrap();
            for seed in [d.frontend_seed, d.noise_seed] {
                assert!(i64::try_from(seed).is_ok(), "device {i}: seed {seed}");
            }
        }
    }

    #[test]
    fn adding_a_key_does_not_move_the_others() {
        let n = nominal();
        let a = spread("devices = 1\nf1_hz = { sd = 40.0 }")
            .draw(&n, 0)
            .unwrap();
        let b = spread("devices = 1\nf1_hz = { sd = 40.0 }\nq2 = { rel_sd = 0.05 }")
            .draw(&n, 0)
            .unwrap();
        assert_eq!(a.gyro.f1_hz, b.gyro.f1_hz);
        assert_ne!(a.gyro.q2, b.gyro.q2);
        assert_eq!(a.noise_seed, b.noise_seed);
    }

    /// The board's oscillator spreads after the seeds: the key leaves the
    /// part and its noise where they were; its draws have the asked sd
    /// around 0 (2000 devices: within 5% of it, 3.2 of its standard
    /// errors of 1.6%, the mean within 5 standard errors); `rel_sd` and an
    /// sd whose 5 sigma passes `MAX_CLOCK_PPM` are refused by name.
    #[test]
    fn the_clock_spreads_after_everything_else() {
        let n = nominal();
        let base = "devices = 2000\nf1_hz = { sd = 40.0 }";
        let (a, b) = (
            spread(base),
            spread(&format!("{base}\nclock_error_ppm = {{ sd = 20.0 }}")),
        );
        b.validate(&n).unwrap();
        let drawn: Vec<_> = (0..2000)
            .map(|i| (a.draw(&n, i).unwrap(), b.draw(&n, i).unwrap()))
            .collect();
        for (x, y) in &drawn {
            assert_eq!(
                (x.gyro.clone(), x.frontend_seed, x.noise_seed),
                (y.gyro.clone(), y.frontend_seed, y.noise_seed)
            );
            assert_eq!(x.clock_error_ppm, 0.0);
        }
        let v: Vec<f64> = drawn.iter().map(|d| d.1.clock_error_ppm).collect();
        let m = v.iter().sum::<f64>() / 2000.0;
        let sd = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / 1999.0).sqrt();
        assert!(m.abs() < 5.0 * 20.0 / 2000f64.sqrt(), "{m}");
        assert!((sd / 20.0 - 1.0).abs() < 0.05, "{sd}");
        let err = |text: &str| spread(text).validate(&n).unwrap_err().to_string();
        assert!(err("devices = 2\nclock_error_ppm = { rel_sd = 0.1 }").contains("give `sd`"));
        assert!(
            err("devices = 2\nclock_error_ppm = { sd = 2001 }")
                .starts_with("[spread] clock_error_ppm.sd = 2001: allowed 0..=2000 ppm")
        );
    }

    #[test]
    fn the_draws_have_the_asked_spread() {
        // 4000 devices: the sample sd is within 5% of the asked one
        // (its relative standard error is 1 / sqrt(2 x 3999) = 1.1%, so 5%
        // is 4.5 standard errors), the mean within 5 standard errors.
        let s = spread("devices = 4000\nsplit_hz = { sd = 25.0 }\nq2 = { rel_sd = 0.1 }");
        let n = nominal();
        let d: Vec<_> = (0..4000).map(|i| s.draw(&n, i).unwrap().gyro).collect();
        let stats = |v: Vec<f64>| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
            (m, var.sqrt())
        };
        let (m, sd) = stats(d.iter().map(|g| g.f2_hz - g.f1_hz).collect());
        assert!((m - 700.0).abs() < 5.0 * 25.0 / 4000f64.sqrt(), "{m}");
        assert!((sd / 25.0 - 1.0).abs() < 0.05, "{sd}");
        let (m, sd) = stats(d.iter().map(|g| g.q2).collect());
        assert!((m - 3000.0).abs() < 5.0 * 300.0 / 4000f64.sqrt(), "{m}");
        assert!((sd / 300.0 - 1.0).abs() < 0.05, "{sd}");
        assert!(d.iter().all(|g| g.f1_hz == 25.1e3 && g.q1 == 3e3));
    }

    #[test]
    fn bad_keys_are_refused_by_name() {
        let n = nominal();
        let err = |text: &str| spread(text).validate(&n).unwrap_err().to_string();
        assert!(err("devices = 0").contains("[spread] devices = 0: allowed 1..=100000"));
        assert!(err("devices = 2\nq1 = { rel_sd = 0.5 }").contains("q1.rel_sd = 0.5"));
        assert!(err("devices = 2\nq1 = { sd = -1 }").contains("q1.sd = -1"));
        let both = err("devices = 2\nq1 = { sd = 1, rel_sd = 0.1 }");
        assert_eq!(
            both,
            "[spread] q1: give exactly one of `sd` (absolute) or `rel_sd` (relative)"
        );
        assert!(err("devices = 2\nquadrature_dps = { rel_sd = 0.1 }").contains("give `sd`"));
        assert!(err("devices = 2\nf1_hz = { sd = 6000 }").contains("f1_hz.sd"));
        assert!(err("devices = 2\ntolerance = 0").contains("tolerance"));
        assert!(toml::from_str::<Spread>("devices = 2\nq3 = { sd = 1 }").is_err());
    }

    /// A spread that would draw devices the model refuses more often than
    /// 5 sigma out is refused as a whole, naming the key, each just past
    /// its bound; the bound itself is taken.
    #[test]
    fn a_spread_5_sigma_out_is_still_a_device() {
        let n = nominal();
        let check = |text: &str| spread(&format!("devices = 2\n{text}")).validate(&n);
        let refused = |text: &str, key: &str| {
            let e = check(text).unwrap_err().to_string();
            assert!(e.starts_with(&format!("[spread] {key} = ")), "{text}: {e}");
        };
        // f2 = 25.8 kHz: sqrt(3000^2 + 4000^2) = 5000 Hz is 5 sigma = 25 kHz.
        check("f1_hz = { sd = 3000.0 }\nsplit_hz = { sd = 4000.0 }").unwrap();
        refused(
            "f1_hz = { sd = 3000.0 }\nsplit_hz = { sd = 4200.0 }",
            "split_hz.sd",
        );
        refused("split_hz = { sd = 5200.0 }", "split_hz.sd");
        for (key, bound) in [("q1", 600.0), ("q2", 600.0), ("angular_gain", 0.16)] {
            check(&format!("{key} = {{ sd = {bound} }}")).unwrap();
            refused(
                &format!("{key} = {{ sd = {} }}", bound * 1.001),
                &format!("{key}.sd"),
            );
        }
        for key in ["quadrature_dps", "damping_coupling_dps"] {
            check(&format!("{key} = {{ sd = 2e4 }}")).unwrap();
            refused(&format!("{key} = {{ sd = 2.001e4 }}"), &format!("{key}.sd"));
        }
    }
}
