// RADIANCE octrees (oconv output) read by ReadOctree: frozen ones (objects in binary after a
// table of type names) and unfrozen ones (a list of scene files, read again), then flattened as
// the ray tracers take them. ReadOctree takes a path, so each input is written to a scratch
// file. Unfrozen octrees may list only fuzz_util.h's part file: any other name would be opened
// (or run, "!command") as a scene. oconv -i then reads each one's tree and adds the part file's
// objects to it.
#include "fuzz_util.h"
#include "scene/binary.h"
#include "scene/flatten.h"
#include "scene/oconv.h"
#include "scene/octree.h"

namespace {

// The files an unfrozen octree lists, read as ReadOctree reads them; false where they are not
// all the part file (or where the octree is bad before them: ReadOctree reports that itself).
bool ListsOnlyThePartFile(std::string_view data) {
    auto in = dayflux::InputSource::FromString(std::string(data), "fuzz.oct");
    dayflux::RadianceBinaryInput oct(*in, "octree");
    try {
        oct.Header("Radiance_octree");
        oct.Int(2);
        for (int i = 0; i < 4; ++i) oct.String();  // the cube's origin and size
        for (std::string f; !(f = oct.String()).empty();)
            if (f != dayflux::fuzz::kPartFile) return false;
    } catch (const dayflux::UserError &) {
    }
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    dayflux::fuzz::WritePartFile();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static dayflux::fuzz::ScratchFile file;
    const std::string_view bytes = dayflux::fuzz::AsText(data, size);
    if (!ListsOnlyThePartFile(bytes)) return -1;
    const std::string &path = file.Write(bytes);
    dayflux::fuzz::ExpectUserErrors([&] {
        dayflux::IsOctreeFile(path);
        dayflux::Scene scene;
        dayflux::ReadOctree(path, &scene);
        if (dayflux::fuzz::NamesFiles(scene)) return;
        dayflux::Flatten(std::move(scene));
        dayflux::OconvOptions o;
        o.warnings = false;
        o.input_octree = path;
        dayflux::MakeOctree({dayflux::fuzz::kPartFile}, o, "oconv -i fuzz.oct\n");
    });
    return 0;
}
