//! `[periodic]`: periodic axes (each of x, y, z at most once), one positive period per axis
//! from `length` or from `box` (not both; `origin` only with `length`); its `time_delay`: a
//! body carrying a `[[load]]` with `cyclic` (whose cycle the delay follows), an axis among the
//! periodic ones, and the lag as `lag_deg` or as `sleeper_spacing` with `speed`.

use super::super::schema::{CyclicLoad, Periodic, RawScene, TimeDelay};
use super::checker::Checker;
use super::Refs;

/// The axes named by `text` ("x", "y", "z" once each), or an error naming the table.
fn axes_of(c: &mut Checker<'_>, at: &[&str], label: &str, text: &str) -> Option<Vec<usize>> {
    let mut axes = Vec::new();
    for ch in text.chars() {
        match "xyz".find(ch) {
            Some(k) if !axes.contains(&k) => axes.push(k),
            _ => {
                c.error(
                    at,
                    format!(
                        "{label}: axes = {text:?}: give each of x, y, z at most once, e.g. \"y\" \
                         or \"xy\""
                    ),
                );
                return None;
            }
        }
    }
    if axes.is_empty() {
        c.error(
            at,
            format!("{label}: axes is empty; name the periodic axes, e.g. \"y\""),
        );
        return None;
    }
    Some(axes)
}

/// `[periodic]`: axes, one period each (from `length` or `box`), the time delay's body,
/// axis and lag; fills the cycle of the load the delay follows.
pub(super) fn periodic_table(c: &mut Checker<'_>, raw: &RawScene, p: &Periodic, refs: &mut Refs) {
    let l = "[periodic]";
    let axes = axes_of(c, &["periodic", "axes"], l, &p.axes);
    periods(c, p, axes.as_deref());
    if p.bbox.is_some() && p.origin.is_some() {
        c.error(
            &["periodic", "origin"],
            format!("{l}: `box` already sets the origin; drop `origin`"),
        );
    }
    if let Some(d) = &p.time_delay {
        refs.time_delay_cycle = time_delay(c, raw, p, d, axes.as_deref());
    }
}

/// The periods along `axes`: from `length`, one per axis, or from `box`.
fn periods(c: &mut Checker<'_>, p: &Periodic, axes: Option<&[usize]>) {
    let l = "[periodic]";
    match (&p.length, &p.bbox) {
        (Some(_), Some(_)) | (None, None) => c.error(
            &["periodic"],
            format!("{l}: give the periods as `length` (one per axis) or the cell as `box`, one of the two"),
        ),
        (Some(length), None) => {
            if axes.as_ref().is_some_and(|a| a.len() != length.len()) {
                c.error(
                    &["periodic", "length"],
                    format!(
                        "{l}: length has {} entries for axes = {:?}; give one period per axis",
                        length.len(),
                        p.axes
                    ),
                );
            }
            for v in length {
                c.positive(&["periodic", "length"], l, "length", *v, "m");
            }
        }
        (None, Some(b)) => {
            if let Some(axes) = axes {
                for &k in axes {
                    c.positive(&["periodic", "box"], l, "box extent", b[1][k] - b[0][k], "m");
                }
            }
        }
    }
}

/// `[periodic.time_delay]`: a body with a cyclic load (returned: the first such load's
/// cycle), one of the periodic axes, the lag.
fn time_delay(
    c: &mut Checker<'_>,
    raw: &RawScene,
    p: &Periodic,
    d: &TimeDelay,
    axes: Option<&[usize]>,
) -> Option<CyclicLoad> {
    let l = "[periodic.time_delay]";
    let cyclic = raw
        .loads
        .iter()
        .find_map(|ld| ld.cyclic.filter(|_| ld.body == d.body));
    if cyclic.is_none() {
        c.error(
            &["periodic", "time_delay", "body"],
            format!(
                "{l}: body {:?} carries no [[load]] with `cyclic`; the delay follows the phase of \
                 that load: give the sleeper's [[load]] a `cyclic` factor",
                d.body
            ),
        );
    }
    match (&d.axis, axes) {
        (Some(a), Some(axes))
            if a.len() != 1 || !axes.contains(&"xyz".find(a.as_str()).unwrap_or(3)) =>
        {
            c.error(
                &["periodic", "time_delay", "axis"],
                format!(
                    "{l}: axis = {a:?} is not one of the periodic axes {:?}",
                    p.axes
                ),
            );
        }
        (None, Some(axes)) if axes.len() > 1 => c.error(
            &["periodic", "time_delay"],
            format!(
                "{l}: the cell is periodic along {:?}; say which axis the load travels along \
                 with `axis`",
                p.axes
            ),
        ),
        _ => {}
    }
    lag(c, d);
    cyclic
}

/// The lag: `lag_deg`, or `sleeper_spacing` with `speed`, not a mix.
fn lag(c: &mut Checker<'_>, d: &TimeDelay) {
    let l = "[periodic.time_delay]";
    match (d.lag_deg, d.sleeper_spacing, d.speed) {
        (Some(lag), None, None) => {
            c.finite(&["periodic", "time_delay", "lag_deg"], l, "lag_deg", &[lag]);
        }
        (None, Some(s), Some(v)) => {
            c.positive(
                &["periodic", "time_delay", "sleeper_spacing"],
                l,
                "sleeper_spacing",
                s,
                "m",
            );
            c.positive(&["periodic", "time_delay", "speed"], l, "speed", v, "m/s");
        }
        (None, None, None) => {}
        _ => c.error(
            &["periodic", "time_delay"],
            format!(
                "{l}: give the lag as `lag_deg`, or as `sleeper_spacing` with `speed`, not a mix"
            ),
        ),
    }
}
