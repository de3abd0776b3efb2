// Klems BSDF XML files: each input loaded as rmtxop and dctimestep load it (the transmission and
// both reflection matrices, LoadBsdfMatrix) and as the BSDF material does (LoadKlemsBsdf).
// Both take a path, so each input is written to a scratch file.
#include "fuzz_util.h"
#include "matrix/bsdf_xml.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static dayflux::fuzz::ScratchFile file;
    const std::string &path = file.Write(dayflux::fuzz::AsText(data, size));
    for (dayflux::BsdfPart part :
         {dayflux::BsdfPart::kTransmission, dayflux::BsdfPart::kReflectionFront,
          dayflux::BsdfPart::kReflectionBack})
        dayflux::fuzz::ExpectUserErrors([&] { dayflux::LoadBsdfMatrix(path, part); });
    dayflux::fuzz::ExpectUserErrors([&] { dayflux::LoadKlemsBsdf(path); });
    return 0;
}
