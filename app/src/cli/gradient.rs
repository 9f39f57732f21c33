//! `tetlab gradient`: C and ∇C of one constraint at given points, next to central differences.

use super::{UsageError, args};
use glam::DVec3;
use serde::Serialize;
use std::io::Write;
use std::path::PathBuf;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::verify::{analytic_and_numeric, max_abs_error};
use tetlab_core::constraints::{Families, Family};
use tetlab_core::numbers::finite_difference::central_difference;

/// Options of `tetlab gradient`.
#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("what").required(true).args(["constraint", "constraint_file"])))]
pub struct Args {
    /// The constraint family: edges (2 points: distance), height (4: height of p1 above the
    /// plane of p0, p2, p3) or volume (4: signed volume). `distance` and `plane` are aliases.
    #[arg(long, value_parser = builtin_family)]
    constraint: Option<Family>,
    /// A constraint file (assets/constraints/*.toml) instead of a built-in family: C, its
    /// gradient by automatic differentiation, the file's own, and central differences.
    #[arg(long, value_name = "FILE")]
    constraint_file: Option<PathBuf>,
    /// The particles in the constraint's order, each X,Y,Z; negative numbers are fine.
    #[arg(long, value_name = "X,Y,Z", num_args = 1.., required = true, value_parser = args::point)]
    points: Vec<DVec3>,
    /// The particles at rest, for a family that reads its rest shape (the neo-Hookean pair:
    /// F = Ds Dm⁻¹); the same number as --points. Without it, the rest shape is --points (F = I).
    #[arg(long, value_name = "X,Y,Z", num_args = 1.., value_parser = args::point)]
    rest_shape: Vec<DVec3>,
    /// The rest value: distance d, signed height d or signed volume V.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = args::finite_number)]
    rest: f64,
    /// Where the particles were at the start of the substep, for a constraint file that reads
    /// them (start0, …); the same number as --points. Without it, --points (no motion).
    #[arg(long, value_name = "X,Y,Z", num_args = 1.., value_parser = args::point)]
    start: Vec<DVec3>,
    /// The substep's length h in seconds, for a constraint file that reads it [default: 1/6000,
    /// the default substep].
    #[arg(long, value_name = "SECONDS", value_parser = args::finite_number)]
    h: Option<f64>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
}

/// A built-in family by name (a file's is given with `--constraint-file`).
fn builtin_family(text: &str) -> Result<Family, String> {
    Families::builtin().parse(text)
}

/// What `--json` prints.
#[derive(Debug, Serialize)]
struct Output {
    constraint: String,
    value: f64,
    rest: f64,
    gradients: Vec<[f64; 3]>,
    finite_difference: Vec<[f64; 3]>,
    max_abs_error: f64,
    degenerate: bool,
}

/// Evaluates the constraint and writes the result to `out`.
pub fn run(args: &Args, out: &mut impl Write) -> Result<(), UsageError> {
    let Some(family) = args.constraint else {
        return run_file(args, out);
    };
    if !args.start.is_empty() || args.h.is_some() {
        return Err(UsageError(
            "--start, --h: a built-in family reads neither where the particles were nor h; \
             they are for a constraint file that names start0… or h"
                .to_owned(),
        ));
    }
    let families = Families::builtin();
    if args.points.len() != families.arity(family) {
        return Err(UsageError(format!(
            "--points: the {} constraint takes {} points, got {}",
            families.name(family),
            families.arity(family),
            args.points.len()
        )));
    }
    let rest_shape = rest_shape(
        args,
        families.row(family).reads_rest_shape,
        &format!(
            "the {} constraint does not read a rest shape",
            families.name(family)
        ),
    )?;
    let evaluation = families
        .constraint(family)
        .evaluate(&args.points, args.rest, rest_shape);
    let (analytic, numeric) =
        analytic_and_numeric(&families, family, &args.points, args.rest, rest_shape);
    let output = Output {
        constraint: families.name(family).to_owned(),
        value: evaluation.value,
        rest: args.rest,
        gradients: analytic.iter().map(|&g| without_negative_zero(g)).collect(),
        finite_difference: numeric.iter().map(|&g| without_negative_zero(g)).collect(),
        max_abs_error: max_abs_error(&analytic, &numeric),
        degenerate: evaluation.degenerate,
    };
    let all_finite = output.value.is_finite()
        && output.max_abs_error.is_finite()
        && output
            .gradients
            .iter()
            .chain(&output.finite_difference)
            .flatten()
            .all(|x| x.is_finite());
    if !all_finite {
        return Err(UsageError(
            "--points: the coordinates are too large; C or ∇C overflows f64".into(),
        ));
    }
    let written = if args.json {
        serde_json::to_writer(&mut *out, &output)
            .map_err(std::io::Error::from)
            .and_then(|()| writeln!(out))
    } else {
        write_table(&families, family, &output, out)
    };
    written.map_err(UsageError::stdout)
}

/// The components with −0 written as 0 (x + 0 is +0 for x = −0 and x otherwise).
fn without_negative_zero(v: DVec3) -> [f64; 3] {
    (v + DVec3::ZERO).to_array()
}

fn write_table(
    families: &Families,
    family: Family,
    o: &Output,
    out: &mut impl Write,
) -> std::io::Result<()> {
    // The formula's lines up to C itself; its gradient lines are what the table below shows.
    let definition = families
        .row(family)
        .formula
        .lines()
        .take_while(|line| !line.starts_with('∇'));
    writeln!(out, "constraint  {}", o.constraint)?;
    for line in definition {
        writeln!(out, "            {line}")?;
    }
    write_value(
        out,
        o.value,
        o.rest,
        o.degenerate
            .then_some("yes: ∇C is undefined here and reported as zero"),
    )?;
    writeln!(
        out,
        "{:<9}{:<46}∇C central difference",
        "particle", "∇C analytic"
    )?;
    for (i, (a, n)) in o.gradients.iter().zip(&o.finite_difference).enumerate() {
        writeln!(out, "{:<9}{:<46}{}", format!("p{i}"), triple(a), triple(n))?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "max |analytic - central difference| = {:.3e}",
        o.max_abs_error
    )
}

fn triple(v: &[f64; 3]) -> String {
    format!("({:>13.6e},{:>13.6e},{:>13.6e})", v[0], v[1], v[2])
}

/// What `--constraint-file --json` prints.
#[derive(Debug, Serialize)]
struct FileOutput {
    constraint_file: String,
    name: String,
    value: f64,
    rest: f64,
    /// ∇C by automatic differentiation; null where it is undefined.
    automatic: Option<Vec<[f64; 3]>>,
    /// The file's gradient per particle; null where it gives none or it is undefined.
    yours: Vec<Option<[f64; 3]>>,
    /// Whether the file gives a gradient for each particle.
    given: Vec<bool>,
    finite_difference: Vec<[f64; 3]>,
    degenerate: bool,
    /// The kinks of C this configuration is on (`abs at FILE:LINE:COLUMN`): there AD gives one
    /// side's gradient and central differences the mean of the two.
    kinks: Vec<String>,
}

/// `--rest-shape`, or `--points` when it is not given: refused (`why`) for a constraint that
/// reads no rest shape, and unless it has as many points as `--points`.
fn rest_shape<'a>(args: &'a Args, reads: bool, why: &str) -> Result<&'a [DVec3], UsageError> {
    if args.rest_shape.is_empty() {
        Ok(&args.points)
    } else if !reads {
        Err(UsageError(format!("--rest-shape: {why}")))
    } else if args.rest_shape.len() != args.points.len() {
        Err(UsageError(format!(
            "--rest-shape: {} points, as many as --points ({})",
            args.rest_shape.len(),
            args.points.len()
        )))
    } else {
        Ok(&args.rest_shape)
    }
}

/// Where the particles were at the start of the substep and h: `--start` (or `--points`) and
/// `--h` (or the default substep), refused for a file that reads neither, and unless `--start`
/// has as many points as `--points` and h is positive.
fn moving<'a>(
    args: &'a Args,
    file: &ConstraintFile,
) -> Result<tetlab_core::constraint_file::Moving<'a>, UsageError> {
    let given = !args.start.is_empty() || args.h.is_some();
    if given && !file.reads_motion() {
        return Err(UsageError(format!(
            "--start, --h: {} reads neither where the particles were (start0…) nor h",
            file.name
        )));
    }
    if !args.start.is_empty() && args.start.len() != args.points.len() {
        return Err(UsageError(format!(
            "--start: {} points, as many as --points ({})",
            args.start.len(),
            args.points.len()
        )));
    }
    let h = args.h.unwrap_or(tetlab_core::constraint_file::RESTING_H);
    if h <= 0.0 {
        return Err(UsageError(format!(
            "--h: {h} s; the substep is longer than 0"
        )));
    }
    Ok(tetlab_core::constraint_file::Moving {
        start: if args.start.is_empty() {
            &args.points
        } else {
            &args.start
        },
        h,
    })
}

/// Every constraint of the file (one, or each of its `[[constraint]]` tables in turn).
fn run_file(args: &Args, out: &mut impl Write) -> Result<(), UsageError> {
    let path = args
        .constraint_file
        .as_ref()
        .expect("clap requires one of the two");
    let files = ConstraintFile::load_all(path).map_err(|e| UsageError(e.to_string()))?;
    for (k, file) in files.iter().enumerate() {
        if k > 0 && !args.json {
            writeln!(out).map_err(UsageError::stdout)?;
        }
        run_one_file(args, path, file, out)?;
    }
    Ok(())
}

fn run_one_file(
    args: &Args,
    path: &std::path::Path,
    file: &ConstraintFile,
    out: &mut impl Write,
) -> Result<(), UsageError> {
    if args.points.len() != file.arity() {
        return Err(UsageError(format!(
            "--points: {} applies to {} points, got {}",
            path.display(),
            file.arity(),
            args.points.len()
        )));
    }
    let rest_shape = rest_shape(
        args,
        file.reads_rest_shape(),
        &format!(
            "{} reads no rest shape (q0…, Dm, F, V0); its rest value is --rest",
            file.name
        ),
    )?;
    // What the element stores, from the rest shape and the default material.
    let stored = file.store(
        rest_shape,
        &tetlab_core::constraints::material::Material::default(),
    );
    let moving = moving(args, file)?;
    let evaluation = file.evaluate_moving(&args.points, moving, args.rest, &stored);
    let numeric = central_difference(&args.points, |p| {
        file.value_moving(p, moving, args.rest, &stored)
    });
    // At a kink of abs, min, max, sign or if, AD takes one side and central differences
    // average the two: say so, where.
    let scale = args.points.iter().map(|p| p.length()).fold(1.0, f64::max);
    let kinks: Vec<String> = file
        .switches_at(&args.points, args.rest, &stored)
        .into_iter()
        .filter(|(_, _, decides)| decides.abs() <= 1e-9 * scale)
        .map(|((line, column), what, _)| format!("{what} at {}:{line}:{column}", path.display()))
        .collect();
    let finite = |v: &DVec3| v.is_finite();
    let output = FileOutput {
        constraint_file: path.display().to_string(),
        name: file.name.clone(),
        value: evaluation.value,
        rest: args.rest,
        automatic: evaluation
            .automatic
            .as_ref()
            .map(|g| g.iter().map(|&v| without_negative_zero(v)).collect()),
        yours: evaluation
            .yours
            .iter()
            .map(|g| g.filter(finite).map(without_negative_zero))
            .collect(),
        given: (0..file.arity()).map(|k| file.gives_gradient(k)).collect(),
        finite_difference: numeric
            .iter()
            .map(|&v| without_negative_zero(if v.is_finite() { v } else { DVec3::ZERO }))
            .collect(),
        degenerate: evaluation.automatic.is_none(),
        kinks,
    };
    let written = if args.json {
        serde_json::to_writer(&mut *out, &output)
            .map_err(std::io::Error::from)
            .and_then(|()| writeln!(out))
    } else {
        write_file_table(&output, out)
    };
    written.map_err(UsageError::stdout)
}

fn write_file_table(o: &FileOutput, out: &mut impl Write) -> std::io::Result<()> {
    writeln!(out, "constraint  {} ({})", o.name, o.constraint_file)?;
    write_value(
        out,
        o.value,
        o.rest,
        o.degenerate.then_some(
            "yes: the gradient is undefined here (a length or normalisation of a zero vector, \
             or a division by zero)",
        ),
    )?;
    if !o.kinks.is_empty() {
        writeln!(
            out,
            "kink        yes: on the kink of {}; C has two one-sided gradients here, AD gives one \
             side's and central differences average the two",
            o.kinks.join(", ")
        )?;
        writeln!(out)?;
    }
    writeln!(
        out,
        "{:<9}{:<46}{:<46}∇C central difference",
        "particle", "∇C automatic differentiation", "∇C yours"
    )?;
    for (i, numeric) in o.finite_difference.iter().enumerate() {
        let automatic = o
            .automatic
            .as_ref()
            .map_or_else(|| "undefined".to_owned(), |g| triple(&g[i]));
        let yours = match (&o.yours[i], o.given[i]) {
            (Some(g), _) => triple(g),
            (None, true) => "undefined".to_owned(),
            (None, false) => "not given".to_owned(),
        };
        writeln!(
            out,
            "{:<9}{automatic:<46}{yours:<46}{}",
            format!("p{i}"),
            triple(numeric)
        )?;
    }
    Ok(())
}

/// The lines of C, the rest value and whether the configuration is degenerate (`Some(why)`).
fn write_value(
    out: &mut impl Write,
    value: f64,
    rest: f64,
    degenerate: Option<&str>,
) -> std::io::Result<()> {
    if value.is_finite() {
        writeln!(out, "C           {value}")?;
    } else {
        writeln!(out, "C           undefined here")?;
    }
    writeln!(out, "rest        {rest}")?;
    writeln!(out, "degenerate  {}", degenerate.unwrap_or("no"))?;
    writeln!(out)
}
