//! What the end-of-sweep rebuild of the static-bias experiment costs a frame
//! (docs/experiments.md, "XPBD's static bias, and an experiment that removes it"): the cantilever
//! of `core/tests/static_bias.rs` (the beam scene at resolution 1, neo-Hookean E = 10 MPa,
//! ν = 0.3, 4 iterations) stepped one frame at 20 and 100 substeps on the reference engine and on
//! the engine that rebuilds the positions from the multipliers after every sweep
//! (`core/tests/support/rebuilt_engine.rs`, three fixed-point passes). `cargo bench -p
//! tetlab-core --bench static_bias`.

#[path = "../tests/support/rebuilt_engine.rs"]
mod rebuilt_engine;

#[path = "../tests/support/cantilever.rs"]
mod cantilever;

use criterion::{Criterion, criterion_group, criterion_main};

fn frames(c: &mut Criterion) {
    let mut group = c.benchmark_group("cantilever frame");
    for substeps in [20, 100] {
        for (name, rebuilt) in [("xpbd", false), ("rebuilt", true)] {
            // A few frames into its swing, so that every multiplier is at work.
            let mut simulation = cantilever::cantilever(substeps, rebuilt);
            for _ in 0..10 {
                simulation.step();
            }
            group.bench_function(format!("{name}, {substeps} substeps"), |b| {
                b.iter(|| simulation.step())
            });
        }
    }
    group.finish();
}

criterion_group!(benches, frames);
criterion_main!(benches);
