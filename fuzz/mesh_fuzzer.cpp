// RADIANCE compiled meshes (.rtm, obj2mesh output) read by ReadMesh: the quantised cube, the
// skipped octree, the mesh's own materials (as a frozen octree stores objects) and the patches
// of triangles. ReadMesh takes a path, so each input is written to a scratch file.
#include "fuzz_util.h"
#include "scene/meshes.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static dayflux::fuzz::ScratchFile file;
    const std::string &path = file.Write(dayflux::fuzz::AsText(data, size));
    dayflux::fuzz::ExpectUserErrors([&] {
        dayflux::Scene scene;
        dayflux::ReadMesh(path, &scene);
    });
    return 0;
}
