//! Helpers for the screenless tests of the workbench: a workbench on a scene, the pixels of a
//! colour in its 3D view, a click.

#![allow(dead_code)] // each test file uses a different part of this module

use eframe::egui;
use egui_kittest::Harness;
use tetlab::gui::{Preferences, TetlabApp};
use tetlab_core::teaching::visual;

/// The workbench on built-in `scene` at `resolution`, with the default preferences, rendered on
/// wgpu (1280 × 800), after three frames.
pub fn workbench(scene: &str, resolution: u32) -> Harness<'static, TetlabApp> {
    let mut preferences = Preferences::default();
    preferences.scene.builtin = scene.into();
    preferences.scene.resolution = resolution;
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .wgpu()
        .build_eframe(move |cc| {
            let mut app = TetlabApp::new(cc, Box::new(tetlab::gui::platform::Desktop))
                .expect("the wgpu renderer is there");
            let builtin = tetlab_core::scene::Builtin::from_name(&preferences.scene.builtin)
                .expect("a built-in scene");
            app.load_builtin(builtin, resolution).unwrap();
            app.controls.scene = preferences.scene.clone();
            app.freeze_timings(
                std::time::Duration::from_millis(2),
                std::time::Duration::from_millis(16),
            );
            app
        });
    harness.run_steps(3);
    harness
}

/// The part of the 3D view's top-left corner the legend may take (up to 15 entries), left out
/// when pixels are counted.
const LEGEND_HEIGHT: f32 = 280.0;

/// How many pixels of the 3D view, outside the legend in its top-left corner, are close to
/// `colour` (after two-sided lighting, so the hue is compared, not the brightness).
pub fn pixels_like(harness: &mut Harness<'static, TetlabApp>, colour: visual::Rgba) -> usize {
    let image = harness.render().expect("renders");
    let rect = harness.state().viewport.rect;
    let scale = image.width() as f32 / 1280.0;
    let mut count = 0;
    for y in (rect.min.y * scale) as u32..(rect.max.y * scale) as u32 {
        for x in (rect.min.x * scale) as u32..(rect.max.x * scale) as u32 {
            let in_legend = (x as f32) < (rect.min.x + 200.0) * scale
                && (y as f32) < (rect.min.y + LEGEND_HEIGHT) * scale;
            if in_legend {
                continue;
            }
            let p = image
                .get_pixel(x.min(image.width() - 1), y.min(image.height() - 1))
                .0;
            let hue = |c: [u8; 4]| {
                let sum = c[0] as f32 + c[1] as f32 + c[2] as f32 + 1.0;
                [c[0] as f32 / sum, c[1] as f32 / sum, c[2] as f32 / sum]
            };
            let (a, b) = (hue(p), hue(colour));
            if (a[0] - b[0]).abs() + (a[1] - b[1]).abs() + (a[2] - b[2]).abs() < 0.08
                && p[0] as u32 + p[1] as u32 + p[2] as u32 > 120
            {
                count += 1;
            }
        }
    }
    count
}

pub fn click_at(harness: &mut Harness<'static, TetlabApp>, pos: egui::Pos2) {
    harness.event(egui::Event::PointerMoved(pos));
    harness.run_steps(1);
    for pressed in [true, false] {
        harness.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Default::default(),
        });
        harness.run_steps(1);
    }
}

/// Opens `assets/lessons/FILE` as a user would: L, the path typed in the lesson file field,
/// "Open lesson".
pub fn open_lesson_file(harness: &mut Harness<'static, TetlabApp>, file: &str) {
    use egui_kittest::kittest::Queryable;
    // Relative to the package folder, where tests run: the same text in any clone, so the
    // snapshots do not depend on where the repository is.
    let path = format!("../assets/lessons/{file}");
    harness.key_press(egui::Key::L);
    harness.run_steps(1);
    harness.get_by_label("lesson file").click();
    harness.run_steps(1);
    harness.get_by_label("lesson file").type_text(&path);
    harness.run_steps(1);
    harness.get_by_label("Open lesson").click();
    harness.run_steps(2);
}
