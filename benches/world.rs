//! World-file validation costs (the author's feedback loop, issue 24 moved these out of timed
//! tests): parsing and checking `worlds/institute-floor.toml` (77 doors, 343 wall segments; the
//! route test drive excluded, it is the simulator's), and refusing a wall of 10,002 points at
//! the segment limit (it must be refused before any geometry work grows with it). Figures in
//! BENCHMARKS.md.

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

/// The 10,002-point wall of `tests/it/world.rs::too_many_segments_are_refused`.
fn zigzag_world() -> String {
    let mut src = String::from(
        "format_version = 1\nname = \"big\"\n[robot_home]\nx_m = 0.5\ny_m = 0.5\n\
         [[routes]]\nid = \"lap\"\nwaypoints_m = [[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]]\n\
         [[walls]]\nid = \"zigzag\"\npoints_m = [",
    );
    for i in 0..10_002 {
        let (x, y) = ((i % 1000) as f64 * 0.01, (i / 1000) as f64 * 0.01);
        src.push_str(&format!("[{x}, {y}],"));
    }
    src.push_str("]\n");
    src
}

fn bench_refuse(c: &mut Criterion) {
    let src = zigzag_world();
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
