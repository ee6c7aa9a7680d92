//! JSON Schemas (draft-07) of the files people write, for editors: Taplo and Even Better TOML
//! complete keys and flag mistakes inline from a `#:schema` line (docs/editors.md).
//!
//! A schema comes from what the readers use, never from a second list:
//! - the **keys** of each table are the reader's key tables (`spec::world::*_KEYS`,
//!   `spec::scenario::*_KEYS`), or the serde structs whose fields are those keys
//!   (`spec::world::WorldSpec`, `spec::evaluation::{EvaluationSpec, ExpectSpec}`,
//!   `recognizer::RecognizerConfig`) through `schemars`; a table whose reader refuses unknown
//!   keys has `additionalProperties: false`, so a misspelt key fails the schema too;
//! - the **types** are the reader's: a model table (`[laser]`, `[robot]`, …) holds numbers but
//!   for its name key and `spec::scenario::WORD_KEYS`, as `spec::scenario` reads it;
//! - the **ranges** are the reader's limits (`spec::scenario::NUMBER_LIMITS`, `MAX_LAPS`,
//!   `MAX_PEDESTRIANS`, the step and timeout bounds, `spec::world::MAX_ABS_COORD_M`);
//! - each key's **description** (unit, default, limits, meaning) is its row in the format
//!   reference, `docs/world-format.md` or `docs/scenario-format.md` (embedded), which a test
//!   holds to the key tables; a key without a row keeps its struct's doc comment.
//!
//! Checks beyond keys and types (geometry, references to door or route ids, cross-checks
//! between keys) stay the readers' own: a file may pass the schema and still be refused by
//! `world check` or `scenario check`.

use crate::recognizer::{RecognizerConfig, SECTIONS as RECOGNIZER_SECTIONS};
use crate::sim::laser::LaserPreset;
use crate::spec::evaluation::{EvaluationSpec, ExpectSpec};
use crate::spec::scenario as sc;
use crate::spec::world::{self as wo, MAX_ABS_COORD_M, WorldSpec};
use schemars::generate::{SchemaGenerator, SchemaSettings};
use serde_json::{Map, Value, json};

/// The format reference of world files, whose rows describe the keys.
const WORLD_REFERENCE: &str = include_str!("../docs/world-format.md");
/// The format reference of scenario files.
const SCENARIO_REFERENCE: &str = include_str!("../docs/scenario-format.md");

/// The draft the schemas are written in (Taplo reads draft-07).
pub const DRAFT_07: &str = "http://json-schema.org/draft-07/schema#";

/// Which file a schema describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    World,
    Scenario,
}

impl FileKind {
    /// Every kind, in the order `placewords schema` lists them.
    pub const ALL: [FileKind; 2] = [FileKind::World, FileKind::Scenario];

    /// The name on the command line and in `schemas/NAME.schema.json`.
    pub fn name(self) -> &'static str {
        match self {
            FileKind::World => "world",
            FileKind::Scenario => "scenario",
        }
    }

    /// The kind named `name`, if any.
    pub fn from_name(name: &str) -> Option<FileKind> {
        FileKind::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The schema of this kind of file.
    pub fn schema(self) -> Value {
        match self {
            FileKind::World => world_schema(),
            FileKind::Scenario => scenario_schema(),
        }
    }

    /// The schema as the text `placewords schema` prints and `schemas/` holds: pretty JSON
    /// with keys in order, and a final newline.
    pub fn schema_text(self) -> String {
        let mut text = serde_json::to_string_pretty(&self.schema()).unwrap_or_default();
        text.push('\n');
        text
    }
}

/// A generator that writes draft-07 and inlines every sub-schema (one tree per file, so each
/// table can be described where it stands).
fn generator() -> SchemaGenerator {
    let mut settings = SchemaSettings::draft07();
    settings.inline_subschemas = true;
    settings.into_generator()
}

/// The schema of a world file.
pub fn world_schema() -> Value {
    let mut root = generator().into_root_schema_for::<WorldSpec>().to_value();
    let reference = Reference::parse(WORLD_REFERENCE);
    let tables: [(&[&str], &str, &[&str]); 6] = [
        (&[], "Top level", wo::TOP_KEYS),
        (&["robot_home"], "`[robot_home]`", wo::HOME_KEYS),
        (&["walls", "[]"], "`[[walls]]`", wo::WALL_KEYS),
        (&["doors", "[]"], "`[[doors]]`", wo::DOOR_KEYS),
        (&["routes", "[]"], "`[[routes]]`", wo::ROUTE_KEYS),
        (&["areas", "[]"], "`[[areas]]`", wo::AREA_KEYS),
    ];
    for (path, section, keys) in tables {
        if let Some(t) = object_at(&mut root, path) {
            keep_only(t, keys);
            for (key, p) in properties(t) {
                if key == "format_version" {
                    p.insert("const".into(), json!(1));
                }
                limit_points(p);
            }
            reference.describe(t, section, 0);
        }
    }
    // Sections the reader requires, with at least one entry (`spec::world`'s
    // `required_section`; the missing-key fixtures hold the two together).
    if let Some(t) = root.as_object_mut() {
        let required = t.entry("required").or_insert_with(|| json!([]));
        if let Some(r) = required.as_array_mut() {
            for key in ["walls", "routes"] {
                if !r.contains(&json!(key)) {
                    r.push(json!(key));
                }
            }
        }
        for (key, p) in properties(t) {
            if key == "walls" || key == "routes" {
                p.insert("minItems".into(), json!(1));
            }
        }
    }
    finish(
        root,
        "placewords world file",
        "A world of placewords (`format_version = 1`): walls, doors, routes, home pose, \
         areas. Reference: docs/world-format.md; `placewords world check FILE` runs every check.",
    )
}

/// The schema of a scenario file.
pub fn scenario_schema() -> Value {
    let mut g = generator();
    let mut recognizer = g.subschema_for::<RecognizerConfig>().to_value();
    // `levels` and the like are the harness's to set: the reader refuses them, so must this.
    if let Some(Value::Object(p)) = recognizer.get_mut("properties") {
        p.retain(|k, _| !sc::RECOGNIZER_HARNESS_KEYS.contains(&k.as_str()));
    }
    let evaluation = g.subschema_for::<EvaluationSpec>().to_value();
    let expect = g.subschema_for::<ExpectSpec>().to_value();
    let mut props = Map::new();
    for &key in sc::TOP_KEYS {
        let schema = match key {
            "format_version" => json!({ "type": "integer", "const": 1 }),
            "name" | "description" | "world" | "route" | "seeds" => json!({ "type": "string" }),
            "seed" => json!({ "type": "integer", "minimum": 0 }),
            "runs" => json!({ "type": "array", "minItems": 1, "items": run_schema() }),
            "door_configs" => json!({
                "type": "object",
                "additionalProperties": { "type": "array", "items": { "type": "string" } },
            }),
            "pedestrians" => pedestrians_schema(),
            "laser" => settings_schema("laser", sc::LASER_KEYS, "preset"),
            "odometry" => settings_schema("odometry", sc::ODOMETRY_KEYS, "model"),
            "robot" => settings_schema("robot", sc::ROBOT_KEYS, ""),
            "scan_context" => settings_schema("scan_context", sc::SCAN_CONTEXT_KEYS, ""),
            "subjects" => json!({ "type": "array", "items": subject_schema() }),
            "recognizer" => recognizer.clone(),
            "evaluation" => evaluation.clone(),
            "expect" => expect.clone(),
            // A key the reader gained without a type here: the schema test names it.
            _ => json!({}),
        };
        props.insert(key.into(), schema);
    }
    let mut root = json!({
        "type": "object",
        "properties": props,
        "required": ["format_version", "world", "route", "seed", "runs"],
        "additionalProperties": false,
    });
    let reference = Reference::parse(SCENARIO_REFERENCE);
    let mut tables: Vec<(&[&str], &str, usize)> = vec![
        (&[], "Top level", 0),
        (&["runs", "[]"], "`[[runs]]`", 0),
        (&["runs", "[]", "doors_random"], "`doors_random`", 0),
        (&["pedestrians"], "`[pedestrians]`", 0),
        (&["laser"], "`[laser]`", 0),
        (&["odometry"], "`[odometry]`", 0),
        (&["robot"], "`[robot]`", 0),
        (&["recognizer"], "`[recognizer]`", 0),
        (&["scan_context"], "`[scan_context]`", 0),
        (&["subjects", "[]"], "`[[subjects]]`", 0),
        (&["evaluation"], "`[evaluation]`", 0),
        (&["expect"], "`[expect]`", 0),
        (&["expect", "subjects", "[]"], "`[expect]`", 1),
        (&["expect", "regression"], "`[expect.regression]`", 0),
    ];
    // One reference table per subtable of `[recognizer]`, under its own heading.
    let subtables: Vec<(Vec<&str>, String)> = RECOGNIZER_SECTIONS
        .iter()
        .map(|&s| (vec!["recognizer", s], format!("`[recognizer.{s}]`")))
        .collect();
    for (path, heading) in &subtables {
        tables.push((path.as_slice(), heading.as_str(), 0));
    }
    for (path, section, nth) in tables {
        if let Some(t) = object_at(&mut root, path) {
            reference.describe(t, section, nth);
        }
    }
    finish(
        root,
        "placewords scenario file",
        "A scenario of placewords (`format_version = 1`): the world and route, seeds, runs and \
         door settings, people, sensor, odometry and robot models, recognizer and evaluation \
         settings, and the [expect] gate. Reference: docs/scenario-format.md; `placewords \
         scenario check FILE` runs every check.",
    )
}

/// `[[runs]]`: what `spec::scenario` reads of an entry.
fn run_schema() -> Value {
    let mut props = Map::new();
    for &key in sc::RUN_KEYS {
        let schema = match key {
            "start_waypoint" => json!({ "type": "integer", "minimum": 0 }),
            "direction" => json!({ "type": "string", "enum": ["forward", "reverse"] }),
            "laps" => json!({ "type": "integer", "minimum": 1, "maximum": sc::MAX_LAPS }),
            "doors" => json!({ "type": "string" }),
            "doors_cycle" => {
                json!({ "type": "array", "minItems": 1, "items": { "type": "string" } })
            }
            "doors_random" => doors_random_schema(),
            _ => json!({}),
        };
        props.insert(key.into(), schema);
    }
    json!({
        "type": "object",
        "properties": props,
        "required": ["laps"],
        "additionalProperties": false,
    })
}

/// The schema of a run's `doors_random` table: probabilities, `open_probability` required.
fn doors_random_schema() -> Value {
    let mut p = Map::new();
    for &k in sc::DOORS_RANDOM_KEYS {
        p.insert(
            k.into(),
            json!({ "type": "number", "minimum": 0, "maximum": 1 }),
        );
    }
    json!({
        "type": "object",
        "properties": p,
        "required": ["open_probability"],
        "additionalProperties": false,
    })
}

/// `[[subjects]]`: what `spec::subjects` reads of an entry.
fn subject_schema() -> Value {
    use crate::spec::subjects::{MAX_TIMEOUT_S, SUBJECT_KEYS};
    let mut props = Map::new();
    for &key in SUBJECT_KEYS {
        let schema = match key {
            "name" => json!({ "type": "string", "pattern": "^[A-Za-z0-9_-]+$" }),
            "exec" => json!({ "type": "string", "minLength": 1 }),
            "timeout_s" => {
                json!({ "type": "number", "exclusiveMinimum": 0, "maximum": MAX_TIMEOUT_S })
            }
            "args" => json!({ "type": "array", "items": { "type": "string" } }),
            _ => json!({}),
        };
        props.insert(key.into(), schema);
    }
    json!({
        "type": "object",
        "properties": props,
        "required": ["name", "exec"],
        "additionalProperties": false,
    })
}

/// `[pedestrians]`: the count, where people walk, and the walkers' numbers.
fn pedestrians_schema() -> Value {
    let mut schema = settings_schema("pedestrians", sc::PEDESTRIAN_KEYS, "");
    if let Some(t) = schema.as_object_mut() {
        t.insert("required".into(), json!(["count"]));
        for (key, p) in properties(t) {
            let typed = match key.as_str() {
                "count" => {
                    json!({ "type": "integer", "minimum": 0, "maximum": sc::MAX_PEDESTRIANS })
                }
                "areas" => json!({ "type": "array", "items": { "type": "string" } }),
                "paths_m" => json!({
                    "type": "array",
                    "items": { "type": "array", "minItems": 2, "items": point() },
                }),
                _ => continue,
            };
            *p = typed.as_object().cloned().unwrap_or_default();
        }
    }
    schema
}

/// A model table as `spec::scenario` reads it: each key a number, but for its name key (a
/// string) and the word keys; the sizes of [`sc::NUMBER_LIMITS`] and the robot's step and
/// timeout bounds as ranges.
fn settings_schema(table: &str, keys: &[&str], name_key: &str) -> Value {
    let mut props = Map::new();
    for &key in keys {
        let schema = if key == name_key {
            match table {
                "laser" => json!({ "type": "string", "enum": LaserPreset::NAMES }),
                _ => json!({ "type": "string" }),
            }
        } else if sc::WORD_KEYS.contains(&key) {
            json!({ "type": "string" })
        } else {
            number_schema(table, key)
        };
        props.insert(key.into(), schema);
    }
    json!({ "type": "object", "properties": props, "additionalProperties": false })
}

/// A number of `[table]` with the reader's size limits.
fn number_schema(table: &str, key: &str) -> Value {
    let mut s = json!({ "type": "number" });
    if let Some(l) = sc::number_limit(table, key) {
        // A magnitude: the sign is the model's rule (said in the description).
        s["minimum"] = json!(-l.max);
        s["maximum"] = json!(l.max);
        if l.min_nonzero > 0.0 {
            // 0, or at least `min_nonzero` in size.
            s["not"] = json!({ "allOf": [
                { "exclusiveMinimum": -l.min_nonzero, "exclusiveMaximum": l.min_nonzero },
                { "not": { "const": 0 } },
            ]});
        }
    }
    match (table, key) {
        ("robot", "step_s") => {
            s["minimum"] = json!(sc::MIN_STEP_S);
            s["maximum"] = json!(sc::MAX_STEP_S);
        }
        ("robot", "blocked_timeout_s") => {
            s["exclusiveMinimum"] = json!(0);
            s["maximum"] = json!(sc::MAX_BLOCKED_TIMEOUT_S);
        }
        _ => {}
    }
    s
}

/// A point `[x, y]` in metres, each coordinate within the readers' bound.
fn point() -> Value {
    json!({
        "type": "array",
        "minItems": 2,
        "maxItems": 2,
        "items": { "type": "number", "minimum": -MAX_ABS_COORD_M, "maximum": MAX_ABS_COORD_M },
    })
}

/// Bounds the coordinates of a point (or of a list of points) of a world table.
fn limit_points(p: &mut Map<String, Value>) {
    let is_pair = |v: &Map<String, Value>| v.get("maxItems") == Some(&json!(2));
    let bound = |v: &mut Map<String, Value>| {
        if let Some(Value::Object(c)) = point().get("items") {
            v.insert("items".into(), Value::Object(c.clone()));
        }
    };
    if is_pair(p) {
        bound(p);
    } else if let Some(Value::Object(items)) = p.get_mut("items")
        && is_pair(items)
    {
        bound(items);
    }
}

/// The root's draft, title and description.
fn finish(mut root: Value, title: &str, description: &str) -> Value {
    if let Some(t) = root.as_object_mut() {
        t.insert("$schema".into(), json!(DRAFT_07));
        t.insert("title".into(), json!(title));
        t.insert("description".into(), json!(description));
    }
    root
}

/// The object schema at `path` below `root`: a key names a property, `[]` the items of an
/// array; an optional value (`anyOf` with null) is looked through.
fn object_at<'v>(root: &'v mut Value, path: &[&str]) -> Option<&'v mut Map<String, Value>> {
    let mut at = root;
    for step in path {
        at = look_through(at)?;
        at = if *step == "[]" {
            at.get_mut("items")?
        } else {
            at.get_mut("properties")?.get_mut(*step)?
        };
    }
    look_through(at)?.as_object_mut()
}

/// `{"anyOf": [schema, {"type": "null"}]}` → schema; anything else as it is.
fn look_through(v: &mut Value) -> Option<&mut Value> {
    let inner = v
        .get("anyOf")
        .and_then(Value::as_array)
        .and_then(|a| a.iter().position(|s| s.get("properties").is_some()));
    match inner {
        Some(i) => v.get_mut("anyOf")?.get_mut(i),
        None => Some(v),
    }
}

/// The properties of an object schema, by name.
fn properties(
    t: &mut Map<String, Value>,
) -> impl Iterator<Item = (&String, &mut Map<String, Value>)> {
    t.get_mut("properties")
        .and_then(Value::as_object_mut)
        .into_iter()
        .flat_map(|p| p.iter_mut())
        .filter_map(|(k, v)| v.as_object_mut().map(|v| (k, v)))
}

/// Drops properties the reader does not accept (none today: a test holds the struct fields to
/// the key tables); kept so a field added to a struct for another use never widens the schema.
fn keep_only(t: &mut Map<String, Value>, keys: &[&str]) {
    if let Some(Value::Object(p)) = t.get_mut("properties") {
        p.retain(|k, _| keys.contains(&k.as_str()));
    }
}

/// The tables of a format reference: each with the heading of its section and its rows.
struct Reference {
    tables: Vec<RefTable>,
}

struct RefTable {
    /// The section's heading without its `#`s: `` `[laser]` ``, `Top level`.
    section: String,
    /// The header row's cells, lower case: `key`, `unit`, `default`, `limits`, `meaning`.
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Reference {
    /// Reads the Markdown tables of a reference. Cells are split at ` | ` (a `|` inside a cell,
    /// as in `|Δ|`, has no spaces around it).
    fn parse(md: &str) -> Reference {
        let mut tables: Vec<RefTable> = Vec::new();
        let mut section = String::new();
        let mut in_table = false;
        for line in md.lines() {
            let line = line.trim_end();
            if line.starts_with('#') {
                section = line.trim_start_matches('#').trim().to_string();
                in_table = false;
                continue;
            }
            if !line.starts_with('|') {
                in_table = false;
                continue;
            }
            let cells = split_row(line);
            if cells
                .iter()
                .all(|c| c.chars().all(|ch| ch == '-' || ch == ':'))
            {
                continue;
            }
            Self::push_row(&mut tables, &section, in_table, cells);
            in_table = true;
        }
        Reference { tables }
    }

    /// Adds a row of `cells` to the last table when the row `continues` one, else starts a
    /// table in `section` with `cells` as its (lower-cased) header.
    fn push_row(tables: &mut Vec<RefTable>, section: &str, continues: bool, cells: Vec<String>) {
        if continues {
            if let Some(t) = tables.last_mut() {
                t.rows.push(cells);
            }
        } else {
            tables.push(RefTable {
                section: section.to_string(),
                header: cells.iter().map(|c| c.to_lowercase()).collect(),
                rows: Vec::new(),
            });
        }
    }

    /// Sets the description of each property of `t` from its row in the `nth` table of
    /// `section`; a key without a row keeps the description it has (its doc comment).
    fn describe(&self, t: &mut Map<String, Value>, section: &str, nth: usize) {
        let table = self.tables.iter().filter(|t| t.section == section).nth(nth);
        let Some(table) = table else { return };
        for (key, p) in properties(t) {
            let row = table
                .rows
                .iter()
                .find(|r| r.first().map(String::as_str) == Some(&format!("`{key}`")));
            if let Some(row) = row {
                p.insert("description".into(), json!(table.describe(row)));
            }
        }
    }
}

/// The sentence of a non-empty cell `c` of column `name` (other than the meaning): a default
/// that says "required" as such, anything else as "Name: c".
fn column_sentence(name: &str, c: &str) -> String {
    match name {
        "default" if c.starts_with("required") => sentence(&format!("R{}", &c[1..])),
        _ => sentence(&format!("{}{}: {c}", name[..1].to_uppercase(), &name[1..])),
    }
}

impl RefTable {
    /// A row as one description: the meaning, then each other column that says something.
    fn describe(&self, row: &[String]) -> String {
        let cell = |name: &str| {
            self.header
                .iter()
                .position(|h| h == name)
                .and_then(|i| row.get(i))
                .map(|c| c.trim())
                .filter(|c| !c.is_empty())
        };
        let mut parts = Vec::new();
        if let Some(m) = cell("meaning") {
            parts.push(sentence(m));
        }
        for (i, name) in self.header.iter().enumerate().skip(1) {
            let Some(c) = row.get(i).map(|c| c.trim()).filter(|c| !c.is_empty()) else {
                continue;
            };
            if name != "meaning" {
                parts.push(column_sentence(name, c));
            }
        }
        parts.join(" ")
    }
}

/// `text` with a capital first letter and a final full stop.
fn sentence(text: &str) -> String {
    let mut c = text.chars();
    let mut s: String = match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    };
    if !s.ends_with('.') {
        s.push('.');
    }
    s
}

/// The cells of a Markdown table row: split at each `|` with a space or the line's end on both
/// sides (a `|` inside a cell, as in `|Δ|`, touches its text).
fn split_row(line: &str) -> Vec<String> {
    let chars: Vec<char> = line.trim().chars().collect();
    let bar = |i: usize| {
        chars[i] == '|'
            && (i == 0 || chars[i - 1] == ' ')
            && (i + 1 == chars.len() || chars[i + 1] == ' ')
    };
    let mut cells = Vec::new();
    let mut cell = String::new();
    for (i, &c) in chars.iter().enumerate() {
        if bar(i) {
            if i > 0 {
                cells.push(cell.trim().to_string());
            }
            cell.clear();
        } else {
            cell.push(c);
        }
    }
    if !cell.trim().is_empty() {
        cells.push(cell.trim().to_string());
    }
    cells
}
