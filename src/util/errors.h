// User errors and internal checks, split as in pbrt: a user error names the input it came from
// (file and line where known) and ends the program with a non-zero exit; CHECK guards invariants
// of our own code.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

namespace dayflux {

// Where in an input a problem was found. line 0 means "no line" (binary data, whole file).
struct FileLoc {
    std::string file;
    int line = 0;

    std::string ToString() const;
};

// Thrown by library code for bad input; programs catch it in main, print it, and exit 1.
class UserError : public std::runtime_error {
  public:
    explicit UserError(const std::string &message) : std::runtime_error(message) {}
};

// Reports a problem with the user's input: "file:line: message" (or "file: message").
[[noreturn]] void ErrorExit(const FileLoc *loc, std::string_view message);
[[noreturn]] void ErrorExit(std::string_view message);

// Warnings go to stderr at once, prefixed with the program name, as RADIANCE does.
void Warning(const FileLoc *loc, std::string_view message);
void Warning(std::string_view message);

// The program name used in messages ("dctimestep: ..."); set once by each tool's main.
void SetProgramName(std::string_view argv0);
const std::string &ProgramName();

// Runs body, turning UserError, allocation failure and any other escaped exception into a
// message and exit status 1 (never an abort).
int RunTool(int argc, char **argv, int (*body)(int, char **));

}  // namespace dayflux

#define CHECK(cond)                                                                               \
    do {                                                                                          \
        if (!(cond)) {                                                                            \
            std::fprintf(stderr, "%s:%d: internal error: CHECK(%s) failed\n", __FILE__, __LINE__, \
                         #cond);                                                                  \
            std::abort();                                                                         \
        }                                                                                         \
    } while (false)
