// .rad scene text read by SceneReader::ReadText, "!xform" lines included (done in-process), and
// flattened to triangles and shapes as the ray tracers take it. Inputs whose '!' lines would
// reach the shell, stdin or files of this machine are left out (fuzz_util.h), as are scenes with
// instances or meshes, whose files Flatten() would open. Each scene is also made into an octree
// (oconv, with options drawn from the input's length), which reads it from a scratch file.
#include "fuzz_util.h"
#include "scene/flatten.h"
#include "scene/oconv.h"
#include "scene/reader.h"

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    dayflux::fuzz::WritePartFile();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const std::string_view text = dayflux::fuzz::AsText(data, size);
    if (!dayflux::fuzz::OnlySafeCommands(text)) return -1;
    dayflux::fuzz::ExpectUserErrors([&] {
        dayflux::Scene scene;
        dayflux::SceneReader reader(&scene);
        reader.ReadText(text, "fuzz.rad");
        if (dayflux::fuzz::NamesFiles(scene)) return;
        dayflux::Flatten(std::move(scene));
        static dayflux::fuzz::ScratchFile file;
        dayflux::OconvOptions o;
        o.warnings = false;
        o.frozen = size & 1;
        o.set_limit = 1 + static_cast<int>(size >> 1) % 6;
        o.resolution = 64 << (size >> 4) % 3;  // finer: coincident surfaces, hours
        dayflux::MakeOctree({file.Write(text)}, o, "oconv fuzz.rad\n");
    });
    return 0;
}
