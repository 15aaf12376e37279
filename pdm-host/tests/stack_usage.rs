//! The stack the kernel's entry points need, measured: each workload runs on a thread made with
//! `std::thread::Builder::stack_size(n)` in a child process (this test binary, re-run with
//! `PDM_STACK_PROBE` set), and a binary search finds the smallest `n` (to 4 KiB) for which it
//! completes; a stack overflow aborts only the child. The figure therefore includes the thread's
//! own start-up frames and glibc's TLS, i.e. it is what a host thread must be given.
//!
//! * `host_budgets_cover_the_largest_capacity` (fast, runs with the suite): every entry point at
//!   the largest capacity the host uses (CAP = 1024), and the adaptive mode at its depth limit,
//!   complete on a thread of half the stack the host gives (`pdm_host::validate::stack`), in
//!   the build's profile.
//! * `stack_table` (ignored, ≈ 8 min on a busy 2-core machine): the full table of
//!   VALIDATION.md, `cargo test --release -p pdm-host --test stack_usage -- --ignored
//!   --nocapture`; `PDM_STACK_CAPS=256,1024` restricts the capacities (debug builds are slow).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::process::Command;

use pdm_host::validate::scene::Scene;
use pdm_host::validate::stack;
use pdm_kernel::{
    adaptive_exchange, pair_exchange, surface_form_factor, Adaptive, PairSettings, ParamRect, Patch, PatchGrid,
    Quadrature, Real, MAX_ORDER,
};

const ENV: &str = "PDM_STACK_PROBE";

/// A workload: entry point (and geometry), precision, capacity, adaptive depth limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Probe {
    entry: Entry,
    f64: bool,
    cap: usize,
    depth: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Entry {
    /// `surface_form_factor`: sphere 2 × 4 → face 1 whole, the sphere as occluder.
    Surface,
    /// `pair_exchange`, face 1 quadrant → face 2 quadrant sharing an edge, sphere occluder.
    PairEdge,
    /// `pair_exchange`, face 1 → face 6 (opposite), sphere occluder: the boundary path.
    PairShadow,
    /// `pair_exchange`, a sphere cell → face 2 across the back-face cut: the boundary path.
    PairCurved,
    /// `adaptive_exchange`, the edge pair of `PairEdge` (split 2 × 2 while the sphere may cut).
    AdaptiveEdge,
    /// `adaptive_exchange`, the opposite faces of `PairShadow` (halving across boundaries).
    AdaptiveShadow,
}

const ENTRIES: [Entry; 6] =
    [Entry::Surface, Entry::PairEdge, Entry::PairShadow, Entry::PairCurved, Entry::AdaptiveEdge, Entry::AdaptiveShadow];

impl Entry {
    fn name(self) -> &'static str {
        match self {
            Self::Surface => "surface",
            Self::PairEdge => "pair-edge",
            Self::PairShadow => "pair-shadow",
            Self::PairCurved => "pair-curved",
            Self::AdaptiveEdge => "adaptive-edge",
            Self::AdaptiveShadow => "adaptive-shadow",
        }
    }
    fn adaptive(self) -> bool {
        matches!(self, Self::AdaptiveEdge | Self::AdaptiveShadow)
    }
}

impl Probe {
    fn spec(self, bytes: usize) -> String {
        format!("{},{},{},{},{bytes}", self.entry.name(), if self.f64 { "f64" } else { "f32" }, self.cap, self.depth)
    }

    fn parse(s: &str) -> (Self, usize) {
        let f: Vec<&str> = s.split(',').collect();
        let entry = ENTRIES.into_iter().find(|e| e.name() == f[0]).unwrap();
        let probe = Self { entry, f64: f[1] == "f64", cap: f[2].parse().unwrap(), depth: f[3].parse().unwrap() };
        (probe, f[4].parse().unwrap())
    }

    /// Runs the workload (in the child).
    fn run(self) {
        if self.f64 {
            self.run_in::<f64>();
        } else {
            self.run_in::<f32>();
        }
    }

    fn run_in<T: Real>(self) {
        match self.cap {
            25 => workload::<T, 25>(self.entry, self.depth),
            64 => workload::<T, 64>(self.entry, self.depth),
            144 => workload::<T, 144>(self.entry, self.depth),
            256 => workload::<T, 256>(self.entry, self.depth),
            576 => workload::<T, 576>(self.entry, self.depth),
            1024 => workload::<T, 1024>(self.entry, self.depth),
            c => panic!("no capacity {c}"),
        }
    }
}

/// The workload at capacity `CAP`: the order is the largest with order² ≤ CAP (the adaptive
/// mode: max_order 12 as in `pdm-ff validate`, tolerance far below reach so every level splits).
fn workload<T: Real, const CAP: usize>(entry: Entry, depth: u32) {
    let order = (1..=MAX_ORDER).take_while(|p| p * p <= CAP).last().unwrap();
    let scene = Scene::<T>::new(1.0).unwrap();
    let sphere = scene.sphere.unwrap();
    let [f1, f2, _, _, _, f6] = &scene.faces;
    let h = T::from_f64(0.5);
    let (zero, one) = (T::ZERO, T::ONE);
    // Face 1 (y from −3 at t = 0) and face 2 (z = +3 at t = 1) share the edge y = −3, z = 3.
    let q1 = Patch::new(f1, ParamRect { t0: zero, t1: h, s0: zero, s1: h }).unwrap();
    let q2 = Patch::new(f2, ParamRect { t0: h, t1: one, s0: zero, s1: h }).unwrap();
    let (w1, w6) = (Patch::whole(f1).unwrap(), Patch::whole(f6).unwrap());
    let quarter = T::PI * T::from_f64(0.25);
    let cell = Patch::new(&sphere, ParamRect { t0: quarter, t1: T::PI * h, s0: T::PI, s1: T::PI + quarter }).unwrap();
    let settings = PairSettings { order, singular_order: MAX_ORDER, boundaries: true };
    let tolerance = T::from_f64(if T::MANTISSA_DIGITS == 24 { 1e-7 } else { 1e-14 });
    let adaptive = Adaptive { tolerance, max_order: 12, max_depth: depth, absolute: T::ZERO };
    let value = match entry {
        Entry::Surface => surface_form_factor::<T, _, _, _, CAP>(
            PatchGrid::new(&sphere, 2, 4).unwrap(),
            PatchGrid::new(f1, 1, 1).unwrap(),
            Quadrature::uniform(order),
            &sphere,
        ),
        Entry::PairEdge => pair_exchange::<T, _, _, _, CAP>(&q1, &q2, settings, &sphere).map(|e| e.value),
        Entry::PairShadow => pair_exchange::<T, _, _, _, CAP>(&w1, &w6, settings, &sphere).map(|e| e.value),
        Entry::PairCurved => pair_exchange::<T, _, _, _, CAP>(&cell, &w1, settings, &()).map(|e| e.value),
        Entry::AdaptiveEdge => adaptive_exchange::<T, _, _, _, CAP>(&q1, &q2, adaptive, &sphere).map(|e| e.value),
        Entry::AdaptiveShadow => adaptive_exchange::<T, _, _, _, CAP>(&w1, &w6, adaptive, &sphere).map(|e| e.value),
    };
    let value = value.unwrap_or_else(|e| panic!("KERNEL-ERROR {entry:?}: {e}"));
    assert!(value.is_finite());
}

/// The child: runs the probe named in `PDM_STACK_PROBE` on a thread of the given stack size.
/// Without the variable this test does nothing.
#[test]
fn child() {
    let Ok(spec) = std::env::var(ENV) else { return };
    let (probe, bytes) = Probe::parse(&spec);
    let worker = std::thread::Builder::new().stack_size(bytes).spawn(move || probe.run()).unwrap();
    worker.join().unwrap();
    println!("PROBE-OK");
}

/// `true` if the probe completes on a thread of `bytes` stack; a kernel error is a failure of
/// the test, not of the stack.
fn fits(probe: Probe, bytes: usize) -> bool {
    let out = Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "child", "--nocapture", "--test-threads=1"])
        .env(ENV, probe.spec(bytes))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("KERNEL-ERROR"), "{probe:?}: {stderr}");
    let ok = out.status.success() && String::from_utf8_lossy(&out.stdout).contains("PROBE-OK");
    assert!(ok || stderr.contains("overflowed its stack"), "{probe:?} failed for another reason: {stderr}");
    ok
}

/// The smallest stack (to 4 KiB) on which the probe completes.
fn measure(probe: Probe) -> usize {
    const STEP: usize = 4 << 10;
    let mut hi = 256 << 10;
    while !fits(probe, hi) {
        hi *= 2;
        assert!(hi <= 1 << 30, "{probe:?} does not fit in 1 GiB");
    }
    let mut lo = 16 << 10; // below glibc's minimum nothing runs
    while hi - lo > STEP {
        let mid = (lo + hi) / 2 / STEP * STEP;
        if fits(probe, mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

fn kib(bytes: usize) -> String {
    format!("{} KiB", bytes.div_ceil(1024))
}

/// The host's stack for the capacity and precision, halved: the margin the host promises.
fn half_budget(f64: bool, cap: usize) -> usize {
    let bytes = if f64 { stack::thread_stack::<f64>(cap) } else { stack::thread_stack::<f32>(cap) };
    bytes / 2
}

#[test]
fn host_budgets_cover_the_largest_capacity() {
    if std::env::var(ENV).is_ok() {
        return;
    }
    for f64 in [false, true] {
        for entry in ENTRIES {
            let depth = if entry == Entry::AdaptiveEdge { 2 } else { stack::ADAPTIVE_MAX_DEPTH };
            let probe = Probe { entry, f64, cap: 1024, depth: if entry.adaptive() { depth } else { 0 } };
            let budget = half_budget(f64, 1024);
            assert!(fits(probe, budget), "{probe:?} needs more than half the host's stack ({})", kib(budget));
        }
    }
}

/// The capacities of the table: `PDM_STACK_CAPS` (comma-separated) or all the host uses.
fn capacities() -> Vec<usize> {
    match std::env::var("PDM_STACK_CAPS") {
        Ok(list) => list.split(',').map(|c| c.trim().parse().unwrap()).collect(),
        Err(_) => stack::CAPACITIES.to_vec(),
    }
}

/// The full table: bytes per entry point, precision and capacity (adaptive: per depth, and
/// the depth limit extrapolated from depths 0–2 of the edge pair, which splits 16-fold per
/// level and is too slow deeper).
#[test]
#[ignore = "≈ 8 min: cargo test --release -p pdm-host --test stack_usage -- --ignored --nocapture"]
fn stack_table() {
    if std::env::var(ENV).is_ok() {
        return;
    }
    let profile = if cfg!(debug_assertions) { "debug" } else { "release" };
    println!("stack needed ({profile}), smallest std::thread::Builder::stack_size that completes, 4 KiB steps");
    println!("| entry point | T | CAP | bytes | host gives |");
    println!("| --- | --- | --- | --- | --- |");
    for f64 in [false, true] {
        let t = if f64 { "f64" } else { "f32" };
        for cap in capacities() {
            let host = 2 * half_budget(f64, cap);
            let mut worst = 0;
            for entry in ENTRIES.into_iter().filter(|e| !e.adaptive()) {
                let need = measure(Probe { entry, f64, cap, depth: 0 });
                worst = worst.max(need);
                println!("| {} | {t} | {cap} | {} | {} |", entry.name(), kib(need), kib(host));
            }
            if cap >= 256 {
                let at = |entry, depth| measure(Probe { entry, f64, cap, depth });
                let edge: Vec<usize> = (0..=2).map(|d| at(Entry::AdaptiveEdge, d)).collect();
                let per_level = (edge[2] - edge[0]) / 2;
                let extrapolated = edge[2] + (stack::ADAPTIVE_MAX_DEPTH as usize - 2) * per_level;
                let shadow = at(Entry::AdaptiveShadow, stack::ADAPTIVE_MAX_DEPTH);
                println!(
                    "| adaptive-edge depth 0/1/2 | {t} | {cap} | {} / {} / {} (+{} per level; depth {}: {}) | {} |",
                    kib(edge[0]),
                    kib(edge[1]),
                    kib(edge[2]),
                    kib(per_level),
                    stack::ADAPTIVE_MAX_DEPTH,
                    kib(extrapolated),
                    kib(host)
                );
                println!(
                    "| adaptive-shadow depth {} | {t} | {cap} | {} | {} |",
                    stack::ADAPTIVE_MAX_DEPTH,
                    kib(shadow),
                    kib(host)
                );
                worst = worst.max(extrapolated).max(shadow);
            }
            assert!(2 * worst <= host, "{t} CAP {cap}: needs {}, the host gives {}", kib(worst), kib(host));
        }
    }
}
