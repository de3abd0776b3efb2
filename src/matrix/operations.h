// rmtxop's operations on whole matrices, with RADIANCE's arithmetic order and the header info
// lines it adds ("Applied scalar", "Transposed rows and columns", ...).
#pragma once

#include <vector>

#include "matrix/matrices.h"

namespace dayflux {

// Multiplies component k by factors[k].
void Scale(Matrix *m, const std::vector<double> &factors);
// New components out_k = sum_j cmat[k * ncomp + j] * in_j, n = cmat.size() / ncomp.
Matrix TransformComponents(const Matrix &m, const std::vector<double> &cmat);
Matrix Transpose(const Matrix &m);
// Matrix product per component. Sums of few terms follow RADIANCE exactly (long double, last
// term first); large products use Eigen in double, equal to rounding.
Matrix Multiply(const Matrix &a, const Matrix &b);
// sum += add; false if the sizes differ.
bool AddInto(Matrix *sum, const Matrix &add);
// m1 *= m2 or m1 /= m2 element by element (a 1-component m2 applies to every component).
// Division by zero gives 0 and counts in *zero_divides. False if the sizes differ.
bool ElementMultiply(Matrix *m1, const Matrix &m2, bool divide, int *zero_divides);

}  // namespace dayflux
