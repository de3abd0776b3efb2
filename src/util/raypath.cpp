#include "util/raypath.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "util/errors.h"

namespace dayflux {

namespace fs = std::filesystem;

std::string DayfluxLibDirectory() {
    if (const char *env = std::getenv("DAYFLUX_LIB")) return env;
    std::error_code ec;
    fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return "";
    return (exe.parent_path().parent_path() / "lib" / "dayflux").string();
}

std::vector<std::string> RaypathDirectories() {
    std::vector<std::string> dirs;
    if (const char *rp = std::getenv("RAYPATH")) {
        std::string s = rp;
        size_t start = 0;
        while (start <= s.size()) {
            size_t end = s.find(':', start);
            if (end == std::string::npos) end = s.size();
            if (end > start) dirs.push_back(s.substr(start, end - start));
            start = end + 1;
        }
    }
    dirs.push_back(".");
    const std::string lib = DayfluxLibDirectory();
    if (!lib.empty()) dirs.push_back(lib);
    return dirs;
}

std::string FindOnRaypath(const std::string &name) {
    if (name.empty()) ErrorExit("empty file name");
    if (name[0] == '/' || name.rfind("./", 0) == 0 || name.rfind("../", 0) == 0) {
        if (fs::exists(name)) return name;
        ErrorExit("cannot find '" + name + "'");
    }
    std::string searched;
    for (const std::string &d : RaypathDirectories()) {
        fs::path p = fs::path(d) / name;
        if (fs::is_regular_file(p)) return p.string();
        searched += (searched.empty() ? "" : ":") + d;
    }
    ErrorExit("cannot find '" + name + "' on RAYPATH (" + searched + ")");
}

}  // namespace dayflux
