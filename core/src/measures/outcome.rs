//! What a headless run came to: the last frame's metrics, the last frame with an inverted tet,
//! the largest speed any particle reached, the deepest contact, and how far the centre of mass
//! travelled, with the verdicts read from them (recovered, thrown, a particle under a surface). `tetlab run` reports one; an ensemble
//! ([`crate::measures::ensemble`]) counts them over projection orders.

use crate::measures::metrics::Metrics;
use crate::simulation::Simulation;
use glam::DVec3;

/// A run's outcome so far, updated frame by frame with [`Outcome::observe`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    /// The metrics of the last frame observed.
    pub last: Metrics,
    /// The frame of [`Outcome::last`].
    pub frame: u64,
    /// The last frame at which some tet was inverted (frame 0 is the state before the first
    /// step), `None` if none ever was.
    pub last_inverted_frame: Option<u64>,
    /// The largest particle speed seen, in m/s, and the frame it was seen at.
    pub largest_speed: (f64, u64),
    /// The largest penetration seen ([`Metrics::max_penetration`]), in m, and the frame it was
    /// seen at.
    pub deepest: (f64, u64),
    /// The centre of mass at frame 0, where the run started.
    pub start: DVec3,
    /// The diagonal of the body's rest bounding box, in metres: what "thrown" is measured by.
    pub body_length: f64,
}

impl Outcome {
    /// The outcome of a run that has not stepped yet: `simulation` at frame 0, measured as
    /// `initial`.
    pub fn start(simulation: &Simulation, initial: &Metrics) -> Outcome {
        Outcome {
            last: *initial,
            frame: simulation.frame(),
            last_inverted_frame: (initial.inverted_tets > 0).then_some(simulation.frame()),
            largest_speed: (initial.max_speed, simulation.frame()),
            deepest: (initial.max_penetration, simulation.frame()),
            start: initial.centre_of_mass,
            body_length: simulation.rest_diagonal(),
        }
    }

    /// Takes in the frame `simulation` is at, measured as `metrics`.
    pub fn observe(&mut self, simulation: &Simulation, metrics: &Metrics) {
        self.last = *metrics;
        self.frame = simulation.frame();
        if metrics.inverted_tets > 0 {
            self.last_inverted_frame = Some(self.frame);
        }
        if metrics.max_speed > self.largest_speed.0 {
            self.largest_speed = (metrics.max_speed, self.frame);
        }
        if metrics.max_penetration > self.deepest.0 {
            self.deepest = (metrics.max_penetration, self.frame);
        }
    }

    /// Whether no tet is inverted at the end.
    pub fn recovered(&self) -> bool {
        self.last.inverted_tets == 0
    }

    /// How far the centre of mass is from where it started, in metres.
    pub fn displacement(&self) -> DVec3 {
        self.last.centre_of_mass - self.start
    }

    /// How far the centre of mass is from where it started across the ground (x and z), in
    /// metres.
    pub fn horizontal_displacement(&self) -> f64 {
        let d = self.displacement();
        d.x.hypot(d.z)
    }

    /// Whether the body was thrown: its centre of mass ended further from its start,
    /// horizontally, than the diagonal of its rest bounding box ([`Outcome::body_length`]).
    /// A body recovering where it lies shifts by a fraction of its size; one launched by an
    /// edit undone within a substep flies off by many times it.
    ///
    /// ```
    /// use glam::DVec3;
    /// use tetlab_core::measures::metrics::Metrics;
    /// use tetlab_core::measures::outcome::Outcome;
    /// use tetlab_core::scene::{Builtin, Scene};
    /// use tetlab_core::simulation::{Settings, Simulation};
    /// let cube = Simulation::new(&Scene::builtin(Builtin::Cube, 1).unwrap(), Settings::default());
    /// let mut metrics = Metrics::measure(&cube);
    /// let mut outcome = Outcome::start(&cube, &metrics);
    /// assert!(!outcome.thrown());
    /// // The unit cube's diagonal is √3 m: its centre 2 m away across the ground is thrown.
    /// metrics.centre_of_mass += DVec3::new(2.0, 5.0, 0.0);
    /// outcome.observe(&cube, &metrics);
    /// assert!(outcome.thrown() && outcome.horizontal_displacement() == 2.0);
    /// ```
    pub fn thrown(&self) -> bool {
        self.horizontal_displacement() > self.body_length
    }

    /// One line for a reader: "0 inverted at the end (none from frame 3 on), min V/V₀ 0.998,
    /// max edge strain 1.2e-3, largest speed 0.52 m/s (frame 1), centre of mass moved 0.012 m
    /// (0.003 m across the ground)".
    pub fn describe(&self) -> String {
        let inverted = match self.last_inverted_frame {
            _ if !self.recovered() => format!("{} inverted at the end", self.last.inverted_tets),
            Some(frame) => format!("0 inverted at the end (none from frame {} on)", frame + 1),
            None => "0 inverted at any frame".to_owned(),
        };
        format!(
            "{inverted}, min V/V0 {:.4}, max edge strain {:.3e}, largest speed {:.3} m/s (frame \
             {}), centre of mass moved {:.3} m ({:.3} m across the ground)",
            self.last.min_volume_ratio,
            self.last.max_edge_strain,
            self.largest_speed.0,
            self.largest_speed.1,
            self.displacement().length(),
            self.horizontal_displacement()
        )
    }

    /// The warning a reader gets when the body was thrown ([`Outcome::thrown`]), else `None`.
    pub fn thrown_warning(&self) -> Option<String> {
        self.thrown().then(|| {
            format!(
                "the body was thrown: its centre of mass ended {:.3} m from its start across \
                 the ground, more than its length ({:.3} m, the diagonal of its rest bounding \
                 box); its largest speed was {:.3} m/s at frame {}",
                self.horizontal_displacement(),
                self.body_length,
                self.largest_speed.0,
                self.largest_speed.1
            )
        })
    }
}
