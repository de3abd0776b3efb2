#include "matrix/header.h"

#include <cctype>
#include <cstring>
#include <ctime>

#include "util/strings.h"

namespace dayflux {

namespace {

// Value after "NAME=" if the line starts with it (RADIANCE matches the name exactly).
std::optional<std::string_view> Variable(std::string_view line, std::string_view name) {
    if (line.size() <= name.size() || line.substr(0, name.size()) != name ||
        line[name.size()] != '=')
        return std::nullopt;
    std::string_view v = line.substr(name.size() + 1);
    while (!v.empty() && std::isspace(static_cast<unsigned char>(v.front()))) v.remove_prefix(1);
    while (!v.empty() && std::isspace(static_cast<unsigned char>(v.back()))) v.remove_suffix(1);
    return v;
}

int DimensionValue(const FileLoc &loc, std::string_view name, std::string_view value) {
    int n = 0;
    if (!ParseInt(value, &n) || n < 0)
        ErrorExit(&loc,
                  "bad " + std::string(name) + " value '" + std::string(value) + "' in header");
    return n;
}

}  // namespace

MatrixHeader ReadHeader(InputSource &in) {
    MatrixHeader h;
    int first = in.Peek();
    if (first < 0) {
        FileLoc loc = in.LocNoLine();
        ErrorExit(&loc, "empty input where a matrix header was expected");
    }
    if (!std::isprint(first) && first != '\n') {
        FileLoc loc = in.LocNoLine();
        ErrorExit(&loc, "not a RADIANCE file: binary data where a header was expected");
    }
    std::string line;
    bool first_line = true;
    for (;;) {
        FileLoc loc = in.Loc();
        if (!in.ReadLine(&line))
            ErrorExit(&loc, "unexpected end of input in header (no blank line)");
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (first_line) {
            first_line = false;
            if (line.rfind("#?", 0) != 0)
                ErrorExit(&loc, "missing header: the first line should be '#?RADIANCE', not '" +
                                    line.substr(0, 40) + "'");
            continue;
        }
        if (line.empty()) break;
        std::string_view l = line;
        if (auto v = Variable(l, "NROWS")) {
            h.nrows = DimensionValue(loc, "NROWS", *v);
        } else if (auto v = Variable(l, "NCOLS")) {
            h.ncols = DimensionValue(loc, "NCOLS", *v);
        } else if (auto v = Variable(l, "NCOMP")) {
            h.ncomp = DimensionValue(loc, "NCOMP", *v);
            if (h.ncomp == 0) ErrorExit(&loc, "bad NCOMP value '0' in header");
        } else if (auto v = Variable(l, "BigEndian")) {
            h.big_endian = !v->empty() && v->front() == '1';
        } else if (auto v = Variable(l, "FORMAT")) {
            std::string_view name = v->substr(0, v->find_first_of(" \t"));
            auto f = FormatFromName(name);
            if (!f) ErrorExit(&loc, "unknown data format '" + std::string(name) + "' in header");
            h.format = *f;
        } else if (auto v = Variable(l, "EXPOSURE")) {
            double e = 0;
            if (!ParseNumber(*v, &e) || e <= 0) ErrorExit(&loc, "bad EXPOSURE value in header");
            for (double &x : h.exposure) x *= e;
        } else if (auto v = Variable(l, "COLORCORR")) {
            std::string s(*v);
            double c[3];
            if (std::sscanf(s.c_str(), "%lf %lf %lf", &c[0], &c[1], &c[2]) != 3)
                ErrorExit(&loc, "bad COLORCORR value in header");
            for (int k = 0; k < 3; ++k) h.exposure[k] *= c[k];
        } else if (line.rfind("#?", 0) == 0) {
            // A second id line (concatenated headers) carries nothing we keep.
        } else {
            h.info += line;
            h.info += '\n';
        }
    }
    return h;
}

bool NextIsResolution(InputSource &in) {
    // "-Y 3 +X 4" and its kin, not data such as "-3.2 ...".
    const int c = in.Peek();
    if (c != '-' && c != '+') return false;
    const int d = in.PeekSecond();
    return d == 'X' || d == 'Y';
}

void ReadResolution(InputSource &in, int *xres, int *yres) {
    FileLoc loc = in.Loc();
    std::string line;
    if (!in.ReadLine(&line)) ErrorExit(&loc, "missing picture resolution line");
    char ys = 0, yc = 0, xs = 0, xc = 0;
    int y = 0, x = 0;
    if (std::sscanf(line.c_str(), " %c%c %d %c%c %d", &ys, &yc, &y, &xs, &xc, &x) != 6 ||
        yc != 'Y' || xc != 'X' || y <= 0 || x <= 0)
        ErrorExit(&loc, "bad picture resolution line '" + line + "'");
    if (ys != '-' || xs != '+')
        ErrorExit(&loc, "picture orientation '" + line + "' is not the standard '-Y N +X M'");
    *xres = x;
    *yres = y;
}

bool ReadHeaderLines(std::FILE *fp, const std::function<bool(const char *)> &on_line) {
    constexpr int kMaxLine = 2048;  // RADIANCE's MAXLINE
    const int first = std::fgetc(fp);
    if (first == EOF || !std::isprint(first)) return false;
    std::ungetc(first, fp);
    char buf[kMaxLine];
    for (;;) {
        buf[kMaxLine - 2] = '\n';
        if (!std::fgets(buf, kMaxLine, fp)) return false;
        if (buf[buf[0] == '\r' ? 1 : 0] == '\n') return true;
        if (buf[kMaxLine - 2] != '\n') {  // a line cut short: its last byte read again
            std::ungetc(buf[kMaxLine - 2], fp);
            buf[kMaxLine - 2] = '\0';
        }
        if (!on_line(buf)) return false;
    }
}

std::string HeaderStart(int argc, char **argv) { return "#?RADIANCE\n" + CommandLine(argc, argv); }

std::string QuotedWord(std::string_view w) {
    bool space = false;
    char quote = 0;
    for (size_t k = 0; k < w.size(); ++k) {
        if (std::isspace(static_cast<unsigned char>(w[k])))
            space = true;
        else if (k > 0 && w[k] == '"' && k + 1 < w.size())
            quote = '\'';
        else if (k > 0 && w[k] == '\'' && k + 1 < w.size())
            quote = '"';
    }
    if (!space && !quote) return std::string(w);
    if (!quote) quote = '"';
    return quote + std::string(w) + quote;
}

std::string CommandLine(int argc, char **argv) {
    std::string s;
    for (int i = 0; i < argc; ++i) {
        s += QuotedWord(argv[i]);
        s += i + 1 < argc ? ' ' : '\n';
    }
    return s;
}

std::string DateLines() {
    std::time_t now = std::time(nullptr);
    char buf[128];
    std::tm local{}, gmt{};
    localtime_r(&now, &local);
    gmtime_r(&now, &gmt);
    std::string s;
    std::strftime(buf, sizeof buf, "CAPDATE= %Y:%m:%d %H:%M:%S\n", &local);
    s += buf;
    std::strftime(buf, sizeof buf, "GMT= %Y:%m:%d %H:%M:%S\n", &gmt);
    s += buf;
    return s;
}

std::string FormatLine(DataFormat format) {
    return "FORMAT=" + std::string(FormatName(format)) + "\n";
}

std::string HeaderFields(int nrows, int ncols, int ncomp, DataFormat format) {
    std::string s;
    s += "NROWS=" + std::to_string(nrows) + "\n";
    s += "NCOLS=" + std::to_string(ncols) + "\n";
    s += "NCOMP=" + std::to_string(ncomp) + "\n";
    if (format == DataFormat::Float || format == DataFormat::Double)
        s += NativeBigEndian() ? "BigEndian=1\n" : "BigEndian=0\n";
    s += FormatLine(format);
    s += '\n';
    return s;
}

std::string ResolutionLine(int xres, int yres) {
    return "-Y " + std::to_string(yres) + " +X " + std::to_string(xres) + "\n";
}

}  // namespace dayflux
