//! Where a log's missing recall is: every observation with a revisit (an earlier observation at
//! least 20 m of true travel before, within 1 m, facing within 45° the same or the opposite way)
//! that no correct pair recognized, put in the first class that explains it:
//!
//! - **verify:CHECK**: the recognizer with verification off recognizes it; CHECK is the first check
//!   (travel, turn, density, sides, straight) whose tolerance, opened alone, recognizes it
//!   (`several` when none alone does);
//! - **short**: its revisit stretch (the consecutive observations around it that have a revisit
//!   the same way, across gaps of up to 1 m where a weaving robot strays) holds fewer level-0 words than τ (τ + `reverse_extra_ngram` read backwards):
//!   no chain of words fits there, whatever the checks (the decided out-of-reach case: no pose
//!   prior);
//! - **words:WHY**: the stretch is long enough, but the level-0 words along the true
//!   correspondence (each word against the word holding the true partner of its middle
//!   observation) do not match τ times in a row around it; WHY says where the run stops nearest
//!   it: `class`, `size` or `angle` differ, `order` (the past words are not consecutive),
//!   `partner` (a word's middle observation has no revisit that way), `end` (its run ends);
//! - **other**: a matching chain exists along the truth, but even without verification no correct
//!   pair covers it (the two-class rule, the candidate gap, the alignment placing it elsewhere,
//!   a chain through higher levels that differs).
//!
//! The classes are an estimate (the chain along the truth uses level 0 only), good enough to
//! tell which share a change to verification can reach.
//!
//! Then, for the misses outside the short stretches, how far along their stretch the nearest
//! recognized observation lies and on which side (the miss `before` a recognized run, `after`
//! one, or `between` two): misses next to recognized runs are within reach of the pairing
//! (`fill_max_psi_diff` came from this count), isolated ones of the words only.
//!
//! ```text
//! cargo run --release --example revisit_reach -- ../shared/data/carmen/intel-corrected.log.gz --seed 1
//! ```

use anyhow::Result;
use clap::Parser;
use placewords::eval::GroundTruth;
use placewords::experiment::{config_for_levels, load_recognizer_config};
use placewords::geom::wrap_angle;
use placewords::log::RunLog;
use placewords::recognizer::{Direction, Recognizer, RecognizerConfig, Word};
use std::collections::{BTreeMap, HashSet};
use std::path::PathBuf;
use std::process::ExitCode;

#[path = "support/input.rs"]
mod input;

#[derive(Parser)]
#[command(about = "Why a log's revisits were not recognized")]
struct Args {
    /// A CARMEN log (plain or gzip) or a scenario file (.toml).
    input: PathBuf,
    /// Odometry noise seed (log) or the scenario's seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Level configurations (as `recognize --levels`).
    #[arg(long, default_value_t = 3)]
    levels: usize,
    /// Recognizer settings (as `recognize --config`) instead of the defaults.
    #[arg(long)]
    config: Option<PathBuf>,
}

/// Ground-truth rule: radius, minimum true travel between the visits, heading tolerance.
const RADIUS_M: f64 = 1.0;
const MIN_GAP_M: f64 = 20.0;
const HEADING_TOL_DEG: f64 = 45.0;
/// How far along its stretch a miss looks for the nearest recognized observation, metres.
const NEAREST_REACH_M: f64 = 20.0;
/// Observations without a revisit a stretch runs on across, as travel, metres.
const STRETCH_GAP_M: f64 = 1.0;

/// One observation's truth: position, heading, true travel.
struct Truth {
    x: f64,
    y: f64,
    theta: f64,
    travel_m: f64,
}

fn main() -> ExitCode {
    input::exit_code(run(&Args::parse()))
}

fn run(args: &Args) -> Result<()> {
    let (runs, mut cfg) = input::load(&args.input, args.seed)?;
    if let Some(path) = &args.config {
        cfg = load_recognizer_config(path)?;
    }
    let cfg = config_for_levels(&cfg, args.levels);
    let truth = GroundTruth::from_runs(&runs);
    let (rec, pairs) = recognize(&runs, cfg.clone())?;
    let t = truths(&rec, &truth);
    let partner: Vec<Option<(usize, Direction)>> = (0..t.len()).map(|i| revisit(&t, i)).collect();
    let recognized = |pairs: &[(usize, usize)]| -> HashSet<usize> {
        pairs
            .iter()
            .filter(|&&(q, p)| dist(&t[q], &t[p]) <= RADIUS_M)
            .map(|&(q, _)| q)
            .collect()
    };
    let base = recognized(&pairs);
    let loose = |edit: &dyn Fn(&mut RecognizerConfig)| -> Result<HashSet<usize>> {
        let mut c = cfg.clone();
        edit(&mut c);
        Ok(recognized(&recognize(&runs, c)?.1))
    };
    let no_verify = loose(&|c| c.verify.enabled = false)?;
    let checks: Vec<(&str, HashSet<usize>)> = vec![
        (
            "travel",
            loose(&|c| {
                c.verify.verify_travel_ratio = 10.0;
                c.verify.verify_travel_slack_m = 1e3;
            })?,
        ),
        ("turn", loose(&|c| c.verify.verify_turn_deg = 360.0)?),
        ("density", loose(&|c| c.verify.verify_max_psi_rms = 1e3)?),
        (
            "sides",
            loose(&|c| {
                c.verify.verify_max_lateral_rms = 1e3;
                c.verify.reverse_verify_max_lateral_rms = 1e3;
            })?,
        ),
        ("straight", loose(&|c| c.verify.reverse_min_turn_deg = 0.0)?),
    ];
    let l0: Vec<&Word> = rec.words().level(0).collect();
    let mut word_of = vec![usize::MAX; t.len()];
    for (k, w) in l0.iter().enumerate() {
        for o in w.obs_range() {
            word_of[o] = k;
        }
    }
    let tau = cfg.matcher.min_ngram[0].max(1);
    // A weaving robot leaves the 1 m radius (or the 45° heading) for a few observations inside
    // one revisit: a stretch runs on across such gaps.
    let gap = (STRETCH_GAP_M / cfg.front_end.observation_spacing_m).round() as usize;
    let mut classes: BTreeMap<String, [usize; 2]> = BTreeMap::new();
    let mut nearest: BTreeMap<String, [usize; 2]> = BTreeMap::new();
    let (mut with_revisit, mut hit) = (0, 0);
    for i in 0..t.len() {
        let Some((_, dir)) = partner[i] else { continue };
        with_revisit += 1;
        if base.contains(&i) {
            hit += 1;
            continue;
        }
        let need = match dir {
            Direction::Same => tau,
            Direction::Opposite => tau + cfg.matcher.reverse_extra_ngram,
        };
        let class = if no_verify.contains(&i) {
            let first = checks.iter().find(|(_, s)| s.contains(&i));
            format!("verify:{}", first.map_or("several", |c| c.0))
        } else if stretch_words(&partner, &l0, &word_of, i, dir, gap) < need {
            "short".to_string()
        } else if let (len, why) = truth_chain(&cfg, &partner, &l0, &word_of, i, dir)
            && len < need
        {
            format!("words:{why}")
        } else {
            "other".to_string()
        };
        if class != "short" {
            let spacing_m = cfg.front_end.observation_spacing_m;
            let reach = (NEAREST_REACH_M / spacing_m).round() as usize;
            let row = match nearest_recognized(&partner, &base, i, dir, gap, reach) {
                Some((n, side)) => format!("{}, {side}", distance_bucket(n as f64 * spacing_m)),
                None => format!("none within {NEAREST_REACH_M} m"),
            };
            nearest.entry(row).or_default()[dir as usize] += 1;
        }
        classes.entry(class).or_default()[dir as usize] += 1;
    }
    let share = |n: usize| n as f64 / with_revisit.max(1) as f64;
    println!(
        "{with_revisit} observations with a revisit, {hit} recognized (recall {:.3})",
        share(hit)
    );
    println!(
        "{:<16} {:>6} {:>6} {:>6}  share",
        "not recognized", "same", "opp", "all"
    );
    for (class, [same, opp]) in &classes {
        let n = same + opp;
        println!("{class:<16} {same:>6} {opp:>6} {n:>6}  {:.3}", share(n));
    }
    println!(
        "misses outside the short stretches, by the nearest recognized observation of their stretch:"
    );
    println!("{:<20} {:>6} {:>6}", "nearest, side", "same", "opp");
    for (row, [same, opp]) in &nearest {
        println!("{row:<20} {same:>6} {opp:>6}");
    }
    let short = classes.get("short").map_or(0, |c| c[0] + c[1]);
    let right = |q: usize, p: usize, dir: Direction| {
        let turn = wrap_angle(t[q].theta - t[p].theta).abs();
        let tol = HEADING_TOL_DEG.to_radians();
        dist(&t[q], &t[p]) <= RADIUS_M
            && match dir {
                Direction::Same => turn <= tol,
                Direction::Opposite => turn >= std::f64::consts::PI - tol,
            }
    };
    let rejected = rec.diagnostics().rejected;
    let (mut lookalike, mut delayed, mut lost) = (0, 0, 0);
    for r in &rejected {
        let ok = right(r.query, r.past, r.direction)
            && r.oldest.is_none_or(|(q, p)| right(q, p, r.direction));
        if !ok {
            lookalike += 1;
        } else if base.contains(&r.query) {
            delayed += 1;
        } else {
            lost += 1;
        }
    }
    println!(
        "rejected candidates {}: look-alikes {lookalike}, true revisits recognized anyway {delayed}, true revisits lost {lost}",
        rejected.len()
    );
    println!(
        "ceiling without the short stretches: recall {:.3}; without verification: {:.3}",
        1.0 - share(short),
        share(no_verify.len().min(with_revisit))
    );
    Ok(())
}

/// The recognizer after every frame of `runs`, and every (query, past) observation pair its
/// matches claimed.
fn recognize(runs: &[RunLog], cfg: RecognizerConfig) -> Result<(Recognizer, Vec<(usize, usize)>)> {
    let mut rec = Recognizer::new(cfg)?;
    let mut pairs = Vec::new();
    let mut frame = 0;
    let mut take = |ms: Vec<placewords::recognizer::WordMatch>| {
        for m in ms {
            pairs.extend(m.pairs());
        }
    };
    for run in runs {
        take(rec.start_run());
        for f in run.frames() {
            take(rec.push_frame(frame, f.odom, &f.scan));
            frame += 1;
        }
    }
    take(rec.finish());
    Ok((rec, pairs))
}

/// Every observation's true pose and true travel.
fn truths(rec: &Recognizer, truth: &GroundTruth) -> Vec<Truth> {
    let mut out: Vec<Truth> = Vec::new();
    for o in rec.observations() {
        let p = truth
            .observation_pose(o)
            .expect("every frame has a truth")
            .0;
        let travel_m = out
            .last()
            .map_or(0.0, |l| l.travel_m + (p.x - l.x).hypot(p.y - l.y));
        out.push(Truth {
            x: p.x,
            y: p.y,
            theta: p.theta,
            travel_m,
        });
    }
    out
}

fn dist(a: &Truth, b: &Truth) -> f64 {
    (a.x - b.x).hypot(a.y - b.y)
}

/// The nearest earlier observation that is a revisit of `i`, and which way it was driven.
fn revisit(t: &[Truth], i: usize) -> Option<(usize, Direction)> {
    let tol = HEADING_TOL_DEG.to_radians();
    let mut best: Option<(f64, usize, Direction)> = None;
    for j in 0..i {
        if t[i].travel_m - t[j].travel_m < MIN_GAP_M {
            break;
        }
        let d = dist(&t[i], &t[j]);
        if d > RADIUS_M || best.is_some_and(|b| b.0 <= d) {
            continue;
        }
        let turn = wrap_angle(t[i].theta - t[j].theta).abs();
        if turn <= tol {
            best = Some((d, j, Direction::Same));
        } else if turn >= std::f64::consts::PI - tol {
            best = Some((d, j, Direction::Opposite));
        }
    }
    best.map(|(_, j, dir)| (j, dir))
}

/// How many observations along its revisit stretch (driven the way `dir` says, across gaps of
/// at most `gap` observations without a revisit) the nearest recognized observation lies from
/// `i`, up to `reach`, and on which side of it `i` is: `before` it, `after` it, or `between` two
/// equally near; `None` when none is that near.
fn nearest_recognized(
    partner: &[Option<(usize, Direction)>],
    recognized: &HashSet<usize>,
    i: usize,
    dir: Direction,
    gap: usize,
    reach: usize,
) -> Option<(usize, &'static str)> {
    let inside = |o: usize| partner[o].is_some_and(|(_, d)| d == dir);
    // Steps from `i` one way (`by` = ±1) to the first recognized observation of the stretch.
    let walk = |by: isize| -> Option<usize> {
        let mut without = 0;
        for n in 1..=reach {
            let o = i
                .checked_add_signed(by * n as isize)
                .filter(|&o| o < partner.len())?;
            if !inside(o) {
                without += 1;
                if without > gap {
                    return None;
                }
                continue;
            }
            without = 0;
            if recognized.contains(&o) {
                return Some(n);
            }
        }
        None
    };
    match (walk(1), walk(-1)) {
        (Some(a), Some(b)) if a == b => Some((a, "between")),
        (Some(a), Some(b)) if a < b => Some((a, "before")),
        (Some(a), None) => Some((a, "before")),
        (_, Some(b)) => Some((b, "after")),
        (None, None) => None,
    }
}

/// The distance class of a miss `m` metres from the nearest recognized observation.
fn distance_bucket(m: f64) -> String {
    let upto = [1.0, 2.0, 4.0, 8.0]
        .into_iter()
        .find(|&b| m <= b + 1e-9)
        .unwrap_or(NEAREST_REACH_M);
    format!("≤ {upto} m")
}

/// Level-0 words with at least half their observations in the revisit stretch around `i`
/// (consecutive observations with a revisit driven the way `dir` says, across gaps of at most
/// `gap` observations without).
fn stretch_words(
    partner: &[Option<(usize, Direction)>],
    l0: &[&Word],
    word_of: &[usize],
    i: usize,
    dir: Direction,
    gap: usize,
) -> usize {
    let inside = |o: usize| partner[o].is_some_and(|(_, d)| d == dir);
    let (mut a, mut b) = (i, i);
    while let Some(o) = (a.saturating_sub(gap + 1)..a).rev().find(|&o| inside(o)) {
        a = o;
    }
    while let Some(o) = (b + 1..(b + gap + 2).min(partner.len())).find(|&o| inside(o)) {
        b = o;
    }
    let (wa, wb) = (word_of[a], word_of[b]);
    (wa..=wb)
        .filter(|&k| {
            let r = l0[k].obs_range();
            let within = r.clone().filter(|&o| o >= a && o <= b).count();
            2 * within >= r.len()
        })
        .count()
}

/// The longest run of consecutive level-0 word pairs around `i`'s word that match along the
/// true correspondence (each word against the word holding its middle observation's partner,
/// the past words consecutive in the way `dir` reads them), and why it stops nearest `i`:
/// `partner` (the middle observation has no revisit that way), `class`, `size`, `angle`, or
/// `order` (the past words are not consecutive).
fn truth_chain(
    cfg: &RecognizerConfig,
    partner: &[Option<(usize, Direction)>],
    l0: &[&Word],
    word_of: &[usize],
    i: usize,
    dir: Direction,
) -> (usize, &'static str) {
    let pair = |k: usize| -> Result<usize, &'static str> {
        let w = l0[k];
        let mid = w.first_obs + w.size / 2;
        let (p, _) = partner[mid].filter(|&(_, d)| d == dir).ok_or("partner")?;
        let pk = word_of[p];
        let v = l0[pk];
        let sizes = cfg.matcher.sizes_match(
            w.size,
            v.size,
            w.sampling_slack_obs + v.sampling_slack_obs,
            dir,
        );
        let b = if dir == Direction::Opposite {
            -v.angle_deg
        } else {
            v.angle_deg
        };
        let da = wrap_angle((w.angle_deg - b).to_radians())
            .abs()
            .to_degrees();
        if w.class != v.class {
            Err("class")
        } else if !sizes {
            Err("size")
        } else if da > cfg.matcher.angle_tolerance_deg {
            Err("angle")
        } else {
            Ok(pk)
        }
    };
    let step: i64 = if dir == Direction::Opposite { -1 } else { 1 };
    let k0 = word_of[i];
    let p0 = match pair(k0) {
        Ok(p) => p,
        Err(why) => return (0, why),
    };
    // Walks from i's word one way (`by` = ±1) while the pairs match and follow each other.
    let walk = |by: i64| -> (usize, &'static str) {
        let (mut k, mut pk, mut len) = (k0 as i64, p0 as i64, 0);
        loop {
            let next = k + by;
            if next < 0 || next >= l0.len() as i64 || l0[next as usize].run != l0[k as usize].run {
                return (len, "end");
            }
            match pair(next as usize) {
                Ok(q) if q as i64 == pk + by * step => (k, pk, len) = (next, q as i64, len + 1),
                Ok(_) => return (len, "order"),
                Err(why) => return (len, why),
            }
        }
    };
    let ((back, why_back), (fwd, why_fwd)) = (walk(-1), walk(1));
    (1 + back + fwd, if back <= fwd { why_back } else { why_fwd })
}
