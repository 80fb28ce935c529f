//! The three engines are one design: identical outputs on every clock of a
//! co-simulation with the gyroscope in the loop, and identical experiment
//! results.

#[cfg(not(feature = "verilator"))]
#[test]
fn verilator_engine_is_built() {
    panic!(
        "these tests need the Verilator engine: run with --features verilator \
         (and the Debian package `verilator` installed), as scripts/test.sh does"
    );
}

#[cfg(feature = "verilator")]
mod with_verilator {
    use gyrocal_hdl::model::gyro_interface::{CarrierProfile, Outputs};
    use gyrocal_sim::cosim::CoSim;
    use gyrocal_sim::engine::{Engine, EngineKind, ModelEngine};
    use gyrocal_sim::experiment::{self, Experiment, Plan};
    use gyrocal_sim::gyro::GyroParams;
    use gyrocal_sim::verilator::VerilatorEngine;

    /// A fast scaled device: 1.0123 MHz modes 300 Hz apart, 10 MHz clock.
    fn small_device() -> Experiment {
        let mut e = Experiment::paper();
        e.gyro = GyroParams {
            f1_hz: 1.0123e6,
            f2_hz: 1.0126e6,
            q1: 3000.0,
            q2: 2500.0,
            angular_gain: 0.6,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
        };
        e.drive.carrier_hz = 1.0123e6;
        e.drive.clock_hz = 10e6;
        e.filter.decimation = Some(250);
        e.points.readout_rates_dps = vec![20.0, 40.0];
        e.points.cal_freqs_hz = vec![3.0, 5.0];
        e
    }

    fn cosim<E: Engine>(exp: &Experiment, plan: &Plan, point: usize) -> CoSim<E> {
        experiment::point_loop::<E>(exp, plan, &plan.points[point]).unwrap()
    }

    #[test]
    fn model_equals_verilator_for_ten_million_clocks_with_the_gyro_in_the_loop() {
        // 5 M clocks of readout at 40 deg/s, then 5 M of calibration at 5 Hz,
        // each from power-up: every port on every clock, plus the internal
        // probes every 997 clocks.
        let exp = small_device();
        let plan = experiment::plan(&exp).unwrap();
        let mut compared = 0u64;
        for point in [1, 3] {
            same_on_every_clock(&exp, &plan, point, 5_000_000, |_| compared += 1);
        }
        assert_eq!(compared, 10_000_000);
    }

    /// The model and Verilator engines side by side from power-up at
    /// `point` for `clocks`: every port on every clock, the internal probes
    /// every 997 clocks. `each` sees the ports of every clock.
    fn same_on_every_clock(
        exp: &Experiment,
        plan: &Plan,
        point: usize,
        clocks: u64,
        mut each: impl FnMut(&Outputs),
    ) {
        let mut model = cosim::<ModelEngine>(exp, plan, point);
        let mut verilated = cosim::<VerilatorEngine>(exp, plan, point);
        for n in 1..=clocks {
            let (a, b) = (model.step(), verilated.step());
            assert_eq!(a, b, "point {point}, clock {n}");
            if n % 997 == 0 {
                assert_eq!(
                    model.engine().probes(),
                    verilated.engine().probes(),
                    "probes, clock {n}"
                );
            }
            each(&a);
        }
    }

    #[test]
    fn one_experiment_gives_identical_results_on_all_three_engines() {
        // A tiny device (Q 150, short windows) so that rust-hdl's simulation
        // runs it in seconds: four points of 5,000-57,000 clocks (a
        // calibration window is 8 periods of its 2 f_cal ripple). One round
        // of windows: a budget too small for a second one, so that the
        // engines' different speeds cannot change the plan.
        let reports = on_all_three_engines(&tiny_device());
        // 107,923 clocks measured: at R = 166 the calibration ripple allows
        // at most ~1.5 kHz, and windows of 8 ripple periods at 700 Hz are
        // longer than the 2 kHz ones at R = 16 were (under 80,000 then);
        // each point also waits 8,232 clocks for the carrier tables, then
        // settles (`gyrocal_sim::settling`: the resonator's and the
        // filters' transients decay at once, not one after the other as
        // before, 133,953 clocks then).
        eprintln!("tiny experiment: {} clocks", reports[0].timing.cycles);
        assert!(
            reports[0].timing.cycles < 115_000,
            "{} clocks",
            reports[0].timing.cycles
        );
        assert_identical(&reports);
    }

    /// The tiny device of the test above.
    fn tiny_device() -> Experiment {
        let mut exp = small_device();
        exp.gyro.q1 = 150.0;
        exp.gyro.q2 = 150.0;
        // The least decimation the filter takes; cut-offs within f_z / 5
        // and calibration ripples (2 f_cal) sampled 20 times per period.
        exp.filter.decimation = Some(gyrocal_hdl::filter_design::MIN_DECIMATION);
        exp.filter.butterworth_hz = Some(5e3);
        exp.filter.rc_hz = Some(10e3);
        exp.points.cal_freqs_hz = vec![700.0, 1400.0];
        exp.points.min_window_s = Some(5e-4);
        exp.points.budget_s = 1e-6;
        exp
    }

    /// `exp` on the model, Verilator and rtl engines, in that order.
    fn on_all_three_engines(exp: &Experiment) -> Vec<gyrocal_sim::report::Report> {
        [EngineKind::Model, EngineKind::Verilator, EngineKind::Rtl]
            .into_iter()
            .map(|engine| gyrocal_sim::report::run(exp, engine, &|_| {}).unwrap())
            .collect()
    }

    /// Every point's z, batches and trace, and the figures, the same on
    /// every engine; and not vacuous.
    fn assert_identical(reports: &[gyrocal_sim::report::Report]) {
        for r in &reports[1..] {
            assert_eq!(r.points.len(), reports[0].points.len());
            for (p, q) in r.points.iter().zip(&reports[0].points) {
                assert_eq!(p.z_lsb, q.z_lsb, "{}", r.timing.engine);
                assert_eq!(p.batch_z, q.batch_z, "{}", r.timing.engine);
                assert_eq!(p.trace, q.trace, "{}", r.timing.engine);
            }
            assert_eq!(
                (
                    r.scale_factors.sf_read_per_dps,
                    r.scale_factors.sf_cal_per_dps,
                    r.scale_factors.ratio
                ),
                (
                    reports[0].scale_factors.sf_read_per_dps,
                    reports[0].scale_factors.sf_cal_per_dps,
                    reports[0].scale_factors.ratio
                )
            );
        }
        // Not vacuous: the outputs moved with rate and calibration frequency.
        assert!(
            reports[0].scale_factors.sf_read_per_dps[0] != 0.0
                && reports[0].scale_factors.sf_cal_per_dps[1] != 0.0
        );
    }

    #[test]
    fn the_fine_core_is_one_design_on_all_three_engines() {
        // `[drive] carrier_profile = "fine"`: the model, the exported
        // verilog-out/ecp5/gyro_interface.v in Verilator and rust-hdl's
        // FineGyroInterface. Every port on every clock of 1 M clocks of
        // readout and 1 M of calibration with the gyroscope in the loop
        // (probes every 997), then the tiny experiment on all three.
        let mut exp = small_device();
        exp.drive.carrier_profile = CarrierProfile::Fine;
        let plan = experiment::plan(&exp).unwrap();
        let mut table = cosim::<ModelEngine>(&small_device(), &plan, 1);
        let mut differ = 0u64;
        same_on_every_clock(&exp, &plan, 1, 1_000_000, |a| {
            differ += u64::from(table.step() != *a)
        });
        same_on_every_clock(&exp, &plan, 3, 1_000_000, |_| {});
        // Not the table core under another name.
        assert!(
            differ > 1000,
            "the fine core's ports differed from the table core's on {differ} clocks"
        );
        let mut tiny = tiny_device();
        tiny.drive.carrier_profile = CarrierProfile::Fine;
        assert_identical(&on_all_three_engines(&tiny));
    }
}
