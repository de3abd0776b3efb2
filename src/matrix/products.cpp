#include "matrix/products.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>
#include <mutex>

#include "util/pipeline.h"

namespace dayflux {

namespace {

// A tile of one component, kTileRows rows x kStrip columns: c[r][j] = sum over k ascending of
// ap[k][r] * bp[k][j], from nought, each entry's terms in RADIANCE's order. Float products are
// exact in double, so fused multiply-adds give the same bits. Both operands are packed (k-major,
// contiguous, already double), so the loop is loads, broadcasts and FMAs on accumulators held in
// registers. Compiled for x86-64-v3 (AVX2, FMA) where available.
constexpr int kTileRows = 6;
constexpr int kStrip = 8;
// Written with GCC's vector types, so that each row's 8 sums stay in two 4-double registers: 12
// accumulators, enough independent FMAs in flight to keep both FMA units busy (a plain loop over
// 6 x 8 came out spilled, 4x slower; 4 x 8 reached 18 G multiply-adds a second, 6 x 8 in
// vectors 24).
typedef double Double4 __attribute__((vector_size(32)));
__attribute__((target_clones("arch=x86-64-v3", "default"))) void TileKernel(const double *ap,
                                                                            const double *bp,
                                                                            int inner, double *c) {
    Double4 s[kTileRows][2] = {};
    for (int k = 0; k < inner; ++k) {
        Double4 b0, b1;
        std::memcpy(&b0, bp + kStrip * k, sizeof b0);
        std::memcpy(&b1, bp + kStrip * k + 4, sizeof b1);
        const double *a = ap + kTileRows * k;
        for (int r = 0; r < kTileRows; ++r) {
            const Double4 av = {a[r], a[r], a[r], a[r]};
            s[r][0] += av * b0;
            s[r][1] += av * b1;
        }
    }
    std::memcpy(c, s, sizeof s);
}

// Rows of a (interleaved components) as the tiles read them: component comp, k-major within each
// group of kTileRows rows, zero past nrows.
void PackRows(const float *a, int nrows, int inner, int comp, double *packed) {
    const int groups = (nrows + kTileRows - 1) / kTileRows;
    for (int g = 0; g < groups; ++g)
        for (int k = 0; k < inner; ++k)
            for (int r = 0; r < kTileRows; ++r) {
                const int row = g * kTileRows + r;
                packed[(static_cast<size_t>(g) * inner + k) * kTileRows + r] =
                    row < nrows ? a[(static_cast<size_t>(row) * inner + k) * 3 + comp] : 0.0;
            }
}

}  // namespace

size_t ColumnOperand::NonZeros() const {
    if (sparse_) return entry_row_.size();
    size_t n = 0;
    for (int k = 0; k < rows_; ++k)
        for (int j = 0; j < cols_; ++j)
            n += Dense(0, k, j) != 0 || Dense(1, k, j) != 0 || Dense(2, k, j) != 0;
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
        op.PackStrips();
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
        op.PackStrips();
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

void ColumnOperand::PackStrips() {
    const int strips = (cols_ + kStrip - 1) / kStrip;
    for (int c = 0; c < 3; ++c) {
        strips_[c].assign(static_cast<size_t>(strips) * rows_ * kStrip, 0.0);
        for (int k = 0; k < rows_; ++k)
            for (int j = 0; j < cols_; ++j)
                strips_[c][(static_cast<size_t>(j / kStrip) * rows_ + k) * kStrip + j % kStrip] =
                    planes_[c][static_cast<size_t>(k) * cols_ + j];
        std::vector<float>().swap(planes_[c]);  // (the strips hold them now, as doubles)
    }
}

double ColumnOperand::Dense(int c, int k, int j) const {
    return strips_[c][(static_cast<size_t>(j / kStrip) * rows_ + k) * kStrip + j % kStrip];
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
            for (int c = 0; c < 3; ++c) col[3 * r + c] = static_cast<float>(Dense(c, r, j));
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
    // For each component: the rows packed once, then each strip of columns (in L1) against every
    // group of rows (in L2), so the right operand passes through the cache once per block.
    const int groups = (nrows + kTileRows - 1) / kTileRows;
    std::vector<double> packed(static_cast<size_t>(groups) * inner * kTileRows);
    const int s0 = col0 / kStrip, s1 = (col1 + kStrip - 1) / kStrip;
    for (int c = 0; c < 3; ++c) {
        PackRows(a, nrows, inner, c, packed.data());
        for (int strip = s0; strip < s1; ++strip) {
            const double *bp = b.strips_[c].data() + static_cast<size_t>(strip) * inner * kStrip;
            const int j0 = std::max(col0, strip * kStrip),
                      j1 = std::min(col1, (strip + 1) * kStrip);
            for (int g = 0; g < groups; ++g) {
                double tile[kTileRows][kStrip];
                TileKernel(packed.data() + static_cast<size_t>(g) * inner * kTileRows, bp, inner,
                           &tile[0][0]);
                const int rows = std::min(kTileRows, nrows - g * kTileRows);
                for (int r = 0; r < rows; ++r) {
                    float *orow = out + static_cast<size_t>(g * kTileRows + r) * width * 3;
                    for (int j = j0; j < j1; ++j)
                        orow[(j - col0) * 3 + c] = static_cast<float>(tile[r][j - strip * kStrip]);
                }
            }
        }
    }
}

ColorMatrix Multiply(const ColorMatrix &a, const ColumnOperand &b) {
    CHECK(a.ncomp == 3 && a.cols == b.Rows());
    ColorMatrix r(a.rows, b.Cols(), 3);
    r.dtype = DataFormat::Float;
    const int block = 18;  // (three of the kernel's groups of six rows)
    tbb::parallel_for(0, (a.rows + block - 1) / block, [&](int blk) {
        const int r0 = blk * block, nr = std::min(block, a.rows - r0);
        MultiplyRows(a.row(r0), nr, a.cols, b, 0, b.Cols(), r.row(r0));
    });
    return r;
}

namespace {

// The product of the rows read_row gives (each inner x 3 floats; false at the end) and right,
// formatted by fmt and written to out in order, blocks of rows computed in parallel.
template <class ReadRow>
int ProductOfRows(int inner, ReadRow read_row, const ColumnOperand &right, const RowFormatter &fmt,
                  OutputFile &out) {
    const int ncols = right.Cols();
    // Rows per block: enough work per task, bounded memory (about 8 MiB of results per block).
    const size_t row_bytes = static_cast<size_t>(ncols) * 3 * sizeof(float);
    const int block_rows =
        static_cast<int>(std::clamp<size_t>((8u << 20) / std::max<size_t>(row_bytes, 1), 4, 256));
    struct Block {
        std::vector<float> a, res;  // the left rows read, their products
        int nrows = 0;
        std::string text;  // the products formatted, unless written as they are
    };
    // Finished blocks' buffers, reused: fresh ones cost a page fault per 4 KiB, which was a third
    // of the run with 150 MB of products (docs/benchmarks.md).
    std::mutex pool_mutex;
    std::vector<std::unique_ptr<Block>> pool;
    const bool as_they_are = fmt.WritesFloatsAsTheyAre();
    bool done = false;
    int total = 0;
    OrderedPipeline<Block>(
        [&]() -> std::unique_ptr<Block> {
            if (done) return nullptr;
            std::unique_ptr<Block> b;
            {
                const std::lock_guard lock(pool_mutex);
                if (!pool.empty()) b = std::move(pool.back()), pool.pop_back();
            }
            if (!b) b = std::make_unique<Block>();
            b->a.resize(static_cast<size_t>(block_rows) * inner * 3);
            b->nrows = 0;
            while (b->nrows < block_rows &&
                   read_row(b->a.data() + static_cast<size_t>(b->nrows) * inner * 3))
                ++b->nrows;
            if (b->nrows < block_rows) done = true;
            if (b->nrows == 0) return nullptr;
            return b;
        },
        [&](Block &b) {
            b.res.resize(static_cast<size_t>(b.nrows) * ncols * 3);
            MultiplyRows(b.a.data(), b.nrows, inner, right, 0, ncols, b.res.data());
            if (as_they_are) return;
            b.text.clear();
            for (int r = 0; r < b.nrows; ++r)
                fmt.Append(b.res.data() + static_cast<size_t>(r) * ncols * 3, &b.text);
            std::vector<float>().swap(b.res);  // (formatted: a pooled block keeps its text alone)
        },
        [&](Block &b) {
            if (as_they_are)
                out.Write(b.res.data(), b.res.size() * sizeof(float));
            else
                out.Write(b.text);
            total += b.nrows;
            auto spent = std::make_unique<Block>(std::move(b));
            const std::lock_guard lock(pool_mutex);
            pool.push_back(std::move(spent));
        });
    return total;
}

}  // namespace

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
    const int total = ProductOfRows(
        left.Cols(), [&](float *row) { return left.ReadRow(row); }, right, fmt, out);
    left.Finish();
    return total;
}

int StreamProduct(const ColorMatrix &left, const ColumnOperand &right, const RowFormatter &fmt,
                  OutputFile &out) {
    CHECK(left.ncomp == 3 && left.cols == right.Rows());
    int next = 0;
    return ProductOfRows(
        left.cols,
        [&](float *row) {
            if (next == left.rows) return false;
            std::memcpy(row, left.row(next++), static_cast<size_t>(left.cols) * 3 * sizeof(float));
            return true;
        },
        right, fmt, out);
}

}  // namespace dayflux
