// cnt: RADIANCE's counter, for recipes that number things (cnt 5165 | rcalc ...): every
// combination of 0..N1-1, 0..N2-1, ..., the last counting fastest, one per line, each number
// after a tab. Output byte for byte as RADIANCE 5.4a's.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "util/errors.h"

namespace dayflux {
namespace {

// loop(): the lines of counts[k..] after prefix (a count of 0 or below ends the list).
void Count(const std::vector<int> &counts, size_t k, std::string &line, std::string *out) {
    if (k >= counts.size() || counts[k] == 0) {
        *out += line;
        *out += '\n';
        if (out->size() > (1 << 16)) {
            if (std::fwrite(out->data(), 1, out->size(), stdout) != out->size())
                ErrorExit("write error on standard output");
            out->clear();
        }
        return;
    }
    const size_t length = line.size();
    for (int i = 0; i < counts[k]; ++i) {
        line += '\t';
        line += std::to_string(i);
        Count(counts, k + 1, line, out);
        line.resize(length);
    }
}

int Main(int argc, char **argv) {
    std::vector<int> counts;
    for (int a = 1; a < argc; ++a) counts.push_back(std::atoi(argv[a]));
    std::string line, out;
    Count(counts, 0, line, &out);
    if (std::fwrite(out.data(), 1, out.size(), stdout) != out.size() || std::fflush(stdout) != 0)
        ErrorExit("write error on standard output");
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
