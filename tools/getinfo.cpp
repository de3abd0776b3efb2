// getinfo: RADIANCE's header reader, with its options and output byte for byte (RADIANCE 5.4a):
//   getinfo [-d|+d] [file ..]     each file's header, its lines indented by a tab (+d: and its
//                                 dimensions; -d: its dimensions alone); no file: the standard
//                                 input's header as it is
//   getinfo [-d] -                the standard input without its header (-d: nor its
//                                 resolution line)
//   getinfo -a line ..            the standard input with lines added to its header
//   getinfo [+d|-d] -c cmd args   the header, the command line added, then cmd run on the data
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "matrix/header.h"
#include "util/errors.h"
#include "util/files.h"

namespace dayflux {
namespace {

// A header line as getinfo lists a file's: a tab after each line that ends.
void PutIndented(const char *line) {
    std::fputs(line, stdout);
    const size_t n = std::strlen(line);
    if (n > 0 && line[n - 1] == '\n') std::putchar('\t');
}

// The dimensions after a header: a picture's resolution line, an octree's cube, or not known.
void PutDimensions(std::FILE *fp) {
    int c = std::getc(fp);
    switch (c) {
        case '+':
        case '-':
            do std::putchar(c);
            while (c != '\n' && (c = std::getc(fp)) != EOF);
            break;
        case 1: {  // an octree: its cube's four numbers, NUL-terminated
            std::getc(fp);
            for (int fields = 0; (c = std::getc(fp)) != EOF;) {
                if (c != 0) {
                    std::putchar(c);
                    continue;
                }
                if (++fields >= 4) break;
                std::putchar(' ');
            }
            std::putchar('\n');
            break;
        }
        default:
            std::fputs("unknown file type\n", stdout);
    }
}

int BadHeader() {
    std::fputs("Bad header!\n", stderr);
    return 1;
}

// Reads a picture's resolution line (RADIANCE's fgetsresolu(): at most 31 bytes, the last X and
// Y in it, the signs before them, the sizes after) and, with keep, writes it in its standard
// form; false, with RADIANCE's message, where there is none.
bool PassResolution(bool keep) {
    char buf[32];
    const char *x = nullptr, *y = nullptr;
    if (std::fgets(buf, sizeof buf, stdin))
        for (const char *c = buf; *c; ++c) {
            if (*c == 'X') x = c;
            if (*c == 'Y') y = c;
        }
    const int xres = x ? std::atoi(x + 1) : 0, yres = y ? std::atoi(y + 1) : 0;
    if (xres <= 0 || yres <= 0) {
        std::fputs("No resolution string!\n", stderr);
        return false;
    }
    const char xs = x > buf && x[-1] == '-' ? '-' : '+', ys = y > buf && y[-1] == '-' ? '-' : '+';
    if (keep) {
        if (x > y)
            std::printf("%cY %d %cX %d\n", ys, yres, xs, xres);
        else
            std::printf("%cX %d %cY %d\n", xs, xres, ys, yres);
    }
    return true;
}

int Main(int argc, char **argv) {
    int dim = 0;  // +d: 1, -d: -1
    if (argc > 1 && (argv[1][0] == '-' || argv[1][0] == '+') && argv[1][1] == 'd') {
        dim = argv[1][0] == '-' ? -1 : 1;
        --argc, ++argv;
    }
    const auto copy_line = [](const char *line) {
        std::fputs(line, stdout);
        return true;
    };
    const auto skip_line = [](const char *) { return true; };
    const auto indent_line = [](const char *line) {
        PutIndented(line);
        return true;
    };
    if (argc > 2 && std::strcmp(argv[1], "-c") == 0) {
        std::setvbuf(stdin, nullptr, _IONBF, 0);  // the command reads what is left
        if (!ReadHeaderLines(stdin, copy_line)) return BadHeader();
        std::fputs(CommandLine(argc - 2, argv + 2).c_str(), stdout);
        std::putchar('\n');
        if (dim != 0 && !PassResolution(dim > 0)) return 1;
        std::fflush(stdout);
        execvp(argv[2], argv + 2);
        std::perror(argv[2]);
        return 1;
    }
    if (argc > 2 && std::strcmp(argv[1], "-a") == 0) {
        if (!ReadHeaderLines(stdin, copy_line)) return BadHeader();
        for (int i = 2; i < argc; ++i) {
            const size_t n = std::strlen(argv[i]);
            if (n == 0) continue;
            std::fputs(argv[i], stdout);
            if (argv[i][n - 1] != '\n') std::putchar('\n');
        }
        std::putchar('\n');
        CopyStream(stdin, stdout);
        return 0;
    }
    if (argc == 2 && std::strcmp(argv[1], "-") == 0) {
        if (!ReadHeaderLines(stdin, skip_line)) return BadHeader();
        if (dim < 0 && !PassResolution(false)) return 1;
        CopyStream(stdin, stdout);
        return 0;
    }
    for (int i = 1; i < argc; ++i) {
        std::fputs(argv[i], stdout);
        std::FILE *fp = std::fopen(argv[i], "r");
        if (!fp) {
            std::fputs(": cannot open\n", stdout);
            continue;
        }
        if (dim < 0) {
            if (!ReadHeaderLines(fp, skip_line)) {
                std::fputs("bad header!\n", stdout);  // (after the name, as RADIANCE has it)
                std::fclose(fp);
                continue;
            }
            std::fputs(": ", stdout);
            PutDimensions(fp);
        } else {
            PutIndented(":\n");
            if (!ReadHeaderLines(fp, indent_line)) {
                std::fflush(stdout);
                std::fprintf(stderr, "%s: bad header!\n", argv[i]);
                return 1;
            }
            std::putchar('\n');
            if (dim > 0) {
                std::putchar('\t');
                PutDimensions(fp);
            }
        }
        std::fclose(fp);
    }
    if (argc == 1) {
        if (dim < 0) {
            if (!ReadHeaderLines(stdin, skip_line)) return BadHeader();
            PutDimensions(stdin);
        } else {
            if (!ReadHeaderLines(stdin, copy_line)) return BadHeader();
            std::putchar('\n');
            if (dim > 0) PutDimensions(stdin);
        }
    }
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
