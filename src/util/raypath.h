// RADIANCE's search path for auxiliary files (.cal, .dat, ...): the user's RAYPATH first, then
// the current directory, then dayflux's own lib/ found relative to the running program
// (bin/../lib/dayflux, the same in the build tree and when installed).
#pragma once

#include <string>
#include <vector>

namespace dayflux {

std::vector<std::string> RaypathDirectories();
// The path of name on the search path; absolute and ./-relative names are taken as they are.
// Throws UserError naming the file and the path searched when it is not found.
std::string FindOnRaypath(const std::string &name);
// dayflux's own library folder (where lib/*.cal are installed).
std::string DayfluxLibDirectory();

}  // namespace dayflux
