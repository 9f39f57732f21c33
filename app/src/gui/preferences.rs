//! What the workbench remembers between runs: the scene, the solver settings and the display
//! options, kept as JSON in eframe's storage.

use super::geometry::ViewOptions;
use super::panels::controls::SceneChoice;
use tetlab_core::simulation::Settings;

/// What the workbench remembers between runs (eframe storage).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Preferences {
    /// The scene section.
    pub scene: SceneChoice,
    /// The solver settings.
    pub settings: Settings,
    /// The display options.
    pub view: ViewOptions,
}

impl Preferences {
    /// The preferences `storage` keeps (as JSON, the same on the desktop and in a page, which
    /// then needs no RON), or the defaults when it keeps none or ones it cannot read.
    pub fn load(storage: &dyn eframe::Storage) -> Preferences {
        storage
            .get_string(STORAGE_KEY)
            .and_then(|text| serde_json::from_str(&text).ok())
            .unwrap_or_default()
    }

    /// Keeps them in `storage`.
    pub fn save(&self, storage: &mut dyn eframe::Storage) {
        if let Ok(text) = serde_json::to_string(self) {
            storage.set_string(STORAGE_KEY, text);
        }
    }
}

impl Default for Preferences {
    /// The solver's defaults, except that edits settle: inverting or dragging by hand is undone
    /// without launching the body out of view.
    fn default() -> Self {
        Self {
            scene: SceneChoice::default(),
            settings: Settings {
                settle_edits: true,
                ..Settings::default()
            },
            view: ViewOptions::default(),
        }
    }
}

const STORAGE_KEY: &str = "tetlab";
