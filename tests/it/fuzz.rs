//! Fuzz targets kept in the repo (issue 31 point 6): every parser of user input, fed mutations
//! of a small corpus (`tests/fixtures/fuzz-corpus/`, `worlds/`, `scenarios/`), must return
//! `Ok` or an error — never panic. Mutations replace numbers with extreme values (1e308, 1e-300,
//! 2^64 − 1, nan, …), delete, duplicate or truncate lines and flip bytes, which reaches far
//! deeper than random text.
//!
//! Each target runs `PLACEWORDS_FUZZ_CASES` inputs (default 48, to keep the suite short); a
//! long campaign, with each target's count and slowest input printed:
//! `PLACEWORDS_FUZZ_CASES=5000 cargo test --release --test it fuzz -- --nocapture`.

use super::common::{fuzz_cases as cases, fuzz_timed, root};
use proptest::prelude::*;

/// Values that broke parsers and models before: huge, tiny, out of integer range, not numbers.
const EXTREMES: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1e308",
    "-1e308",
    "1e-300",
    "1e-9",
    "18446744073709551615",
    "9223372036854775807",
    "-9223372036854775808",
    "4294967296",
    "nan",
    "inf",
    "1e999",
    "0.5",
    "1000000",
    "\"\"",
    "[]",
    "{}",
    "true",
    "\u{fffd}",
    "0x7fffffff",
];

/// One mutation: what, where (a fraction of the text) and which extreme value.
type Mutation = (u8, u32, u8);

fn mutations() -> impl Strategy<Value = Vec<Mutation>> {
    prop::collection::vec((0u8..6, any::<u32>(), any::<u8>()), 1..6)
}

/// Byte ranges of the number-like runs of `text`.
fn numbers(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < text.len() {
        if text[i].is_ascii_digit()
            || (text[i] == b'-' && text.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            let start = i;
            i += 1;
            while i < text.len() && (text[i].is_ascii_alphanumeric() || b".-+_".contains(&text[i]))
            {
                i += 1;
            }
            out.push((start, i));
        } else {
            i += 1;
        }
    }
    out
}

/// `base` with the mutations applied, in order.
fn mutate(base: &str, muts: &[Mutation]) -> String {
    let mut t = base.as_bytes().to_vec();
    for &(kind, at, tok) in muts {
        let token = EXTREMES[tok as usize % EXTREMES.len()].as_bytes();
        let pos = if t.is_empty() {
            0
        } else {
            at as usize % t.len()
        };
        let line = |t: &[u8]| {
            let s = t[..pos]
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |i| i + 1);
            let e = t[pos..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(t.len(), |i| pos + i + 1);
            (s, e)
        };
        match kind {
            0 => {
                let nums = numbers(&t);
                if !nums.is_empty() {
                    let (s, e) = nums[at as usize % nums.len()];
                    t.splice(s..e, token.iter().copied());
                }
            }
            1 => {
                let (s, e) = line(&t);
                t.drain(s..e);
            }
            2 => {
                let (s, e) = line(&t);
                let copy: Vec<u8> = t[s..e].to_vec();
                t.splice(s..s, copy);
            }
            3 => {
                t.splice(pos..pos, token.iter().copied());
            }
            4 => t.truncate(pos),
            _ => {
                if let Some(b) = t.get_mut(pos) {
                    *b = tok;
                }
            }
        }
    }
    String::from_utf8_lossy(&t).into_owned()
}

fn corpus(files: &[&str]) -> Vec<String> {
    files
        .iter()
        .map(|f| std::fs::read_to_string(root().join(f)).unwrap())
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn world_files_never_panic(which in 0usize..3, muts in mutations()) {
        let c = corpus(&["worlds/loop-small.toml", "worlds/two-loops.toml", "tests/fixtures/valid-base.toml"]);
        let text = mutate(&c[which], &muts);
        fuzz_timed("world", &|| text.clone(), || placewords::world::parse_world(&text, "fuzz.toml").is_ok());
    }

    #[test]
    fn scenario_files_never_panic(which in 0usize..4, muts in mutations()) {
        let c = corpus(&[
            "scenarios/smoke.toml",
            "scenarios/A.toml",
            "scenarios/reverse.toml",
            "tests/fixtures/fuzz-corpus/scan-context.toml",
        ]);
        let path = root().join("scenarios/fuzz.toml");
        let text = mutate(&c[which], &muts);
        fuzz_timed("scenario", &|| text.clone(), || {
            placewords::experiment::parse_scenario(&text, &path, &placewords::world::load_world_for)
                .is_ok()
        });
    }

    #[test]
    fn carmen_logs_never_panic(which in 0usize..2, muts in mutations(), lenient in any::<bool>()) {
        let c = corpus(&["tests/fixtures/carmen/mixed.log", "tests/fixtures/carmen/malformed.log"]);
        let opts = placewords::io::carmen::ReadOptions { lenient };
        let text = mutate(&c[which], &muts);
        fuzz_timed("carmen", &|| text.clone(), || {
            placewords::io::carmen::parse_log_str(&text, "fuzz.log", opts).is_ok()
        });
    }

    #[test]
    fn mobilesim_maps_never_panic(muts in mutations()) {
        let c = corpus(&["tests/fixtures/fuzz-corpus/box.map"]);
        let text = mutate(&c[0], &muts);
        fuzz_timed("mobilesim", &|| text.clone(), || {
            placewords::authoring::mobilesim::import_mobilesim(&text, "fuzz.map").is_ok()
        });
    }

    /// Issue 31 point 4: a world `world import` writes passes `world check` (run on the
    /// written file, as a user would, test drive included), whatever the map; an import that
    /// cannot give such a world is refused (or gives no route), never written wrong.
    #[test]
    fn imported_worlds_pass_world_check(which in 0usize..2, muts in mutations()) {
        let c = corpus(&["tests/fixtures/fuzz-corpus/box.map", "../shared/data/mobilesim/corridors.map"]);
        let text = mutate(&c[which], &muts);
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("imported.toml");
        let out_name = out.display().to_string();
        fuzz_timed("import_then_check", &|| text.clone(), || {
            let imported = placewords::authoring::import::import_map(&text, "fuzz.map", &out_name);
            if let Ok(w) = &imported {
                std::fs::write(&out, &w.text).unwrap();
                let checked = placewords::sim::test_drive::check_world(&out);
                prop_assert!(checked.is_ok(), "imported, then refused by world check: {}\n{}", checked.err().unwrap(), w.text);
            }
            Ok(imported.is_ok())
        })?;
    }

    #[test]
    fn matches_csv_never_panics(muts in mutations()) {
        let c = corpus(&["tests/fixtures/fuzz-corpus/matches.csv"]);
        let text = mutate(&c[0], &muts);
        fuzz_timed("matches_csv", &|| text.clone(), || {
            placewords::io::matches_csv::parse_matches(&text, "fuzz.csv").is_ok()
        });
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    /// Merge parts are read and checked by `merge` (issue 31: the shard index and count).
    #[test]
    fn merge_parts_never_panic(muts in mutations()) {
        let c = corpus(&["tests/fixtures/fuzz-corpus/part-1-of-2.json"]);
        let dir = tempfile::tempdir().unwrap();
        let part = dir.path().join("part.json");
        let text = mutate(&c[0], &muts);
        std::fs::write(&part, &text).unwrap();
        fuzz_timed("merge_part", &|| text.clone(), || {
            placewords::experiment::stress::merge_files(&[part.clone(), part], Vec::new()).is_ok()
        });
    }

    /// Baselines are read and compared by `check --baseline` and `compare` (issue 25): a
    /// mutated report on either side gives a comparison or an error, never a panic.
    #[test]
    fn baselines_never_panic(muts in mutations(), mutated_is_base in any::<bool>()) {
        let c = corpus(&["tests/fixtures/fuzz-corpus/baseline-smoke.json"]);
        let dir = tempfile::tempdir().unwrap();
        let mutated = dir.path().join("mutated.json");
        let text = mutate(&c[0], &muts);
        std::fs::write(&mutated, &text).unwrap();
        let good = root().join("tests/fixtures/fuzz-corpus/baseline-smoke.json");
        let (base, new) = if mutated_is_base { (&mutated, &good) } else { (&good, &mutated) };
        fuzz_timed("baseline", &|| text.clone(), || {
            placewords::experiment::stress::compare_files(base, new, Default::default()).is_ok()
        });
    }
}

/// A small lap file of two runs (layouts, ranges and names of every kind), for the lap file
/// target.
fn lap_file() -> Vec<u8> {
    use placewords::geom::{OdomPose, Pose2, TruePose};
    use placewords::log::{Frame, LapLog};
    use placewords::scan::{BeamLayout, Scan};
    let lap = |lap: usize, frames: usize| LapLog {
        lap,
        door_config: "north-pair".into(),
        open_doors: vec!["n-03".into()],
        frames: (0..frames)
            .map(|i| Frame {
                time_s: i as f64 * 0.1,
                odom: OdomPose(Pose2 {
                    x: i as f64,
                    y: 0.5,
                    theta: -0.25,
                }),
                truth: TruePose(Pose2 {
                    x: i as f64 + 0.01,
                    y: 0.49,
                    theta: -0.2,
                }),
                scan: Scan {
                    layout: BeamLayout::centered(3 + i % 2, 3.0, 32.767, Pose2::IDENTITY),
                    ranges_m: (0..3 + i % 2).map(|k| 1.0 + k as f64 / 7.0).collect(),
                    time_s: i as f64 * 0.1,
                },
            })
            .collect(),
    };
    let mut w =
        placewords::io::lap_file::LapFileWriter::new(Vec::new(), &"7".repeat(64), &[2, 1]).unwrap();
    w.push(0, &lap(0, 3)).unwrap();
    w.push(0, &lap(1, 2)).unwrap();
    w.push(1, &lap(0, 4)).unwrap();
    w.finish().unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    /// Lap cache entries (`io::lap_file`, issue 25 point 3): bytes flipped, set to extremes
    /// (a length or count of 0, 2^32, 2^64 − 1), cut or inserted anywhere give laps or an
    /// error, never a panic, from reading and from verifying alike.
    #[test]
    fn lap_files_never_panic(muts in prop::collection::vec((0u8..4, any::<u32>(), any::<u8>()), 1..6)) {
        let mut b = lap_file();
        for (what, at, v) in muts {
            let pos = at as usize % (b.len() + 1);
            match what {
                0 => if let Some(x) = b.get_mut(pos) { *x = v },
                1 => {
                    let extreme = [0u64, 1 << 32, u64::MAX, u64::from(v)][v as usize % 4];
                    let end = (pos + 8).min(b.len());
                    let bytes = extreme.to_le_bytes();
                    b[pos..end].copy_from_slice(&bytes[..end - pos]);
                }
                2 => b.truncate(pos),
                _ => b.insert(pos, v),
            }
        }
        use placewords::io::lap_file::LapFileReader;
        let len = b.len() as u64;
        fuzz_timed("lap_file", &|| format!("{b:?}"), || {
            let _ = LapFileReader::open(&b[..], len).and_then(|r| r.read_runs());
            let _ = LapFileReader::open(&b[..], len).and_then(|r| r.verify());
        });
    }
}

/// The mutator reaches numbers: a corpus file comes back changed where a number stood.
#[test]
fn the_mutator_replaces_numbers() {
    let base = "a = 12\nb = [3.5, -4]\n";
    assert_eq!(mutate(base, &[(0, 0, 3)]), "a = 1e308\nb = [3.5, -4]\n");
    assert_eq!(
        mutate(base, &[(0, 2, 7)]),
        "a = 12\nb = [3.5, 18446744073709551615]\n"
    );
}
