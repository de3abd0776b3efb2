#include "util/options.h"

#include <fstream>
#include <string>

#include "util/errors.h"
#include "util/strings.h"

namespace dayflux {

double OptionNumber(int argc, char **argv, int *i, void (*usage)(const char *)) {
    if (*i + 1 >= argc) usage(argv[0]);
    double v;
    if (!ParseNumber(argv[++*i], &v))
        ErrorExit(std::string(argv[*i - 1]) + ": '" + argv[*i] + "' is not a number");
    return v;
}

std::vector<std::string> ExpandOptionFiles(const std::vector<std::string> &args) {
    std::vector<std::string> expanded;
    for (size_t i = 1; i < args.size(); ++i) {
        const std::string &a = args[i];
        if (a.size() > 1 && a[0] == '@') {
            std::ifstream f(a.substr(1));
            if (!f) ErrorExit("cannot open option file '" + a.substr(1) + "'");
            for (std::string w; f >> w;) expanded.push_back(w);
        } else {
            expanded.push_back(a);
        }
    }
    return expanded;
}

}  // namespace dayflux
