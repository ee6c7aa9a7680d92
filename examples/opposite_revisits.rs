//! Where a log's (or a scenario's) opposite-direction revisits are and why word chains read
//! backwards do or do not follow them: the stretches of observations whose true revisit was
//! driven the other way (their length in metres and level-0 words), the level-0 words of the
//! two passes side by side (the past pass read backwards: order reversed, angle syllable
//! negated), which syllable of each pair fails to match (class D, size S, angle A), and the
//! longest run of consecutive matching level-0 pairs in each stretch, strict and bridging one
//! substituted word, against the τ an opposite chain needs.
//!
//! ```text
//! cargo run --release --example opposite_revisits -- ../shared/data/carmen/fhw-corrected.log.gz --seed 1
//! cargo run --release --example opposite_revisits -- scenarios/reverse.toml --seed 1 --list
//! ```

use anyhow::Result;
use clap::Parser;
use placewords::eval::GroundTruth;
use placewords::geom::Pose2;
use placewords::recognizer::{Direction, RecognizerConfig, Word};
use std::path::PathBuf;
use std::process::ExitCode;

#[path = "support/input.rs"]
mod input;

#[derive(Parser)]
#[command(about = "Opposite-direction revisits of a log or scenario, word by word")]
struct Args {
    /// A CARMEN log (plain or gzip) or a scenario file (.toml).
    input: PathBuf,
    /// Odometry noise seed (log) or the scenario's seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print the words of every stretch side by side (else one line per stretch).
    #[arg(long)]
    list: bool,
    /// Shortest stretch printed, metres.
    #[arg(long, default_value_t = 5.0)]
    min_stretch_m: f64,
    /// A recognizer settings file (`[recognizer]` table) instead of the input's settings.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Print Ψ and the class of every 3rd observation of level-0 words FROM..TO (e.g. `72..80`)
    /// beside its revisit's.
    #[arg(long)]
    profile: Option<String>,
    /// The same-direction revisits instead (the past pass read forwards), for comparison.
    #[arg(long)]
    same: bool,
}

/// The truth's rule for a revisit: within 1 m, at least 20 m of true travel before, facing
/// within 45° of the opposite way.
const RADIUS_M: f64 = 1.0;
const GAP_M: f64 = 20.0;
const FACING_RAD: f64 = std::f64::consts::FRAC_PI_4;

fn main() -> ExitCode {
    input::exit_code(run(&Args::parse()))
}

/// Per observation, the nearest earlier observation that is its revisit driven the other way
/// (driven the same way with `same`).
fn partners(poses: &[Pose2], travel: &[f64], same: bool) -> Vec<Option<usize>> {
    let flip = if same { 0.0 } else { std::f64::consts::PI };
    let mut out = vec![None; poses.len()];
    for (i, p) in poses.iter().enumerate() {
        let mut best: Option<(f64, usize)> = None;
        for (j, q) in poses[..i].iter().enumerate() {
            if travel[i] - travel[j] < GAP_M {
                break;
            }
            let d = p.distance(q);
            let facing = placewords::geom::wrap_angle(p.theta - q.theta + flip);
            if d <= RADIUS_M && facing.abs() <= FACING_RAD && best.is_none_or(|(b, _)| d < b) {
                best = Some((d, j));
            }
        }
        out[i] = best.map(|(_, j)| j);
    }
    out
}

/// Which syllables of current word `c` and past word `p` read backwards fail the matcher's
/// rule: "D", "S", "A" (empty when they match).
fn failed_syllables(c: &Word, p: &Word, cfg: &RecognizerConfig, same: bool) -> String {
    let sign = if same { -1.0 } else { 1.0 };
    let m = &cfg.matcher;
    let mut out = String::new();
    if c.class != p.class {
        out.push('D');
    }
    let dir = if same {
        Direction::Same
    } else {
        Direction::Opposite
    };
    if !m.sizes_match(
        c.size,
        p.size,
        c.sampling_slack_obs + p.sampling_slack_obs,
        dir,
    ) {
        out.push('S');
    }
    let d = placewords::geom::wrap_angle((c.angle_deg + sign * p.angle_deg).to_radians())
        .to_degrees()
        .abs();
    let slack = (c.angle_slack_deg + p.angle_slack_deg).min(m.angle_tolerance_deg / 2.0);
    if d > m.angle_tolerance_deg + slack + 1e-9 {
        out.push('A');
    }
    out
}

/// A stretch: consecutive level-0 words of the current pass paired with past level-0 words
/// read backwards (the past word holding the partner of the current word's middle observation).
struct Stretch {
    pairs: Vec<(usize, usize)>,
    length_m: f64,
}

fn stretches(
    words: &[&Word],
    partner: &[Option<usize>],
    word_of: &[usize],
    same: bool,
) -> Vec<Stretch> {
    let mut out: Vec<Stretch> = Vec::new();
    let mut cur: Vec<(usize, usize)> = Vec::new();
    let close = |cur: &mut Vec<(usize, usize)>, out: &mut Vec<Stretch>| {
        if let (Some(&(f, _)), Some(&(l, _))) = (cur.first(), cur.last()) {
            let length_m = words[l].end_travel_m - words[f].start_travel_m;
            out.push(Stretch {
                pairs: std::mem::take(cur),
                length_m,
            });
        }
    };
    for (ci, w) in words.iter().enumerate() {
        let r = w.obs_range();
        let mid = r.start + r.len() / 2;
        // The middle observation's partner, else any of the word's.
        let p = partner[mid].or_else(|| r.clone().find_map(|o| partner[o]));
        let Some(p) = p.map(|o| word_of[o]) else {
            close(&mut cur, &mut out);
            continue;
        };
        let follows = cur.last().is_some_and(|&(lc, lp)| {
            let step = if same {
                p.wrapping_sub(lp)
            } else {
                lp.wrapping_sub(p)
            };
            lc + 1 == ci && step <= 2 && words[lc].run == w.run
        });
        if !follows {
            close(&mut cur, &mut out);
        }
        cur.push((ci, p));
    }
    close(&mut cur, &mut out);
    out
}

/// Longest run of consecutive matching pairs, strict and bridging one failed pair of equal class.
fn longest_runs(fails: &[String]) -> (usize, usize) {
    let (mut strict, mut best_strict, mut bridged, mut best_bridged) = (0, 0, 0, 0);
    let mut last_bridge_ok = false;
    for f in fails {
        if f.is_empty() {
            strict += 1;
            bridged += 1;
            last_bridge_ok = true;
        } else {
            strict = 0;
            // A substitution bridges a same-class word; the bridged pair does not count.
            bridged = if !f.contains('D') && last_bridge_ok {
                last_bridge_ok = false;
                bridged
            } else {
                0
            };
        }
        best_strict = best_strict.max(strict);
        best_bridged = best_bridged.max(bridged);
    }
    (best_strict, best_bridged)
}

/// The shift of the revisit's observation, along its own pass, that best aligns Ψ with the
/// current observation's (positive: later on the past pass), and the RMS Ψ difference there:
/// a shift that is not 0 is Ψ lagging along the direction of travel.
fn print_psi_lag(psi: &[f64], partner: &[Option<usize>], travel: &[f64]) {
    let rms = |k: i64| {
        let (mut sq, mut n) = (0.0, 0usize);
        for (i, p) in partner.iter().enumerate() {
            let Some(j) = p.and_then(|j| j.checked_add_signed(k as isize)) else {
                continue;
            };
            if j < psi.len() && (travel[j] - travel[p.unwrap_or(j)]).abs() < 5.0 {
                sq += (psi[i] - psi[j]).powi(2);
                n += 1;
            }
        }
        (sq / n.max(1) as f64).sqrt()
    };
    let line: Vec<String> = (-30..=30)
        .step_by(5)
        .map(|k| format!("{k}: {:.3}", rms(k)))
        .collect();
    println!(
        "RMS Ψ difference by shift of the revisit (observations): {}",
        line.join(", ")
    );
}

/// The candidates of the direction studied that verification turned down: the check, and how
/// far apart the true positions of the newest and the oldest pair are (a true revisit has both
/// within the truth's radius).
fn print_rejections(rec: &placewords::recognizer::Recognizer, poses: &[Pose2], same: bool) {
    use placewords::place::Direction;
    let want = if same {
        Direction::Same
    } else {
        Direction::Opposite
    };
    let diag = rec.diagnostics();
    let names = placewords::recognizer::Rejection::ALL;
    for r in diag.rejected.iter().filter(|r| r.direction == want) {
        let d = |(q, p): (usize, usize)| poses[q].distance(&poses[p]);
        let newest = d((r.query, r.past));
        let oldest = r.oldest.map_or(f64::NAN, d);
        println!(
            "  rejected by {:8}: newest pair {newest:6.1} m apart, oldest {oldest:6.1} m ({})",
            names[r.check].name(),
            if newest <= RADIUS_M && oldest <= RADIUS_M {
                "a true revisit"
            } else {
                "a look-alike"
            }
        );
    }
}

fn run(args: &Args) -> Result<()> {
    let (runs, mut cfg) = input::load(&args.input, args.seed)?;
    if let Some(path) = &args.config {
        cfg = placewords::experiment::load_recognizer_config(path)?;
    }
    let truth = GroundTruth::from_runs(&runs);
    let mut rec = placewords::recognizer::Recognizer::new(cfg.clone())?;
    let mut matches = Vec::new();
    let mut frame = 0;
    for run in &runs {
        matches.extend(rec.start_run());
        for f in run.frames() {
            matches.extend(rec.push_frame(frame, f.odom, &f.scan));
            frame += 1;
        }
    }
    matches.extend(rec.finish());
    let obs = rec.observations();
    let poses: Vec<Pose2> = obs
        .iter()
        .map(|o| truth.observation_pose(o).map_or(o.odom_pose.0, |p| p.0))
        .collect();
    let travel: Vec<f64> = obs.iter().map(|o| o.travel_m).collect();
    let partner = partners(&poses, &travel, args.same);
    let words: Vec<&Word> = rec.words().level(0).collect();
    let mut word_of = vec![0; obs.len()];
    for (i, w) in words.iter().enumerate() {
        word_of[w.obs_range()].fill(i);
    }
    let with = partner.iter().filter(|p| p.is_some()).count();
    // Ψ at an observation against Ψ at its revisit: how much the density of one place depends on
    // the way the robot drove through it.
    let psi = rec.words().psi();
    let (mut sq, mut n) = (0.0, 0usize);
    for (i, p) in partner.iter().enumerate() {
        if let Some(j) = *p {
            sq += (psi[i] - psi[j]).powi(2);
            n += 1;
        }
    }
    println!(
        "RMS Ψ difference between an observation and its revisit: {:.3} ({n} pairs)",
        (sq / n.max(1) as f64).sqrt()
    );
    print_psi_lag(psi, &partner, &travel);
    if let Some((from, to)) = args.profile.as_deref().and_then(|p| p.split_once("..")) {
        let (from, to): (usize, usize) = (from.parse()?, to.parse()?);
        let classes = rec.words().observation_classes();
        let words: Vec<&Word> = rec.words().level(0).collect();
        for w in &words[from..to.min(words.len())] {
            for i in w.obs_range().step_by(3) {
                let other = partner[i].map_or(String::new(), |j| {
                    format!("{:.3} D{} (obs {j})", psi[j], classes[j])
                });
                println!("  obs {i:5} Ψ {:.3} D{} | {other}", psi[i], classes[i]);
            }
        }
    }
    // How far across the path the revisit lies (a robot keeping to one side of a corridor
    // passes 2·offset apart driven the other way).
    let mut across: Vec<f64> = (partner.iter().enumerate())
        .filter_map(|(i, p)| p.map(|j| (i, j)))
        .map(|(i, j)| {
            let (a, b) = (poses[i], poses[j]);
            ((b.y - a.y) * a.theta.cos() - (b.x - a.x) * a.theta.sin()).abs()
        })
        .collect();
    across.sort_by(f64::total_cmp);
    if !across.is_empty() {
        println!(
            "distance across the path to the revisit: median {:.2} m, p75 {:.2} m",
            across[across.len() / 2],
            across[across.len() * 3 / 4]
        );
    }
    let tau = cfg.matcher.min_ngram[0] + cfg.matcher.reverse_extra_ngram;
    let min_words = cfg.matcher.ngram_travel_min_words + cfg.matcher.reverse_extra_ngram;
    println!(
        "{} observations, {with} with an opposite revisit; {} level-0 words; an opposite chain \
         needs {tau} words, or {min_words} spanning {} m and turning {}°",
        obs.len(),
        words.len(),
        cfg.matcher.reverse_ngram_travel_m,
        cfg.verify.reverse_min_turn_deg
    );
    let (mut tally, mut longest, mut pairs) = ([0usize; 3], (0, 0), 0);
    // Per pair of the same class, |S₁ − S₂| / max(S₁, S₂): how far the boundaries moved.
    let mut size_ratios: Vec<f64> = Vec::new();
    for s in stretches(&words, &partner, &word_of, args.same) {
        if s.length_m < args.min_stretch_m {
            continue;
        }
        let fails: Vec<String> = (s.pairs.iter())
            .map(|&(c, p)| failed_syllables(words[c], words[p], &cfg, args.same))
            .collect();
        pairs += fails.len();
        for &(c, p) in s
            .pairs
            .iter()
            .filter(|&&(c, p)| words[c].class == words[p].class)
        {
            let (a, b) = (words[c].size as f64, words[p].size as f64);
            size_ratios.push((a - b).abs() / a.max(b));
        }
        for (k, ch) in ['D', 'S', 'A'].iter().enumerate() {
            tally[k] += fails.iter().filter(|f| f.contains(*ch)).count();
        }
        let (strict, bridged) = longest_runs(&fails);
        longest = (longest.0.max(strict), longest.1.max(bridged));
        let (c0, p0) = s.pairs[0];
        let at = poses[words[c0].first_obs];
        let turn_deg =
            (poses[words[s.pairs[s.pairs.len() - 1].0].first_obs].theta - at.theta).to_degrees();
        println!(
            "stretch {:5.1} m, {:2} words (current from word {c0}, past from word {p0} back) at \
             ({:6.1}, {:6.1}), turning {turn_deg:6.0}°: longest matching run {strict} strict, \
             {bridged} bridged",
            s.length_m,
            s.pairs.len(),
            at.x,
            at.y
        );
        if args.list {
            for (&(c, p), f) in s.pairs.iter().zip(&fails) {
                let (cw, pw) = (words[c], words[p]);
                println!(
                    "    D{:2} S{:4} A{:6.1} | D{:2} S{:4} A{:6.1} (word {p:4})  {}",
                    cw.class,
                    cw.size,
                    cw.angle_deg,
                    pw.class,
                    pw.size,
                    if args.same {
                        pw.angle_deg
                    } else {
                        -pw.angle_deg
                    },
                    if f.is_empty() { "match" } else { f }
                );
            }
        }
    }
    print_rejections(&rec, &poses, args.same);
    let want = if args.same {
        placewords::place::Direction::Same
    } else {
        placewords::place::Direction::Opposite
    };
    for m in matches.iter().filter(|m| m.direction == want) {
        let far = m.pairs().map(|(q, p)| poses[q].distance(&poses[p]));
        println!(
            "  match at {} levels: {} word pairs, {} observation pairs, {:.1} m apart at most",
            m.levels,
            m.ngram_len,
            m.pair_count(),
            far.fold(0.0, f64::max)
        );
    }
    size_ratios.sort_by(f64::total_cmp);
    let q = |f: f64| size_ratios.get(((size_ratios.len().max(1) - 1) as f64 * f) as usize);
    println!(
        "failed syllables over the stretches' {pairs} pairs: class {}, size {}, angle {}; \
         same-class size differences (share of the larger) median {:.2}, p75 {:.2}; longest \
         matching run {} strict, {} bridged",
        tally[0],
        tally[1],
        tally[2],
        q(0.5).copied().unwrap_or(f64::NAN),
        q(0.75).copied().unwrap_or(f64::NAN),
        longest.0,
        longest.1
    );
    Ok(())
}
