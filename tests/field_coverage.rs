//! The field's sigmas are honest: over random devices, none of them a
//! device the field was tuned on, the self-calibrated scale factor lies
//! within 2 and 3 of its reported sigma (self-calibration and the rate
//! table's truth in quadrature, `selfcal_error_uncertainty`) as often as
//! promised (issue 20).
//!
//! Devices. `DEVICES` drawn by `common/random_device.rs` from seeds 2001
//! on in its `FAST` span (10 kHz..10 MHz, Q 100..1e4, split 0..20
//! bandwidths either sign, carrier at a mode or between, clock 2.6 to 40
//! carriers, 2..8 rates, 2..6 calibration frequencies), keeping those
//! with a clock of at most `MAX_CLOCK_HZ` (a field step's cost grows with
//! the clock: these take 0.1 to 1 s each). The run coverage test uses
//! seeds 1001..; the field was tuned on `tests/data/field_*.toml` alone.
//! Each device drifts over two steps, 25 and 35 deg C (`drift`: -30 and
//! -31 ppm/K, Q -2000 ppm/K, a 1 deg front-end phase growing 0.1 deg/K),
//! so each gives four figures, t = selfcal_error / its sigma. Half of them
//! carry a quadrature coupling of +-1 to 300 deg/s (`coupling_of`) that
//! their datasheet does not give, which the cycle measures. The same
//! devices run again with a damping coupling on half of them
//! (`damping_of`, `damping_couplings_lie_within_their_sigmas_as_promised`).
//!
//! What was found with it, and fixed: on seed 2047 (clock 2.6 carriers,
//! Q 960) the identified loop phase lay 4 sigma low and the self-cal
//! error at 3.2 sigma: the fine fit left out the DAC's images, which the
//! ADC folds onto the carrier (`gyrocal_host::images`); the fit and the
//! prediction now carry them (seeds 2082 and 2096, Q 129 and 154 at 3
//! and 3.8 carriers per clock, were at 7.2 and 4.6 sigma). The rate
//! table's part spread with 7 degrees of freedom let one dither seed of
//! the consumer device read at 50 and 100 deg/s sit 5.4 sigma off
//! (`TABLE_WINDOWS`).
//!
//! Assertions, and why they can fail:
//! - Between 90% and 99.5% of all t within 2 (95.4% for normal errors
//!   over honest sigmas; the truth's part spread carries the coverage
//!   factor of its degrees of freedom, 15 or 63). A systematic the budget
//!   misses, of the size of the sigma, puts a normal's 81% within 2;
//!   sigmas twice too large put 99.99% within 2. The four figures of a
//!   device share its identification, so the 160 count as 40 to 160
//!   trials: at 96% a binomial standard deviation of 1.5 to 3%.
//! - Every t within 4, and every t beyond 3 a draw, not a bias: that
//!   device run again at dither seeds 2 to 5 (`REDRAWS`) puts the
//!   figure's mean t within 1.5 (`beyond_three_are_draws`). Not every t
//!   within 3: an honest sigma leaves a figure beyond 3 with probability
//!   0.27%, so 160 figures hold none beyond in only 65% of draws (0.9973
//!   ^ 160), a bound that inflated sigmas pass and honest ones fail a
//!   third of the time. It held while the truth's part spread, over two
//!   windows, was short on some outputs and long on others; since the
//!   table runs to eight windows where its sigma weighs
//!   (`TABLE_EXTENDED_WINDOWS`), the pinned devices read 97.5% within
//!   2, largest |t| 2.56, RMS 0.79 (99.4%, 2.21 and 0.73 before), and
//!   seed 2013 with its damping coupling
//!   (Q 574 / 459, 300 deg/s) reads -3.39 at 25 deg C on output 1. Over
//!   dither seeds 1 to 12 its rate table scattered 4.8e-5 against a
//!   quoted 4.3e-5 and the self-calibration 9.7e-6 against 2.1e-5; seed
//!   1's table is 2.9 of its own sigma from their mean: a draw (at seeds
//!   2 to 5 it reads +0.66, -0.00, -1.24 and -0.71). The mean
//!   of four more t has a standard deviation of 0.5 over an honest sigma,
//!   beyond 1.5 in 0.27% of draws; a bias of 2 sigma, as seed 2096 had
//!   (below), lies beyond it 90% of the time. A t beyond 4 (6e-5 per
//!   honest figure, 1% over 160) fails outright. Seed 2096 (Q 154, 3.8
//!   clocks per carrier), output 1 at 35 deg C, read -0.049% +- 0.014%
//!   (-3.4 sigma) over seeds up to 2100 (85 devices, 340 figures, 97.6%
//!   within 2). Single runs at other front-end lags (-0.013, -0.019,
//!   -0.049, -0.045, -0.040% at 0 to 4 deg) looked erratic; averaged
//!   over noise seeds 1 to 12 the error follows the lag: -0.1e-4,
//!   -0.3e-4, -1.45e-4 (mean t -0.97) and -3.3e-4 (mean t -2.15) at 0, 1,
//!   2 and 4 deg. It was the front end's gain slope across the
//!   calibration's sidebands, which the budget now carries
//!   (`selfcal::budget::front_slope`; docs/field.md has the table): mean
//!   t -0.86 and -0.94 at 2 and 4 deg, and seed 2096 reads -3.0 sigma,
//!   the -2 sigma draw left. Before the front end's delay was in the
//!   identification it read -0.026% +- 0.026%, covered by a Q sigma the
//!   delay's misfit had inflated.
//! - Not inflated: the RMS of t at least 0.3 (an honest set gives about
//!   0.85 to 1).
//! - Every step finishes: a failed step is a clear error, but these
//!   devices are inside the supported ranges.
//!
//! To look at other seeds (one line per device):
//! ```sh
//! GYROCAL_FIELD_SEEDS=2001..2101 cargo test --release --test field_coverage -- --ignored --nocapture explore
//! ```

#[path = "common/random_device.rs"]
mod random_device;

use gyrocal_hdl::host::traffic::Rng;
use gyrocal_sim::coverage::Figure;
use gyrocal_sim::field::scenario::{self, FieldReport};
use random_device::{FAST, RandomDevice};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Devices in the coverage test.
const DEVICES: usize = 40;
/// First seed drawn.
const FIRST_SEED: u64 = 2001;
/// Devices with a faster clock are skipped (cost).
const MAX_CLOCK_HZ: f64 = 3e7;
/// The coverage devices' front-end phase at 25 deg C (deg) and its drift
/// (deg/K).
const LAG: (f64, f64) = (1.0, 0.1);

/// The drift every device goes through, with a front-end phase of `lag`
/// deg at 25 deg C growing `per_k` deg/K.
fn drift(lag: f64, per_k: f64) -> String {
    format!(
        "[drift]\ntemperatures_c = [25, 35]\ntcf1_ppm_per_k = -30.0\n\
         tcf2_ppm_per_k = -31.0\nq_ppm_per_k = -2000\nfront_end_phase_deg = {lag:?}\n\
         front_end_phase_deg_per_k = {per_k:?}\n"
    )
}

/// The scenario of device `d` with a quadrature coupling of `coupling`
/// deg/s and a damping coupling of `damping` deg/s, which its datasheet
/// does not give, through `drift`, with `extra` sections.
fn scenario_text(
    d: &RandomDevice,
    coupling: f64,
    damping: f64,
    drift: &str,
    extra: &str,
) -> String {
    format!(
        "{}{drift}{extra}[datasheet]\nquadrature_dps = 0\ndamping_coupling_dps = 0\n",
        d.toml("").replace(
            "angular_gain =",
            &format!(
                "quadrature_dps = {coupling}\ndamping_coupling_dps = {damping}\nangular_gain ="
            )
        )
    )
}

/// The damping coupling of device `d` (deg/s): none for half the seeds,
/// else a log-uniform fraction 1e-3..0.3 of its stability limit (the
/// geometric mean of the modes' bandwidths, `d^2 < B1 B2`, over 2
/// lambda) and at most 300 deg/s (the quadrature's span), either sign,
/// from splitmix64 of the seed apart from the device's and the
/// quadrature coupling's draws.
fn damping_of(d: &RandomDevice) -> f64 {
    let mut g = Rng(d.seed ^ 0x6a09_e667_f3bc_c909);
    let mut unit = || (g.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    if unit() < 0.5 {
        return 0.0;
    }
    let sign = if unit() < 0.5 { -1.0 } else { 1.0 };
    let fraction = (1e-3f64.ln() + (0.3f64 / 1e-3).ln() * unit()).exp();
    let two_pi = 2.0 * std::f64::consts::PI;
    let bandwidths = (two_pi * d.f_hz[0] / d.q[0]) * (two_pi * d.f_hz[1] / d.q[1]);
    let limit_dps = (bandwidths.sqrt() / (2.0 * d.lambda)).to_degrees();
    format!("{:.4e}", sign * (fraction * limit_dps).min(300.0))
        .parse()
        .unwrap()
}

/// The quadrature coupling of device `seed` (deg/s): none for half the
/// seeds, else +-1..300 deg/s log-uniform (`GYROCAL_FIELD_COUPLING=0`
/// turns them off), from splitmix64 of the seed apart from the device's
/// draws.
fn coupling_of(seed: u64) -> f64 {
    if std::env::var("GYROCAL_FIELD_COUPLING").is_ok_and(|v| v == "0") {
        return 0.0;
    }
    let mut g = Rng(seed ^ 0x9e37_79b9_7f4a_7c15);
    let mut unit = || (g.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    if unit() < 0.5 {
        return 0.0;
    }
    let sign = if unit() < 0.5 { -1.0 } else { 1.0 };
    let magnitude = (300f64.ln() * unit()).exp();
    format!("{:.4e}", sign * magnitude).parse().unwrap()
}

/// The field run of the device of `seed`, with its damping coupling
/// (`damping_of`) when `damping`, or None when its clock is too fast for
/// the test.
fn field(seed: u64, damping: bool) -> Option<(RandomDevice, Arc<FieldReport>)> {
    let d = RandomDevice::draw(seed, FAST);
    if d.clock_hz > MAX_CLOCK_HZ {
        return None;
    }
    let damping = if damping { damping_of(&d) } else { 0.0 };
    let text = scenario_text(&d, coupling_of(seed), damping, &drift(LAG.0, LAG.1), "");
    Some((d, run_once(text)))
}

/// The report of the scenario `text`, run once per test binary: the
/// damping test's devices without a damping coupling (half of them) are
/// the coverage test's runs, text for text, and a run is a function of
/// its text (every noise seeded). Both tests ask side by side; a text
/// asked while it runs waits for that run.
fn run_once(text: String) -> Arc<FieldReport> {
    type Cell = Arc<OnceLock<Arc<FieldReport>>>;
    static RUNS: OnceLock<Mutex<HashMap<String, Cell>>> = OnceLock::new();
    let cell: Cell = {
        let mut runs = RUNS.get_or_init(Default::default).lock().unwrap();
        runs.entry(text.clone()).or_default().clone()
    };
    cell.get_or_init(|| {
        let sc = scenario::parse("random.toml", &text).unwrap();
        Arc::new(scenario::run(&sc, &|_| {}).unwrap())
    })
    .clone()
}

/// Device `d`'s scenario with its (quadrature, damping) couplings and
/// `drift` under each ADC noise seed of `noise_seeds` (`[frontend]
/// seed`): the reports by noise seed, every step finished.
fn under_noise_seeds(
    d: &RandomDevice,
    (coupling, damping): (f64, f64),
    drift: &str,
    noise_seeds: std::ops::RangeInclusive<u64>,
) -> Vec<(u64, FieldReport)> {
    noise_seeds
        .map(|noise_seed| {
            let extra = format!("[frontend]\nseed = {noise_seed}\n");
            let text = scenario_text(d, coupling, damping, drift, &extra);
            let sc = scenario::parse("noise-seeds.toml", &text).unwrap();
            let r = scenario::run(&sc, &|_| {}).unwrap();
            assert!(
                r.failed.is_empty(),
                "noise seed {noise_seed}: {:?}",
                r.failed
            );
            (noise_seed, r)
        })
        .collect()
}

/// t = error / sigma of each step and output.
fn t_values(r: &FieldReport) -> Vec<f64> {
    r.steps
        .iter()
        .flat_map(|s| (0..2).map(move |k| s.selfcal_error[k] / s.selfcal_error_uncertainty[k]))
        .collect()
}

/// The identified parameters with a truth, in `Parameter`'s order (its
/// discriminant is the index), as `identified_t` names them.
const IDENTIFIED: [&str; 6] = ["f1", "f2", "Q1", "Q2", "quadrature", "damping"];

/// Those whose coverage the test asserts (`identified_coverage`).
const ASSERTED: [&str; 4] = ["f1", "f2", "Q1", "Q2"];

/// The identified parameters that have a truth, as (name, t = error /
/// sigma) for each step, against the device at that step: what the
/// sweep's summary scores (`IdentifiedJson::scored`; the damping coupling
/// only on a device that has one).
fn identified_t(r: &FieldReport) -> Vec<Named> {
    r.steps
        .iter()
        .flat_map(|s| s.identified.scored(None, s.temperature_c, &s.truth.gyro))
        .map(|s| match s.figure {
            Figure::Parameter(p) => (IDENTIFIED[p as usize], s.t),
            Figure::Output(_) => unreachable!("scored identifies parameters only"),
        })
        .collect()
}

/// Share within 2, largest |t| and RMS of `t`.
fn coverage(t: &[f64]) -> (f64, f64, f64) {
    let n = t.len() as f64;
    let in2 = t.iter().filter(|x| x.abs() <= 2.0).count() as f64 / n;
    let worst = t.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let rms = (t.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
    (in2, worst, rms)
}

/// One line per device.
fn describe(d: &RandomDevice, r: &FieldReport) -> String {
    let mut line = format!(
        "seed {} {}, coupling {} deg/s, damping {} deg/s, {:.2e} clocks:",
        d.seed,
        d.summary(),
        coupling_of(d.seed),
        r.steps
            .first()
            .map_or(0.0, |s| s.truth.gyro.damping_coupling_dps),
        r.clocks as f64
    );
    for s in &r.steps {
        for k in 0..2 {
            line += &format!(
                " {:+.4}%/{:.4}% t={:+.2}",
                100.0 * s.selfcal_error[k],
                100.0 * s.selfcal_error_uncertainty[k],
                s.selfcal_error[k] / s.selfcal_error_uncertainty[k]
            );
        }
    }
    for s in &r.steps {
        line += &format!(
            " quadrature {:.4} +- {:.4} (true {:.4})",
            s.identified.quadrature_dps,
            s.identified.quadrature_dps_uncertainty,
            s.truth.gyro.quadrature_dps
        );
        line += &format!(
            " damping {:.4} +- {:.4} (true {:.4})",
            s.identified.damping_coupling_dps,
            s.identified.damping_coupling_dps_uncertainty,
            s.truth.gyro.damping_coupling_dps
        );
    }
    for f in &r.failed {
        line += &format!(
            " FAILED at {} deg C ({}): {}",
            f.temperature_c, f.stage, f.error
        );
    }
    line
}

/// An identified parameter's name and t.
type Named = (&'static str, f64);

/// The t of the parameter `name` in `id_t`, in order.
fn named(id_t: &[Named], name: &str) -> Vec<f64> {
    id_t.iter().filter(|p| p.0 == name).map(|p| p.1).collect()
}

/// The `DEVICES` coverage devices' field runs, with their damping
/// couplings when `damping`, each described on stderr: every step's
/// self-calibration t, every identified parameter's t, and the
/// self-calibration t's (share within 2, largest |t|, RMS); and the runs.
fn coverage_runs(damping: bool) -> Coverage {
    let runs: Vec<Run> = (FIRST_SEED..)
        .filter_map(|s| field(s, damping))
        .take(DEVICES)
        .collect();
    let mut t = vec![];
    let mut id_t = vec![];
    for (d, r) in &runs {
        eprintln!("{}", describe(d, r));
        assert!(r.failed.is_empty(), "seed {}: {:?}", d.seed, r.failed);
        t.extend(t_values(r));
        id_t.extend(identified_t(r));
        eprintln!(
            "   id t: {:?}",
            identified_t(r)
                .iter()
                .map(|p| format!("{} {:+.2}", p.0, p.1))
                .collect::<Vec<_>>()
        );
    }
    let (in2, worst, rms) = coverage(&t);
    eprintln!(
        "{} figures: {:.1}% within 2 sigma, largest |t| {worst:.2}, RMS t {rms:.2}",
        t.len(),
        100.0 * in2
    );
    Coverage {
        t,
        id_t,
        in2,
        rms,
        runs,
    }
}

/// A coverage device and its field report.
type Run = (RandomDevice, Arc<FieldReport>);

/// What `coverage_runs` found.
struct Coverage {
    /// Every self-calibration t, step by step, output by output.
    t: Vec<f64>,
    /// Every identified parameter's t (`identified_t`).
    id_t: Vec<Named>,
    /// The share of `t` within 2.
    in2: f64,
    /// The RMS of `t`.
    rms: f64,
    /// The devices and their reports.
    runs: Vec<Run>,
}

/// Dither seeds a figure beyond 3 sigma is drawn again at
/// (`beyond_three_are_draws`).
const REDRAWS: std::ops::RangeInclusive<u64> = 2..=5;

/// The bound on the mean t of a figure's `REDRAWS` (module header).
const REDRAWN_MEAN_T: f64 = 1.5;

/// Every self-calibration t within 4, and each one beyond 3 a draw, not a
/// bias: its device run again at the `REDRAWS` dither seeds (`[frontend]
/// seed`; the first run is seed 1) puts that figure's mean t within
/// `REDRAWN_MEAN_T` (module header: why not every t within 3).
fn beyond_three_are_draws(runs: &[Run], damping: bool) {
    for (d, r) in runs {
        for (i, t) in t_values(r).into_iter().enumerate() {
            if t.abs() <= 3.0 {
                continue;
            }
            let (step, output) = (i / 2, i % 2 + 1);
            let at = format!("seed {} step {step} output {output}", d.seed);
            assert!(t.abs() <= 4.0, "{at} at {t:.2} sigma");
            let couplings = (
                coupling_of(d.seed),
                if damping { damping_of(d) } else { 0.0 },
            );
            let again = under_noise_seeds(d, couplings, &drift(LAG.0, LAG.1), REDRAWS);
            let redrawn: Vec<f64> = again.iter().map(|(_, r)| t_values(r)[i]).collect();
            let mean = redrawn.iter().sum::<f64>() / redrawn.len() as f64;
            eprintln!(
                "{at} at {t:+.2} sigma; at dither seeds {REDRAWS:?}: {redrawn:+.2?}, mean {mean:+.2}"
            );
            assert!(
                mean.abs() <= REDRAWN_MEAN_T,
                "{at} at {t:.2} sigma, and at mean t {mean:.2} over dither seeds {REDRAWS:?}: a bias its sigma misses"
            );
        }
    }
}

#[test]
fn self_calibrated_scale_factors_lie_within_their_sigmas_as_promised() {
    let Coverage {
        t,
        id_t,
        in2,
        rms,
        runs,
    } = coverage_runs(false);
    assert_eq!(t.len(), 4 * DEVICES);
    assert!(
        (0.90..=0.995).contains(&in2),
        "{:.1}% within 2 sigma",
        100.0 * in2
    );
    beyond_three_are_draws(&runs, false);
    assert!(rms >= 0.3, "RMS t {rms:.2}: sigmas inflated");
    identified_coverage(&id_t);
}

/// The identified f1, f2, Q1 and Q2 against each step's device: every t
/// within 3, between 90% and 99.5% of them within 2, and no sigma
/// inflated: each parameter's RMS t at least 0.3 (the issue's rule, no
/// sigma above 5 times its errors' spread, is 0.2).
///
/// What this found: Q1 and Q2 of seeds 2003 and 2025 (modes 4 to 5
/// bandwidths apart, coupled) at 3 to 7.5 sigma, from uncoupling with a
/// pull taken as constant across the sweep (`coupling::uncouple` now
/// refits each sweep with it); with the waits' bounds tightened to what
/// they leave (`identify::settling_residue`, `identify::REF_STEP_PULL`),
/// the residuals' sigma alone left Q at RMS t 2.4 (14% within 2): the
/// jackknife over carriers (`identify::refit`) covers it. Then f1's RMS t
/// was 0.15 (its sigma 6.7 times its errors' spread) and every Q came out
/// high, by 0.86 phi (absolute) at a pick-off lag phi: the front end's
/// group delay, a phase sloping across each sweep, which narrows the
/// fitted resonance and whose misfit had doubled the sigmas of fk
/// (`identify::FrontEnd`, now in the fit's model; with the modes not
/// resolved it is measured at probe points 8 bandwidths each side, where
/// a first-order front end's +-100% had put those Q sigmas 40 times their
/// errors). Pinned then: 98.4% within 2, largest |t| 2.49, RMS t f1 0.64,
/// f2 0.70, Q1 0.74, Q2 0.59. With the table core's carrier lines in the
/// fine sweep's sigma (`identify::point_spur_sd`, counted once beside the
/// residuals' noise) and the waits' terms as sigmas (`REF_STEP_SD`, the
/// settling bound over sqrt 3): 98.8% within 2, largest |t| 2.47, RMS t
/// f1 0.63, f2 0.70, Q1 0.73, Q2 0.60. With the waits still at their
/// bounds, the lines (added in quadrature, or counted once) had put 99.7%
/// within 2, beyond this test's 99.5%. With each wait's residue decaying
/// on through its window (`identify::window_mean`): 97.8% within 2,
/// largest |t| 2.49, RMS t f1 0.67, f2 0.75, Q1 0.79, Q2 0.66. With the
/// settling residue through the fit at its RMS pull (`identify::SETTLE_SD`,
/// where it had been the bound over sqrt 3 for f, Q and the phase alike),
/// pinned now: the same but f2 at 0.76. On these devices the waits' term
/// is small beside the statistical ones; on the high-Q families of
/// docs/sweep.md it had been as large, and f1 read RMS t 0.44 to 0.59.
fn identified_coverage(id_t: &[Named]) {
    let all: Vec<f64> = id_t
        .iter()
        .filter(|p| ASSERTED.contains(&p.0))
        .map(|p| p.1)
        .collect();
    let (in2, worst, rms) = coverage(&all);
    eprintln!(
        "identified f and Q, {} figures: {:.1}% within 2 sigma, largest |t| {worst:.2}, RMS t {rms:.2}",
        all.len(),
        100.0 * in2
    );
    for name in IDENTIFIED {
        let t = named(id_t, name);
        let (in2, worst, rms) = coverage(&t);
        eprintln!(
            "  {name}: {:.1}% within 2, largest |t| {worst:.2}, RMS t {rms:.2}",
            100.0 * in2
        );
    }
    assert!(
        (0.90..=0.995).contains(&in2),
        "identified: {:.1}% within 2 sigma",
        100.0 * in2
    );
    assert!(worst <= 3.0, "an identified parameter at {worst:.2} sigma");
    for name in ASSERTED {
        let t = named(id_t, name);
        let rms = coverage(&t).2;
        assert!(rms >= 0.3, "{name}: RMS t {rms:.2}, its sigma inflated");
    }
    quadrature_coverage(id_t);
}

/// The quadrature coupling measured at rest (`gyrocal_host::coupling`),
/// of the half of the devices that carry one and of the half that do not:
/// its sigma is the spread of 8 batch estimates times the coverage factor
/// of their 7 degrees of freedom, and in deg/s lambda's 1-sigma
/// (`CouplingFigure`; exact here). Asserted: 90% to 99.5% within 2 and an
/// RMS t of at least 0.3, as for f and Q; not yet every t within 3.
///
/// Pinned: 96.2% of 80 within 2, RMS t 0.83, largest |t| 3.40: seed 2011
/// (modes matched, 3.6 deg/s) at 25 deg C, 3.804 +- 0.062 deg/s. Seeds
/// 2001..2100 (170 figures): 97.6% within 2, that one beyond 3, RMS t
/// 0.75, where honest sigmas from 7 degrees of freedom give 0.78. On seed
/// 2011, two sets of windows measured in a row on one board (150 noise
/// seeds, both steps: 300 pairs) differ by 1.107 +- 0.045 times their
/// batch standard errors: output 1's estimate 1.01, output 2's (the cross
/// response to drive 1 at 1/8 of its amplitude, twelve times the noise of
/// output 1's there) 1.12, the z windows themselves 0.99 to 1.13. That is
/// about what z's own memory leaves: adjacent batches share the output
/// filter's (lag-one correlation 0.65 at 8 z samples, none beyond 24), which
/// makes the spread of 8 batches of 64 samples 1.05 times too narrow, and
/// z is white beyond (2^20 samples of the difference of two noise seeds:
/// within 6% from 64 to 2048 samples). The 3.40 is then a Student t draw of
/// some 5 (0.13% at 7 degrees of freedom) on a sigma some 10% small.
fn quadrature_coverage(id_t: &[Named]) {
    let t = named(id_t, "quadrature");
    let (in2, _, rms) = coverage(&t);
    assert!(
        (0.90..=0.995).contains(&in2),
        "quadrature: {:.1}% within 2 sigma",
        100.0 * in2
    );
    assert!(rms >= 0.3, "quadrature: RMS t {rms:.2}, its sigma inflated");
}

/// The damping coupling (`gyrocal_host::coupling`, the imaginary part of
/// the quadrature's estimate) of the half of the devices that carry one
/// (`damping_of`; on the others it is seen as none and reported as 0):
/// at least 90% within 2, every t within 3, an RMS t of at least 0.3.
/// Not the 99.5% ceiling: these are some 40 figures, and 40 figures of a
/// sigma exactly right all fall within 2 in 0.954^40 = 15% of draws
/// (with the spur term of `coupling::spur_lines` they read 100%); the
/// ceiling is the survey's, seeds 2001..2400 (336 figures), 99.4%.
///
/// What this found: with the phasor G_k in the estimate the DAC's images
/// on a detuned output read both couplings 1.6% large at 2.6 clocks per
/// carrier (seeds 2212 and 2360 at 14 to 16 sigma, 2380 at 14 to 21 and
/// its self-calibrated scale factors at -9.3 and +5.0 sigma through the
/// drive-gain ratio measured at rest); seeds 2001..2400 (336 figures)
/// gave 94.6% within 2 and 7 beyond 3. With the images in
/// (`drive_ratio::Folded`): 98.5% within 2, none beyond 3; with the
/// table core's spur lines in the sigma too (`coupling::spur_lines`),
/// 99.4% within 2, none beyond 3, and the quadrature coupling's 664
/// figures 98.5% within 2, one beyond 3 (seed 2218 at 3.09; 97.7% and
/// two beyond before).
fn damping_coverage(id_t: &[Named]) {
    let t = named(id_t, "damping");
    let (in2, worst, rms) = coverage(&t);
    eprintln!(
        "damping, {} figures: {:.1}% within 2 sigma, largest |t| {worst:.2}, RMS t {rms:.2}",
        t.len(),
        100.0 * in2
    );
    assert!(t.len() >= DEVICES / 2, "{} damping figures", t.len());
    assert!(in2 >= 0.90, "damping: {:.1}% within 2 sigma", 100.0 * in2);
    assert!(worst <= 3.0, "damping: a figure at {worst:.2} sigma");
    assert!(rms >= 0.3, "damping: RMS t {rms:.2}, its sigma inflated");
}

/// The same devices with their damping couplings (`damping_of`: half of
/// them, 1e-3 to 0.3 of the stability limit, up to 300 deg/s): the
/// identified coupling covers its truth (`damping_coverage`), and of the
/// self-calibrated scale factors at least 90% lie within 2 of their
/// sigmas, every one within 4, and those beyond 3 are draws
/// (`beyond_three_are_draws`; seed 2013's -3.39, module header). Not
/// asserted here, and why:
/// - the 99.5% ceiling on the scale factors: these 160 read 95.6% within
///   2 (largest |t| 3.39, RMS t 0.87; before the truth ran on to eight
///   windows, 100%, largest 1.95, RMS 0.72), where seeds 2001..2400 with their
///   damping couplings (1328 figures) give 97.8%, of which 160 figures
///   (40 to 160 trials) show none beyond 2 in 3% to 40% of draws. The
///   devices that carry one read RMS t 0.79 there against 0.96 for the
///   same devices without (98.4% and 97.5% within 2): the coupling's
///   sigma in the budget costs some 20% of width, not a twofold;
/// - f and Q, asserted without couplings above: here f2 of seed 2033 (at
///   2.94 clocks per carrier, -11 deg/s) at 35 deg C reads 3.9 sigma high
///   at noise seed 1, and -0.19 and -0.05 at seeds 2 and 3: a sigma of
///   3e-5 Hz some draws exceed, left as found.
#[test]
fn damping_couplings_lie_within_their_sigmas_as_promised() {
    let Coverage {
        id_t,
        in2,
        rms,
        runs,
        ..
    } = coverage_runs(true);
    assert!(in2 >= 0.90, "{:.1}% within 2 sigma", 100.0 * in2);
    beyond_three_are_draws(&runs, true);
    assert!(rms >= 0.3, "RMS t {rms:.2}: sigmas inflated");
    damping_coverage(&id_t);
}

/// Devices at 2.6 to 2.8 clocks per carrier with a damping coupling of
/// 211 and 300 deg/s, where the DAC's images had read the coupling 14 to
/// 21 sigma off and, through the drive-gain ratio measured at rest, the
/// self-calibrated scale factors of seed 2380 9.3 sigma off
/// (`damping_coverage`): now the couplings and every scale factor within
/// 3 of their sigmas.
#[test]
fn the_dac_images_are_in_the_couplings_at_few_clocks_per_carrier() {
    for seed in [2360, 2380] {
        let d = RandomDevice::draw(seed, FAST);
        let text = scenario_text(
            &d,
            coupling_of(seed),
            damping_of(&d),
            &drift(LAG.0, LAG.1),
            "",
        );
        let sc = scenario::parse("random.toml", &text).unwrap();
        let r = scenario::run(&sc, &|_| {}).unwrap();
        assert!(r.failed.is_empty(), "seed {seed}: {:?}", r.failed);
        eprintln!("{}", describe(&d, &r));
        for (name, t) in identified_t(&r) {
            if ["quadrature", "damping"].contains(&name) {
                assert!(t.abs() <= 3.0, "seed {seed}: {name} at {t:.2} sigma");
            }
        }
        let t = t_values(&r);
        assert!(t.iter().all(|x| x.abs() <= 3.0), "seed {seed}: t {t:.2?}");
    }
}

/// A carrier-table spur line that beats slower than the coupling's
/// windows: seed 2258 (2 MHz, Q 9600 / 8100, 3.06 clocks per carrier)
/// without couplings, where at 35 deg C the report names a line 2.8 Hz
/// from the carrier. Each window's mean carries it whole and every batch
/// the same, so the batch spread never saw it: over noise seeds 1 to 8
/// the quadrature coupling read -2.25 to +1.71 deg/s (RMS 1.56) against
/// sigmas of 0.19 to 0.72, up to 10 sigma. The lines in the windows
/// (`coupling::spur_lines`) now enter the sigma, 2.3 to 2.5 deg/s there:
/// every figure within 3 sigma, and RMS t at least 0.3 (a sigma more
/// than three times its error fails it).
#[test]
fn a_slow_spur_line_is_in_the_couplings_sigma() {
    let d = RandomDevice::draw(2258, FAST);
    let mut t = vec![];
    for (noise_seed, r) in under_noise_seeds(&d, (0.0, 0.0), &drift(LAG.0, LAG.1), 1..=8) {
        for (name, x) in identified_t(&r) {
            if ["quadrature", "damping"].contains(&name) {
                assert!(
                    x.abs() <= 3.0,
                    "noise seed {noise_seed}: {name} at {x:.2} sigma"
                );
                if name == "quadrature" {
                    t.push(x);
                }
            }
        }
    }
    let rms = (t.iter().map(|x| x * x).sum::<f64>() / t.len() as f64).sqrt();
    eprintln!("quadrature t {t:.2?}, RMS {rms:.2}");
    assert!(rms >= 0.3, "RMS t {rms:.2}: the sigma inflated");
}

/// The front end's gain slope across the calibration's sidebands
/// (`selfcal::budget::front_slope`): seed 2096 (Q 154, output 1 detuned)
/// behind a pick-off lag of 8 deg at both steps, noise seeds 1 to 6.
/// Before the budget carried the slope there, output 1 sat 5 sigma off
/// (mean t -5.03 over 12 noise seeds; the error, -1.25e-3, grows as the
/// lag squared). The pick-off sits at the end of the bound the term
/// takes, its slope (f / f_ref)^2 = 1.05 times it, so each t was about
/// -1.05 when the term came in: the term (1.28e-3) dwarfs the
/// staircase's sigma (1.1e-4) and the error's spread over seeds
/// (1.5e-4). The budget's later terms widened the sigma a little: the
/// twelve figures read -0.74 to -1.09, mean -0.90 (2026-12-01, `--
/// --nocapture` prints them). Asserted: every |t| within 2 (it was 4.4
/// to 6.1), and the mean |t| at least 0.5 (a sigma more than twice its
/// error would fail it).
#[test]
fn a_large_front_end_lag_is_in_the_sigma() {
    let d = RandomDevice::draw(2096, FAST);
    let mut t = vec![];
    let couplings = (coupling_of(d.seed), 0.0);
    for (_, r) in under_noise_seeds(&d, couplings, &drift(8.0, 0.0), 1..=6) {
        // Output 1 of each step.
        t.extend(t_values(&r).into_iter().step_by(2));
    }
    eprintln!("output 1 at 8 deg of lag, t: {t:.2?}");
    assert!(t.iter().all(|x| x.abs() <= 2.0), "t {t:.2?}");
    let mean = t.iter().map(|x| x.abs()).sum::<f64>() / t.len() as f64;
    assert!(mean >= 0.5, "mean |t| {mean:.2}: the sigma inflated");
}

/// One line per device of `GYROCAL_FIELD_SEEDS` (A..B), for exploring.
#[test]
#[ignore]
fn explore() {
    let seeds = std::env::var("GYROCAL_FIELD_SEEDS").unwrap_or_else(|_| "2001..2011".into());
    let (a, b) = seeds.split_once("..").expect("GYROCAL_FIELD_SEEDS=A..B");
    let range = a.parse::<u64>().unwrap()..b.parse::<u64>().unwrap();
    let mut t = vec![];
    let mut id_t = vec![];
    let damping = std::env::var("GYROCAL_FIELD_DAMPING").map_or(true, |v| v != "0");
    for (d, r) in range.filter_map(|s| field(s, damping)) {
        println!("{}", describe(&d, &r));
        t.extend(t_values(&r));
        id_t.extend(identified_t(&r));
    }
    let line = |what: &str, t: &[f64]| {
        let n = t.len() as f64;
        println!(
            "{what}, {} figures: {:.1}% within 2 sigma, {} beyond 3",
            t.len(),
            100.0 * t.iter().filter(|x| x.abs() <= 2.0).count() as f64 / n,
            t.iter().filter(|x| x.abs() > 3.0).count()
        );
    };
    line("self-calibrated scale factors", &t);
    for name in IDENTIFIED {
        let t = named(&id_t, name);
        line(name, &t);
    }
}

/// The scenario file of device `GYROCAL_FIELD_SEED` as the coverage test
/// runs it, to run alone with `gyrocal field --config FILE`.
#[test]
#[ignore = "prints a scenario, run by hand"]
fn scenario_file() {
    let seed = std::env::var("GYROCAL_FIELD_SEED").map_or(2001, |s| s.parse().unwrap());
    let d = RandomDevice::draw(seed, FAST);
    print!(
        "{}",
        scenario_text(
            &d,
            coupling_of(seed),
            damping_of(&d),
            &drift(LAG.0, LAG.1),
            ""
        )
    );
}
