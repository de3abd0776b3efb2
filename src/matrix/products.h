// Products of colour matrices as dctimestep forms them: float data, each entry summed in double
// over the inner index in ascending order (RADIANCE's cm_multiply() order, so results agree to
// the last bit), the left operand streamed by rows so memory stays bounded, and the structure
// of the right operand used: a sun matrix with one patch per hour is kept sparse.
#pragma once

#include <cstdint>
#include <vector>

#include "matrix/matrices.h"
#include "matrix/reader.h"
#include "matrix/writer.h"
#include "util/files.h"

namespace dayflux {

// The right-hand operand of a product, stored by columns.
class ColumnOperand {
  public:
    // Keeps entries sparse when fewer than a quarter of them are non-zero.
    static ColumnOperand FromMatrix(const ColorMatrix &m);
    // Reads a 3-component matrix row by row without ever holding it densely if it is sparse.
    static ColumnOperand Read(MatrixReader &reader);

    int Rows() const { return rows_; }
    int Cols() const { return cols_; }
    bool IsSparse() const { return sparse_; }
    size_t NonZeros() const;
    ColorMatrix ToMatrix() const;
    // The 3-component column j as a vector (for picture sums).
    std::vector<float> Column(int j) const;

  private:
    friend void MultiplyRows(const float *, int, int, const ColumnOperand &, int, int, float *);
    void Finish();
    void PackStrips();                        // strips_ from planes_, which it then frees
    double Dense(int c, int k, int j) const;  // component c of row k, column j (dense)

    int rows_ = 0, cols_ = 0;
    bool sparse_ = false;
    std::vector<float> planes_[3];  // dense, while it is made: [k][row * cols + col]
    // dense, as the product's tiles read it: per component, strips of 8 columns (zero past the
    // last), each k-major (row k's 8 values together), in double
    std::vector<double> strips_[3];
    std::vector<uint32_t> start_;  // sparse: entries of column j in [start_[j], start_[j+1])
    std::vector<uint32_t> entry_row_;
    std::vector<float> entry_value_;  // 3 per entry
};

// out[r][j - col0][c] = sum_k a[r][k][c] * b[k][j][c] for columns j in [col0, col1), rows r <
// nrows; a has inner dimension b.Rows(). out has (col1 - col0) columns.
void MultiplyRows(const float *a, int nrows, int inner, const ColumnOperand &b, int col0, int col1,
                  float *out);

// a x b, with rows computed in parallel.
ColorMatrix Multiply(const ColorMatrix &a, const ColumnOperand &b);

// Streams the rows of left through left x right and writes each result row with fmt, in order,
// computing and formatting blocks of rows in parallel. Returns the number of rows written.
int StreamProduct(MatrixReader &left, const ColumnOperand &right, const RowFormatter &fmt,
                  OutputFile &out);
// The same for a left matrix held whole (one whose row count its header did not give).
int StreamProduct(const ColorMatrix &left, const ColumnOperand &right, const RowFormatter &fmt,
                  OutputFile &out);

}  // namespace dayflux
