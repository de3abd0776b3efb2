#include "matrix/operations.h"

#include <tbb/parallel_for.h>

#include <Eigen/Core>

namespace dayflux {

namespace {
constexpr const char *kTypeMismatch = "WARNING: data type mismatch\n";
// Beyond this many multiply-adds a product leaves the exact long double path for Eigen.
constexpr double kExactProductLimit = 5e7;

void ResultType(Matrix *m, DataFormat a, DataFormat b) {
    DataFormat t = CombinedFormat(a, b);
    if (t == DataFormat::Unknown)
        m->info += kTypeMismatch;
    else
        m->dtype = t;
}
}  // namespace

void Scale(Matrix *m, const std::vector<double> &f) {
    CHECK(static_cast<int>(f.size()) == m->ncomp);
    for (size_t i = 0; i < m->data.size(); ++i) m->data[i] *= f[i % m->ncomp];
    if (!m->info.empty()) m->info += "Applied scalar\n";
}

Matrix TransformComponents(const Matrix &m, const std::vector<double> &cmat) {
    const int n = static_cast<int>(cmat.size()) / m.ncomp;
    CHECK(n > 0 && static_cast<int>(cmat.size()) == n * m.ncomp);
    Matrix out(m.rows, m.cols, n);
    if (!m.info.empty())
        out.info = m.info + "Applied " + std::to_string(n) + "x" + std::to_string(m.ncomp) +
                   " component transform\n";
    out.dtype = m.dtype;
    const size_t elements = static_cast<size_t>(m.rows) * m.cols;
    for (size_t e = 0; e < elements; ++e) {
        const double *src = &m.data[e * m.ncomp];
        for (int kd = 0; kd < n; ++kd) {
            double d = 0;
            for (int ks = m.ncomp; ks--;) d += cmat[kd * m.ncomp + ks] * src[ks];
            out.data[e * n + kd] = d;
        }
    }
    return out;
}

Matrix Transpose(const Matrix &m) {
    if (m.rows == 1 || m.cols == 1) {  // RADIANCE relabels vectors without a note
        Matrix t = m;
        std::swap(t.rows, t.cols);
        return t;
    }
    Matrix t(m.cols, m.rows, m.ncomp);
    if (!m.info.empty()) t.info = m.info + "Transposed rows and columns\n";
    t.dtype = m.dtype;
    for (int i = 0; i < t.rows; ++i)
        for (int j = 0; j < t.cols; ++j)
            for (int k = 0; k < t.ncomp; ++k) t.at(i, j, k) = m.at(j, i, k);
    return t;
}

Matrix Multiply(const Matrix &a, const Matrix &b) {
    CHECK(a.ncomp == b.ncomp && a.cols == b.rows);
    Matrix r(a.rows, b.cols, a.ncomp);
    ResultType(&r, a.dtype, b.dtype);
    const double work = static_cast<double>(a.rows) * b.cols * a.cols * a.ncomp;
    if (work <= kExactProductLimit) {
        for (int i = 0; i < r.rows; ++i)
            for (int j = 0; j < r.cols; ++j)
                for (int k = 0; k < r.ncomp; ++k) {
                    long double d = 0;
                    for (int h = a.cols; h--;) d += a.at(i, h, k) * b.at(h, j, k);
                    r.at(i, j, k) = static_cast<double>(d);
                }
        return r;
    }
    using Strided =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>, 0,
                   Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>>;
    using StridedOut =
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>, 0,
                   Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>>;
    const int n = a.ncomp;
    for (int k = 0; k < n; ++k) {
        Strided B(b.data.data() + k, b.rows, b.cols,
                  Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>(b.cols * n, n));
        const int block = 64;
        tbb::parallel_for(0, (a.rows + block - 1) / block, [&](int blk) {
            const int r0 = blk * block, nr = std::min(block, a.rows - r0);
            Strided A(a.data.data() + static_cast<size_t>(r0) * a.cols * n + k, nr, a.cols,
                      Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>(a.cols * n, n));
            StridedOut R(r.data.data() + static_cast<size_t>(r0) * r.cols * n + k, nr, r.cols,
                         Eigen::Stride<Eigen::Dynamic, Eigen::Dynamic>(r.cols * n, n));
            Eigen::MatrixXd tmp = A * B;
            R = tmp;
        });
    }
    return r;
}

bool AddInto(Matrix *sum, const Matrix &add) {
    if (sum->rows != add.rows || sum->cols != add.cols || sum->ncomp != add.ncomp) return false;
    ResultType(sum, sum->dtype, add.dtype);
    for (size_t i = 0; i < sum->data.size(); ++i) sum->data[i] += add.data[i];
    return true;
}

bool ElementMultiply(Matrix *m1, const Matrix &m2, bool divide, int *zero_divides) {
    if (m1->rows != m2.rows || m1->cols != m2.cols) return false;
    if (m2.ncomp > 1 && m2.ncomp != m1->ncomp) return false;
    ResultType(m1, m1->dtype, m2.dtype);
    *zero_divides = 0;
    const size_t elements = static_cast<size_t>(m1->rows) * m1->cols;
    const int n = m1->ncomp;
    for (size_t e = 0; e < elements; ++e) {
        double *v = &m1->data[e * n];
        if (m2.ncomp == 1) {
            double d = m2.data[e];
            if (divide) {
                if (d == 0) {
                    ++*zero_divides;
                    for (int k = 0; k < n; ++k) v[k] = 0;
                    continue;
                }
                d = 1. / d;  // RADIANCE multiplies by the reciprocal here
            }
            for (int k = 0; k < n; ++k) v[k] *= d;
        } else {
            const double *w = &m2.data[e * n];
            for (int k = 0; k < n; ++k) {
                if (!divide)
                    v[k] *= w[k];
                else if (w[k] == 0)
                    ++*zero_divides, v[k] = 0;
                else
                    v[k] /= w[k];
            }
        }
    }
    if (*zero_divides) m1->info += "WARNING: zero divide(s) corrupted results\n";
    return true;
}

}  // namespace dayflux
