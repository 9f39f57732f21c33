//! What a lesson step does: its actions, as a lesson file writes them and as they act on a
//! simulation.

use super::*;

/// Something a lesson step does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Back to the rest shape.
    Reset,
    /// A perturbation of the whole body (mirror, flatten, scramble) or of tet 0 (invert).
    Perturb(Perturbation),
    /// Invert tet K by reflecting its first corner through the opposite face.
    InvertTet(usize),
    /// Select tet K (its arrows are shown).
    Select(usize),
    /// Set the active constraint families.
    Constraints(PerFamily<bool>),
    /// XPBD or PBD.
    Solver(Method),
    /// XPBD compliance of a family.
    Compliance(Family, f64),
    /// PBD stiffness of a family.
    Stiffness(Family, f64),
    /// Substeps per frame.
    Substeps(u32),
    /// Iterations per substep.
    Iterations(u32),
    /// Gravity (0 also turns the ground off).
    Gravity(f64),
    /// Show a second simulation beside the first with these constraint families (`None`: stop).
    Compare(Option<PerFamily<bool>>),
}

impl Action {
    pub(super) fn parse(families: &Families, text: &str) -> Result<Action, String> {
        let (name, argument) = match text.split_once(':') {
            Some((name, argument)) => (name.trim(), Some(argument.trim())),
            None => (text.trim(), None),
        };
        let need =
            |what: &str| argument.ok_or_else(|| format!("'{text}' needs a value: {name}:{what}"));
        let whole = |what: &str| -> Result<u64, String> {
            let argument = need(what)?;
            argument
                .parse()
                .map_err(|_| format!("'{argument}' is not a whole number in '{text}'"))
        };
        let family_value = |what: &str, bounds: &Bounds<f64>| -> Result<(Family, f64), String> {
            let argument = need(what)?;
            crate::simulation::settings::family_value(families, argument, bounds)
                .map_err(|e| format!("{e} in '{text}'"))
        };
        let setting = |what: &str, bounds: &Bounds<u32>| -> Result<u32, String> {
            bounds
                .parse(need(what)?)
                .map_err(|e| format!("{e} in '{text}'"))
        };
        let action = match name {
            "reset" => match argument {
                None => Action::Reset,
                Some(_) => return Err(format!("'{text}': reset takes no value")),
            },
            "invert" => match argument {
                None => Action::Perturb(Perturbation::Invert),
                Some(_) => Action::InvertTet(whole("K")? as usize),
            },
            "mirror" | "flatten" | "scramble" => Action::Perturb(Perturbation::parse(text.trim())?),
            "select" => Action::Select(whole("K")? as usize),
            "constraints" => Action::Constraints(families.parse_list(need("LIST")?)?),
            "solver" => Action::Solver(Method::parse(need("xpbd|pbd")?)?),
            "compliance" => {
                let (family, alpha) = family_value("FAMILY=α", &limits::COMPLIANCE)?;
                Action::Compliance(family, alpha)
            }
            "stiffness" => {
                let (family, k) = family_value("FAMILY=k", &limits::STIFFNESS)?;
                Action::Stiffness(family, k)
            }
            "substeps" => Action::Substeps(setting("N", &limits::SUBSTEPS)?),
            "iterations" => Action::Iterations(setting("N", &limits::ITERATIONS)?),
            "gravity" => Action::Gravity(
                limits::GRAVITY
                    .parse(need("G")?)
                    .map_err(|e| format!("{e} in '{text}'"))?,
            ),
            "compare" => match need("LIST|off")? {
                "off" => Action::Compare(None),
                list => Action::Compare(Some(families.parse_list(list)?)),
            },
            _ => {
                return Err(format!(
                    "'{text}' is not an action: expected reset, invert, invert:K, mirror, \
                     flatten, scramble:SEED, select:K, constraints:LIST, solver:NAME, \
                     compliance:FAMILY=α, stiffness:FAMILY=k, substeps:N, iterations:N, \
                     gravity:G or compare:LIST|off"
                ));
            }
        };
        Ok(action)
    }

    /// Applies the action to `simulation`. [`Action::Select`] sets `selected_tet`;
    /// [`Action::Compare`] is for the front end and changes nothing here.
    pub fn apply(self, simulation: &mut Simulation, selected_tet: &mut usize) {
        let mut settings = *simulation.settings();
        match self {
            Action::Reset => simulation.reset(),
            Action::Perturb(perturbation) => simulation.perturb(perturbation),
            Action::InvertTet(tet) => {
                let corners = simulation.tets()[tet];
                let mut positions = simulation.positions().to_vec();
                reflect_through_opposite_face(&mut positions, &corners, 0);
                simulation.place(corners[0] as usize, positions[corners[0] as usize]);
            }
            Action::Select(tet) => *selected_tet = tet,
            Action::Constraints(active) => settings.active = active,
            Action::Solver(method) => settings.method = method,
            Action::Compliance(family, alpha) => settings.compliance.set(family, alpha),
            Action::Stiffness(family, k) => settings.stiffness.set(family, k),
            Action::Substeps(n) => settings.substeps = n,
            Action::Iterations(n) => settings.iterations = n,
            Action::Gravity(g) => settings.set_gravity(g),
            Action::Compare(_) => {}
        }
        simulation.set_settings(settings);
    }

    /// Whether a comparison shown beside the lesson's simulation gets this action too: every
    /// action but [`Action::Constraints`] (each side keeps its own families) and
    /// [`Action::Compare`] itself.
    pub fn applies_to_comparison(self) -> bool {
        !matches!(self, Action::Constraints(_) | Action::Compare(_))
    }

    /// The tet this action refers to, if any (to check it against the scene).
    pub(super) fn tet(self) -> Option<usize> {
        match self {
            Action::InvertTet(tet) | Action::Select(tet) => Some(tet),
            _ => None,
        }
    }
}
