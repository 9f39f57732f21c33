//! One scene run under many projection orders: where a result hangs on the order in which the
//! constraints are projected (a large inversion undone by rigid constraints, contact with the
//! ground), one run is one sample. An ensemble runs the same scene, settings and perturbation
//! with order seeds 1…N ([`Settings::order_seed`]) on one engine or both, and reports the
//! outcome as a distribution: "recovers in 16 of 16 orderings on both engines".
//!
//! The members are independent, so they run side by side on worker threads; each member's fast
//! engine runs on one thread, which gives the same bits as any other count. The results come
//! back in (engine, seed) order whatever the number of workers.

use crate::constraints::Families;
use crate::measures::metrics::Metrics;
use crate::measures::outcome::Outcome;
use crate::scene::{Perturbation, Scene};
use crate::simulation::divergence::Divergence;
use crate::simulation::{EngineChoice, Settings, Simulation};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A scene, the settings and perturbation it runs with, and for how long.
#[derive(Clone, Debug)]
pub struct Ensemble<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The table of families the members run: the built-in ones and those of the constraint
    /// files the settings may make active.
    pub families: &'a Families,
    /// The settings of every member but its engine and order seed.
    pub settings: Settings,
    /// Applied before the first frame.
    pub perturbation: Option<Perturbation>,
    /// Frames each member runs.
    pub frames: u64,
}

/// One member of an ensemble: its engine, its order seed and what it came to.
#[derive(Clone, Debug, PartialEq)]
pub struct Member {
    /// [`EngineChoice::Reference`] or [`EngineChoice::Fast`].
    pub engine: EngineChoice,
    /// Its order seed.
    pub order_seed: u64,
    /// Its outcome, or where it diverged.
    pub result: Result<Outcome, Divergence>,
}

impl Ensemble<'_> {
    /// One run on `engine` with `order_seed`, the fast engine on `threads` threads.
    pub(crate) fn run_one(
        &self,
        engine: EngineChoice,
        order_seed: Option<u64>,
        threads: usize,
    ) -> Result<Outcome, Divergence> {
        let settings = Settings {
            engine,
            order_seed,
            ..self.settings
        };
        let mut simulation = Simulation::with_families(self.scene, settings, self.families.clone());
        simulation.set_threads(threads);
        if let Some(perturbation) = self.perturbation {
            simulation.perturb(perturbation);
        }
        let initial = Metrics::measure_sound(&simulation)?;
        let mut outcome = Outcome::start(&simulation, &initial);
        for _ in 0..self.frames {
            simulation.step();
            let metrics = Metrics::measure_sound(&simulation)?;
            outcome.observe(&simulation, &metrics);
        }
        Ok(outcome)
    }

    /// Every (engine, seed) of `engines` × `seeds`, on `workers` threads at once; the members in
    /// that order.
    pub fn run(&self, engines: &[EngineChoice], seeds: &[u64], workers: usize) -> Vec<Member> {
        let jobs: Vec<(EngineChoice, u64)> = engines
            .iter()
            .flat_map(|&engine| seeds.iter().map(move |&seed| (engine, seed)))
            .collect();
        let results: Vec<Mutex<Option<Member>>> = jobs.iter().map(|_| Mutex::new(None)).collect();
        let next = AtomicUsize::new(0);
        let work = || {
            loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(&(engine, seed)) = jobs.get(k) else {
                    break;
                };
                let member = Member {
                    engine,
                    order_seed: seed,
                    result: self.run_one(engine, Some(seed), 1),
                };
                *results[k].lock().unwrap_or_else(|e| e.into_inner()) = Some(member);
            }
        };
        std::thread::scope(|scope| {
            for _ in 1..workers.clamp(1, jobs.len().max(1)) {
                scope.spawn(work);
            }
            work();
        });
        results
            .into_iter()
            .map(|slot| {
                slot.into_inner()
                    .unwrap_or_else(|e| e.into_inner())
                    .expect("every job ran")
            })
            .collect()
    }
}

/// The outcomes of one engine's members, counted.
#[derive(Clone, Debug, PartialEq)]
pub struct Tally {
    /// The engine.
    pub engine: EngineChoice,
    /// How many members ran on it.
    pub members: usize,
    /// How many ended with no inverted tet (and did not diverge).
    pub recovered: usize,
    /// How many diverged.
    pub diverged: usize,
    /// How many were thrown ([`Outcome::thrown`]).
    pub thrown: usize,
    /// The inverted tets at the end of each member that did not diverge, smallest first.
    pub inverted_at_the_end: Vec<usize>,
    /// The largest max edge strain at the end among the members that did not diverge: a body
    /// may end with no tet inverted yet tangled.
    pub largest_strain: f64,
}

impl Tally {
    /// The members of `members` that ran on `engine`, counted.
    pub fn of(members: &[Member], engine: EngineChoice) -> Tally {
        let mine: Vec<&Member> = members.iter().filter(|m| m.engine == engine).collect();
        let outcomes: Vec<&Outcome> = mine.iter().filter_map(|m| m.result.as_ref().ok()).collect();
        let mut inverted_at_the_end: Vec<usize> =
            outcomes.iter().map(|o| o.last.inverted_tets).collect();
        inverted_at_the_end.sort_unstable();
        Tally {
            engine,
            members: mine.len(),
            recovered: outcomes.iter().filter(|o| o.recovered()).count(),
            diverged: mine.len() - outcomes.len(),
            thrown: outcomes.iter().filter(|o| o.thrown()).count(),
            inverted_at_the_end,
            largest_strain: outcomes
                .iter()
                .map(|o| o.last.max_edge_strain)
                .fold(0.0, f64::max),
        }
    }

    /// "recovers in 16 of 16 orderings", "recovers in 3 of 4 orderings (1 ends with 170
    /// inverted)", with divergences and throws named; and, where some member ends strained, how
    /// much ("max edge strain at the end up to 0.64").
    ///
    /// ```
    /// use tetlab_core::measures::ensemble::Tally;
    /// use tetlab_core::simulation::EngineChoice;
    /// let tally = Tally {
    ///     engine: EngineChoice::Fast,
    ///     members: 4,
    ///     recovered: 2,
    ///     diverged: 1,
    ///     thrown: 0,
    ///     inverted_at_the_end: vec![0, 0, 7],
    ///     largest_strain: 0.002,
    /// };
    /// assert_eq!(
    ///     tally.describe(),
    ///     "recovers in 2 of 4 orderings (1 ends with 7 inverted; 1 diverges)"
    /// );
    /// let tangled = Tally { largest_strain: 0.64, ..tally };
    /// assert!(tangled.describe().ends_with("; max edge strain at the end up to 0.64"));
    /// ```
    pub fn describe(&self) -> String {
        let mut text = format!(
            "recovers in {} of {} orderings",
            self.recovered, self.members
        );
        let failed: Vec<String> = self
            .inverted_at_the_end
            .iter()
            .filter(|&&n| n > 0)
            .map(|n| n.to_string())
            .collect();
        let mut notes = Vec::new();
        if !failed.is_empty() {
            let (some, last) = failed.split_at(failed.len() - 1);
            let list = if some.is_empty() {
                last[0].clone()
            } else {
                format!("{} and {}", some.join(", "), last[0])
            };
            let who = if failed.len() == 1 {
                "1 ends".to_owned()
            } else {
                format!("{} end", failed.len())
            };
            notes.push(format!("{who} with {list} inverted"));
        }
        if self.diverged > 0 {
            notes.push(format!(
                "{} diverge{}",
                self.diverged,
                if self.diverged == 1 { "s" } else { "" }
            ));
        }
        if self.thrown > 0 {
            notes.push(format!("{} thrown", self.thrown));
        }
        if !notes.is_empty() {
            text += &format!(" ({})", notes.join("; "));
        }
        // A percent of strain is a shape that holds; beyond it, say how far some member is off.
        if self.largest_strain > 0.01 {
            text += &format!(
                "; max edge strain at the end up to {:.2}",
                self.largest_strain
            );
        }
        text
    }
}
