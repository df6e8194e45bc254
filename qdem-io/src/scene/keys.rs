//! The reference of every scene key: its table, type, default and meaning, rendered as
//! README.md's key reference ([`markdown_table`], between [`README_BEGIN`] and [`README_END`]).
//!
//! Each key is written once, beside its field: the `scene_table!` declarations of
//! [`super::schema`] give every table's struct and its `KEYS` together, and [`SCENE_KEYS`]
//! lists the tables. The tests hold the reference to what serde does: every key the parser
//! accepts is listed and every listed key accepted; a required key left out is refused as
//! missing and a scene of only required keys parses; a value of each stated type is accepted
//! (each listed string) and a value of another type refused; an optional key written with its
//! stated default parses to what its absence gives; and README.md's table is
//! [`markdown_table`]. After adding a key to the schema, regenerate README.md's table with
//! `QDEM_WRITE_KEYS=1 cargo test -p qdem-io --lib scene::keys`.

use super::schema::{
    Ballast, Body, Bonded, Contact, CyclicLoad, Granular, Material, Measure, Output, Periodic,
    Probe, RawFix, RawLoad, Run, Section, Series, TimeDelay, Wall, WallServo,
};

/// One scene key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneKey {
    /// The table, as written in a scene (`[run]`, `[[load]]`), or an inline table of one
    /// (`[[load]] cyclic`).
    pub table: &'static str,
    /// The key.
    pub key: &'static str,
    /// Its type, then `required` or `optional`.
    pub kind: &'static str,
    /// What serde fills in when an optional key is absent, as a TOML value (`"0.9"`,
    /// `"[0.0, 0.0, 0.0]"`, `"\"auto\""`); `None` for a required key and for an optional one
    /// that is then absent (an `Option` left `None`).
    pub default: Option<&'static str>,
    /// What it means, with its unit and default.
    pub meaning: &'static str,
}

/// The line before README.md's key table.
pub const README_BEGIN: &str =
    "<!-- scene keys: generated from qdem-io/src/scene/schema/; QDEM_WRITE_KEYS=1 cargo test -p qdem-io --lib scene::keys -->";
/// The line after README.md's key table.
pub const README_END: &str = "<!-- end of scene keys -->";

/// Every key a scene file may hold, table by table: each table's keys as its struct in
/// [`super::schema`] declares them (a table missing here fails the tests).
pub const SCENE_KEYS: &[SceneKey] = &flatten::<{ count(TABLES) }>(TABLES);

/// The tables, in README.md's order.
const TABLES: &[&[SceneKey]] = &[
    Run::KEYS,
    Material::KEYS,
    Body::KEYS,
    RawFix::KEYS,
    RawLoad::KEYS,
    CyclicLoad::KEYS,
    Series::KEYS,
    Probe::KEYS,
    Section::KEYS,
    Measure::KEYS,
    Contact::KEYS,
    Wall::KEYS,
    WallServo::KEYS,
    Periodic::KEYS,
    TimeDelay::KEYS,
    Granular::KEYS,
    Ballast::KEYS,
    Bonded::KEYS,
    Output::KEYS,
];

/// The number of keys of `tables`.
const fn count(tables: &[&[SceneKey]]) -> usize {
    let (mut n, mut t) = (0, 0);
    while t < tables.len() {
        n += tables[t].len();
        t += 1;
    }
    n
}

/// The keys of `tables` one after another (`N` of them).
const fn flatten<const N: usize>(tables: &[&[SceneKey]]) -> [SceneKey; N] {
    let mut out = [tables[0][0]; N];
    let (mut n, mut t) = (0, 0);
    while t < tables.len() {
        let mut k = 0;
        while k < tables[t].len() {
            out[n] = tables[t][k];
            n += 1;
            k += 1;
        }
        t += 1;
    }
    out
}

/// The registry as a Markdown table: `| table | key | type | meaning |`, one row per key.
///
/// ```
/// let table = qdem_io::scene::keys::markdown_table();
/// assert!(table.contains("| `[run]` | `t_end` | number, required |"));
/// ```
pub fn markdown_table() -> String {
    let mut out = String::from("| table | key | type | meaning |\n| --- | --- | --- | --- |\n");
    for k in SCENE_KEYS {
        out.push_str(&format!(
            "| `{}` | `{}` | {} | {} |\n",
            k.table,
            k.key,
            k.kind,
            k.meaning.replace('|', "\\|")
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::schema::RawScene;
    use std::collections::BTreeSet;
    use std::path::Path;

    /// A scene text that puts the unknown key `zz_unknown` into `table`.
    fn probe_text(table: &str) -> String {
        match table.split_once(' ') {
            Some((outer, inline)) => format!("{outer}\n{inline} = {{ zz_unknown = 1 }}\n"),
            None => format!("{table}\nzz_unknown = 1\n"),
        }
    }

    /// The keys serde accepts in the table where `text` puts `zz_unknown`: the list of its
    /// "unknown field" error.
    fn accepted(text: &str) -> BTreeSet<String> {
        let error = toml::from_str::<RawScene>(text)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        let list = error
            .split_once("unknown field `zz_unknown`, expected ")
            .unwrap_or_else(|| panic!("no unknown-field error for {text:?}: {error}"))
            .1;
        let list = list.lines().next().unwrap_or("");
        list.split('`')
            .skip(1)
            .step_by(2)
            .map(str::to_string)
            .collect()
    }

    const HOW: &str = "declare the key in its table's scene_table! in qdem-io/src/scene/schema/ \
                       (or remove it), and list a new table in TABLES of keys.rs; then \
                       regenerate README.md's table: QDEM_WRITE_KEYS=1 cargo test -p qdem-io \
                       --lib scene::keys";

    /// The scene as serde reads it, or serde's message.
    fn parse(text: &str) -> Result<RawScene, String> {
        toml::from_str::<RawScene>(text).map_err(|e| e.to_string())
    }

    /// The keys of `table`.
    fn keys_of(table: &str) -> impl Iterator<Item = &'static SceneKey> + '_ {
        SCENE_KEYS.iter().filter(move |k| k.table == table)
    }

    /// The tables of the reference, in its order.
    fn tables() -> Vec<&'static str> {
        let mut tables: Vec<&str> = SCENE_KEYS.iter().map(|k| k.table).collect();
        tables.dedup();
        tables
    }

    /// Where `table` lives inside another table: the outer table and the key that holds it
    /// (`[[load]] cyclic` in `[[load]]`, `[periodic.time_delay]` in `[periodic]`).
    fn parent(table: &str) -> Option<(String, &str)> {
        if let Some((outer, key)) = table.split_once(' ') {
            return Some((outer.to_string(), key));
        }
        let (outer, key) = table.trim_matches(['[', ']']).split_once('.')?;
        Some((format!("[{outer}]"), key))
    }

    /// The type of a key without its `, required` or `, optional`.
    fn type_of(key: &SceneKey) -> &'static str {
        key.kind.rsplit_once(", ").map_or(key.kind, |(ty, _)| ty)
    }

    /// Whether the reference states `key` required.
    fn is_required(key: &SceneKey) -> bool {
        key.kind.ends_with(", required")
    }

    /// The table `key` holds, when its value is a table.
    fn nested(key: &SceneKey) -> String {
        tables()
            .into_iter()
            .find(|t| parent(t).is_some_and(|(outer, k)| outer == key.table && k == key.key))
            .unwrap_or_else(|| panic!("{} {}: no table of its keys", key.table, key.key))
            .to_string()
    }

    /// Values of the stated type of `key`, as TOML: every listed string for a type that lists
    /// them.
    fn samples(key: &SceneKey) -> Vec<String> {
        let ty = type_of(key);
        let one = |v: &str| vec![v.to_string()];
        match ty {
            "number" => one("2.5"),
            "integer" => one("3"),
            "string" => one("\"s\""),
            "bool" => one("true"),
            "path" => one("\"p.msh\""),
            "[x, y, z]" => one("[1.0, 2.0, 3.0]"),
            "[a, b]" => one("[1.0, 2.0]"),
            "[number, …]" => one("[1.0, 2.0]"),
            "[integer, integer]" => one("[3, 5]"),
            "[path, …]" => one("[\"p.msh\", \"q.msh\"]"),
            "[[x, y, z], [x, y, z]]" => one("[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]"),
            "[[x, y, z], …]" => one("[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]"),
            "[[t, factor], …]" | "[[size, passing], …]" => one("[[0.0, 0.0], [1.0, 1.0]]"),
            "number or \"auto\"" => vec!["2.5".into(), "\"auto\"".into()],
            "table" | "inline table" => {
                one(&format!("{{ {} }}", fields(&nested(key), None).join(", ")))
            }
            _ => {
                let listed = listed(ty);
                assert!(
                    !listed.is_empty(),
                    "{} {}: no sample of the type {ty:?}",
                    key.table,
                    key.key
                );
                listed
            }
        }
    }

    /// The strings a type such as `"simple", "pinned" or "none"` lists, quoted.
    fn listed(ty: &str) -> Vec<String> {
        ty.split('"')
            .skip(1)
            .step_by(2)
            .map(|s| format!("\"{s}\""))
            .collect()
    }

    /// The lines of `table`: its required keys, each a sample of its type, and `set` (a key
    /// and its value, or none to leave that key out).
    fn fields(table: &str, set: Option<(&str, Option<&str>)>) -> Vec<String> {
        let mut lines: Vec<String> = keys_of(table)
            .filter(|k| is_required(k) && set.is_none_or(|(key, _)| key != k.key))
            .map(|k| format!("{} = {}", k.key, samples(k)[0]))
            .collect();
        if let Some((key, Some(value))) = set {
            lines.push(format!("{key} = {value}"));
        }
        lines
    }

    /// A scene that holds `table` with its required keys, inside its parents, and `set`.
    fn scene(table: &str, set: Option<(&str, Option<&str>)>) -> String {
        let run = match table {
            "[run]" => String::new(),
            _ => format!("[run]\n{}\n", fields("[run]", None).join("\n")),
        };
        let own = fields(table, set);
        match parent(table) {
            Some((outer, key)) if table.contains(' ') => format!(
                "{run}{outer}\n{}\n{key} = {{ {} }}\n",
                fields(&outer, None).join("\n"),
                own.join(", ")
            ),
            Some((outer, _)) => format!(
                "{run}{outer}\n{}\n{table}\n{}\n",
                fields(&outer, None).join("\n"),
                own.join("\n")
            ),
            None => format!("{run}{table}\n{}\n", own.join("\n")),
        }
    }

    /// A scene of each table's required keys parses, and each required key left out is
    /// refused as missing.
    #[test]
    fn required_keys_are_the_parsers() {
        let mut wrong = Vec::new();
        for table in tables() {
            if let Err(e) = parse(&scene(table, None)) {
                wrong.push(format!(
                    "{table} with its required keys only is refused: {e}"
                ));
            }
            for key in keys_of(table).filter(|k| is_required(k)) {
                let missing = format!("missing field `{}`", key.key);
                match parse(&scene(table, Some((key.key, None)))) {
                    Err(e) if e.contains(&missing) => {}
                    other => wrong.push(format!(
                        "{table} {}: stated required, but without it: {other:?}",
                        key.key
                    )),
                }
            }
        }
        assert!(
            wrong.is_empty(),
            "{wrong:#?}\nfix the key's required/optional or its serde default"
        );
    }

    /// Each key accepts a value of its stated type (every string a type lists) and refuses a
    /// value of another type (and a string a type that lists strings does not list).
    #[test]
    fn stated_types_are_the_parsers() {
        let mut wrong = Vec::new();
        for key in SCENE_KEYS {
            let with = |value: &str| parse(&scene(key.table, Some((key.key, Some(value)))));
            for value in samples(key) {
                if let Err(e) = with(&value) {
                    wrong.push(format!(
                        "{} {} = {value} (a {}) refused: {e}",
                        key.table, key.key, key.kind
                    ));
                }
            }
            let mut foreign = vec![if type_of(key) == "bool" {
                "\"s\""
            } else {
                "true"
            }];
            if !listed(type_of(key)).is_empty() {
                foreign.push("\"zz_unlisted\"");
            }
            for value in foreign {
                if with(value).is_ok() {
                    wrong.push(format!(
                        "{} {} = {value} accepted, not a {}",
                        key.table, key.key, key.kind
                    ));
                }
            }
        }
        assert!(wrong.is_empty(), "{wrong:#?}\nfix the key's stated type");
    }

    /// An optional key written with its stated default parses to what leaving it out gives:
    /// the default is serde's.
    #[test]
    fn stated_defaults_are_the_parsers() {
        let mut wrong = Vec::new();
        for key in SCENE_KEYS {
            let Some(default) = key.default else { continue };
            let absent = parse(&scene(key.table, Some((key.key, None))));
            let given = parse(&scene(key.table, Some((key.key, Some(default)))));
            let (absent, given) = (format!("{absent:?}"), format!("{given:?}"));
            if absent != given {
                wrong.push(format!(
                    "{} {}: stated default {default}, but left out it parses to\n{absent}\nand \
                     written as {default} to\n{given}",
                    key.table, key.key
                ));
            }
        }
        assert!(wrong.is_empty(), "{wrong:#?}\nfix the key's stated default");
    }

    /// Every key the parser accepts is registered, and every registered key is accepted;
    /// every top-level table the parser accepts has registered keys.
    #[test]
    fn registry_matches_the_parser() {
        let tables: BTreeSet<&str> = SCENE_KEYS.iter().map(|k| k.table).collect();
        let mut missing = Vec::new();
        let mut stale = Vec::new();
        for table in &tables {
            let parser = accepted(&probe_text(table));
            let registry: BTreeSet<String> = SCENE_KEYS
                .iter()
                .filter(|k| k.table == *table)
                .map(|k| k.key.to_string())
                .collect();
            missing.extend(parser.difference(&registry).map(|k| format!("{table} {k}")));
            stale.extend(registry.difference(&parser).map(|k| format!("{table} {k}")));
        }
        for top in accepted("zz_unknown = 1\n") {
            let named = |t: &&str| {
                let name = t.trim_start_matches('[').split([']', '.', ' ']).next();
                name == Some(top.as_str())
            };
            if !tables.iter().any(named) {
                missing.push(format!("the table [{top}] (every key of it)"));
            }
        }
        assert!(
            missing.is_empty() && stale.is_empty(),
            "the scene key registry is out of date:\n  accepted by the parser but not \
             registered: {missing:?}\n  registered but refused by the parser: {stale:?}\n\
             fix: {HOW}"
        );
    }

    /// The ways a meaning may write the TOML value `default`: the value itself, a number
    /// without a zero fraction, `zero` or `the origin` for zeros, ¼ and ½, a string unquoted.
    fn written(default: &str) -> Vec<String> {
        let mut forms = vec![default.to_string(), default.trim_matches('"').to_string()];
        let zeros = default
            .trim_matches(['[', ']'])
            .split(", ")
            .all(|x| x == "0.0" || x == "0");
        if zeros {
            forms.extend(["0", "zero", "the origin"].map(String::from));
        }
        if let Ok(x) = default.parse::<f64>() {
            forms.push(x.to_string());
            forms.extend(match x {
                0.25 => Some("¼".to_string()),
                0.5 => Some("½".to_string()),
                _ => None,
            });
        }
        forms
    }

    /// The meaning of an optional key with a default names it: the clause (between `;`s) that
    /// says `default` (up to `; ` or `. `) holds one of the ways of writing it.
    #[test]
    fn meanings_state_the_defaults() {
        let mut wrong = Vec::new();
        for key in SCENE_KEYS {
            let Some(default) = key.default else { continue };
            let forms = written(default);
            let agrees = key
                .meaning
                .split("; ")
                .flat_map(|clause| clause.split(". "))
                .filter(|clause| clause.to_lowercase().contains("default"))
                .any(|clause| forms.iter().any(|form| clause.contains(form.as_str())));
            if !agrees {
                wrong.push(format!(
                    "{} {}: default {default}, meaning {:?}",
                    key.table, key.key, key.meaning
                ));
            }
        }
        assert!(
            wrong.is_empty(),
            "{wrong:#?}\nfix the meaning's default or the stated one"
        );
    }

    /// README.md's key table is the registry's rendering; with `QDEM_WRITE_KEYS=1` the test
    /// writes it there instead.
    #[test]
    fn readme_table_is_the_registry() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md");
        let readme = std::fs::read_to_string(&path).unwrap();
        let (before, rest) = readme
            .split_once(README_BEGIN)
            .unwrap_or_else(|| panic!("README.md has no line {README_BEGIN:?}; {HOW}"));
        let (current, after) = rest
            .split_once(README_END)
            .unwrap_or_else(|| panic!("README.md has no line {README_END:?}; {HOW}"));
        let table = format!("\n{}", markdown_table());
        if std::env::var_os("QDEM_WRITE_KEYS").is_some() {
            let text = format!("{before}{README_BEGIN}{table}{README_END}{after}");
            std::fs::write(&path, text).unwrap();
            return;
        }
        let rows = |t: &str| t.lines().map(str::to_string).collect::<BTreeSet<_>>();
        let (want, have) = (rows(&table), rows(current));
        let absent: Vec<_> = want.difference(&have).collect();
        let extra: Vec<_> = have.difference(&want).collect();
        assert!(
            current == table,
            "README.md's scene key table differs from the registry:\n  rows missing from \
             README.md: {absent:#?}\n  rows README.md has that the registry does not: \
             {extra:#?}\nfix: QDEM_WRITE_KEYS=1 cargo test -p qdem-io --lib scene::keys"
        );
    }
}
