//! Numbers and ranges for the figures: superscripts and subscripts,
//! significant-digit and engineering formats, tick labels, padded axis
//! ranges and clipping of polylines to a band.

pub(super) fn sup(n: i32) -> String {
    n.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            '9' => '⁹',
            c => c,
        })
        .collect()
}

pub(super) fn sub(n: usize) -> char {
    char::from_u32(0x2080 + n as u32).unwrap_or('?')
}

/// `v` with `digits` significant digits as "−6.024×10⁻¹⁶".
pub(super) fn fmt_sci(v: f64, digits: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let e = v.abs().log10().floor() as i32;
    let m = v / 10f64.powi(e);
    let (m, e) = if format!("{:.*}", digits - 1, m.abs()).starts_with("10") {
        (m / 10.0, e + 1)
    } else {
        (m, e)
    };
    let mant = format!("{:.*}", digits - 1, m).replace('-', "−");
    if e == 0 {
        mant
    } else {
        format!("{mant}×10{}", sup(e))
    }
}

/// `v` with up to `digits` significant digits, plain between 10⁻³ and
/// 10⁵ ("1.533", "10"), else as `fmt_sci`.
pub(super) fn fmt_num(v: f64, digits: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let e = v.abs().log10().floor() as i32;
    if !(-3..5).contains(&e) {
        return fmt_sci(v, digits);
    }
    let decimals = (digits as i32 - 1 - e).max(0) as usize;
    let s = format!("{:.*}", decimals, v);
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    s.replace('-', "−")
}

/// Engineering exponent (a multiple of 3) for values up to `max_abs`.
pub(super) fn eng_exponent(max_abs: f64) -> i32 {
    if max_abs > 0.0 && max_abs.is_finite() {
        3 * (max_abs.log10().floor() as i32).div_euclid(3)
    } else {
        0
    }
}

/// A unit with a power of ten in front: "10⁻¹⁸ m²/s²".
pub(super) fn scaled_unit(exp: i32, unit: &str) -> String {
    if exp == 0 {
        unit.to_string()
    } else {
        format!("10{} {unit}", sup(exp))
    }
}

/// Tick labels with as many decimals as a span of `span` over about 8
/// ticks needs.
pub(super) fn tick_formatter(span: f64) -> impl Fn(&f64) -> String {
    let step = span.abs() / 8.0;
    let decimals = if step > 0.0 && step.is_finite() {
        (-step.log10()).ceil().clamp(0.0, 6.0) as usize
    } else {
        0
    };
    move |v: &f64| {
        let s = format!("{:.*}", decimals, v);
        let s = if s
            .trim_start_matches('-')
            .chars()
            .all(|c| c == '0' || c == '.')
        {
            s.trim_start_matches('-').to_string()
        } else {
            s
        };
        s.replace('-', "−")
    }
}

/// [min, max] of `values`, widened by `lo` and `hi` times the span (and
/// never empty).
pub(super) fn padded_range(values: impl IntoIterator<Item = f64>, lo: f64, hi: f64) -> (f64, f64) {
    let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        a = a.min(v);
        b = b.max(v);
    }
    if !(a.is_finite() && b.is_finite()) {
        return (-1.0, 1.0);
    }
    let span = if b > a {
        b - a
    } else if a != 0.0 {
        a.abs() * 0.1
    } else {
        1.0
    };
    (a - lo * span, b + hi * span)
}

/// Pieces of the polyline `pts` inside y in [lo, hi], cut exactly at the
/// bounds (plotters does not clip lines to the plotting area).
pub(super) fn clip_polyline(pts: &[(f64, f64)], lo: f64, hi: f64) -> Vec<Vec<(f64, f64)>> {
    let mut pieces = vec![];
    let mut cur: Vec<(f64, f64)> = vec![];
    let inside = |y: f64| y >= lo && y <= hi;
    let cross = |a: (f64, f64), b: (f64, f64), y: f64| {
        let t = (y - a.1) / (b.1 - a.1);
        (a.0 + t * (b.0 - a.0), y)
    };
    for (i, &p) in pts.iter().enumerate() {
        if i == 0 {
            if inside(p.1) {
                cur.push(p);
            }
            continue;
        }
        let q = pts[i - 1];
        // The part of segment q-p within the band, in order from q to p.
        let mut seg = vec![];
        if inside(q.1) {
            seg.push(q);
        }
        let mut crossings: Vec<(f64, f64)> = [lo, hi]
            .iter()
            .filter(|&&y| (q.1 - y) * (p.1 - y) < 0.0)
            .map(|&y| cross(q, p, y))
            .collect();
        crossings.sort_by(|a, b| ((a.0 - q.0).abs()).total_cmp(&(b.0 - q.0).abs()));
        seg.extend(crossings);
        if inside(p.1) {
            seg.push(p);
        }
        if seg.is_empty() {
            if cur.len() > 1 {
                pieces.push(std::mem::take(&mut cur));
            }
            cur.clear();
            continue;
        }
        if cur.is_empty() {
            cur.extend(seg.iter().copied());
        } else {
            cur.extend(seg.iter().skip(1).copied());
        }
        if !inside(p.1) {
            if cur.len() > 1 {
                pieces.push(std::mem::take(&mut cur));
            }
            cur.clear();
        }
    }
    if cur.len() > 1 {
        pieces.push(cur);
    }
    pieces
}
