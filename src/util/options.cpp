#include "util/options.h"

#include <cmath>
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
    // NaN and infinity would pass every range check after (gendaymtx -r nan: a NaN sky).
    if (!std::isfinite(v))
        ErrorExit(std::string(argv[*i - 1]) + ": '" + argv[*i] + "' is not a finite number");
    return v;
}

std::string OptionCursor::Value(const std::string &opt) {
    if (i_ + 1 >= args_.size()) ErrorExit(opt + ": missing argument");
    return args_[++i_];
}

double OptionCursor::Number(const std::string &opt) {
    double v;
    const std::string w = Value(opt);
    if (!ParseNumber(w, &v) || !std::isfinite(v)) ErrorExit(opt + ": bad number '" + w + "'");
    return v;
}

int OptionCursor::Integer(const std::string &opt) {
    const double v = Number(opt);
    if (std::fabs(v) > 1e9) ErrorExit(opt + ": " + args_[i_] + " is out of range");
    return static_cast<int>(v);
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
