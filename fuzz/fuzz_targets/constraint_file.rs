//! A constraint file. Whatever the bytes, reading gives a compiled constraint or an error naming a
//! line and column that exist; never a panic. A compiled one is evaluated (C, its gradient by
//! automatic differentiation in both modes and the file's own) at a regular tet and at coincident
//! points: the results are finite or flagged undefined, and evaluating never panics.

#![no_main]

use glam::DVec3;
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::input::text_file::decode;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = decode(data) else {
        return;
    };
    match ConstraintFile::parse(Path::new("fuzz.toml"), text) {
        Ok(file) => {
            let tet = [
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 0.0, 1.0),
            ];
            for points in [&tet[..], &[DVec3::ZERO; 4][..]] {
                let points = &points[..file.arity()];
                let rest = file.rest_value(points);
                let e = file.evaluate(points, if rest.is_finite() { rest } else { 0.0 });
                if let Some(g) = &e.automatic {
                    assert!(g.iter().all(|v| v.is_finite()));
                }
                // What a simulation takes (reverse-mode AD, or the file's own gradient): finite,
                // or degenerate with zero gradients.
                for own in [false, true] {
                    let (value, gradients, degenerate) = match points.len() {
                        2 => {
                            let e = file.evaluate_by(&[points[0], points[1]], rest, &[], own);
                            (e.value, e.gradients.to_vec(), e.degenerate)
                        }
                        _ => {
                            let p = [points[0], points[1], points[2], points[3]];
                            let e = file.evaluate_by(&p, rest, &[], own);
                            (e.value, e.gradients.to_vec(), e.degenerate)
                        }
                    };
                    assert!(value.is_finite());
                    assert!(gradients.iter().all(|g| g.is_finite()));
                    assert!(!degenerate || gradients.iter().all(|g| *g == DVec3::ZERO));
                }
            }
        }
        Err(e) => {
            if let Some((line, column)) = e.at {
                let lines = text.lines().count() + 1;
                assert!(line >= 1 && line <= lines && column >= 1, "{e}");
            }
        }
    }
});
