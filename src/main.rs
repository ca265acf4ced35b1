//! The pendant binary. The window is not built yet; until it is, this says so plainly.

fn main() {
    println!(
        "xsel-pendant {}: the desktop window is not built yet.\n\
         What exists today: the Format B protocol library, the SCARA model and the simulated\n\
         controller. Run `cargo run --bin xsel-sim -- --help` to try the simulator.",
        env!("CARGO_PKG_VERSION")
    );
}
