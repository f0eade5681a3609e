//! The expression language of implicit surfaces: `f(x, y, z)` written as
//! text, parsed once and compiled to a flat postfix program evaluated on a
//! fixed-size stack (no allocation, no tree walk per evaluation).
//!
//! The grammar, loosest binding first:
//!
//! ```text
//! sum     = product (("+" | "-") product)*
//! product = unary (("*" | "/") unary)*
//! unary   = ("-" | "+") unary | power
//! power   = atom ("^" unary)?            right-associative: 2^3^2 = 2^9
//! atom    = number | x | y | z | pi | name "(" sum ("," sum)* ")" | "(" sum ")"
//! ```
//!
//! So `-x^2` is `-(x^2)` and `2^-x` is `2^(-x)`. The functions are `sin cos
//! tan asin acos atan sqrt abs exp ln floor` of one argument and `atan2 min
//! max pow` of two. Sub-expressions without a variable are folded to
//! constants at compile time. Errors carry the byte offset in the text of
//! the character they concern.

use std::fmt;

use crate::math::Vec3;

/// The deepest evaluation stack (and parenthesis nesting) an expression may
/// need.
pub const MAX_DEPTH: usize = 64;

/// The longest expression accepted, in bytes.
pub const MAX_LENGTH: usize = 10_000;

/// Why an expression could not be compiled, and where.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct ExpressionError {
    /// Byte offset in the expression of the character at fault (its length
    /// at the end of the text).
    pub offset: usize,
    /// What was expected or wrong.
    pub message: String,
}

/// A function of one argument.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Unary {
    Neg,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sqrt,
    Abs,
    Exp,
    Ln,
    Floor,
}

/// A function or operator of two arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Binary {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Atan2,
    Min,
    Max,
}

impl Unary {
    fn apply(self, a: f64) -> f64 {
        match self {
            Unary::Neg => -a,
            Unary::Sin => a.sin(),
            Unary::Cos => a.cos(),
            Unary::Tan => a.tan(),
            Unary::Asin => a.asin(),
            Unary::Acos => a.acos(),
            Unary::Atan => a.atan(),
            Unary::Sqrt => a.sqrt(),
            Unary::Abs => a.abs(),
            Unary::Exp => a.exp(),
            Unary::Ln => a.ln(),
            Unary::Floor => a.floor(),
        }
    }
}

impl Binary {
    fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Binary::Add => a + b,
            Binary::Sub => a - b,
            Binary::Mul => a * b,
            Binary::Div => a / b,
            Binary::Pow => power(a, b),
            Binary::Atan2 => a.atan2(b),
            Binary::Min => a.min(b),
            Binary::Max => a.max(b),
        }
    }
}

/// `a^b`, with small whole exponents as products (exact and fast, and
/// defined for negative bases).
fn power(a: f64, b: f64) -> f64 {
    if b == 2.0 {
        a * a
    } else if b == 3.0 {
        a * a * a
    } else if b == 4.0 {
        let s = a * a;
        s * s
    } else if b.fract() == 0.0 && b.abs() <= 64.0 {
        a.powi(b as i32)
    } else {
        a.powf(b)
    }
}

/// The names of the functions, with their arities.
const UNARY_NAMES: &[(&str, Unary)] = &[
    ("sin", Unary::Sin),
    ("cos", Unary::Cos),
    ("tan", Unary::Tan),
    ("asin", Unary::Asin),
    ("acos", Unary::Acos),
    ("atan", Unary::Atan),
    ("sqrt", Unary::Sqrt),
    ("abs", Unary::Abs),
    ("exp", Unary::Exp),
    ("ln", Unary::Ln),
    ("floor", Unary::Floor),
];
const BINARY_NAMES: &[(&str, Binary)] = &[
    ("atan2", Binary::Atan2),
    ("min", Binary::Min),
    ("max", Binary::Max),
    ("pow", Binary::Pow),
];

/// One instruction of the postfix program.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    Const(f64),
    Var(u8),
    Unary(Unary),
    Binary(Binary),
}

/// A compiled expression: postfix instructions and the stack depth they
/// need (at most [`MAX_DEPTH`]).
#[derive(Clone, PartialEq)]
pub struct Expression {
    ops: Vec<Op>,
    text: String,
}

impl fmt::Debug for Expression {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Expression({:?})", self.text)
    }
}

/// A tree, built by the parser and folded before it is flattened.
enum Node {
    Const(f64),
    Var(u8),
    Unary(Unary, Box<Node>),
    Binary(Binary, Box<Node>, Box<Node>),
}

impl Node {
    /// The node with constant sub-trees folded.
    fn unary(op: Unary, a: Node) -> Node {
        match a {
            Node::Const(a) => Node::Const(op.apply(a)),
            a => Node::Unary(op, Box::new(a)),
        }
    }

    fn binary(op: Binary, a: Node, b: Node) -> Node {
        match (a, b) {
            (Node::Const(a), Node::Const(b)) => Node::Const(op.apply(a, b)),
            (a, b) => Node::Binary(op, Box::new(a), Box::new(b)),
        }
    }

    /// Appends the postfix form; returns the stack depth it needs.
    fn flatten(&self, ops: &mut Vec<Op>) -> usize {
        match self {
            Node::Const(c) => {
                ops.push(Op::Const(*c));
                1
            }
            Node::Var(i) => {
                ops.push(Op::Var(*i));
                1
            }
            Node::Unary(op, a) => {
                let depth = a.flatten(ops);
                ops.push(Op::Unary(*op));
                depth
            }
            Node::Binary(op, a, b) => {
                let left = a.flatten(ops);
                let right = b.flatten(ops);
                ops.push(Op::Binary(*op));
                left.max(right + 1)
            }
        }
    }
}

/// A token and where it starts.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Token<'a> {
    Number(f64),
    Name(&'a str),
    Symbol(char),
    End,
}

/// The recursive-descent parser over the text.
struct Parser<'a> {
    text: &'a str,
    at: usize,
    /// Start of the current token.
    token_start: usize,
    token: Token<'a>,
    depth: usize,
}

impl<'a> Parser<'a> {
    fn error(&self, offset: usize, message: impl Into<String>) -> ExpressionError {
        ExpressionError {
            offset,
            message: message.into(),
        }
    }

    /// Reads the next token into `self.token`.
    fn advance(&mut self) -> Result<(), ExpressionError> {
        let bytes = self.text.as_bytes();
        while self.at < bytes.len() && bytes[self.at].is_ascii_whitespace() {
            self.at += 1;
        }
        self.token_start = self.at;
        let Some(c) = self.text[self.at..].chars().next() else {
            self.token = Token::End;
            return Ok(());
        };
        if c.is_ascii_digit() || c == '.' {
            let mut end = self.at;
            while end < bytes.len() && (bytes[end].is_ascii_digit() || bytes[end] == b'.') {
                end += 1;
            }
            if end < bytes.len() && (bytes[end] == b'e' || bytes[end] == b'E') {
                let mut exp = end + 1;
                if exp < bytes.len() && (bytes[exp] == b'+' || bytes[exp] == b'-') {
                    exp += 1;
                }
                if exp < bytes.len() && bytes[exp].is_ascii_digit() {
                    while exp < bytes.len() && bytes[exp].is_ascii_digit() {
                        exp += 1;
                    }
                    end = exp;
                }
            }
            let literal = &self.text[self.at..end];
            let value: f64 = literal
                .parse()
                .map_err(|_| self.error(self.at, format!("`{literal}` is not a number")))?;
            if !value.is_finite() {
                return Err(self.error(self.at, format!("`{literal}` is too large")));
            }
            self.token = Token::Number(value);
            self.at = end;
        } else if c.is_ascii_alphabetic() || c == '_' {
            let mut end = self.at;
            while end < bytes.len() && (bytes[end].is_ascii_alphanumeric() || bytes[end] == b'_') {
                end += 1;
            }
            self.token = Token::Name(&self.text[self.at..end]);
            self.at = end;
        } else if "+-*/^(),".contains(c) {
            self.token = Token::Symbol(c);
            self.at += 1;
        } else {
            return Err(self.error(self.at, format!("unexpected character `{c}`")));
        }
        Ok(())
    }

    /// What the current token is, for messages.
    fn found(&self) -> String {
        match self.token {
            Token::End => "the end of the expression".into(),
            _ => format!("`{}`", self.text[self.token_start..self.at].trim()),
        }
    }

    fn expect(&mut self, symbol: char) -> Result<(), ExpressionError> {
        if self.token == Token::Symbol(symbol) {
            self.advance()
        } else {
            Err(self.error(
                self.token_start,
                format!("expected `{symbol}`, found {}", self.found()),
            ))
        }
    }

    /// Guards the recursion (and so the evaluation stack) against deep
    /// nesting.
    fn nest(&mut self) -> Result<(), ExpressionError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.error(
                self.token_start,
                format!("the expression nests more than {MAX_DEPTH} levels deep"),
            ));
        }
        Ok(())
    }

    fn sum(&mut self) -> Result<Node, ExpressionError> {
        self.nest()?;
        let mut node = self.product()?;
        while let Token::Symbol(c @ ('+' | '-')) = self.token {
            self.advance()?;
            let right = self.product()?;
            let op = if c == '+' { Binary::Add } else { Binary::Sub };
            node = Node::binary(op, node, right);
        }
        self.depth -= 1;
        Ok(node)
    }

    fn product(&mut self) -> Result<Node, ExpressionError> {
        let mut node = self.unary()?;
        while let Token::Symbol(c @ ('*' | '/')) = self.token {
            self.advance()?;
            let right = self.unary()?;
            let op = if c == '*' { Binary::Mul } else { Binary::Div };
            node = Node::binary(op, node, right);
        }
        Ok(node)
    }

    fn unary(&mut self) -> Result<Node, ExpressionError> {
        match self.token {
            Token::Symbol(c @ ('-' | '+')) => {
                self.nest()?;
                self.advance()?;
                let operand = self.unary()?;
                self.depth -= 1;
                Ok(if c == '-' {
                    Node::unary(Unary::Neg, operand)
                } else {
                    operand
                })
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Node, ExpressionError> {
        let base = self.atom()?;
        if self.token == Token::Symbol('^') {
            self.nest()?;
            self.advance()?;
            let exponent = self.unary()?;
            self.depth -= 1;
            return Ok(Node::binary(Binary::Pow, base, exponent));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Node, ExpressionError> {
        let start = self.token_start;
        match self.token {
            Token::Number(value) => {
                self.advance()?;
                Ok(Node::Const(value))
            }
            Token::Symbol('(') => {
                self.advance()?;
                let node = self.sum()?;
                self.expect(')')?;
                Ok(node)
            }
            Token::Name(name) => {
                self.advance()?;
                if self.token == Token::Symbol('(') {
                    return self.call(name, start);
                }
                match name {
                    "x" => Ok(Node::Var(0)),
                    "y" => Ok(Node::Var(1)),
                    "z" => Ok(Node::Var(2)),
                    "pi" => Ok(Node::Const(std::f64::consts::PI)),
                    _ if is_function(name) => Err(self.error(
                        start,
                        format!("`{name}` is a function: write `{name}(...)`"),
                    )),
                    _ => Err(self.error(
                        start,
                        format!("unknown variable `{name}`; expected x, y, z or pi"),
                    )),
                }
            }
            _ => Err(self.error(
                start,
                format!(
                    "expected a number, a variable, a function or `(`, found {}",
                    self.found()
                ),
            )),
        }
    }

    /// A call of `name`, whose `(` is the current token.
    fn call(&mut self, name: &str, start: usize) -> Result<Node, ExpressionError> {
        let unary = UNARY_NAMES.iter().find(|(n, _)| *n == name).map(|f| f.1);
        let binary = BINARY_NAMES.iter().find(|(n, _)| *n == name).map(|f| f.1);
        let arity = match (unary, binary) {
            (Some(_), _) => 1,
            (_, Some(_)) => 2,
            _ => {
                let names: Vec<&str> = UNARY_NAMES
                    .iter()
                    .map(|f| f.0)
                    .chain(BINARY_NAMES.iter().map(|f| f.0))
                    .collect();
                return Err(self.error(
                    start,
                    format!(
                        "unknown function `{name}`; expected one of: {}",
                        names.join(", ")
                    ),
                ));
            }
        };
        self.advance()?;
        let mut args = vec![self.sum()?];
        while self.token == Token::Symbol(',') {
            self.advance()?;
            args.push(self.sum()?);
        }
        if self.token != Token::Symbol(')') {
            return Err(self.error(
                self.token_start,
                format!("expected `,` or `)`, found {}", self.found()),
            ));
        }
        if args.len() != arity {
            let plural = if arity == 1 { "" } else { "s" };
            return Err(self.error(
                start,
                format!(
                    "`{name}` takes {arity} argument{plural}, found {}",
                    args.len()
                ),
            ));
        }
        self.advance()?;
        let mut args = args.into_iter();
        let a = args.next().unwrap_or(Node::Const(0.0));
        Ok(match (unary, binary) {
            (Some(op), _) => Node::unary(op, a),
            (_, Some(op)) => Node::binary(op, a, args.next().unwrap_or(Node::Const(0.0))),
            _ => a,
        })
    }
}

fn is_function(name: &str) -> bool {
    UNARY_NAMES.iter().any(|f| f.0 == name) || BINARY_NAMES.iter().any(|f| f.0 == name)
}

impl Expression {
    /// Parses and compiles `text`.
    pub fn parse(text: &str) -> Result<Self, ExpressionError> {
        if text.len() > MAX_LENGTH {
            return Err(ExpressionError {
                offset: 0,
                message: format!("the expression is longer than {MAX_LENGTH} bytes"),
            });
        }
        let mut parser = Parser {
            text,
            at: 0,
            token_start: 0,
            token: Token::End,
            depth: 0,
        };
        parser.advance()?;
        if parser.token == Token::End {
            return Err(parser.error(0, "the expression is empty"));
        }
        let tree = parser.sum()?;
        if parser.token != Token::End {
            return Err(parser.error(
                parser.token_start,
                format!("expected an operator, found {}", parser.found()),
            ));
        }
        let mut ops = Vec::new();
        let depth = tree.flatten(&mut ops);
        if depth > MAX_DEPTH {
            return Err(parser.error(
                0,
                format!("the expression needs a stack deeper than {MAX_DEPTH}"),
            ));
        }
        Ok(Self {
            ops,
            text: text.to_string(),
        })
    }

    /// The text it was compiled from.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// How many operations one evaluation runs (after constant folding).
    pub fn operations(&self) -> usize {
        self.ops.len()
    }

    /// True when the expression folded to a constant (it names no
    /// variable).
    pub fn is_constant(&self) -> bool {
        matches!(self.ops.as_slice(), [Op::Const(_)])
    }

    /// The value at `p`.
    #[inline]
    pub fn eval(&self, p: Vec3) -> f64 {
        let vars = [p.x, p.y, p.z];
        let mut stack = [0.0f64; MAX_DEPTH];
        let mut top = 0usize;
        for op in &self.ops {
            match *op {
                Op::Const(c) => {
                    stack[top] = c;
                    top += 1;
                }
                Op::Var(i) => {
                    stack[top] = vars[i as usize];
                    top += 1;
                }
                Op::Unary(f) => stack[top - 1] = f.apply(stack[top - 1]),
                Op::Binary(f) => {
                    top -= 1;
                    stack[top - 1] = f.apply(stack[top - 1], stack[top]);
                }
            }
        }
        stack[0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(text: &str, x: f64, y: f64, z: f64) -> f64 {
        Expression::parse(text).unwrap().eval(Vec3::new(x, y, z))
    }

    fn error(text: &str) -> (usize, String) {
        let e = Expression::parse(text).unwrap_err();
        (e.offset, e.message)
    }

    #[test]
    fn arithmetic_follows_precedence() {
        assert_eq!(at("1 + 2 * 3", 0.0, 0.0, 0.0), 7.0);
        assert_eq!(at("(1 + 2) * 3", 0.0, 0.0, 0.0), 9.0);
        assert_eq!(at("8 / 4 / 2", 0.0, 0.0, 0.0), 1.0);
        assert_eq!(at("8 - 4 - 2", 0.0, 0.0, 0.0), 2.0);
        assert_eq!(at("2 * x - y / 4", 3.0, 8.0, 0.0), 4.0);
    }

    #[test]
    fn unary_minus_binds_looser_than_power() {
        assert_eq!(at("-x^2", 3.0, 0.0, 0.0), -9.0);
        assert_eq!(at("(-x)^2", 3.0, 0.0, 0.0), 9.0);
        assert_eq!(at("2^-x", 1.0, 0.0, 0.0), 0.5);
        assert_eq!(at("- -x", 3.0, 0.0, 0.0), 3.0);
        assert_eq!(at("+x", 3.0, 0.0, 0.0), 3.0);
    }

    #[test]
    fn power_is_right_associative() {
        assert_eq!(at("2^3^2", 0.0, 0.0, 0.0), 512.0);
        assert_eq!(at("x^y^z", 2.0, 3.0, 2.0), 512.0);
        assert_eq!(at("(x^y)^z", 2.0, 3.0, 2.0), 64.0);
    }

    #[test]
    fn numbers_variables_and_pi() {
        assert_eq!(at("1.5e2 + .5 + 2.", 0.0, 0.0, 0.0), 152.5);
        assert_eq!(at("1e-3", 0.0, 0.0, 0.0), 1e-3);
        assert_eq!(at("x + 10*y + 100*z", 1.0, 2.0, 3.0), 321.0);
        assert_eq!(at("pi", 0.0, 0.0, 0.0), std::f64::consts::PI);
    }

    #[test]
    fn every_function_evaluates() {
        let cases: &[(&str, f64)] = &[
            ("sin(x)", 0.5f64.sin()),
            ("cos(x)", 0.5f64.cos()),
            ("tan(x)", 0.5f64.tan()),
            ("asin(x)", 0.5f64.asin()),
            ("acos(x)", 0.5f64.acos()),
            ("atan(x)", 0.5f64.atan()),
            ("atan2(x, y)", 0.5f64.atan2(-2.0)),
            ("sqrt(x)", 0.5f64.sqrt()),
            ("abs(y)", 2.0),
            ("min(x, y)", -2.0),
            ("max(x, y)", 0.5),
            ("exp(x)", 0.5f64.exp()),
            ("ln(x)", 0.5f64.ln()),
            ("pow(x, z)", 0.5f64.powf(1.5)),
            ("x^z", 0.5f64.powf(1.5)),
            ("floor(y + 0.5)", -2.0),
            ("y^3", -8.0),
        ];
        for &(text, expected) in cases {
            let got = at(text, 0.5, -2.0, 1.5);
            assert!(
                (got - expected).abs() <= 1e-15,
                "{text}: {got} != {expected}"
            );
        }
    }

    #[test]
    fn constants_are_folded() {
        let e = Expression::parse("2 * pi * (1 + 3) - sqrt(16)").unwrap();
        assert!(e.is_constant());
        assert_eq!(e.eval(Vec3::ZERO), 8.0 * std::f64::consts::PI - 4.0);
        let e = Expression::parse("x * (2 + 3)").unwrap();
        assert_eq!(e.ops.len(), 3, "{:?}", e.ops);
    }

    #[test]
    fn errors_name_the_column_and_what_was_expected() {
        assert_eq!(error(""), (0, "the expression is empty".into()));
        assert_eq!(error("   "), (0, "the expression is empty".into()));
        assert_eq!(
            error("x + w"),
            (4, "unknown variable `w`; expected x, y, z or pi".into())
        );
        let (offset, message) = error("x + foo(y)");
        assert_eq!(offset, 4);
        assert!(message.starts_with("unknown function `foo`; expected one of: sin"));
        assert_eq!(
            error("1 + sin(x, y)"),
            (4, "`sin` takes 1 argument, found 2".into())
        );
        assert_eq!(
            error("max(x)"),
            (0, "`max` takes 2 arguments, found 1".into())
        );
        assert_eq!(
            error("x * (y + 1"),
            (10, "expected `)`, found the end of the expression".into())
        );
        assert_eq!(
            error("x + * y"),
            (
                4,
                "expected a number, a variable, a function or `(`, found `*`".into()
            )
        );
        assert_eq!(error("x y"), (2, "expected an operator, found `y`".into()));
        assert_eq!(error("x $ y"), (2, "unexpected character `$`".into()));
        assert_eq!(
            error("sqrt + 1"),
            (0, "`sqrt` is a function: write `sqrt(...)`".into())
        );
        assert_eq!(error("1e999"), (0, "`1e999` is too large".into()));
        assert_eq!(error("1..2"), (0, "`1..2` is not a number".into()));
        assert_eq!(
            error("min(x y)"),
            (6, "expected `,` or `)`, found `y`".into())
        );
    }

    #[test]
    fn deep_nesting_is_refused_not_overflowed() {
        let deep = format!("{}x{}", "(".repeat(1000), ")".repeat(1000));
        assert!(error(&deep).1.contains("nests more than"));
        let minus = format!("{}x", "-".repeat(1000));
        assert!(error(&minus).1.contains("nests more than"));
        let long = "x+".repeat(MAX_LENGTH);
        assert!(error(&long).1.contains("longer than"));
        // A long flat sum needs a stack of two.
        let sum = format!("{}x", "x+".repeat(1000));
        assert_eq!(at(&sum, 1.0, 0.0, 0.0), 1001.0);
    }

    #[test]
    fn right_leaning_chains_within_the_limit_evaluate() {
        let chain = format!("{}x{}", "x+(".repeat(30), ")".repeat(30));
        assert_eq!(at(&chain, 1.0, 0.0, 0.0), 31.0);
    }
}
