//! World-file validation costs (the author's feedback loop, issue 24 moved these out of timed
//! tests): parsing and checking `worlds/institute-floor.toml` (77 doors, 343 wall segments; the
//! route test drive excluded, it is the simulator's), and refusing a wall of 10,002 points at
//! the segment limit (it must be refused before any geometry work grows with it). Figures in
//! BENCHMARKS.md.

#[path = "../tests/support/big_world.rs"]
mod big_world;

use criterion::{Criterion, criterion_group};
use placewords::world::parse_world;
use std::hint::black_box;
use std::path::Path;

fn bench_validate(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/institute-floor.toml");
    let src = std::fs::read_to_string(&path).expect("the shipped world");
    c.bench_function("world_validate_institute_floor", |b| {
        b.iter(|| parse_world(black_box(&src), "institute-floor.toml").expect("valid"))
    });
}

fn bench_refuse(c: &mut Criterion) {
    let src = big_world::zigzag_wall_world();
    c.bench_function("world_refuse_10002_point_wall", |b| {
        b.iter(|| parse_world(black_box(&src), "big.toml").expect_err("over the limit"))
    });
}

criterion_group!(benches, bench_validate, bench_refuse);

fn main() {
    benches();
    criterion::Criterion::default()
        .configure_from_args()
        .final_summary();
}
