// Making RADIANCE octrees (oconv): the scene's objects sorted into RADIANCE's octree by its own
// object-cube tests, written in its binary format, so that RADIANCE's programs and ours read them
// and the bytes are those RADIANCE's oconv writes for the same scene.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace dayflux {

struct OconvOptions {
    int set_limit = 6;       // -n: objects a cube holds before it is split
    int resolution = 16384;  // -r: the smallest cube is the scene's size over this
    bool frozen = false;     // -f: the objects are stored in the octree, not their files
    bool warnings = true;    // -w turns them off
    bool bounded = false;    // -b: the cube below, not the scene's bounding cube
    double bounds_origin[3] = {0, 0, 0};
    double bounds_size = 0;
    std::string input_octree;  // -i: the octree the new objects are added to
};

// The octree of the scene files (paths, "!command"s, "-" for stdin, which freezes it), as oconv
// writes it: the header (the input octree's lines, then command_line, which ends in a newline,
// and the format), the cube, the file list or the objects, and the tree.
// The octree goes to write in pieces as it is made (after every check that can fail: nothing is
// written for bad input).
void MakeOctree(const std::vector<std::string> &files, const OconvOptions &options,
                const std::string &command_line,
                const std::function<void(std::string_view)> &write);
// The same, returned whole.
std::string MakeOctree(const std::vector<std::string> &files, const OconvOptions &options,
                       const std::string &command_line);

}  // namespace dayflux
