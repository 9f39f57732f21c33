//! The arrows front ends draw: ∇C per family (and a file's gradient where it disagrees with
//! the one in use), Δx of the next projection, Δp of the last substep, and which tets' arrows
//! are drawn.

use super::*;

/// The colour of the correction arrows (Δp of the last substep): magenta.
pub const CORRECTION: Rgba = [200, 50, 200, 255];

/// What an arrow shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// ∇ₚC of one constraint of a family, as the solver projects it.
    Gradient(Family),
    /// For a family read from a constraint file that gives its own gradient: the gradient the
    /// solver does not use (yours, or AD's when the file asks for its own to be used), drawn only
    /// at particles where it differs from the one in use.
    Disagreeing(Family),
    /// Δp, the correction the last substep's projections made (see
    /// [`Simulation::corrections`]).
    Correction,
    /// One eigenmode of the selected tet's energy Hessian: its displacement at each corner
    /// ([`crate::energy::modes`]).
    Mode,
}

/// The colour of the mode arrows and of the tet moved along a mode: teal.
pub const MODE: Rgba = [20, 170, 150, 255];

impl Quantity {
    /// The arrow colour: [`family_colour`] for gradients, the same lightened halfway to white
    /// for the disagreeing one, [`CORRECTION`] for corrections.
    pub fn colour(self, families: &Families) -> Rgba {
        match self {
            Quantity::Gradient(family) => family_colour(families, family),
            Quantity::Disagreeing(family) => {
                let [r, g, b, a] = family_colour(families, family);
                let light = |c: u8| c + (255 - c) / 2;
                [light(r), light(g), light(b), a]
            }
            Quantity::Correction => CORRECTION,
            Quantity::Mode => MODE,
        }
    }

    /// What it is, for legends: "grad C: heights", "grad C: my-height, yours, where it differs",
    /// "dp".
    pub fn label(self, families: &Families) -> String {
        match self {
            Quantity::Gradient(family) => match families.file(family) {
                Some(file) if file.use_gradient => {
                    format!("grad C: {} (yours)", families.name(family))
                }
                Some(_) => format!("grad C: {} (AD)", families.name(family)),
                None => format!("grad C: {}", families.row(family).label),
            },
            Quantity::Disagreeing(family) => {
                let other = Quantity::disagreeing_name(families, family);
                format!(
                    "grad C: {}, {other}, where it differs",
                    families.name(family)
                )
            }
            Quantity::Correction => "dp".to_owned(),
            Quantity::Mode => "mode".to_owned(),
        }
    }
}

impl Quantity {
    /// Which gradient the [`Quantity::Disagreeing`] arrows of `family` show: "yours", or "AD"
    /// when the file asks the solver to use its own (`use_gradient`).
    pub fn disagreeing_name(families: &Families, family: Family) -> &'static str {
        match families.file(family) {
            Some(file) if file.use_gradient => "AD",
            _ => "yours",
        }
    }

    /// The gradient quantities a family's arrows can show: its ∇C, and for a constraint file
    /// that gives its own gradient, the one not in use ([`Quantity::Disagreeing`]).
    pub fn of_family(
        families: &Families,
        family: Family,
    ) -> impl Iterator<Item = Quantity> + use<> {
        let gives = families
            .file(family)
            .is_some_and(|file| (0..file.arity()).any(|k| file.gives_gradient(k)));
        [Quantity::Gradient(family)]
            .into_iter()
            .chain(gives.then_some(Quantity::Disagreeing(family)))
    }
}

/// The relative difference (to the largest gradient of the constraint) from which a
/// [`Quantity::Disagreeing`] arrow is drawn.
pub const DISAGREEMENT: f64 = 1e-6;

/// The [`Quantity::Disagreeing`] arrows of one projection of a file family: at each particle the
/// file gives a gradient for, the gradient the solver does not use, where it differs from the
/// one it uses by more than [`DISAGREEMENT`]. Appends to `out`, unscaled.
fn disagreeing_arrows(
    families: &Families,
    positions: &[DVec3],
    projection: &Projection,
    out: &mut Vec<Arrow>,
) {
    let Some(file) = families.file(projection.family) else {
        return;
    };
    if projection.degenerate || !(0..projection.len).any(|k| file.gives_gradient(k)) {
        return;
    }
    let points: Vec<DVec3> = projection.particles[..projection.len]
        .iter()
        .map(|&i| positions[i as usize])
        .collect();
    let other = file.gradients_of(
        &points,
        projection.rest,
        projection.stored(),
        !file.use_gradient,
    );
    let used = &projection.gradients[..projection.len];
    let scale = used.iter().map(|g| g.length()).fold(0.0, f64::max);
    for (k, (&particle, &gradient)) in projection.particles().iter().zip(&other).enumerate() {
        let differs = (gradient - used[k]).length() > DISAGREEMENT * scale;
        if file.gives_gradient(k) && differs {
            out.push(Arrow {
                quantity: Quantity::Disagreeing(projection.family),
                particle,
                origin: positions[particle as usize],
                value: gradient,
                vector: DVec3::ZERO,
            });
        }
    }
}

/// One arrow at one particle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arrow {
    /// What it shows.
    pub quantity: Quantity,
    /// The particle the arrow starts at.
    pub particle: u32,
    /// Where it starts: the particle's position.
    pub origin: DVec3,
    /// The quantity itself (∇ₚC, or Δp in metres), unscaled.
    pub value: DVec3,
    /// What to draw from `origin`: `value` times the arrow set's scale.
    pub vector: DVec3,
}

/// The longest gradient arrow of a family on a tet at gain 1, as a fraction of the tet's mean edge
/// length (`tet_size`).
pub const GRADIENT_ARROW_LENGTH: f64 = 0.4;

/// The gradient arrows of `family` on tet `tet`: ∇ₚC at each particle p of each of the family's
/// constraints on that tet — 6 edges × 2 particles, 4 heights × 4 particles, or 1 volume × 4
/// particles — and, for a constraint file that gives its own gradient, the one not in use where
/// it differs ([`Quantity::Disagreeing`]). Degenerate constraints have no arrows. Gradients of different families have
/// different units (1, 1 and m²), so each family is scaled on its own: its longest arrow on the tet
/// is drawn `gain` × [`GRADIENT_ARROW_LENGTH`] × the tet's size long. Appends to `out`.
pub(crate) fn tet_gradient_arrows(
    simulation: &Simulation,
    tet: usize,
    family: Family,
    gain: f64,
    out: &mut Vec<Arrow>,
) {
    let positions = simulation.positions();
    let first = out.len();
    for c in simulation.tet_constraints(tet, family) {
        let projection = simulation.projection(family, c);
        if projection.degenerate {
            continue;
        }
        for (&particle, &gradient) in projection.particles().iter().zip(&projection.gradients) {
            out.push(Arrow {
                quantity: Quantity::Gradient(family),
                particle,
                origin: positions[particle as usize],
                value: gradient,
                vector: DVec3::ZERO,
            });
        }
        disagreeing_arrows(simulation.families(), positions, &projection, out);
    }
    let length = gain * GRADIENT_ARROW_LENGTH * tet_size(positions, &simulation.tets()[tet]);
    scale_to_longest(&mut out[first..], length);
}

/// Sets each arrow's vector to its value times one factor, chosen so the longest is `length`.
fn scale_to_longest(arrows: &mut [Arrow], length: f64) {
    let longest = arrows.iter().map(|a| a.value.length()).fold(0.0, f64::max);
    let scale = if longest > 0.0 { length / longest } else { 0.0 };
    for arrow in arrows {
        arrow.vector = arrow.value * scale;
    }
}

/// The arrows of one projection (the one step-by-step mode is about to make): ∇ₚC at each of its
/// particles, the longest drawn `gain` × [`GRADIENT_ARROW_LENGTH`] × the mean distance between
/// them (for one particle, its element's size, [`Projection::size`]), and the Δx it will apply, `correction_gain` times its true length. Appends to `out`.
pub fn projection_arrows(
    families: &Families,
    positions: &[DVec3],
    projection: &Projection,
    gain: f64,
    correction_gain: f64,
    out: &mut Vec<Arrow>,
) {
    let particles = projection.particles();
    let point = |k: usize| positions[particles[k] as usize];
    let mut size = 0.0;
    let mut pairs = 0;
    for a in 0..particles.len() {
        for b in a + 1..particles.len() {
            size += point(a).distance(point(b));
            pairs += 1;
        }
    }
    // A particle alone is drawn to its element's size (the longest rest edge at it).
    let size = match pairs {
        0 => projection.size,
        _ => size / pairs as f64,
    };
    let first = out.len();
    if !projection.degenerate {
        for (&particle, &gradient) in particles.iter().zip(&projection.gradients) {
            out.push(Arrow {
                quantity: Quantity::Gradient(projection.family),
                particle,
                origin: positions[particle as usize],
                value: gradient,
                vector: DVec3::ZERO,
            });
        }
        disagreeing_arrows(families, positions, projection, out);
    }
    scale_to_longest(&mut out[first..], gain * GRADIENT_ARROW_LENGTH * size);
    for (&particle, &delta) in particles.iter().zip(&projection.delta_x) {
        out.extend(correction_arrow(
            positions,
            particle,
            delta,
            correction_gain,
        ));
    }
}

/// The arrow of a displacement `delta` at `particle`, `gain` times its true length; none for a
/// zero displacement.
fn correction_arrow(positions: &[DVec3], particle: u32, delta: DVec3, gain: f64) -> Option<Arrow> {
    (delta != DVec3::ZERO).then(|| Arrow {
        quantity: Quantity::Correction,
        particle,
        origin: positions[particle as usize],
        value: delta,
        vector: delta * gain,
    })
}

/// The correction arrows of `particles`: Δp of the last substep at each, drawn `gain` times its
/// true length (Δp is a displacement, in the scene's units). Zero corrections have no arrow.
/// Appends to `out`.
pub(crate) fn correction_arrows(
    simulation: &Simulation,
    particles: impl IntoIterator<Item = u32>,
    gain: f64,
    out: &mut Vec<Arrow>,
) {
    let positions = simulation.positions();
    let corrections = simulation.corrections();
    for particle in particles {
        let delta = corrections[particle as usize];
        out.extend(correction_arrow(positions, particle, delta, gain));
    }
}

/// The arrows of an eigenmode of tet `corners` (its unit eigenvector `vector`, one displacement
/// per corner): the longest drawn `gain` × [`GRADIENT_ARROW_LENGTH`] × the tet's size long, from
/// the corners at `positions`. A corner that does not move has no arrow. Appends to `out`.
pub fn mode_arrows(
    positions: &[DVec3],
    corners: [u32; 4],
    vector: &[DVec3; 4],
    gain: f64,
    out: &mut Vec<Arrow>,
) {
    let first = out.len();
    for (&particle, &value) in corners.iter().zip(vector) {
        if value != DVec3::ZERO {
            out.push(Arrow {
                quantity: Quantity::Mode,
                particle,
                origin: positions[particle as usize],
                value,
                vector: DVec3::ZERO,
            });
        }
    }
    let length = gain * GRADIENT_ARROW_LENGTH * tet_size(positions, &corners);
    scale_to_longest(&mut out[first..], length);
}

/// The corners of tet `corners` moved along a mode: each at its position plus `offset` × the
/// tet's size × its share of the unit eigenvector `vector` (for display only: an eigenvector says
/// a direction, and `offset` how far to go along it, in tet sizes).
pub fn along_mode(
    positions: &[DVec3],
    corners: [u32; 4],
    vector: &[DVec3; 4],
    offset: f64,
) -> [DVec3; 4] {
    let size = tet_size(positions, &corners);
    std::array::from_fn(|k| positions[corners[k] as usize] + vector[k] * (offset * size))
}

/// Whose arrows are shown: no tet's, one tet's (the selected one), or every tet's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArrowSelection {
    /// No arrows.
    None,
    /// The arrows of one tet: ∇C of each active family's constraints on it, Δp at its corners.
    Tet(usize),
    /// The arrows of every tet, and Δp at every particle.
    AllTets,
}

/// The arrows of `selection`, as the workbench draws them and the recorder logs them: the
/// gradient arrows of every active family (`tet_gradient_arrows`, scaled by
/// `gradient_gain`; none when it is `None`), then Δp of the last substep at the particles
/// (`correction_arrows`, `correction_gain` times its length; none when it is `None`).
/// Appends to `out`.
pub fn selected_arrows(
    simulation: &Simulation,
    selection: ArrowSelection,
    gradient_gain: Option<f64>,
    correction_gain: Option<f64>,
    out: &mut Vec<Arrow>,
) {
    let tets = match selection {
        ArrowSelection::None => return,
        ArrowSelection::Tet(tet) => tet..tet + 1,
        ArrowSelection::AllTets => 0..simulation.tets().len(),
    };
    if let Some(gain) = gradient_gain {
        let active = *simulation.active();
        for family in active.families() {
            for tet in tets.clone() {
                tet_gradient_arrows(simulation, tet, family, gain, out);
            }
        }
    }
    if let Some(gain) = correction_gain {
        match selection {
            ArrowSelection::Tet(tet) => {
                correction_arrows(simulation, simulation.tets()[tet], gain, out);
            }
            _ => {
                let particles = 0..simulation.positions().len() as u32;
                correction_arrows(simulation, particles, gain, out);
            }
        }
    }
}
