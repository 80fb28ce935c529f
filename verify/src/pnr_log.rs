//! Reading nextpnr's log: device utilisation, Fmax, the critical path and
//! the first error.
//!
//! The log, not `--report`'s JSON, is read because nextpnr writes the
//! report only after a successful run: a design that does not fit fails
//! in placement, after the utilisation table, which is exactly what the
//! resource figures need. The formats below are those of Debian's
//! nextpnr-ice40 0.4 and YoWASP's nextpnr-ecp5 0.11, which agree on these
//! lines:
//!
//! ```text
//! Info: Device utilisation:
//! Info:          ICESTORM_LC: 11500/ 5280   217%
//! Info: Max frequency for clock 'clk$SB_IO_IN_$glb_clk': 51.60 MHz (PASS at 30.00 MHz)
//!       (0.11 prints `Warning:` instead of `Info:` on a FAIL)
//! Info: Critical path report for clock 'clk$SB_IO_IN_$glb_clk' (posedge -> posedge):
//! Info:  0.54  0.54  Source core.x_SB_DFF_Q_DFFLC.O      (0.4; 0.11 puts a type column first)
//! Info:  ...         Sink core.y_SB_DFF_Q_DFFLC.I0
//! Info: 8.3 ns logic, 11.1 ns routing
//! ```

use regex::Regex;
use std::sync::LazyLock;

/// One line of the utilisation table: a bel type, used and available.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BelUse {
    /// nextpnr's bel type, e.g. `ICESTORM_LC`, `MULT18X18D`.
    pub bel: String,
    /// Cells of this type in the design.
    pub used: u64,
    /// Bels of this type in the part.
    pub available: u64,
}

/// The achieved clock frequency of the last timing analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct Fmax {
    /// nextpnr's name of the clock net.
    pub clock: String,
    /// Maximum frequency in MHz.
    pub mhz: f64,
    /// The `--freq` constraint in MHz.
    pub constraint_mhz: f64,
}

/// The critical register-to-register path of the last timing analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct CriticalPath {
    /// The cell port where the path starts.
    pub from: String,
    /// The cell port where it ends.
    pub to: String,
    /// Delay in cells, ns.
    pub logic_ns: f64,
    /// Delay in routing, ns.
    pub routing_ns: f64,
}

fn strip_info(line: &str) -> &str {
    line.strip_prefix("Info:").unwrap_or(line).trim()
}

/// The first utilisation table in `log` (empty if there is none).
pub fn utilisation(log: &str) -> Vec<BelUse> {
    static ROW: LazyLock<Regex> =
        LazyLock::new(|| Regex::new(r"^([A-Za-z0-9_]+):\s+(\d+)/\s*(\d+)\s+\d+%$").unwrap());
    let mut lines = log
        .lines()
        .skip_while(|l| !l.contains("Device utilisation:"));
    lines.next();
    lines
        .map(strip_info)
        .skip_while(|l| l.is_empty())
        .map_while(|l| ROW.captures(l))
        .map(|c| BelUse {
            bel: c[1].to_owned(),
            used: c[2].parse().unwrap_or(u64::MAX),
            available: c[3].parse().unwrap_or(0),
        })
        .collect()
}

/// The last "Max frequency for clock" line of `log`.
pub fn fmax(log: &str) -> Option<Fmax> {
    static LINE: LazyLock<Regex> = LazyLock::new(|| {
        Regex::new(
            r"Max frequency for clock '([^']*)': ([0-9.]+) MHz \((?:PASS|FAIL) at ([0-9.]+) MHz\)",
        )
        .unwrap()
    });
    let c = log.lines().filter_map(|l| LINE.captures(l)).next_back()?;
    Some(Fmax {
        clock: c[1].to_owned(),
        mhz: c[2].parse().ok()?,
        constraint_mhz: c[3].parse().ok()?,
    })
}

/// The last clock-to-same-clock critical path report of `log`.
pub fn critical_path(log: &str) -> Option<CriticalPath> {
    static SOURCE: LazyLock<Regex> = LazyLock::new(|| Regex::new(r"\bSource (\S+)").unwrap());
    static SINK: LazyLock<Regex> = LazyLock::new(|| Regex::new(r"\bSink (\S+)").unwrap());
    static TOTAL: LazyLock<Regex> =
        LazyLock::new(|| Regex::new(r"^([0-9.]+) ns logic, ([0-9.]+) ns routing$").unwrap());
    let lines: Vec<&str> = log.lines().map(strip_info).collect();
    let start = lines.iter().rposition(|l| {
        l.starts_with("Critical path report for clock") && l.contains("(posedge -> posedge)")
    })?;
    let block = &lines[start + 1..];
    let end = block.iter().position(|l| TOTAL.is_match(l))?;
    let total = TOTAL.captures(block[end])?;
    let from = block[..end].iter().find_map(|l| SOURCE.captures(l))?;
    let to = block[..end].iter().rev().find_map(|l| SINK.captures(l))?;
    Some(CriticalPath {
        from: from[1].to_owned(),
        to: to[1].to_owned(),
        logic_ns: total[1].parse().ok()?,
        routing_ns: total[2].parse().ok()?,
    })
}

/// The first line starting with `ERROR:`, without the prefix.
pub fn first_error(log: &str) -> Option<String> {
    log.lines()
        .find_map(|l| l.strip_prefix("ERROR:"))
        .map(|e| e.trim().to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    const ICE40_04: &str = "\
Info: Packing constants..
Info: Device utilisation:
Info: \t         ICESTORM_LC: 11500/ 5280   217%
Info: \t        ICESTORM_RAM:    12/   30    40%
Info: \t               SB_IO:     3/   96     3%
Info: \t        ICESTORM_DSP:    30/    8   375%
Info: \t      ICESTORM_SPRAM:     0/    4     0%
Info: 
Info: Placed 3 cells based on constraints.
ERROR: Unable to place cell 'x', no BELs remaining to implement cell type 'ICESTORM_DSP'
";

    const ECP5_011: &str = "\
Info: Device utilisation:
Info: \t          TRELLIS_IO:     3/  197     1%
Info: \t        TRELLIS_COMB:  9800/24288    40%
Info: \t          MULT18X18D:    12/   28    42%
Info: 
Warning: Max frequency for clock '$glbnet$clk$TRELLIS_IO_IN': 48.10 MHz (FAIL at 100.00 MHz)
Info: Critical path report for clock '$glbnet$clk$TRELLIS_IO_IN' (posedge -> posedge):
Info:       type curr  total name
Info:   clk-to-q  0.52  0.52 Source core.a_TRELLIS_FF_Q.Q
Info:    routing  0.74  1.26 Net core.a budget 0.000000 ns (2,3) -> (4,5)
Info:                          Sink core.b_CCU2C_A0.A0
Info:      logic  0.40  1.66 Source core.b_CCU2C_A0.COUT
Info:    routing  0.90  2.56 Net core.c
Info:                          Sink core.d_TRELLIS_FF_Q.DI
Info: 0.9 ns logic, 1.6 ns routing
Info: 
Info: Max frequency for clock '$glbnet$clk$TRELLIS_IO_IN': 101.52 MHz (PASS at 100.00 MHz)
Info: Critical path report for clock '<async>' (posedge -> posedge):
Info: Critical path report for clock '$glbnet$clk$TRELLIS_IO_IN' (posedge -> posedge):
Info:   clk-to-q  0.52  0.52 Source core.e_TRELLIS_FF_Q.Q
Info:                          Sink core.f_TRELLIS_FF_Q.DI
Info: 3.1 ns logic, 6.7 ns routing
Info: Critical path report for cross-domain path '<async>' -> 'posedge clk':
";

    #[test]
    fn utilisation_table_is_read_until_its_end() {
        let u = utilisation(ICE40_04);
        assert_eq!(u.len(), 5);
        assert_eq!(
            u[0],
            BelUse {
                bel: "ICESTORM_LC".into(),
                used: 11500,
                available: 5280
            }
        );
        assert_eq!((u[3].used, u[3].available), (30, 8));
        assert_eq!(utilisation(ECP5_011)[1].bel, "TRELLIS_COMB");
        assert!(utilisation("no table").is_empty());
    }

    #[test]
    fn the_last_timing_analysis_counts() {
        let f = fmax(ECP5_011).unwrap();
        assert_eq!((f.mhz, f.constraint_mhz), (101.52, 100.0));
        assert_eq!(f.clock, "$glbnet$clk$TRELLIS_IO_IN");
        let p = critical_path(ECP5_011).unwrap();
        assert_eq!(p.from, "core.e_TRELLIS_FF_Q.Q");
        assert_eq!(p.to, "core.f_TRELLIS_FF_Q.DI");
        assert_eq!((p.logic_ns, p.routing_ns), (3.1, 6.7));
        assert!(fmax(ICE40_04).is_none() && critical_path(ICE40_04).is_none());
    }

    #[test]
    fn errors_are_found() {
        assert!(
            first_error(ICE40_04)
                .unwrap()
                .starts_with("Unable to place cell")
        );
        assert!(first_error(ECP5_011).is_none());
    }
}
