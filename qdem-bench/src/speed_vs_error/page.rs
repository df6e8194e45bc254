//! The page `speed-vs-error.md`: a header, one section per family between the markers
//! `<!-- speed-vs-error:NAME -->` and `<!-- speed-vs-error:NAME:end -->`, in
//! [`Family::ALL`]'s order, then the hand-written part from [`KEPT_FROM`] on. A study that
//! runs some families replaces their sections and keeps the others' as they were, so that one
//! family can be regenerated without running the rest.

use super::{Family, StudyError};
use qdem_io::output::write_atomic;
use std::path::Path;

/// The heading from which `speed-vs-error.md` is written by hand (the modelling advice
/// checked against runs): [`write_page`] keeps it and all that follows.
pub const KEPT_FROM: &str = "## Modelling advice against runs";

const HEADER: &str = "# Speed versus error, per kind of scene\n\n\
Regenerate every section with `cargo run --release -p qdem-bench --bin study -- speed-vs-error \
--all` (this page and `figures/speed_vs_error_*.svg`; `--families bbm,packing` runs some and \
keeps the others' sections, plain `speed-vs-error` runs the cantilever). Each family runs a \
sweep of the choices it offers and states each run's error against a named reference beside \
its speed. Speed is the CPU seconds of the run (user + system over all threads, from \
`/proc/self/stat`): the machines these ran on were shared, which lengthens wall time more than \
CPU time; each section names its machine and the load when it ran.\n";

fn begin(family: Family) -> String {
    format!("<!-- speed-vs-error:{} -->", family.name())
}

fn end(family: Family) -> String {
    format!("<!-- speed-vs-error:{}:end -->", family.name())
}

/// The section of `family` in `page`, markers included.
fn marked(page: &str, family: Family) -> Option<&str> {
    let (begin, end) = (begin(family), end(family));
    let from = page.find(&begin)?;
    let to = page[from..].find(&end)? + from + end.len();
    Some(&page[from..to])
}

/// Writes `speed-vs-error.md` into `docs`: the sections in `new` (family, its markdown),
/// the other families' sections as the page had them, and the hand-written part from
/// [`KEPT_FROM`] on. Text of the old page outside the markers and before [`KEPT_FROM`] is
/// dropped.
///
/// ```
/// use qdem_bench::speed_vs_error::{write_page, Family, KEPT_FROM};
/// let docs = std::env::temp_dir().join(format!("qdem-svr-page-{}", std::process::id()));
/// std::fs::create_dir_all(&docs).unwrap();
/// let page = docs.join("speed-vs-error.md");
/// std::fs::write(&page, format!("# old header\n\n{KEPT_FROM}\n\nchecked by hand\n")).unwrap();
/// write_page(&docs, &[(Family::Bbm, "## beam, first".into())]).unwrap();
/// write_page(&docs, &[(Family::Packing, "## packing".into())]).unwrap();
/// let text = std::fs::read_to_string(&page).unwrap();
/// assert!(!text.contains("old header"));
/// assert!(text.contains("## beam, first") && text.contains("## packing"));
/// assert!(text.find("## beam").unwrap() < text.find("## packing").unwrap());
/// assert!(text.ends_with(&format!("{KEPT_FROM}\n\nchecked by hand\n")));
/// # std::fs::remove_dir_all(&docs).unwrap();
/// ```
pub fn write_page(docs: &Path, new: &[(Family, String)]) -> Result<(), StudyError> {
    let path = docs.join("speed-vs-error.md");
    let old = std::fs::read_to_string(&path).unwrap_or_default();
    let mut text = HEADER.to_string();
    for family in Family::ALL {
        let section = match new.iter().find(|(f, _)| *f == family) {
            Some((_, markdown)) => Some(format!(
                "{}\n{}\n{}",
                begin(family),
                markdown.trim_end(),
                end(family)
            )),
            None => marked(&old, family).map(str::to_string),
        };
        if let Some(section) = section {
            text += &format!("\n{section}\n");
        }
    }
    if let Some(i) = old.find(KEPT_FROM) {
        text += &format!("\n{}", &old[i..]);
    }
    write_atomic(&path, |w| w.write_all(text.as_bytes()))?;
    Ok(())
}
