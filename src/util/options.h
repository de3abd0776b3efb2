// Command-line helpers shared by the programs' option parsers.
#pragma once

#include <string>
#include <vector>

namespace dayflux {

// The number after option argv[*i], advancing *i: a missing value calls usage (which does not
// return), a word that is not a number is an error naming the option.
double OptionNumber(int argc, char **argv, int *i, void (*usage)(const char *));

// The arguments after the program's name with each @file replaced by the file's words, as
// RADIANCE's expandarg() does (an error where the file cannot be read).
std::vector<std::string> ExpandOptionFiles(const std::vector<std::string> &args);

}  // namespace dayflux
