//! Whether the ambiguity map predicts the recognizer: a scenario's map (its door sets, its
//! robot, its recognizer settings) held against the false pairs of real, noisy runs of the same
//! scenario. Each false pair is placed on the route at its query's true position (the nearest
//! point of the route); the pair is *predicted* when that point lies in a flagged stretch. The
//! figures: the share of false pairs predicted, the share of the route flagged, and their
//! ratio, the map's *lift* (1 = no better than flagging at random).

use super::ambiguity::{
    AmbiguityError, AmbiguityReport, BIN_M, Cause, Drive, DriveSettings, ambiguity_with, mark,
};
use crate::experiment::{ExperimentOptions, Scenario, run_scenario};
use crate::geom::Vec2;
use crate::sim::plan::{DoorChoice, DoorPlan};
use crate::world::Route;
use serde::Serialize;

/// Laps of a random-door run whose draws stand for its distribution in the map.
pub const RANDOM_DOOR_DRAWS: usize = 4;

/// Along-route distance under which a false pair counts as a slip along the corridor, metres.
pub const SLIP_PAIR_M: f64 = 5.0;

/// The door sets a scenario's runs use, each once (a random-door run: its first
/// [`RANDOM_DOOR_DRAWS`] laps' draws at the scenario's seed), its robot and its seed.
pub fn scenario_drive_settings(scn: &Scenario) -> DriveSettings {
    let plan = &scn.sim;
    let mut sets: Vec<DoorChoice> = Vec::new();
    let mut add = |c: DoorChoice| {
        if !sets.iter().any(|s| s.states == c.states) {
            sets.push(c);
        }
    };
    for (run, r) in plan.runs.iter().enumerate() {
        match &r.doors {
            DoorPlan::Fixed(c) => add(c.clone()),
            DoorPlan::Cycle(list) => list.iter().cloned().for_each(&mut add),
            DoorPlan::Random { .. } => {
                for lap in 0..RANDOM_DOOR_DRAWS {
                    let (_, states) = crate::sim::runner::door_states(plan, run, lap);
                    add(DoorChoice {
                        name: format!("random (run {run}, lap {lap})"),
                        states,
                    });
                }
            }
        }
    }
    DriveSettings {
        door_sets: sets,
        robot: plan.robot.clone(),
        seed: plan.seed,
    }
}

/// The ambiguity map of a scenario: its world and route, every door set its runs use, its
/// robot, its recognizer settings (all its level configurations) and its true-positive radius.
pub fn scenario_ambiguity(scn: &Scenario) -> Result<(AmbiguityReport, Drive), AmbiguityError> {
    ambiguity_with(
        &scn.sim.world,
        &scn.sim.route.id,
        &scenario_drive_settings(scn),
        &scn.recognizer,
        scn.evaluation.tp_radius_m,
    )
}

/// The map against the recognizer over some seeds.
#[derive(Clone, Debug, Serialize)]
pub struct Prediction {
    pub scenario: String,
    /// The subject whose false pairs are placed (the scenario's deepest level configuration).
    pub subject: String,
    pub seeds: Vec<u64>,
    /// Observation pairs the subject claimed, over the seeds.
    pub pairs: usize,
    pub false_pairs: usize,
    /// False pairs whose query lies in a flagged stretch.
    pub predicted: usize,
    /// `predicted / false_pairs` (0 when there are none).
    pub predicted_share: f64,
    /// Share of the route flagged, 0..1.
    pub flagged_share: f64,
    /// `predicted_share / flagged_share`: how much better than flagging at random.
    pub lift: f64,
    /// Predicted false pairs by the cause of the flag at their query (one pair may count under
    /// several causes where flags overlap).
    pub predicted_look_alike: usize,
    pub predicted_door_change: usize,
    /// Under a slip or a shift (the words of a stretch matching itself shifted).
    pub predicted_slip: usize,
    /// False pairs whose two ends lie within [`SLIP_PAIR_M`] of each other along the route:
    /// slips along a corridor.
    pub slip_pairs: usize,
    /// Per seed: (seed, false pairs, predicted).
    pub per_seed: Vec<(u64, usize, usize)>,
    /// Every false pair's query and past, metres along the route (to plot or count anew).
    pub places_m: Vec<(f64, f64)>,
}

/// Per 0.1 m bin of the loop, which causes flag it: (look-alike, door change, slip).
struct Flags {
    look_alike: Vec<bool>,
    door_change: Vec<bool>,
    slip: Vec<bool>,
}

impl Flags {
    fn of(report: &AmbiguityReport) -> Flags {
        let n = ((report.route_length_m / BIN_M).ceil() as usize).max(1);
        let mut f = Flags {
            look_alike: vec![false; n],
            door_change: vec![false; n],
            slip: vec![false; n],
        };
        for s in &report.stretches {
            let into = match s.cause {
                Cause::LookAlike => &mut f.look_alike,
                Cause::DoorChange => &mut f.door_change,
                Cause::Shift => &mut f.slip,
            };
            mark(into, s.from_m, s.length_m);
        }
        for s in &report.slips {
            mark(&mut f.slip, s.from_m, s.length_m);
        }
        f
    }

    fn any(&self, b: usize) -> bool {
        self.look_alike[b] || self.door_change[b] || self.slip[b]
    }

    fn share(&self) -> f64 {
        let n = self.slip.len();
        (0..n).filter(|&b| self.any(b)).count() as f64 / n as f64
    }
}

/// Metres along `route` (from waypoint 0) of the route point nearest to `p`.
pub fn place_on_route(route: &Route, p: Vec2) -> f64 {
    let mut start = 0.0;
    let mut best = (f64::INFINITY, 0.0);
    for leg in route.legs() {
        let t = leg.project(p);
        let dist = (p - leg.point_at(t)).norm();
        if dist < best.0 {
            best = (dist, start + t * leg.length());
        }
        start += leg.length();
    }
    best.1
}

/// Runs `scn` at each of `seeds` (its deepest level configuration only), places every false
/// pair on the route and holds them against the scenario's ambiguity map `report`.
pub fn predict(
    scn: &Scenario,
    report: &AmbiguityReport,
    seeds: &[u64],
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Prediction, crate::experiment::ExperimentError> {
    let levels = scn.recognizer.levels;
    let flags = Flags::of(report);
    let n = flags.slip.len();
    let loop_m = report.route_length_m;
    let bin = |s: f64| ((s / BIN_M) as usize).min(n - 1);
    let mut out = Prediction {
        scenario: scn.sim.name.clone(),
        subject: format!("words-{levels}"),
        seeds: seeds.to_vec(),
        pairs: 0,
        false_pairs: 0,
        predicted: 0,
        predicted_share: 0.0,
        flagged_share: flags.share(),
        lift: 0.0,
        predicted_look_alike: 0,
        predicted_door_change: 0,
        predicted_slip: 0,
        slip_pairs: 0,
        per_seed: Vec::new(),
        places_m: Vec::new(),
    };
    for &seed in seeds {
        progress(seed);
        let mut one = scn.clone();
        one.sim.seed = seed;
        let opts = ExperimentOptions {
            levels: vec![levels],
            ..ExperimentOptions::default()
        };
        let exp = run_scenario(&one, &opts)?;
        let Some((_, rec)) = exp.recognitions.first() else {
            continue;
        };
        let status = crate::eval::observation_status::observation_status(rec, &scn.evaluation);
        let (mut wrong, mut hit) = (0, 0);
        for (q, p) in &status.wrong_pairs {
            let (sq, sp) = (
                place_on_route(&scn.sim.route, *q),
                place_on_route(&scn.sim.route, *p),
            );
            out.places_m
                .push(((sq * 10.0).round() / 10.0, (sp * 10.0).round() / 10.0));
            let along = (sq - sp).rem_euclid(loop_m);
            out.slip_pairs += usize::from(along.min(loop_m - along) <= SLIP_PAIR_M);
            let b = bin(sq);
            wrong += 1;
            if flags.any(b) {
                hit += 1;
                out.predicted_look_alike += usize::from(flags.look_alike[b]);
                out.predicted_door_change += usize::from(flags.door_change[b]);
                out.predicted_slip += usize::from(flags.slip[b]);
            }
        }
        out.pairs += status.pair_counts.iter().map(|c| c.1).sum::<usize>();
        out.false_pairs += wrong;
        out.predicted += hit;
        out.per_seed.push((seed, wrong, hit));
    }
    if out.false_pairs > 0 {
        out.predicted_share = out.predicted as f64 / out.false_pairs as f64;
    }
    if out.flagged_share > 0.0 {
        out.lift = out.predicted_share / out.flagged_share;
    }
    Ok(out)
}

impl Prediction {
    /// A few lines for people.
    pub fn summary(&self) -> String {
        let pct = |x: f64| 100.0 * x;
        if self.false_pairs == 0 {
            // 0 of 0 is no share: say there was nothing to place instead of "0 %, lift 0".
            return format!(
                "{} ({}, seeds {:?}): no false pair to place ({} pairs, all correct); the \
                 flagged stretches cover {:.0} % of the route\n",
                self.scenario,
                self.subject,
                self.seeds,
                self.pairs,
                pct(self.flagged_share)
            );
        }
        let mut s = format!(
            "{} ({}, seeds {:?}): {} of {} false pairs ({:.0} %) lie in flagged stretches, \
             which cover {:.0} % of the route (lift {:.1})\n",
            self.scenario,
            self.subject,
            self.seeds,
            self.predicted,
            self.false_pairs,
            pct(self.predicted_share),
            pct(self.flagged_share),
            self.lift
        );
        s.push_str(&format!(
            "  flagged as look-alike {}, door change {}, slip {}; {} of the false pairs are \
             slips of at most {SLIP_PAIR_M} m along the route\n",
            self.predicted_look_alike,
            self.predicted_door_change,
            self.predicted_slip,
            self.slip_pairs
        ));
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without a false pair the summary says there was nothing to place, not "0 of 0 (0 %)"
    /// and a lift of 0; with some it gives the share and the lift.
    #[test]
    fn a_run_without_false_pairs_is_said_to_have_none() {
        let mut p = Prediction {
            scenario: "smoke".into(),
            subject: "words-3".into(),
            seeds: vec![1, 2],
            pairs: 3_236,
            false_pairs: 0,
            predicted: 0,
            predicted_share: 0.0,
            flagged_share: 0.57,
            lift: 0.0,
            predicted_look_alike: 0,
            predicted_door_change: 0,
            predicted_slip: 0,
            slip_pairs: 0,
            per_seed: vec![(1, 0, 0), (2, 0, 0)],
            places_m: Vec::new(),
        };
        let none = p.summary();
        assert!(
            none.contains("no false pair to place (3236 pairs, all correct)"),
            "{none}"
        );
        assert!(!none.contains("lift"), "{none}");
        (p.false_pairs, p.predicted, p.predicted_share, p.lift) = (10, 8, 0.8, 0.8 / 0.57);
        let some = p.summary();
        assert!(some.contains("8 of 10 false pairs (80 %)"), "{some}");
        assert!(some.contains("lift 1.4"), "{some}");
    }
}
