//! The case-file expression language and its lowering to trigonometric polynomials.
//!
//! Grammar: numbers, parameter and coordinate names, `pi`, binary `+ - * /`, `^` with a
//! non-negative integer exponent, unary minus, parentheses, and `cos(..)`, `sin(..)` of an angle
//! expression. Everything a trigonometric polynomial cannot hold is refused with the offending
//! part named: other functions (`sqrt`, `atan2` of coordinates), division by anything that is not constant
//! (`1/th2`), non-integer or negative powers, bare angles outside `cos`/`sin`, and `cos`/`sin` of
//! anything but an integer combination of angle coordinates plus a constant (`cos(th1*th2)`,
//! `cos(th1/2)`).
//!
//! `atan2(y, x)` of constants names a constant angle; with rational `x`, `y` and a rational
//! hypotenuse (`atan2(4, 3)`: cosine 3/5, sine 4/5) the rotation it makes stays exact over ℚ,
//! and with `x`, `y` and the hypotenuse in ℚ(√2, √3) (`atan2(1, 1)` = π/4) exact over that field
//! (see [`crate::field_surd`]).
//!
//! Lowering is generic over the coefficient [`Field`]: the same code builds the numeric
//! polynomials and, for the balance decision, the exact ones.

use std::collections::BTreeMap;

use crate::angle::LinearAngle;
use crate::field::Field;
use crate::monomial::VarKind;
use crate::poly::Poly;
use crate::scalar::Rational;

/// Why an expression was refused: the whole expression, the offending part and the reason.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("expression `{expr}`: {reason} (at `{part}`)")]
pub struct ExprError {
    pub expr: String,
    pub part: String,
    pub reason: String,
}

/// Size limits of one expression.
///
/// The parser and the lowering recurse once per nesting level, so an unbounded depth would let
/// a case file (12,000 nested parentheses, a 20,000-term sum) overflow the stack; the length
/// bound keeps a single field from costing more than a few milliseconds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExprLimits {
    /// Most bytes of source text.
    pub length: usize,
    /// Deepest syntax tree: each parenthesis, unary sign, function call and each operator of
    /// a chain (`a + b + c` is two levels) adds one level.
    pub depth: usize,
}

/// Default [`ExprLimits::length`].
pub const MAX_EXPRESSION_LENGTH: usize = 10_000;
/// Default [`ExprLimits::depth`]: far beyond any hand-written pose, far below what the stack of
/// a 2 MB thread holds.
pub const MAX_EXPRESSION_DEPTH: usize = 256;

impl Default for ExprLimits {
    fn default() -> Self {
        ExprLimits {
            length: MAX_EXPRESSION_LENGTH,
            depth: MAX_EXPRESSION_DEPTH,
        }
    }
}

/// Names known to expressions: parameters and the chart coordinates (index = position), over
/// the coefficient field `F` ([`ExprContext`] for `f64`, [`ExactContext`] for exact rationals).
#[derive(Clone, Debug)]
pub struct Context<F: Field> {
    parameters: BTreeMap<String, F::Constant>,
    coordinates: Vec<(String, VarKind)>,
    limits: ExprLimits,
}

/// An angle as `(integer multiples of angle coordinates, sorted by index; constant part)`.
pub type AngleParts<C> = (Vec<(usize, i32)>, C);

/// The numeric expression context (the model's workhorse).
pub type ExprContext = Context<f64>;
/// The exact expression context: numbers are the decimals written, `pi` and `atan2` are tracked
/// symbolically, and anything irrational outside a rotation angle is refused as not exact.
pub type ExactContext = Context<Rational>;

impl<F: Field> Default for Context<F> {
    fn default() -> Self {
        Context {
            parameters: BTreeMap::new(),
            coordinates: Vec::new(),
            limits: ExprLimits::default(),
        }
    }
}

impl<F: Field> Context<F> {
    pub fn new(
        parameters: BTreeMap<String, F::Constant>,
        coordinates: Vec<(String, VarKind)>,
    ) -> Self {
        Context {
            parameters,
            coordinates,
            limits: ExprLimits::default(),
        }
    }

    /// The same context with other size limits.
    pub fn with_limits(mut self, limits: ExprLimits) -> Self {
        self.limits = limits;
        self
    }

    pub fn coordinates(&self) -> &[(String, VarKind)] {
        &self.coordinates
    }

    /// Parses an expression that must be a trigonometric polynomial in the coordinates.
    pub fn parse_poly(&self, src: &str) -> Result<Poly<F>, ExprError> {
        let (ast, span) = self.parse(src)?;
        match self.lower(src, &ast)? {
            Value::Poly(p) => Ok(p),
            Value::Affine(a) if a.angles.is_empty() => Ok(Poly::constant(
                F::to_scalar(&a.constant).map_err(|reason| error(src, span, &reason))?,
            )),
            Value::Affine(_) => Err(error(
                src,
                span,
                "a bare angle is not a trigonometric polynomial; use cos(..) or sin(..)",
            )),
        }
    }

    /// Parses an angle: integer multiples of angle coordinates (sorted by index) and a constant.
    pub fn parse_angle_parts(&self, src: &str) -> Result<AngleParts<F::Constant>, ExprError> {
        let (ast, span) = self.parse(src)?;
        let value = self.lower(src, &ast)?;
        to_angle(src, span, value)
    }

    /// `(cos φ, sin φ)` of an angle expression `φ`, as polynomials over `F`.
    pub fn parse_cos_sin(&self, src: &str) -> Result<(Poly<F>, Poly<F>), ExprError> {
        let (ast, span) = self.parse(src)?;
        let value = self.lower(src, &ast)?;
        let (terms, constant) = to_angle(src, span, value)?;
        let (c0, s0) = F::cos_sin(&constant).map_err(|reason| error(src, span, &reason))?;
        Ok(LinearAngle { terms, offset: 0.0 }.expand(c0, s0))
    }

    /// Parses an expression that must not depend on any coordinate.
    pub fn parse_constant(&self, src: &str) -> Result<F::Constant, ExprError> {
        let (ast, span) = self.parse(src)?;
        match self.lower(src, &ast)? {
            Value::Affine(a) if a.angles.is_empty() => Ok(a.constant),
            Value::Poly(p) if p.is_constant() => Ok(F::from_scalar(p.constant_term())),
            _ => Err(error(src, span, "must be a constant (no coordinates)")),
        }
    }

    fn parse(&self, src: &str) -> Result<(Node, Span), ExprError> {
        if src.len() > self.limits.length {
            return Err(error(
                src,
                Span { start: 0, end: 0 },
                &format!(
                    "the expression has {} bytes; the limit is {}",
                    src.len(),
                    self.limits.length
                ),
            ));
        }
        let tokens = tokenize(src)?;
        let mut parser = Parser {
            src,
            tokens,
            pos: 0,
            nesting: 0,
            max_depth: self.limits.depth,
        };
        let node = parser.expression(0)?;
        if let Some(tok) = parser.tokens.get(parser.pos) {
            return Err(error(src, tok.span, "unexpected token"));
        }
        let span = node.span;
        Ok((node, span))
    }

    fn lower(&self, src: &str, node: &Node) -> Result<Value<F>, ExprError> {
        let span = node.span;
        let here = |reason: String| error(src, span, &reason);
        match &node.kind {
            NodeKind::Number(x) => Ok(Value::constant(F::literal(*x).map_err(here)?)),
            NodeKind::Name(name) => self.lower_name(src, span, name),
            NodeKind::Neg(inner) => self.lower(src, inner)?.negate(src, span),
            NodeKind::Binary(op, lhs, rhs) => {
                let a = self.lower(src, lhs)?;
                let b = self.lower(src, rhs)?;
                match op {
                    '+' => add(src, span, a, b),
                    '-' => add(src, span, a, b.negate(src, span)?),
                    '*' => multiply(src, span, a, b),
                    '/' => {
                        let divisor = b.as_constant().ok_or_else(|| {
                            error(src, rhs.span, "division by a non-constant expression")
                        })?;
                        if F::constant_value(&divisor) == 0.0 {
                            return Err(error(src, rhs.span, "division by zero"));
                        }
                        let inverse = F::reciprocal(&divisor)
                            .map_err(|reason| error(src, rhs.span, &reason))?;
                        a.scale(src, span, &inverse)
                    }
                    '^' => {
                        let exponent = b.as_constant().ok_or_else(|| {
                            error(src, rhs.span, "exponent must be a constant integer")
                        })?;
                        let exponent = F::constant_value(&exponent);
                        if exponent < 0.0 || exponent.fract() != 0.0 || exponent > 64.0 {
                            return Err(error(
                                src,
                                rhs.span,
                                "exponent must be an integer between 0 and 64",
                            ));
                        }
                        power(src, lhs.span, a, exponent as u32)
                    }
                    _ => unreachable!("parser only builds + - * / ^"),
                }
            }
            NodeKind::Call(function, args) => match function.as_str() {
                "cos" | "sin" => {
                    if args.len() != 1 {
                        return Err(error(src, span, "cos and sin take exactly one argument"));
                    }
                    let argument = self.lower(src, &args[0])?;
                    let (terms, constant) = to_angle(src, args[0].span, argument)?;
                    let (c0, s0) = F::cos_sin(&constant)
                        .map_err(|reason| error(src, args[0].span, &reason))?;
                    let (c, s) = LinearAngle { terms, offset: 0.0 }.expand(c0, s0);
                    Ok(Value::Poly(if function == "cos" { c } else { s }))
                }
                "atan2" => {
                    if args.len() != 2 {
                        return Err(error(src, span, "atan2 takes exactly two arguments (y, x)"));
                    }
                    let constant = |arg: &Node| -> Result<F::Constant, ExprError> {
                        self.lower(src, arg)?.as_constant().ok_or_else(|| {
                            error(src, arg.span, "atan2 takes constant arguments only")
                        })
                    };
                    let (y, x) = (constant(&args[0])?, constant(&args[1])?);
                    if F::constant_value(&y) == 0.0 && F::constant_value(&x) == 0.0 {
                        return Err(error(src, span, "atan2(0, 0) is undefined"));
                    }
                    Ok(Value::constant(F::atan2(&y, &x).map_err(here)?))
                }
                _ => Err(error(
                    src,
                    span,
                    &format!("function `{function}` is not allowed (only cos, sin and atan2)"),
                )),
            },
        }
    }

    fn lower_name(&self, src: &str, span: Span, name: &str) -> Result<Value<F>, ExprError> {
        if let Some(k) = self.coordinates.iter().position(|(n, _)| n == name) {
            return Ok(match self.coordinates[k].1 {
                VarKind::Angle => Value::Affine(Affine {
                    angles: BTreeMap::from([(k, 1.0)]),
                    constant: F::zero_constant(),
                }),
                VarKind::Length => Value::Poly(Poly::length(k)),
            });
        }
        if let Some(value) = self.parameters.get(name) {
            return Ok(Value::constant(value.clone()));
        }
        if name == "pi" {
            return Ok(Value::constant(F::pi()));
        }
        Err(error(
            src,
            span,
            "unknown name (not a parameter or coordinate)",
        ))
    }
}

impl ExprContext {
    /// Parses an angle: an integer combination of angle coordinates plus a constant.
    pub fn parse_angle(&self, src: &str) -> Result<LinearAngle, ExprError> {
        let (terms, offset) = self.parse_angle_parts(src)?;
        Ok(LinearAngle { terms, offset })
    }
}

/// An intermediate value: either a trigonometric polynomial, or an affine combination of bare
/// angle coordinates (which is only valid inside `cos`/`sin` or as a rotation angle).
#[derive(Clone, Debug)]
enum Value<F: Field> {
    Poly(Poly<F>),
    Affine(Affine<F>),
}

#[derive(Clone, Debug)]
struct Affine<F: Field> {
    /// Multiples of angle coordinates (integers once validated by [`to_angle`]).
    angles: BTreeMap<usize, f64>,
    constant: F::Constant,
}

impl<F: Field> Value<F> {
    fn constant(c: F::Constant) -> Self {
        Value::Affine(Affine {
            angles: BTreeMap::new(),
            constant: c,
        })
    }

    fn as_constant(&self) -> Option<F::Constant> {
        match self {
            Value::Affine(a) if a.angles.is_empty() => Some(a.constant.clone()),
            Value::Poly(p) if p.is_constant() => Some(F::from_scalar(p.constant_term())),
            _ => None,
        }
    }

    fn negate(self, src: &str, span: Span) -> Result<Self, ExprError> {
        self.scale(src, span, &F::literal(-1.0).expect("-1 is a number"))
    }

    fn scale(self, src: &str, span: Span, s: &F::Constant) -> Result<Self, ExprError> {
        let here = |reason: String| error(src, span, &reason);
        Ok(match self {
            Value::Poly(p) => Value::Poly(p.scale(F::to_scalar(s).map_err(here)?)),
            Value::Affine(a) => {
                let factor = F::constant_value(s);
                Value::Affine(Affine {
                    angles: a.angles.into_iter().map(|(k, n)| (k, n * factor)).collect(),
                    constant: F::mul_constants(&a.constant, s).map_err(here)?,
                })
            }
        })
    }
}

fn bare_angle_error(src: &str, span: Span) -> ExprError {
    error(
        src,
        span,
        "a bare angle cannot be combined with a polynomial; use cos(..) or sin(..)",
    )
}

fn add<F: Field>(src: &str, span: Span, a: Value<F>, b: Value<F>) -> Result<Value<F>, ExprError> {
    match (a, b) {
        (Value::Affine(mut x), Value::Affine(y)) => {
            for (k, n) in y.angles {
                *x.angles.entry(k).or_insert(0.0) += n;
            }
            x.angles.retain(|_, n| *n != 0.0);
            x.constant = F::add_constants(&x.constant, &y.constant);
            Ok(Value::Affine(x))
        }
        (Value::Poly(p), Value::Affine(a)) | (Value::Affine(a), Value::Poly(p)) => {
            if !a.angles.is_empty() {
                return Err(bare_angle_error(src, span));
            }
            let c = F::to_scalar(&a.constant).map_err(|reason| error(src, span, &reason))?;
            Ok(Value::Poly(&p + &Poly::constant(c)))
        }
        (Value::Poly(p), Value::Poly(q)) => Ok(Value::Poly(&p + &q)),
    }
}

fn multiply<F: Field>(
    src: &str,
    span: Span,
    a: Value<F>,
    b: Value<F>,
) -> Result<Value<F>, ExprError> {
    if let Some(c) = a.as_constant() {
        return b.scale(src, span, &c);
    }
    if let Some(c) = b.as_constant() {
        return a.scale(src, span, &c);
    }
    match (a, b) {
        (Value::Poly(p), Value::Poly(q)) => {
            check_degree(src, span, p.max_power() + q.max_power())?;
            Ok(Value::Poly(&p * &q))
        }
        (Value::Affine(_), Value::Affine(_)) => Err(error(
            src,
            span,
            "a product of angles is not a trigonometric polynomial",
        )),
        _ => Err(bare_angle_error(src, span)),
    }
}

fn power<F: Field>(src: &str, span: Span, a: Value<F>, n: u32) -> Result<Value<F>, ExprError> {
    if let Some(c) = a.as_constant() {
        let value = F::pow_constant(&c, n).map_err(|reason| error(src, span, &reason))?;
        return Ok(Value::constant(value));
    }
    match a {
        Value::Poly(p) => {
            check_degree(src, span, p.max_power().saturating_mul(n))?;
            Ok(Value::Poly(p.pow(n)))
        }
        Value::Affine(_) if n == 1 => Ok(a),
        Value::Affine(_) => Err(error(
            src,
            span,
            "a power of an angle is not a trigonometric polynomial",
        )),
    }
}

/// Highest power of one coordinate an expression may reach (monomials store powers in a byte).
pub const MAX_DEGREE: u32 = 128;

fn check_degree(src: &str, span: Span, degree: u32) -> Result<(), ExprError> {
    if degree > MAX_DEGREE {
        return Err(error(
            src,
            span,
            &format!("degree {degree} exceeds the supported {MAX_DEGREE} in one coordinate"),
        ));
    }
    Ok(())
}

fn to_angle<F: Field>(
    src: &str,
    span: Span,
    value: Value<F>,
) -> Result<AngleParts<F::Constant>, ExprError> {
    let affine = match value {
        Value::Affine(a) => a,
        Value::Poly(p) if p.is_constant() => Affine {
            angles: BTreeMap::new(),
            constant: F::from_scalar(p.constant_term()),
        },
        Value::Poly(_) => {
            return Err(error(
                src,
                span,
                "an angle must be an integer combination of angle coordinates plus a constant",
            ));
        }
    };
    let mut terms = Vec::new();
    for (k, n) in affine.angles {
        let rounded = n.round();
        if (n - rounded).abs() > 1e-12 || rounded.abs() > 64.0 {
            return Err(error(
                src,
                span,
                &format!("angle multiples must be integers (found {n})"),
            ));
        }
        if rounded != 0.0 {
            terms.push((k, rounded as i32));
        }
    }
    Ok((terms, affine.constant))
}

// ---------------------------------------------------------------- tokens and parser

#[derive(Clone, Copy, Debug, PartialEq)]
struct Span {
    start: usize,
    end: usize,
}

impl Span {
    fn join(self, other: Span) -> Span {
        Span {
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }
}

/// Longest expression or part quoted in an error, in characters: a 10,000-byte expression is
/// named by its start, not printed whole.
const MAX_QUOTED: usize = 120;

fn quote(text: &str) -> String {
    match text.char_indices().nth(MAX_QUOTED) {
        None => text.to_string(),
        Some((cut, _)) => format!("{}…", &text[..cut]),
    }
}

fn error(src: &str, span: Span, reason: &str) -> ExprError {
    ExprError {
        expr: quote(src),
        part: quote(src.get(span.start..span.end).unwrap_or(src)),
        reason: reason.to_string(),
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Number(f64),
    Name(String),
    Op(char),
    Open,
    Close,
    Comma,
}

#[derive(Clone, Debug)]
struct Token {
    tok: Tok,
    span: Span,
}

fn tokenize(src: &str) -> Result<Vec<Token>, ExprError> {
    let bytes = src.as_bytes();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let ch = bytes[i] as char;
        let start = i;
        if ch.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        let tok = if ch.is_ascii_digit() || ch == '.' {
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                i += 1;
            }
            if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
                let mut j = i + 1;
                if j < bytes.len() && (bytes[j] == b'+' || bytes[j] == b'-') {
                    j += 1;
                }
                if j < bytes.len() && bytes[j].is_ascii_digit() {
                    i = j;
                    while i < bytes.len() && bytes[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let text = &src[start..i];
            let value: f64 = text
                .parse()
                .map_err(|_| error(src, Span { start, end: i }, "malformed number"))?;
            Tok::Number(value)
        } else if ch.is_ascii_alphabetic() || ch == '_' {
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            Tok::Name(src[start..i].to_string())
        } else {
            i += 1;
            match ch {
                '+' | '-' | '*' | '/' | '^' => Tok::Op(ch),
                '(' => Tok::Open,
                ')' => Tok::Close,
                ',' => Tok::Comma,
                _ => {
                    // Step over a whole UTF-8 character so the span stays on a boundary.
                    while i < bytes.len() && !src.is_char_boundary(i) {
                        i += 1;
                    }
                    return Err(error(src, Span { start, end: i }, "unexpected character"));
                }
            }
        };
        tokens.push(Token {
            tok,
            span: Span { start, end: i },
        });
    }
    if tokens.is_empty() {
        return Err(ExprError {
            expr: quote(src),
            part: quote(src),
            reason: "empty expression".to_string(),
        });
    }
    Ok(tokens)
}

#[derive(Clone, Debug)]
struct Node {
    kind: NodeKind,
    span: Span,
    /// Height of the tree below and including this node (a leaf is 1).
    depth: usize,
}

#[derive(Clone, Debug)]
enum NodeKind {
    Number(f64),
    Name(String),
    Neg(Box<Node>),
    Binary(char, Box<Node>, Box<Node>),
    Call(String, Vec<Node>),
}

struct Parser<'a> {
    src: &'a str,
    tokens: Vec<Token>,
    pos: usize,
    /// Recursive calls of [`Parser::expression`] now active.
    nesting: usize,
    /// Deepest tree (and deepest recursion) allowed.
    max_depth: usize,
}

/// Binding powers (left, right): `^` is right-associative and binds tighter than unary minus.
fn infix_power(op: char) -> (u8, u8) {
    match op {
        '+' | '-' => (1, 2),
        '*' | '/' => (3, 4),
        '^' => (8, 7),
        _ => unreachable!(),
    }
}

const UNARY_MINUS_POWER: u8 = 5;

impl Parser<'_> {
    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.pos)
    }

    fn end_span(&self) -> Span {
        let end = self.src.len();
        Span { start: 0, end }
    }

    /// Refuses a tree deeper than the limit, naming the part that reached it.
    fn check_depth(&self, depth: usize, span: Span) -> Result<(), ExprError> {
        if depth > self.max_depth {
            return Err(error(
                self.src,
                span,
                &format!(
                    "the expression nests deeper than {} levels (parentheses, signs, calls and chained operators)",
                    self.max_depth
                ),
            ));
        }
        Ok(())
    }

    /// Builds a node one level above its deepest child, refusing it past the depth limit.
    fn node(&self, kind: NodeKind, span: Span, child_depth: usize) -> Result<Node, ExprError> {
        let depth = child_depth + 1;
        self.check_depth(depth, span)?;
        Ok(Node { kind, span, depth })
    }

    fn expression(&mut self, min_power: u8) -> Result<Node, ExprError> {
        // The recursion depth is bounded before recursing, so that no input can exhaust the
        // stack; the tree depth (which also grows along operator chains) is bounded in `node`.
        self.nesting += 1;
        let start = self.peek().map_or(self.end_span(), |t| t.span);
        self.check_depth(self.nesting, start)?;
        let result = self.expression_inner(min_power);
        self.nesting -= 1;
        result
    }

    fn expression_inner(&mut self, min_power: u8) -> Result<Node, ExprError> {
        let mut lhs = self.prefix()?;
        while let Some(Token {
            tok: Tok::Op(op), ..
        }) = self.peek().cloned()
        {
            let (left, right) = infix_power(op);
            if left < min_power {
                break;
            }
            self.pos += 1;
            let rhs = self.expression(right)?;
            let span = lhs.span.join(rhs.span);
            let depth = lhs.depth.max(rhs.depth);
            lhs = self.node(
                NodeKind::Binary(op, Box::new(lhs), Box::new(rhs)),
                span,
                depth,
            )?;
        }
        Ok(lhs)
    }

    fn prefix(&mut self) -> Result<Node, ExprError> {
        let Some(token) = self.peek().cloned() else {
            return Err(error(
                self.src,
                self.end_span(),
                "unexpected end of expression",
            ));
        };
        self.pos += 1;
        match token.tok {
            Tok::Number(x) => self.node(NodeKind::Number(x), token.span, 0),
            Tok::Op('-') => {
                let inner = self.expression(UNARY_MINUS_POWER)?;
                let span = token.span.join(inner.span);
                let depth = inner.depth;
                self.node(NodeKind::Neg(Box::new(inner)), span, depth)
            }
            Tok::Op('+') => self.expression(UNARY_MINUS_POWER),
            Tok::Open => {
                let inner = self.expression(0)?;
                self.expect_close(token.span)?;
                Ok(inner)
            }
            Tok::Name(name) => {
                if matches!(self.peek(), Some(Token { tok: Tok::Open, .. })) {
                    self.pos += 1;
                    let mut args = vec![self.expression(0)?];
                    while matches!(
                        self.peek(),
                        Some(Token {
                            tok: Tok::Comma,
                            ..
                        })
                    ) {
                        self.pos += 1;
                        args.push(self.expression(0)?);
                    }
                    let close = self.expect_close(token.span)?;
                    let depth = args.iter().map(|a| a.depth).max().unwrap_or(0);
                    self.node(NodeKind::Call(name, args), token.span.join(close), depth)
                } else {
                    self.node(NodeKind::Name(name), token.span, 0)
                }
            }
            _ => Err(error(self.src, token.span, "unexpected token")),
        }
    }

    fn expect_close(&mut self, open: Span) -> Result<Span, ExprError> {
        match self.peek() {
            Some(Token {
                tok: Tok::Close,
                span,
            }) => {
                let span = *span;
                self.pos += 1;
                Ok(span)
            }
            _ => Err(error(self.src, open, "unclosed parenthesis")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Point;

    fn context() -> ExprContext {
        ExprContext::new(
            BTreeMap::from([("d1".to_string(), 0.3), ("d4".to_string(), 0.25)]),
            vec![
                ("th1".to_string(), VarKind::Angle),
                ("th2".to_string(), VarKind::Angle),
                ("rho".to_string(), VarKind::Length),
            ],
        )
    }

    const KINDS: [VarKind; 3] = [VarKind::Angle, VarKind::Angle, VarKind::Length];

    #[test]
    fn evaluates_like_the_formula() {
        let ctx = context();
        let p = ctx
            .parse_poly("d1*cos(th1) - d4*sin(2*th2 - th1 + pi/4)^2 + rho^3/2 - -1")
            .unwrap();
        let q = [0.4, -0.9, 1.7];
        let expected = 0.3 * 0.4f64.cos()
            - 0.25
                * (2.0 * -0.9 - 0.4 + std::f64::consts::FRAC_PI_4)
                    .sin()
                    .powi(2)
            + 1.7f64.powi(3) / 2.0
            + 1.0;
        assert!((p.eval(&Point::new(&q, &KINDS)) - expected).abs() < 1e-13);
    }

    #[test]
    fn power_binds_tighter_than_unary_minus() {
        let ctx = context();
        assert_eq!(ctx.parse_constant("-2^2").unwrap(), -4.0);
        assert_eq!(ctx.parse_constant("2^3^2").unwrap(), 512.0);
        assert_eq!(ctx.parse_constant("1e-3*2").unwrap(), 0.002);
    }

    #[test]
    fn angle_parse() {
        let ctx = context();
        let a = ctx.parse_angle("-th2 + 2*th1 + pi/2").unwrap();
        assert_eq!(a.terms, vec![(0, 2), (1, -1)]);
        assert!((a.offset - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    fn refused(src: &str, part: &str) {
        let err = context().parse_poly(src).unwrap_err();
        assert_eq!(err.part, part, "{err}");
        assert!(err.to_string().contains(src), "{err}");
    }

    #[test]
    fn refuses_what_is_not_a_trig_polynomial() {
        refused("sqrt(2)", "sqrt(2)");
        refused("1 + atan2(th1, th2)", "th1");
        refused("cos(th1*th2)", "th1*th2");
        refused("1/th2", "th2");
        refused("d1/rho", "rho");
        refused("cos(th1/2)", "th1/2");
        refused("cos(rho)", "rho");
        refused("th1 + cos(th2)", "th1 + cos(th2)");
        refused("th1", "th1");
        refused("rho^-1", "-1");
        refused("rho^0.5", "0.5");
        refused("foo + 1", "foo");
        refused("cos(th1", "cos");
        refused("(th1 + 2", "(");
        refused("2 $ 3", "$");
        refused("1 2", "2");
        refused(
            "cos(th1)^64*cos(th1)^64*cos(th1)^64",
            "cos(th1)^64*cos(th1)^64*cos(th1)^64",
        );
        refused("(rho^60)^3", "rho^60");
    }

    /// Runs `work` on a thread with a 2 MB stack (a test thread's default), so that a
    /// recursion the limits fail to bound shows up as a crash here.
    fn on_small_stack<T: Send + 'static>(work: impl FnOnce() -> T + Send + 'static) -> T {
        std::thread::Builder::new()
            .stack_size(2 << 20)
            .spawn(work)
            .unwrap()
            .join()
            .unwrap()
    }

    #[test]
    fn hostile_nesting_is_refused_not_a_stack_overflow() {
        let depth = MAX_EXPRESSION_DEPTH;
        // Each under the length limit, so that the depth limit is what refuses it.
        let cases = [
            format!("{}1{}", "(".repeat(4_000), ")".repeat(4_000)),
            format!("{}1", "-".repeat(9_000)),
            format!("{}1", "+".repeat(9_000)),
            vec!["d1"; 3_000].join("+"),
            vec!["2"; 3_000].join("^"),
            format!("{}th1{}", "cos(".repeat(1_500), ")".repeat(1_500)),
        ];
        for src in cases {
            assert!(src.len() <= MAX_EXPRESSION_LENGTH);
            let shown = src.chars().take(20).collect::<String>();
            let err = on_small_stack(move || context().parse_poly(&src).unwrap_err());
            assert!(
                err.reason.contains(&format!("deeper than {depth}")),
                "{shown}: {err}"
            );
            assert!(
                err.expr.chars().count() <= 121,
                "the error quotes a clipped expression"
            );
        }
    }

    #[test]
    fn the_sizes_of_the_issue_are_refused_by_length() {
        for src in [
            format!("{}1{}", "(".repeat(12_000), ")".repeat(12_000)),
            format!("{}1", "-".repeat(30_000)),
            vec!["d1"; 20_000].join("+"),
        ] {
            let err = on_small_stack(move || context().parse_poly(&src).unwrap_err());
            assert!(err.reason.contains("the limit is 10000"), "{err}");
        }
    }

    #[test]
    fn nesting_up_to_the_limit_is_accepted_on_a_small_stack() {
        // A chain of n − 1 additions is a tree of depth n; nested parentheses add recursion but
        // no tree level; each unary minus adds one of both.
        let n = MAX_EXPRESSION_DEPTH;
        let sum = vec!["1"; n].join("+");
        assert_eq!(
            on_small_stack(move || context().parse_constant(&sum)),
            Ok(n as f64)
        );
        let parens = format!("{}2{}", "(".repeat(n - 1), ")".repeat(n - 1));
        assert_eq!(
            on_small_stack(move || context().parse_constant(&parens)),
            Ok(2.0)
        );
        let minus = format!("{}3", "-".repeat(n - 1));
        let expected = if (n - 1).is_multiple_of(2) { 3.0 } else { -3.0 };
        assert_eq!(
            on_small_stack(move || context().parse_constant(&minus)),
            Ok(expected)
        );
        let too_deep = vec!["1"; n + 1].join("+");
        assert!(on_small_stack(move || context().parse_constant(&too_deep)).is_err());
    }

    #[test]
    fn long_expressions_are_refused_by_length() {
        let long = format!("1{}", "+0".repeat(MAX_EXPRESSION_LENGTH));
        let err = context().parse_constant(&long).unwrap_err();
        assert!(err.reason.contains("the limit is 10000"), "{err}");
        assert!(err.to_string().len() < 400, "{err}");
        // With the length limit lifted the same text gets as far as the depth limit.
        let relaxed = context().with_limits(ExprLimits {
            length: 30_000,
            depth: MAX_EXPRESSION_DEPTH,
        });
        let err = on_small_stack(move || relaxed.parse_constant(&long).unwrap_err());
        assert!(err.reason.contains("deeper than"), "{err}");
    }
}
