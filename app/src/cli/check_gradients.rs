//! `tetlab check-gradients`: every family's analytic gradient against central differences on
//! seeded random configurations — the figures of `docs/gradients.md`; or, with
//! `--constraint-file`, a user's own gradient against automatic differentiation.

use super::UsageError;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraint_file::check::{AGREEMENT, Reflection, Report, check};
use tetlab_core::constraints::Families;
use tetlab_core::constraints::verify::{CONDITIONING, random_check};
use tetlab_core::energy::check::{HessianReport, MAX_SAMPLES, check as hessian_check};

/// Options of `tetlab check-gradients`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Well-conditioned configurations to compare per family (or for the constraint file).
    #[arg(long, visible_alias = "configs", default_value_t = 10_000, value_parser = clap::value_parser!(u32).range(1..=10_000_000))]
    samples: u32,
    /// A constraint file (assets/constraints/*.toml): its own gradient against automatic
    /// differentiation and AD against central differences; exit status 1 when yours disagrees.
    #[arg(long, value_name = "FILE")]
    constraint_file: Option<PathBuf>,
    /// Seed of the random configurations.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print one JSON object per family (one for the constraint file) instead of a table.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct Row {
    constraint: String,
    compared: usize,
    skipped_near_degenerate: usize,
    max_relative_error: f64,
    mean_relative_error: f64,
    /// The analytic gradient against automatic differentiation.
    max_error_against_automatic_differentiation: f64,
    /// ∇²C: forward mode over the analytic ∇C against second-order dual numbers of C, and
    /// against central differences of AD's ∇C, largest relative errors.
    hessian: HessianOutput,
}

/// The check of ∇²C, as `--json` writes it.
#[derive(Serialize)]
struct HessianOutput {
    compared: usize,
    against_second_order: f64,
    against_finite_differences: f64,
    /// The file's own blocks (`[hessian]`), keyed p0p1…: largest relative error against AD.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    yours: BTreeMap<String, Figure>,
}

impl HessianOutput {
    fn of(r: &HessianReport) -> HessianOutput {
        HessianOutput {
            compared: r.compared,
            against_second_order: r.against_second_order,
            against_finite_differences: r.against_finite_differences,
            yours: r
                .yours
                .iter()
                .map(|&((i, j), e)| (format!("p{i}p{j}"), Figure::of(Some(e))))
                .collect(),
        }
    }
}

/// Runs the check for every family and writes one row each; or checks the constraint file.
/// `Ok(false)` when the file's gradient disagrees with automatic differentiation.
pub fn run(args: &Args, out: &mut impl Write) -> Result<bool, UsageError> {
    if let Some(path) = &args.constraint_file {
        return run_file(args, path, out);
    }
    let families = Families::builtin();
    let rows: Vec<Row> = families
        .all()
        .map(|family| {
            let r = random_check(&families, family, args.samples as usize, args.seed);
            let h = hessian_check(&families, family, None, args.samples as usize, args.seed);
            Row {
                hessian: HessianOutput::of(&h),
                constraint: families.name(family).to_owned(),
                compared: r.compared,
                skipped_near_degenerate: r.skipped,
                max_relative_error: r.max_relative_error,
                mean_relative_error: r.mean_relative_error,
                max_error_against_automatic_differentiation: r.max_automatic_error,
            }
        })
        .collect();
    write(args, &rows, out).map_err(UsageError::stdout)?;
    Ok(true)
}

/// What `--constraint-file --json` prints.
#[derive(Serialize)]
struct FileOutput {
    constraint_file: String,
    name: String,
    agrees: bool,
    compared: usize,
    skipped_near_degenerate: usize,
    /// Keyed p0…; null for a particle the file gives no gradient for, "non_finite" where the
    /// file's gradient is NaN or infinite where AD's is finite.
    max_relative_error: BTreeMap<String, Figure>,
    worst: Option<WorstOutput>,
    automatic_vs_finite_difference: f64,
    /// Of AD's gradient.
    translation_invariant: bool,
    /// Of the file's gradient; null unless it gives every particle's.
    your_gradient_translation_invariant: Option<bool>,
    rotation_invariant: bool,
    /// Where C has a kink or a jump, found by sampling near it: each with where it is.
    kinks: Vec<KinkOutput>,
    reflection: &'static str,
    near_degenerate: usize,
    undefined_near_degenerate: usize,
    /// ∇²C by AD, checked; and the file's own blocks, when it gives any.
    hessian: HessianOutput,
    /// Whether every Hessian block the file gives agrees with AD (true when it gives none).
    hessian_agrees: bool,
}

#[derive(Serialize)]
struct WorstOutput {
    particle: String,
    points: Vec<[f64; 3]>,
    rest: f64,
    relative_error: Figure,
    /// Whether AD's gradient is zero there, so that the error is absolute.
    absolute: bool,
    command: String,
}

#[derive(Serialize)]
struct KinkOutput {
    what: &'static str,
    line: usize,
    column: usize,
    lines_tried: usize,
    lines_crossing: usize,
    largest_jump: f64,
    random_configurations_on_it: usize,
}

/// A figure as JSON gives it: a number, `"non_finite"` for NaN or ±∞ (JSON has neither; serde
/// would write `null`, which means "not given" here), or `null` for none.
#[derive(Serialize)]
#[serde(untagged)]
enum Figure {
    Number(f64),
    Word(&'static str),
    None(Option<()>),
}

impl Figure {
    fn of(x: Option<f64>) -> Figure {
        match x {
            Some(x) if x.is_finite() => Figure::Number(x),
            Some(_) => Figure::Word("non_finite"),
            None => Figure::None(None),
        }
    }
}

/// `x` with two significant digits, in scientific notation below 0.01 (`1.0e-4`).
fn two_digits(x: f64) -> String {
    if !x.is_finite() {
        "non-finite (NaN or infinite)".to_owned()
    } else if x == 0.0 || (0.01..1000.0).contains(&x.abs()) {
        let decimals = if x == 0.0 {
            1
        } else {
            (1 - x.abs().log10().floor() as i32).max(0) as usize
        };
        format!("{x:.decimals$}")
    } else {
        format!("{x:.1e}")
    }
}

/// `path` as a shell reads it back: quoted when it holds a space or another special character.
fn shell_word(path: &std::path::Path) -> String {
    let text = path.display().to_string();
    shlex::try_quote(&text).map_or(text.clone(), |q| q.into_owned())
}

/// Checks every constraint of the file in turn (one, or each `[[constraint]]`); `Ok(false)`
/// when the gradient of any disagrees.
fn run_file(args: &Args, path: &std::path::Path, out: &mut impl Write) -> Result<bool, UsageError> {
    let files = ConstraintFile::load_all(path).map_err(|e| UsageError(e.to_string()))?;
    // The table the Hessian check evaluates the file's families through.
    let mut families = Families::builtin();
    let added = families
        .register_all(files.clone())
        .map_err(|e| UsageError(format!("{}: {e}", path.display())))?;
    let mut agrees = true;
    for (k, (file, family)) in files.iter().zip(added).enumerate() {
        if k > 0 && !args.json {
            writeln!(out).map_err(UsageError::stdout)?;
        }
        let hessian = hessian_check(
            &families,
            family,
            Some(file),
            args.samples as usize,
            args.seed,
        );
        agrees &= run_one_file(args, path, (file, &hessian), out)?;
    }
    Ok(agrees)
}

fn run_one_file(
    args: &Args,
    path: &std::path::Path,
    (file, hessian): (&ConstraintFile, &HessianReport),
    out: &mut impl Write,
) -> Result<bool, UsageError> {
    let report = check(file, args.samples as usize, args.seed);
    if report.compared == 0 {
        // Where it is undefined, at the first configuration that the check drew.
        let mut rng = tetlab_core::numbers::random::SplitMix64::new(args.seed);
        let (points, around, _) = tetlab_core::constraints::verify::draw(&mut rng, file);
        let material = tetlab_core::constraints::material::Material::default();
        let stored = file.store(&around.rest_shape, &material);
        let rest = file.rest_value(&around.rest_shape, &material);
        let why = file
            .undefined_at(&points, rest, &stored)
            .map_or_else(String::new, |e| format!(": {e}"));
        return Err(UsageError(format!(
            "{}: C or its gradient is undefined at every random configuration tried{why}",
            path.display()
        )));
    }
    let kinks = tetlab_core::constraint_file::check::kinks(file, 200, args.seed);
    let output = file_output(path, file, (&report, hessian), &kinks);
    let written = if args.json {
        serde_json::to_writer(&mut *out, &output)
            .map_err(std::io::Error::from)
            .and_then(|()| writeln!(out))
    } else {
        write_file_report(args, &output, &report, out)
    };
    written.map_err(UsageError::stdout)?;
    Ok(output.agrees && output.hessian_agrees)
}

fn file_output(
    path: &std::path::Path,
    file: &ConstraintFile,
    (report, hessian): (&Report, &HessianReport),
    kinks: &[tetlab_core::constraint_file::check::Kink],
) -> FileOutput {
    let worst = report
        .worst
        .as_ref()
        .filter(|w| w.relative_error > AGREEMENT)
        .map(|w| WorstOutput {
            particle: format!("p{}", w.particle),
            points: w.points.iter().map(|p| p.to_array()).collect(),
            rest: w.rest,
            relative_error: Figure::of(Some(w.relative_error)),
            absolute: w.absolute,
            command: {
                // Every number as Rust prints an f64: the shortest text that reads back as the
                // same bits, so the command reproduces the failure exactly.
                let points = |points: &[glam::DVec3]| {
                    (points.iter())
                        .map(|p| format!("{:?},{:?},{:?}", p.x, p.y, p.z))
                        .collect::<Vec<_>>()
                        .join(" ")
                };
                let mut shape = (w.rest_shape.as_deref())
                    .map(|shape| format!(" --rest-shape {}", points(shape)))
                    .unwrap_or_default();
                if let Some((start, h)) = &w.moving {
                    shape += &format!(" --start {} --h {h:?}", points(start));
                }
                format!(
                    "tetlab gradient --constraint-file {} --points {}{shape} --rest {:?}",
                    shell_word(path),
                    points(&w.points),
                    w.rest
                )
            },
        });
    FileOutput {
        constraint_file: path.display().to_string(),
        name: file.name.clone(),
        agrees: report.agrees(),
        compared: report.compared,
        skipped_near_degenerate: report.skipped,
        max_relative_error: report
            .max_relative_error
            .iter()
            .enumerate()
            .map(|(k, e)| (format!("p{k}"), Figure::of(*e)))
            .collect(),
        worst,
        automatic_vs_finite_difference: report.automatic_vs_finite_difference,
        translation_invariant: report.translation_invariant(),
        your_gradient_translation_invariant: report.given_translation_invariant(),
        rotation_invariant: report.rotation_invariant(),
        kinks: kinks
            .iter()
            .map(|k| KinkOutput {
                what: k.what,
                line: k.at.0,
                column: k.at.1,
                lines_tried: k.tried,
                lines_crossing: k.crossed,
                largest_jump: k.jump,
                random_configurations_on_it: k.landed,
            })
            .collect(),
        reflection: report.reflection.describe(),
        near_degenerate: report.near_degenerate,
        undefined_near_degenerate: report.undefined,
        hessian: HessianOutput::of(hessian),
        hessian_agrees: hessian.yours_agree(AGREEMENT),
    }
}

fn write_file_report(
    args: &Args,
    o: &FileOutput,
    report: &Report,
    out: &mut impl Write,
) -> std::io::Result<()> {
    let yes = |b: bool| if b { "yes" } else { "no" };
    writeln!(out, "constraint file {}: {}", o.constraint_file, o.name)?;
    writeln!(
        out,
        "{} random configurations compared, seed {} ({} skipped as near-degenerate)",
        o.compared, args.seed, o.skipped_near_degenerate
    )?;
    writeln!(out)?;
    writeln!(
        out,
        "your gradient against automatic differentiation (AD), largest relative error:"
    )?;
    for (particle, error) in &o.max_relative_error {
        match error {
            Figure::Number(e) if *e <= AGREEMENT => writeln!(out, "  {particle}  {e:.2e}  agrees")?,
            Figure::Number(e) => writeln!(out, "  {particle}  {e:.2e}  WRONG")?,
            Figure::Word(_) => writeln!(
                out,
                "  {particle}  non-finite  WRONG (NaN or infinite where AD's is finite)"
            )?,
            Figure::None(_) => writeln!(out, "  {particle}  not given, not checked")?,
        }
    }
    writeln!(
        out,
        "AD against central differences: {:.2e}",
        o.automatic_vs_finite_difference
    )?;
    writeln!(
        out,
        "translation invariant (sum of the gradients = 0): AD's {} ({})",
        yes(o.translation_invariant),
        against_rounding(report.translation, report.translation_excess)
    )?;
    match report.translation_given {
        Some(t) => writeln!(
            out,
            "  and yours {} ({})",
            yes(o.your_gradient_translation_invariant == Some(true)),
            if t.is_finite() {
                against_rounding(t, report.translation_given_excess.unwrap_or(0.0))
            } else {
                "non-finite".to_owned()
            }
        )?,
        None => writeln!(
            out,
            "  yours is not checked for it: it does not give every particle's gradient"
        )?,
    }
    if o.max_relative_error.len() == 1 {
        // About its own place, one particle cannot turn: Σ p × ∇C is 0 whatever C is.
        writeln!(
            out,
            "rotation invariant: not asked of one particle (it turns about itself)"
        )?;
    } else {
        writeln!(
            out,
            "rotation invariant (sum of p x gradient = 0): {} ({})",
            yes(o.rotation_invariant),
            against_rounding(report.rotation, report.rotation_excess)
        )?;
    }
    match report.reflection {
        Reflection::Untried => writeln!(out, "a reflection (x -> -x): {}", o.reflection)?,
        _ => writeln!(out, "a reflection (x -> -x) leaves C {}", o.reflection)?,
    }
    writeln!(
        out,
        "near-degenerate configurations: {}; C or its gradient undefined at {} (flagged, never NaN)",
        o.near_degenerate, o.undefined_near_degenerate
    )?;
    write_file_hessian(&o.hessian, o.max_relative_error.len(), out)?;
    writeln!(out)?;
    match &o.worst {
        None if o
            .max_relative_error
            .values()
            .all(|e| matches!(e, Figure::None(_))) =>
        {
            writeln!(
                out,
                "the file gives no gradient: nothing of yours to check (add [gradient] p0 = \"...\")"
            )
        }
        None => writeln!(
            out,
            "agrees: your gradient matches AD within {AGREEMENT:.0e}"
        ),
        Some(w) => {
            let off = match &w.relative_error {
                Figure::Number(e) if w.absolute => {
                    format!("{} (absolute: AD's gradient is zero there)", two_digits(*e))
                }
                Figure::Number(e) => format!("{} of the gradient's size", two_digits(*e)),
                _ => "a non-finite amount (NaN or infinite where AD's is finite)".to_owned(),
            };
            writeln!(
                out,
                "DISAGREES: {} is off by {off}; see it with\n  {}",
                w.particle, w.command
            )
        }
    }?;
    let wrong: Vec<(&String, &Figure)> = o
        .hessian
        .yours
        .iter()
        .filter(|(_, e)| !matches!(e, Figure::Number(x) if *x <= AGREEMENT))
        .collect();
    for (block, error) in wrong {
        let off = match error {
            Figure::Number(e) => format!("{} of the Hessian's size", two_digits(*e)),
            _ => "a non-finite amount (NaN or infinite where AD's is finite)".to_owned(),
        };
        writeln!(out, "DISAGREES: your Hessian block {block} is off by {off}")?;
    }
    if !o.kinks.is_empty() {
        writeln!(out)?;
        writeln!(
            out,
            "C has kinks, where its gradient jumps (random configurations land on none, so the \
             figures above are away from them):"
        )?;
        for k in &o.kinks {
            writeln!(
                out,
                "  {} at {}:{}:{}: crossed by {} of {} random lines; there ∇C jumps by up to {} \
                 of its size",
                k.what,
                o.constraint_file,
                k.line,
                k.column,
                k.lines_crossing,
                k.lines_tried,
                two_digits(k.largest_jump)
            )?;
        }
        writeln!(
            out,
            "  on a kink a projection takes one side's gradient; `tetlab gradient` at a point on \
             one says so"
        )?;
    }
    Ok(())
}

/// The Hessian lines of a file's report.
fn write_file_hessian(
    h: &HessianOutput,
    arity: usize,
    out: &mut impl Write,
) -> std::io::Result<()> {
    writeln!(
        out,
        "Hessian (∇²C) on {} configurations: forward mode over AD's ∇C against second-order AD \
         {:.1e}, against central differences of ∇C {:.1e}",
        h.compared, h.against_second_order, h.against_finite_differences
    )?;
    if h.yours.is_empty() {
        let block = match arity {
            1 => "p0p0",
            _ => "p0p1",
        };
        return writeln!(
            out,
            "  the file gives no Hessian: nothing of yours to check (add [hessian] {block} = \"...\")"
        );
    }
    for (block, error) in &h.yours {
        match error {
            Figure::Number(e) if *e <= AGREEMENT => {
                writeln!(out, "  your {block}  {e:.2e}  agrees")?
            }
            Figure::Number(e) => writeln!(out, "  your {block}  {e:.2e}  WRONG")?,
            _ => writeln!(out, "  your {block}  non-finite  WRONG")?,
        }
    }
    Ok(())
}

fn write(args: &Args, rows: &[Row], out: &mut impl Write) -> std::io::Result<()> {
    if args.json {
        for row in rows {
            serde_json::to_writer(&mut *out, row)?;
            writeln!(out)?;
        }
        return Ok(());
    }
    writeln!(
        out,
        "seed {}; a configuration is skipped when two points are closer than {CONDITIONING} of the \
         largest distance or a triangle of three has an angle whose sine is below {CONDITIONING}",
        args.seed
    )?;
    let w = rows.iter().map(|r| r.constraint.len()).max().unwrap_or(0) + 2;
    writeln!(
        out,
        "{:<w$}{:>10}{:>10}{:>22}{:>22}{:>16}{:>18}{:>18}",
        "family",
        "compared",
        "skipped",
        "max relative error",
        "mean relative error",
        "against AD",
        "Hessian vs AD²",
        "Hessian vs FD"
    )?;
    for r in rows {
        writeln!(
            out,
            "{:<w$}{:>10}{:>10}{:>22.3e}{:>22.3e}{:>16.3e}{:>18.3e}{:>18.3e}",
            r.constraint,
            r.compared,
            r.skipped_near_degenerate,
            r.max_relative_error,
            r.mean_relative_error,
            r.max_error_against_automatic_differentiation,
            r.hessian.against_second_order,
            r.hessian.against_finite_differences
        )?;
    }
    writeln!(
        out,
        "(relative errors of the analytic gradient against central differences, then against \
         automatic differentiation; then ∇²C, forward mode over the analytic ∇C, against \
         second-order dual numbers of C (AD²) and against central differences of AD's ∇C, on \
         the first {} configurations at most)",
        MAX_SAMPLES
    )?;
    Ok(())
}

/// A largest sum of an invariance check (relative to the gradient's size), and what it is
/// against rounding: within the fixed bound, within what rounding allows at its configuration
/// (an ill-conditioned one), or how many times that it is.
fn against_rounding(largest: f64, excess: f64) -> String {
    use tetlab_core::constraint_file::check::INVARIANCE;
    if largest <= INVARIANCE {
        format!("{largest:.1e}")
    } else if excess <= 1.0 {
        format!("{largest:.1e}, within what rounding gives at that configuration")
    } else {
        format!("{largest:.1e}, {excess:.1e} times what rounding gives there")
    }
}
