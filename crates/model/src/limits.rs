//! Resource limits: the sizes beyond which a case file is refused before it can exhaust the
//! time, memory or stack of the machine.
//!
//! Every limit is set where a 2-core, 24 GB machine still answers in reasonable time (the
//! figures are in `docs/case-format.md`, section *Limits*), and each can be lifted explicitly
//! (`--limit NAME=VALUE` on the command line, or by editing a [`Limits`] in a program). A case
//! that exceeds one gets an error naming the field, the size found and the limit, *before* the
//! costly stage starts: the task count is computed from the grid axes, not by building the grid.

use std::fmt;
use std::str::FromStr;

use counterpoise_symbolic::{ExprLimits, MAX_EXPRESSION_DEPTH, MAX_EXPRESSION_LENGTH};

/// Highest power of one coordinate a body pose may reach. Not liftable: the symbolic core
/// stores powers in a byte and a spring's energy squares a pose, so 2·64 must stay below 256.
pub const MAX_POSE_DEGREE: u32 = 64;

/// The resource limits of loading and running a case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Size of the case file, bytes.
    pub file_bytes: u64,
    /// Entries of `parameters`.
    pub parameters: u64,
    /// Entries of any one list other than `parameters` (bodies, joints, payloads, paths,
    /// pose steps of a body, waypoints and sequence of a path).
    pub list_items: u64,
    /// Bytes of one expression.
    pub expression_length: u64,
    /// Depth of one expression's syntax tree.
    pub expression_depth: u64,
    /// Points of the task grid (the product of the axes' `n`).
    pub grid_points: u64,
    /// Time samples of one task (`tasks.samples`, `--samples`).
    pub samples: u64,
    /// Tasks × samples per task: the number of inverse-dynamics evaluations of one column.
    pub task_samples: u64,
    /// Most balancing elements per variant (`balancing.dmax`, `--dmax`).
    pub dmax: u64,
    /// Variants the balance search may enumerate (paper Eq. A8, counted before enumerating).
    pub variants: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            file_bytes: 16 << 20,
            parameters: 10_000,
            list_items: 10_000,
            expression_length: MAX_EXPRESSION_LENGTH as u64,
            expression_depth: MAX_EXPRESSION_DEPTH as u64,
            grid_points: 1_000,
            samples: 1_000,
            task_samples: 30_000_000,
            dmax: 8,
            variants: 30_000,
        }
    }
}

/// The name of one limit, as given to `--limit NAME=VALUE`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limit {
    FileBytes,
    Parameters,
    ListItems,
    ExpressionLength,
    ExpressionDepth,
    GridPoints,
    Samples,
    TaskSamples,
    Dmax,
    Variants,
}

impl Limit {
    pub const ALL: [Limit; 10] = [
        Limit::FileBytes,
        Limit::Parameters,
        Limit::ListItems,
        Limit::ExpressionLength,
        Limit::ExpressionDepth,
        Limit::GridPoints,
        Limit::Samples,
        Limit::TaskSamples,
        Limit::Dmax,
        Limit::Variants,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Limit::FileBytes => "file-bytes",
            Limit::Parameters => "parameters",
            Limit::ListItems => "list-items",
            Limit::ExpressionLength => "expression-length",
            Limit::ExpressionDepth => "expression-depth",
            Limit::GridPoints => "grid-points",
            Limit::Samples => "samples",
            Limit::TaskSamples => "task-samples",
            Limit::Dmax => "dmax",
            Limit::Variants => "variants",
        }
    }

    /// The hint appended to an error: how to lift the limit.
    pub fn hint(self) -> String {
        format!("raise it with --limit {}=N", self.name())
    }
}

impl fmt::Display for Limit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Limits {
    pub fn get(&self, limit: Limit) -> u64 {
        *self.field(limit)
    }

    pub fn set(&mut self, limit: Limit, value: u64) {
        *self.field_mut(limit) = value;
    }

    fn field(&self, limit: Limit) -> &u64 {
        match limit {
            Limit::FileBytes => &self.file_bytes,
            Limit::Parameters => &self.parameters,
            Limit::ListItems => &self.list_items,
            Limit::ExpressionLength => &self.expression_length,
            Limit::ExpressionDepth => &self.expression_depth,
            Limit::GridPoints => &self.grid_points,
            Limit::Samples => &self.samples,
            Limit::TaskSamples => &self.task_samples,
            Limit::Dmax => &self.dmax,
            Limit::Variants => &self.variants,
        }
    }

    fn field_mut(&mut self, limit: Limit) -> &mut u64 {
        match limit {
            Limit::FileBytes => &mut self.file_bytes,
            Limit::Parameters => &mut self.parameters,
            Limit::ListItems => &mut self.list_items,
            Limit::ExpressionLength => &mut self.expression_length,
            Limit::ExpressionDepth => &mut self.expression_depth,
            Limit::GridPoints => &mut self.grid_points,
            Limit::Samples => &mut self.samples,
            Limit::TaskSamples => &mut self.task_samples,
            Limit::Dmax => &mut self.dmax,
            Limit::Variants => &mut self.variants,
        }
    }

    /// Applies `NAME=VALUE` (the value may be written `1e7`).
    pub fn apply(&mut self, setting: &str) -> Result<(), String> {
        let (name, value) = setting
            .split_once('=')
            .ok_or_else(|| format!("expected NAME=VALUE, found `{setting}`"))?;
        let limit = Limit::from_str(name.trim())?;
        let value = parse_count(value.trim())
            .ok_or_else(|| format!("`{value}` is not a whole number ≥ 1"))?;
        self.set(limit, value);
        Ok(())
    }

    /// The limits of one expression, for the symbolic parser.
    pub fn expressions(&self) -> ExprLimits {
        ExprLimits {
            length: usize::try_from(self.expression_length).unwrap_or(usize::MAX),
            depth: usize::try_from(self.expression_depth).unwrap_or(usize::MAX),
        }
    }

    /// Stack a thread needs to parse expressions as deep as these limits allow (the parser and
    /// the lowering recurse once per level; a few kB per level is ample).
    pub fn stack_bytes(&self) -> usize {
        let per_level = 16 << 10;
        let depth = usize::try_from(self.expression_depth).unwrap_or(usize::MAX);
        (8usize << 20).saturating_add(depth.saturating_mul(per_level))
    }
}

/// A positive whole number, written plainly or in exponent form (`30000`, `3e4`).
fn parse_count(text: &str) -> Option<u64> {
    if let Ok(n) = text.parse::<u64>() {
        return (n >= 1).then_some(n);
    }
    let x: f64 = text.parse().ok()?;
    (x.is_finite() && x >= 1.0 && x.fract() == 0.0 && x <= u64::MAX as f64).then_some(x as u64)
}

impl FromStr for Limit {
    type Err = String;

    fn from_str(name: &str) -> Result<Limit, String> {
        Limit::ALL
            .into_iter()
            .find(|l| l.name() == name)
            .ok_or_else(|| {
                let names: Vec<&str> = Limit::ALL.iter().map(|l| l.name()).collect();
                format!("unknown limit `{name}` (one of {})", names.join(", "))
            })
    }
}

/// `n` with thousands separators, or in exponent form when huge (`1.2e13`).
pub fn format_count(n: f64) -> String {
    if !(n.is_finite() && n < 1e9) {
        return format!("{n:.1e}");
    }
    let digits = format!("{}", n.round() as u64);
    let mut out = String::new();
    for (k, ch) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k) % 3 == 0 {
            out.push(',');
        }
        out.push(ch);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_parse_and_round_trip() {
        let mut limits = Limits::default();
        limits.apply("grid-points=5000").unwrap();
        limits.apply("variants=1e6").unwrap();
        assert_eq!(limits.grid_points, 5000);
        assert_eq!(limits.get(Limit::Variants), 1_000_000);
        assert!(limits.apply("grid-points=0").is_err());
        assert!(limits.apply("grid-points=2.5").is_err());
        assert!(
            limits
                .apply("gridpoints=5")
                .unwrap_err()
                .contains("grid-points")
        );
        assert!(limits.apply("samples").is_err());
        for limit in Limit::ALL {
            assert_eq!(limit.name().parse::<Limit>(), Ok(limit));
        }
    }

    #[test]
    fn counts_print_readably() {
        assert_eq!(format_count(406.0), "406");
        assert_eq!(format_count(3_682.0), "3,682");
        assert_eq!(format_count(1_000_000.0), "1,000,000");
        assert_eq!(format_count(1.2e13), "1.2e13");
    }
}
