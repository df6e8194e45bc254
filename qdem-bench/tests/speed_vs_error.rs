//! The speed-versus-error families at their quick size: each sweep makes physical sense
//! (errors that shrink with the step or the element size as the integrators and the
//! discretisation say they must), and `study speed-vs-error --families` writes the page's
//! sections and figures, keeping the hand-written part; the reduced track's contact stiffness
//! sets its step and overlap as a linear spring does. Timings are not asserted.

use qdem_bench::speed_vs_error::{bbm, boxtest, packing, track, Size, KEPT_FROM};
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("qdem-svr-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Velocity Verlet's energy error grows with the step (second order between impacts, and each
/// Hertz impact resolved by fewer steps): the elastic packing's drift rises at each fourfold
/// step, and at 0.05 T_R, four times below LIGGGHTS's recommended 0.2 T_R, it stays under 1%
/// of the energy the fall releases.
#[test]
fn packing_energy_drift_grows_with_the_step() {
    let sweep = packing::Sweep::of(Size::Quick);
    let rows = packing::run(&sweep).unwrap();
    let drifts: Vec<f64> = rows.iter().map(|r| r.drift).collect();
    assert!(drifts.windows(2).all(|w| w[0] < w[1]), "drifts {drifts:?}");
    assert!(drifts[0] < 0.01, "drift at 0.05 T_R: {}", drifts[0]);
    // The spheres touch: the contact force is measured, not an empty mean.
    assert!(rows.iter().all(|r| r.mean_force > 0.0));
}

/// Average-acceleration Newmark's error against the explicit run of the same element size
/// falls with its step (second order in ∆t: at least twice smaller for a fivefold step,
/// leaving room for the explicit run's own error), on both element sizes.
#[test]
fn bbm_implicit_error_shrinks_with_the_step() {
    let work = scratch("bbm");
    let sweep = bbm::Sweep::of(Size::Quick);
    let rows = bbm::run(&sweep, &work).unwrap();
    let errors = bbm::deviations(&rows);
    for size in &sweep.sizes {
        let own: Vec<f64> = rows
            .iter()
            .zip(&errors)
            .filter(|(r, _)| r.size == *size && r.implicit_dt.is_some())
            .map(|(_, e)| e.1)
            .collect();
        assert_eq!(own.len(), sweep.dts.len());
        assert!(own[1] < 0.5 * own[0], "element {size}: errors {own:?}");
    }
    std::fs::remove_dir_all(&work).unwrap();
}

/// Stiffer contacts give a smaller resilient displacement (the rebound from the last peak
/// load) under the same cyclic load: for a fixed network of Hertz contacts it goes as
/// E^(-2/3), 6.3 times smaller for 16 times the modulus. The softer beds' rebound also
/// carries the settling they are still doing, so only the order at each step and at least
/// half of Hertz's reduction are held.
#[test]
fn boxtest_stiffer_contacts_deflect_less() {
    let work = scratch("boxtest");
    let sweep = boxtest::Sweep::of(Size::Quick);
    let rows = boxtest::run(&sweep, &work).unwrap();
    let resilient: Vec<f64> = rows.iter().map(|r| r.resilient_mm).collect();
    assert!(
        resilient.windows(2).all(|w| w[0] > w[1]),
        "resilient displacements {resilient:?}"
    );
    let ratio = resilient[0] / resilient[resilient.len() - 1];
    let hertz = (rows[rows.len() - 1].young / rows[0].young).powf(2.0 / 3.0);
    assert!(
        ratio > hertz / 2.0 && ratio < hertz * 2.0,
        "ratio {ratio}, Hertz {hertz}: {rows:?}"
    );
    assert!(rows.iter().all(|r| r.settlement_mm > 0.0), "{rows:?}");
    std::fs::remove_dir_all(&work).unwrap();
}

/// The reduced track's contact stiffness, on one stone of its bed at rest on the ground:
/// a linear contact's own step bound goes as k_n^(-1/2), twice as long at k_n / 4 (to 1%,
/// the spread of the estimate's floor contacts is the same at both stiffnesses); a rigid stone,
/// whose step the contacts set, steps twice as long, a deformable one at most that (its
/// tetrahedra bound it); and the mean overlap of the n contacts carrying its weight W is
/// W/(n k_n), four times deeper at k_n / 4 (to 1%: the stone is at rest to 1e-6 of it).
#[test]
fn track_softer_contacts_step_longer_and_overlap_deeper() {
    let work = scratch("track");
    let sweep = track::Sweep::of(Size::Quick);
    assert_eq!(sweep.softenings, [1.0, 4.0]);
    let (stones, rows) = track::run(&sweep, &work).unwrap();
    assert!(rows.is_empty());
    let close = |a: f64, b: f64, tol: f64| (a / b - 1.0).abs() < tol;
    for pair in stones.chunks(2) {
        let (stiff, soft) = (&pair[0], &pair[1]);
        assert_eq!(stiff.rigid, soft.rigid);
        assert!(
            close(soft.contact_dt / stiff.contact_dt, 2.0, 0.01),
            "{pair:?}"
        );
        let step_ratio = soft.dt / stiff.dt;
        match stiff.rigid {
            true => assert!(close(step_ratio, 2.0, 0.01), "{pair:?}"),
            false => assert!(step_ratio > 1.0 && step_ratio <= 2.0 + 1e-9, "{pair:?}"),
        }
        assert_eq!(stiff.touching, soft.touching, "{pair:?}");
        assert!(stiff.touching >= 3, "{pair:?}");
        assert!(
            close(soft.mean_overlap / stiff.mean_overlap, 4.0, 0.01),
            "{pair:?}"
        );
        for s in pair {
            let hooke = s.weight / (s.touching as f64 * s.normal_stiffness);
            assert!(
                close(s.mean_overlap, hooke, 0.01),
                "{s:?}: W/(n k_n) = {hooke}"
            );
        }
    }
    std::fs::remove_dir_all(&work).unwrap();
}

/// The study writes the families' sections and SVGs and keeps the hand-written part.
#[test]
fn study_writes_the_sections_and_keeps_the_hand_written_part() {
    let docs = scratch("docs");
    let page = docs.join("speed-vs-error.md");
    std::fs::write(&page, format!("# old\n\n{KEPT_FROM}\n\nby hand\n")).unwrap();
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .args([
            "speed-vs-error",
            "--families",
            "packing",
            "--quick",
            "--docs",
        ])
        .arg(&docs)
        .arg("--work")
        .arg(docs.join("work"))
        .status()
        .unwrap();
    assert!(status.success());
    let text = std::fs::read_to_string(&page).unwrap();
    assert!(text.contains("## A packing"));
    assert!(text.ends_with(&format!("{KEPT_FROM}\n\nby hand\n")));
    let svg = std::fs::read_to_string(docs.join("figures/speed_vs_error_packing.svg")).unwrap();
    assert!(svg.starts_with("<svg") || svg.contains("<svg"));
    std::fs::remove_dir_all(&docs).unwrap();
}
