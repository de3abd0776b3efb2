// rcontrib's outputs: the standard output, or the files and commands -o names by modifier and
// bin (ofname()), each with the columns that go there, and -se's standard errors; headers as
// RADIANCE writes them; -r's recovery of existing outputs. Files are written as "name.partial" and
// renamed by Commit(), so a run that stopped early leaves no complete-looking output; -r continues
// a partial file (a run that was stopped or killed) or the output itself, as RADIANCE's does.
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
    // For a run that stops early: the records written so far kept in the partial files, and a
    // sentence saying where and how to continue ("" when -r cannot continue these outputs).
    std::string KeepPartial();

  private:
    struct Stream;
    void Open(Stream &s, const std::vector<std::string> &header_args,
              const std::string &octree_header, const std::string &label);
    long RecoverableRecords();
    long RecordsIn(const std::string &file, const Stream &s, bool partial, size_t *prefix) const;

    const RcontribOptions &o_;
    std::vector<Stream> streams_;
    long recovered_ = 0;
    long written_ = 0;  // records written by this run
    std::vector<double> part_;
    std::string text_;
};

}  // namespace dayflux
