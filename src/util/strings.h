// Number parsing and formatting shared by the matrix formats and option parsers.
#pragma once

#include <charconv>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace dayflux {

// Parses a whole word as a number the way scanf("%lf") would accept it (a leading '+' allowed).
bool ParseNumber(std::string_view word, double *value);
// Parses straight to float, rounding once as scanf("%f") does.
bool ParseNumber(std::string_view word, float *value);
bool ParseInt(std::string_view word, int *value);

// The fields between separators (n separators give n + 1 fields, empty ones kept).
std::vector<std::string> Split(std::string_view s, char separator);
// The white-space separated words.
std::vector<std::string> SplitWords(std::string_view s);
// s without white space at either end.
std::string Trim(std::string_view s);

// RADIANCE's isflt(): true if the word is a decimal number (used to gather option factors).
bool IsFloatWord(std::string_view word);

// value as printf("%g") prints it, for messages.
inline std::string FormatNumber(double value) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", value);
    return buf;
}

// Appends value as printf("%.*e", precision, value) would print it.
inline void AppendScientific(std::string *out, double value, int precision) {
    char buf[64];
    auto res =
        std::to_chars(buf, buf + sizeof buf, value, std::chars_format::scientific, precision);
    out->append(buf, res.ptr);
}

// Appends value as printf("%.*g", precision, value) would print it (precision 1..15). A fast path
// handles the usual case; values close to a rounding tie go through std::to_chars.
void AppendGeneral(std::string *out, double value, int precision);
// The same into a buffer with room for 32 characters; returns the end of what was written.
char *FormatGeneral(char *p, double value, int precision);

}  // namespace dayflux
