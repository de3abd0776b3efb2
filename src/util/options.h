// Command-line helpers shared by the programs' option parsers.
#pragma once

#include <string>
#include <vector>

namespace dayflux {

// The number after option argv[*i], advancing *i: a missing value calls usage (which does not
// return), a word that is not a finite number is an error naming the option.
double OptionNumber(int argc, char **argv, int *i, void (*usage)(const char *));

// A cursor over a program's arguments for its option parser: each value read for the option at
// the cursor, with messages naming the option. Numbers must be finite; whole numbers are taken
// as RADIANCE's atoi() takes them (2.5 is 2), within +-1e9.
class OptionCursor {
  public:
    explicit OptionCursor(std::vector<std::string> args) : args_(std::move(args)) {}
    const std::vector<std::string> &Args() const { return args_; }
    size_t &Index() { return i_; }
    std::string Value(const std::string &opt);
    double Number(const std::string &opt);
    int Integer(const std::string &opt);

  protected:
    std::vector<std::string> args_;
    size_t i_ = 0;
};

// The arguments after the program's name with each @file replaced by the file's words, as
// RADIANCE's expandarg() does (an error where the file cannot be read).
std::vector<std::string> ExpandOptionFiles(const std::vector<std::string> &args);

}  // namespace dayflux
