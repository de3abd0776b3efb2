// A whole rfluxmtx run from its command line (args[0]: the program's name, for messages): the
// outputs written and committed, or a UserError. rfluxmtx-gpu and genBSDF run it.
#pragma once

#include <string>
#include <vector>

namespace dayflux {

void RunRfluxmtx(const std::vector<std::string> &args);

}  // namespace dayflux
