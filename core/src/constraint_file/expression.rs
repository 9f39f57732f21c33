//! The expression language of constraint files, parsed into a syntax tree ([`Expr`]). The grammar
//! is `expression.pest` (the pest crate): numbers, names, calls `f(a, b)`, components `v.x`,
//! unary −, `+ − * /` with the usual precedence, left to right, and comparisons `< <= > >=` as
//! the condition of `if(…)`, and in a `where` joined by `and` and `or` (`parse_condition`).
//! An expression may span lines. Types are checked later, when the
//! tree is compiled (`super::program`).
//!
//! # Nothing the parser reads can crash it
//! The parser and the compiler recurse into the tree, so a tree must be shallow enough for any
//! stack, the browser's 1 MB included. Before pest sees the text, `check_depth` measures how
//! deep its tree would be (one level per open parenthesis, unary −, and operator of a chain,
//! which builds a left-leaning tree) in one pass that does not recurse, and refuses a text that
//! would be deeper than [`MAX_DEPTH`] or longer than [`MAX_LENGTH`], at the byte where it
//! becomes too deep.

use pest::Parser;
use pest::iterators::Pair;
use pest::pratt_parser::{Assoc, Op, PrattParser};
use std::sync::LazyLock;

/// The parser pest derives from the grammar (its `Rule` enum is generated, undocumented).
mod grammar {
    #![allow(missing_docs)]
    #[derive(pest_derive::Parser)]
    #[grammar = "constraint_file/expression.pest"]
    pub(super) struct Grammar;
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

/// A comparison, the condition of `if(…)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CompareOp {
    /// `<`
    Less,
    /// `<=`
    LessOrEqual,
    /// `>`
    Greater,
    /// `>=`
    GreaterOrEqual,
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
    /// A component of a vector, `v.x`: the vector, the component's name and where it is.
    Member(Box<Expr>, String, Span),
    /// a < b and the like: only the condition of `if(…)`.
    Compare(CompareOp, Box<Expr>, Box<Expr>, Span),
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
    /// The same expression, said to be at `span` (a bracketed one: with its brackets).
    fn at(mut self, span: Span) -> Expr {
        match &mut self {
            Expr::Number(_, s)
            | Expr::Name(_, s)
            | Expr::Neg(_, s)
            | Expr::Binary(.., s)
            | Expr::Member(.., s)
            | Expr::Compare(.., s) => *s = span,
            Expr::Call { span: s, .. } => *s = span,
        }
        self
    }

    /// Where the expression is in its source.
    pub fn span(&self) -> Span {
        match self {
            Expr::Number(_, s)
            | Expr::Name(_, s)
            | Expr::Neg(_, s)
            | Expr::Binary(.., s)
            | Expr::Member(.., s)
            | Expr::Compare(.., s) => *s,
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
        .op(Op::postfix(Rule::member))
});

/// The deepest tree an expression may make: far more than a formula needs (the deepest of
/// `assets/constraints` is under 20), and shallow enough that parsing and compiling it fit in a
/// 1 MB stack with room to spare (`core/tests/constraint_language.rs` parses the deepest on one).
pub const MAX_DEPTH: usize = 100;

/// The longest text an expression (or the whole of `define`) may be, in bytes: a formula that
/// fits in `super::program::MAX_REGISTERS` operations is a few kilobytes at most.
pub const MAX_LENGTH: usize = 64 * 1024;

/// Refuses a text whose tree would be deeper than [`MAX_DEPTH`] or that is longer than
/// [`MAX_LENGTH`], naming the byte where it goes too deep; in one pass, with no recursion, so
/// that it is safe on any input.
///
/// The depth counted is an upper bound of the tree's: each open parenthesis adds a level for
/// what is inside it, and within a parenthesis (or a call's argument, or a definition) each
/// unary − and each binary operator adds one, since `a + b + c` is `(a + b) + c`.
pub(crate) fn check_depth(text: &str) -> Result<(), SyntaxError> {
    // The depth of the enclosing parentheses, and within the innermost one the operators so far.
    let mut open: Vec<(usize, usize)> = Vec::new();
    let (mut level, mut chain) = (0usize, 0usize);
    let bytes = text.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'#' => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            b'(' => {
                open.push((level, chain));
                level += chain + 1;
                chain = 0;
            }
            b')' => {
                if let Some((l, c)) = open.pop() {
                    (level, chain) = (l, c);
                }
            }
            b',' => chain = 0,
            // `<=` and `>=` are one operator; `=` alone starts a definition.
            b'=' if i == 0 || !matches!(bytes[i - 1], b'<' | b'>') => chain = 0,
            b'+' | b'-' | b'*' | b'/' | b'<' | b'>' => chain += 1,
            // A component, `.x`: one level each (a `.` in a number is not one).
            b'.' if bytes
                .get(i + 1)
                .is_some_and(|b| b.is_ascii_alphabetic() || *b == b'_') =>
            {
                chain += 1
            }
            _ => {}
        }
        if level + chain > MAX_DEPTH {
            return Err(SyntaxError {
                offset: i,
                message: format!(
                    "the expression nests too deeply: more than {MAX_DEPTH} levels of parentheses, \
                     unary minus and operators in one chain (split it with `define`)"
                ),
            });
        }
        i += 1;
    }
    if text.len() > MAX_LENGTH {
        return Err(SyntaxError {
            offset: MAX_LENGTH,
            message: format!(
                "the expression is {} bytes long; at most {MAX_LENGTH} are read (split it with `define`)",
                text.len()
            ),
        });
    }
    Ok(())
}

/// Parses one expression.
pub(crate) fn parse_expression(text: &str) -> Result<Expr, SyntaxError> {
    check_depth(text)?;
    let mut pairs = Grammar::parse(Rule::expression, text).map_err(|e| syntax_error(text, e))?;
    let expression = pairs.next().expect("the grammar's root");
    let expr = expression
        .into_inner()
        .find(|p| p.as_rule() == Rule::expr)
        .expect("an expression holds one expr");
    Ok(build(expr))
}

/// Parses a `where`: comparisons joined by `and` and `or`, `and` first; as the `or` of
/// conjunctions, each a list of [`Expr::Compare`].
pub(crate) fn parse_condition(text: &str) -> Result<Vec<Vec<Expr>>, SyntaxError> {
    check_depth(text)?;
    let mut pairs = Grammar::parse(Rule::condition, text).map_err(|e| syntax_error(text, e))?;
    let root = pairs.next().expect("the grammar's root");
    Ok(root
        .into_inner()
        .filter(|p| p.as_rule() == Rule::conjunction)
        .map(|conjunction| {
            conjunction
                .into_inner()
                .filter(|p| p.as_rule() == Rule::clause)
                .map(argument)
                .collect()
        })
        .collect())
}

/// Parses `define`: one `name = expression` per line, in order.
pub(crate) fn parse_definitions(text: &str) -> Result<Vec<(String, Span, Expr)>, SyntaxError> {
    check_depth(text)?;
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
        Rule::number
        | Rule::name
        | Rule::call
        | Rule::expr
        | Rule::neg
        | Rule::argument
        | Rule::paren => "a number, a name or (",
        Rule::add | Rule::sub | Rule::mul | Rule::div | Rule::member => "an operator",
        Rule::le | Rule::lt | Rule::ge | Rule::gt => "a comparison",
        Rule::and_ | Rule::or_ => "`and` or `or`",
        Rule::clause | Rule::conjunction => "a comparison (`q0.y > 0.5`)",
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
        .map_postfix(|operand, member| {
            let span = Span::join(operand.span(), Span::of(&member));
            let name = member.as_str().trim_start_matches('.').trim().to_owned();
            Expr::Member(Box::new(operand), name, span)
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
                args: inner.map(argument).collect(),
                span,
            }
        }
        Rule::paren => {
            let inner = pair
                .into_inner()
                .next()
                .expect("brackets hold an expression");
            build(inner).at(span)
        }
        _ => build(pair),
    }
}

/// A call's argument: an expression, or a comparison of two.
fn argument(pair: Pair<'_, Rule>) -> Expr {
    let span = Span::of(&pair);
    let mut inner = pair.into_inner();
    let left = build(inner.next().expect("an argument holds an expression"));
    let Some(op) = inner.next() else {
        return left;
    };
    let op = match op.as_rule() {
        Rule::lt => CompareOp::Less,
        Rule::le => CompareOp::LessOrEqual,
        Rule::gt => CompareOp::Greater,
        _ => CompareOp::GreaterOrEqual,
    };
    let right = build(inner.next().expect("a comparison has two sides"));
    Expr::Compare(op, Box::new(left), Box::new(right), span)
}

#[cfg(test)]
mod examples {
    #[allow(unused_imports)]
    use super::*;

    /// The example of `parse_expression`'s documentation (a unit test: the item is not exported).
    #[test]
    fn parse_expression_example() {
        use crate::constraint_file::expression::{Expr, parse_expression};
        // Precedence: 1 + 2 * 3 is 1 + (2 * 3).
        let Expr::Binary(op, _, right, _) = parse_expression("1 + 2 * 3").unwrap() else {
            panic!()
        };
        assert_eq!(op.symbol(), "+");
        assert!(matches!(*right, Expr::Binary(..)));
    }

    /// The example of `check_depth`'s documentation (a unit test: the item is not exported).
    #[test]
    fn check_depth_example() {
        use crate::constraint_file::expression::{MAX_DEPTH, check_depth};
        assert!(check_depth("-(1 + 2) * sqrt(3)").is_ok());
        let deep = format!(
            "{}1{}",
            "(".repeat(MAX_DEPTH + 1),
            ")".repeat(MAX_DEPTH + 1)
        );
        let e = check_depth(&deep).unwrap_err();
        assert_eq!(e.offset, MAX_DEPTH);
        assert!(e.message.contains("too deeply"));
    }

    /// `parse_condition`: `and` binds before `or`; a where is comparisons, not a value.
    #[test]
    fn parse_condition_example() {
        use crate::constraint_file::expression::{Expr, parse_condition};
        let c = parse_condition("q0.y > 1 and q0.x < 0 or q0.z >= 2").unwrap();
        assert_eq!(c.iter().map(Vec::len).collect::<Vec<_>>(), [2, 1]);
        assert!(matches!(c[1][0], Expr::Compare(..)));
        assert!(parse_condition("q0.y + 1").is_err());
        assert!(parse_condition("q0.y > 1 andq0.x < 0").is_err());
        let e = parse_condition("q0.y > 1 and").unwrap_err();
        assert_eq!(e.offset, 12, "{}", e.message);
    }
}
