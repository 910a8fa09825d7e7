// The kernel of IncrementalQr: folds m new rows B into the upper-triangular factor R of a least-
// squares system by Householder reflections on [R; B], in panels of four columns. Column j's
// reflector is v = (v0 e_j ; a) (a = column j of B after the earlier reflectors), so it touches row
// j of R and the rows of B only; four reflectors are applied to the trailing columns together:
//   s_i = beta_i (v0_i R(j0+i, c) + a_i' B_c - sum_{l<i} s_l a_i' a_l),  B_c -= sum_i s_i a_i,
// which reads and writes B once per panel instead of twice per column (Golub & Van Loan, blocked
// Householder QR). Same arithmetic as one reflector at a time, up to rounding.
#pragma once

namespace cvg_bench {

/// r: kk x kk upper triangle, column-major with leading dimension ldr (updated in place).
/// b: rows4 x kk, column-major with leading dimension ldb >= rows4, rows4 a multiple of 4 (pad with
/// zero rows); overwritten with the reflector vectors. Columns whose B part is zero get no
/// reflection (R row unchanged), as in the unblocked algorithm.
void householderPanelUpdate(double* r, int ldr, double* b, int ldb, int rows4, int kk);

}  // namespace cvg_bench
