// A fuzz target's entry point run once on each file named (every file of a folder, in name
// order), as libFuzzer's -runs=0 does: the regression run of the seed corpora for builds without
// libFuzzer (GCC, the CI). A crash or an abort ends it with the file named just before.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
extern "C" __attribute__((weak)) int LLVMFuzzerInitialize(int *argc, char ***argv);

namespace {

std::vector<std::filesystem::path> Inputs(int argc, char **argv) {
    std::vector<std::filesystem::path> files;
    for (int i = 1; i < argc; ++i) {
        if (std::string(argv[i]).rfind("--", 0) == 0) continue;  // the target's own flags
        if (!std::filesystem::is_directory(argv[i])) {
            files.emplace_back(argv[i]);
            continue;
        }
        std::vector<std::filesystem::path> in_dir;
        for (const auto &e : std::filesystem::directory_iterator(argv[i]))
            if (e.is_regular_file()) in_dir.push_back(e.path());
        std::sort(in_dir.begin(), in_dir.end());
        files.insert(files.end(), in_dir.begin(), in_dir.end());
    }
    return files;
}

}  // namespace

int main(int argc, char **argv) {
    if (LLVMFuzzerInitialize) LLVMFuzzerInitialize(&argc, &argv);
    const std::vector<std::filesystem::path> files = Inputs(argc, argv);
    if (files.empty()) {
        std::fprintf(stderr, "%s: no inputs (give files or folders)\n", argv[0]);
        return 1;
    }
    for (const auto &f : files) {
        std::fprintf(stderr, "running %s\n", f.c_str());
        std::ifstream in(f, std::ios::binary);
        const std::string data((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
        LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t *>(data.data()), data.size());
    }
    std::fprintf(stderr, "%zu inputs, no crash\n", files.size());
    return 0;
}
