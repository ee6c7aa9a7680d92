//! One region-vs-region ICP test, the unit of the ICP baseline's cost (a new region is tested
//! against every past region). Setup (clouds, k-d trees) stays outside the timed part.

use criterion::{Criterion, criterion_group, criterion_main};
use placewords::baseline::icp::{Cloud, IcpConfig, align, even_sample};
use placewords::geom::{Pose2, Vec2};
use std::hint::black_box;

/// Points every 5 cm along a corridor corner with a niche.
fn walls() -> Vec<[f64; 2]> {
    let lines: [&[(f64, f64)]; 2] = [
        &[(-2.5, -1.0), (1.0, -1.0), (1.0, -2.5)],
        &[
            (-2.5, 1.0),
            (-0.5, 1.0),
            (-0.5, 1.6),
            (0.3, 1.6),
            (0.3, 1.0),
            (2.5, 1.0),
            (2.5, -0.3),
        ],
    ];
    let mut pts = Vec::new();
    for l in lines {
        for w in l.windows(2) {
            let (a, b) = (Vec2::new(w[0].0, w[0].1), Vec2::new(w[1].0, w[1].1));
            let n = ((b - a).norm() / 0.05).round() as usize;
            for k in 0..n {
                let p = a + (b - a) * (k as f64 / n as f64);
                pts.push([p.x, p.y]);
            }
        }
    }
    pts
}

fn bench(c: &mut Criterion) {
    let cfg = IcpConfig::default();
    let target = Cloud::new(&even_sample(&walls(), 150));
    let moved = Pose2::new(0.3, -0.2, 8f64.to_radians()).inverse();
    let shifted: Vec<[f64; 2]> = walls()
        .iter()
        .map(|p| {
            let q = moved.transform_point(Vec2::new(p[0], p[1]));
            [q.x, q.y]
        })
        .collect();
    let same_place = Cloud::new(&even_sample(&shifted, 150));
    let room: Vec<[f64; 2]> = (0..150)
        .map(|k| {
            let a = k as f64 / 150.0 * std::f64::consts::TAU;
            [2.0 * a.cos(), 2.0 * a.sin()]
        })
        .collect();
    let other_place = Cloud::new(&room);
    c.bench_function("icp region vs region, same place", |b| {
        b.iter(|| align(black_box(&same_place), black_box(&target), &cfg))
    });
    c.bench_function("icp region vs region, other place", |b| {
        b.iter(|| align(black_box(&other_place), black_box(&target), &cfg))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
