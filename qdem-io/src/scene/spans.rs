//! Where things are in the scene text: a map from key paths to byte spans, built from toml's
//! spanned document, so that both toml's errors and our own semantic checks can name a line.

use std::collections::HashMap;
use std::ops::Range;

use toml::de::{DeTable, DeValue};

use super::schema::ARRAY_TABLES;

/// One key (or array element) of the document.
#[derive(Debug, Clone)]
struct Entry {
    path: Vec<String>,
    key: Range<usize>,
    value: Range<usize>,
    /// The value, when it is a string (used to name `[[body]] "beam"`).
    string: Option<String>,
    /// Whether the value is a table or an array of tables.
    is_table: bool,
    is_array_of_tables: bool,
}

/// Spans of every key and value of a parsed scene text.
#[derive(Debug, Clone, Default)]
pub(crate) struct SpanIndex {
    entries: Vec<Entry>,
    by_path: HashMap<Vec<String>, usize>,
}

impl SpanIndex {
    /// Index a parsed document.
    pub fn new(root: &DeTable<'_>) -> SpanIndex {
        let mut index = SpanIndex::default();
        index.walk_table(root, &mut Vec::new());
        index
    }

    fn push(&mut self, entry: Entry) {
        self.by_path.insert(entry.path.clone(), self.entries.len());
        self.entries.push(entry);
    }

    fn walk_table(&mut self, table: &DeTable<'_>, path: &mut Vec<String>) {
        for (key, value) in table.iter() {
            path.push(key.get_ref().to_string());
            self.walk_value(key.span(), value, path);
            path.pop();
        }
    }

    fn walk_value(
        &mut self,
        key: Range<usize>,
        value: &toml::Spanned<DeValue<'_>>,
        path: &mut Vec<String>,
    ) {
        let inner = value.get_ref();
        let array_of_tables = match inner {
            DeValue::Array(a) => {
                !a.is_empty() && a.iter().all(|e| matches!(e.get_ref(), DeValue::Table(_)))
            }
            _ => false,
        };
        self.push(Entry {
            path: path.clone(),
            key,
            value: value.span(),
            string: match inner {
                DeValue::String(s) => Some(s.to_string()),
                _ => None,
            },
            is_table: matches!(inner, DeValue::Table(_)),
            is_array_of_tables: array_of_tables,
        });
        match inner {
            DeValue::Table(t) => self.walk_table(t, path),
            DeValue::Array(a) => {
                for (i, element) in a.iter().enumerate() {
                    path.push(i.to_string());
                    self.walk_value(element.span(), element, path);
                    path.pop();
                }
            }
            _ => {}
        }
    }

    fn get(&self, path: &[String]) -> Option<&Entry> {
        self.by_path.get(path).map(|&i| &self.entries[i])
    }

    /// The byte offset to report for `path`: its value, or, when absent (a defaulted or
    /// missing key), the nearest ancestor that is present.
    pub fn offset(&self, path: &[&str]) -> Option<usize> {
        let mut owned: Vec<String> = path.iter().map(|s| s.to_string()).collect();
        loop {
            if let Some(e) = self.get(&owned) {
                return Some(e.value.start);
            }
            owned.pop()?;
        }
    }

    /// Whether the document writes the key at exactly `path`.
    pub fn has(&self, path: &[&str]) -> bool {
        let owned: Vec<String> = path.iter().map(|s| s.to_string()).collect();
        self.get(&owned).is_some()
    }

    /// Whether `path` is a table (including an element of an array of tables).
    pub fn is_table(&self, path: &[String]) -> bool {
        self.get(path).is_some_and(|e| e.is_table)
    }

    /// The string value at `path`, if there is one.
    pub fn string(&self, path: &[String]) -> Option<&str> {
        self.get(path).and_then(|e| e.string.as_deref())
    }

    /// The key whose name sits exactly at `span`: its table path and its name.
    pub fn key_at(&self, span: &Range<usize>) -> Option<(Vec<String>, String)> {
        let e = self.entries.iter().find(|e| {
            e.key == *span && e.path.last().is_some_and(|k| k.parse::<usize>().is_err())
        })?;
        let mut parent = e.path.clone();
        let name = parent.pop()?;
        Some((parent, name))
    }

    /// The path of the value (or table header) at `span`, or else of the innermost value
    /// containing it.
    pub fn value_at(&self, span: &Range<usize>) -> Option<Vec<String>> {
        // An element of an array of tables has the same span (its header) as the array: take
        // the deepest exact match.
        if let Some(e) = self
            .entries
            .iter()
            .filter(|e| e.value == *span)
            .max_by_key(|e| e.path.len())
        {
            return Some(e.path.clone());
        }
        self.entries
            .iter()
            .filter(|e| e.value.start <= span.start && span.end <= e.value.end)
            .min_by_key(|e| e.value.end - e.value.start)
            .map(|e| e.path.clone())
    }

    /// Whether the root key `name` was written as a table or an array of tables, for
    /// messages about unknown top-level keys.
    pub fn root_kind(&self, name: &str) -> RootKind {
        match self.get(&[name.to_owned()]) {
            Some(e) if e.is_array_of_tables => RootKind::ArrayOfTables,
            Some(e) if e.is_table => RootKind::Table,
            _ => RootKind::Value,
        }
    }

    /// A human name for the table at `path`: `[run]`, `[[body]] "beam"`, `[[fix]] #2`,
    /// `[output.extra]`; the empty path is "the top level".
    pub fn describe(&self, path: &[String]) -> String {
        describe_with(path, |p| self.string(p).map(str::to_owned))
    }
}

/// How a top-level key was written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RootKind {
    /// `[name]`
    Table,
    /// `[[name]]`
    ArrayOfTables,
    /// `name = value`
    Value,
}

/// `describe` with a lookup of `name` strings, so that validation can use it without spans.
pub(crate) fn describe_with(
    path: &[String],
    name_of: impl Fn(&[String]) -> Option<String>,
) -> String {
    let Some(root) = path.first() else {
        return "the top level".to_owned();
    };
    if ARRAY_TABLES.contains(&root.as_str()) {
        let mut out = format!("[[{root}]]");
        let mut rest = &path[1..];
        if let Some(index) = rest.first().and_then(|i| i.parse::<usize>().ok()) {
            let mut name_path = path[..2].to_vec();
            name_path.push("name".to_owned());
            match name_of(&name_path) {
                Some(name) => out.push_str(&format!(" {name:?}")),
                None => out.push_str(&format!(" #{}", index + 1)),
            }
            rest = &rest[1..];
        }
        if !rest.is_empty() {
            out.push_str(&format!(", table `{}`", rest.join(".")));
        }
        out
    } else {
        format!("[{}]", path.join("."))
    }
}
