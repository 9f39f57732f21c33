//! The GPU engine's compute shaders, written by running the CPU engines' own code on traced
//! numbers ([`crate::numbers::traced`]): a unit's projection is its family's `evaluate` (a
//! built-in formula, or a constraint file's tape) and the projection rule every engine shares
//! ([`correct_in_reach`]); the per-particle stages are `integrate`'s per-particle functions and
//! the compliant grab's `pull`. No formula is written in WGSL by hand; what is hand-written here
//! is where each number lives (the buffers of [`super::memory`]) and the compensated store.
//!
//! Every kernel has the same bindings ([`PRELUDE`]) and one thread per element or particle:
//! thread t of a dispatch of `count` works on `indices[first + t]` (a projection's slot: batch
//! × 8 + lane of the fast engine's layout) or on particle t.

use super::memory::{Memory, Section};
use crate::constraints::{Families, Family, Projected, SubstepStart, Unit, VisitProjected};
use crate::numbers::traced::{Traced, TracedMask, TracedVec3, record, statement};
use crate::numbers::vector::{Real, rounded};
use crate::simulation::integrate::{self, Ending, Motion};
use crate::simulation::projection::{Rule, correct_in_reach};
use std::fmt::Write;

/// The threads of a workgroup.
pub(super) const WORKGROUP: u32 = 64;

/// Where the frame's numbers are in the `frame` uniform (vectors of four f32).
pub(super) mod slot {
    /// (+∞, NaN, 0, 0): the numbers WGSL has no literal for.
    pub(crate) const SPECIAL: usize = 0;
    /// The prediction: (g h along y, h, the ground's height, 0).
    pub(crate) const MOTION: usize = 1;
    /// The end of a substep: (h, what damping keeps, −g h, 0).
    pub(crate) const ENDING: usize = 2;
    /// (the reach, the compliant grab's α̃, 0, 0).
    pub(crate) const REACH_AND_GRAB: usize = 3;
    /// The grab's target in the engine's coordinates.
    pub(crate) const TARGET: usize = 4;
    /// Each family's rule (x: α̃ or k′), from here on.
    pub(crate) const RULES: usize = 5;
    /// The vectors of the uniform.
    pub(crate) const LEN: usize = RULES + crate::constraints::MAX_FAMILIES;
}

/// What every kernel declares: the engine's four buffers, the frame's numbers and the
/// dispatch's (its first index, its thread count and a particle), and the thread's number `t`.
pub(super) const PRELUDE: &str = "\
@group(0) @binding(0) var<storage, read_write> points: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> numbers: array<f32>;
@group(0) @binding(2) var<storage, read> indices: array<u32>;
@group(0) @binding(3) var<storage, read_write> counters: array<atomic<u32>>;
@group(0) @binding(4) var<uniform> frame: array<vec4<f32>, FRAME_LEN>;
struct Dispatch { first: u32, count: u32, particle: u32, spare: u32 }
@group(0) @binding(5) var<uniform> dispatch: Dispatch;

@compute @workgroup_size(WORKGROUP)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let t = id.x + id.y * groups.x * WORKGROUPu;
    if (t >= dispatch.count) {
        return;
    }
    let special = frame[0];
";

/// A kernel's source: the prelude, then `body` (which reads `t`), closed.
fn kernel(body: &str) -> String {
    let prelude = PRELUDE
        .replace("FRAME_LEN", &slot::LEN.to_string())
        .replace("WORKGROUP", &WORKGROUP.to_string());
    format!("{prelude}{body}}}\n")
}

/// The frame uniform's component `c` (0 to 3) of vector `slot`.
fn uniform(slot: usize, c: usize) -> Traced {
    Traced::input(&format!("frame[{slot}].{}", ["x", "y", "z", "w"][c]))
}

/// `points[section + index]` as a traced vector.
fn point(memory: &Memory, section: Section, index: &str) -> TracedVec3 {
    TracedVec3::input_xyz(&format!("points[{}u + {index}]", memory.section(section)))
}

/// Records `points[section + index] = v`.
fn store_point(memory: &Memory, section: Section, index: &str, v: TracedVec3) {
    let at = memory.section(section);
    statement(format_args!(
        "points[{at}u + {index}] = vec4<f32>({}, {}, {}, 0.0f);",
        v.x, v.y, v.z
    ));
}

/// Records `numbers[at] = value`.
fn store_number(at: &str, value: Traced) {
    statement(format_args!("numbers[{at}] = {value};"));
}

/// Records the compensated move of particle `index` (read as `x`) by `delta`: x + r moves by δ
/// (x = fl(x + (δ + r)), r = (δ + r) − (x_new − x)), as the fast engine's stores.
fn compensated_add(memory: &Memory, index: &str, x: TracedVec3, delta: TracedVec3) {
    let r = point(memory, Section::Residuals, index);
    let step = rounded(delta + r);
    let moved = rounded(x + step);
    let residual = step - rounded(moved - x);
    store_point(memory, Section::Positions, index, moved);
    store_point(memory, Section::Residuals, index, residual);
}

/// How a unit's kernel is made: its families' rules (by kind), whether each has own
/// compliances, and where its numbers are.
pub(super) struct UnitKernel<'a> {
    /// The GPU's memory map.
    pub memory: &'a Memory,
    /// The rule of every family (its kind decides the code; its value is read from `frame`).
    pub rules: &'a crate::constraints::PerFamily<Rule<f64>>,
}

impl UnitKernel<'_> {
    /// The kernel that projects `unit`'s elements of one colour, one per thread.
    pub(super) fn source(&self, families: &Families, unit: Unit) -> String {
        families.visit_unit(unit, Visitor { kernel: self })
    }
}

struct Visitor<'a, 'b> {
    kernel: &'a UnitKernel<'b>,
}

impl VisitProjected for Visitor<'_, '_> {
    type Output = String;

    fn visit<const N: usize, const K: usize, P: Projected<N, K>>(
        self,
        families: [Family; K],
        constraint: &P,
    ) -> String {
        let memory = self.kernel.memory;
        let layout = memory.layout_of(families[0]);
        let mut head = String::new();
        let _ = writeln!(head, "    let slot = indices[dispatch.first + t];");
        let _ = writeln!(head, "    let b = slot / 8u;");
        let _ = writeln!(head, "    let lane = slot % 8u;");
        for k in 0..N {
            let _ = writeln!(
                head,
                "    let i{k} = indices[{}u + (b * {N}u + {k}u) * 8u + lane];",
                layout.particles
            );
        }
        let ((), body) = record(|| {
            let p: [TracedVec3; N] =
                std::array::from_fn(|k| point(memory, Section::Positions, &format!("i{k}")));
            let weights: [Traced; N] = std::array::from_fn(|k| {
                Traced::input(&format!(
                    "numbers[{}u + (b * {N}u + {k}u) * 8u + lane]",
                    layout.weights
                ))
            });
            let size = Traced::input(&format!("numbers[{}u + slot]", layout.size));
            let numbers = families.map(|f| memory.family(f));
            let rest = numbers.map(|n| Traced::input(&format!("numbers[{}u + slot]", n.rest)));
            let stored: [Vec<Traced>; K] = std::array::from_fn(|k| {
                let n = numbers[k];
                (0..n.stored_len)
                    .map(|s| {
                        Traced::input(&format!(
                            "numbers[{}u + (b * {}u + {s}u) * 8u + lane]",
                            n.stored, n.stored_len
                        ))
                    })
                    .collect()
            });
            let lambda = numbers.map(|n| Traced::input(&format!("numbers[{}u + slot]", n.lambda)));
            let shape: [TracedVec3; N] = if P::READS_REST_SHAPE {
                std::array::from_fn(|k| point(memory, Section::Rest, &format!("i{k}")))
            } else {
                p
            };
            let (start, h) = if constraint.reads_motion() {
                let start: [TracedVec3; N] =
                    std::array::from_fn(|k| point(memory, Section::Previous, &format!("i{k}")));
                (start, uniform(slot::MOTION, 1))
            } else {
                (p, Traced::from_f64(crate::constraint_file::RESTING_H))
            };
            let evaluations = constraint.evaluate_stored(
                &p,
                rest,
                &shape,
                std::array::from_fn(|k| &stored[k][..]),
                SubstepStart { start: &start, h },
            );
            let rules: [Rule<Traced>; K] = std::array::from_fn(|k| {
                let family = families[k];
                let value = uniform(slot::RULES + family.index(), 0);
                let rule = match self.kernel.rules[family] {
                    Rule::Xpbd { .. } => Rule::Xpbd { alpha_tilde: value },
                    Rule::Pbd { .. } => Rule::Pbd { k: value },
                    Rule::CompliantPbd { .. } => Rule::CompliantPbd { alpha_tilde: value },
                };
                match numbers[k].own {
                    Some(own) => rule.with_own(Traced::input(&format!("numbers[{own}u + slot]"))),
                    None => rule,
                }
            });
            let reach = uniform(slot::REACH_AND_GRAB, 0);
            let d = correct_in_reach(evaluations, weights, lambda, rules, (reach, size), || p);
            for k in 0..K {
                let n = numbers[k];
                store_number(
                    &format!("{}u + slot", n.lambda),
                    lambda[k] + d.delta_lambda[k],
                );
                count(d.skipped[k].degenerate, 2 * families[k].index());
                count(d.skipped[k].too_long, 2 * families[k].index() + 1);
            }
            for (k, delta) in d.delta_x.into_iter().enumerate() {
                compensated_add(memory, &format!("i{k}"), p[k], delta);
            }
        });
        kernel(&(head + &body))
    }
}

/// Records `counters[counter] += 1` where `flag` is set.
fn count(flag: TracedMask, counter: usize) {
    match flag {
        TracedMask::Const(false) => {}
        _ => statement(format_args!(
            "if ({flag}) {{ atomicAdd(&counters[{counter}], 1u); }}"
        )),
    }
}

/// What shapes a per-particle kernel's code: the ground, plane strain, external forces,
/// damping and the settling cap. Their values are read from `frame`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) struct Shape {
    /// A ground at y = 0 of the scene.
    pub ground: bool,
    /// Every particle keeps its z.
    pub plane_strain: bool,
    /// Some particle has an external force.
    pub forces: bool,
    /// Velocities are damped.
    pub damped: bool,
    /// Velocities are capped (an edit settles).
    pub cap: bool,
}

impl Shape {
    /// No ground, no plane strain, no forces, no damping, no cap: the shape of the kernels whose
    /// code nothing shapes.
    pub(super) const NONE: Shape = Shape {
        ground: false,
        plane_strain: false,
        forces: false,
        damped: false,
        cap: false,
    };
}

/// The prediction, one particle a thread ([`integrate::predict_particle`]): x_prev = x,
/// r_prev = r, then x, v, r and the ground's push.
pub(super) fn predict(memory: &Memory, shape: Shape) -> String {
    let ((), body) = record(|| {
        statement(format_args!("let i = t;"));
        let x = point(memory, Section::Positions, "i");
        let v = point(memory, Section::Velocities, "i");
        let r = point(memory, Section::Residuals, "i");
        store_point(memory, Section::Previous, "i", x);
        store_point(memory, Section::PreviousResiduals, "i", r);
        let w = Traced::input("numbers[i]");
        let force = shape.forces.then(|| point(memory, Section::Forces, "i"));
        let motion = Motion {
            pull: TracedVec3 {
                x: Traced::ZERO,
                y: uniform(slot::MOTION, 0),
                z: Traced::ZERO,
            },
            h: uniform(slot::MOTION, 1),
            floor: shape.ground.then(|| uniform(slot::MOTION, 2)),
            plane_strain: shape.plane_strain,
        };
        let (x, v, r, push) = integrate::predict_particle((x, v, Some(r)), w, force, &motion);
        store_point(memory, Section::Positions, "i", x);
        store_point(memory, Section::Velocities, "i", v);
        if let Some(r) = r {
            store_point(memory, Section::Residuals, "i", r);
        }
        store_point(memory, Section::Pushes, "i", push);
    });
    kernel(&body)
}

/// The ground and the plane after a sweep, one particle a thread
/// ([`integrate::ground_particle`], [`integrate::plane_particle`]).
pub(super) fn ground_and_plane(memory: &Memory, shape: Shape) -> String {
    let ((), body) = record(|| {
        statement(format_args!("let i = t;"));
        let mut x = point(memory, Section::Positions, "i");
        if shape.ground {
            let w = Traced::input("numbers[i]");
            let push = point(memory, Section::Pushes, "i");
            let floor = uniform(slot::MOTION, 2);
            let (grounded, pushed) = integrate::ground_particle(x, w, floor, push);
            x = grounded;
            store_point(memory, Section::Pushes, "i", pushed);
        }
        if shape.plane_strain {
            let start = point(memory, Section::Previous, "i");
            x = integrate::plane_particle(x, start);
        }
        store_point(memory, Section::Positions, "i", x);
    });
    kernel(&body)
}

/// The end of a substep, one particle a thread ([`integrate::end_particle`]): v from the
/// motion of x + r, and what the ground, damping and the cap took.
pub(super) fn update_velocities(memory: &Memory, shape: Shape) -> String {
    let ((), body) = record(|| {
        statement(format_args!("let i = t;"));
        let x = point(memory, Section::Positions, "i");
        let previous = point(memory, Section::Previous, "i");
        let r = point(memory, Section::Residuals, "i");
        let r_previous = point(memory, Section::PreviousResiduals, "i");
        let moved = rounded(x - previous) + rounded(r - r_previous);
        let v = point(memory, Section::Velocities, "i");
        let w = Traced::input("numbers[i]");
        let force = shape.forces.then(|| point(memory, Section::Forces, "i"));
        let push = point(memory, Section::Pushes, "i");
        let taken = point(memory, Section::Taken, "i");
        let ending = Ending {
            h: uniform(slot::ENDING, 0),
            keep: uniform(slot::ENDING, 1),
            damped: shape.damped,
            cap: shape.cap,
            pull: TracedVec3 {
                x: Traced::ZERO,
                y: uniform(slot::ENDING, 2),
                z: Traced::ZERO,
            },
        };
        let (v, taken) = integrate::end_particle((moved, v), (w, force, push), taken, &ending);
        store_point(memory, Section::Velocities, "i", v);
        store_point(memory, Section::Taken, "i", taken);
    });
    kernel(&body)
}

/// Keeps the predicted positions, one particle a thread.
pub(super) fn keep_predicted(memory: &Memory) -> String {
    let (p, x) = (
        memory.section(Section::Predicted),
        memory.section(Section::Positions),
    );
    kernel(&format!("    points[{p}u + t] = points[{x}u + t];\n"))
}

/// Δp = x − predicted x and its sum over the frame, one particle a thread.
pub(super) fn keep_corrections(memory: &Memory) -> String {
    let ((), body) = record(|| {
        statement(format_args!("let i = t;"));
        let x = point(memory, Section::Positions, "i");
        let predicted = point(memory, Section::Predicted, "i");
        let sum = point(memory, Section::FrameCorrections, "i");
        let last = x - predicted;
        store_point(memory, Section::LastCorrections, "i", last);
        store_point(memory, Section::FrameCorrections, "i", sum + last);
    });
    kernel(&body)
}

/// Puts `dispatch.particle` at the grab's target (a rigid grab), its residual zero.
pub(super) fn hold(memory: &Memory) -> String {
    let (x, r) = (
        memory.section(Section::Positions),
        memory.section(Section::Residuals),
    );
    let target = slot::TARGET;
    kernel(&format!(
        "    let i = dispatch.particle;\n    points[{x}u + i] = vec4<f32>(frame[{target}].xyz, 0.0f);\n    points[{r}u + i] = vec4<f32>(0.0f);\n"
    ))
}

/// The compliant grab on `dispatch.particle` ([`crate::simulation::substep::pull`]), its
/// multiplier at the memory's grab λ.
pub(super) fn soft_grab(memory: &Memory) -> String {
    let ((), body) = record(|| {
        statement(format_args!("let i = dispatch.particle;"));
        let mut x = point(memory, Section::Positions, "i");
        let w = Traced::input("numbers[i]");
        let at = memory.grab_lambda();
        let mut lambda = Traced::input(&format!("numbers[{at}u]"));
        let target = TracedVec3 {
            x: uniform(slot::TARGET, 0),
            y: uniform(slot::TARGET, 1),
            z: uniform(slot::TARGET, 2),
        };
        let alpha = uniform(slot::REACH_AND_GRAB, 1);
        crate::simulation::substep::pull(&mut x, w, &mut lambda, target, alpha);
        store_point(memory, Section::Positions, "i", x);
        store_number(&format!("{at}u"), lambda);
    });
    kernel(&body)
}

/// Sets `numbers[dispatch.first + t]` to 0 (the multipliers, at the start of a substep).
pub(super) fn zero_numbers() -> String {
    kernel("    numbers[dispatch.first + t] = 0.0f;\n")
}

/// Checks `source` with naga, the compiler wgpu runs: the error in words where it is not valid
/// WGSL (a fault of the generator, or a formula it cannot translate).
pub(super) fn validate(source: &str) -> Result<(), String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .map(|_| ())
    .map_err(|e| e.emit_to_string(source))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraint_file::ConstraintFile;
    use crate::scene::{Builtin, Scene};
    use crate::simulation::fast::FastSimulation;
    use crate::simulation::{Settings, Simulation};

    /// Every kernel the engine can write for the built-in families and a constraint file (a
    /// tape with a prelude, the edge damper that reads the motion), under XPBD and PBD and every
    /// shape of the per-particle stages, is valid WGSL: naga accepts it, no adapter needed.
    #[test]
    fn every_kernel_is_valid_wgsl() {
        let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
        let mut families = Families::builtin();
        let mut names = vec!["edges", "height", "volume", "neohookean"]
            .into_iter()
            .map(str::to_owned)
            .collect::<Vec<_>>();
        for file in ["arap.toml", "edge-damper.toml"] {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../assets/constraints")
                .join(file);
            let family = families
                .define(ConstraintFile::load(&path).unwrap())
                .unwrap();
            names.push(families.name(family).to_owned());
        }
        let active = families.parse_list(&names.join(",")).unwrap();
        for method in [
            crate::simulation::Method::Xpbd,
            crate::simulation::Method::Pbd,
        ] {
            let settings = Settings {
                active,
                method,
                ..Settings::default()
            };
            let simulation = Simulation::with_families(&scene, settings, families.clone());
            let mirror = FastSimulation::new(simulation.start());
            let units: Vec<Unit> = families.units(&active).collect();
            let memory = Memory::new(&mirror, &families, &units);
            let h = simulation.resolved().substep_length();
            let rules = families.per_family(|f| simulation.resolved().rule(f, h));
            let kernel = UnitKernel {
                memory: &memory,
                rules: &rules,
            };
            for &unit in &units {
                let source = kernel.source(&families, unit);
                let name = families.name(unit.lead);
                validate(&source).unwrap_or_else(|e| panic!("{name}: {e}\n{source}"));
                println!("{name}: {} lines of WGSL", source.lines().count());
            }
            for bits in 0..32u32 {
                let shape = Shape {
                    ground: bits & 1 != 0,
                    plane_strain: bits & 2 != 0,
                    forces: bits & 4 != 0,
                    damped: bits & 8 != 0,
                    cap: bits & 16 != 0,
                };
                for source in [
                    predict(&memory, shape),
                    ground_and_plane(&memory, shape),
                    update_velocities(&memory, shape),
                ] {
                    validate(&source).unwrap_or_else(|e| panic!("{shape:?}: {e}\n{source}"));
                }
            }
            for source in [
                keep_predicted(&memory),
                keep_corrections(&memory),
                hold(&memory),
                soft_grab(&memory),
                zero_numbers(),
            ] {
                validate(&source).unwrap_or_else(|e| panic!("{e}\n{source}"));
            }
        }
    }

    /// A kernel that is not WGSL is an error naming the fault, not a panic.
    #[test]
    fn an_invalid_kernel_is_an_error() {
        let error = validate("fn main() { let x: f32 = y; }").unwrap_err();
        assert!(error.contains('y'), "{error}");
    }
}
