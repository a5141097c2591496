//! The core's criterion benchmarks (`benches/`: cones, mncp, mpc), run by `make bench` or
//! `cargo bench -p regrasp-bench`. A crate of their own so that `cargo test -p regrasp-core`
//! does not compile criterion; this library is empty.
