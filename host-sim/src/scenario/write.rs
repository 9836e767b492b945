//! Scenario files written: a [`ScenarioFile`] serialized by the `toml` crates (keys, quoting
//! and escaping theirs), never put together with `format!`. Two layouts:
//! - [`ScenarioFile::to_toml`]: the `toml` crate's, keys in sorted order (a campaign's
//!   worst-run file);
//! - [`ScenarioFile::to_document`]: keys in the type's order, each number readable (the
//!   shortest decimal that reads back as the same value, with an exponent below 10⁻³ and from
//!   10⁶: never 309 digits), a list of points one per line; a writer may add a header comment
//!   and write some numbers at its own precision ([`ScenarioDocument::set_numbers`]).

use std::fmt;

use controller_core::readable::Readable;
use toml_edit::{Array, DocumentMut, Item, Value};

use super::file::ScenarioFile;
use super::ScenarioError;

/// A value a writer lays out itself, where [`ScenarioFile`] writes it: its table (`None`: the
/// top level) and key. A test holds each to the type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KeyPath {
    pub table: Option<&'static str>,
    pub key: &'static str,
}

impl KeyPath {
    /// A waypoint mission's points.
    pub const POINTS: KeyPath = KeyPath {
        table: Some("trajectory"),
        key: "points",
    };
    /// A waypoint mission's speed profile.
    pub const SPEEDS: KeyPath = KeyPath {
        table: Some("trajectory"),
        key: "speeds",
    };
    /// A waypoint mission's speed changes' |σ̈|.
    pub const SPEED_CHANGE: KeyPath = KeyPath {
        table: Some("trajectory"),
        key: "speed_change",
    };
    /// The run's duration.
    pub const DURATION: KeyPath = KeyPath {
        table: None,
        key: "duration",
    };
    /// Every path above (for the test that holds them to the type).
    pub const ALL: [KeyPath; 4] = [
        KeyPath::POINTS,
        KeyPath::SPEEDS,
        KeyPath::SPEED_CHANGE,
        KeyPath::DURATION,
    ];
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.table {
            Some(t) => write!(f, "{t}.{}", self.key),
            None => f.write_str(self.key),
        }
    }
}

fn unwritable(message: impl fmt::Display) -> ScenarioError {
    ScenarioError::Write(message.to_string())
}

impl ScenarioFile {
    /// The file as the `toml` crate writes a table: the top-level keys, then each table, keys
    /// in sorted order, numbers as `toml` writes them (`10.0`).
    pub fn to_toml(&self) -> Result<String, ScenarioError> {
        let table = toml::Table::try_from(self).map_err(unwritable)?;
        toml::to_string(&table).map_err(unwritable)
    }

    /// The file as a document to lay out: keys in the type's order, numbers readable, arrays
    /// of arrays one entry per line.
    pub fn to_document(&self) -> Result<ScenarioDocument, ScenarioError> {
        let mut doc = toml_edit::ser::to_document(self).map_err(unwritable)?;
        for (_, item) in doc.as_table_mut().iter_mut() {
            as_tables(item);
            layout_item(item)?;
        }
        Ok(ScenarioDocument { doc })
    }
}

/// An inline table as a `[table]`, an array of inline tables as `[[tables]]`, recursively
/// (the serializer writes a map, as a flattened table is, inline).
fn as_tables(item: &mut Item) {
    let taken = std::mem::take(item);
    *item = match taken {
        Item::Value(Value::InlineTable(t)) => Item::Table(t.into_table()),
        Item::Value(Value::Array(a)) if !a.is_empty() && a.iter().all(Value::is_inline_table) => {
            let mut tables = toml_edit::ArrayOfTables::new();
            for v in a {
                if let Value::InlineTable(t) = v {
                    tables.push(t.into_table());
                }
            }
            Item::ArrayOfTables(tables)
        }
        other => other,
    };
    match item {
        Item::Table(t) => t.iter_mut().for_each(|(_, i)| as_tables(i)),
        Item::ArrayOfTables(a) => a
            .iter_mut()
            .for_each(|t| t.iter_mut().for_each(|(_, i)| as_tables(i))),
        _ => {}
    }
}

/// Every number of `item` readable, every array of arrays one entry per line.
fn layout_item(item: &mut Item) -> Result<(), ScenarioError> {
    match item {
        Item::Value(v) => layout_value(v),
        Item::Table(t) => t.iter_mut().try_for_each(|(_, i)| layout_item(i)),
        Item::ArrayOfTables(a) => a
            .iter_mut()
            .try_for_each(|t| t.iter_mut().try_for_each(|(_, i)| layout_item(i))),
        Item::None => Ok(()),
    }
}

fn layout_value(value: &mut Value) -> Result<(), ScenarioError> {
    match value {
        // −0 keeps its sign (`toml`'s `-0.0`; Readable's `-0` would read back as 0).
        Value::Float(f)
            if f.value().is_finite() && !(*f.value() == 0.0 && f.value().is_sign_negative()) =>
        {
            let x = *f.value();
            set_repr(value, &Readable(x).to_string())
        }
        Value::Array(a) => {
            a.iter_mut().try_for_each(layout_value)?;
            if a.iter().any(|v| v.is_array()) {
                one_per_line(a);
            }
            Ok(())
        }
        Value::InlineTable(t) => t.iter_mut().try_for_each(|(_, v)| layout_value(v)),
        _ => Ok(()),
    }
}

/// `[\n    a,\n    b,\n]`.
fn one_per_line(a: &mut Array) {
    for v in a.iter_mut() {
        v.decor_mut().set_prefix("\n    ");
        v.decor_mut().set_suffix("");
    }
    a.set_trailing_comma(true);
    a.set_trailing("\n");
}

/// `value` written as `repr`, a TOML number (decor kept).
fn set_repr(value: &mut Value, repr: &str) -> Result<(), ScenarioError> {
    let mut new: Value = repr
        .parse()
        .map_err(|e| unwritable(format!("{repr:?} is not a TOML value: {e}")))?;
    if !(new.is_float() || new.is_integer()) {
        return Err(unwritable(format!("{repr:?} is not a TOML number")));
    }
    *new.decor_mut() = value.decor().clone();
    *value = new;
    Ok(())
}

/// A scenario file being laid out by its writer ([`ScenarioFile::to_document`]).
#[derive(Clone, Debug)]
pub struct ScenarioDocument {
    doc: DocumentMut,
}

impl ScenarioDocument {
    fn item_mut(&mut self, at: KeyPath) -> Result<&mut Item, ScenarioError> {
        let missing = || unwritable(format!("the file has no `{at}`"));
        let table = match at.table {
            Some(t) => self.doc.get_mut(t).ok_or_else(missing)?,
            None => self.doc.as_item_mut(),
        };
        table.get_mut(at.key).ok_or_else(missing)
    }

    /// Writes the numbers at `at` (a number or an array of them, nested or not; in order) as
    /// `repr` of `values`, the writer's own values at its own precision (e.g. a plan's metres to
    /// the millimetre). `values` has one entry per number, and each `repr` is a TOML number.
    pub fn set_numbers(
        &mut self,
        at: KeyPath,
        values: &[f64],
        repr: impl Fn(f64) -> String,
    ) -> Result<(), ScenarioError> {
        let value = self
            .item_mut(at)?
            .as_value_mut()
            .ok_or_else(|| unwritable(format!("`{at}` is not a value")))?;
        let mut numbers = Vec::new();
        collect_numbers(value, &mut numbers);
        if numbers.len() != values.len() {
            return Err(unwritable(format!(
                "`{at}` holds {} numbers, {} given",
                numbers.len(),
                values.len()
            )));
        }
        numbers
            .into_iter()
            .zip(values)
            .try_for_each(|(v, &x)| set_repr(v, &repr(x)))
    }

    /// `key = value` of the entry at `at`, as the document writes it.
    pub fn entry(&mut self, at: KeyPath) -> Result<String, ScenarioError> {
        let item = self.item_mut(at)?;
        let value = item
            .as_value()
            .ok_or_else(|| unwritable(format!("`{at}` is not a value")))?;
        Ok(format!("{} = {}", at.key, value.to_string().trim()))
    }

    /// A comment above the file's first line: `# ` and each of `lines`. A control character in
    /// a line (a newline in a file name) is written escaped, so a comment cannot end early.
    pub fn set_header(&mut self, lines: &[String]) {
        let mut prefix = String::new();
        for line in lines {
            prefix.push_str("# ");
            for c in line.chars() {
                match c.is_control() {
                    true => prefix.extend(c.escape_default()),
                    false => prefix.push(c),
                }
            }
            prefix.push('\n');
        }
        self.doc.decor_mut().set_prefix(prefix);
    }
}

fn collect_numbers<'a>(value: &'a mut Value, out: &mut Vec<&'a mut Value>) {
    match value {
        Value::Array(a) => a.iter_mut().for_each(|v| collect_numbers(v, out)),
        Value::Float(_) | Value::Integer(_) => out.push(value),
        _ => {}
    }
}

impl fmt::Display for ScenarioDocument {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.doc)
    }
}
