// rcollate: RADIANCE's reshaper of matrix files, with its options, messages and output byte for
// byte (RADIANCE 5.4a): records (n_comp words or binary values) re-arranged into other rows and
// columns (-ir -ic -or -oc), transposed (-t) or re-ordered by blocks (-o RxC[xR1xC1..]); headers
// read and written or not (-h, -hi, -ho); ascii, float, double or byte data (-f[afdb][N]).
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "matrix/header.h"
#include "util/errors.h"
#include "util/files.h"

namespace dayflux {
namespace {

constexpr int kMaxLevels = 16;  // RADIANCE's MAXLEVELS: RxC block pairs

struct Settings {
    std::string format;  // "" until given or read
    int comp_size = 0;   // bytes a binary value; 0: ascii
    int n_comp = 0;      // values a record
    int in_cols = 0, in_rows = 0, out_cols = 0, out_rows = 0;
    bool transpose = false, in_header = true, out_header = true, warnings = true, check = false;
    int blocks[kMaxLevels][2] = {};  // -o's nesting, outermost first (sizes multiplied out)
    int levels = 0;
};

bool IsSpaceOrNul(char c) { return c == '\0' || std::isspace(static_cast<unsigned char>(c)); }

// -o RxC[xR1xC1..]: the levels parsed (each level's sizes times those inside it); exits where the
// specification is bad, as RADIANCE's get_array() does.
int ParseBlocks(const char *spec, int levels[][2], int room) {
    if (room <= 0) {
        std::fputs("Too many block levels!\n", stderr);
        std::exit(1);
    }
    if (std::sscanf(spec, "%dx%d", &levels[0][0], &levels[0][1]) != 2) {
        std::fputs("Bad block specification!\n", stderr);
        std::exit(1);
    }
    while (std::isdigit(static_cast<unsigned char>(*spec))) ++spec;
    ++spec;  // the 'x'
    while (std::isdigit(static_cast<unsigned char>(*spec))) ++spec;
    if (*spec != 'x' && *spec != 'X') {
        if (*spec) {
            std::fputs("Blocks must be separated by 'x' or 'X'\n", stderr);
            std::exit(1);
        }
        return 1;
    }
    const int inner = ParseBlocks(spec + 1, levels + 1, room - 1);
    levels[0][0] *= levels[1][0];
    levels[0][1] *= levels[1][1];
    return inner + 1;
}

// A header line: the format and sizes taken (checked against what options gave), the rest
// copied to the output's header. False where they disagree (RADIANCE's message said).
bool TakeHeaderLine(Settings &s, const std::string &line) {
    if (line.rfind("FORMAT=", 0) == 0) {
        size_t at = 7;
        while (at < line.size() && std::isspace(static_cast<unsigned char>(line[at]))) ++at;
        if (at < line.size()) {
            size_t end = at;
            while (end < line.size() && !std::isspace(static_cast<unsigned char>(line[end])) &&
                   end - at < 63)
                ++end;
            const std::string format = line.substr(at, end - at);
            if (s.format.empty()) {
                s.format = format;
                return true;
            }
            if (format == s.format) return true;
            std::fprintf(stderr, "Input format '%s' != '%s'\n", format.c_str(), s.format.c_str());
            return false;
        }
    }
    const auto size_line = [&](const char *key, int *value, const char *message) {
        if (line.rfind(key, 0) != 0) return 0;
        const int n = std::atoi(line.c_str() + 6);
        if (*value > 0 && n != *value) {
            std::fputs(message, stderr);
            return -1;
        }
        *value = n;
        return 1;
    };
    for (const int r : {size_line("NROWS=", &s.in_rows, "Incorrect input row count\n"),
                        size_line("NCOLS=", &s.in_cols, "Incorrect input column count\n"),
                        size_line("NCOMP=", &s.n_comp, "Incorrect number of components\n")}) {
        if (r < 0) return false;
        if (r > 0) return true;
    }
    if (s.out_header) std::fputs(line.c_str(), stdout);
    return true;
}

// Defaults: ascii, three values a record; a transpose's output sizes from its input's.
bool CheckSizes(Settings &s) {
    if (s.format.empty()) {
        s.format = "ascii";
    } else if (s.comp_size == 0) {
        if (s.format == "float")
            s.comp_size = sizeof(float);
        else if (s.format == "double")
            s.comp_size = sizeof(double);
        else if (s.format == "byte")
            s.comp_size = 1;
        else if (s.format != "ascii") {
            std::fprintf(stderr, "Unsupported format: %s\n", s.format.c_str());
            return false;
        }
    }
    if (s.transpose && s.out_rows <= 0 && s.out_cols <= 0) {
        if (s.in_rows > 0) s.out_cols = s.in_rows;
        if (s.in_cols > 0) s.out_rows = s.in_cols;
    } else if (s.out_rows <= 0 && s.out_cols > 0 && (s.in_rows * s.in_cols) % s.out_cols == 0) {
        s.out_rows = s.in_rows * s.in_cols / s.out_cols;
    }
    if (s.n_comp <= 0) s.n_comp = 3;
    return true;
}

// The ascii records of data: where each starts (and, last, the end); false (with RADIANCE's
// message) where a line ends inside a record.
bool IndexRecords(const std::string &data, int words, std::vector<size_t> *starts) {
    size_t at = 0;
    const size_t end = data.size();
    for (;;) {
        while (at < end && IsSpaceOrNul(data[at])) ++at;
        if (at >= end) break;
        starts->push_back(at);
        int left = words;
        while (++at < end) {
            if (!IsSpaceOrNul(data[at])) continue;
            if (--left <= 0) break;
            bool more = true;
            do {
                if (data[at] == '\n') {
                    std::fputs("Unexpected EOL in record!\n", stderr);
                    return false;
                }
                if (++at >= end) {
                    more = false;
                    break;
                }
            } while (IsSpaceOrNul(data[at]));
            if (!more) break;
        }
    }
    starts->push_back(end);
    return true;
}

// Records before the first line's end: the input's columns where nothing gave them.
int CountColumns(const std::string &data, const std::vector<size_t> &starts) {
    size_t eol = starts[0];
    const size_t end = starts.back();
    while (data[eol] != '\n')
        if (++eol >= end) return 0;
    int n = 0;
    while (n + 1 < static_cast<int>(starts.size()) && starts[n] < eol) ++n;
    return n;
}

// Record n's words, one space between them.
void PutRecord(const std::string &data, const std::vector<size_t> &starts, size_t n, int words) {
    size_t at = starts[n];
    const size_t next = starts[n + 1];
    do {
        std::putchar(data[at++]);
        if (at < data.size() && !IsSpaceOrNul(data[at])) continue;
        if (--words <= 0) break;
        std::putchar(' ');
        do
            if (++at >= next) break;
        while (IsSpaceOrNul(data[at]));
    } while (at < next);
}

// Where output row r, column c comes from in the input (-o's blocks, -t).
long long InputPosition(const Settings &s, int r, int c) {
    if (s.levels > 1) {
        long long n = 0;
        const int(*level)[2] = s.blocks;
        for (int left = s.levels; left > 1; --left, ++level) {
            const int sr = r / level[1][0], sc = c / level[1][1];
            r -= sr * level[1][0];
            c -= sc * level[1][1];
            n += static_cast<long long>(sr) * level[1][0] * level[0][1] +
                 static_cast<long long>(sc) * level[1][0] * level[1][1];
        }
        n += static_cast<long long>(r) * level[0][1] + c;
        if (s.transpose) {
            const long long row = n / s.in_rows, col = n - row * s.in_rows;
            n = col * s.in_cols + row;
        }
        return n;
    }
    if (s.transpose) return static_cast<long long>(c) * s.in_cols + r;
    return static_cast<long long>(r) * s.out_cols + c;
}

// The whole data in memory, its records written in their new order.
bool Reorder(Settings &s, const std::string &data) {
    if (s.in_rows <= 0) s.in_rows = s.transpose ? s.out_cols : s.out_rows;
    if (s.in_cols <= 0) s.in_cols = s.transpose ? s.out_rows : s.out_cols;
    std::vector<size_t> starts;
    long long records;
    const long long record_bytes = static_cast<long long>(s.n_comp) * s.comp_size;
    if (s.comp_size == 0) {
        if (data.empty() || !IndexRecords(data, s.n_comp, &starts)) return false;
        if (s.in_cols <= 0) s.in_cols = CountColumns(data, starts);
        records = static_cast<long long>(starts.size()) - 1;
    } else if (s.in_rows > 0 && s.in_cols > 0) {
        records = static_cast<long long>(s.in_rows) * s.in_cols;
        if (records > static_cast<long long>(data.size()) / record_bytes) {
            std::fputs("Input too small for specified size and type\n", stderr);
            return false;
        }
    } else {
        records = static_cast<long long>(data.size()) / record_bytes;
    }
    const auto bad = [] {
        std::fputs("Bad dimension(s)\n", stderr);
        return false;
    };
    if (s.in_rows <= 0 && s.in_cols > 0)
        s.in_rows = static_cast<int>(records / s.in_cols);
    else if (s.in_cols <= 0 && s.in_rows > 0)
        s.in_cols = static_cast<int>(records / s.in_rows);
    if (records != static_cast<long long>(s.in_rows) * s.in_cols) return bad();
    if (s.transpose) {
        if (s.out_cols <= 0) s.out_cols = s.in_rows;
        if (s.out_rows <= 0) s.out_rows = s.in_cols;
        if (s.levels <= 1 && (s.out_rows != s.in_cols || s.out_cols != s.in_rows)) return bad();
    } else {
        if (s.out_cols <= 0) s.out_cols = s.in_cols;
        if (s.out_rows <= 0) s.out_rows = s.in_rows;
    }
    if (static_cast<long long>(s.in_rows) * s.in_cols !=
        static_cast<long long>(s.out_rows) * s.out_cols) {
        std::fputs("Number of input and output records do not match\n", stderr);
        return false;
    }
    if (s.out_header) std::printf("NROWS=%d\nNCOLS=%d\n\n", s.out_rows, s.out_cols);
    for (int i = 0; i < s.out_rows; ++i) {
        for (int j = 0; j < s.out_cols; ++j) {
            const long long n = InputPosition(s, i, j);
            if (n >= records) {
                std::fputs("Index past end-of-file\n", stderr);
                return false;
            }
            if (s.comp_size == 0) {
                PutRecord(data, starts, static_cast<size_t>(n), s.n_comp);
                std::putchar(j >= s.out_cols - 1 ? '\n' : '\t');
            } else {
                std::fwrite(data.data() + n * record_bytes, s.comp_size, s.n_comp, stdout);
            }
        }
        if (std::ferror(stdout)) {
            std::fputs("Error writing to stdout\n", stderr);
            return false;
        }
    }
    return true;
}

// The next word of the standard input (at most 255 bytes), leaving it at the line's end or the
// next word; false at the end.
bool NextWord(std::string *word) {
    int c;
    while ((c = std::getchar()) == 0 || (c != EOF && std::isspace(c))) {
    }
    if (c == EOF) return false;
    word->clear();
    do word->push_back(static_cast<char>(c));
    while ((c = std::getchar()) != EOF && !std::isspace(c) && word->size() < 255);
    while (c != EOF && c != '\n' && std::isspace(c)) c = std::getchar();
    if (c != EOF) std::ungetc(c, stdin);
    return true;
}

// Ascii records streamed into rows of the output's columns (no reordering needed).
bool Reshape(const Settings &s) {
    long long to_go = static_cast<long long>(s.in_rows) * s.in_cols;
    int columns_to_go = s.out_cols;
    if (s.out_header) {
        if (s.out_rows > 0) std::printf("NROWS=%d\n", s.out_rows);
        if (s.out_cols > 0) std::printf("NCOLS=%d\n", s.out_cols);
        std::putchar('\n');
    }
    if (s.comp_size != 0 || (!s.check && s.out_cols == s.in_cols && s.out_rows == s.in_rows))
        return CopyStream(stdin, stdout);
    if (s.out_cols <= 0) {
        std::fputs("Missing -oc specification\n", stderr);
        return false;
    }
    if (to_go <= 0 && s.out_rows > 0) {
        to_go = static_cast<long long>(s.out_rows) * s.out_cols;
    } else if (static_cast<long long>(s.out_rows) * s.out_cols != to_go) {
        std::fprintf(stderr, "Number of input and output records disagree (%dx%d != %dx%d)\n",
                     s.in_rows, s.in_cols, s.out_rows, s.out_cols);
        return false;
    }
    std::string word;
    bool ended = false;
    do {
        int n = s.n_comp;
        while (n-- > 0) {
            if (!NextWord(&word)) {
                if (to_go > 0 || n < s.n_comp - 1) break;
                ended = true;  // the data's end where a record would start
                break;
            }
            std::fputs(word.c_str(), stdout);
            if (n > 0) {  // within a record
                const int c = std::getchar();
                if (c == '\n' || c == EOF) break;
                std::ungetc(c, stdin);
                std::putchar(' ');
            }
        }
        if (ended) break;
        if (n >= 0) {
            std::fputs("Incomplete record / unexpected EOF\n", stderr);
            return false;
        }
        if (--columns_to_go <= 0) {
            std::putchar('\n');
            columns_to_go = s.out_cols;
        } else {
            std::putchar('\t');
        }
    } while (--to_go != 0);
    if (s.warnings && columns_to_go != s.out_cols)
        std::fputs("Warning -- incomplete final row\n", stderr);
    if (s.warnings && NextWord(&word))
        std::fputs("Warning -- characters beyond expected EOD\n", stderr);
    return true;
}

int Usage(const char *prog) {
    std::fprintf(stderr,
                 "Usage: %s [-h[io]][-w][-c][-f[afdb][N]][-t][-ic in_col][-ir in_row][-oc "
                 "out_col][-or out_row][-o RxC[xR1xC1..]] [input.dat]\n",
                 prog);
    return 1;
}

int Main(int argc, char **argv) {
    Settings s;
    int a = 1;
    const auto value = [&](int *to) {
        if (a + 1 >= argc) return false;
        *to = std::atoi(argv[++a]);
        return true;
    };
    for (; a < argc && argv[a][0] == '-'; ++a) {
        const char *arg = argv[a];
        bool ok = true;
        switch (arg[1]) {
            case 'i':
                ok = arg[2] == 'c' ? value(&s.in_cols) : arg[2] == 'r' && value(&s.in_rows);
                break;
            case 'o':
                if (arg[2] == 'c')
                    ok = value(&s.out_cols);
                else if (arg[2] == 'r')
                    ok = value(&s.out_rows);
                else
                    ok = !arg[2] && a + 1 < argc &&
                         (s.levels = ParseBlocks(argv[++a], s.blocks, kMaxLevels)) != 0;
                break;
            case 'h':
                if (arg[2] == 'i')
                    s.in_header = false;
                else if (arg[2] == 'o')
                    s.out_header = false;
                else if (arg[2] == '\0')
                    s.in_header = s.out_header = false;
                else
                    ok = false;
                break;
            case 't':
                s.transpose = !s.transpose;
                break;
            case 'f': {
                const char kind =
                    static_cast<char>(std::tolower(static_cast<unsigned char>(arg[2])));
                if (kind == 'a')
                    s.format = "ascii", s.comp_size = 0;
                else if (kind == 'f')
                    s.format = "float", s.comp_size = sizeof(float);
                else if (kind == 'd')
                    s.format = "double", s.comp_size = sizeof(double);
                else if (kind == 'b')
                    s.format = "byte", s.comp_size = 1;
                else
                    ok = false;
                if (ok && arg[3] && !std::isdigit(static_cast<unsigned char>(arg[3]))) ok = false;
                if (ok) s.n_comp = arg[3] ? std::atoi(arg + 3) : 1;
                break;
            }
            case 'w':
                s.warnings = !s.warnings;
                break;
            case 'c':
                s.check = true;
                break;
            default:
                ok = false;
        }
        if (!ok) return Usage(argv[0]);
    }
    if (a < argc - 1) return Usage(argv[0]);
    if (s.levels) {
        s.out_rows = s.blocks[0][0];
        s.out_cols = s.blocks[0][1];
    }
    if (a == argc - 1 && !std::freopen(argv[a], "r", stdin)) {
        std::fprintf(stderr, "%s: cannot open for reading\n", argv[a]);
        return 1;
    }
    if (!s.transpose && !s.check && s.levels <= 1 && s.in_header == s.out_header &&
        s.out_cols == s.in_cols && s.out_rows == s.in_rows) {
        if (s.warnings) std::fprintf(stderr, "%s: no-op -- copying input verbatim\n", argv[0]);
        return CopyStream(stdin, stdout) ? 0 : 1;
    }
    if (s.in_header &&
        !ReadHeaderLines(stdin, [&](const char *line) { return TakeHeaderLine(s, line); }))
        return 1;
    if (!CheckSizes(s)) return 1;
    if (s.out_header) {
        const std::string start = s.in_header ? CommandLine(a, argv) : HeaderStart(a, argv);
        std::printf("%sNCOMP=%d\nFORMAT=%s\n", start.c_str(), s.n_comp, s.format.c_str());
    }
    if (s.transpose || s.check || s.levels > 1 || (s.out_header && s.out_rows <= 0)) {
        std::string data;
        char buf[1 << 16];
        for (size_t n; (n = std::fread(buf, 1, sizeof buf, stdin)) > 0;) data.append(buf, n);
        if (data.empty() || std::ferror(stdin)) {
            if (a == argc - 1)
                std::fprintf(stderr, "%s: error loading file into memory\n", argv[a]);
            else
                std::fprintf(stderr, "%s: error loading stdin into memory\n", argv[0]);
            return 1;
        }
        return Reorder(s, data) ? 0 : 1;
    }
    return Reshape(s) ? 0 : 1;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
