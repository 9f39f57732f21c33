//! The settings as they apply to one table of families ([`Resolved`]): what the user set, with
//! what follows from it worked out in one place. [`super::Settings`] stays what was asked; the
//! compliance a material gives, the active families kept to the table and the rule each family is
//! projected by are derived here, from the settings and the table, where they are needed.

use super::projection::Rule;
use super::settings::{Method, Settings};
use crate::constraints::{Families, Family, PerFamily};

/// [`Settings`] resolved against a table of families.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resolved {
    /// What was set.
    pub settings: Settings,
    /// The active families of the table ([`Settings::active`] kept to the table's places).
    pub active: PerFamily<bool>,
    /// The XPBD compliance each family is projected with: the material's for a family it gives
    /// one ([`crate::constraints::Row::compliance_from_material`]: the neo-Hookean pair's 1/μ and
    /// 1/λ, a file's `stiffness`), [`Settings::compliance`] otherwise.
    pub compliance: PerFamily<f64>,
    /// Which families take their compliance from the material.
    pub from_material: PerFamily<bool>,
}

impl Resolved {
    /// `settings` for the families of `families`.
    ///
    /// ```
    /// use tetlab_core::constraints::{Families, Family};
    /// use tetlab_core::constraints::material::Material;
    /// use tetlab_core::simulation::{Resolved, Settings};
    /// let mut settings = Settings::default();
    /// settings.material = Material::parse("E=1e5,nu=0.25").unwrap();
    /// settings.compliance[Family::EDGES] = 1e-6;
    /// let resolved = Resolved::new(&settings, &Families::builtin());
    /// // What was set is kept; the neo-Hookean pair's compliance is the material's 1/μ.
    /// assert_eq!(resolved.compliance[Family::EDGES], 1e-6);
    /// let mu = settings.material.mu();
    /// assert!((resolved.compliance[Family::NEOHOOKEAN_DEVIATORIC] * mu - 1.0).abs() < 1e-15);
    /// ```
    pub fn new(settings: &Settings, families: &Families) -> Resolved {
        let from = |f: Family| families.row(f).compliance_from_material;
        Resolved {
            settings: *settings,
            active: families.per_family(|f| settings.active[f]),
            compliance: families.per_family(|f| match from(f) {
                Some(compliance) => compliance(&settings.material),
                None => settings.compliance[f],
            }),
            from_material: families.per_family(|f| from(f).is_some()),
        }
    }

    /// h = Δt / substeps.
    pub fn substep_length(&self) -> f64 {
        self.settings.dt / self.settings.substeps.max(1) as f64
    }

    /// The rule `family` is projected by in a substep of length h: XPBD α̃ = α / h², or PBD
    /// k′ = 1 − (1 − k)^(1/iterations), so that the sweeps of a substep compound to k; PBD on a
    /// family whose compliance a material gives keeps the compliance and forgets λ.
    pub fn rule(&self, family: Family, h: f64) -> Rule<f64> {
        let settings = &self.settings;
        match settings.method {
            Method::Xpbd => Rule::Xpbd {
                alpha_tilde: self.compliance[family] / (h * h),
            },
            Method::Pbd if self.from_material[family] => Rule::CompliantPbd {
                alpha_tilde: self.compliance[family] / (h * h),
            },
            Method::Pbd => {
                let k = settings.stiffness[family].clamp(0.0, 1.0);
                let n = settings.iterations.max(1) as f64;
                Rule::Pbd {
                    k: 1.0 - (1.0 - k).powf(1.0 / n),
                }
            }
        }
    }

    /// Whether edits settle: [`Settings::settle_edits`], under every family (the cap is held off
    /// for a frame in one case: `Simulation::hold_off_settling` in `simulation/settling.rs`).
    pub fn edits_settle(&self) -> bool {
        self.settings.settle_edits
    }

    /// Whether `family` stores energy the account can measure, ½ C² / α: it is compliant (α > 0)
    /// and projected by a rule that keeps α (XPBD, or PBD on a material's family). A rigid family
    /// (α = 0) stores none it could measure, and PBD's stiffness k is no material constant (the
    /// same k is stiffer at more substeps), so neither has a store to book.
    pub fn stores_energy(&self, family: Family) -> bool {
        self.compliance[family] > 0.0
            && (self.settings.method == Method::Xpbd || self.from_material[family])
    }

    /// Whether an active family takes its compliance from the material: the first, if one does.
    pub fn material_family(&self) -> Option<Family> {
        self.active.families().find(|&f| self.from_material[f])
    }
}
