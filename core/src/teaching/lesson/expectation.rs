//! What a lesson step expects: `METRIC OP NUMBER`, checked against the metrics.

use super::format::finite;
use super::*;
use crate::energy::modes::Modes;

/// A relation a step expects between a metric and a number.
#[derive(Clone, Debug, PartialEq)]
pub struct Expectation {
    /// Whether the metric is the comparison simulation's (written `compare.METRIC`).
    pub of_comparison: bool,
    /// The metric's name, one of [`Metrics::headline`], or `gradient_error.NAME` ([`GRADIENT_ERROR`]).
    pub metric: String,
    /// For [`GRADIENT_ERROR`]: the family (of a constraint file) whose gradient it is about.
    pub gradient_of: Option<Family>,
    /// For [`MODE_METRICS`]: what of the selected tet's energy Hessian it counts.
    pub of_modes: Option<ModeCount>,
    /// The comparison.
    pub op: Op,
    /// The number compared with.
    pub value: f64,
}

/// A comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// ==
    Equal,
    /// !=
    NotEqual,
    /// <
    Less,
    /// <=
    LessOrEqual,
    /// >
    Greater,
    /// >=
    GreaterOrEqual,
}

impl Op {
    const ALL: [(&'static str, Op); 6] = [
        ("==", Op::Equal),
        ("!=", Op::NotEqual),
        ("<=", Op::LessOrEqual),
        (">=", Op::GreaterOrEqual),
        ("<", Op::Less),
        (">", Op::Greater),
    ];

    fn symbol(self) -> &'static str {
        Op::ALL
            .iter()
            .find(|(_, op)| *op == self)
            .map(|(s, _)| *s)
            .expect("every op has a symbol")
    }

    /// Whether `a OP b`.
    pub fn holds(self, a: f64, b: f64) -> bool {
        match self {
            Op::Equal => a == b,
            Op::NotEqual => a != b,
            Op::Less => a < b,
            Op::LessOrEqual => a <= b,
            Op::Greater => a > b,
            Op::GreaterOrEqual => a >= b,
        }
    }
}

/// The measure of how far a constraint file's gradient is from automatic differentiation, as a
/// lesson expects it: `gradient_error.NAME < 1e-6`, NAME a family read from a constraint file
/// ([`crate::constraint_file::grade::Grade::error`]: the largest relative error over random
/// configurations; infinite when the file leaves a particle's gradient out).
pub const GRADIENT_ERROR: &str = "gradient_error";

/// What a lesson can count of the selected tet's energy Hessian
/// ([`crate::energy::modes::Modes::of_tet`]: the energy of the active families on it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeCount {
    /// `zero_modes`: how many eigenvalues count as zero ([`crate::energy::modes::ZERO`]).
    Zero,
    /// `negative_modes`: how many are negative: the directions along which the energy is not
    /// convex.
    Negative,
}

/// The metrics of the selected tet's energy Hessian, by name.
pub const MODE_METRICS: [(&str, ModeCount); 2] = [
    ("zero_modes", ModeCount::Zero),
    ("negative_modes", ModeCount::Negative),
];

/// What an expectation is checked against: the simulation, its selected tet, and the metrics of
/// it and of the comparison (`None` when there is none).
#[derive(Clone, Copy)]
pub struct Measured<'a> {
    /// The simulation (its families, whose files the gradient errors are of).
    pub simulation: &'a Simulation,
    /// The selected tet (the one whose modes are counted).
    pub tet: usize,
    /// Its metrics.
    pub metrics: &'a Metrics,
    /// The comparison's metrics.
    pub comparison: Option<&'a Metrics>,
}

impl Expectation {
    /// The metric's current value, and whether the expectation holds for it (never for a value
    /// that is not finite); `None` when it is about the comparison and there is none.
    pub fn check(&self, measured: Measured<'_>) -> Option<(f64, bool)> {
        let holds =
            |value: f64| Some((value, value.is_finite() && self.op.holds(value, self.value)));
        if let Some(family) = self.gradient_of {
            return holds(gradient_error(measured.simulation.families(), family));
        }
        if let Some(count) = self.of_modes {
            // No active family, or no such tet: no count (NaN, which never holds).
            let value = Modes::of_tet(measured.simulation, measured.tet).map_or(f64::NAN, |m| {
                let count = match count {
                    ModeCount::Zero => m.zero_count(),
                    ModeCount::Negative => m.negative_count(),
                };
                count as f64
            });
            return holds(value);
        }
        let metrics = if self.of_comparison {
            measured.comparison?
        } else {
            measured.metrics
        };
        let value = metrics
            .named()
            .into_iter()
            .find(|(name, _)| *name == self.metric)
            .map(|(_, v)| v)
            .expect("the metric name was checked when the lesson was read");
        holds(value)
    }

    pub(super) fn parse(families: &Families, text: &str) -> Result<Expectation, String> {
        let (symbol, op, at) = Op::ALL
            .iter()
            .find_map(|&(symbol, op)| text.find(symbol).map(|at| (symbol, op, at)))
            .ok_or_else(|| format!("'{text}' is not METRIC OP NUMBER (e.g. inverted_tets == 0)"))?;
        let metric = text[..at].trim();
        let number = text[at + symbol.len()..].trim();
        let value = finite(number)?;
        if let Some(name) = metric
            .strip_prefix(GRADIENT_ERROR)
            .and_then(|m| m.strip_prefix('.'))
        {
            let family = families.parse(name)?;
            if families.file(family).is_none() {
                return Err(format!(
                    "{GRADIENT_ERROR}.{name}: {name} is a built-in family; {GRADIENT_ERROR} is about \
                     the gradient a constraint file gives (name one in constraint_files)"
                ));
            }
            return Ok(Expectation {
                of_comparison: false,
                metric: format!("{GRADIENT_ERROR}.{name}"),
                gradient_of: Some(family),
                of_modes: None,
                op,
                value,
            });
        }
        if let Some(&(name, count)) = MODE_METRICS.iter().find(|(name, _)| *name == metric) {
            return Ok(Expectation {
                of_comparison: false,
                metric: name.to_owned(),
                gradient_of: None,
                of_modes: Some(count),
                op,
                value,
            });
        }
        let (of_comparison, metric) = match metric.strip_prefix("compare.") {
            Some(metric) => (true, metric),
            None => (false, metric),
        };
        let names = Metrics::default().named().map(|(name, _)| name);
        if !names.contains(&metric) {
            let modes = MODE_METRICS.map(|(name, _)| name);
            return Err(format!(
                "'{metric}' is not a metric: expected one of {}, {}, or {GRADIENT_ERROR}.FAMILY",
                names.join(", "),
                modes.join(", ")
            ));
        }
        Ok(Expectation {
            of_comparison,
            metric: metric.to_owned(),
            gradient_of: None,
            of_modes: None,
            op,
            value,
        })
    }
}

/// The error of `family`'s gradient against AD as its grade gives it
/// ([`crate::constraint_file::grade::Grade::error`], worked out once per definition of the
/// family); infinite for a family without a file.
fn gradient_error(families: &Families, family: Family) -> f64 {
    crate::constraint_file::grade::of_family(families, family).map_or(f64::INFINITY, |g| g.error())
}

impl fmt::Display for Expectation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let prefix = match self.gradient_of {
            Some(_) => self.metric.clone(),
            None if self.of_comparison => format!("compare.{}", self.metric),
            None => self.metric.clone(),
        };
        let v = self.value;
        let number = if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e6) {
            format!("{v:e}")
        } else {
            v.to_string()
        };
        write!(f, "{prefix} {} {number}", self.op.symbol())
    }
}
