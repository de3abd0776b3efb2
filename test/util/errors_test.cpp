// RunTool, every program's main: whatever escapes the program's body ends as a message and exit
// status 1, never as an abort.
#include "util/errors.h"

#include <gtest/gtest.h>

#include <new>
#include <stdexcept>
#include <vector>

namespace dayflux {
namespace {

int Throws(int, char **argv) {
    const std::string what = argv[1];
    if (what == "user") throw UserError("x.rad:3: bad input");
    if (what == "length") std::vector<double>(std::vector<double>().max_size() + 1);
    if (what == "alloc") throw std::bad_alloc();
    if (what == "other") throw std::out_of_range("vector::at");
    return 0;
}

TEST(RunTool, EveryEscapedExceptionIsAMessageAndStatusOne) {
    const std::string name = ProgramName();  // RunTool sets it; other tests see it
    for (const auto &[what, said] :
         {std::pair{"user", "prog: x.rad:3: bad input\n"},
          std::pair{"length", "prog: out of memory (a size beyond what memory can hold)\n"},
          std::pair{"alloc", "prog: out of memory\n"},
          std::pair{"other", "prog: internal error: vector::at\n"}}) {
        char prog[] = "prog", *argv[] = {prog, const_cast<char *>(what), nullptr};
        testing::internal::CaptureStderr();
        const int status = RunTool(2, argv, Throws);
        EXPECT_EQ(testing::internal::GetCapturedStderr(), said);
        EXPECT_EQ(status, 1) << what;
    }
    SetProgramName(name);
}

}  // namespace
}  // namespace dayflux
