//! The crack pattern of a bonded body as SVG (paper 001 Fig. 3): the body's outline and, for
//! every broken bond, the crack face it stands for: a segment through the bond's midpoint,
//! perpendicular to it and as long as the particle diameter (reference positions), coloured
//! by the time it broke (early dark red, late orange), and the time of the picture.

use crate::output::{write_atomic, OutputError};
use qdem_contact::BondedParticles;
use qdem_core::step::State;
use std::io::Write;
use std::path::Path;

/// Pixels per metre of the picture's width.
const WIDTH_PX: f64 = 1200.0;

/// Writes the crack pattern of `model` at `state` to `path`.
pub fn write_crack_svg(
    path: &Path,
    model: &BondedParticles,
    state: &State,
) -> Result<(), OutputError> {
    let x = &state.reference;
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in x {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let r = model.radii().first().copied().unwrap_or(0.0);
    let (x0, y0, x1, y1) = (lo[0] - r, lo[1] - r, hi[0] + r, hi[1] + r);
    let scale = WIDTH_PX / (x1 - x0);
    let (w, h) = (WIDTH_PX, (y1 - y0) * scale);
    let px = |v: f64| (v - x0) * scale;
    let py = |v: f64| (y1 - v) * scale;
    let log = model.broken_log();
    let t_end = state.time.max(1e-300);
    write_atomic(path, |out: &mut dyn Write| {
        writeln!(
            out,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{:.0}" viewBox="0 0 {w:.1} {:.1}">"#,
            h + 30.0,
            h + 30.0
        )?;
        writeln!(
            out,
            r##"<rect x="0" y="0" width="{w:.1}" height="{h:.1}" fill="#eeeeee" stroke="black"/>"##
        )?;
        for &(time, k) in log {
            let b = model.bonds()[k as usize];
            let (a, c) = (x[b.i as usize], x[b.j as usize]);
            let mid = [0.5 * (a[0] + c[0]), 0.5 * (a[1] + c[1])];
            let face = [-b.axis[1] * r, b.axis[0] * r];
            let (a, c) = (
                [mid[0] - face[0], mid[1] - face[1]],
                [mid[0] + face[0], mid[1] + face[1]],
            );
            let f = (time / t_end).clamp(0.0, 1.0);
            let (red, green) = (140.0 + 115.0 * f, 120.0 * f);
            writeln!(
                out,
                r#"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="rgb({red:.0},{green:.0},0)" stroke-width="2"/>"#,
                px(a[0]),
                py(a[1]),
                px(c[0]),
                py(c[1]),
            )?;
        }
        writeln!(
            out,
            r#"<text x="4" y="{:.1}" font-family="sans-serif" font-size="14">{} broken bonds of {} at t = {:.4} s (dark: early, orange: late)</text>"#,
            h + 20.0,
            log.len(),
            model.bonds().len(),
            state.time
        )?;
        writeln!(out, "</svg>")
    })
}
