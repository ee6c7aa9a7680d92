//! JSON output of `placewords run`, `table` and `sweep`: the results [`crate::eval::scores`]
//! holds, written as pretty JSON (its module doc gives the schema), and read back for checks.

use crate::eval::provenance::Provenance;
use crate::eval::scores::Report;
use serde::Serialize;

/// A result with its provenance appended under `provenance`, the result's own keys first and
/// in their order.
#[derive(Serialize)]
struct WithProvenance<'a, T: Serialize> {
    #[serde(flatten)]
    result: &'a T,
    provenance: &'a Provenance,
}

/// `value` (a [`Report`], `SweepReport` or `TableReport`) as pretty-printed JSON.
pub fn to_json(value: &impl Serialize) -> String {
    // The result types hold only numbers, strings and vectors: serializing cannot fail.
    serde_json::to_string_pretty(value).expect("a result always serializes")
}

/// `value` (a struct) as pretty JSON with `provenance` (`eval::provenance`) as its last key:
/// what every command writes.
pub fn to_json_with(value: &impl Serialize, provenance: &Provenance) -> String {
    to_json(&WithProvenance {
        result: value,
        provenance,
    })
}

/// The provenance of a report's JSON (any command's), or why it has none.
pub fn provenance_from_json(s: &str) -> serde_json::Result<Provenance> {
    #[derive(serde::Deserialize)]
    struct Only {
        provenance: Provenance,
    }
    serde_json::from_str::<Only>(s).map(|o| o.provenance)
}

/// A report read back from its JSON.
pub fn report_from_json(s: &str) -> serde_json::Result<Report> {
    serde_json::from_str(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::scores::tests::sample;

    #[test]
    fn report_json_has_the_promised_keys_and_round_trips() {
        let rep = sample("B", [0.93, 0.91, 0.9], [0.1, 0.25, 0.33]);
        let json = to_json(&rep);
        let v: serde_json::Value = serde_json::from_str(&json).unwrap();
        for k in [
            "scenario",
            "seed",
            "laps",
            "revisits",
            "subjects",
            "simulate_seconds_per_lap",
        ] {
            assert!(v.get(k).is_some(), "missing {k}");
        }
        for k in [
            "name",
            "kind",
            "levels",
            "thresholds",
            "precision",
            "recall",
            "match_precision",
            "pairs",
            "recognize_seconds_per_lap",
            "sensitivity",
            "door_configs",
        ] {
            assert!(v["subjects"][0].get(k).is_some(), "missing subjects[0].{k}");
        }
        assert_eq!(v["subjects"][0]["name"], "words-1");
        assert_eq!(v["subjects"][0]["kind"], "words");
        let icp = &v["subjects"][3];
        assert_eq!((&icp["name"], &icp["kind"]), (&"icp".into(), &"icp".into()));
        for k in ["precision", "recall", "pairs", "recognize_seconds_per_lap"] {
            assert!(icp.get(k).is_some(), "missing the icp subject's {k}");
        }
        assert!(
            icp.get("levels").is_none(),
            "levels belong to words subjects"
        );
        assert_eq!(v["revisits"], 5000);
        assert_eq!(report_from_json(&json).unwrap(), rep);
    }

    #[test]
    fn provenance_goes_last_and_reads_back() {
        let rep = sample("B", [0.93, 0.91, 0.9], [0.1, 0.25, 0.33]);
        let mut prov = Provenance::new(vec!["placewords".into(), "run".into()]);
        prov.add_seeds([3]);
        let json = to_json_with(&rep, &prov);
        assert_eq!(provenance_from_json(&json).unwrap(), prov);
        assert_eq!(
            report_from_json(&json).unwrap(),
            rep,
            "a reader of reports skips it"
        );
        let plain = to_json(&rep);
        assert!(
            json.starts_with(plain.trim_end_matches("\n}")),
            "the result's keys come first"
        );
    }
}
