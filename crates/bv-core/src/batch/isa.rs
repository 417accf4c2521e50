//! Which instruction set the batch kernels run with: detected once, or forced
//! with the `BV_ISA` environment variable (`scalar`, `avx2`, `avx512`,
//! `neon` or `simd128`) so that every path can be measured and tested on one
//! machine.

use std::fmt;
use std::sync::OnceLock;

/// An instruction set the batch kernels are compiled for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Isa {
    /// One f32 lane at a time, on any CPU.
    Scalar,
    /// x86-64 AVX2 + FMA, 8 lanes.
    Avx2,
    /// x86-64 AVX-512F, 16 lanes.
    Avx512,
    /// AArch64 NEON, 4 lanes.
    Neon,
    /// WebAssembly `simd128`, 4 lanes.
    Simd128,
}

/// `BV_ISA` names an instruction set that is unknown or that this CPU (or
/// this build) does not have.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum IsaError {
    /// Not one of the names.
    #[error("BV_ISA=`{given}` is not an instruction set bv knows: use one of {}", names(&Isa::ALL))]
    Unknown {
        /// What was given (shortened when long).
        given: String,
    },
    /// A known name this CPU or build lacks.
    #[error("BV_ISA={isa}: this CPU or build does not have it; it has {}", names(&Isa::available()))]
    Unavailable {
        /// The instruction set asked for.
        isa: Isa,
    },
}

/// `s`, cut to `max` characters with an ellipsis (a huge value is not
/// echoed back whole).
fn shorten(s: &str, max: usize) -> String {
    if s.chars().count() <= max {
        s.to_string()
    } else {
        let head: String = s.chars().take(max).collect();
        format!("{head}…")
    }
}

fn names(isas: &[Isa]) -> String {
    isas.iter().map(|i| i.name()).collect::<Vec<_>>().join(", ")
}

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Isa {
    /// Every instruction set bv knows, widest first.
    pub const ALL: [Isa; 5] = [Isa::Avx512, Isa::Avx2, Isa::Neon, Isa::Simd128, Isa::Scalar];

    /// The name `BV_ISA` and `bv bench --json` use.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Scalar => "scalar",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
            Isa::Neon => "neon",
            Isa::Simd128 => "simd128",
        }
    }

    /// f32 lanes per vector.
    pub fn lanes(self) -> usize {
        match self {
            Isa::Scalar => 1,
            Isa::Avx2 => 8,
            Isa::Avx512 => 16,
            Isa::Neon | Isa::Simd128 => 4,
        }
    }

    /// Whether kernels run two vectors per step on this path
    /// ([`super::Twice`], for those whose [`super::LaneKernel::TWICE`]
    /// allows it): AVX2 and AVX-512, where it measured faster (see
    /// [`super::twice`]). NEON and `simd128` keep one vector: no machine
    /// here times them (qemu and Node give no real timings).
    pub const fn twice(self) -> bool {
        matches!(self, Isa::Avx2 | Isa::Avx512)
    }

    /// Whether this CPU and build can run it.
    pub fn is_available(self) -> bool {
        match self {
            Isa::Scalar => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "aarch64")]
            Isa::Neon => true,
            #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
            Isa::Simd128 => true,
            #[allow(unreachable_patterns)]
            _ => false,
        }
    }

    /// The instruction sets this CPU and build can run, widest first
    /// (always ending with [`Isa::Scalar`]).
    pub fn available() -> Vec<Isa> {
        Isa::ALL.into_iter().filter(|i| i.is_available()).collect()
    }

    /// The widest available instruction set.
    pub fn best() -> Isa {
        Isa::ALL
            .into_iter()
            .find(|i| i.is_available())
            .unwrap_or(Isa::Scalar)
    }

    /// The instruction set named `s` (case and surrounding space ignored),
    /// if this CPU has it.
    pub fn parse(s: &str) -> Result<Isa, IsaError> {
        let t = s.trim().to_ascii_lowercase();
        let isa = Isa::ALL
            .into_iter()
            .find(|i| i.name() == t)
            .ok_or_else(|| IsaError::Unknown {
                given: shorten(s, 40),
            })?;
        if isa.is_available() {
            Ok(isa)
        } else {
            Err(IsaError::Unavailable { isa })
        }
    }

    /// What the `BV_ISA` environment variable asks for: `None` when it is
    /// unset or empty.
    pub fn from_env() -> Result<Option<Isa>, IsaError> {
        match std::env::var("BV_ISA") {
            Ok(s) if !s.trim().is_empty() => Isa::parse(&s).map(Some),
            Ok(_) | Err(std::env::VarError::NotPresent) => Ok(None),
            Err(std::env::VarError::NotUnicode(s)) => Err(IsaError::Unknown {
                given: shorten(&s.to_string_lossy(), 40),
            }),
        }
    }

    /// The instruction set batches run with in this process: `BV_ISA`'s, or
    /// the best one (read once). A `BV_ISA` that cannot be honoured is an
    /// error here; programs check it at start-up ([`Isa::from_env`]) and
    /// refuse to run, and a library caller that did not gets
    /// [`Isa::best`].
    pub fn selected() -> Isa {
        static SELECTED: OnceLock<Isa> = OnceLock::new();
        *SELECTED.get_or_init(|| Isa::from_env().ok().flatten().unwrap_or_else(Isa::best))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_scalar_is_always_there() {
        for isa in Isa::ALL {
            match Isa::parse(isa.name()) {
                Ok(i) => assert_eq!(i, isa),
                Err(IsaError::Unavailable { isa: i }) => {
                    assert_eq!(i, isa);
                    assert!(!isa.is_available());
                }
                Err(e) => panic!("{isa}: {e}"),
            }
        }
        assert_eq!(Isa::parse(" Scalar\n"), Ok(Isa::Scalar));
        assert_eq!(Isa::available().last(), Some(&Isa::Scalar));
        assert!(Isa::best().is_available());
    }

    #[test]
    fn errors_name_the_choices() {
        let e = Isa::parse("sse9").unwrap_err().to_string();
        assert!(
            e.contains("sse9") && e.contains("avx2") && e.contains("scalar"),
            "{e}"
        );
        let long = "x".repeat(10_000);
        let e = Isa::parse(&long).unwrap_err().to_string();
        assert!(e.len() < 300, "{}", e.len());
        // Some instruction set is missing on every machine (NEON on x86,
        // AVX on ARM): its error lists what this one has.
        let missing = Isa::ALL.into_iter().find(|i| !i.is_available());
        if let Some(m) = missing {
            let e = Isa::parse(m.name()).unwrap_err().to_string();
            assert!(
                e.contains(m.name()) && e.contains("it has") && e.contains("scalar"),
                "{e}"
            );
        }
    }
}
