//! "Did you mean …?" suggestions: an optimal-string-alignment (restricted Damerau–Levenshtein)
//! distance and a picker that proposes the closest candidate.

/// The largest edit distance at which a candidate is still proposed.
pub const MAX_DISTANCE: usize = 2;

/// Optimal-string-alignment distance between `a` and `b`: the number of single-character
/// insertions, deletions, substitutions and transpositions of adjacent characters that turn
/// `a` into `b` (no substring is edited twice). Works on `char`s, not bytes.
///
/// ```
/// use qdem_io::scene::suggest::edit_distance;
/// assert_eq!(edit_distance("t_ned", "t_end"), 1);
/// assert_eq!(edit_distance("outptu", "output"), 1);
/// assert_eq!(edit_distance("densty", "density"), 1);
/// assert_eq!(edit_distance("", "abc"), 3);
/// ```
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let (n, m) = (a.len(), b.len());
    // Three rolling rows: i-2, i-1, i.
    let mut prev2 = vec![0usize; m + 1];
    let mut prev: Vec<usize> = (0..=m).collect();
    let mut cur = vec![0usize; m + 1];
    for i in 1..=n {
        cur[0] = i;
        for j in 1..=m {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut d = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                d = d.min(prev2[j - 2] + 1);
            }
            cur[j] = d;
        }
        std::mem::swap(&mut prev2, &mut prev);
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[m]
}

/// The candidate closest to `word`, if one is close enough to be worth proposing: a
/// case-insensitive match wins outright, then an English plural of the candidate (`bodies` for
/// `body`), otherwise the smallest [`edit_distance`] not above [`MAX_DISTANCE`] (and smaller than the candidate's own length, so that a one-letter typo is
/// not "corrected" to an unrelated two-letter key). Ties go to the earlier candidate.
///
/// ```
/// use qdem_io::scene::suggest::did_you_mean;
/// assert_eq!(did_you_mean("t_ned", ["t_end", "dt"]), Some("t_end"));
/// assert_eq!(did_you_mean("Density", ["name", "density"]), Some("density"));
/// assert_eq!(did_you_mean("banana", ["t_end", "dt"]), None);
/// ```
pub fn did_you_mean<'a, I>(word: &str, candidates: I) -> Option<&'a str>
where
    I: IntoIterator<Item = &'a str>,
{
    let lower = word.to_lowercase();
    let mut best: Option<(usize, &'a str)> = None;
    for candidate in candidates {
        if candidate == word {
            continue;
        }
        let distance = if candidate.to_lowercase() == lower {
            0
        } else if singular(&lower).is_some_and(|s| s == candidate.to_lowercase()) {
            1
        } else {
            edit_distance(word, candidate)
        };
        if distance > MAX_DISTANCE || distance >= candidate.chars().count().max(1) {
            continue;
        }
        if best.is_none_or(|(d, _)| distance < d) {
            best = Some((distance, candidate));
        }
    }
    best.map(|(_, c)| c)
}

/// `word` without a plural ending (`ies` → `y`, `es`, `s`), if it has one.
fn singular(word: &str) -> Option<String> {
    if let Some(stem) = word.strip_suffix("ies") {
        return Some(format!("{stem}y"));
    }
    word.strip_suffix('s').map(str::to_owned)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances() {
        assert_eq!(edit_distance("abc", "abc"), 0);
        assert_eq!(edit_distance("abc", "acb"), 1);
        assert_eq!(edit_distance("abc", "ab"), 1);
        assert_eq!(edit_distance("abc", "xbc"), 1);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("ca", "abc"), 3); // OSA, not full Damerau
    }

    #[test]
    fn suggestions() {
        assert_eq!(did_you_mean("x", ["dt", "t_end"]), None);
        assert_eq!(did_you_mean("tend", ["dt", "t_end"]), Some("t_end"));
        assert_eq!(
            did_you_mean("vtu_evry", ["dir", "vtu_every"]),
            Some("vtu_every")
        );
        assert_eq!(
            did_you_mean("concret", ["steel", "concrete"]),
            Some("concrete")
        );
        assert_eq!(did_you_mean("bodies", ["material", "body"]), Some("body"));
        assert_eq!(did_you_mean("Probes", ["material", "probe"]), Some("probe"));
    }
}
