//! The memory a reconstruction may use, so running short of it is an error
//! naming what was needed instead of an abort.
//!
//! Two limits count: the memory the system has available and, under an
//! address-space limit (`ulimit -v`, `prlimit --as`), the address space
//! left. The second is spent faster than memory is: every thread that
//! runs a Cholesky factorisation gets faer's dense-kernel workspace
//! (`private-gemm-x86`, twice the L3 cache: 64 MiB on a 32 MiB L3, ~600 MiB
//! on the largest server caches), allocated once and infallibly, and its
//! own malloc arena (64 MiB of address space with glibc, up to 8 per core,
//! also for short-lived threads such as the EXR encoder's). Their size does
//! not depend on the problem and no caller can ask for it fallibly, so the
//! threads are what must fit: [`fit_to_address_space`] sizes a pool to half
//! the address space left, the other half for the data, and caps the
//! arenas at as many.

use sfp_core::{Error, Result};
use std::path::Path;

/// Bytes a reconstruction needs per image pixel, at the least: a third of
/// what every method peaks at (1.1–1.2 KB a pixel between the 512² and
/// 1024² sphere views, Smith, SMSfP, Atkinson and Mahmoud alike: the
/// images, the maps every step keeps, the system and its factor), so only
/// views that cannot fit are refused.
pub const MIN_BYTES_PER_PIXEL: u64 = 400;

/// Refuses, before any work, a `width × height` reconstruction that cannot
/// fit in the memory [`available`] ([`MIN_BYTES_PER_PIXEL`]), with an error
/// saying how much it needs: running out in the middle aborts the process.
pub fn check_reconstruction(width: usize, height: usize) -> Result<()> {
    let needed = (width as u64 * height as u64).saturating_mul(MIN_BYTES_PER_PIXEL);
    match available() {
        Some(available) if needed > available => Err(Error::memory(format!(
            "out of memory: reconstructing a {width}×{height} view needs at least {:.1} GB \
             ({MIN_BYTES_PER_PIXEL} bytes a pixel) but {:.1} GB is available: use a smaller \
             image (e.g. super-pixel demosaicing) or more memory",
            needed as f64 * 1e-9,
            available as f64 * 1e-9
        ))),
        _ => Ok(()),
    }
}

/// Address space each solving thread reserves besides the data: the dense
/// kernels' workspace (twice the L3 cache, [`l3_cache_bytes`]), a malloc
/// arena and a stack.
pub fn per_thread_bytes() -> u64 {
    const ARENA_AND_STACK: u64 = (64 + 2) << 20;
    2 * l3_cache_bytes() + ARENA_AND_STACK
}

/// Under an address-space limit, the threads a pool may have
/// ([`threads_that_fit`]), with glibc's malloc arenas capped at as many;
/// without a limit `wanted` and nothing changed.
pub fn fit_to_address_space(wanted: usize) -> usize {
    let threads = threads_that_fit(wanted);
    if address_space_left().is_some() {
        cap_malloc_arenas(threads);
    }
    threads
}

/// Caps glibc's malloc arenas at `count` (`mallopt(M_ARENA_MAX)`), so
/// threads beyond it share arenas instead of reserving 64 MiB each.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn cap_malloc_arenas(count: usize) {
    const M_ARENA_MAX: std::ffi::c_int = -8;
    unsafe extern "C" {
        fn mallopt(param: std::ffi::c_int, value: std::ffi::c_int) -> std::ffi::c_int;
    }
    let count = std::ffi::c_int::try_from(count).unwrap_or(std::ffi::c_int::MAX);
    // SAFETY: mallopt only sets a tunable of glibc's allocator; any value
    // is accepted (an unknown one is ignored with a 0 return).
    unsafe {
        mallopt(M_ARENA_MAX, count);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn cap_malloc_arenas(_count: usize) {}

/// The number of threads, at most `wanted` (and at least 1), whose
/// [`per_thread_bytes`] fit in half the address space left; `wanted` when
/// there is no address-space limit.
pub fn threads_that_fit(wanted: usize) -> usize {
    let Some(left) = address_space_left() else {
        return wanted;
    };
    let fit = (left / 2 / per_thread_bytes()).max(1);
    wanted
        .min(usize::try_from(fit).unwrap_or(usize::MAX))
        .max(1)
}

/// The threads a rayon pool built with the default count would have:
/// `RAYON_NUM_THREADS` when set to a positive number, else the cores. (Not
/// `rayon::current_num_threads`, which builds the global pool.)
pub fn default_threads() -> usize {
    std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// Bytes a new allocation can count on: the system's available memory
/// (Linux `MemAvailable`) and the address space left, whichever is less;
/// `None` where neither is known.
pub fn available() -> Option<u64> {
    match (mem_available(), address_space_left()) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// `RLIMIT_AS` minus the address space in use, when there is a limit
/// (Linux: `/proc/self/limits`, `/proc/self/status`).
pub fn address_space_left() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    // "Max address space   <soft>   <hard>   bytes": "unlimited" has no number.
    let limit: u64 = line
        .trim_start_matches("Max address space")
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let used = kib_field(Path::new("/proc/self/status"), "VmSize:")?;
    Some(limit.saturating_sub(used))
}

/// `MemAvailable` of `/proc/meminfo`, in bytes.
fn mem_available() -> Option<u64> {
    kib_field(Path::new("/proc/meminfo"), "MemAvailable:")
}

/// The L3 cache of the first processor (Linux sysfs), 32 MiB where unknown:
/// the size the dense kernels size their workspace by.
fn l3_cache_bytes() -> u64 {
    let read = |name: &str| {
        std::fs::read_to_string(format!("/sys/devices/system/cpu/cpu0/cache/{name}")).ok()
    };
    (0..8)
        .find(|i| read(&format!("index{i}/level")).is_some_and(|l| l.trim() == "3"))
        .and_then(|i| read(&format!("index{i}/size")))
        .and_then(|size| {
            let size = size.trim();
            let kib = size.strip_suffix('K')?.parse::<u64>().ok()?;
            Some(kib << 10)
        })
        .unwrap_or(32 << 20)
}

/// A `NAME: <n> kB` field of a `/proc` file, in bytes.
fn kib_field(path: &Path, name: &str) -> Option<u64> {
    let text = std::fs::read_to_string(path).ok()?;
    let line = text.lines().find(|l| l.starts_with(name))?;
    let kib: u64 = line[name.len()..].split_whitespace().next()?.parse().ok()?;
    Some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_view_beyond_the_memory_is_refused_saying_what_it_needs() {
        assert!(check_reconstruction(64, 64).is_ok());
        if available().is_some() {
            let e = check_reconstruction(1 << 30, 1 << 30).unwrap_err();
            assert!(matches!(e, Error::Memory(_)), "{e}");
            assert!(e.to_string().contains("1073741824×1073741824"), "{e}");
        }
    }

    #[test]
    fn threads_are_capped_only_by_a_limit() {
        assert!(per_thread_bytes() >= 66 << 20);
        let fit = threads_that_fit(1000);
        assert!(fit >= 1);
        if address_space_left().is_none() {
            assert_eq!(fit, 1000);
        }
        assert_eq!(threads_that_fit(1), 1);
    }
}
