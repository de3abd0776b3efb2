#include "matrix/products.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>

#include "util/pipeline.h"

namespace dayflux {

namespace {

// Register-blocked micro-kernel: 4 rows x 8 columns of one component, k ascending, so every
// accumulator sums its terms exactly in RADIANCE's order. Float products are exact in double,
// so fused multiply-adds give the same bits. Compiled for x86-64-v3 (AVX2, FMA) where available.
__attribute__((target_clones("arch=x86-64-v3", "default"))) void MicroKernel(
    const float *a, int inner, const float *b, int ldb, int c, double acc[4][8]) {
    double s[4][8] = {};
    for (int k = 0; k < inner; ++k) {
        const float *bk = b + static_cast<size_t>(k) * ldb;
        double bv[8];
        for (int j = 0; j < 8; ++j) bv[j] = bk[j];
        for (int r = 0; r < 4; ++r) {
            const double av = a[(static_cast<size_t>(r) * inner + k) * 3 + c];
            for (int j = 0; j < 8; ++j) s[r][j] += av * bv[j];
        }
    }
    for (int r = 0; r < 4; ++r)
        for (int j = 0; j < 8; ++j) acc[r][j] = s[r][j];
}

// Any block shape (the edges of the product), same order of sums.
void EdgeKernel(const float *a, int nrows, int inner, const float *b, int ldb, int c, int width,
                float *out, int out_cols, int out_col0) {
    for (int r = 0; r < nrows; ++r)
        for (int j = 0; j < width; ++j) {
            double s = 0;
            for (int k = 0; k < inner; ++k)
                s += static_cast<double>(a[(static_cast<size_t>(r) * inner + k) * 3 + c]) *
                     b[static_cast<size_t>(k) * ldb + j];
            out[(static_cast<size_t>(r) * out_cols + out_col0 + j) * 3 + c] = static_cast<float>(s);
        }
}

}  // namespace

size_t ColumnOperand::NonZeros() const {
    if (sparse_) return entry_row_.size();
    size_t n = 0;
    for (size_t i = 0; i < planes_[0].size(); ++i)
        n += planes_[0][i] != 0 || planes_[1][i] != 0 || planes_[2][i] != 0;
    return n;
}

ColumnOperand ColumnOperand::FromMatrix(const ColorMatrix &m) {
    CHECK(m.ncomp == 3);
    ColumnOperand op;
    op.rows_ = m.rows;
    op.cols_ = m.cols;
    op.sparse_ = true;
    // Gather entries row by row (rows ascending within every column), then decide.
    std::vector<uint32_t> count(m.cols + 1, 0);
    for (int r = 0; r < m.rows; ++r)
        for (int j = 0; j < m.cols; ++j) {
            const float *v = &m.at(r, j, 0);
            count[j + 1] += v[0] != 0 || v[1] != 0 || v[2] != 0;
        }
    size_t nnz = 0;
    for (int j = 0; j < m.cols; ++j) nnz += count[j + 1], count[j + 1] += count[j];
    if (nnz * 4 >= static_cast<size_t>(m.rows) * m.cols) {
        op.sparse_ = false;
        for (int c = 0; c < 3; ++c) op.planes_[c].resize(static_cast<size_t>(m.rows) * m.cols);
        for (int r = 0; r < m.rows; ++r)
            for (int j = 0; j < m.cols; ++j)
                for (int c = 0; c < 3; ++c)
                    op.planes_[c][static_cast<size_t>(r) * m.cols + j] = m.at(r, j, c);
        return op;
    }
    op.start_ = count;
    op.entry_row_.resize(nnz);
    op.entry_value_.resize(3 * nnz);
    std::vector<uint32_t> fill(count.begin(), count.end() - 1);
    for (int r = 0; r < m.rows; ++r)
        for (int j = 0; j < m.cols; ++j) {
            const float *v = &m.at(r, j, 0);
            if (v[0] == 0 && v[1] == 0 && v[2] == 0) continue;
            uint32_t e = fill[j]++;
            op.entry_row_[e] = r;
            std::copy(v, v + 3, &op.entry_value_[3 * e]);
        }
    return op;
}

ColumnOperand ColumnOperand::Read(MatrixReader &reader) {
    if (reader.Comps() != 3) {
        FileLoc loc{reader.Name(), 0};
        ErrorExit(&loc, "unexpected # components (must be 3)");
    }
    // Keep non-zero entries as triplets while reading; densify at the end if they are many.
    const int cols = reader.Cols();
    std::vector<float> row(static_cast<size_t>(cols) * 3);
    std::vector<uint32_t> rows_of, cols_of;
    std::vector<float> values;
    int nrows = 0;
    while (reader.ReadRow(row.data())) {
        for (int j = 0; j < cols; ++j) {
            const float *v = &row[3 * j];
            if (v[0] == 0 && v[1] == 0 && v[2] == 0) continue;
            rows_of.push_back(nrows);
            cols_of.push_back(j);
            values.insert(values.end(), v, v + 3);
        }
        ++nrows;
    }
    reader.Finish();
    if (nrows == 0) {
        FileLoc loc{reader.Name(), 0};
        ErrorExit(&loc, "no data rows in matrix");
    }
    ColumnOperand op;
    op.rows_ = nrows;
    op.cols_ = cols;
    const size_t nnz = rows_of.size();
    if (nnz * 4 >= static_cast<size_t>(nrows) * cols) {
        for (int c = 0; c < 3; ++c) op.planes_[c].assign(static_cast<size_t>(nrows) * cols, 0.f);
        for (size_t e = 0; e < nnz; ++e)
            for (int c = 0; c < 3; ++c)
                op.planes_[c][static_cast<size_t>(rows_of[e]) * cols + cols_of[e]] =
                    values[3 * e + c];
        return op;
    }
    op.sparse_ = true;
    op.start_.assign(cols + 1, 0);
    for (uint32_t j : cols_of) ++op.start_[j + 1];
    for (int j = 0; j < cols; ++j) op.start_[j + 1] += op.start_[j];
    std::vector<uint32_t> fill(op.start_.begin(), op.start_.end() - 1);
    op.entry_row_.resize(nnz);
    op.entry_value_.resize(3 * nnz);
    for (size_t e = 0; e < nnz; ++e) {  // read in row order, so rows ascend within each column
        uint32_t at = fill[cols_of[e]]++;
        op.entry_row_[at] = rows_of[e];
        std::copy(&values[3 * e], &values[3 * e + 3], &op.entry_value_[3 * at]);
    }
    return op;
}

ColorMatrix ColumnOperand::ToMatrix() const {
    ColorMatrix m(rows_, cols_, 3);
    for (int j = 0; j < cols_; ++j) {
        std::vector<float> col = Column(j);
        for (int r = 0; r < rows_; ++r) std::copy(&col[3 * r], &col[3 * r + 3], &m.at(r, j, 0));
    }
    return m;
}

std::vector<float> ColumnOperand::Column(int j) const {
    std::vector<float> col(static_cast<size_t>(rows_) * 3, 0.f);
    if (sparse_) {
        for (uint32_t e = start_[j]; e < start_[j + 1]; ++e)
            std::copy(&entry_value_[3 * e], &entry_value_[3 * e + 3], &col[3 * entry_row_[e]]);
    } else {
        for (int r = 0; r < rows_; ++r)
            for (int c = 0; c < 3; ++c)
                col[3 * r + c] = planes_[c][static_cast<size_t>(r) * cols_ + j];
    }
    return col;
}

void MultiplyRows(const float *a, int nrows, int inner, const ColumnOperand &b, int col0, int col1,
                  float *out) {
    CHECK(inner == b.rows_);
    const int width = col1 - col0;
    if (b.sparse_) {
        for (int r = 0; r < nrows; ++r) {
            const float *arow = a + static_cast<size_t>(r) * inner * 3;
            float *orow = out + static_cast<size_t>(r) * width * 3;
            for (int j = col0; j < col1; ++j) {
                double s[3] = {0, 0, 0};
                for (uint32_t e = b.start_[j]; e < b.start_[j + 1]; ++e) {
                    const float *av = arow + 3 * static_cast<size_t>(b.entry_row_[e]);
                    const float *bv = &b.entry_value_[3 * e];
                    for (int c = 0; c < 3; ++c) s[c] += static_cast<double>(av[c]) * bv[c];
                }
                for (int c = 0; c < 3; ++c) orow[3 * (j - col0) + c] = static_cast<float>(s[c]);
            }
        }
        return;
    }
    // Column panels small enough to stay in cache while every block of rows passes over them.
    constexpr int kPanel = 128;
    for (int c = 0; c < 3; ++c) {
        const float *plane = b.planes_[c].data();
        for (int p0 = col0; p0 < col1; p0 += kPanel) {
            const int p1 = std::min(col1, p0 + kPanel);
            int r0 = 0;
            for (; r0 + 4 <= nrows; r0 += 4) {
                const float *ablock = a + static_cast<size_t>(r0) * inner * 3;
                int j = p0;
                for (; j + 8 <= p1; j += 8) {
                    double acc[4][8];
                    MicroKernel(ablock, inner, plane + j, b.cols_, c, acc);
                    for (int r = 0; r < 4; ++r)
                        for (int jj = 0; jj < 8; ++jj)
                            out[(static_cast<size_t>(r0 + r) * width + (j - col0) + jj) * 3 + c] =
                                static_cast<float>(acc[r][jj]);
                }
                if (j < p1)
                    EdgeKernel(ablock, 4, inner, plane + j, b.cols_, c, p1 - j,
                               out + static_cast<size_t>(r0) * width * 3, width, j - col0);
            }
            if (r0 < nrows)
                EdgeKernel(a + static_cast<size_t>(r0) * inner * 3, nrows - r0, inner, plane + p0,
                           b.cols_, c, p1 - p0, out + static_cast<size_t>(r0) * width * 3, width,
                           p0 - col0);
        }
    }
}

ColorMatrix Multiply(const ColorMatrix &a, const ColumnOperand &b) {
    CHECK(a.ncomp == 3 && a.cols == b.Rows());
    ColorMatrix r(a.rows, b.Cols(), 3);
    r.dtype = DataFormat::Float;
    const int block = 16;
    tbb::parallel_for(0, (a.rows + block - 1) / block, [&](int blk) {
        const int r0 = blk * block, nr = std::min(block, a.rows - r0);
        MultiplyRows(a.row(r0), nr, a.cols, b, 0, b.Cols(), r.row(r0));
    });
    return r;
}

int StreamProduct(MatrixReader &left, const ColumnOperand &right, const RowFormatter &fmt,
                  OutputFile &out) {
    if (left.Comps() != 3) {
        FileLoc loc{left.Name(), 0};
        ErrorExit(&loc, "unexpected # components (must be 3)");
    }
    if (left.Cols() != right.Rows()) {
        FileLoc loc{left.Name(), 0};
        ErrorExit(&loc, "has " + std::to_string(left.Cols()) +
                            " columns but the matrix it multiplies has " +
                            std::to_string(right.Rows()) + " rows");
    }
    const int inner = left.Cols();
    const int ncols = right.Cols();
    // Rows per block: enough work per task, bounded memory (about 8 MiB of results per block).
    const size_t row_bytes = static_cast<size_t>(ncols) * 3 * sizeof(float);
    const int block_rows =
        static_cast<int>(std::clamp<size_t>((8u << 20) / std::max<size_t>(row_bytes, 1), 4, 256));
    struct Block {
        std::vector<float> a;
        int nrows = 0;
        std::string text;
    };
    bool done = false;
    int total = 0;
    OrderedPipeline<Block>(
        [&]() -> std::unique_ptr<Block> {
            if (done) return nullptr;
            auto b = std::make_unique<Block>();
            b->a.resize(static_cast<size_t>(block_rows) * inner * 3);
            while (b->nrows < block_rows &&
                   left.ReadRow(b->a.data() + static_cast<size_t>(b->nrows) * inner * 3))
                ++b->nrows;
            if (b->nrows < block_rows) done = true;
            if (b->nrows == 0) return nullptr;
            return b;
        },
        [&](Block &b) {
            std::vector<float> res(static_cast<size_t>(b.nrows) * ncols * 3);
            MultiplyRows(b.a.data(), b.nrows, inner, right, 0, ncols, res.data());
            std::vector<float>().swap(b.a);
            for (int r = 0; r < b.nrows; ++r)
                fmt.Append(res.data() + static_cast<size_t>(r) * ncols * 3, &b.text);
        },
        [&](Block &b) {
            out.Write(b.text);
            total += b.nrows;
        });
    left.Finish();
    return total;
}

}  // namespace dayflux
