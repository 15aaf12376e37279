//! Prints the independent cube reference (`pdm_host::reference::cube`) for side 6 and a radius
//! (default 1): `cargo run --release -p pdm-host --example cube_reference -- 1.0`.
fn main() {
    let radius = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(1.0);
    let r = pdm_host::reference::cube::cube_face_factors(6.0, radius);
    println!("({:?}, {:?}, {:?}, {:?})", r.f_adjacent, r.f_opposite, r.f_adjacent_error, r.f_opposite_error);
    println!("sum rule residual {:e}", r.sum_rule_residual);
}
