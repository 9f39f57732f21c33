//! The fast engine evaluates a constraint file's family several batches of lanes at a time
//! (`Constraint::evaluate_batches`, one pass of the tape over a block of batches). Each batch's
//! evaluation must be, to the bit, what it gets alone (`Constraint::evaluate_stored`), so that the
//! grouping changes no result: checked for every example file, at random configurations with a
//! degenerate lane among them.

#[path = "support/example_files.rs"]
mod example_files;
use example_files::example_files;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::file::FileConstraint;
use tetlab_core::constraints::{Constraint, Evaluation, GROUP, SubstepStart};
use tetlab_core::numbers::lanes::{F32x8, LANES, Vec3x8};
use tetlab_core::numbers::random::SplitMix64;
use tetlab_core::numbers::vector::Vector3;

fn lanes(random: &mut SplitMix64, lo: f64, hi: f64) -> F32x8 {
    F32x8::new(std::array::from_fn(|_| random.range(lo, hi) as f32))
}

fn bits<const N: usize>(e: &Evaluation<Vec3x8, N>) -> Vec<u32> {
    let mut out: Vec<u32> = e.value.to_array().iter().map(|x| x.to_bits()).collect();
    for g in &e.gradients {
        for c in [g.x, g.y, g.z] {
            out.extend(c.to_array().iter().map(|x| x.to_bits()));
        }
    }
    out.extend((0..LANES).map(|k| u32::from(e.degenerate.lane(k))));
    out
}

/// The grouped evaluation of `file` against each batch alone, over 50 random groups.
fn same_bits<const N: usize>(file: &ConstraintFile) -> usize {
    let constraint = FileConstraint::<N>(std::sync::Arc::new(file.clone()));
    let mut random = SplitMix64::new(7);
    let mut checked = 0;
    for round in 0..50 {
        let mut p = [[Vec3x8::ZERO; N]; GROUP];
        let mut shape = [[Vec3x8::ZERO; N]; GROUP];
        let mut start = [[Vec3x8::ZERO; N]; GROUP];
        for j in 0..GROUP {
            for k in 0..N {
                let mut point = || Vec3x8 {
                    x: lanes(&mut random, -1.0, 1.0),
                    y: lanes(&mut random, -1.0, 1.0),
                    z: lanes(&mut random, -1.0, 1.0),
                };
                p[j][k] = point();
                shape[j][k] = point();
                start[j][k] = point();
            }
        }
        if round % 5 == 0 {
            // Every particle of batch 0 at one place: a degenerate evaluation.
            p[0] = [p[0][0]; N];
        }
        let rest: [F32x8; GROUP] = std::array::from_fn(|_| lanes(&mut random, 0.1, 1.0));
        let stored: Vec<Vec<F32x8>> = (0..GROUP)
            .map(|_| {
                (0..file.stored_len())
                    .map(|_| lanes(&mut random, 0.5, 1.5))
                    .collect()
            })
            .collect();
        let rows: [&[F32x8]; GROUP] = std::array::from_fn(|j| stored[j].as_slice());
        // Where the particles were at the start of the substep, and h: what a file that reads
        // them gets (the others ignore it).
        let h = lanes(&mut random, 1e-4, 1e-2);
        let grouped = constraint.evaluate_batches(&p, rest, &shape, rows, (&start, h));
        for j in 0..GROUP {
            let moving = SubstepStart {
                start: &start[j],
                h,
            };
            let alone = constraint.evaluate_stored(&p[j], rest[j], &shape[j], rows[j], moving);
            assert_eq!(
                bits(&grouped[j]),
                bits(&alone),
                "{}: batch {j} of group {round}",
                file.name
            );
            checked += 1;
        }
    }
    checked
}

#[test]
fn a_file_family_evaluated_in_groups_gives_each_batch_its_own_bits() {
    let mut families = 0;
    for path in example_files() {
        for file in ConstraintFile::load_all(&path).unwrap() {
            let checked = match file.arity() {
                1 => same_bits::<1>(&file),
                2 => same_bits::<2>(&file),
                3 => same_bits::<3>(&file),
                4 => same_bits::<4>(&file),
                arity => panic!("{}: arity {arity}", file.name),
            };
            assert_eq!(checked, 50 * GROUP);
            families += 1;
        }
    }
    // volume, height, the neo-Hookean pair, bending, surface area and the rest of the examples.
    assert!(families >= 8, "only {families} families checked");
}
