//! The instruction set the model engine's block runs
//! (`super::gyro_interface::GyroInterface::run`) are compiled for,
//! chosen once per process at run time.
//!
//! The crate is built for the portable x86-64 baseline (SSE2), so that
//! one binary runs on any machine. The block run is compiled twice more
//! and called when the processor has the features:
//!
//! - x86-64-v3 (AVX2, FMA, BMI1/2, LZCNT, MOVBE), where the gyroscope's
//!   4x4 products and the integer stages' passes take four lanes instead
//!   of two;
//! - x86-64-v4 (x86-64-v3 and AVX-512 F, BW, CD, DQ, VL), whose packed
//!   64-bit products (`vpmullq`) and arithmetic shifts (`vpsraq`), which
//!   AVX2 lacks, keep more of the integer stages' i64 passes in vectors.
//!
//! All compile the same source, and none changes a result: the integer
//! arithmetic is exact either way, and Rust never contracts a float
//! multiply and add into an FMA nor reorders a float sum, so each float
//! operation rounds the same in all. The run tests play every supported
//! instruction set against the clock-by-clock `step`.
//!
//! `GYROCAL_ISA=portable` (or `x86-64-v3`, `x86-64-v4`) in the
//! environment overrides the choice, to compare them or to rule a wider
//! one out.
//!
//! ```
//! use gyrocal_hdl::model::isa::Isa;
//! assert!(Isa::Portable.supported());
//! assert!(Isa::supported_all().contains(&Isa::selected()));
//! assert_eq!("x86-64-v3".parse::<Isa>(), Ok(Isa::X86_64V3));
//! assert_eq!("x86-64-v4".parse::<Isa>(), Ok(Isa::X86_64V4));
//! // x86-64-v4 includes x86-64-v3.
//! assert!(!Isa::X86_64V4.supported() || Isa::X86_64V3.supported());
//! ```

use std::fmt;
use std::str::FromStr;
use std::sync::OnceLock;

/// Hands `$then!` its arguments followed by x86-64-v3's target features
/// as a list of string literals. The processor check (`Isa::supported`)
/// and the compiled copy of the block run
/// (`super::gyro_interface::GyroInterface::run_x86_64_v3`) both expand
/// this one list, so they cannot disagree: a copy that used a feature the
/// check left out would stop a processor without it on an illegal
/// instruction.
macro_rules! x86_64_v3_features {
    ($then:ident ! ( $($args:tt)* )) => {
        $then! { $($args)* ["avx2", "fma", "bmi1", "bmi2", "lzcnt", "movbe"] }
    };
}
pub(crate) use x86_64_v3_features;

/// x86-64-v4's target features, as `x86_64_v3_features` gives v3's:
/// x86-64-v3's and AVX-512 F, BW, CD, DQ and VL.
macro_rules! x86_64_v4_features {
    ($then:ident ! ( $($args:tt)* )) => {
        $then! { $($args)* [
            "avx2", "fma", "bmi1", "bmi2", "lzcnt", "movbe",
            "avx512f", "avx512bw", "avx512cd", "avx512dq", "avx512vl"
        ] }
    };
}
pub(crate) use x86_64_v4_features;

/// Whether the processor has every feature of the list.
#[cfg(target_arch = "x86_64")]
macro_rules! all_detected {
    ([$($feature:tt),*]) => {
        true $(&& std::is_x86_feature_detected!($feature))*
    };
}

/// The variable that overrides the choice.
pub const ENV: &str = "GYROCAL_ISA";

/// An instruction set the block run is compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// The build's own target (x86-64: SSE2), any machine.
    Portable,
    /// x86-64-v3: AVX2, FMA, BMI1, BMI2, LZCNT, MOVBE.
    X86_64V3,
    /// x86-64-v4: x86-64-v3 and AVX-512 (F, BW, CD, DQ, VL).
    X86_64V4,
}

/// Why `GYROCAL_ISA` cannot be used.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum IsaError {
    /// Not the name of an instruction set.
    Unknown(String),
    /// An instruction set this processor lacks.
    Unsupported(Isa),
}

impl fmt::Display for IsaError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let allowed = Isa::supported_all()
            .iter()
            .map(|isa| isa.name())
            .collect::<Vec<_>>()
            .join(" or ");
        match self {
            IsaError::Unknown(name) => {
                write!(
                    f,
                    "{ENV} = \"{name}\": not an instruction set; allowed {allowed}"
                )
            }
            IsaError::Unsupported(isa) => write!(
                f,
                "{ENV} = \"{}\": this processor lacks it; allowed {allowed}",
                isa.name()
            ),
        }
    }
}

impl std::error::Error for IsaError {}

impl Isa {
    /// Every instruction set, narrowest first.
    pub const ALL: [Isa; 3] = [Isa::Portable, Isa::X86_64V3, Isa::X86_64V4];

    /// The name `GYROCAL_ISA` takes and reports print.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Portable => "portable",
            Isa::X86_64V3 => "x86-64-v3",
            Isa::X86_64V4 => "x86-64-v4",
        }
    }

    /// Whether this processor runs it.
    pub fn supported(self) -> bool {
        match self {
            Isa::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Isa::X86_64V3 => {
                static V3: OnceLock<bool> = OnceLock::new();
                *V3.get_or_init(|| x86_64_v3_features!(all_detected!()))
            }
            #[cfg(target_arch = "x86_64")]
            Isa::X86_64V4 => {
                static V4: OnceLock<bool> = OnceLock::new();
                *V4.get_or_init(|| x86_64_v4_features!(all_detected!()))
            }
            #[cfg(not(target_arch = "x86_64"))]
            Isa::X86_64V3 | Isa::X86_64V4 => false,
        }
    }

    /// The instruction sets this processor runs, narrowest first.
    pub fn supported_all() -> Vec<Isa> {
        Isa::ALL.into_iter().filter(|isa| isa.supported()).collect()
    }

    /// `GYROCAL_ISA`, if set: the instruction set it names, or why it
    /// cannot be used.
    pub fn from_env() -> Result<Option<Isa>, IsaError> {
        match std::env::var(ENV) {
            Err(_) => Ok(None),
            Ok(name) => {
                let isa: Isa = name.parse()?;
                if isa.supported() {
                    Ok(Some(isa))
                } else {
                    Err(IsaError::Unsupported(isa))
                }
            }
        }
    }

    /// The instruction set runs use: `GYROCAL_ISA` when it names one this
    /// processor runs, else the widest it runs. Decided at the first call.
    /// (A command line checks `from_env` first, and stops with its error.)
    pub fn selected() -> Isa {
        static SELECTED: OnceLock<Isa> = OnceLock::new();
        *SELECTED.get_or_init(|| {
            Isa::from_env()
                .ok()
                .flatten()
                .unwrap_or_else(|| *Isa::supported_all().last().unwrap_or(&Isa::Portable))
        })
    }
}

impl FromStr for Isa {
    type Err = IsaError;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        Isa::ALL
            .into_iter()
            .find(|isa| isa.name() == name)
            .ok_or_else(|| IsaError::Unknown(name.to_string()))
    }
}

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_names_say_what_is_allowed() {
        for isa in Isa::ALL {
            assert_eq!(isa.name().parse::<Isa>(), Ok(isa));
        }
        let e = "avx512".parse::<Isa>().unwrap_err().to_string();
        assert!(
            e.starts_with("GYROCAL_ISA = \"avx512\": not an instruction set; allowed portable")
        );
        let e = IsaError::Unsupported(Isa::X86_64V3).to_string();
        assert!(e.contains("this processor lacks it"), "{e}");
    }
}
