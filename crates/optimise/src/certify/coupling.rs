//! Which part of a spring's coupling error the branching has to remove.
//!
//! The relaxation replaces a spring's `W = K a⊗b` by convex envelopes, and the search splits the
//! anchor components that carry the error `E = (W·K − α⊗β)/K` at a box's relaxed point. Part of
//! that error may be no error at all: where the balanced family has directions that move the
//! spring's `W` block and no other lifted column (no other element, not the spring's own `K`,
//! `α = K a` or `β = K b`), moving along them changes nothing but `W`, and springs are massless,
//! so neither the motor torques nor any other constraint sees it. An error in the image of those
//! directions is removed by choosing `W = α⊗β/K` there, which every realization of the springs
//! does; splitting anchors to shrink it is wasted. On the palletizer, K54 joins upper_arm and
//! front_link, which both turn by θ3, and K76 rear_link and forearm, which both turn by −θ2:
//! `a·R(ψ_i − ψ_s)·b` is constant, `W` never enters the energy, and the whole block is free.
//! The split choice scores the error projected on the complement of that image.

use nalgebra::DMatrix;

use crate::problem::VariantProblem;

/// Per spring, the orthogonal projector (on its `W` block, row-major `i·nb + l`) onto the
/// complement of the errors the family removes: the identity where no direction moves `W`
/// alone, the zero matrix where every `W` does.
pub(crate) fn coupling_projectors(problem: &VariantProblem) -> Vec<DMatrix<f64>> {
    problem
        .springs
        .iter()
        .map(|s| {
            let (na, nb) = (s.axes_a.len(), s.axes_b.len());
            let first = s.column + 1 + na + nb;
            projector_off_private(&problem.nullspace, first, na * nb)
        })
        .collect()
}

/// Relative size below which a singular value counts as zero: the nullspace holds exact zeros
/// where an element does not enter, and rounding of order 1e-16 elsewhere.
const RANK_TOLERANCE: f64 = 1e-9;

/// The projector for the lifted rows `first..first + n` of the family's `nullspace` (one
/// column per free direction): the identity less the projector onto the block's image of the
/// directions that move no other row. The directions are those of the kernel of the other
/// rows, not single columns: a basis need not align with them.
fn projector_off_private(nullspace: &DMatrix<f64>, first: usize, n: usize) -> DMatrix<f64> {
    let mut projector = DMatrix::<f64>::identity(n, n);
    let block = first..first + n;
    let rest: Vec<usize> = (0..nullspace.nrows())
        .filter(|j| !block.contains(j))
        .collect();
    // The kernel of the other rows: the eigenvectors of their Gram matrix with eigenvalue zero
    // (a squared singular value, hence the squared tolerance).
    let others = nullspace.select_rows(&rest);
    let eigen = (others.transpose() * &others).symmetric_eigen();
    let largest = eigen.eigenvalues.amax().max(f64::MIN_POSITIVE);
    let kernel: Vec<usize> = (0..nullspace.ncols())
        .filter(|&c| eigen.eigenvalues[c].abs() <= RANK_TOLERANCE * RANK_TOLERANCE * largest)
        .collect();
    if kernel.is_empty() {
        return projector;
    }
    // The block's image of that kernel, and its orthonormal basis.
    let image = nullspace.rows(first, n) * eigen.eigenvectors.select_columns(&kernel);
    let svd = image.svd(true, false);
    let top = svd.singular_values.max();
    let Some(u) = svd.u.filter(|_| top > 0.0) else {
        return projector;
    };
    for (c, &value) in svd.singular_values.iter().enumerate() {
        if value > RANK_TOLERANCE * top {
            let direction = u.column(c);
            projector -= direction * direction.transpose();
        }
    }
    projector
}

#[cfg(test)]
mod tests {
    use super::projector_off_private;
    use nalgebra::DMatrix;

    /// The cosine and sine combinations of a planar `W` (row-major `W11, W12, W21, W22`), the
    /// only ones a relative rotation sees: `a·R(θ)·b = cos θ (W11 + W22) + sin θ (W12 − W21)`.
    fn rotation_seen() -> DMatrix<f64> {
        #[rustfmt::skip]
        let p = DMatrix::from_row_slice(4, 4, &[
            0.5, 0.0, 0.0, 0.5,
            0.0, 0.5, -0.5, 0.0,
            0.0, -0.5, 0.5, 0.0,
            0.5, 0.0, 0.0, 0.5,
        ]);
        p
    }

    /// A family of three directions over seven lifted rows, the `W` block at rows 2–5 between
    /// other rows: direction `u` moves the other rows and `W` along the seen combinations,
    /// `v` and `w` move `W` alone along the two unseen ones, `(1, 0, 0, −1)` and
    /// `(0, 1, 1, 0)`. The basis given mixes them (`u + v`, `u − v`, `w`), and its scale is
    /// `scale`: the projector must not depend on either, and it is by hand the projector onto
    /// the seen combinations.
    fn mixed_family(scale: f64, weak: f64) -> DMatrix<f64> {
        // Rows: other 0, other 1, W11, W12, W21, W22, other 6.
        let u = [1.0, -2.0, 1.0, 2.0, -2.0, 1.0, 0.5];
        let v = [0.0, 0.0, 1.0, 0.0, 0.0, -1.0, weak];
        let w = [0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0];
        DMatrix::from_fn(7, 3, |r, c| {
            scale
                * match c {
                    0 => u[r] + v[r],
                    1 => u[r] - v[r],
                    _ => w[r],
                }
        })
    }

    #[test]
    fn the_projector_keeps_what_other_rows_see_in_any_basis_and_scale() {
        for scale in [1.0, 1e-6, 1e3] {
            let p = projector_off_private(&mixed_family(scale, 0.0), 2, 4);
            assert!((&p - rotation_seen()).amax() <= 1e-9, "scale {scale}: {p}");
        }
    }

    /// A direction that moves another row a little is not private: with `v` also moving row
    /// 6 (after the block) by 1e-5 of its `W` part, only `w` is free, and the projector is the
    /// identity less the projector onto `(0, 1, 1, 0)/√2`.
    #[test]
    fn a_weak_coupling_to_another_row_is_still_a_coupling() {
        let p = projector_off_private(&mixed_family(1.0, 1e-5), 2, 4);
        let mut expected = DMatrix::<f64>::identity(4, 4);
        for (r, c) in [(1, 1), (1, 2), (2, 1), (2, 2)] {
            expected[(r, c)] -= 0.5;
        }
        assert!((&p - expected).amax() <= 1e-9, "{p}");
    }

    /// Where every direction moves another row the projector is the identity; where the block
    /// is moved by no direction at all, too (nothing to remove).
    #[test]
    fn without_private_directions_every_error_counts() {
        let coupled = DMatrix::from_fn(6, 2, |r, c| (r + 2 * c + 1) as f64);
        let p = projector_off_private(&coupled, 1, 4);
        assert!((&p - DMatrix::identity(4, 4)).amax() <= 1e-12, "{p}");
        let mut idle = DMatrix::<f64>::zeros(6, 2);
        idle[(0, 0)] = 1.0;
        idle[(5, 1)] = 1.0;
        let p = projector_off_private(&idle, 1, 4);
        assert!((&p - DMatrix::identity(4, 4)).amax() <= 1e-12, "{p}");
    }
}
