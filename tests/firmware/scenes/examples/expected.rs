//! The scenes computed on the build machine, printed in the firmware's format, so that run.sh
//! can compare the firmware with the host for the same backend:
//! `cargo run --release -p pdm-firmware-scenes --example expected --target <host> [--features micromath]`.

use pdm_firmware_scenes as scenes;

fn main() {
    let backend = if cfg!(feature = "micromath") {
        "micromath"
    } else {
        "libm"
    };
    println!(
        "host: backend={backend} order={} cap={} arch={}",
        scenes::ORDER,
        scenes::CAP,
        std::env::consts::ARCH
    );
    for (i, name) in scenes::NAMES.iter().enumerate() {
        match scenes::run(i) {
            Ok(v) => println!("CASE {name} value={v:e} bits=0x{:08x}", v.to_bits()),
            Err(e) => {
                eprintln!("CASE {name} error={e:?}");
                std::process::exit(1);
            }
        }
    }
}
