//! The one reader of recognizer settings, for a scenario's `[recognizer]` and for a
//! `recognize --config` file: the keys of `[recognizer.<component>]` subtables laid over the
//! defaults, each problem at its `file:line:col`. Unknown keys get a "did you mean" (within
//! their subtable, or the subtable a key belongs in); a key of the flat form before subtables
//! (`[recognizer] kernel_radius_m`) is refused with where it goes now; `levels` is the
//! harness's to set and refused.

use crate::recognizer::{RENAMED_KEYS, RecognizerConfig, SECTIONS, table_name};
use crate::spec::SpecError;
use crate::spec::diag::{Diags, echo, read_text};
use crate::spec::scenario::{RECOGNIZER_HARNESS_KEYS, RecognizerEntry};
use crate::spec::suggest::{closest, hint};
use std::path::Path;
use toml::Table;

/// Recognizer settings from a file holding a `[recognizer]` table alone (`recognize --config`),
/// read and checked as a scenario's `[recognizer]`: every problem at its `file:line:col`, unknown
/// keys with "did you mean".
pub fn load_recognizer_config(path: &Path) -> Result<RecognizerConfig, SpecError> {
    let src = read_text(path)?;
    parse_recognizer_config(&src, path)
}

/// [`load_recognizer_config`] on text; `path` names the file in messages.
pub fn parse_recognizer_config(src: &str, path: &Path) -> Result<RecognizerConfig, SpecError> {
    let file = path.display().to_string();
    let mut d = Diags::new(src, &file);
    let cfg = crate::spec::scenario::read_recognizer_file(src, &mut d)
        .map(|entries| recognizer(&entries, &mut d));
    match cfg {
        Some(cfg) if !d.has_errors() => Ok(cfg),
        _ => Err(SpecError::Invalid(d.into_sorted())),
    }
}

/// The settings `entries` give over the defaults; the defaults, with every problem in `d`,
/// when they are not usable.
pub(crate) fn recognizer(entries: &[RecognizerEntry], d: &mut Diags) -> RecognizerConfig {
    let keys = Keys::new();
    let mut table = keys.defaults.clone();
    let mut ok = true;
    let mut unknown_sections = Vec::new();
    for e in entries {
        match keys.place(e).and_then(|section| keys.typed(section, e)) {
            Ok(section) => {
                if let Some(Some(t)) = table.get_mut(section).map(toml::Value::as_table_mut) {
                    t.insert(e.key.get_ref().clone(), e.value.clone());
                }
            }
            Err(Refused::Key(message)) => {
                d.at(e.key.span().start, message);
                ok = false;
            }
            // Said once, at the subtable's name, however many keys it holds.
            Err(Refused::Section(at, message)) => {
                if !unknown_sections.contains(&at) {
                    unknown_sections.push(at);
                    d.at(at, message);
                }
                ok = false;
            }
        }
    }
    let cfg = match table.try_into::<RecognizerConfig>() {
        Ok(cfg) if ok => cfg,
        _ => return RecognizerConfig::default(),
    };
    for p in cfg.problems() {
        let at = entries.iter().find(|e| e.is(p.section, p.field));
        let at = at.or(entries.first()).map_or(0, |e| e.key.span().start);
        d.at(at, p.to_string());
    }
    cfg
}

/// Why an entry is not read: a message at its key, or at its subtable's name (`at`, a byte
/// offset) for an unknown subtable.
enum Refused {
    Key(String),
    Section(usize, String),
}

/// The keys the recognizer knows, from its defaults: per subtable, its keys.
struct Keys {
    defaults: Table,
}

impl Keys {
    fn new() -> Self {
        Keys {
            defaults: Table::try_from(RecognizerConfig::default()).unwrap_or_default(),
        }
    }

    /// The subtables of `[recognizer]`.
    fn sections(&self) -> impl Iterator<Item = &'static str> + Clone {
        SECTIONS.iter().copied()
    }

    /// The keys of subtable `section`.
    fn keys_of(&self, section: &str) -> Vec<&str> {
        match self.defaults.get(section).and_then(toml::Value::as_table) {
            Some(t) => t.keys().map(String::as_str).collect(),
            None => Vec::new(),
        }
    }

    /// Where a key of the flat form before subtables lives now: (subtable, key).
    fn home_of(&self, old: &str) -> Option<(&'static str, String)> {
        if let Some(&(_, section, key)) = RENAMED_KEYS.iter().find(|r| r.0 == old) {
            return Some((section, key.to_string()));
        }
        self.sections()
            .find(|s| self.keys_of(s).contains(&old))
            .map(|s| (s, old.to_string()))
    }

    /// The keys of every subtable, for suggestions across them.
    fn all_keys(&self) -> Vec<&str> {
        self.sections().flat_map(|s| self.keys_of(s)).collect()
    }

    /// The subtable entry `e` belongs in, or why it is refused.
    fn place(&self, e: &RecognizerEntry) -> Result<&'static str, Refused> {
        let key = e.key.get_ref().as_str();
        match &e.section {
            None => Err(Refused::Key(self.flat_key(key, &e.value))),
            Some(section) => {
                let name = section.get_ref().as_str();
                match self.sections().find(|s| *s == name) {
                    Some(s) if self.keys_of(s).contains(&key) => Ok(s),
                    Some(s) => Err(Refused::Key(self.misplaced(s, key))),
                    None => Err(Refused::Section(
                        section.span().start,
                        self.unknown_section(name),
                    )),
                }
            }
        }
    }

    /// Why a key of `[recognizer]` itself is refused: every setting is in a subtable.
    fn flat_key(&self, key: &str, value: &toml::Value) -> String {
        if RECOGNIZER_HARNESS_KEYS.contains(&key) {
            return "`levels` in [recognizer] is not read: `run` and `recognize` search 1, 2 and 3 \
                    levels each time (the table's rows); run one with `--levels N` (1-4), and \
                    gate one in `check` with [[expect.subjects]] `subject = \"words-N\"`"
                .to_string();
        }
        if let Some((section, new)) = self.home_of(key) {
            let renamed = if new == key {
                String::new()
            } else {
                format!(" as `{new} = {value}`")
            };
            return format!(
                "`{key}` is no longer a key of [recognizer] itself: move {key} into {}{renamed} \
                 (docs/scenario-format.md, \"Updating a scenario written before subtables\")",
                table_name(section)
            );
        }
        if self.sections().any(|s| s == key) {
            return format!(
                "`{key}` in [recognizer] must be a table of settings: write them under {}",
                table_name(key)
            );
        }
        self.unknown(key, "[recognizer]")
    }

    /// Why `key` is not read in subtable `section`.
    fn misplaced(&self, section: &str, key: &str) -> String {
        match self.home_of(key) {
            Some((home, new)) if home != section || new != key => format!(
                "`{key}` is not a key of {}: move it into {}{}",
                table_name(section),
                table_name(home),
                if new == key {
                    String::new()
                } else {
                    format!(" as `{new}`")
                }
            ),
            _ => match closest(key, self.keys_of(section)) {
                Some(c) => format!(
                    "unknown key `{}` in {}; did you mean `{c}`?",
                    echo(key),
                    table_name(section)
                ),
                None => self.unknown(key, &table_name(section)),
            },
        }
    }

    /// An unknown key in `table`, with the nearest key of any subtable and where it lives.
    fn unknown(&self, key: &str, table: &str) -> String {
        let all = self.all_keys();
        match closest(key, all.iter().copied()).and_then(|c| self.home_of(c)) {
            Some((section, near)) => format!(
                "unknown key `{}` in {table}; did you mean `{near}` in {}?",
                echo(key),
                table_name(section)
            ),
            None => format!(
                "unknown key `{}` in {table}; the settings are in the subtables {}",
                echo(key),
                self.section_list()
            ),
        }
    }

    fn unknown_section(&self, section: &str) -> String {
        let h = hint(section, self.sections(), "subtables of [recognizer]");
        format!("unknown table {}; {h}", table_name(&echo(section)))
    }

    fn section_list(&self) -> String {
        self.sections()
            .map(table_name)
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// `section` when `e`'s value has the key's type, else the message.
    fn typed(&self, section: &'static str, e: &RecognizerEntry) -> Result<&'static str, Refused> {
        let mut one = self.defaults.clone();
        if let Some(Some(t)) = one.get_mut(section).map(toml::Value::as_table_mut) {
            t.insert(e.key.get_ref().clone(), e.value.clone());
        }
        match one.try_into::<RecognizerConfig>() {
            Ok(_) => Ok(section),
            Err(err) => {
                let msg = err.message().trim().replace('\n', " ");
                Err(Refused::Key(format!(
                    "{} {}: {msg}",
                    table_name(section),
                    e.key.get_ref()
                )))
            }
        }
    }
}
