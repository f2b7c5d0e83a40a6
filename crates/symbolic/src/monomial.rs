//! Monomials of the canonical trigonometric-polynomial basis.
//!
//! A monomial is `Π_k c_k^{a_k} s_k^{b_k} x_k^{e_k}` where `c_k = cos q_k`, `s_k = sin q_k` for an
//! angle coordinate and `x_k = q_k` for a length coordinate. Since `sin² = 1 − cos²` is reduced on
//! every product, `b_k ∈ {0, 1}`; with that rule the monomials are linearly independent as
//! functions, so a polynomial's coefficient map is unique (canonical).
//!
//! One byte per coordinate holds the power (`a_k` for an angle, `e_k` for a length) and one bit per
//! coordinate holds the sine flag. A length coordinate never sets its sine bit, so the monomial
//! itself does not need to know the kind of a coordinate: only differentiation does.

/// Most chart coordinates a mechanism may have.
pub const MAX_VARS: usize = 12;

/// The kind of a chart coordinate: an angle enters through `cos`/`sin`, a length as itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VarKind {
    Angle,
    Length,
}

/// One basis monomial; ordered so that coefficient maps iterate deterministically.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Monomial {
    powers: [u8; MAX_VARS],
    sines: u16,
}

impl Monomial {
    /// The constant monomial `1`.
    pub const ONE: Monomial = Monomial {
        powers: [0; MAX_VARS],
        sines: 0,
    };

    /// `cos q_var` (angle) or `q_var` (length): the power of coordinate `var` raised by one.
    pub fn base(var: usize) -> Monomial {
        assert!(var < MAX_VARS, "coordinate index {var} exceeds {MAX_VARS}");
        let mut m = Monomial::ONE;
        m.powers[var] = 1;
        m
    }

    /// `sin q_var`.
    pub fn sine(var: usize) -> Monomial {
        assert!(var < MAX_VARS, "coordinate index {var} exceeds {MAX_VARS}");
        Monomial {
            powers: [0; MAX_VARS],
            sines: 1 << var,
        }
    }

    /// Power of `cos q_var` (angle) or of `q_var` (length).
    pub fn power(&self, var: usize) -> u8 {
        self.powers[var]
    }

    /// Whether `sin q_var` is a factor.
    pub fn has_sine(&self, var: usize) -> bool {
        self.sines & (1 << var) != 0
    }

    /// Whether this is the constant monomial.
    pub fn is_one(&self) -> bool {
        *self == Monomial::ONE
    }

    /// Total degree in all coordinates (powers plus sine flags).
    pub fn degree(&self) -> u32 {
        self.powers.iter().map(|&p| u32::from(p)).sum::<u32>() + self.sines.count_ones()
    }

    /// Coordinates this monomial depends on.
    pub fn variables(&self) -> impl Iterator<Item = usize> + '_ {
        (0..MAX_VARS).filter(|&k| self.powers[k] > 0 || self.has_sine(k))
    }

    pub(crate) fn with_power(mut self, var: usize, power: u8) -> Monomial {
        self.powers[var] = power;
        self
    }

    pub(crate) fn with_sine(mut self, var: usize, on: bool) -> Monomial {
        if on {
            self.sines |= 1 << var;
        } else {
            self.sines &= !(1 << var);
        }
        self
    }

    /// Product of two monomials before the `sin² = 1 − cos²` reduction: powers add, and the
    /// returned mask lists the coordinates whose sine appears squared.
    pub(crate) fn raw_product(&self, other: &Monomial) -> (Monomial, u16) {
        let mut m = Monomial::ONE;
        for k in 0..MAX_VARS {
            let p = u16::from(self.powers[k]) + u16::from(other.powers[k]);
            m.powers[k] = u8::try_from(p).expect("trigonometric polynomial degree overflow (>255)");
        }
        let squared = self.sines & other.sines;
        m.sines = self.sines ^ other.sines;
        (m, squared)
    }
}
