#include "util/strings.h"

#include <cctype>

namespace dayflux {

namespace {
template <class T>
bool ParseFloating(std::string_view word, T *value) {
    if (!word.empty() && word[0] == '+') word.remove_prefix(1);
    if (word.empty()) return false;
    auto res = std::from_chars(word.data(), word.data() + word.size(), *value);
    if (res.ec == std::errc::result_out_of_range) {
        // Follow strtod: overflow gives +-HUGE_VAL, underflow gives 0 (keeping the sign).
        double d = std::strtod(std::string(word).c_str(), nullptr);
        *value = static_cast<T>(d);
        return true;
    }
    return res.ec == std::errc() && res.ptr == word.data() + word.size();
}
}  // namespace

bool ParseNumber(std::string_view word, double *value) { return ParseFloating(word, value); }
bool ParseNumber(std::string_view word, float *value) { return ParseFloating(word, value); }

bool ParseInt(std::string_view word, int *value) {
    if (!word.empty() && word[0] == '+') word.remove_prefix(1);
    auto res = std::from_chars(word.data(), word.data() + word.size(), *value);
    return res.ec == std::errc() && res.ptr == word.data() + word.size() && !word.empty();
}

bool IsFloatWord(std::string_view s) {
    // Same grammar as RADIANCE's isflt(): [space][sign]digits[.digits][e[sign]digits][space]
    size_t i = 0, n = s.size();
    auto digit = [&](size_t k) { return k < n && std::isdigit(static_cast<unsigned char>(s[k])); };
    while (i < n && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    if (i < n && (s[i] == '-' || s[i] == '+')) ++i;
    bool any = false;
    while (digit(i)) ++i, any = true;
    if (i < n && s[i] == '.') {
        ++i;
        while (digit(i)) ++i, any = true;
    }
    if (!any) return false;
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        ++i;
        if (i < n && (s[i] == '-' || s[i] == '+')) ++i;
        if (!digit(i)) return false;
        while (digit(i)) ++i;
    }
    while (i < n && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    return i == n;
}

}  // namespace dayflux
