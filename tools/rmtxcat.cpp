// rmtxcat (ours: RADIANCE has no program that stacks matrices): the rows of several RADIANCE
// matrices one after another, as one run would have written them, for the shards of a sensor
// file traced apart (docs/shards.md). Every input must have the same columns and components;
// the output has RADIANCE's header (this command line, the first input's header lines, NROWS
// where every input's row count is known) in the first input's format unless -fa/-ff/-fd asks
// for another. A shard that is short, of another size, or missing is an error naming it, and
// nothing is written that looks complete.
#include <memory>
#include <string>
#include <vector>

#include "matrix/header.h"
#include "matrix/reader.h"
#include "matrix/writer.h"
#include "util/errors.h"
#include "util/files.h"

namespace dayflux {
namespace {

[[noreturn]] void Usage(const char *prog) {
    ErrorExit(std::string("Usage: ") + prog + " [-h][-fa|-ff|-fd] m1 m2 .. > merged");
}

int64_t BytesPerValue(DataFormat f) {
    return f == DataFormat::Float ? 4 : f == DataFormat::Double ? 8 : 0;
}

// The rows input r holds: its NROWS, else (binary files) what its size gives, else -1.
int64_t KnownRows(const MatrixReader &r) {
    if (r.Rows() > 0) return r.Rows();
    const int64_t row_bytes = BytesPerValue(r.Format()) * r.Cols() * r.Comps();
    const auto left = r.BytesLeft();
    if (row_bytes == 0 || !left) return -1;
    if (*left % row_bytes != 0)
        ErrorExit(r.Name() + ": " + std::to_string(*left) +
                  " bytes of data are not whole rows of " + std::to_string(row_bytes) +
                  " bytes (a shard cut short?)");
    return static_cast<int64_t>(*left / row_bytes);
}

int Main(int argc, char **argv) {
    bool header = true;
    DataFormat format = DataFormat::Unknown;
    int i = 1;
    for (; i < argc && argv[i][0] == '-' && argv[i][1]; ++i) {
        const std::string a = argv[i];
        if (a == "-h")
            header = false;
        else if (a == "-fa" || a == "-ff" || a == "-fd")
            format = a[2] == 'a'   ? DataFormat::Ascii
                     : a[2] == 'f' ? DataFormat::Float
                                   : DataFormat::Double;
        else
            Usage(argv[0]);
    }
    if (i >= argc) Usage(argv[0]);
    // A first pass reads every header; files are closed again and reopened one at a time to
    // copy them, so a merge of thousands of shards holds one open (the standard input and
    // commands cannot be read twice, so they stay open).
    struct Input {
        std::string spec;
        std::unique_ptr<MatrixReader> reader;  // kept open: "-" and "!command"
    };
    std::vector<Input> inputs;
    MatrixHeader first_header;
    std::string first_name;
    int ncols = 0, ncomp = 0;
    DataFormat first_format = DataFormat::Unknown;
    int64_t rows = 0;
    for (; i < argc; ++i) {
        auto r = std::make_unique<MatrixReader>(argv[i]);
        if (inputs.empty()) {
            first_header = r->Header(), first_name = r->Name();
            ncols = r->Cols(), ncomp = r->Comps(), first_format = r->Format();
        }
        if (r->Cols() != ncols || r->Comps() != ncomp)
            ErrorExit(r->Name() + ": " + std::to_string(r->Cols()) + " columns of " +
                      std::to_string(r->Comps()) + " components, where '" + first_name + "' has " +
                      std::to_string(ncols) + " of " + std::to_string(ncomp));
        const int64_t n = KnownRows(*r);
        rows = rows < 0 || n < 0 ? -1 : rows + n;
        const std::string spec = argv[i];
        const bool reopen = spec != "-" && spec[0] != '!';
        inputs.push_back(Input{spec, reopen ? nullptr : std::move(r)});
    }
    if (format == DataFormat::Unknown)
        format = BytesPerValue(first_format) ? first_format : DataFormat::Ascii;
    OutputFile out("-");
    if (header) {
        std::string h = HeaderStart(argc, argv) + first_header.info;
        std::string fields =
            HeaderFields(rows > 0 ? static_cast<int>(rows) : 0, ncols, ncomp, format);
        if (rows <= 0) fields.erase(0, fields.find('\n') + 1);  // no NROWS= when unknown
        out.Write(h + fields);
    }
    const RowFormatter formatter(format, ncols, ncomp);
    std::vector<double> row(static_cast<size_t>(ncols) * ncomp);
    std::string text;
    for (Input &in : inputs) {
        std::unique_ptr<MatrixReader> r =
            in.reader ? std::move(in.reader) : std::make_unique<MatrixReader>(in.spec);
        if (r->Cols() != ncols || r->Comps() != ncomp)
            ErrorExit(r->Name() + ": changed while being merged");
        for (int k = 0; r->Rows() == 0 || k < r->Rows(); ++k) {
            if (!r->ReadRow(row.data())) break;
            text.clear();
            formatter.Append(row.data(), &text);
            out.Write(text);
        }
        r->Finish(true);
    }
    out.Commit();
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
