//! Conjugate gradients preconditioned by a kept Cholesky factor, for the implicit step's
//! system (M + γ∆t C + β∆t² K) δa = r of paper 001 Eq. 26 after bonds broke or contacts
//! opened or closed since the factor was computed (issue 26).
//!
//! With P = L Lᵀ the factor of an earlier matrix A₀ and A = A₀ + ∆ the current one, P⁻¹A =
//! I + P⁻¹∆: a bond that breaks changes K by a block of rank at most 3 (Eq. 4 over the
//! (u, v, θ) of its two particles), a contact that opens or closes by one of rank at most 2
//! (Eq. 5), so for k such events P⁻¹A has at most 3k + 1 distinct eigenvalues and conjugate
//! gradients end in at most 3k + 1 iterations in exact arithmetic (the Krylov space of a
//! matrix with m distinct eigenvalues has dimension at most m). Each iteration is one product with
//! A and one pair of triangular solves with L, against a numeric factorisation for
//! refactorising; when the events have piled up and the count passes the caller's bound, the
//! caller refactorises.
//!
//! The start is x₀ = P⁻¹ b, the answer of the kept factor, and the stopping test is on the
//! preconditioned residual, √(rᵀP⁻¹r) ≤ tol · √(bᵀP⁻¹b): the error in the energy norm of P,
//! independent of the units of the DOFs (translations and rotations in one vector). Every
//! product and sum runs in one fixed order (sequentially), so the iterates are the same bits
//! on any number of threads.

use crate::solvers::sparse::SparseCholesky;
use faer::sparse::SparseColMatRef;

/// A kept factor whose answer is off by more than this, relative to the right-hand side in
/// its energy norm, is not tried. A stiff contact added since the factorisation puts P⁻¹A's
/// eigenvalue at about (ω∆t)²/4 of the contact's mode (10²–10⁴ for the beam at ∆t = 5 ms),
/// and the iterations then resolve each such direction in turn. Measured on the 0.025 m
/// benchmark beam: the solves that started within 0.4–1.2 converged in 2–6 iterations, those
/// that started near 10² in 4–8, and most of those that started above 10³ not in 12.
const FAR_OFF: f64 = 5.0;

/// The iterates' buffers, owned by the caller and reused from solve to solve.
#[derive(Clone, Debug, Default)]
pub(crate) struct Scratch {
    rhs: Vec<f64>,
    residual: Vec<f64>,
    preconditioned: Vec<f64>,
    direction: Vec<f64>,
    product: Vec<f64>,
}

impl Scratch {
    /// The right-hand side of the last [`solve`] as it was passed in.
    pub(crate) fn rhs(&self) -> &[f64] {
        &self.rhs
    }
}

/// Solves A x = b for the symmetric positive definite `a` (lower triangle), preconditioned by
/// `factor`; `x` holds b on entry and x on return. Ok with the number of iterations (0 when
/// the factor's answer already met `tolerance`), or Err with `max_iterations` if the residual
/// was still above it then, or with 0 if the factor's own answer was [`FAR_OFF`] (x then holds
/// the last iterate, [`Scratch::rhs`] still b).
pub(crate) fn solve(
    a: SparseColMatRef<'_, usize, f64>,
    factor: &mut SparseCholesky,
    x: &mut [f64],
    scratch: &mut Scratch,
    tolerance: f64,
    max_iterations: usize,
) -> Result<usize, usize> {
    let n = x.len();
    let Scratch {
        rhs,
        residual: r,
        preconditioned: z,
        direction: p,
        product: q,
    } = scratch;
    for buffer in [&mut *rhs, &mut *r, &mut *z, &mut *p, &mut *q] {
        buffer.resize(n, 0.0);
    }
    rhs.copy_from_slice(x);
    factor.solve_in_place(x);
    let scale = dot(rhs, x);
    if scale <= 0.0 {
        return Ok(0);
    }
    symmetric_product(a, x, q);
    for ((r, b), q) in r.iter_mut().zip(rhs.iter()).zip(q.iter()) {
        *r = b - q;
    }
    z.copy_from_slice(r);
    factor.solve_in_place(z);
    let mut rz = dot(r, z);
    if rz > FAR_OFF * FAR_OFF * scale {
        return Err(0);
    }
    let target = tolerance * tolerance * scale;
    p.copy_from_slice(z);
    for iteration in 0..max_iterations {
        if rz <= target {
            return Ok(iteration);
        }
        symmetric_product(a, p, q);
        let alpha = rz / dot(p, q);
        for (((x, r), p), q) in x.iter_mut().zip(r.iter_mut()).zip(p.iter()).zip(q.iter()) {
            *x += alpha * p;
            *r -= alpha * q;
        }
        z.copy_from_slice(r);
        factor.solve_in_place(z);
        let next = dot(r, z);
        let beta = next / rz;
        rz = next;
        for (p, z) in p.iter_mut().zip(z.iter()) {
            *p = z + beta * *p;
        }
    }
    if rz <= target {
        Ok(max_iterations)
    } else {
        Err(max_iterations)
    }
}

/// y ← A x for the symmetric `a` given by its lower triangle, column by column.
fn symmetric_product(a: SparseColMatRef<'_, usize, f64>, x: &[f64], y: &mut [f64]) {
    y.fill(0.0);
    for (j, &xj) in x.iter().enumerate() {
        let mut yj = 0.0;
        for (i, &v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            y[i] += v * xj;
            if i != j {
                yj += v * x[i];
            }
        }
        y[j] += yj;
    }
}

/// xᵀy, summed in index order.
fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};

    /// A chain of `n` unit masses joined by springs of stiffness `k[i]` between i and i + 1,
    /// the first also held by a spring to the ground: M + K, lower triangle.
    fn chain(k: &[f64]) -> SparseColMat<usize, f64> {
        let n = k.len() + 1;
        let mut entries = vec![Triplet::new(0, 0, 1.0 + 10.0)];
        entries.extend((1..n).map(|i| Triplet::new(i, i, 1.0)));
        for (i, &k) in k.iter().enumerate() {
            entries.push(Triplet::new(i, i, k));
            entries.push(Triplet::new(i + 1, i + 1, k));
            entries.push(Triplet::new(i + 1, i, -k));
        }
        SparseColMat::try_new_from_triplets(n, n, &entries).unwrap()
    }

    fn factor_of(a: &SparseColMat<usize, f64>) -> SparseCholesky {
        let mut factor = SparseCholesky::default();
        factor.factorize((a.as_ref(), 0.0), "test").unwrap();
        factor
    }

    #[test]
    fn springs_removed_since_the_factor_cost_at_most_one_iteration_each_plus_one() {
        let n = 200;
        let stiff: Vec<f64> = (0..n - 1).map(|i| 1e4 * (1.0 + (i % 7) as f64)).collect();
        let mut factor = factor_of(&chain(&stiff));
        // Three springs "break" (rank one each): at most 3 + 1 iterations.
        let mut broken = stiff.clone();
        for i in [17, 90, 150] {
            broken[i] = 0.0;
        }
        let a = chain(&broken);
        let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
        let mut x = b.clone();
        let mut scratch = Scratch::default();
        let iterations = solve(a.as_ref(), &mut factor, &mut x, &mut scratch, 1e-12, 50).unwrap();
        assert!(iterations <= 4, "{iterations} iterations");
        // The answer is A's: the residual against b at rounding, and the direct solve's.
        let mut ax = vec![0.0; n];
        symmetric_product(a.as_ref(), &x, &mut ax);
        let (res, norm) = (dot_diff(&ax, &b), dot(&b, &b).sqrt());
        assert!(res <= 1e-9 * norm, "residual {res} of {norm}");
        let mut direct = b.clone();
        factor_of(&a).solve_in_place(&mut direct);
        let error = dot_diff(&x, &direct) / dot(&direct, &direct).sqrt();
        assert!(error < 1e-9, "relative error {error}");
        assert_eq!(scratch.rhs(), &b[..]);
    }

    #[test]
    fn the_kept_factor_of_the_same_matrix_answers_without_iterating() {
        let k: Vec<f64> = (0..49).map(|i| 1.0 + i as f64).collect();
        let a = chain(&k);
        let mut factor = factor_of(&a);
        let mut x = vec![1.0; 50];
        let mut scratch = Scratch::default();
        assert_eq!(
            solve(a.as_ref(), &mut factor, &mut x, &mut scratch, 1e-10, 5),
            Ok(0)
        );
    }

    #[test]
    fn a_bound_too_small_for_the_changes_is_reported() {
        let stiff = vec![1e4; 99];
        let mut factor = factor_of(&chain(&stiff));
        let broken: Vec<f64> = (0..99)
            .map(|i| if i % 3 == 0 { 0.0 } else { 1e4 })
            .collect();
        let a = chain(&broken);
        let mut x: Vec<f64> = (0..100).map(|i| (i as f64).sin()).collect();
        let mut scratch = Scratch::default();
        assert_eq!(
            solve(a.as_ref(), &mut factor, &mut x, &mut scratch, 1e-12, 3),
            Err(3)
        );
    }

    fn dot_diff(x: &[f64], y: &[f64]) -> f64 {
        x.iter()
            .zip(y)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt()
    }
}
