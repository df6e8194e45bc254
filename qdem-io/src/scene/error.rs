//! Scene errors: [`Diagnostic`] (one located message) and [`SceneError`], plus the translation
//! of toml/serde errors into messages that name the table and propose a fix.

use std::fmt;
use std::io;
use std::ops::Range;
use std::path::{Path, PathBuf};

use super::schema::{ARRAY_TABLES, DT_MESSAGE};
use super::spans::{RootKind, SpanIndex};
use super::suggest::did_you_mean;

/// One problem in a scene file, located where possible.
///
/// Displays as `path:line:column: message`, or `path: message` when no position is known.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// The scene file.
    pub path: PathBuf,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// 1-based column in characters, when known.
    pub column: Option<usize>,
    /// What is wrong and, where we can tell, how to fix it.
    pub message: String,
}

impl Diagnostic {
    /// A diagnostic at byte `offset` of `text` (no position when `offset` is `None`).
    pub(crate) fn at(
        path: &Path,
        text: Option<&str>,
        offset: Option<usize>,
        message: impl Into<String>,
    ) -> Diagnostic {
        let (line, column) = match (text, offset) {
            (Some(text), Some(offset)) => {
                let (l, c) = line_col(text, offset);
                (Some(l), Some(c))
            }
            _ => (None, None),
        };
        Diagnostic {
            path: path.to_path_buf(),
            line,
            column,
            message: message.into(),
        }
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
            if let Some(column) = self.column {
                write!(f, ":{column}")?;
            }
        }
        write!(f, ": {}", self.message)
    }
}

/// 1-based line and column (in characters) of byte `offset` in `text`.
pub(crate) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (
        before.matches('\n').count() + 1,
        before[line_start..].chars().count() + 1,
    )
}

/// Diagnostics for many `(offset, message)` pairs, in the given order, with their positions
/// found in one pass over `text` (in offset order): `line_col` for each would cost a pass per
/// diagnostic, quadratic for a large file with many problems.
pub(crate) fn located(
    path: &Path,
    text: Option<&str>,
    items: Vec<(Option<usize>, String)>,
) -> Vec<Diagnostic> {
    let mut positions: Vec<Option<(usize, usize)>> = vec![None; items.len()];
    if let Some(text) = text {
        let mut order: Vec<usize> = (0..items.len()).filter(|&k| items[k].0.is_some()).collect();
        order.sort_by_key(|&k| items[k].0);
        let mut sweep = Sweep::new(text);
        for k in order {
            positions[k] = items[k].0.map(|offset| sweep.line_col(offset));
        }
    }
    items
        .into_iter()
        .zip(positions)
        .map(|((_, message), position)| Diagnostic {
            path: path.to_path_buf(),
            line: position.map(|p| p.0),
            column: position.map(|p| p.1),
            message,
        })
        .collect()
}

/// [`line_col`] for non-decreasing offsets, each in time proportional to the distance from the
/// previous one.
struct Sweep<'a> {
    text: &'a str,
    /// The last offset asked for (a char boundary), its line, its line's start and its column.
    offset: usize,
    line: usize,
    line_start: usize,
    column: usize,
}

impl<'a> Sweep<'a> {
    fn new(text: &'a str) -> Self {
        Sweep {
            text,
            offset: 0,
            line: 1,
            line_start: 0,
            column: 1,
        }
    }

    fn line_col(&mut self, offset: usize) -> (usize, usize) {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        if offset < self.offset {
            return line_col(self.text, offset);
        }
        let between = &self.text[self.offset..offset];
        match between.rfind('\n') {
            Some(last) => {
                self.line += between.matches('\n').count();
                self.line_start = self.offset + last + 1;
                self.column = self.text[self.line_start..offset].chars().count() + 1;
            }
            None => self.column += between.chars().count(),
        }
        self.offset = offset;
        (self.line, self.column)
    }
}

/// Why a scene could not be loaded.
///
/// Every message starts with the scene path (and `:line:column` where known).
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file could not be read.
    #[error(
        "{}: cannot read the scene file: {source}; check the path (a relative path is taken \
         from the working directory)",
        path.display()
    )]
    Read {
        /// The scene file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: io::Error,
    },
    /// The text is not valid TOML.
    #[error("{0}")]
    Syntax(Diagnostic),
    /// Valid TOML that does not fit the schema: an unknown key or table, a missing key, a value
    /// of the wrong type or an unknown variant. Only the first such problem is reported.
    #[error("{0}")]
    Schema(Diagnostic),
    /// The scene fits the schema but its values are inconsistent or out of range; every
    /// problem found is listed, one per line, in file order.
    #[error("{}", join_lines(.0))]
    Invalid(Vec<Diagnostic>),
    /// Files the scene refers to (meshes) are missing; one per line.
    #[error("{}", join_lines(.0))]
    MissingFiles(Vec<Diagnostic>),
}

impl SceneError {
    /// The located problems behind this error (empty for [`SceneError::Read`]).
    pub fn diagnostics(&self) -> &[Diagnostic] {
        match self {
            SceneError::Read { .. } => &[],
            SceneError::Syntax(d) | SceneError::Schema(d) => std::slice::from_ref(d),
            SceneError::Invalid(ds) | SceneError::MissingFiles(ds) => ds,
        }
    }
}

fn join_lines(diagnostics: &[Diagnostic]) -> String {
    diagnostics
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("\n")
}

/// The backtick-quoted words of serde's "expected ..." tail.
fn expected_list(message: &str) -> Vec<String> {
    let Some(tail) = message.split_once("expected").map(|(_, t)| t) else {
        return Vec::new();
    };
    tail.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_owned)
        .collect()
}

/// The first backtick-quoted word of `message`.
fn first_quoted(message: &str) -> Option<&str> {
    message.split('`').nth(1)
}

fn quoted_list(items: &[String]) -> String {
    items
        .iter()
        .map(|s| format!("`{s}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn root_table_name(key: &str) -> String {
    if ARRAY_TABLES.contains(&key) {
        format!("[[{key}]]")
    } else {
        format!("[{key}]")
    }
}

/// Make serde's type vocabulary read like TOML.
fn tomlish(message: &str) -> String {
    let mut m = message
        .replace("expected f64", "expected a number")
        .replace("expected a sequence", "expected an array")
        .replace("invalid type: sequence", "invalid type: array")
        .replace("invalid type: map", "invalid type: table")
        .replace("expected a map", "expected a table");
    if let Some(i) = m.find("expected struct ") {
        m.replace_range(i.., "expected a table");
    }
    m
}

/// Split a value path into the table that holds it and the key (with array indices) inside
/// that table: `["run", "gravity", "1"]` → (`["run"]`, `gravity[1]`).
fn split_key(spans: &SpanIndex, path: &[String]) -> (Vec<String>, String) {
    let mut table_len = 0;
    for len in 1..path.len() {
        if spans.is_table(&path[..len]) {
            table_len = len;
        }
    }
    let mut key = String::new();
    for seg in &path[table_len..] {
        if seg.parse::<usize>().is_ok() && !key.is_empty() {
            key.push_str(&format!("[{seg}]"));
        } else {
            if !key.is_empty() {
                key.push('.');
            }
            key.push_str(seg);
        }
    }
    (path[..table_len].to_vec(), key)
}

/// Turn a toml deserialization (schema) error into a located, explained diagnostic.
pub(crate) fn schema_diagnostic(
    err: &toml::de::Error,
    text: &str,
    path: &Path,
    spans: &SpanIndex,
) -> Diagnostic {
    let span: Option<Range<usize>> = err.span();
    let raw = err.message().trim().to_owned();
    let offset = span.as_ref().map(|s| s.start);
    let message = explain(&raw, span.as_ref(), spans);
    Diagnostic::at(path, Some(text), offset, message)
}

fn explain(raw: &str, span: Option<&Range<usize>>, spans: &SpanIndex) -> String {
    if raw.starts_with("unknown field") {
        let name = first_quoted(raw).unwrap_or_default().to_owned();
        let expected = expected_list(raw);
        let parent = span.and_then(|s| spans.key_at(s)).map(|(p, _)| p);
        return unknown_key(&name, parent.as_deref(), &expected, spans);
    }
    let value_path = match span {
        Some(s) if s.is_empty() => Some(Vec::new()),
        Some(s) => spans.value_at(s),
        None => None,
    };
    if raw.starts_with("missing field") {
        let name = first_quoted(raw).unwrap_or_default();
        return match value_path.as_deref() {
            None | Some([]) => format!(
                "missing table `{}`; add it (see the scene format)",
                root_table_name(name)
            ),
            Some(table) => format!(
                "missing key `{name}` in {}; add `{name} = ...`",
                spans.describe(table)
            ),
        };
    }
    let (table, key) = match value_path.as_deref() {
        Some(p) if !p.is_empty() => {
            let (t, k) = split_key(spans, p);
            (Some(t), Some(k))
        }
        _ => (None, None),
    };
    let place = match (&table, &key) {
        (Some(t), Some(k)) if t.is_empty() => format!("top-level key `{k}`"),
        (Some(t), Some(k)) => format!("`{k}` in {}", spans.describe(t)),
        _ => String::new(),
    };
    if raw.starts_with("unknown variant") {
        let value = first_quoted(raw).unwrap_or_default();
        let expected = expected_list(raw);
        let what = key.clone().unwrap_or_else(|| "value".to_owned());
        let mut m = format!("unknown {what} `{value}`");
        if !place.is_empty() {
            m = format!("unknown value `{value}` for {place}");
        }
        m.push_str(&format!("; valid values: {}", quoted_list(&expected)));
        if let Some(s) = did_you_mean(value, expected.iter().map(String::as_str)) {
            m.push_str(&format!("; did you mean `{s}`?"));
        }
        return m;
    }
    if raw == DT_MESSAGE {
        return if place.is_empty() {
            DT_MESSAGE.to_owned()
        } else {
            format!("{place}: {DT_MESSAGE}")
        };
    }
    if place.is_empty() {
        tomlish(raw)
    } else {
        format!("{place}: {}", tomlish(raw))
    }
}

fn unknown_key(
    name: &str,
    parent: Option<&[String]>,
    expected: &[String],
    spans: &SpanIndex,
) -> String {
    let candidates = expected.iter().map(String::as_str);
    match parent {
        Some([]) => {
            let written = match spans.root_kind(name) {
                RootKind::Table => format!("table `[{name}]`"),
                RootKind::ArrayOfTables => format!("table `[[{name}]]`"),
                RootKind::Value => format!("top-level key `{name}`"),
            };
            let mut m = format!("unknown {written}");
            match did_you_mean(name, candidates) {
                Some(s) => m.push_str(&format!("; did you mean `{}`?", root_table_name(s))),
                None => {
                    let tables: Vec<String> = expected.iter().map(|k| root_table_name(k)).collect();
                    m.push_str(&format!("; the tables are {}", tables.join(", ")));
                }
            }
            m
        }
        _ => {
            let mut m = format!("unknown key `{name}`");
            if let Some(p) = parent {
                m.push_str(&format!(" in {}", spans.describe(p)));
            }
            match did_you_mean(name, candidates) {
                Some(s) => m.push_str(&format!("; did you mean `{s}`?")),
                None if expected.is_empty() => m.push_str("; no keys are allowed here"),
                None => m.push_str(&format!("; valid keys: {}", quoted_list(expected))),
            }
            m
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions() {
        let text = "ab\ncdé\nf";
        assert_eq!(line_col(text, 0), (1, 1));
        assert_eq!(line_col(text, 3), (2, 1));
        assert_eq!(line_col(text, 7), (2, 4));
        assert_eq!(line_col(text, 8), (3, 1));
        assert_eq!(line_col(text, 6), (2, 3)); // inside é: backs up to its start
        assert_eq!(line_col(text, 99), (3, 2));
    }

    #[test]
    fn one_pass_positions_match_line_col() {
        let text = "ab\ncdé\nf\n\nxyz";
        let offsets = [7, 0, 99, 3, 6, 12, 8, 10, 3];
        let items: Vec<(Option<usize>, String)> = offsets
            .iter()
            .map(|&o| (Some(o), format!("at {o}")))
            .chain([(None, "nowhere".to_owned())])
            .collect();
        let ds = located(Path::new("s.toml"), Some(text), items);
        for (d, &o) in ds.iter().zip(&offsets) {
            let (l, c) = line_col(text, o);
            assert_eq!((d.line, d.column), (Some(l), Some(c)), "offset {o}");
            assert_eq!(d.message, format!("at {o}"));
        }
        assert_eq!((ds[9].line, ds[9].column), (None, None));
        let ds = located(Path::new("s.toml"), None, vec![(Some(3), "x".to_owned())]);
        assert_eq!((ds[0].line, ds[0].column), (None, None));
    }

    #[test]
    fn expected_words() {
        assert_eq!(
            expected_list("unknown field `x`, expected one of `a`, `b`, `c`"),
            ["a", "b", "c"]
        );
        assert_eq!(
            expected_list("unknown field `x`, expected `a` or `b`"),
            ["a", "b"]
        );
        assert!(expected_list("unknown field `x`, there are no fields").is_empty());
    }
}
