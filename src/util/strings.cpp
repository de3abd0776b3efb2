#include "util/strings.h"

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>

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

namespace {
constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                             1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

char *Slow(char *p, double value, int precision) {
    return std::to_chars(p, p + 32, value, std::chars_format::general, precision).ptr;
}
}  // namespace

void AppendGeneral(std::string *out, double value, int precision) {
    char buf[48];
    out->append(buf, FormatGeneral(buf, value, precision));
}

char *FormatGeneral(char *buf, double value, int precision) {
    if (value == 0 && !std::signbit(value)) {
        *buf = '0';
        return buf + 1;
    }
    const double a = std::fabs(value);
    if (!(a >= 1e-300 && a < 1e300) || precision < 1 || precision > 15)
        return Slow(buf, value, precision);
    // Decimal exponent from the binary one; off by at most one, which the scaling below corrects.
    uint64_t bits;
    std::memcpy(&bits, &a, sizeof bits);
    const int e2 = static_cast<int>(bits >> 52) - 1023;  // a is normal here
    int e10 = (e2 * 78913) >> 18;  // floor(e2 log10(2)) without a call to floor()
    const int shift = precision - 1 - e10;
    if (shift > 22 || shift < -22) return Slow(buf, value, precision);
    double m = shift >= 0 ? a * kPow10[shift] : a / kPow10[-shift];
    if (m < kPow10[precision - 1]) m *= 10, --e10;
    if (m >= kPow10[precision]) m /= 10, ++e10;
    const double fl = static_cast<double>(static_cast<long long>(m)), frac = m - fl;
    // Near a tie (or an exact integer, where the scaling may have rounded) let to_chars decide.
    if (std::fabs(frac - 0.5) < 1e-6 || frac < 1e-9 || frac > 1 - 1e-9)
        return Slow(buf, value, precision);
    long long digits = static_cast<long long>(frac > 0.5 ? fl + 1 : fl);
    if (digits >= static_cast<long long>(kPow10[precision]))
        digits /= 10, ++e10;  // 9.99.. rounded up
    char d[24];
    for (int k = precision - 1; k >= 0; --k, digits /= 10)
        d[k] = static_cast<char>('0' + digits % 10);
    int last = precision;  // %g drops trailing zeros
    while (last > 1 && d[last - 1] == '0') --last;
    int n = 0;
    if (value < 0) buf[n++] = '-';
    if (e10 < -4 || e10 >= precision) {
        buf[n++] = d[0];
        if (last > 1) {
            buf[n++] = '.';
            for (int k = 1; k < last; ++k) buf[n++] = d[k];
        }
        buf[n++] = 'e';
        buf[n++] = e10 < 0 ? '-' : '+';
        const int ea = e10 < 0 ? -e10 : e10;
        if (ea >= 100) buf[n++] = static_cast<char>('0' + ea / 100);
        buf[n++] = static_cast<char>('0' + ea / 10 % 10);
        buf[n++] = static_cast<char>('0' + ea % 10);
    } else if (e10 >= 0) {
        for (int k = 0; k <= e10; ++k) buf[n++] = k < last ? d[k] : '0';
        if (last > e10 + 1) {
            buf[n++] = '.';
            for (int k = e10 + 1; k < last; ++k) buf[n++] = d[k];
        }
    } else {
        buf[n++] = '0';
        buf[n++] = '.';
        for (int k = 0; k < -e10 - 1; ++k) buf[n++] = '0';
        for (int k = 0; k < last; ++k) buf[n++] = d[k];
    }
    return buf + n;
}

std::vector<std::string> Split(std::string_view s, char separator) {
    std::vector<std::string> fields;
    for (size_t start = 0;;) {
        const size_t end = s.find(separator, start);
        fields.emplace_back(s.substr(start, end == std::string_view::npos ? s.npos : end - start));
        if (end == std::string_view::npos) return fields;
        start = end + 1;
    }
}

std::vector<std::string> SplitWords(std::string_view s) {
    std::vector<std::string> words;
    size_t at = 0;
    for (;;) {
        while (at < s.size() && std::isspace(static_cast<unsigned char>(s[at]))) ++at;
        if (at == s.size()) return words;
        const size_t start = at;
        while (at < s.size() && !std::isspace(static_cast<unsigned char>(s[at]))) ++at;
        words.emplace_back(s.substr(start, at - start));
    }
}

std::string Trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    return std::string(s);
}

}  // namespace dayflux
