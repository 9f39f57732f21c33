//! Which engine steps a simulation, as the user chooses it ([`EngineChoice`]): every choice,
//! its name on the command line and in links, a line about it, which engine `auto` picks, and
//! what the front ends show of it. The front ends list the choices from here; how each is built
//! is `engine_slot.rs`.

/// Which engine steps a simulation: the user's choice, among the engines of this list.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum EngineChoice {
    /// The reference engine for scenes of fewer than [`FAST_FROM_TETS`] tets, the fast one
    /// from there.
    #[default]
    Auto,
    /// The f64 engine, one constraint at a time: exact to f64, and the one step-by-step mode
    /// walks through.
    Reference,
    /// The f32 engine in SIMD lanes and on threads: several times faster on a real mesh.
    Fast,
    /// The Newton reference: every substep's implicit Euler step solved exactly (to 10⁻¹⁰), the
    /// discrete problem XPBD approximates ([`super::newton`]). Slow: for validation and small
    /// scenes.
    Newton,
    /// The fast engine's model on a GPU, in WGSL compute shaders on wgpu
    /// (`simulation::gpu`, with the feature `gpu`): where a GPU can be had
    /// ([`EngineChoice::available`]).
    Gpu,
}

/// The size from which [`EngineChoice::Auto`] picks the fast engine. The reference engine's
/// frame grows with the tets, about 19 µs a tet at the default 100 substeps with edges + volume
/// (the 384-tet cube: 7.3 ms a frame; the 1351-tet bunny: 24 ms, where the fast engine takes
/// 4.1; docs/performance.md): from about 900 tets it no longer holds 60 frames a second. The
/// built-in teaching scenes and every lesson's scene but the bunny stay below it, on the exact
/// path.
pub const FAST_FROM_TETS: usize = 1000;

impl EngineChoice {
    /// Every choice, in the order the front ends list them.
    pub const ALL: [EngineChoice; 5] = [
        EngineChoice::Auto,
        EngineChoice::Reference,
        EngineChoice::Fast,
        EngineChoice::Newton,
        EngineChoice::Gpu,
    ];

    /// The engines themselves, every choice but [`EngineChoice::Auto`].
    pub fn engines() -> impl Iterator<Item = EngineChoice> {
        EngineChoice::ALL
            .into_iter()
            .filter(|&e| e != EngineChoice::Auto)
    }

    /// The CPU engines that project constraints (every engine but the Newton reference, which
    /// solves the step they approximate, and the GPU engine): what `validate --engine both` and
    /// an ensemble run. The engines' contract binds the GPU engine too, whose model is the fast
    /// engine's; it runs where it is named (`--engine gpu`), since it needs an adapter.
    ///
    /// ```
    /// use tetlab_core::simulation::EngineChoice;
    /// let both: Vec<_> = EngineChoice::position_based().collect();
    /// assert_eq!(both, [EngineChoice::Reference, EngineChoice::Fast]);
    /// ```
    pub fn position_based() -> impl Iterator<Item = EngineChoice> {
        EngineChoice::engines().filter(|&e| !matches!(e, EngineChoice::Newton | EngineChoice::Gpu))
    }

    /// Its name on the command line, in files and links: `auto`, `reference`, `fast`,
    /// `newton` or `gpu`.
    pub fn name(self) -> &'static str {
        match self {
            EngineChoice::Auto => "auto",
            EngineChoice::Reference => "reference",
            EngineChoice::Fast => "fast",
            EngineChoice::Newton => "newton",
            EngineChoice::Gpu => "gpu",
        }
    }

    /// What it is, in a line (the workbench's tooltip).
    pub fn summary(self) -> String {
        match self {
            EngineChoice::Auto => format!("reference below {FAST_FROM_TETS} tets, fast from there"),
            EngineChoice::Reference => {
                "f64, one constraint at a time: exact, and what step by step walks through".into()
            }
            EngineChoice::Fast => {
                "f32, coloured, eight constraints at a time in SIMD lanes, on every core".into()
            }
            EngineChoice::Newton => {
                "f64, every substep's implicit step solved exactly: the reference XPBD approaches"
                    .into()
            }
            EngineChoice::Gpu => {
                "f32, the fast engine's colours as compute shaders, one thread per constraint"
                    .into()
            }
        }
    }

    /// The choice named `text` ([`EngineChoice::name`]).
    ///
    /// ```
    /// use tetlab_core::simulation::EngineChoice;
    /// assert_eq!(EngineChoice::parse("fast"), Ok(EngineChoice::Fast));
    /// assert_eq!(EngineChoice::parse("gpu"), Ok(EngineChoice::Gpu));
    /// assert!(EngineChoice::parse("cuda").unwrap_err().contains("auto, reference, fast, newton or gpu"));
    /// ```
    pub fn parse(text: &str) -> Result<EngineChoice, String> {
        let text = text.trim();
        EngineChoice::ALL
            .into_iter()
            .find(|e| e.name() == text)
            .ok_or_else(|| {
                let names: Vec<&str> = EngineChoice::ALL.iter().map(|e| e.name()).collect();
                let (last, first) = names.split_last().expect("there are engines");
                format!(
                    "'{text}' is not an engine: expected {} or {last}",
                    first.join(", ")
                )
            })
    }

    /// The engine this choice runs a scene of `tets` tets on: one of
    /// [`EngineChoice::engines`].
    ///
    /// ```
    /// use tetlab_core::simulation::{EngineChoice, FAST_FROM_TETS};
    /// assert_eq!(EngineChoice::Auto.resolve(162), EngineChoice::Reference);
    /// assert_eq!(EngineChoice::Auto.resolve(FAST_FROM_TETS), EngineChoice::Fast);
    /// assert_eq!(EngineChoice::Reference.resolve(100_000), EngineChoice::Reference);
    /// ```
    pub fn resolve(self, tets: usize) -> EngineChoice {
        match self {
            EngineChoice::Auto if tets >= FAST_FROM_TETS => EngineChoice::Fast,
            EngineChoice::Auto => EngineChoice::Reference,
            chosen => chosen,
        }
    }

    /// What the front ends show of this choice's engine on `threads` threads, before it is
    /// built: "reference (f64)", "fast (f32, 2 threads)".
    pub fn describe(self, threads: usize) -> String {
        match self {
            EngineChoice::Fast => {
                let s = if threads == 1 { "" } else { "s" };
                format!("fast (f32, {threads} thread{s})")
            }
            EngineChoice::Auto | EngineChoice::Reference => "reference (f64)".to_owned(),
            EngineChoice::Newton => "newton (f64, implicit Euler to 1e-10)".to_owned(),
            EngineChoice::Gpu => "gpu (f32)".to_owned(),
        }
    }
}
