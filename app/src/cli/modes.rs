//! `tetlab modes`: the energy of some families on one tet, its Hessian by automatic
//! differentiation with the figures that check it, and the Hessian's eigenmodes: eigenvalues with
//! their classes, projected and mass-weighted, and each eigenvector. For the neo-Hookean pair,
//! the analytic eigensystem in F-space beside the numeric one.

use super::simulation_args::FamilyArgs;
use super::{UsageError, args};
use glam::DVec3;
use serde::Serialize;
use std::io::Write;
use tetlab_core::constraints::Families;
use tetlab_core::energy::element::{Compliance, ElementEnergy};
use tetlab_core::energy::hessian::{
    Convergence, asymmetry, convergence, coordinates, hessian, second_order,
};
use tetlab_core::energy::modes::Modes;
use tetlab_core::energy::neohookean::{FSpace, Parameters};
use tetlab_core::input::limits::Number;
use tetlab_core::simulation::{DENSITY, Settings};

/// The rest tet when none is given: the unit right tet.
pub const UNIT_TET: [DVec3; 4] = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];

/// Options of `tetlab modes`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The families, their compliances and material.
    #[command(flatten)]
    families: FamilyArgs,
    /// The tet's four corners, each X,Y,Z [default: the rest shape].
    #[arg(long, value_name = "X,Y,Z", num_args = 1.., value_parser = args::point)]
    points: Vec<DVec3>,
    /// The tet at rest, four corners [default: 0,0,0 1,0,0 0,1,0 0,0,1].
    #[arg(long, value_name = "X,Y,Z", num_args = 1.., value_parser = args::point)]
    rest_shape: Vec<DVec3>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
}

/// One mode, as `--json` writes it.
#[derive(Debug, Serialize)]
struct ModeOutput {
    eigenvalue: f64,
    /// max(λ, 0): the eigenvalue of the projected (positive semi-definite) Hessian.
    projected: f64,
    /// ω² = λ / m of H v = ω² M v, in 1/s².
    omega_squared: f64,
    zero: bool,
    class: &'static str,
    /// translation, rotation, twist, flip, scale.
    shares: [f64; 5],
    /// The unit eigenvector: each corner's displacement.
    vector: [[f64; 3]; 4],
}

/// The analytic F-space system of the neo-Hookean pair, as `--json` writes it.
#[derive(Debug, Serialize)]
struct FSpaceOutput {
    singular_values: [f64; 3],
    /// The nine analytic eigenvalues of ∂²Ψ/∂F², with their classes (twist, flip, scale).
    analytic: Vec<(f64, &'static str)>,
    /// The same, from a numeric decomposition of ∂²Ψ/∂F² by AD, sorted.
    numeric: Vec<f64>,
    /// max |analytic − numeric| / max |λ|.
    relative_difference: f64,
    /// The 12 × 12 eigenvalues after clamping the F-space ones at zero (a different matrix from
    /// clamping the 12 × 12's), sorted.
    projected_in_f_space: Vec<f64>,
}

/// What `--json` prints.
#[derive(Debug, Serialize)]
struct Output {
    constraints: String,
    /// The active families with no energy on one tet (a damper, a pin), left out.
    left_out: Vec<String>,
    /// Per family: its α and whether it is rigid, taken with α = 1.
    compliances: Vec<(String, f64, bool)>,
    energy: f64,
    points: [[f64; 3]; 4],
    rest_shape: [[f64; 3]; 4],
    /// The lumped mass of each corner, density × |V₀| / 4.
    corner_mass: f64,
    /// max |H − Hᵀ| / max |H|.
    asymmetry: f64,
    /// max |H − H₂| / max |H|, H₂ by second-order dual numbers; `None` where H₂ is not finite
    /// (a constraint is degenerate there: its second derivatives do not exist, and AD's H takes
    /// its gradient as zero).
    against_second_order: Option<f64>,
    /// Central differences of ∇E: (step relative to the tet's size, error relative to max |H|).
    convergence: Vec<(f64, f64)>,
    convergence_slope: f64,
    convergence_decades: f64,
    zero_count: usize,
    negative_count: usize,
    modes: Vec<ModeOutput>,
    f_space: Option<FSpaceOutput>,
}

/// Computes and prints the modes.
pub fn run(args: &Args, out: &mut impl Write) -> Result<(), UsageError> {
    let (settings, families) = args.families.apply(Settings::default())?;
    let rest = corners(&args.rest_shape, "--rest-shape", UNIT_TET)?;
    let volume = tetlab_core::constraints::volume::signed_volume(&rest);
    if !volume.is_finite() {
        return Err(UsageError(format!(
            "--rest-shape: the rest tet's volume is not finite ({volume:e}): its coordinates are \
             too large for f64"
        )));
    }
    let flat = volume
        .abs()
        .partial_cmp(&(1e-12 * rest_size(&rest).powi(3)));
    if flat != Some(std::cmp::Ordering::Greater) {
        return Err(UsageError(format!(
            "--rest-shape: the rest tet has no volume ({volume:e}): its corners are coplanar"
        )));
    }
    let x = corners(&args.points, "--points", rest)?;
    let energy = ElementEnergy::new(&families, &settings.active, &settings, rest)
        .map_err(|e| UsageError(format!("--constraints: {e}")))?;
    let at = coordinates(&x);
    let h = hessian(&energy, &at);
    if !h.iter().all(|v| v.is_finite()) {
        return Err(UsageError(
            "--points: the Hessian is not finite there (coincident corners, or numbers too \
             large for f64)"
                .into(),
        ));
    }
    let independent = second_order(&energy, &at);
    let check = convergence(&energy, &at, &h);
    let modes = Modes::of_matrix(h, &x, &rest, energy.corner_mass());
    let f_space = neohookean_pair(&families, &settings).then(|| f_space(&settings, &rest, &x));
    let in_energy = families.per_family(|f| energy.compliances.iter().any(|&(g, _)| g == f));
    let output = Output {
        constraints: families.describe(&in_energy),
        left_out: families
            .all()
            .filter(|&f| settings.active[f] && !in_energy[f])
            .map(|f| families.name(f).to_owned())
            .collect(),
        compliances: energy
            .compliances
            .iter()
            .map(|&(f, c)| {
                (
                    families.name(f).to_owned(),
                    c.alpha(),
                    c == Compliance::Rigid,
                )
            })
            .collect(),
        energy: energy.energy(&x.map(|p| p.to_array())),
        points: x.map(|p| p.to_array()),
        rest_shape: rest.map(|p| p.to_array()),
        corner_mass: energy.corner_mass(),
        asymmetry: asymmetry(&h),
        against_second_order: independent
            .iter()
            .all(|v| v.is_finite())
            .then(|| (h - independent).amax() / h.amax().max(f64::MIN_POSITIVE)),
        convergence: check.steps.clone(),
        convergence_slope: check.slope,
        convergence_decades: check.decades,
        zero_count: modes.zero_count(),
        negative_count: modes.negative_count(),
        modes: modes
            .modes()
            .iter()
            .enumerate()
            .map(|(k, m)| ModeOutput {
                eigenvalue: m.value,
                projected: m.value.max(0.0),
                omega_squared: modes.omega_squared(k),
                zero: modes.is_zero(k),
                class: m.class.name(),
                shares: m.shares,
                vector: m.vector.map(|v| v.to_array()),
            })
            .collect(),
        f_space,
    };
    let written = if args.json {
        serde_json::to_writer(&mut *out, &output)
            .map_err(std::io::Error::from)
            .and_then(|()| writeln!(out))
    } else {
        write_table(&output, &check, out)
    };
    written.map_err(UsageError::stdout)
}

/// Four corners from `points`, or `default` when none are given.
fn corners(points: &[DVec3], option: &str, default: [DVec3; 4]) -> Result<[DVec3; 4], UsageError> {
    match points.len() {
        0 => Ok(default),
        4 => Ok([points[0], points[1], points[2], points[3]]),
        n => Err(UsageError(format!(
            "{option}: a tet has 4 corners, got {n}"
        ))),
    }
}

/// The largest distance between two corners.
fn rest_size(x: &[DVec3; 4]) -> f64 {
    let mut size: f64 = 0.0;
    for a in x {
        for b in x {
            size = size.max(a.distance(*b));
        }
    }
    size
}

/// Whether the active families are exactly the built-in neo-Hookean pair, whose energy has the
/// analytic F-space system.
fn neohookean_pair(families: &Families, settings: &Settings) -> bool {
    let pair = families.parse_list("neohookean").expect("a built-in group");
    families.all().all(|f| settings.active[f] == pair[f])
}

/// The analytic and numeric F-space systems at the deformation of `x` from `rest`.
fn f_space(settings: &Settings, rest: &[DVec3; 4], x: &[DVec3; 4]) -> FSpaceOutput {
    let f = FSpace::of(rest, x, &Parameters::of(&settings.material));
    FSpaceOutput {
        singular_values: f.singular_values,
        analytic: f
            .analytic
            .iter()
            .map(|m| (m.value, m.class.name()))
            .collect(),
        numeric: f.numeric,
        relative_difference: f.relative_difference,
        projected_in_f_space: f.projected_in_f_space,
    }
}

fn write_table(o: &Output, check: &Convergence, out: &mut impl Write) -> std::io::Result<()> {
    writeln!(
        out,
        "energy      E = Σ ½ C² / α of {} on one tet",
        o.constraints
    )?;
    for (name, alpha, rigid) in &o.compliances {
        let note = if *rigid {
            " (rigid: taken with α = 1; compare its eigenvalues' signs, not their sizes)"
        } else {
            ""
        };
        writeln!(out, "            {name}: α = {}{note}", alpha.show())?;
    }
    if !o.left_out.is_empty() {
        writeln!(
            out,
            "            left out: {} (no energy on one tet: a damper's is of the motion, a \
             family on single particles ties the body to the world)",
            o.left_out.join(", ")
        )?;
    }
    writeln!(out, "            E = {} at these points", o.energy.show())?;
    let against = match o.against_second_order {
        Some(e) => format!("{e:.1e}"),
        None => "undefined (a constraint is degenerate here: coincident corners or a flat \
                 face; its gradient is taken as 0)"
            .to_owned(),
    };
    writeln!(
        out,
        "hessian     12 × 12 by AD (forward mode over ∇C); symmetric to {:.1e}; against \
         second-order dual numbers {against}",
        o.asymmetry
    )?;
    let steps: Vec<String> = check
        .steps
        .iter()
        .map(|(s, e)| format!("{:.0e}: {e:.1e}", s))
        .collect();
    writeln!(
        out,
        "check       central differences of ∇E: error falls as ε^{:.2} over {:.0} decades, \
         to {:.1e}",
        check.slope, check.decades, check.floor
    )?;
    writeln!(out, "            (step: error) {}", steps.join(", "))?;
    writeln!(
        out,
        "mass        {:.4e} kg per corner (density {DENSITY} kg/m³ × |V₀| / 4); H v = ω² M v has \
         H's modes, ω² = λ / m",
        o.corner_mass
    )?;
    writeln!(
        out,
        "modes       {} zero (|λ| ≤ 1e-10 max |λ|), {} negative",
        o.zero_count, o.negative_count
    )?;
    writeln!(out)?;
    writeln!(
        out,
        "{:>3}  {:>12}  {:>12}  {:>12}  {:<12} shares: translation rotation twist flip scale",
        "#", "λ", "projected", "ω² (1/s²)", "class",
    )?;
    for (k, m) in o.modes.iter().enumerate() {
        let note = if m.zero {
            "  zero"
        } else if m.eigenvalue < 0.0 {
            "  negative"
        } else {
            ""
        };
        let shares: Vec<String> = m.shares.iter().map(|s| format!("{s:.2}")).collect();
        writeln!(
            out,
            "{k:>3}  {:>12.4e}  {:>12.4e}  {:>12.4e}  {:<12} {}{note}",
            m.eigenvalue,
            m.projected,
            m.omega_squared,
            m.class,
            shares.join(" ")
        )?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "eigenvectors (each corner's displacement, unit length in all)"
    )?;
    for (k, m) in o.modes.iter().enumerate() {
        let corners: Vec<String> = m
            .vector
            .iter()
            .map(|v| format!("({:>7.4},{:>7.4},{:>7.4})", v[0], v[1], v[2]))
            .collect();
        writeln!(out, "{k:>3}  {}", corners.join(" "))?;
    }
    if let Some(f) = &o.f_space {
        writeln!(out)?;
        writeln!(
            out,
            "F-space     Ψ = μ/2 ‖F‖² + λ/2 (det F − γ)²; F's signed singular values ({:.4}, \
             {:.4}, {:.4})",
            f.singular_values[0], f.singular_values[1], f.singular_values[2]
        )?;
        let analytic: Vec<String> = f
            .analytic
            .iter()
            .map(|(v, class)| format!("{class} {v:.6e}"))
            .collect();
        writeln!(out, "analytic    {}", analytic.join(", "))?;
        let numeric: Vec<String> = f.numeric.iter().map(|v| format!("{v:.6e}")).collect();
        writeln!(
            out,
            "numeric     {} (AD's ∂²Ψ/∂F², decomposed; {:.1e} from the analytic)",
            numeric.join(", "),
            f.relative_difference
        )?;
        let projected: Vec<String> = f
            .projected_in_f_space
            .iter()
            .map(|v| format!("{v:.4e}"))
            .collect();
        writeln!(
            out,
            "clamped in F-space, then |V₀| Bᵀ H_F B: {} (the 12 × 12 clamp above is another \
             matrix)",
            projected.join(", ")
        )?;
    }
    Ok(())
}
