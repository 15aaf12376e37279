//! Thread stacks for kernel work. The kernel keeps its sample buffers (`PatchSamples<T, CAP>`,
//! 7·CAP values each) on the stack, several per frame, and the tolerance mode recurses once per
//! halving (`Adaptive::max_depth` levels), so the stack a thread needs grows with CAP, the
//! precision and the depth; debug builds (opt-level 0 for the host crate, where the generic
//! kernel is instantiated) need several times more than release. Rayon's worker threads get
//! 2 MiB unless told otherwise, which order 28+ in the tolerance mode (CAP 1024) overflowed.
//!
//! The figures below are measured by `tests/stack_usage.rs` (the smallest
//! `std::thread::Builder::stack_size` on which each entry point completes, binary search in child
//! processes; table and command in VALIDATION.md). [`thread_stack`] gives every thread that runs
//! kernel work twice the measured need for the largest capacity it will use, plus room for the
//! host's and rayon's own frames; the test `host_budgets_cover_the_largest_capacity` checks the
//! factor 2 at CAP = 1024 on every build.

use pdm_kernel::{Real, MAX_ORDER};

/// The capacities the host instantiates: the kernel's [`pdm_kernel::with_capacity`] chooses
/// among them.
pub use pdm_kernel::CAPACITIES;

/// `max_depth` of the tolerance mode in `pdm-ff validate` and `pdm-ff tradeoff`.
pub const ADAPTIVE_MAX_DEPTH: u32 = 6;

/// Kernel need, release: fixed part (bytes). Measured (VALIDATION.md): 148–160 KiB (f32) and
/// 288–308 KiB (f64) at the smallest capacities, where the samples hardly count.
const RELEASE_BASE: usize = 320 << 10;
/// Kernel need, release: bytes per byte of one `PatchSamples<T, CAP>`. Measured: the tolerance
/// mode at depth [`ADAPTIVE_MAX_DEPTH`] grows by ≈ 43 bytes per sample byte (≈ 6.5 buffers
/// per recursion level); 48 bounds every row of the table.
const RELEASE_SAMPLES: usize = 48;
/// The same for debug builds. Measured: 36–344 KiB without the tolerance mode.
const DEBUG_BASE: usize = 512 << 10;
/// The same for debug builds. Measured: ≈ 157 bytes per sample byte at depth 6 (f32, CAP 256
/// and 1024: 1116 and 4416 KiB).
const DEBUG_SAMPLES: usize = 176;

/// Room for the host's and rayon's own frames (job recursion, collection), on top of the
/// kernel's need.
const HOST_FRAMES: usize = 1 << 20;

/// Bytes of one `PatchSamples<T, CAP>` (7 arrays of CAP values and a few scalars).
#[must_use]
pub fn samples_bytes<T>(cap: usize) -> usize {
    7 * cap * core::mem::size_of::<T>() + 64
}

/// The measured stack the kernel's entry points need at capacity `cap` in this build
/// (upper envelope of the table in VALIDATION.md, tolerance mode at [`ADAPTIVE_MAX_DEPTH`]).
#[must_use]
pub fn kernel_need<T>(cap: usize) -> usize {
    let (base, per) =
        if cfg!(debug_assertions) { (DEBUG_BASE, DEBUG_SAMPLES) } else { (RELEASE_BASE, RELEASE_SAMPLES) };
    base + per * samples_bytes::<T>(cap)
}

/// The stack every thread that runs kernel work at capacity `cap` gets: twice
/// [`kernel_need`] plus 1 MiB for the host's own frames, rounded up to a MiB.
#[must_use]
pub fn thread_stack<T: Real>(cap: usize) -> usize {
    let bytes = 2 * kernel_need::<T>(cap) + HOST_FRAMES;
    bytes.div_ceil(1 << 20) << 20
}

/// The capacity the host picks for `order` (the kernel's [`pdm_kernel::capacity_for`] order²,
/// else the largest of [`CAPACITIES`]).
#[must_use]
pub fn capacity_for(order: usize) -> usize {
    pdm_kernel::capacity_for(order.saturating_mul(order)).unwrap_or(MAX_ORDER * MAX_ORDER)
}

/// A rayon pool of `threads` workers (0: as many as the current pool has) whose stacks hold
/// kernel work at capacity `cap` in precision `T`.
pub fn pool<T: Real>(threads: usize, cap: usize) -> Result<rayon::ThreadPool, String> {
    let threads = if threads == 0 { rayon::current_num_threads() } else { threads };
    let stack = thread_stack::<T>(cap);
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .stack_size(stack)
        .thread_name(|i| format!("pdm-worker-{i}"))
        .build()
        .map_err(|e| format!("cannot start {threads} worker threads with {} MiB stacks: {e}", stack >> 20))
}
