#include "test_util.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

namespace dayflux::test {

TempDir::TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("dayflux-test-" + std::to_string(getpid()) + "-" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
}

std::string ReadFile(const std::filesystem::path &p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

std::vector<TargetReportSensor> ReadTargetReport(const std::filesystem::path &p) {
    std::vector<TargetReportSensor> sensors;
    std::istringstream in(ReadFile(p));
    std::string line;
    std::getline(in, line);  // its comment
    for (long index; in >> index;) {
        TargetReportSensor x;
        in >> x.samples >> x.error;
        sensors.push_back(x);
    }
    return sensors;
}

void WriteFile(const std::filesystem::path &p, const std::string &data) {
    std::ofstream f(p, std::ios::binary);
    f << data;
}

CommandResult RunCommand(const std::string &command, const std::filesystem::path &dir) {
    // Captured output goes to the system's temporary folder under this process's id: ctest runs
    // tests as parallel processes, often in the same folder, and test data must stay untouched.
    static int counter = 0;
    const std::string stem =
        "dayflux-test-" + std::to_string(getpid()) + "-" + std::to_string(++counter);
    const std::filesystem::path tmp = std::filesystem::temp_directory_path();
    const std::filesystem::path out = tmp / (stem + ".out");
    const std::filesystem::path err = tmp / (stem + ".err");
    const std::string full = "cd '" + dir.string() + "' && PATH='" + BinDir().string() +
                             "':\"$PATH\" && ( " + command + " ) > '" + out.string() + "' 2> '" +
                             err.string() + "'";
    int raw = std::system(full.c_str());
    CommandResult r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = ReadFile(out);
    r.err = ReadFile(err);
    std::filesystem::remove(out);
    std::filesystem::remove(err);
    return r;
}

std::string Comparable(const std::string &text) {
    if (text.rfind("#?", 0) != 0) return text;
    size_t end = text.find("\n\n");
    if (end == std::string::npos) return text;
    std::istringstream head(text.substr(0, end + 1));
    std::string line, kept;
    while (std::getline(head, line)) {
        if (line.rfind("CAPDATE=", 0) == 0 || line.rfind("GMT=", 0) == 0 ||
            line.rfind("BigEndian=", 0) == 0)
            continue;
        kept += line + "\n";
    }
    return kept + text.substr(end + 1);
}

std::string MatrixBody(const std::filesystem::path &p) {
    const std::string text = ReadFile(p);
    const size_t end = text.find("\n\n");
    return end == std::string::npos ? "" : text.substr(end + 2);
}

}  // namespace dayflux::test
