//! A constraint file. Whatever the bytes, reading gives compiled constraints or an error naming a
//! line and column that exist; never a panic, never a stack overflow. Each compiled constraint
//! is evaluated (C, its gradient by automatic differentiation in both modes and the file's own)
//! at a regular tet and at coincident points, with what the element stores: the results are
//! finite or flagged undefined, and evaluating never panics; a `where` chooses among the tet's
//! particles without a panic.
//!
//! # A generator for deep and long inputs
//! Inputs that once crashed the parser (10⁴ nested parentheses, 20,000 unary minuses, a
//! megabyte of sum) are far beyond what mutating short inputs reaches. So the input is read as
//! segments separated by NUL bytes: a segment `N*TEXT` stands for TEXT repeated N times (N up to
//! 200,000, the whole at most 2 MB), any other for itself. `value = "\010000*(\01\010000*)\0"`
//! is a file of 10⁴ nested parentheses, and the fuzzer mutates N and TEXT like any other bytes.
//! Input without a NUL byte is the file itself.

#![no_main]

use glam::DVec3;
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::material::Material;
use tetlab_core::input::text_file::decode;

/// The text the input stands for (see the module's notes).
fn expand(data: &[u8]) -> Vec<u8> {
    if !data.contains(&0) {
        return data.to_vec();
    }
    let mut out = Vec::new();
    for segment in data.split(|&b| b == 0) {
        let digits = segment.iter().take_while(|b| b.is_ascii_digit()).count();
        let repeat = (digits > 0 && segment.get(digits) == Some(&b'*'))
            .then(|| {
                std::str::from_utf8(&segment[..digits])
                    .ok()?
                    .parse::<usize>()
                    .ok()
            })
            .flatten();
        match repeat {
            Some(n) => {
                let unit = &segment[digits + 1..];
                let n = n.min(200_000);
                for _ in 0..n {
                    if out.len() + unit.len() > 2 << 20 {
                        break;
                    }
                    out.extend_from_slice(unit);
                }
            }
            None => out.extend_from_slice(segment),
        }
    }
    out
}

fuzz_target!(|data: &[u8]| {
    let bytes = expand(data);
    let Ok(text) = decode(&bytes) else {
        return;
    };
    match ConstraintFile::parse_all(Path::new("fuzz.toml"), text) {
        Ok(files) => {
            let material = Material::default();
            let tet = [
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 0.0, 1.0),
            ];
            for file in &files {
                // Which particles a file on single particles chooses: any of the tet's, in
                // order, and never a panic.
                let chosen = file.chooses(&tet);
                assert!(chosen.windows(2).all(|w| w[0] < w[1]) && chosen.iter().all(|&i| i < 4));
                for points in [&tet[..], &[DVec3::ZERO; 4][..]] {
                    let points = &points[..file.arity()];
                    let stored = file.store(&tet[..file.arity()], &material);
                    let rest = file.rest_value(&tet[..file.arity()], &material);
                    assert!(rest.is_finite());
                    let e = file.evaluate(points, rest, &stored);
                    if let Some(g) = &e.automatic {
                        assert!(g.iter().all(|v| v.is_finite()));
                    }
                    // What a simulation takes (reverse-mode AD, or the file's own gradient):
                    // finite, or degenerate with zero gradients.
                    for own in [false, true] {
                        let (value, gradients, degenerate) = match points.len() {
                            1 => {
                                let e = file.evaluate_by(&[points[0]], rest, &stored, own);
                                (e.value, e.gradients.to_vec(), e.degenerate)
                            }
                            2 => {
                                let e =
                                    file.evaluate_by(&[points[0], points[1]], rest, &stored, own);
                                (e.value, e.gradients.to_vec(), e.degenerate)
                            }
                            3 => {
                                let p = [points[0], points[1], points[2]];
                                let e = file.evaluate_by(&p, rest, &stored, own);
                                (e.value, e.gradients.to_vec(), e.degenerate)
                            }
                            _ => {
                                let p = [points[0], points[1], points[2], points[3]];
                                let e = file.evaluate_by(&p, rest, &stored, own);
                                (e.value, e.gradients.to_vec(), e.degenerate)
                            }
                        };
                        assert!(value.is_finite());
                        assert!(gradients.iter().all(|g| g.is_finite()));
                        assert!(!degenerate || gradients.iter().all(|g| *g == DVec3::ZERO));
                    }
                    // Where C is undefined, the reason names a place in the file.
                    if let Some(e) = file.undefined_at(points, rest, &stored) {
                        let (line, column) = e.at.expect("a place");
                        assert!(line >= 1 && line <= text.lines().count() + 1 && column >= 1);
                    }
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
