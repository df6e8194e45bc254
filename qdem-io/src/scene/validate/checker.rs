//! The checker every table's checks report to, and the checks several tables share: names
//! (non-empty, unique), lists of defined names for messages, numbers in [0, 1), boxes.

use std::collections::HashMap;
use std::path::Path;

use super::super::error::{located, SceneError};
use super::super::spans::SpanIndex;
use super::super::suggest::did_you_mean;

/// The most edit-distance cells (characters of the word times characters of the candidates)
/// that "did you mean" suggestions may cost in one scene: plenty for any real scene, and a bound
/// for a huge one with thousands of undefined references (whose messages then go without
/// suggestions).
const SUGGESTION_BUDGET: usize = 20_000_000;

/// The most names listed in a "defined bodies: ..." message; the rest are counted.
const MAX_LISTED_NAMES: usize = 20;

/// Collects located problems.
pub(super) struct Checker<'a> {
    text: Option<&'a str>,
    spans: Option<&'a SpanIndex>,
    /// Problems as (byte offset, message); positions are resolved once, at the end.
    found: Vec<(Option<usize>, String)>,
    /// Byte offsets of the starts of the text's lines.
    line_starts: Vec<usize>,
    /// What is left of [`SUGGESTION_BUDGET`].
    suggestion_budget: usize,
}

impl<'a> Checker<'a> {
    pub(super) fn new(text: Option<&'a str>, spans: Option<&'a SpanIndex>) -> Self {
        let line_starts = text.map_or_else(Vec::new, |t| {
            std::iter::once(0)
                .chain(t.match_indices('\n').map(|(k, _)| k + 1))
                .collect()
        });
        Checker {
            text,
            spans,
            found: Vec::new(),
            line_starts,
            suggestion_budget: SUGGESTION_BUDGET,
        }
    }

    fn offset(&self, at: &[&str]) -> Option<usize> {
        self.spans.and_then(|s| s.offset(at))
    }

    fn line_of(&self, at: &[&str]) -> Option<usize> {
        let offset = self.offset(at)?;
        self.text
            .map(|_| self.line_starts.partition_point(|&start| start <= offset))
    }

    /// Whether the scene text writes the key at `at` (false for a scene built in code, which
    /// has no text: its keys hold their defaults or what the code set).
    pub(super) fn given(&self, at: &[&str]) -> bool {
        self.spans.is_some_and(|s| s.has(at))
    }

    pub(super) fn error(&mut self, at: &[&str], message: String) {
        let offset = self.offset(at);
        self.found.push((offset, message));
    }

    /// [`did_you_mean`] within the scene's [`SUGGESTION_BUDGET`].
    pub(super) fn suggest<'n>(&mut self, word: &str, candidates: &[&'n str]) -> Option<&'n str> {
        let cells = candidates
            .iter()
            .fold(0usize, |sum, c| sum.saturating_add(c.len() + 1))
            .saturating_mul(word.len() + 1);
        if cells > self.suggestion_budget {
            return None;
        }
        self.suggestion_budget -= cells;
        did_you_mean(word, candidates.iter().copied())
    }

    /// Check that every component is finite; true when they all are.
    pub(super) fn finite(&mut self, at: &[&str], label: &str, key: &str, values: &[f64]) -> bool {
        let bad: Vec<String> = values
            .iter()
            .filter(|v| !v.is_finite())
            .map(|v| v.to_string())
            .collect();
        if bad.is_empty() {
            return true;
        }
        self.error(
            at,
            format!(
                "{label}: `{key}` must be a finite number, not {}",
                bad.join(", ")
            ),
        );
        false
    }

    /// A finite, strictly positive number.
    pub(super) fn positive(&mut self, at: &[&str], label: &str, key: &str, v: f64, unit: &str) {
        if self.finite(at, label, key, &[v]) && v <= 0.0 {
            self.error(
                at,
                format!("{label}: {key} = {v}: must be positive ({unit}); give a value above 0"),
            );
        }
    }

    /// A finite, non-negative number.
    pub(super) fn non_negative(&mut self, at: &[&str], label: &str, key: &str, v: f64, unit: &str) {
        if self.finite(at, label, key, &[v]) && v < 0.0 {
            self.error(
                at,
                format!("{label}: {key} = {v}: must not be negative ({unit}); use 0 to disable"),
            );
        }
    }

    /// Every problem found, in file order (those without a position last, in the order they
    /// were found), or `Ok` when there is none.
    pub(super) fn finish(self, path: &Path) -> Result<(), SceneError> {
        if self.found.is_empty() {
            return Ok(());
        }
        let mut found = self.found;
        found.sort_by_key(|(offset, _)| offset.unwrap_or(usize::MAX));
        Err(SceneError::Invalid(located(path, self.text, found)))
    }

    /// The line where `name` was first defined, for duplicate messages.
    pub(super) fn first_seen(&self, table: &str, index: usize) -> String {
        let i = index.to_string();
        match self.line_of(&[table, &i, "name"]) {
            Some(line) => format!("line {line}"),
            None => format!("[[{table}]] #{}", index + 1),
        }
    }
}

/// `[[table]] "name"`, or `[[table]] #N` (1-based) for a table without a name.
pub(super) fn label(table: &str, index: usize, name: Option<&str>) -> String {
    match name {
        Some(n) if !n.is_empty() => format!("[[{table}]] {n:?}"),
        _ => format!("[[{table}]] #{}", index + 1),
    }
}

/// `"a", "b", "c"`, at most [`MAX_LISTED_NAMES`] of them, then `… and N more`.
pub(super) fn quoted_names<'a>(names: impl ExactSizeIterator<Item = &'a str>) -> String {
    let total = names.len();
    let mut listed: Vec<String> = names
        .take(MAX_LISTED_NAMES)
        .map(|n| format!("{n:?}"))
        .collect();
    if total > listed.len() {
        listed.push(format!("… and {} more", total - listed.len()));
    }
    listed.join(", ")
}

/// Check names: non-empty and unique within their table.
pub(super) fn unique_names<'n>(
    c: &mut Checker<'_>,
    table: &str,
    names: impl Iterator<Item = &'n str>,
) -> HashMap<&'n str, usize> {
    let mut seen: HashMap<&str, usize> = HashMap::new();
    for (i, name) in names.enumerate() {
        let idx = i.to_string();
        let at = [table, idx.as_str(), "name"];
        if name.is_empty() {
            c.error(
                &at,
                format!("{}: name is empty; give it a name", label(table, i, None)),
            );
            continue;
        }
        if let Some(&first) = seen.get(name) {
            let where_ = c.first_seen(table, first);
            c.error(
                &at,
                format!(
                    "{} (#{}): duplicate {table} name {name:?}, already used at {where_}; rename one of them",
                    label(table, i, Some(name)),
                    i + 1
                ),
            );
        } else {
            seen.insert(name, i);
        }
    }
    seen
}

/// A number in [0, 1).
pub(super) fn fraction(
    c: &mut Checker<'_>,
    at: &[&str],
    label: &str,
    key: &str,
    v: f64,
    meaning: &str,
) {
    if c.finite(at, label, key, &[v]) && !(0.0..1.0).contains(&v) {
        c.error(
            at,
            format!("{label}: {key} = {v}: must be in [0, 1) ({meaning})"),
        );
    }
}

/// A box `key` of `table`: finite corners, the upper above the lower on every axis.
pub(super) fn box_corners(c: &mut Checker<'_>, table: &str, l: &str, key: &str, b: &[[f64; 3]; 2]) {
    if c.finite(&[table, key], l, key, &b.concat()) && (0..3).any(|k| b[1][k] <= b[0][k]) {
        c.error(
            &[table, key],
            format!(
                "{l}: {key} = {b:?}: the upper corner must lie above the lower one on every axis"
            ),
        );
    }
}
