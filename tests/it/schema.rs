//! The JSON Schemas for editors (`placewords schema`, docs/editors.md): the committed
//! `schemas/*.schema.json` are what the command prints, each schema's keys are the reader's,
//! every shipped file and fixture the readers accept passes its schema, and a file the reader
//! refuses for an unknown, missing or mistyped key fails its schema at that key (checks beyond
//! keys and types, like geometry, are the readers' alone). Re-mint the committed schemas with
//! `PLACEWORDS_BLESS=1`.

use super::common::{placewords, root};
use placewords::schema::FileKind;
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn validator(kind: FileKind) -> jsonschema::Validator {
    jsonschema::draft7::new(&kind.schema()).expect("the schema is valid draft-07")
}

/// `schemas/NAME.schema.json` equals `placewords schema NAME`, byte for byte.
#[test]
fn the_committed_schemas_are_what_placewords_schema_prints() {
    let bless = std::env::var_os("PLACEWORDS_BLESS").is_some();
    for kind in FileKind::ALL {
        let o = placewords(&["schema", kind.name()]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let printed = String::from_utf8(o.stdout).unwrap();
        assert_eq!(printed, kind.schema_text());
        let path = root().join(format!("schemas/{}.schema.json", kind.name()));
        if bless {
            std::fs::write(&path, &printed).unwrap();
        }
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            committed == printed,
            "{} differs from `placewords schema {}`; re-mint with PLACEWORDS_BLESS=1 and review the diff",
            path.display(),
            kind.name()
        );
        let v: Value = serde_json::from_str(&committed).unwrap();
        assert_eq!(v["$schema"], "http://json-schema.org/draft-07/schema#");
    }
}

/// `schema -o FILE` writes the same text; a wrong extension or kind is exit 2.
#[test]
fn schema_writes_a_file_and_refuses_bad_arguments() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("w.schema.json");
    let o = placewords(&["schema", "world", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        FileKind::World.schema_text()
    );
    let png = dir.path().join("w.png");
    assert_eq!(
        placewords(&["schema", "world", "-o", png.to_str().unwrap()])
            .status
            .code(),
        Some(2)
    );
    assert!(!png.exists());
    assert_eq!(placewords(&["schema", "robot"]).status.code(), Some(2));
}

/// Each object's properties in `schema`, by the path of the table (`robot_home`,
/// `walls[]`, `expect.subjects[].same`).
fn tables(schema: &Value) -> Vec<(String, BTreeSet<String>)> {
    fn walk(s: &Value, path: &str, out: &mut Vec<(String, BTreeSet<String>)>) {
        if let Some(any) = s.get("anyOf").and_then(Value::as_array) {
            for v in any {
                walk(v, path, out);
            }
        }
        if let Some(items) = s.get("items").filter(|i| i.is_object()) {
            walk(items, &format!("{path}[]"), out);
        }
        if let Some(p) = s.get("properties").and_then(Value::as_object) {
            out.push((path.to_string(), p.keys().cloned().collect()));
            for (k, v) in p {
                let sub = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                walk(v, &sub, out);
            }
        }
    }
    let mut out = Vec::new();
    walk(schema, "", &mut out);
    out
}

/// A table's path in a schema and the keys it holds.
type Table<'a> = (&'a str, BTreeSet<String>);

fn set(keys: &[&str]) -> BTreeSet<String> {
    keys.iter().map(|k| k.to_string()).collect()
}

/// Each table of each schema holds exactly the keys its reader accepts (the key tables the
/// readers check unknown keys against, and `RecognizerConfig`'s fields less the harness's),
/// refuses others, and every key has a type and a description saying its default.
#[test]
fn each_schema_table_holds_the_readers_keys() {
    use placewords::spec::{evaluation as ev, scenario as sc, world as wo};
    let defaults =
        toml::Table::try_from(placewords::recognizer::RecognizerConfig::default()).unwrap();
    let recognizer = defaults
        .keys()
        .filter(|k| !sc::RECOGNIZER_HARNESS_KEYS.contains(&k.as_str()))
        .cloned()
        .collect::<BTreeSet<_>>();
    // Each subtable of `[recognizer]` (`recognizer.grid`) with its keys.
    let subtables: Vec<(String, BTreeSet<String>)> = defaults
        .iter()
        .filter_map(|(k, v)| {
            Some((
                format!("recognizer.{k}"),
                v.as_table()?.keys().cloned().collect(),
            ))
        })
        .collect();
    let expected: [(FileKind, Vec<Table>); 2] = [
        (
            FileKind::World,
            vec![
                ("", set(wo::TOP_KEYS)),
                ("robot_home", set(wo::HOME_KEYS)),
                ("walls[]", set(wo::WALL_KEYS)),
                ("doors[]", set(wo::DOOR_KEYS)),
                ("routes[]", set(wo::ROUTE_KEYS)),
                ("areas[]", set(wo::AREA_KEYS)),
            ],
        ),
        (
            FileKind::Scenario,
            vec![
                ("", set(sc::TOP_KEYS)),
                ("runs[]", set(sc::RUN_KEYS)),
                ("runs[].doors_random", set(sc::DOORS_RANDOM_KEYS)),
                ("pedestrians", set(sc::PEDESTRIAN_KEYS)),
                ("laser", set(sc::LASER_KEYS)),
                ("odometry", set(sc::ODOMETRY_KEYS)),
                ("robot", set(sc::ROBOT_KEYS)),
                ("scan_context", set(sc::SCAN_CONTEXT_KEYS)),
                ("subjects[]", set(placewords::spec::subjects::SUBJECT_KEYS)),
                ("recognizer", recognizer),
                ("evaluation", set(ev::EVALUATION_KEYS)),
                ("expect", set(ev::EXPECT_KEYS)),
                ("expect.subjects[]", set(ev::EXPECT_SUBJECT_KEYS)),
                ("expect.subjects[].same", set(ev::EXPECT_DIRECTION_KEYS)),
                ("expect.subjects[].opposite", set(ev::EXPECT_DIRECTION_KEYS)),
                ("expect.regression", set(ev::EXPECT_REGRESSION_KEYS)),
            ]
            .into_iter()
            .chain(subtables.iter().map(|(p, k)| (p.as_str(), k.clone())))
            .collect(),
        ),
    ];
    let mut wrong = Vec::new();
    for (kind, want) in expected {
        let schema = kind.schema();
        let found = tables(&schema);
        for (path, keys) in &want {
            match found.iter().find(|(p, _)| p == path) {
                None => wrong.push(format!("{}: no table `{path}`", kind.name())),
                Some((_, got)) if got != keys => wrong.push(format!(
                    "{}: `{path}` has {got:?}, the reader takes {keys:?}",
                    kind.name()
                )),
                Some(_) => {}
            }
        }
        let mut tables_seen = found.iter().map(|(p, _)| p.as_str()).collect::<Vec<_>>();
        tables_seen.retain(|p| !want.iter().any(|(w, _)| w == p));
        if !tables_seen.is_empty() {
            wrong.push(format!(
                "{}: tables no reader has: {tables_seen:?}",
                kind.name()
            ));
        }
        let unknown = serde_json::json!({ "format_versoin": 1 });
        assert!(!validator(kind).is_valid(&unknown), "{}", kind.name());
        check_properties(&schema, kind.name(), &mut wrong);
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// Every property has a type (or an enumeration) and a description that gives its default
/// (or says it is required); every table refuses unknown keys but `[door_configs]`, whose keys
/// are the author's names.
fn check_properties(s: &Value, at: &str, wrong: &mut Vec<String>) {
    let s = match s.get("anyOf").and_then(Value::as_array) {
        Some(any) => any
            .iter()
            .find(|v| v.get("type") != Some(&"null".into()))
            .unwrap_or(s),
        None => s,
    };
    if let Some(items) = s.get("items").filter(|i| i.is_object()) {
        check_properties(items, &format!("{at}[]"), wrong);
    }
    let Some(props) = s.get("properties").and_then(Value::as_object) else {
        return;
    };
    if s.get("additionalProperties") != Some(&Value::Bool(false)) {
        wrong.push(format!("{at}: unknown keys are not refused"));
    }
    for (k, v) in props {
        let typed = ["type", "enum", "oneOf", "anyOf", "const"]
            .iter()
            .any(|t| v.get(*t).is_some());
        if !typed {
            wrong.push(format!("{at}.{k}: no type"));
        }
        let d = v["description"].as_str().unwrap_or("");
        if !(d.contains("Default") || d.contains("default") || d.contains("Required")) {
            wrong.push(format!("{at}.{k}: the description gives no default: {d:?}"));
        }
        if k != "door_configs" {
            check_properties(v, &format!("{at}.{k}"), wrong);
        }
    }
}

/// Every shipped world and scenario starts with a `#:schema` line naming its committed schema.
#[test]
fn shipped_files_point_at_their_schema() {
    for (dir, kind) in [
        ("worlds", FileKind::World),
        ("scenarios", FileKind::Scenario),
    ] {
        for path in toml_files(&root().join(dir)) {
            let src = std::fs::read_to_string(&path).unwrap();
            let first = src.lines().next().unwrap_or("");
            let want = format!("#:schema ../schemas/{}.schema.json", kind.name());
            assert_eq!(first, want, "{}", path.display());
            let named = path
                .parent()
                .unwrap()
                .join(first.trim_start_matches("#:schema ").trim());
            assert!(
                named.is_file(),
                "{}: {} is missing",
                path.display(),
                named.display()
            );
        }
    }
}

fn toml_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "toml") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// What a TOML file is, by its keys: a world, a scenario, or neither (a recognizer settings
/// file, or text that is not TOML).
fn kind_of(path: &Path) -> Option<(FileKind, Value)> {
    let name = path.file_name()?.to_str()?;
    if name.ends_with(".recognizer.toml") {
        return None;
    }
    let text = std::fs::read_to_string(path).ok()?;
    let table: toml::Table = toml::from_str(&text).ok()?;
    let json = serde_json::to_value(&table).ok()?;
    let kind = if table.contains_key("world") || table.contains_key("runs") {
        FileKind::Scenario
    } else if ["robot_home", "walls", "doors", "routes"]
        .iter()
        .any(|k| table.contains_key(*k))
    {
        FileKind::World
    } else {
        return None;
    };
    Some((kind, json))
}

/// The reader's verdict: `Ok`, or the messages of its problems.
fn read(kind: FileKind, path: &Path) -> Result<(), Vec<String>> {
    let r = match kind {
        FileKind::World => placewords::world::load_world(path).map(|_| ()),
        FileKind::Scenario => placewords::experiment::load_scenario(path).map(|_| ()),
    };
    r.map_err(|e| match e {
        placewords::spec::SpecError::Invalid(ds) => ds
            .into_iter()
            .filter(|d| d.path == path.display().to_string())
            .map(|d| d.message)
            .collect(),
        other => vec![other.to_string()],
    })
}

/// The keys a reader's messages name: as unknown, as refused otherwise (a message that starts
/// with the key, like "`max_seconds_per_lap` in [expect.subjects.opposite]: time is not counted
/// per direction" or "`[expect.icp]` is the form before subjects"), and as missing or mistyped.
struct ReaderKeys {
    unknown: BTreeSet<String>,
    refused: BTreeSet<String>,
    missing_or_mistyped: BTreeSet<String>,
}

fn reader_keys(messages: &[String]) -> ReaderKeys {
    let quoted = |m: &str, prefix: &str| -> Option<String> {
        let rest = m.strip_prefix(prefix)?;
        Some(rest[..rest.find('`')?].to_string())
    };
    let mut keys = ReaderKeys {
        unknown: BTreeSet::new(),
        refused: BTreeSet::new(),
        missing_or_mistyped: BTreeSet::new(),
    };
    for m in messages {
        if let Some(k) = quoted(m, "unknown key `") {
            keys.unknown.insert(k);
        } else if let Some(k) = quoted(m, "missing key `") {
            keys.missing_or_mistyped.insert(k);
        } else if let Some(rest) = m.strip_prefix('`')
            && let Some(end) = rest.find('`')
        {
            // `[[expect.levels]]` names the key `levels` of [expect].
            let key = rest[..end].trim_matches(|c| c == '[' || c == ']');
            let key = key.rsplit('.').next().unwrap_or(key).to_string();
            if rest[end..].contains(" must be ") {
                keys.missing_or_mistyped.insert(key);
            } else {
                keys.refused.insert(key);
            }
        }
    }
    keys
}

/// The keys a schema's errors name: unexpected ones, and those missing, mistyped or out of
/// range (the last key of the error's place).
fn schema_keys(v: &jsonschema::Validator, json: &Value) -> (BTreeSet<String>, BTreeSet<String>) {
    use jsonschema::error::ValidationErrorKind as K;
    let mut unknown = BTreeSet::new();
    let mut other = BTreeSet::new();
    for e in v.iter_errors(json) {
        match e.kind() {
            K::AdditionalProperties { unexpected } => unknown.extend(unexpected.iter().cloned()),
            K::Required { property } => {
                other.insert(property.as_str().unwrap_or("").to_string());
            }
            _ => {
                let path = e.instance_path().as_str().to_string();
                let key = path
                    .split('/')
                    .rev()
                    .find(|s| !s.is_empty() && s.parse::<usize>().is_err());
                other.insert(key.unwrap_or("").to_string());
            }
        }
    }
    (unknown, other)
}

/// Every shipped world and scenario, and every fixture: those the reader accepts pass the
/// schema; those it refuses for an unknown key fail the schema for that key and no other
/// unknown one; a key it names as missing or mistyped the schema names too.
#[test]
fn every_shipped_file_and_fixture_agrees_with_its_schema() {
    let validators = [validator(FileKind::World), validator(FileKind::Scenario)];
    let mut files = Vec::new();
    for dir in ["worlds", "scenarios", "tests/fixtures"] {
        files.extend(toml_files(&root().join(dir)));
    }
    let (mut valid, mut refused, mut keyed) = (0, 0, 0);
    let mut wrong = Vec::new();
    for path in &files {
        let Some((kind, json)) = kind_of(path) else {
            continue;
        };
        let shown = path
            .strip_prefix(root())
            .unwrap_or(path)
            .display()
            .to_string();
        let v = &validators[kind as usize];
        let schema = schema_keys(v, &json);
        match read(kind, path) {
            Ok(()) => {
                valid += 1;
                if !v.is_valid(&json) {
                    wrong.push(format!(
                        "{shown}: the reader accepts it, the schema names {schema:?}"
                    ));
                }
            }
            Err(messages) => {
                refused += 1;
                let r = reader_keys(&messages);
                if !(r.unknown.is_empty() && r.missing_or_mistyped.is_empty()) {
                    keyed += 1;
                }
                let named: BTreeSet<_> = r.unknown.union(&r.refused).cloned().collect();
                if !r.unknown.is_subset(&schema.0) || !schema.0.is_subset(&named) {
                    wrong.push(format!(
                        "{shown}: unknown keys: the reader names {:?} (and refuses {:?}), the \
                         schema {:?}",
                        r.unknown, r.refused, schema.0
                    ));
                }
                let missed: Vec<_> = r.missing_or_mistyped.difference(&schema.1).collect();
                if !missed.is_empty() {
                    wrong.push(format!(
                        "{shown}: the reader names {missed:?} missing or mistyped, the schema \
                         does not (it names {:?})",
                        schema.1
                    ));
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // The shipped files, the valid fixtures and the invalid-key and wrong-type ones were all seen.
    assert!(
        valid >= 15 && refused >= 60 && keyed >= 10,
        "{valid} {refused} {keyed}"
    );
}
