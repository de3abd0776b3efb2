#include "util/errors.h"

#include <cstdio>
#include <cstring>
#include <iostream>
#include <new>

#include "util/signals.h"

namespace dayflux {

namespace {
std::string &ProgramNameStorage() {
    static std::string name = "dayflux";
    return name;
}
}  // namespace

std::string FileLoc::ToString() const {
    if (line > 0) return file + ":" + std::to_string(line);
    return file;
}

void ErrorExit(const FileLoc *loc, std::string_view message) {
    if (loc && !loc->file.empty()) throw UserError(loc->ToString() + ": " + std::string(message));
    throw UserError(std::string(message));
}

void ErrorExit(std::string_view message) { ErrorExit(nullptr, message); }

void Warning(const FileLoc *loc, std::string_view message) {
    std::string text = ProgramName() + ": warning - ";
    if (loc && !loc->file.empty()) text += loc->ToString() + ": ";
    text += message;
    text += '\n';
    std::fflush(stdout);
    std::fputs(text.c_str(), stderr);
}

void Warning(std::string_view message) { Warning(nullptr, message); }

void SetProgramName(std::string_view argv0) {
    size_t slash = argv0.rfind('/');
    ProgramNameStorage() =
        std::string(slash == std::string_view::npos ? argv0 : argv0.substr(slash + 1));
}

const std::string &ProgramName() { return ProgramNameStorage(); }

int RunTool(int argc, char **argv, int (*body)(int, char **)) {
    SetProgramName(argc > 0 ? argv[0] : "dayflux");
    // -version as the first argument, as plugins probe RADIANCE's programs (anywhere else it
    // may be an option's value: getinfo -a -version adds a header line).
    if (argc > 1 && std::strcmp(argv[1], "-version") == 0) {
        std::printf("%s %s\n", DAYFLUX_VERSION_LINE, ProgramName().c_str());
        return 0;
    }
    IgnoreFileSizeSignal();
    try {
        return body(argc, argv);
    } catch (const Interrupted &e) {
        std::fflush(stdout);
        std::cerr << ProgramName() << ": " << e.what() << std::endl;
        RaiseDefault(e.Signal());
    } catch (const UserError &e) {
        std::fflush(stdout);
        std::cerr << ProgramName() << ": " << e.what() << std::endl;
    } catch (const std::bad_alloc &) {
        std::cerr << ProgramName() << ": out of memory" << std::endl;
    } catch (const std::length_error &) {
        std::cerr << ProgramName() << ": out of memory (a size beyond what memory can hold)"
                  << std::endl;
    } catch (const std::exception &e) {
        // Anything else that escaped is our fault, but a message beats an abort.
        std::cerr << ProgramName() << ": internal error: " << e.what() << std::endl;
    }
    return 1;
}

}  // namespace dayflux
