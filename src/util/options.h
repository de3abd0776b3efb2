// Command-line helpers shared by the programs' option parsers.
#pragma once

namespace dayflux {

// The number after option argv[*i], advancing *i: a missing value calls usage (which does not
// return), a word that is not a number is an error naming the option.
double OptionNumber(int argc, char **argv, int *i, void (*usage)(const char *));

}  // namespace dayflux
