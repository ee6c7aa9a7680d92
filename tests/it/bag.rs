//! ROS 2 bags (MCAP): `simulate --format mcap` read back by `recognize` and `score`, a bag
//! another tool wrote, the errors bad bags get, and fuzzed bags and CDR messages.

use super::common::{placewords, root};
use placewords::io::real_log::TruthSource;
use placewords::io::ros2::bag::{BagError, BagTopics, read_bag, read_bag_bytes};
use placewords::io::ros2::msg;
use proptest::prelude::*;
use std::collections::BTreeMap;

/// A simulated run written as a bag and as a CARMEN log gives the same recognition: identical
/// matches for both truth sources.
#[test]
fn a_bag_recognizes_exactly_as_the_carmen_log_of_the_same_run() {
    use placewords::experiment::real::{RealLogOptions, recognize_log};
    use placewords::experiment::{ExperimentOptions, load_scenario};
    use placewords::sim::logs::{LogsWriter, RunFormat};
    // Scenario B's first run, 6 laps: enough revisits for every level configuration to match.
    let mut scn = load_scenario(&root().join("scenarios/B.toml")).unwrap();
    scn.sim.runs.truncate(1);
    let runs = placewords::sim::simulate(&scn.sim, Some(6), &|| {}).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for (format, sub) in [(RunFormat::Carmen, "carmen"), (RunFormat::Mcap, "mcap")] {
        let mut w = LogsWriter::new(&scn.sim, Some(6), &dir.path().join(sub), format);
        for r in &runs {
            for lap in &r.laps {
                w.push_lap(r.run, lap).unwrap();
            }
        }
        w.finish().unwrap();
    }
    let carmen = dir.path().join("carmen/run-000.log");
    let bag = dir.path().join("mcap/run-000.mcap");
    for (truth, noise) in [
        (TruthSource::TruePos, "proportional"),
        (TruthSource::Corrected, "proportional"),
    ] {
        let opts = RealLogOptions {
            lenient: false,
            truth,
            noise: placewords::experiment::real::parse_noise_model(noise).unwrap(),
            seed: 7,
            scan_step: 1,
            topics: BagTopics::default(),
        };
        let recognize = |path: &std::path::Path| {
            let exp = ExperimentOptions::default();
            let (e, _) = recognize_log(
                path,
                &opts,
                "run-000",
                &scn.recognizer,
                &scn.evaluation,
                &exp,
                // Loaded whole, so the recognitions keep their matches.
                true,
            )
            .unwrap();
            // The pairs each match claims; its score holds the Ψ residual, which the CARMEN
            // log's printed precision moves in the last digits.
            e.recognitions
                .into_iter()
                .map(|(_, r)| {
                    r.matches
                        .into_iter()
                        .map(|m| (m.runs, m.direction))
                        .collect::<Vec<_>>()
                })
                .collect::<Vec<_>>()
        };
        let from_log = recognize(&carmen);
        assert!(
            from_log.iter().any(|m| !m.is_empty()),
            "there are matches to compare ({truth:?}): {:?}",
            from_log.iter().map(Vec::len).collect::<Vec<_>>()
        );
        assert_eq!(from_log, recognize(&bag), "{truth:?}, noise {noise}");
    }
}

/// `score` reads a folder of bags as it reads a folder of CARMEN logs.
#[test]
fn score_reads_a_folder_of_bags() {
    let dir = tempfile::tempdir().unwrap();
    let smoke = root().join("scenarios/smoke.toml");
    let mut reports = Vec::new();
    for format in ["carmen", "mcap"] {
        let out = dir.path().join(format);
        let o = placewords(&[
            "simulate",
            smoke.to_str().unwrap(),
            "--laps",
            "2",
            "--format",
            format,
            "-o",
            out.to_str().unwrap(),
            "-q",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let matches = dir.path().join("m.csv");
        std::fs::write(
            &matches,
            "query_run,query_scan,matched_run,matched_scan,score,direction\n1,300,0,300,1,same\n",
        )
        .unwrap();
        let o = placewords(&[
            "score",
            out.to_str().unwrap(),
            "--matches",
            matches.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        reports.push(String::from_utf8_lossy(&o.stdout).into_owned());
    }
    assert_eq!(reports[0], reports[1]);
}

/// A bag written by the Python `mcap-ros2-support` writer (tests/fixtures/mcap/README.md) is
/// read: topics found by type, poses interpolated between odometry messages, stamps of a real
/// clock made relative, and `recognize` runs on it.
#[test]
fn a_bag_another_tool_wrote_is_read() {
    let path = root().join("tests/fixtures/mcap/python-ros2.mcap");
    let bag = read_bag(&path, &BagTopics::default()).unwrap();
    assert_eq!(bag.lasers.len(), 40);
    assert!(bag.truepos.is_empty());
    assert_eq!(bag.max_range_m, Some(8.0));
    let first = &bag.lasers[0];
    assert_eq!(first.ranges_m.len(), 181);
    // Beam 180 points left, at the wall 2 m away; beam 0 right, at nothing.
    assert_eq!(first.ranges_m[180], 2.0);
    assert_eq!(first.ranges_m[0], 8.0);
    // The scan at t = 0.075 s lies halfway between odometry at 0.05 and 0.1 s.
    assert!((first.pose.x - 0.0375).abs() < 1e-6, "{:?}", first.pose);
    let o = placewords(&["recognize", path.to_str().unwrap(), "-q"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let topics: Vec<&str> = bag.topics.iter().map(|t| t.topic.as_str()).collect();
    assert_eq!(topics, ["/wheel_odom", "/base_scan"]);
}

/// A tiny bag of `scans` scans and odometry at `odom_times`, unchunked, with the scan channel
/// in `encoding`.
fn tiny_bag(scans: &[f64], odom_times: &[f64], encoding: &str) -> Vec<u8> {
    use placewords::geom::Pose2;
    use placewords::io::ros2::msg::{Header, LaserScan, Odometry};
    let mut out = std::io::Cursor::new(Vec::new());
    {
        let mut w = mcap::WriteOptions::new()
            .profile("ros2")
            .use_chunks(false)
            .create(&mut out)
            .unwrap();
        let mut channel = |topic: &str, type_name: &str, enc: &str| {
            let text = msg::schema_text(type_name).unwrap();
            let s = w.add_schema(type_name, "ros2msg", text.as_bytes()).unwrap();
            w.add_channel(s, topic, enc, &BTreeMap::new()).unwrap()
        };
        let scan_ch = channel("/scan", msg::LASER_SCAN, encoding);
        let odom_ch = channel("/odom", msg::ODOMETRY, "cdr");
        let mut put = |ch: u16, t: f64, data: &[u8]| {
            let ns = msg::time_ns(t);
            let h = mcap::records::MessageHeader {
                channel_id: ch,
                sequence: 0,
                log_time: ns,
                publish_time: ns,
            };
            w.write_to_known_channel(&h, data).unwrap();
        };
        for &t in odom_times {
            let o = Odometry {
                header: Header {
                    stamp_s: t,
                    frame_id: "odom".into(),
                },
                child_frame_id: "base_link".into(),
                pose: Pose2::new(t, 0.0, 0.1),
                speed_m_s: 1.0,
                turn_rad_s: 0.0,
            };
            put(odom_ch, t, &o.encode());
        }
        for &t in scans {
            let s = LaserScan {
                header: Header {
                    stamp_s: t,
                    frame_id: "laser".into(),
                },
                angle_min: -1.0,
                angle_max: 1.0,
                angle_increment: 0.5,
                time_increment: 0.0,
                scan_time: 0.1,
                range_min: 0.0,
                range_max: 10.0,
                ranges: vec![1.0, 2.0, f32::INFINITY, 3.5, 10.0],
            };
            put(scan_ch, t, &s.encode());
        }
        w.finish().unwrap();
    }
    out.into_inner()
}

#[test]
fn bad_bags_get_errors_that_say_what_and_where() {
    let ok = tiny_bag(&[0.0, 0.1], &[0.0, 0.1], "cdr");
    let b = read_bag_bytes(&ok, "t.mcap", &BagTopics::default()).unwrap();
    assert_eq!(b.lasers.len(), 2);
    assert_eq!(b.lasers[0].ranges_m, [1.0, 2.0, 10.0, 3.5, 10.0]);
    let read = |bytes: &[u8], topics: &BagTopics| {
        read_bag_bytes(bytes, "t.mcap", topics)
            .unwrap_err()
            .to_string()
    };
    // A missing topic lists the topics present.
    let e = read(
        &ok,
        &BagTopics {
            scan: Some("/laser".into()),
            odom: None,
        },
    );
    assert!(e.contains("no scan topic /laser"), "{e}");
    assert!(
        e.contains("/scan (sensor_msgs/msg/LaserScan), /odom (nav_msgs/msg/Odometry)"),
        "{e}"
    );
    // A topic of the wrong type.
    let e = read(
        &ok,
        &BagTopics {
            scan: None,
            odom: Some("/scan".into()),
        },
    );
    assert!(
        e.contains("topic /scan is sensor_msgs/msg/LaserScan, not nav_msgs/msg/Odometry"),
        "{e}"
    );
    // An unsupported encoding.
    let json = tiny_bag(&[0.0], &[0.0], "json");
    let e = read(&json, &BagTopics::default());
    assert!(
        e.contains("topic /scan uses message encoding `json`; only `cdr`"),
        "{e}"
    );
    // Scans without odometry in time.
    let late = tiny_bag(&[0.0, 5.0], &[0.0, 0.1], "cdr");
    let e = read(&late, &BagTopics::default());
    assert!(
        e.contains("scan 1 (time 5.000 s) has no odometry within 0.5 s (nearest 4.900 s away)"),
        "{e}"
    );
    // A truncated file names the record cut off and its offset.
    let e = read(&ok[..ok.len() / 2], &BagTopics::default());
    assert!(e.contains("truncated: record 0x"), "{e}");
    assert!(e.contains("at byte offset"), "{e}");
    // Not MCAP at all.
    let e = read(b"FLASER 3 1 2 3", &BagTopics::default());
    assert!(e.contains("not an MCAP file"), "{e}");
}

/// Through the command line a bad bag is exit 2 with the error, never a panic.
#[test]
fn recognize_on_a_bad_bag_exits_2_naming_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("cut.mcap");
    let ok = tiny_bag(&[0.0, 0.1], &[0.0, 0.1], "cdr");
    std::fs::write(&p, &ok[..ok.len() - 40]).unwrap();
    let o = placewords(&["recognize", p.to_str().unwrap(), "-q"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("cut.mcap: truncated"), "{err}");
}

/// A bag with one scan, chunked and compressed as `simulate` writes them.
fn simulated_bag() -> Vec<u8> {
    use placewords::geom::Pose2;
    use placewords::io::ros2::bag::{BagWriter, ScanTiming};
    use placewords::log::{Frame, LapLog};
    use placewords::scan::{BeamLayout, Scan};
    let layout = BeamLayout::centered(5, std::f64::consts::PI, 8.0, Pose2::new(0.02, 0.0, 0.0));
    let frames = (0..3)
        .map(|k| Frame {
            time_s: k as f64 * 0.1,
            odom: placewords::geom::OdomPose(Pose2::new(k as f64 * 0.1, 0.0, 0.0)),
            truth: placewords::geom::TruePose(Pose2::new(k as f64 * 0.1, 0.01, 0.0)),
            scan: Scan {
                layout: layout.clone(),
                ranges_m: vec![1.0, 2.0, 3.0, 8.0, 4.0],
                time_s: k as f64 * 0.1,
            },
        })
        .collect();
    let lap = LapLog {
        lap: 0,
        door_config: "all-closed".into(),
        open_doors: vec![],
        frames,
    };
    let mut w = BagWriter::new(
        std::io::Cursor::new(Vec::new()),
        0,
        ScanTiming::lms200(10.0, 0.5),
    )
    .unwrap();
    w.write_lap(&lap).unwrap();
    w.finish().unwrap().into_inner()
}

/// One byte mutation: where (a fraction of the length) and what.
fn mutate(bytes: &mut Vec<u8>, muts: &[(u8, u32, u8)]) {
    for &(kind, at, v) in muts {
        if bytes.is_empty() {
            return;
        }
        let i = (at as usize) % bytes.len();
        match kind {
            0 => bytes[i] ^= v | 1,
            1 => bytes.truncate(i),
            2 => bytes[i] = 0xff,
            3 => {
                // a length field made huge
                let end = (i + 8).min(bytes.len());
                bytes[i..end].fill(0x7f);
            }
            _ => bytes.insert(i, v),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: super::common::fuzz_cases(), ..ProptestConfig::default() })]

    /// The MCAP reader returns a bag or an error, never panics, on mutated bags (chunked and
    /// compressed, or plain).
    #[test]
    fn fuzz_mcap_reader(
        plain in any::<bool>(),
        muts in prop::collection::vec((0u8..5, any::<u32>(), any::<u8>()), 1..5),
    ) {
        let mut bytes = if plain {
            tiny_bag(&[0.0, 0.1], &[0.0, 0.1], "cdr")
        } else {
            simulated_bag()
        };
        mutate(&mut bytes, &muts);
        let input = || format!("plain {plain}, {} bytes, mutations {muts:?}", bytes.len());
        super::common::fuzz_timed("fuzz_mcap_reader", &input, || {
            let _ = read_bag_bytes(&bytes, "f.mcap", &BagTopics::default());
        });
    }

    /// The CDR decoders return a message or an error, never panic, on any bytes.
    #[test]
    fn fuzz_cdr_decoder(
        seed_msg in 0usize..4,
        muts in prop::collection::vec((0u8..5, any::<u32>(), any::<u8>()), 0..5),
        raw in prop::collection::vec(any::<u8>(), 0..64),
    ) {
        use placewords::geom::Pose2;
        use placewords::io::ros2::msg::{Header, LaserScan, Odometry, PoseStamped, Transform};
        let header = Header { stamp_s: 1.5, frame_id: "laser".into() };
        let mut bytes = match seed_msg {
            0 => LaserScan {
                header, angle_min: -1.0, angle_max: 1.0, angle_increment: 0.5,
                time_increment: 0.0, scan_time: 0.1, range_min: 0.0, range_max: 8.0,
                ranges: vec![1.0; 5],
            }.encode(),
            1 => Odometry {
                header, child_frame_id: "base_link".into(), pose: Pose2::new(1.0, 2.0, 0.5),
                speed_m_s: 0.1, turn_rad_s: 0.0,
            }.encode(),
            2 => msg::encode_tf(&[Transform { header, child_frame_id: "b".into(), pose: Pose2::IDENTITY }]),
            _ => PoseStamped { header, pose: Pose2::new(1.0, 2.0, 0.5) }.encode(),
        };
        mutate(&mut bytes, &muts);
        let input = || format!("message {seed_msg}, mutations {muts:?}, raw {raw:?}");
        super::common::fuzz_timed("fuzz_cdr_decoder", &input, || {
            for input in [&bytes, &raw] {
                let _ = LaserScan::decode(input);
                let _ = Odometry::decode(input);
                let _ = msg::decode_tf(input);
                let _ = PoseStamped::decode(input);
                let _ = msg::decode_string(input);
            }
        });
    }
}

/// A chunk that claims an absurd uncompressed size is an error, not an allocation.
#[test]
fn a_chunk_claiming_a_huge_size_is_refused() {
    let mut bytes = simulated_bag();
    // After the magic, the header record; then the first chunk (opcode 0x06).
    let header_len = u64::from_le_bytes(bytes[9..17].try_into().unwrap()) as usize;
    let chunk = 8 + 9 + header_len;
    assert_eq!(bytes[chunk], 0x06);
    // Chunk body: start, end (8 bytes each), then uncompressed_size.
    let at = chunk + 9 + 16;
    bytes[at..at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    let e = read_bag_bytes(&bytes, "h.mcap", &BagTopics::default()).unwrap_err();
    assert!(
        matches!(e, BagError::Corrupt { .. } | BagError::Truncated { .. }),
        "{e}"
    );
}

/// The input that once aborted the reader (tests/fixtures/mcap/README.md): a length field
/// claiming 2 GB inside a 100-byte record is an error naming the record, not an allocation.
#[test]
fn a_length_claiming_more_than_its_record_holds_is_refused() {
    let path = root().join("tests/fixtures/mcap/huge-length.mcap");
    let e = read_bag(&path, &BagTopics::default()).unwrap_err();
    let e = e.to_string();
    assert!(
        e.contains("corrupt record at byte offset") && e.contains("channel: its topic claims"),
        "{e}"
    );
}
