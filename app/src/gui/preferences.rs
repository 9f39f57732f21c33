//! What the workbench remembers between runs: the scene, the solver settings and the display
//! options, kept as JSON in eframe's storage.

use super::geometry::ViewOptions;
use super::panels::controls::SceneChoice;
use tetlab_core::simulation::{EngineChoice, Settings};

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
    /// An engine kept that cannot run here (the GPU engine, remembered from a machine with a
    /// GPU or a run with one) is `auto` again.
    pub fn load(storage: &dyn eframe::Storage) -> Preferences {
        let mut preferences: Preferences = storage
            .get_string(STORAGE_KEY)
            .and_then(|text| serde_json::from_str(&text).ok())
            .unwrap_or_default();
        if preferences.settings.engine.available().is_err() {
            preferences.settings.engine = EngineChoice::Auto;
        }
        preferences
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
