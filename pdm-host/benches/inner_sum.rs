//! The PDM inner sum (eq. 16) on two precomputed patches: evaluations per second.
//!
//! `cargo bench -p pdm-host --bench inner_sum -- --warm-up-time 1 --measurement-time 3`
//!
//! Two unit squares facing each other at distance 1, sampled at order p (p² samples each), so
//! one `form_factor` call makes p⁴ kernel evaluations; criterion reports them as elements/s.
//! Every sample pair passes the curvature test. "occluded": a sphere of radius 0.2 between the
//! squares, so the occluded loop runs (an exact segment–sphere test per visible pair; about 4 %
//! of the pairs are blocked). Single-threaded: the figure is per core.

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use pdm_kernel::{form_factor, vec3, Parallelogram, Patch, PatchSamples, Real, Sphere};

/// Samples of the two squares at `order`, and the occluding sphere.
fn setup<T: Real, const CAP: usize>(order: usize) -> (Box<PatchSamples<T, CAP>>, Box<PatchSamples<T, CAP>>, Sphere<T>) {
    let c = |x: f64| T::from_f64(x);
    let lower =
        Parallelogram::new(vec3(c(0.0), c(0.0), c(0.0)), vec3(c(1.0), c(0.0), c(0.0)), vec3(c(0.0), c(1.0), c(0.0)))
            .expect("square");
    let upper =
        Parallelogram::new(vec3(c(0.0), c(0.0), c(1.0)), vec3(c(0.0), c(1.0), c(0.0)), vec3(c(1.0), c(0.0), c(0.0)))
            .expect("square");
    let a = Box::new(PatchSamples::<T, CAP>::new(&Patch::whole(&lower).expect("patch"), order).expect("samples"));
    let b = Box::new(PatchSamples::<T, CAP>::new(&Patch::whole(&upper).expect("patch"), order).expect("samples"));
    let sphere = Sphere::outer(vec3(c(0.5), c(0.5), c(0.5)), c(0.2)).expect("sphere");
    (a, b, sphere)
}

fn bench_width<T: Real, const CAP: usize>(c: &mut Criterion, name: &str, order: usize) {
    let (a, b, sphere) = setup::<T, CAP>(order);
    let mut group = c.benchmark_group("inner_sum");
    group.throughput(Throughput::Elements((order as u64).pow(4)));
    group.bench_with_input(BenchmarkId::new(format!("{name}/unoccluded"), order), &order, |bench, _| {
        bench.iter(|| form_factor(black_box(&*a), black_box(&*b), &()).expect("form factor"));
    });
    group.bench_with_input(BenchmarkId::new(format!("{name}/occluded"), order), &order, |bench, _| {
        bench.iter(|| form_factor(black_box(&*a), black_box(&*b), black_box(&sphere)).expect("form factor"));
    });
    group.finish();
}

fn inner_sum(c: &mut Criterion) {
    bench_width::<f32, 256>(c, "f32", 16);
    bench_width::<f32, 1024>(c, "f32", 32);
    bench_width::<f64, 256>(c, "f64", 16);
    bench_width::<f64, 1024>(c, "f64", 32);
}

criterion_group!(benches, inner_sum);
criterion_main!(benches);
