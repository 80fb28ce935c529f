//! The figures of a run (`src/plots/`): every file is written, each PNG
//! decodes at its size and shows the data (both outputs' colours) and text,
//! each SVG is well-formed and carries its axis labels, files are replaced
//! whole, and a target that cannot be written, or a report that cannot be
//! drawn, is an error naming it, never a panic. The Allan deviation figure
//! is drawn from a synthetic rate series, its readings checked in its text.
//!
//! `cargo test --release --test plots -- --ignored paper_figures
//! --nocapture` draws the paper's run into target/figures-paper (or
//! $GYROCAL_FIGURES_DIR) and prints the time write_figures takes;
//! `-- --ignored allan_figure_to_look_at` draws the synthetic Allan figure
//! into target/figures-allan.

#[path = "../src/plots/mod.rs"]
mod plots;

use gyrocal_sim::allan;
use gyrocal_sim::engine::EngineKind;
use gyrocal_sim::experiment::{Experiment, Mode};
use gyrocal_sim::gyro::GyroParams;
use gyrocal_sim::report::Report;
use gyrocal_sim::report::run;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A scaled device (1 MHz, Q 5000, mode 2 detuned 60 Hz from the carrier):
/// about a second in release, run once for all tests.
fn small_report() -> &'static Report {
    static REPORT: OnceLock<Report> = OnceLock::new();
    REPORT.get_or_init(|| {
        let mut e = Experiment::paper();
        e.gyro = GyroParams {
            f1_hz: 1.0123e6,
            f2_hz: 1.0123e6 + 60.0,
            q1: 5000.0,
            q2: 5000.0,
            angular_gain: 0.6,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
        };
        e.drive.carrier_hz = 1.0123e6;
        e.drive.clock_hz = 10e6;
        e.filter.decimation = Some(250);
        e.points.readout_rates_dps = vec![100.0, 200.0, 300.0, 400.0];
        e.points.cal_freqs_hz = vec![2.0, 4.0, 6.0];
        run(&e, EngineKind::Model, &|_| {}).expect("small run")
    })
}

/// Each figure: name, PNG size, texts its SVG must hold.
const FIGURES: [(&str, (u32, u32), &[&str]); 4] = [
    (
        "fig4_readout",
        (1400, 640),
        &["rotation rate Ω (°/s)", "m²/s²", "SF = ", "exact theory"],
    ),
    (
        "fig5a_staircase",
        (1600, 1000),
        &[
            "time, runs end to end (s)",
            "m²/s²",
            "independent run",
            "averaging window",
            "window mean",
        ],
    ),
    (
        "fig5b_calibration",
        (1400, 640),
        &["virtual rate 360·f_cal (°/s)", "m²/s²", "SF = ", "Hz"],
    ),
    (
        "fig_residuals",
        (1400, 640),
        &[
            "rotation rate Ω (°/s)",
            "virtual rate 360·f_cal (°/s)",
            "ppm",
        ],
    ),
];

/// The colours of output 1 and output 2 in every figure.
const OUTPUT_RGB: [[u8; 3]; 2] = [[31, 119, 180], [214, 39, 40]];

fn decode_png(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let decoder = png::Decoder::new(std::io::BufReader::new(file));
    let mut reader = decoder
        .read_info()
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut buf = vec![0; reader.output_buffer_size().expect("buffer size")];
    let info = reader
        .next_frame(&mut buf)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(info.color_type, png::ColorType::Rgb, "{}", path.display());
    assert_eq!(info.bit_depth, png::BitDepth::Eight, "{}", path.display());
    let pixels = buf[..info.buffer_size()]
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    (info.width, info.height, pixels)
}

/// Tags balance (`<a>` ... `</a>`, `<a/>`), the root is one `<svg>`.
fn check_xml(path: &Path, text: &str) {
    let mut stack: Vec<&str> = vec![];
    let mut roots = 0;
    let mut rest = text;
    while let Some(open) = rest.find('<') {
        let close = rest[open..]
            .find('>')
            .unwrap_or_else(|| panic!("{}: unterminated tag", path.display()))
            + open;
        let tag = &rest[open + 1..close];
        if let Some(name) = tag.strip_prefix('/') {
            let top = stack.pop();
            assert_eq!(top, Some(name.trim()), "{}: </{name}>", path.display());
        } else if !tag.starts_with('?') && !tag.starts_with('!') {
            let name = tag
                .split(|c: char| c.is_whitespace() || c == '/')
                .next()
                .unwrap_or("");
            assert!(!name.is_empty(), "{}: empty tag", path.display());
            if stack.is_empty() {
                roots += 1;
                assert_eq!(name, "svg", "{}: root element", path.display());
            }
            if !tag.ends_with('/') {
                stack.push(name);
            }
        }
        rest = &rest[close + 1..];
    }
    assert!(stack.is_empty(), "{}: unclosed {stack:?}", path.display());
    assert_eq!(roots, 1, "{}: root elements", path.display());
}

/// Characters of the embedded font subset (assets/fonts/README.md).
fn in_font(c: char) -> bool {
    let ranges = [
        (0x20, 0x7e),
        (0xa0, 0xff),
        (0x391, 0x3a9),
        (0x3b1, 0x3c9),
        (0x2010, 0x2015),
        (0x2022, 0x2022),
        (0x2026, 0x2026),
        (0x2070, 0x207f),
        (0x2080, 0x2089),
        (0x2190, 0x2193),
        (0x2206, 0x2206),
        (0x2212, 0x2212),
        (0x221a, 0x221a),
        (0x221e, 0x221e),
        (0x2248, 0x2248),
        (0x2264, 0x2265),
    ];
    ranges.iter().any(|&(a, b)| (a..=b).contains(&u32::from(c)))
}

/// The text content of every `<text>` element.
fn svg_texts(svg: &str) -> Vec<&str> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let body = &t[t.find('>')? + 1..];
            Some(body[..body.find("</text>")?].trim())
        })
        .collect()
}

/// Files in `dir` other than the figures (temporary files left behind).
fn strays(dir: &Path, written: &[PathBuf]) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .expect("read dir")
        .map(|e| e.expect("entry").path())
        .filter(|p| !written.contains(p) && p.is_file())
        .collect()
}

#[test]
fn writes_every_figure_as_png_and_svg() {
    let report = small_report();
    let dir = tempfile::tempdir().expect("temp dir");
    let written = plots::write_figures(report, dir.path()).expect("figures");
    let expected: Vec<PathBuf> = FIGURES
        .iter()
        .flat_map(|(name, _, _)| ["png", "svg"].map(|ext| dir.path().join(format!("{name}.{ext}"))))
        .collect();
    assert_eq!(written, expected);
    assert_eq!(strays(dir.path(), &written), Vec::<PathBuf>::new());

    for (name, (w, h), labels) in FIGURES {
        let png_path = dir.path().join(format!("{name}.png"));
        let (pw, ph, pixels) = decode_png(&png_path);
        assert_eq!((pw, ph), (w, h), "{name}.png size");
        let distinct: HashSet<[u8; 3]> = pixels.iter().copied().collect();
        assert!(
            distinct.len() > 50,
            "{name}.png has {} colours: blank?",
            distinct.len()
        );
        for rgb in OUTPUT_RGB {
            let n = pixels.iter().filter(|p| **p == rgb).count();
            assert!(n > 200, "{name}.png: {n} pixels of {rgb:?}, data not drawn");
        }
        let dark = pixels.iter().filter(|p| p.iter().all(|&c| c < 80)).count();
        assert!(dark > 2000, "{name}.png: {dark} dark pixels, no text?");

        let svg_path = dir.path().join(format!("{name}.svg"));
        let svg = std::fs::read_to_string(&svg_path).expect("svg");
        assert!(
            svg.starts_with(&format!("<svg width=\"{w}\" height=\"{h}\"")),
            "{name}.svg: {}",
            &svg[..svg.len().min(80)]
        );
        check_xml(&svg_path, &svg);
        for label in labels {
            assert!(svg.contains(label), "{name}.svg lacks {label:?}");
        }
        let texts = svg_texts(&svg);
        assert!(texts.len() > 20, "{name}.svg: {} texts", texts.len());
        for text in texts {
            let missing: String = text.chars().filter(|&c| !in_font(c)).collect();
            assert!(
                missing.is_empty(),
                "{name}: {missing:?} in {text:?} is not in the embedded font (assets/fonts/README.md)"
            );
        }
    }

    // Again into the same folder: replaced whole, nothing left behind.
    let again = plots::write_figures(report, dir.path()).expect("figures again");
    assert_eq!(again, written);
    assert_eq!(strays(dir.path(), &written), Vec::<PathBuf>::new());
}

#[test]
fn creates_a_missing_folder() {
    let dir = tempfile::tempdir().expect("temp dir");
    let target = dir.path().join("a").join("b");
    let written = plots::write_figures(small_report(), &target).expect("figures");
    assert!(
        written
            .iter()
            .all(|p| p.starts_with(&target) && p.is_file())
    );
}

#[test]
fn unwritable_folder_is_an_error_naming_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("not-a-folder");
    std::fs::write(&file, "x").expect("write");
    let target = file.join("figures");
    let e = plots::write_figures(small_report(), &target).expect_err("a file in the way");
    assert!(
        matches!(&e, plots::PlotError::Write { path, .. } if *path == target),
        "{e:?}"
    );
    let e = e.to_string();
    assert!(
        e.contains(&target.display().to_string()),
        "error does not name {}: {e}",
        target.display()
    );
    assert!(!e.contains('\n'), "not one line: {e}");
}

#[test]
fn occupied_file_name_is_an_error_naming_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let occupied = dir.path().join("fig5a_staircase.png");
    std::fs::create_dir(&occupied).expect("mkdir");
    let e = plots::write_figures(small_report(), dir.path())
        .expect_err("a folder in the way")
        .to_string();
    assert!(
        e.contains(&occupied.display().to_string()),
        "error does not name {}: {e}",
        occupied.display()
    );
    assert!(!e.contains('\n'), "not one line: {e}");
    // The figures before it were written whole; no temporary file remains.
    let written: Vec<PathBuf> = ["fig4_readout.png", "fig4_readout.svg"]
        .iter()
        .map(|n| dir.path().join(n))
        .collect();
    assert!(written.iter().all(|p| p.is_file()));
    assert_eq!(strays(dir.path(), &written), Vec::<PathBuf>::new());
}

#[test]
fn reports_that_cannot_be_drawn_are_errors() {
    let dir = tempfile::tempdir().expect("temp dir");

    let mut no_trace = small_report().clone();
    for p in &mut no_trace.points {
        p.trace.clear();
    }
    let e = plots::write_figures(&no_trace, dir.path()).expect_err("no traces");
    assert!(matches!(e, plots::PlotError::Data(_)), "{e:?}");
    let e = e.to_string();
    assert!(e.contains("trace"), "{e}");

    let mut nan = small_report().clone();
    nan.points[1].z[1] = f64::NAN;
    let e = plots::write_figures(&nan, dir.path())
        .expect_err("NaN")
        .to_string();
    assert!(e.contains("non-finite"), "{e}");

    let first_readout = small_report()
        .points
        .iter()
        .position(|p| p.mode == Mode::Readout)
        .expect("readout");
    let keep = small_report().points[first_readout].rate_dps;
    let mut one_point = small_report().clone();
    one_point
        .points
        .retain(|p| p.mode != Mode::Readout || p.rate_dps == keep);
    let e = plots::write_figures(&one_point, dir.path())
        .expect_err("one readout point")
        .to_string();
    assert!(e.contains("readout"), "{e}");
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0);
}

#[test]
fn flat_outputs_still_draw() {
    // All window means equal (slope 0): the figures must still come out.
    let mut flat = small_report().clone();
    for p in &mut flat.points {
        p.z = [1e-12, -2e-12];
        p.z_theory = [1e-12, -2e-12];
    }
    flat.scale_factors.sf_read_per_dps = [0.0; 2];
    flat.scale_factors.sf_cal_per_dps = [0.0; 2];
    flat.theory.sf_read_per_dps = [0.0; 2];
    flat.theory.sf_cal_per_dps = [0.0; 2];
    flat.scale_factors.intercept_read = [1e-12, -2e-12];
    flat.scale_factors.intercept_cal = [1e-12, -2e-12];
    let dir = tempfile::tempdir().expect("temp dir");
    plots::write_figures(&flat, dir.path()).expect("flat figures");
}

#[test]
#[ignore = "the paper's run takes several seconds in release"]
fn paper_figures() {
    let report = run(&Experiment::paper(), EngineKind::Model, &|_| {}).expect("paper run");
    let dir = std::env::var("GYROCAL_FIGURES_DIR")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/target/figures-paper").into());
    let start = std::time::Instant::now();
    let files = plots::write_figures(&report, Path::new(&dir)).expect("figures");
    println!(
        "write_figures: {:.3} s for {} files in {dir}",
        start.elapsed().as_secs_f64(),
        files.len()
    );
}

/// Allan analysis of a synthetic rate: white noise (N = 0.05 deg/sqrt(s) =
/// 3 deg/sqrt(h)) plus a slow random walk of the rate, so that the curve
/// falls, bottoms out and rises. A xorshift generator summed to
/// near-Gaussian (12 uniforms less 6) keeps the test free of random crates.
fn synthetic_allan() -> allan::AllanAnalysis {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut normal = move || (0..12).map(|_| uniform()).sum::<f64>() - 6.0;
    let (fs, n) = (100.0, 1 << 18);
    let mut walk = 0.0;
    let rate: Vec<f64> = (0..n)
        .map(|_| {
            walk += 2e-4 * normal();
            0.5 * normal() + walk
        })
        .collect();
    allan::analyze(&rate, fs).expect("analysis")
}

#[test]
fn draws_the_allan_deviation_with_its_readings() {
    let analysis = synthetic_allan();
    let arw = analysis
        .angle_random_walk
        .as_ref()
        .expect("points near 1 s");
    let dir = tempfile::tempdir().expect("temp dir");
    let written = plots::write_allan_figure(
        &analysis,
        "Allan deviation, synthetic rate",
        dir.path(),
        "fig_allan",
    )
    .expect("figure");
    assert_eq!(
        written,
        ["png", "svg"].map(|e| dir.path().join(format!("fig_allan.{e}")))
    );
    let (w, h, pixels) = decode_png(&written[0]);
    assert_eq!((w, h), (1000, 720));
    for rgb in OUTPUT_RGB {
        let n = pixels.iter().filter(|p| **p == rgb).count();
        assert!(
            n > 200,
            "fig_allan.png: {n} pixels of {rgb:?}, data not drawn"
        );
    }
    let svg = std::fs::read_to_string(&written[1]).expect("svg");
    check_xml(&written[1], &svg);
    for label in [
        "cluster time τ (s)",
        "(°/h)",
        "τ^−1/2",
        "°/√h",
        "bias instability",
    ] {
        assert!(svg.contains(label), "fig_allan.svg lacks {label:?}");
    }
    // The readings in the legend are the analysis's, to three significant
    // digits (a rounding of at most 0.5 %).
    let reading = |after: &str| -> f64 {
        let at = svg.find(after).unwrap_or_else(|| panic!("no {after:?}")) + after.len();
        let text: String = svg[at..]
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '.')
            .collect();
        text.parse()
            .unwrap_or_else(|_| panic!("{after:?} is followed by {text:?}"))
    };
    let n = reading("N = ");
    assert!(
        (n / arw.deg_per_sqrt_h - 1.0).abs() < 5e-3,
        "N = {n} against {}",
        arw.deg_per_sqrt_h
    );
    let b = reading("σ_min / 0.664 = ");
    let bi = analysis.bias_instability.deg_per_h;
    assert!((b / bi - 1.0).abs() < 5e-3, "B = {b} against {bi}");
    for text in svg_texts(&svg) {
        let missing: String = text.chars().filter(|&c| !in_font(c)).collect();
        assert!(
            missing.is_empty(),
            "{missing:?} in {text:?} is not in the embedded font"
        );
    }
    assert_eq!(strays(dir.path(), &written), Vec::<PathBuf>::new());
}

#[test]
fn an_allan_analysis_that_cannot_be_drawn_is_an_error() {
    let mut zero = synthetic_allan();
    zero.points[3].adev = 0.0;
    let dir = tempfile::tempdir().expect("temp dir");
    let e = plots::write_allan_figure(&zero, "t", dir.path(), "a")
        .expect_err("zero")
        .to_string();
    assert!(e.contains("positive") && !e.contains('\n'), "{e}");
    zero.points.truncate(1);
    assert!(plots::write_allan_figure(&zero, "t", dir.path(), "a").is_err());
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0);
}

#[test]
#[ignore = "writes into target/ for a look at the Allan figure"]
fn allan_figure_to_look_at() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/target/figures-allan");
    let files = plots::write_allan_figure(
        &synthetic_allan(),
        "Allan deviation, synthetic rate",
        Path::new(dir),
        "fig_allan",
    )
    .expect("figure");
    println!("{files:?}");
}
