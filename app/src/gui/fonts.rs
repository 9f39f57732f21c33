//! The workbench's fonts.

use eframe::egui;

/// The fonts: on the desktop, egui's own with DejaVu Sans Mono after them, for the glyphs of the
/// formulas (∇ ₀ ⅙ × λ Δ …) that egui's fonts lack; in a browser, to keep the page small, only
/// Ubuntu Light and DejaVu Sans Mono cut to the characters tetlab shows (`scripts/web-fonts.sh`).
pub fn install_fonts(ctx: &egui::Context) {
    let font = |bytes: &'static [u8]| std::sync::Arc::new(egui::FontData::from_static(bytes));
    let mut fonts = egui::FontDefinitions::default();
    #[cfg(not(target_arch = "wasm32"))]
    let (proportional, monospace) = {
        let dejavu = include_bytes!("../../../assets/fonts/DejaVuSansMono.ttf");
        fonts
            .font_data
            .insert("DejaVuSansMono".into(), font(dejavu));
        (vec!["DejaVuSansMono"], vec!["DejaVuSansMono"])
    };
    #[cfg(target_arch = "wasm32")]
    let (proportional, monospace) = {
        let dejavu = include_bytes!("../../../assets/fonts/web/DejaVuSansMono-subset.ttf");
        let ubuntu = include_bytes!("../../../assets/fonts/web/Ubuntu-Light-subset.ttf");
        fonts
            .font_data
            .insert("DejaVuSansMono".into(), font(dejavu));
        fonts.font_data.insert("Ubuntu-Light".into(), font(ubuntu));
        (
            vec!["Ubuntu-Light", "DejaVuSansMono"],
            vec!["DejaVuSansMono", "Ubuntu-Light"],
        )
    };
    for (family, names) in [
        (egui::FontFamily::Proportional, proportional),
        (egui::FontFamily::Monospace, monospace),
    ] {
        let list = fonts.families.entry(family).or_default();
        list.extend(names.into_iter().map(String::from));
    }
    ctx.set_fonts(fonts);
}
