//! What a lesson step expects: `METRIC OP NUMBER`, checked against the metrics.

use super::format::finite;
use super::*;

/// A relation a step expects between a metric and a number.
#[derive(Clone, Debug, PartialEq)]
pub struct Expectation {
    /// Whether the metric is the comparison simulation's (written `compare.METRIC`).
    pub of_comparison: bool,
    /// The metric's name, one of [`Metrics::headline`], or `gradient_error.NAME` ([`GRADIENT_ERROR`]).
    pub metric: String,
    /// For [`GRADIENT_ERROR`]: the family (of a constraint file) whose gradient it is about.
    pub gradient_of: Option<Family>,
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

impl Expectation {
    /// The metric's current value, and whether the expectation holds for it (never for a value
    /// that is not finite); `None` when it is about the comparison and there is none.
    /// `families` is the table the lesson simulates, whose files the gradient errors are of.
    pub fn check(
        &self,
        families: &Families,
        metrics: &Metrics,
        comparison: Option<&Metrics>,
    ) -> Option<(f64, bool)> {
        if let Some(family) = self.gradient_of {
            let value = gradient_error(families, family);
            return Some((value, value.is_finite() && self.op.holds(value, self.value)));
        }
        let metrics = if self.of_comparison {
            comparison?
        } else {
            metrics
        };
        let value = metrics
            .headline()
            .into_iter()
            .find(|(name, _)| *name == self.metric)
            .map(|(_, v)| v)
            .expect("the metric name was checked when the lesson was read");
        Some((value, value.is_finite() && self.op.holds(value, self.value)))
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
                op,
                value,
            });
        }
        let (of_comparison, metric) = match metric.strip_prefix("compare.") {
            Some(metric) => (true, metric),
            None => (false, metric),
        };
        let names = Metrics::default().headline().map(|(name, _)| name);
        if !names.contains(&metric) {
            return Err(format!(
                "'{metric}' is not a metric: expected one of {}, or {GRADIENT_ERROR}.FAMILY",
                names.join(", ")
            ));
        }
        Ok(Expectation {
            of_comparison,
            metric: metric.to_owned(),
            gradient_of: None,
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
