// rcontrib's outputs: the standard output, or the files and commands -o names by modifier and
// bin (ofname()), each with the columns that go there, and -se's standard errors; headers as
// RADIANCE writes them; -r's recovery of existing outputs. Files are written to temporaries and
// renamed by Commit(), so a failed run leaves no complete-looking output.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "rcontrib/options.h"
#include "util/files.h"

namespace dayflux {

// ofname(): the output name for modifier mod and bin, from a spec with at most one %s (the
// modifier) and one integer conversion (the bin). flags: kByModifier, kByBin.
constexpr int kByModifier = 1, kByBin = 2;
std::string OutputName(const std::string &spec, const std::string &mod, int bin, int *flags);

class RcontribOutputs {
  public:
    // Opens the outputs for records of ncols columns (or, with -r, continues existing ones),
    // writing their headers: the command line, the octree's header, SOFTWARE= with label.
    RcontribOutputs(const RcontribOptions &o, int ncols, std::vector<std::string> header_args,
                    const std::string &octree_header, const std::string &label);
    ~RcontribOutputs();

    // Records every output already holds (-r), which the run skips.
    long Recovered() const { return recovered_; }
    // One record to every output: values (ncols x 3), and standard_errors to -se's.
    void Write(const std::vector<double> &values, const std::vector<double> &standard_errors);
    void Flush();
    void Commit();

  private:
    struct Stream;
    void Open(Stream &s, const std::vector<std::string> &header_args,
              const std::string &octree_header, const std::string &label);
    long RecoverableRecords();

    const RcontribOptions &o_;
    std::vector<Stream> streams_;
    long recovered_ = 0;
    std::vector<double> part_;
    std::string text_;
};

}  // namespace dayflux
