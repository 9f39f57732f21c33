//! `tetlab gradient`: C and ∇C of one constraint at given points, next to central differences.

use super::{UsageError, args};
use glam::DVec3;
use serde::Serialize;
use std::io::Write;
use tetlab_core::constraints::Family;
use tetlab_core::verify::{analytic_and_numeric, max_abs_error};

/// Options of `tetlab gradient`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The constraint family: edges (2 points: distance), height (4: height of p1 above the
    /// plane of p0, p2, p3) or volume (4: signed volume). `distance` and `plane` are aliases.
    #[arg(long, value_parser = Family::parse)]
    constraint: Family,
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
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
}

/// What `--json` prints.
#[derive(Debug, Serialize)]
struct Output {
    constraint: &'static str,
    value: f64,
    rest: f64,
    gradients: Vec<[f64; 3]>,
    finite_difference: Vec<[f64; 3]>,
    max_abs_error: f64,
    degenerate: bool,
}

/// Evaluates the constraint and writes the result to `out`.
pub fn run(args: &Args, out: &mut impl Write) -> Result<(), UsageError> {
    let family = args.constraint;
    if args.points.len() != family.arity() {
        return Err(UsageError(format!(
            "--points: the {} constraint takes {} points, got {}",
            family.name(),
            family.arity(),
            args.points.len()
        )));
    }
    let rest_shape = if args.rest_shape.is_empty() {
        &args.points
    } else if !family.uses_rest_shape() {
        return Err(UsageError(format!(
            "--rest-shape: the {} constraint does not read a rest shape",
            family.name()
        )));
    } else if args.rest_shape.len() != args.points.len() {
        return Err(UsageError(format!(
            "--rest-shape: {} points, as many as --points ({})",
            args.rest_shape.len(),
            args.points.len()
        )));
    } else {
        &args.rest_shape
    };
    let evaluation = family.evaluate(&args.points, args.rest, rest_shape);
    let (analytic, numeric) = analytic_and_numeric(family, &args.points, args.rest, rest_shape);
    let output = Output {
        constraint: family.name(),
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
        write_table(family, &output, out)
    };
    written.map_err(UsageError::stdout)
}

/// The components with −0 written as 0 (x + 0 is +0 for x = −0 and x otherwise).
fn without_negative_zero(v: DVec3) -> [f64; 3] {
    (v + DVec3::ZERO).to_array()
}

fn write_table(family: Family, o: &Output, out: &mut impl Write) -> std::io::Result<()> {
    // The formula's lines up to C itself; its gradient lines are what the table below shows.
    let definition = family
        .formula()
        .iter()
        .take_while(|line| !line.starts_with('∇'));
    writeln!(out, "constraint  {}", o.constraint)?;
    for line in definition {
        writeln!(out, "            {line}")?;
    }
    writeln!(out, "C           {}", o.value)?;
    writeln!(out, "rest        {}", o.rest)?;
    writeln!(
        out,
        "degenerate  {}",
        if o.degenerate {
            "yes: ∇C is undefined here and reported as zero"
        } else {
            "no"
        }
    )?;
    writeln!(out)?;
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
