//! The processor instructions this build assumes, checked before any work.
//!
//! On x86-64, `.cargo/config.toml` compiles every crate for x86-64-v3 (AVX2,
//! BMI1/2, F16C, LZCNT, MOVBE: Intel since 2013, AMD since 2015; fused
//! multiply-adds left out, so every output stays bit for bit that of a
//! plain x86-64 build): the path tracer's vector code then runs on
//! three-operand AVX instructions (`benchmarks/scripts/vs_mitsuba.sh`'s
//! scene in 0.91 s instead of 1.08 s).
//! A processor without them would stop the program at its first such
//! instruction with no word of why; the entry points (`sfp`, the Python
//! module) ask [`refusal`] first, so the user reads what to do instead.
//!
//! The processor is asked directly (`cpuid`): `is_x86_feature_detected!`
//! answers "yes" without asking for every feature the build was compiled
//! with. A build without AVX2 (another target, or `RUSTFLAGS` set) checks
//! nothing. The decision uses integer instructions only, and the refusal
//! is a static text, so that the path to the message runs on the oldest
//! x86-64 processor (`cli/tests/instruction_set.rs` runs it on an emulated
//! one).

/// What a processor without the build's instructions is told.
const REFUSAL: &str = "this build of polar-sfp needs an x86-64-v3 processor \
(AVX2, BMI1/2, F16C, LZCNT, MOVBE), which this machine is not; build it \
for this machine with RUSTFLAGS=\"-C target-cpu=native\" set (`cargo install \
--locked --path cli`, `pip install ./python`; README, \"Set up\")";

/// The message to stop with when the processor lacks instructions this
/// build was compiled for; `None` when it has them all.
pub fn refusal() -> Option<&'static str> {
    (cfg!(target_feature = "avx2") && !has_x86_64_v3()).then_some(REFUSAL)
}

/// Whether the processor, and the operating system's saving of its
/// registers, support what the build uses of x86-64-v3: all of it but
/// the fused multiply-adds it is compiled without (Intel's manual, vol.
/// 2A, CPUID).
#[cfg(target_arch = "x86_64")]
fn has_x86_64_v3() -> bool {
    use std::arch::x86_64::{__cpuid, __cpuid_count, _xgetbv};
    let all = |word: u32, bits: &[u32]| bits.iter().all(|&n| word >> n & 1 == 1);
    if __cpuid(0).eax < 7 || __cpuid(0x8000_0000).eax < 0x8000_0001 {
        return false;
    }
    // Leaf 1, ECX: SSE3, SSSE3, CMPXCHG16B, SSE4.1, SSE4.2, MOVBE, POPCNT,
    // XSAVE, OSXSAVE, AVX, F16C. Leaf 7, EBX: BMI1, AVX2, BMI2.
    // Leaf 0x8000_0001, ECX: LAHF/SAHF, LZCNT.
    let leaves = all(__cpuid(1).ecx, &[0, 9, 13, 19, 20, 22, 23, 26, 27, 28, 29])
        && all(__cpuid_count(7, 0).ebx, &[3, 5, 8])
        && all(__cpuid(0x8000_0001).ecx, &[0, 5]);
    // The operating system saves the SSE and AVX registers (XCR0 bits 1
    // and 2).
    // SAFETY: XGETBV is enabled once OSXSAVE is set, which `leaves` checked.
    leaves && unsafe { _xgetbv(0) } & 0b110 == 0b110
}

#[cfg(not(target_arch = "x86_64"))]
fn has_x86_64_v3() -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The machine that runs the tests ran the build's instructions to get
    /// here, so it must not be refused. (The refusal itself is checked on
    /// an emulated processor without AVX: `cli/tests/instruction_set.rs`.)
    #[test]
    fn the_machine_that_runs_the_tests_is_not_refused() {
        assert_eq!(refusal(), None);
        if cfg!(target_feature = "avx2") {
            assert!(has_x86_64_v3());
        }
    }
}
