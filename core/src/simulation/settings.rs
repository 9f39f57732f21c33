//! How a simulation runs, as the user asked it: [`Settings`] (their ranges are
//! [`crate::input::limits`], checked by [`Settings::check`]; the ground is on when gravity is not
//! zero, [`Settings::set_gravity`]), the engine among them ([`EngineChoice`]). The command
//! line, lessons, `tetlab bench` and the workbench all build their settings here; what follows
//! from them for a table of families (the material's compliances, the rules) is
//! [`super::Resolved`].

use super::engine_choice::EngineChoice;
use crate::constraints::material::Material;
use crate::constraints::{Families, Family, PerFamily};
use crate::input::limits::{self, Bounds};

/// How far one projection may move a particle by default ([`crate::simulation::Settings::reach`]),
/// in longest rest edges of its element (the constraint's particles at rest: an edge's length,
/// a tet's longest edge): 100. A step
/// max |Δxᵢ| = wᵢ|∇ᵢC||Δλ| beyond it is skipped and counted ([`super::projection::Skipped::too_long`]),
/// unless it leaves its element no larger than it is: a correction that pulls a stretched
/// element together is made however long ([`super::projection::correct_in_reach`]).
///
/// A projection moves a particle by about |C| / |∇C|, which grows without bound where ∇C
/// vanishes and C does not: the dihedral angle's cosine at a folded or flattened hinge
/// (cos θ = ±1, where d cos θ / dθ = 0) passes `check-gradients` and yet, with the rule off,
/// throws a flattened bunny's centre of mass 1.2 × 10⁸ m in two frames (`tetlab run --scene
/// ../shared/meshes/bunny.node --perturb flatten --constraints edges --constraint-file
/// assets/constraints/dihedral-cosine.toml --frames 2 --reach 1e9`); with it, 12 m: still a
/// constraint that should not be used there, but one whose run stays finite and says so. A built-in family's step is its violation (an edge's |ℓ − d|, a
/// height's |h − d|) or a tet's size (a volume's |V − V₀| over its face areas), up to some tens
/// of rest edges in a body launched apart, and unbounded only for a tet collapsed to a point.
/// 100 rest edges is past any step of a built-in family on a body that holds together, and
/// short of the steps a singular ∇C takes. `scripts/reach-battery.sh` runs the built-in families
/// on every shipped scene and perturbation, settled and launched, at reach 10, 30, 100 and 10⁹,
/// and prints in how many runs the rule skips a step and in how many it changes the outcome.
pub const DEFAULT_REACH: f64 = 100.0;

/// XPBD or PBD.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Method {
    /// Extended PBD: compliance per family, λ accumulated within a substep.
    Xpbd,
    /// Müller et al. 2006: stiffness per family, corrected for the iteration count.
    Pbd,
}

impl Method {
    /// `xpbd` or `pbd`.
    pub fn parse(text: &str) -> Result<Method, String> {
        match text.trim() {
            "xpbd" => Ok(Method::Xpbd),
            "pbd" => Ok(Method::Pbd),
            other => Err(format!("'{other}' is not a solver: expected xpbd or pbd")),
        }
    }

    /// The name [`Method::parse`] reads.
    pub fn name(self) -> &'static str {
        match self {
            Method::Xpbd => "xpbd",
            Method::Pbd => "pbd",
        }
    }
}

/// How the simulation runs. Every field may change between steps.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Settings {
    /// XPBD or PBD.
    pub method: Method,
    /// Which families are projected.
    pub active: PerFamily<bool>,
    /// XPBD compliance α per family: the inverse of stiffness, 0 is rigid, larger is softer. A
    /// family whose compliance the material gives takes the material's instead.
    pub compliance: PerFamily<f64>,
    /// The material of the families whose compliance it gives (the neo-Hookean pair, a
    /// constraint file's with a `stiffness`): their compliances follow from it
    /// ([`super::Resolved::compliance`]), whatever [`Settings::compliance`] holds for them.
    #[serde(default)]
    pub material: Material,
    /// PBD stiffness k ∈ [0, 1] per family.
    #[serde(deserialize_with = "stiffness_over_the_default")]
    pub stiffness: PerFamily<f64>,
    /// Substeps per frame, ≥ 1.
    pub substeps: u32,
    /// Gauss–Seidel sweeps per substep, ≥ 1.
    pub iterations: u32,
    /// Frame length Δt in seconds.
    pub dt: f64,
    /// Gravity along −y in m/s².
    pub gravity: f64,
    /// Whether the ground plane y = 0 stops particles.
    pub ground: bool,
    /// Velocity damping per second.
    pub damping: f64,
    /// Compliance of the grab constraint; 0 moves the grabbed particle with the target exactly.
    pub grab_compliance: f64,
    /// After an edit (a perturbation or a particle placed by hand), constraint corrections may
    /// move particles but not speed them up, until the edit's violation is undone. Otherwise rigid
    /// constraints undo a large violation within a substep, and v = Δx/h launches the body.
    pub settle_edits: bool,
    /// Which engine steps the simulation ([`EngineChoice`]).
    #[serde(default)]
    pub engine: EngineChoice,
    /// The order in which each family's constraints are projected in a sweep. `None`: the
    /// table's order, the mesh's (the order tetlab always used). A seed: an order drawn from
    /// it per family ([`Settings::projection_order`]): the reference engine projects the
    /// family's constraints in that permutation, the fast engine its colours (within a colour
    /// the order cannot change a bit, since its constraints share no particle). The families
    /// keep their order (edges, heights, volume, …). A result that changes with the seed hangs
    /// on the order of the projections; `tetlab run --ensemble N` counts how often it holds.
    #[serde(default)]
    pub order_seed: Option<u64>,
    /// How far one projection may move a particle, in longest rest edges of its element: a
    /// longer step is skipped and counted ([`DEFAULT_REACH`] says why, and
    /// why 100 is the default).
    #[serde(default = "default_reach")]
    pub reach: f64,
    /// How contact behaves (its thickness and friction), for the families that bind to
    /// contacts ([`super::contact`]).
    #[serde(default)]
    pub contact: super::contact::contact_settings::ContactSettings,
}

fn default_reach() -> f64 {
    DEFAULT_REACH
}

impl Settings {
    /// Sets gravity, and the ground with it: on when g ≠ 0, off in weightlessness (the rule of
    /// the command line and of lessons; the workbench also lets the user set the ground apart).
    pub fn set_gravity(&mut self, gravity: f64) {
        self.gravity = gravity;
        self.ground = gravity != 0.0;
    }

    /// Ok when every number is within its range of [`crate::input::limits`]; otherwise the first that
    /// is not, named (e.g. settings remembered by an older workbench, or edited by hand).
    pub fn check(&self) -> Result<(), String> {
        limits::SUBSTEPS.check(self.substeps)?;
        limits::ITERATIONS.check(self.iterations)?;
        limits::DT.check(self.dt)?;
        limits::GRAVITY.check(self.gravity)?;
        limits::DAMPING.check(self.damping)?;
        limits::REACH.check(self.reach)?;
        self.material.check()?;
        self.contact.check()?;
        limits::COMPLIANCE
            .check(self.grab_compliance)
            .map_err(|e| format!("grab {e}"))?;
        for family in Family::places() {
            let name = family;
            limits::COMPLIANCE
                .check(self.compliance[family])
                .map_err(|e| format!("{e} ({name})"))?;
            limits::STIFFNESS
                .check(self.stiffness[family])
                .map_err(|e| format!("{e} ({name})"))?;
        }
        Ok(())
    }

    /// The order of `n` things (constraints, or colours of constraints) of `family` that
    /// [`Settings::order_seed`] asks for: `None` for the natural order, otherwise a permutation
    /// of 0..n drawn from the seed and the family's place in the table, so that each family
    /// gets its own.
    ///
    /// ```
    /// use tetlab_core::constraints::Family;
    /// use tetlab_core::simulation::Settings;
    /// let natural = Settings::default();
    /// assert_eq!(natural.projection_order(Family::EDGES, 5), None);
    /// let seeded = Settings { order_seed: Some(3), ..Settings::default() };
    /// let edges = seeded.projection_order(Family::EDGES, 50).unwrap();
    /// assert_ne!(edges, (0..50).collect::<Vec<u32>>());
    /// assert_ne!(Some(edges), seeded.projection_order(Family::VOLUME, 50), "one per family");
    /// ```
    pub fn projection_order(&self, family: Family, n: usize) -> Option<Vec<u32>> {
        let seed = self.order_seed?;
        let mixed = crate::numbers::random::SplitMix64::new(
            seed ^ (family.index() as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03),
        )
        .next_u64();
        Some(crate::numbers::random::permutation(n, mixed))
    }

    /// Constraint projections in one frame, given how many constraints each family has: the
    /// active families' counts × substeps × iterations.
    pub fn projections_per_frame(&self, counts: PerFamily<usize>) -> u64 {
        let per_sweep: usize = self.active.families().map(|f| counts[f]).sum();
        per_sweep as u64 * self.substeps.max(1) as u64 * self.iterations.max(1) as u64
    }
}

/// The default substeps per frame: 100. Rigid constraints under one Gauss–Seidel sweep per
/// substep converge only as fast as the substeps are short, and a body resting on a few particles
/// passes all its weight through them. At 10 substeps the armadillo of ../shared/meshes, which
/// loads standing on one toe, crushes that toe, leans and falls over, and its tets at the ground
/// stay flat; from 60 it stands, and 100 leaves a margin. Every shared mesh and built-in scene
/// ends at rest with no inverted tet and below 5 % edge strain (core/tests/defaults.rs,
/// docs/experiments.md table 15).
pub const DEFAULT_SUBSTEPS: u32 = 100;

impl Default for Settings {
    /// XPBD, edges + volume, rigid, [`DEFAULT_SUBSTEPS`] substeps of 1 iteration, Δt = 1/60 s,
    /// gravity 9.81 m/s², the default [`Material`] for the neo-Hookean families, ground on, no
    /// damping.
    fn default() -> Self {
        Self {
            method: Method::Xpbd,
            active: PerFamily::builtin_from_fn(|f| f == Family::EDGES || f == Family::VOLUME),
            compliance: PerFamily::splat(0.0),
            stiffness: PerFamily::splat(1.0),
            substeps: DEFAULT_SUBSTEPS,
            iterations: 1,
            dt: 1.0 / 60.0,
            gravity: 9.81,
            ground: true,
            damping: 0.0,
            grab_compliance: 0.0,
            settle_edits: false,
            material: Material::default(),
            engine: EngineChoice::Auto,
            order_seed: None,
            reach: DEFAULT_REACH,
            contact: super::contact::contact_settings::ContactSettings::default(),
        }
    }
}

/// Stiffnesses as stored (the workbench's preferences): a family the stored map lacks keeps the
/// default of 1, rather than 0, which would turn it off under PBD.
fn stiffness_over_the_default<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
) -> Result<PerFamily<f64>, D::Error> {
    PerFamily::deserialize_over(deserializer, PerFamily::splat(1.0))
}

/// `FAMILY=VALUE` (as in `--compliance edges=1e-6`), with the value checked against `bounds`.
pub(crate) fn family_value(
    families: &Families,
    text: &str,
    bounds: &Bounds<f64>,
) -> Result<(Family, f64), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("'{text}' is not FAMILY=VALUE (e.g. edges=1e-6)"))?;
    let family = settable_family(families, name)?;
    Ok((family, bounds.parse(value)?))
}

/// The family whose compliance or stiffness a user sets by `name` (`--compliance NAME=…`, a
/// lesson's `compliance.NAME`): one that stands on its own and whose compliance no material
/// gives.
pub fn settable_family(families: &Families, name: &str) -> Result<Family, String> {
    let members = families.parse_group(name)?;
    let family = members.families().next().expect("a group has a family");
    if families.row(family).compliance_from_material.is_some() {
        return Err(format!(
            "{}: its constraints take their compliance from the material: give --material \
             E=PA,nu=N (or material = \"E=…,nu=…\" in a lesson)",
            families.row(family).group
        ));
    }
    Ok(family)
}

#[cfg(test)]
mod examples {
    #[allow(unused_imports)]
    use super::*;

    /// The example of `family_value`'s documentation (a unit test: the item is not exported).
    #[test]
    fn family_value_example() {
        use crate::constraints::{Families, Family};
        use crate::input::limits::COMPLIANCE;
        use crate::simulation::settings::family_value;
        let families = Families::builtin();
        assert_eq!(
            family_value(&families, "volume=0.5", &COMPLIANCE),
            Ok((Family::VOLUME, 0.5))
        );
        assert!(
            family_value(&families, "edges=inf", &COMPLIANCE)
                .unwrap_err()
                .contains("out of range")
        );
    }
}
