//! Proof that a complete form-factor computation allocates nothing: a counting global allocator
//! counts, per thread, the allocations a thread makes while armed (the test harness allocates on other
//! threads, so counting is per thread).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use pdm_kernel::{
    form_factor, self_form_factor, surface_form_factor, vec3, AnyOccluder, Cylinder, Disk, Parallelogram, Patch,
    PatchGrid, PatchSamples, Quadrature, Side, Sphere,
};

struct Counting;

thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn record() {
    if ARMED.with(Cell::get) {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
    }
}

#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        record();
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        record();
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn count_allocations<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let before = ALLOCATIONS.with(Cell::get);
    ARMED.with(|a| a.set(true));
    let r = f();
    ARMED.with(|a| a.set(false));
    (r, ALLOCATIONS.with(Cell::get) - before)
}

#[test]
fn the_counter_counts() {
    // The harness must be able to fail: an allocation while armed is seen.
    let (_, n) = count_allocations(|| std::hint::black_box(vec![1u8; 16]));
    assert!(n >= 1, "counting allocator saw no allocation");
}

fn computation<T: pdm_kernel::Real>() -> Result<(T, T, T), pdm_kernel::PdmError> {
    let f = |x: f64| T::from_f64(x);
    let sphere = Sphere::outer(vec3(f(0.0), f(0.0), f(0.0)), f(1.0))?;
    let floor = Parallelogram::new(
        vec3(f(-3.0), f(-3.0), f(-3.0)),
        vec3(f(6.0), f(0.0), f(0.0)),
        vec3(f(0.0), f(6.0), f(0.0)),
    )?;
    let wall = Parallelogram::new(
        vec3(f(-3.0), f(-3.0), f(-3.0)),
        vec3(f(0.0), f(0.0), f(6.0)),
        vec3(f(6.0), f(0.0), f(0.0)),
    )?;
    let post = Cylinder::new(vec3(f(2.0), f(2.0), f(-3.0)), vec3(f(0.0), f(0.0), f(1.0)), f(0.2), f(2.0), Side::Outer)?;
    let lid = Disk::new(vec3(f(2.0), f(2.0), f(-1.0)), vec3(f(0.0), f(0.0), f(1.0)), f(0.2))?;
    let occluders = [AnyOccluder::Sphere(sphere), AnyOccluder::Cylinder(post), AnyOccluder::Disk(lid)];
    let sphere_to_floor = surface_form_factor::<T, _, _, _, 25>(
        PatchGrid::new(&sphere, 4, 8)?,
        PatchGrid::new(&floor, 3, 3)?,
        Quadrature::uniform(5),
        &occluders,
    )?;
    let a = PatchSamples::<T, 64>::new(&Patch::whole(&floor)?, 8)?;
    let b = PatchSamples::<T, 64>::new(&Patch::whole(&wall)?, 8)?;
    let floor_to_wall = form_factor(&a, &b, &occluders[..])?;
    let inside = Sphere::inner(vec3(f(0.0), f(0.0), f(0.0)), f(1.0))?;
    let cap = PatchGrid::new(&inside, 2, 2)?.cell(0, 0).ok_or(pdm_kernel::PdmError::Degenerate)?;
    let self_factor = self_form_factor::<T, _, _, 64>(&cap, 6, &())?;
    Ok((sphere_to_floor, floor_to_wall, self_factor))
}

#[test]
fn complete_form_factor_computation_allocates_nothing_f64() {
    let (r, n) = count_allocations(computation::<f64>);
    let (a, b, c) = r.unwrap();
    assert!(a > 0.1 && b > 0.1 && c > 0.1, "{a} {b} {c}");
    assert_eq!(n, 0, "kernel allocated {n} times");
}

#[test]
fn complete_form_factor_computation_allocates_nothing_f32() {
    let (r, n) = count_allocations(computation::<f32>);
    let (a, b, c) = r.unwrap();
    assert!(a > 0.1 && b > 0.1 && c > 0.1, "{a} {b} {c}");
    assert_eq!(n, 0, "kernel allocated {n} times");
}
