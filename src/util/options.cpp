#include "util/options.h"

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

}  // namespace dayflux
