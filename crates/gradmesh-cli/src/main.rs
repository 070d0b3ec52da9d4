//! The `gradmesh` command.

fn main() {
    println!("gradmesh {}", env!("CARGO_PKG_VERSION"));
}
