// rmtxop: RADIANCE's matrix calculator, with the same arguments, evaluation order and output.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "matrix/header.h"
#include "matrix/matrices.h"
#include "matrix/operations.h"
#include "matrix/writer.h"
#include "util/errors.h"
#include "util/strings.h"

namespace dayflux {
namespace {

constexpr int kMaxComponents = 16;

struct UnaryOps {
    std::vector<double> scale;      // -s factors
    std::vector<double> transform;  // -c coefficients
    bool transpose = false;         // -t
};

struct Operand {
    std::string spec;  // file, "-" or "!command"
    BsdfPart part = BsdfPart::kTransmission;
    UnaryOps ops;
    std::unique_ptr<Matrix> loaded;  // loaded early when deciding the evaluation order
    char binop = 0;                  // operation with the next operand
};

bool verbose = false;

[[noreturn]] void Usage(const char *prog) {
    ErrorExit(std::string("Usage: ") + prog +
              " [-v][-f[adfc][-t][-s sf .. | -c ce ..][-rf|-rb] m1 [.+*/] .. > mres");
}

Matrix &Load(Operand &op) {
    if (!op.loaded)
        op.loaded = std::make_unique<Matrix>(LoadMatrix(op.spec == "-" ? "" : op.spec, op.part));
    return *op.loaded;
}

const std::string &DisplayName(const Operand &op) {
    static const std::string stdin_name = kStdinName;
    return op.spec == "-" ? stdin_name : op.spec;
}

// Applies unary operations to m in RADIANCE's order: -s, -c, then -t (name: the operand's, for
// messages; report: say so with -v).
Matrix ApplyOps(Matrix m, const UnaryOps &ops, const std::string &name, bool report) {
    if (!ops.scale.empty()) {
        if (!ops.transform.empty()) ErrorExit("Options -s and -c are exclusive");
        std::vector<double> sf = ops.scale;
        if (sf.size() == 1)
            sf.assign(m.ncomp, sf[0]);
        else if (static_cast<int>(sf.size()) != m.ncomp)
            ErrorExit(name + ": -s must have one or " + std::to_string(m.ncomp) + " factors");
        Scale(&m, sf);
        if (report) std::fprintf(stderr, "%s: applied scalar\n", name.c_str());
    }
    if (!ops.transform.empty()) {
        if (ops.transform.size() % m.ncomp)
            ErrorExit(name + ": -c must have N x " + std::to_string(m.ncomp) + " coefficients");
        m = TransformComponents(m, ops.transform);
        if (report) std::fprintf(stderr, "%s: applied component transform\n", name.c_str());
    }
    if (ops.transpose) {
        m = Transpose(m);
        if (report) std::fprintf(stderr, "%s: transposed rows and columns\n", name.c_str());
    }
    return m;
}

// Loads the operand and applies its unary operations.
Matrix LoadWithOps(Operand &op) {
    Matrix m = std::move(Load(op));
    op.loaded.reset();
    return ApplyOps(std::move(m), op.ops, DisplayName(op), verbose);
}

constexpr const char *kTrailing = "trailing_ops";

// One matrix, no transpose, its row count in its header: each block of rows read, its
// operations applied (the trailing ones after its own) and written before the next is read, so
// memory stays flat and a pipe's programs overlap. The same numbers and header as the whole
// matrix's: the operations run on the header's shape first (their notes, checks and messages),
// then on each block. False where it cannot stream (the matrix is then loaded into op).
bool StreamOne(Operand &op, const UnaryOps &trailing, DataFormat outfmt,
               const std::string &header_start) {
    if (op.ops.transpose || trailing.transpose || IsXmlSpec(op.spec)) return false;
    MatrixReader reader(op.spec == "-" ? "" : op.spec);
    if (reader.Rows() <= 0) {
        op.loaded = std::make_unique<Matrix>(ReadAll<Matrix>(reader));
        return false;
    }
    Matrix input;
    input.cols = reader.Cols();
    input.ncomp = reader.Comps();
    input.dtype = reader.Format();
    input.info = reader.Header().info;
    const auto shape_after = [&](bool report) {
        return ApplyOps(ApplyOps(input, op.ops, DisplayName(op), report), trailing, kTrailing,
                        report);
    };
    Matrix shape = shape_after(false);
    const DataFormat format = outfmt == DataFormat::Unknown ? shape.dtype : outfmt;
    if (IsPicture(format) && shape.ncomp != 3) {  // (WriteMatrix's grey pictures)
        op.loaded = std::make_unique<Matrix>(ReadAll<Matrix>(reader));
        return false;
    }
    if (verbose) shape_after(true);  // its messages, once
    shape.rows = reader.Rows();
    OutputFile out("-");
    out.Write(MatrixHeaderText(shape, format, header_start));
    const RowFormatter fmt(format, shape.cols, shape.ncomp, AsciiStyle::kRmatrix,
                           RmatrixPrecision(shape.dtype));
    const int block_rows = static_cast<int>(std::clamp<size_t>(
        (size_t{1} << 20) / (sizeof(double) * reader.Cols() * reader.Comps() + 1), 1, 1024));
    Matrix block(block_rows, reader.Cols(), reader.Comps());
    std::string text;
    for (int done = 0; done < shape.rows;) {
        block.rows = std::min(block_rows, shape.rows - done);
        block.data.resize(static_cast<size_t>(block.rows) * block.cols * block.ncomp);
        for (int r = 0; r < block.rows; ++r)
            CHECK(reader.ReadRow(block.row(r)));  // (a short input is an error in ReadRow)
        const Matrix result =
            ApplyOps(ApplyOps(block, op.ops, DisplayName(op), false), trailing, kTrailing, false);
        text.clear();
        for (int r = 0; r < result.rows; ++r) fmt.Append(result.row(r), &text);
        out.Write(text);
        done += block.rows;
    }
    reader.Finish();
    out.Commit();
    return true;
}

Matrix BinaryOp(const std::string &name, Matrix left, char op, Matrix right) {
    switch (op) {
        case '.':
            if (left.ncomp != right.ncomp) ErrorExit(name + ": # components do not match");
            if (left.cols != right.rows)
                ErrorExit(name + ": mismatched dimensions (" + std::to_string(left.rows) + "x" +
                          std::to_string(left.cols) + " times " + std::to_string(right.rows) + "x" +
                          std::to_string(right.cols) + ")");
            return Multiply(left, right);
        case '+':
            if (!AddInto(&left, right)) ErrorExit(name + ": matrix sum failed (sizes differ)");
            return left;
        case '*':
        case '/': {
            const char *what = op == '/' ? "division" : "multiplication";
            int zero_divides = 0;
            if (!ElementMultiply(&left, right, op == '/', &zero_divides))
                ErrorExit(name + ": element-wise " + what + " failed (sizes differ)");
            if (zero_divides)
                std::fprintf(stderr, "%s: warning - error during element-wise %s\n", name.c_str(),
                             what);
            return left;
        }
    }
    ErrorExit(name + ": unknown operation '" + std::string(1, op) + "'");
}

int Rows(Operand &op) { return op.ops.transpose ? Load(op).cols : Load(op).rows; }
int Cols(Operand &op) { return op.ops.transpose ? Load(op).rows : Load(op).cols; }

// RADIANCE's rule: multiply from the right when the chain ends in a thin matrix.
bool PreferRightToLeft(std::vector<Operand> &ops) {
    size_t last = 0;
    while (ops[last].binop) {
        if (ops[last].binop != '.') return false;
        ++last;
    }
    if (last <= 1) return false;  // one product: the order does not matter
    if (Cols(ops[last]) == 1) return true;
    if (Cols(ops[last]) >= Rows(ops[last])) return false;
    return Cols(ops[last]) < Rows(ops[0]);
}

int Main(int argc, char **argv) {
    std::vector<Operand> ops(1);
    DataFormat outfmt = DataFormat::Unknown;
    bool stdin_used = false;
    auto factors = [&](int *i, size_t max) {
        std::vector<double> v;
        while (*i + 1 < argc && v.size() < max && IsFloatWord(argv[*i + 1]))
            v.push_back(std::atof(argv[++*i]));
        return v;
    };
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        const size_t n = ops.size() - 1;  // index of the operand being described
        if (arg.size() == 1 && std::string(".+*/").find(arg[0]) != std::string::npos) {
            if (n == 0 || ops[n - 1].binop)
                ErrorExit(std::string(argv[0]) + ": missing matrix argument before '" + arg +
                          "' operation");
            ops[n - 1].binop = arg[0];
        } else if (arg[0] != '-' || arg.size() == 1) {
            if (arg == "-") {
                if (stdin_used)
                    ErrorExit(std::string(argv[0]) +
                              ": standard input used for more than one matrix");
                stdin_used = true;
            }
            ops[n].spec = arg;
            if (n > 0 && !ops[n - 1].binop) ops[n - 1].binop = '.';
            ops.emplace_back();
        } else {
            switch (arg[1]) {
                case 'v':
                    verbose = true;
                    break;
                case 'f':
                    if (arg == "-fd")
                        outfmt = DataFormat::Double;
                    else if (arg == "-ff")
                        outfmt = DataFormat::Float;
                    else if (arg == "-fa")
                        outfmt = DataFormat::Ascii;
                    else if (arg == "-fc")
                        outfmt = DataFormat::RGBE;
                    else
                        Usage(argv[0]);
                    break;
                case 't':
                    ops[n].ops.transpose = true;
                    break;
                case 's':
                    ops[n].ops.scale = factors(&i, kMaxComponents);
                    break;
                case 'c':
                    ops[n].ops.transform = factors(&i, kMaxComponents * kMaxComponents);
                    break;
                case 'r':
                    if (arg == "-rf")
                        ops[n].part = BsdfPart::kReflectionFront;
                    else if (arg == "-rb")
                        ops[n].part = BsdfPart::kReflectionBack;
                    else
                        Usage(argv[0]);
                    break;
                default:
                    std::fprintf(stderr, "%s: unknown operation '%s'\n", argv[0], arg.c_str());
                    Usage(argv[0]);
            }
        }
    }
    const size_t nmats = ops.size() - 1;
    if (nmats == 0) Usage(argv[0]);
    if (ops[nmats - 1].binop)
        ErrorExit(std::string(argv[0]) + ": missing matrix argument after '" +
                  std::string(1, ops[nmats - 1].binop) + "' operation");
    Operand &trailing = ops[nmats];
    const std::string header_start = HeaderStart(argc, argv);
    if (nmats == 1 && StreamOne(ops[0], trailing.ops, outfmt, header_start)) return 0;

    Matrix result;
    if (PreferRightToLeft(ops)) {
        size_t pos = nmats - 1;
        result = LoadWithOps(ops[pos]);
        while (pos-- > 0)
            result = BinaryOp(DisplayName(ops[pos]), LoadWithOps(ops[pos]), '.', std::move(result));
    } else {
        result = LoadWithOps(ops[0]);
        for (size_t i = 0; i + 1 < nmats; ++i)
            result = BinaryOp(DisplayName(ops[i + 1]), std::move(result), ops[i].binop,
                              LoadWithOps(ops[i + 1]));
    }
    trailing.spec = kTrailing;
    trailing.loaded = std::make_unique<Matrix>(std::move(result));
    result = LoadWithOps(trailing);

    if (outfmt == DataFormat::Unknown) outfmt = result.dtype;
    OutputFile out("-");
    WriteMatrix(result, outfmt, header_start, out);
    out.Commit();
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
