//! A world file over a documented limit, for the test that it is refused located and the bench
//! that it is refused fast: one wall of 10,002 points (the limit is 10,000 segments). Included by
//! path in `tests/it` and `benches/world.rs`.

/// The world file's text.
pub fn zigzag_wall_world() -> String {
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
