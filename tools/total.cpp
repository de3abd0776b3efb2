// total: RADIANCE's column reducer, with its options, arithmetic and output (RADIANCE 5.4a):
// sums (-sE: of |x|^E), products (-p), maxima (-u) or minima (-l) of each column of ascii or
// binary records (-id[N], -if[N]), their means (-m), over every -N records (-r: running), the
// first -in records, the first -on results, written as "%.9g" or binary (-od, -of).
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "util/errors.h"

namespace dayflux {
namespace {

constexpr int kMaxColumns = 8192;  // RADIANCE's MAXCOL

enum Function { kAdd, kMultiply, kMax, kMin };
constexpr double kInitial[] = {0., 1., -1e12, 1e12};  // each function's start (and empty field)

struct Options {
    Function func = kAdd;
    double power = 0;    // -sE
    bool mean = false;   // -m
    long count = 0;      // -N: records a result
    long in_count = 0;   // -in
    long out_count = 0;  // -on
    int binary_in = 0;   // -id[N]: N doubles a record; -if[N]: -N floats; 0: ascii
    int binary_out = 0;  // -od: 1, -of: -1, 0: ascii
    int separator = '\t';
    bool running = false;  // -r
};

[[noreturn]] void Usage(const char *prog) {
    std::fprintf(stderr,
                 "Usage: %s [-m][-sE|p|u|l][-tC][-i{f|d}[N]][-o{f|d}][-count [-r]] [file..]\n",
                 prog);
    std::exit(1);
}

// A binary column count after -id or -if: its digits, or 1.
int BinaryColumns(const char *digits, const char *prog) {
    const int n = std::isdigit(static_cast<unsigned char>(*digits)) ? std::atoi(digits) : 1;
    if (n > kMaxColumns) {
        std::fprintf(stderr, "%s: too many input columns\n", prog);
        std::exit(1);
    }
    return n;
}

// -in N or -on N (a record count), else -ia/-oa, -id[N]/-od or -if[N]/-of (a format: N doubles
// a record, positive; N floats, negative; ascii, 0; an output's column count is its own).
void CountOrFormat(int argc, char **argv, int *a, long *count, int *binary, bool input) {
    const char *arg = argv[*a];
    switch (arg[2]) {
        case 'n':
            if (*a + 1 >= argc) Usage(argv[0]);
            *count = std::atol(argv[++*a]);
            return;
        case 'a':
            *binary = 0;
            return;
        case 'd':
            *binary = input ? BinaryColumns(arg + 3, argv[0]) : 1;
            return;
        case 'f':
            *binary = input ? -BinaryColumns(arg + 3, argv[0]) : -1;
            return;
        default:
            Usage(argv[0]);
    }
}

// The next record's fields (0 at the end). Ascii records are lines of fields split at white space
// or at -t's character, as RADIANCE reads them (a line over 128 KiB read in parts; an empty field
// between separators the function's starting value).
int ReadRecord(const Options &o, std::FILE *fp, double *field) {
    if (o.binary_in > 0)
        return static_cast<int>(std::fread(field, sizeof(double), o.binary_in, fp));
    if (o.binary_in < 0) {
        float values[kMaxColumns];
        const int n = static_cast<int>(std::fread(values, sizeof(float), -o.binary_in, fp));
        for (int i = 0; i < n; ++i) field[i] = values[i];
        return n;
    }
    static std::vector<char> buf(16 * kMaxColumns);
    char *cp = std::fgets(buf.data(), static_cast<int>(buf.size()), fp);
    if (!cp) return 0;
    // isspace() as a table: a call per byte took the means of 200 rows of a year 0.15 s, not 0.09
    static const auto kSpace = [] {
        std::array<bool, 256> t{};
        for (int c = 0; c < 256; ++c) t[c] = std::isspace(c) != 0;
        return t;
    }();
    const auto is_space = [](int c) { return kSpace[static_cast<unsigned char>(c)]; };
    const bool space_separated = is_space(o.separator);
    int n = 0;
    for (; n < kMaxColumns; ++n) {
        while (is_space(*cp)) ++cp;
        if (!*cp) break;
        char *num = cp;
        while (*cp &&
               !(space_separated ? is_space(*cp) : static_cast<unsigned char>(*cp) == o.separator))
            ++cp;
        if (*cp) *cp++ = '\0';
        field[n] = !*num || is_space(*num) ? kInitial[o.func] : std::atof(num);
    }
    return n;
}

void WriteRecord(const Options &o, const double *field, int n) {
    if (o.binary_out > 0) {
        std::fwrite(field, sizeof(double), n, stdout);
        return;
    }
    if (o.binary_out < 0) {
        for (int i = 0; i < n; ++i) {
            const float f = static_cast<float>(field[i]);
            std::fwrite(&f, sizeof f, 1, stdout);
        }
        return;
    }
    for (int i = 0; i < n; ++i) {
        std::printf("%.9g", field[i]);
        if (i + 1 < n) std::putchar(o.separator);
    }
    std::putchar('\n');
    if (!o.running) std::fflush(stdout);
}

// Reduces one input (the standard input where name is null); false where it cannot be opened.
// *written counts the results, against -on.
bool Reduce(const Options &o, const char *name, long *written) {
    std::FILE *fp = name ? std::fopen(name, "r") : stdin;
    if (!fp) {
        std::fprintf(stderr, "%s: cannot open\n", name);
        return false;
    }
    std::vector<double> in(kMaxColumns), tally(kMaxColumns), result(kMaxColumns);
    std::vector<short> sign(kMaxColumns);
    long total = 0;
    while (!std::feof(fp)) {
        if (total == 0) {
            for (int i = 0; i < kMaxColumns; ++i) {
                tally[i] = o.func == kMultiply ? 0. : kInitial[o.func];  // (logs for -p)
                sign[i] = 1;
            }
        }
        int ncol = 0;
        long lines = 0;
        for (int nread;
             (o.count <= 0 || lines < o.count) && (o.in_count <= 0 || lines < o.in_count) &&
             (nread = ReadRecord(o, fp, in.data())) > 0;
             ++lines) {
            for (int i = 0; i < nread; ++i) switch (o.func) {
                    case kAdd:
                        if (in[i] == 0.) break;
                        tally[i] += o.power != 0. ? std::pow(std::fabs(in[i]), o.power) : in[i];
                        break;
                    case kMultiply:
                        if (in[i] == 0.) {
                            sign[i] = 0;
                        } else if (in[i] < 0.) {
                            sign[i] = static_cast<short>(-sign[i]);
                            in[i] = -in[i];
                        }
                        if (sign[i]) tally[i] += std::log(in[i]);
                        break;
                    case kMax:
                        if (in[i] > tally[i]) tally[i] = in[i];
                        break;
                    case kMin:
                        if (in[i] < tally[i]) tally[i] = in[i];
                        break;
                }
            if (nread > ncol) ncol = nread;
        }
        if (lines == 0) break;
        total += lines;
        for (int i = 0; i < ncol; ++i) {
            result[i] = tally[i];
            if (o.mean) {
                result[i] /= static_cast<double>(total);
                if (o.func == kAdd && o.power != 0. && result[i] != 0.)
                    result[i] = std::pow(result[i], 1. / o.power);
            }
            if (o.func == kMultiply) result[i] = sign[i] * std::exp(result[i]);
        }
        WriteRecord(o, result.data(), ncol);
        ++*written;
        if (o.out_count > 0 && *written >= o.out_count) break;
        if (!o.running) total = 0;
        if (o.in_count > 0 && lines >= o.in_count) break;
    }
    std::fclose(fp);
    return true;
}

int Main(int argc, char **argv) {
    Options o;
    int a = 1;
    for (; a < argc && argv[a][0] == '-'; ++a) {
        const char *arg = argv[a];
        if (arg[1] >= '0' && arg[1] <= '9') {
            o.count = std::atoi(arg + 1);
            continue;
        }
        switch (arg[1]) {
            case 'm':
                o.mean = !o.mean;
                break;
            case 'p':
                o.func = kMultiply;
                break;
            case 's':
                o.func = kAdd;
                o.power = std::atof(arg + 2);
                break;
            case 'u':
                o.func = kMax;
                break;
            case 'l':
                o.func = kMin;
                break;
            case 't':
                o.separator = static_cast<unsigned char>(arg[2]);
                break;
            case 'r':
                o.running = !o.running;
                break;
            case 'i':
                CountOrFormat(argc, argv, &a, &o.in_count, &o.binary_in, true);
                break;
            case 'o':
                CountOrFormat(argc, argv, &a, &o.out_count, &o.binary_out, false);
                break;
            default:
                Usage(argv[0]);
        }
    }
    if (o.mean && (o.func == kMax || o.func == kMin)) {
        std::fprintf(stderr, "%s: average %s?!\n", argv[0], o.func == kMax ? "maximum" : "minimum");
        return 1;
    }
    long written = 0;
    if (a >= argc) return Reduce(o, nullptr, &written) ? 0 : 1;
    int status = 0;
    for (; a < argc && (o.out_count <= 0 || written < o.out_count); ++a)
        if (!Reduce(o, argv[a], &written)) status = 2;
    return status;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
