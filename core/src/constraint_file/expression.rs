//! The expression language of constraint files, parsed into a syntax tree ([`Expr`]). The grammar
//! is `expression.pest` (the pest crate): numbers, names, calls `f(a, b)`, unary −, and
//! `+ − * /` with the usual precedence, left to right. Types are checked later, when the tree is
//! compiled ([`super::program`]).

use pest::Parser;
use pest::iterators::Pair;
use pest::pratt_parser::{Assoc, Op, PrattParser};
use std::sync::LazyLock;

/// The parser pest derives from the grammar (its `Rule` enum is generated, undocumented).
mod grammar {
    #![allow(missing_docs)]
    #[derive(pest_derive::Parser)]
    #[grammar = "constraint_file/expression.pest"]
    pub struct Grammar;
}
use grammar::{Grammar, Rule};

/// A byte range of the source text an expression came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span {
    /// First byte.
    pub start: usize,
    /// One past the last byte.
    pub end: usize,
}

impl Span {
    fn of(pair: &Pair<'_, Rule>) -> Span {
        let s = pair.as_span();
        Span {
            start: s.start(),
            end: s.end(),
        }
    }

    fn join(a: Span, b: Span) -> Span {
        Span {
            start: a.start.min(b.start),
            end: a.end.max(b.end),
        }
    }
}

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinaryOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
}

impl BinaryOp {
    /// Its symbol.
    pub fn symbol(self) -> &'static str {
        match self {
            BinaryOp::Add => "+",
            BinaryOp::Sub => "-",
            BinaryOp::Mul => "*",
            BinaryOp::Div => "/",
        }
    }
}

/// A syntax tree.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A literal number.
    Number(f64, Span),
    /// A name: p0…p3, `rest`, or one from `define`.
    Name(String, Span),
    /// −e.
    Neg(Box<Expr>, Span),
    /// a op b.
    Binary(BinaryOp, Box<Expr>, Box<Expr>, Span),
    /// f(args…); the span is the whole call, `name_span` the function's name.
    Call {
        /// The function's name.
        name: String,
        /// Where the name is.
        name_span: Span,
        /// The arguments.
        args: Vec<Expr>,
        /// The whole call.
        span: Span,
    },
}

impl Expr {
    /// Where the expression is in its source.
    pub fn span(&self) -> Span {
        match self {
            Expr::Number(_, s) | Expr::Name(_, s) | Expr::Neg(_, s) | Expr::Binary(.., s) => *s,
            Expr::Call { span, .. } => *span,
        }
    }
}

/// A syntax error: where, and what was expected.
#[derive(Clone, Debug, PartialEq)]
pub struct SyntaxError {
    /// The byte offset in the source.
    pub offset: usize,
    /// What went wrong.
    pub message: String,
}

static PRATT: LazyLock<PrattParser<Rule>> = LazyLock::new(|| {
    PrattParser::new()
        .op(Op::infix(Rule::add, Assoc::Left) | Op::infix(Rule::sub, Assoc::Left))
        .op(Op::infix(Rule::mul, Assoc::Left) | Op::infix(Rule::div, Assoc::Left))
        .op(Op::prefix(Rule::neg))
});

/// Parses one expression.
///
/// ```
/// use tetlab_core::constraint_file::expression::{parse_expression, Expr};
/// // Precedence: 1 + 2 * 3 is 1 + (2 * 3).
/// let Expr::Binary(op, _, right, _) = parse_expression("1 + 2 * 3").unwrap() else { panic!() };
/// assert_eq!(op.symbol(), "+");
/// assert!(matches!(*right, Expr::Binary(..)));
/// ```
pub fn parse_expression(text: &str) -> Result<Expr, SyntaxError> {
    let mut pairs = Grammar::parse(Rule::expression, text).map_err(|e| syntax_error(text, e))?;
    let expression = pairs.next().expect("the grammar's root");
    let expr = expression
        .into_inner()
        .find(|p| p.as_rule() == Rule::expr)
        .expect("an expression holds one expr");
    Ok(build(expr))
}

/// Parses `define`: one `name = expression` per line, in order.
pub fn parse_definitions(text: &str) -> Result<Vec<(String, Span, Expr)>, SyntaxError> {
    let mut pairs = Grammar::parse(Rule::definitions, text).map_err(|e| syntax_error(text, e))?;
    let root = pairs.next().expect("the grammar's root");
    Ok(root
        .into_inner()
        .filter(|p| p.as_rule() == Rule::assignment)
        .map(|assignment| {
            let mut inner = assignment.into_inner();
            let name = inner.next().expect("a name");
            let expr = inner.next().expect("an expression");
            (name.as_str().to_owned(), Span::of(&name), build(expr))
        })
        .collect())
}

fn syntax_error(text: &str, e: pest::error::Error<Rule>) -> SyntaxError {
    let offset = match e.location {
        pest::error::InputLocation::Pos(p) => p,
        pest::error::InputLocation::Span((s, _)) => s,
    };
    let message = match &e.variant {
        pest::error::ErrorVariant::ParsingError { positives, .. } => {
            let wanted: Vec<&str> = positives.iter().filter_map(describe).collect();
            if wanted.is_empty() {
                "unexpected text".to_owned()
            } else {
                let mut wanted = wanted;
                wanted.dedup();
                // `)` is a literal of the grammar, which pest does not list among the rules.
                let before = text.get(..offset).unwrap_or(text);
                if before.matches('(').count() > before.matches(')').count() {
                    wanted.push("`)`");
                }
                format!("expected {}", wanted.join(" or "))
            }
        }
        pest::error::ErrorVariant::CustomError { message } => message.clone(),
    };
    SyntaxError { offset, message }
}

fn describe(rule: &Rule) -> Option<&'static str> {
    Some(match rule {
        Rule::number | Rule::name | Rule::call | Rule::expr | Rule::neg => "a number, a name or (",
        Rule::add | Rule::sub | Rule::mul | Rule::div => "an operator",
        Rule::assignment => "`name = expression`",
        Rule::EOI => "the end of the expression",
        _ => return None,
    })
}

fn build(expr: Pair<'_, Rule>) -> Expr {
    PRATT
        .map_primary(primary)
        .map_prefix(|op, operand| {
            let span = Span::join(Span::of(&op), operand.span());
            Expr::Neg(Box::new(operand), span)
        })
        .map_infix(|left, op, right| {
            let op = match op.as_rule() {
                Rule::add => BinaryOp::Add,
                Rule::sub => BinaryOp::Sub,
                Rule::mul => BinaryOp::Mul,
                _ => BinaryOp::Div,
            };
            let span = Span::join(left.span(), right.span());
            Expr::Binary(op, Box::new(left), Box::new(right), span)
        })
        .parse(expr.into_inner())
}

fn primary(pair: Pair<'_, Rule>) -> Expr {
    let span = Span::of(&pair);
    match pair.as_rule() {
        // The grammar admits only digits, a point and an exponent, which f64 parses (an
        // overflowing literal becomes infinity, refused when the program is compiled).
        Rule::number => Expr::Number(pair.as_str().parse().unwrap_or(f64::INFINITY), span),
        Rule::name => Expr::Name(pair.as_str().to_owned(), span),
        Rule::call => {
            let mut inner = pair.into_inner();
            let name = inner.next().expect("a call has a name");
            Expr::Call {
                name: name.as_str().to_owned(),
                name_span: Span::of(&name),
                args: inner.map(build).collect(),
                span,
            }
        }
        _ => build(pair),
    }
}
